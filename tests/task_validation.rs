//! Task files: the thesis's two tasks load with their data; every kind of bad input gets a
//! clear error naming the file, the field and what is allowed.

use std::f64::consts::PI;

use foldsynth::grammar::VertexType;
use foldsynth::task::{Task, TaskError};

fn path(name: &str) -> String {
    format!("{}/grammar/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_gripper_task_carries_the_thesis_data() {
    let t = Task::load(path("gripper.toml")).unwrap();
    assert_eq!(t.name, "gripper");
    assert_eq!(t.n_max, 3);
    assert!(t.symmetry.mirror_xz);
    let g0 = &t.initial;
    assert_eq!(g0.vertices.len(), 2);
    assert_eq!(
        (g0.vertices[0].xy, g0.vertices[0].ty),
        ([0.0, 0.0], VertexType::Terminal)
    );
    assert_eq!(
        (g0.vertices[1].xy, g0.vertices[1].ty),
        ([1.0, 0.0], VertexType::Extendable)
    );
    let c = &g0.creases[0];
    assert_eq!((c.tail, c.head), (0, 1));
    assert_eq!(
        (g0.facets[c.left].as_str(), g0.facets[c.right].as_str()),
        ("f1", "f2")
    );
    let drive = c.drive.as_ref().unwrap();
    assert_eq!(drive.as_str(), "t");
    assert_eq!(drive.eval(&0.7), 0.7);
    assert_eq!(g0.vertices[1].preds, vec![0]);
    assert_eq!(g0.vertices[1].slots, [None; 3]);
    assert_eq!(g0.mirror.as_ref().unwrap().vertex, vec![0, 1]);
    assert_eq!(g0.mirror.as_ref().unwrap().facet, vec![1, 0]);
    assert_eq!(t.motion.unwrap().t_max, PI / 2.0);
    let b = t.bounds.unwrap();
    assert_eq!(
        (b.l_min, b.l_max, b.alpha_min, b.alpha_max),
        (0.1, 1.5, PI / 18.0, 17.0 * PI / 18.0)
    );
    let o = t.objective.as_ref().unwrap();
    assert_eq!(o.threshold, 1e-5);
    assert_eq!(o.targets.len(), 1);
    assert_eq!(
        (o.targets[0].t, o.targets[0].point(), o.targets[0].weight),
        (PI / 2.0, Some([0.0, 0.0, 1.0]), 1.0)
    );
    let ch = t.check.as_ref().unwrap();
    assert_eq!(ch.states, 16);
    let cylinders: Vec<_> = t.scene.cylinders().collect();
    assert_eq!(cylinders.len(), 1);
    assert_eq!(
        (cylinders[0].radius, cylinders[0].a, cylinders[0].b),
        (0.25, [0.0, -1.0, 0.5], [0.0, 1.0, 0.5])
    );
    assert_eq!(t.scene.obstacles[0].name, "check.cylinders[0]");
    assert_eq!(t.scene.copies, foldsynth::scene::Copies::about_z(2));
}

#[test]
fn the_robotic_arm_task_carries_the_trajectory() {
    let t = Task::load(path("robotic_arm.toml")).unwrap();
    assert_eq!(t.initial, Task::load(path("gripper.toml")).unwrap().initial);
    let o = t.objective.as_ref().unwrap();
    assert_eq!(o.threshold, 0.3);
    assert_eq!(o.targets.len(), 11);
    for (i, tg) in o.targets.iter().enumerate() {
        let ti = i as f64 * PI / 20.0;
        assert!((tg.t - ti).abs() < 1e-15);
        let p = [1.0 + 2.0 * ti.cos(), 0.0, 2.0 * ti.sin()];
        for (a, b) in tg.point().unwrap().iter().zip(p) {
            assert!((a - b).abs() < 1e-15, "target {i}");
        }
    }
    assert!(t.scene.obstacles.is_empty());
    assert_eq!(t.scene.copies.n, 1);
}

const BASE: &str = r#"
[grammar]
n_max = 3
[symmetry]
mirror_xz = true
[[initial_graph.vertices]]
id = "v1"
xy = [0.0, 0.0]
type = "terminal"
[[initial_graph.vertices]]
id = "v2"
xy = [1.0, 0.0]
type = "extendable"
[[initial_graph.creases]]
from = "v1"
to = "v2"
left = "f1"
right = "f2"
drive = "t"
"#;

fn err(text: &str) -> TaskError {
    match Task::from_toml_str(text, "bad.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

/// `BASE` with `from` replaced by `to` (which must occur).
fn edit(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "{from}");
    BASE.replacen(from, to, 1)
}

fn assert_err(e: &TaskError, field: &str, words: &[&str]) {
    assert_eq!(e.file, "bad.toml");
    assert_eq!(e.field, field, "{e}");
    for w in words {
        assert!(e.message.contains(w), "`{w}` not in: {e}");
    }
    let shown = e.to_string();
    assert!(shown.starts_with("bad.toml: ") && shown.contains(field));
}

#[test]
fn the_base_case_is_valid() {
    Task::from_toml_str(BASE, "ok.toml").unwrap();
}

#[test]
fn a_cyclic_g0_is_rejected() {
    let text = BASE.to_owned()
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [1.0, 1.0]\ntype = \"extendable\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"v3\"\nleft = \"f1\"\nright = \"f3\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v3\"\nto = \"v2\"\nleft = \"f3\"\nright = \"f1\"\n";
    // v2 → v3 and v3 → v2 are one pair of vertices: caught as a double crease first.
    assert_err(
        &err(&text),
        "initial_graph.creases[2]",
        &["second crease between"],
    );
    let text = edit("drive = \"t\"\n", "drive = \"t\"\n")
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [1.0, 1.0]\ntype = \"extendable\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"v3\"\nleft = \"f1\"\nright = \"f3\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v3\"\nto = \"v1\"\nleft = \"f3\"\nright = \"f4\"\n";
    let e = err(&text
        .replace("type = \"terminal\"", "type = \"extendable\"")
        .replace("drive = \"t\"\n", ""));
    assert_err(&e, "initial_graph.creases", &["directed cycle", "acyclic"]);
}

#[test]
fn a_vertex_with_three_successors_is_rejected() {
    let mut text = BASE.to_owned();
    for (id, x, y) in [("a", 2.0, 0.0), ("b", 1.0, 1.0), ("c", 1.0, -1.0)] {
        text += &format!(
            "[[initial_graph.vertices]]\nid = \"{id}\"\nxy = [{x}, {y}]\ntype = \"terminal\"\n"
        );
        text += &format!(
            "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"{id}\"\nleft = \"g{id}\"\nright = \"h{id}\"\n"
        );
    }
    assert_err(
        &err(&text),
        "initial_graph.vertices[1]",
        &["already has 3 outgoing creases", "fewer than 3"],
    );
}

#[test]
fn inconsistent_facet_labels_are_rejected() {
    // v2 → v3 shares no facet with v1 → v2: two open sectors around the extendable v2.
    let text = BASE.to_owned()
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [1.0, 1.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"v3\"\nleft = \"f3\"\nright = \"f4\"\n";
    assert_err(
        &err(&text),
        "initial_graph.creases",
        &["inconsistent facet labels", "open"],
    );
    // The same facet on both sides of a crease.
    let e = err(&edit("right = \"f2\"", "right = \"f1\""));
    assert_err(&e, "initial_graph.creases[0].right", &["different facets"]);
    // A facet whose creases do not form one chain: f1 on two separate creases.
    let text = BASE.replace("type = \"extendable\"", "type = \"terminal\"")
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [0.0, 5.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.vertices]]\nid = \"v4\"\nxy = [1.0, 5.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v3\"\nto = \"v4\"\nleft = \"f3\"\nright = \"f1\"\ndrive = \"t\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v1\"\nto = \"v3\"\nleft = \"f4\"\nright = \"f5\"\ndrive = \"t\"\n";
    let e = err(&text.replace("mirror_xz = true", "mirror_xz = false"));
    assert_err(
        &e,
        "initial_graph.creases",
        &["inconsistent facet labels", "f1"],
    );
}

#[test]
fn a_disconnected_g0_is_rejected() {
    let text = BASE.to_owned()
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [5.0, 0.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.vertices]]\nid = \"v4\"\nxy = [6.0, 0.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v3\"\nto = \"v4\"\nleft = \"f3\"\nright = \"f4\"\ndrive = \"t\"\n";
    assert_err(&err(&text), "initial_graph", &["disconnected", "\"v3\""]);
}

#[test]
fn duplicate_and_unknown_ids_are_rejected() {
    let e = err(&edit("id = \"v2\"", "id = \"v1\""));
    assert_err(
        &e,
        "initial_graph.vertices[1].id",
        &["duplicate id \"v1\"", "unique"],
    );
    let e = err(&edit("to = \"v2\"", "to = \"v9\""));
    assert_err(
        &e,
        "initial_graph.creases[0].to",
        &["unknown vertex \"v9\"", "v1, v2"],
    );
    let e = err(&edit("to = \"v2\"", "to = \"v1\""));
    assert_err(&e, "initial_graph.creases[0].to", &["to itself"]);
}

#[test]
fn unknown_fields_are_rejected() {
    let e = err(&edit("n_max = 3", "n_max = 3\nnmax = 4"));
    assert_eq!(e.file, "bad.toml");
    assert!(e.field.contains("nmax"), "{e}");
    assert!(
        e.message.contains("unknown field") && e.message.contains("n_max"),
        "{e}"
    );
    assert!(e.message.contains("line 4"), "{e}");
    let e = err(&edit(
        "type = \"terminal\"",
        "type = \"terminal\"\ncolour = \"red\"",
    ));
    assert!(
        e.field.contains("colour") && e.message.contains("unknown field"),
        "{e}"
    );
    let e = err(&edit("type = \"terminal\"", "type = \"source\""));
    assert!(
        e.message.contains("extendable") && e.message.contains("terminal"),
        "{e}"
    );
}

#[test]
fn bad_coordinates_are_rejected() {
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [nan, 0.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy[0]",
        &["not a finite number"],
    );
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [1.0, inf]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy[1]",
        &["not a finite number"],
    );
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [0.0, 0.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy",
        &["lies on vertex \"v1\""],
    );
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [\"1/0\", 0.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy[0]",
        &["not a finite number"],
    );
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [\"one\", 0.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy[0]",
        &["unknown name `one`"],
    );
}

#[test]
fn drives_are_checked() {
    let e = err(&edit("drive = \"t\"\n", ""));
    assert_err(
        &e,
        "initial_graph.creases[0].drive",
        &["driven", "needs a driving angle"],
    );
    let e = err(&edit("drive = \"t\"", "drive = \"t +\""));
    assert_err(
        &e,
        "initial_graph.creases[0].drive",
        &["not a driving-angle expression"],
    );
    let e = err(&edit("drive = \"t\"", "drive = \"pi/2\""));
    assert_err(
        &e,
        "initial_graph.creases[0].drive",
        &["does not use the driving parameter"],
    );
    let text = BASE.to_owned()
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [1.0, -1.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"v3\"\nleft = \"f3\"\nright = \"f2\"\ndrive = \"t\"\n";
    assert_err(
        &err(&text),
        "initial_graph.creases[1].drive",
        &["takes no drive"],
    );
    let t = Task::from_toml_str(&edit("drive = \"t\"", "drive = \"-t/1.2\""), "ok.toml").unwrap();
    assert_eq!(
        t.initial.creases[0].drive.as_ref().unwrap().eval(&1.2),
        -1.0
    );
}

#[test]
fn types_and_structure_of_extendable_vertices_are_checked() {
    let e = err(&edit("type = \"terminal\"", "type = \"extendable\""));
    assert_err(
        &e,
        "initial_graph.vertices[0].type",
        &["no incoming crease", "terminal"],
    );
    // A lone outgoing crease in the middle of the open sector (no facet shared with p1 or
    // pm) is none of the scenarios of Tables 1–2.
    let text = BASE.to_owned()
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [2.0, 0.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"v3\"\nleft = \"f3\"\nright = \"f4\"\n";
    assert_err(
        &err(&text),
        "initial_graph.creases",
        &["2 sectors are open", "exactly one open sector"],
    );
    let e = err(&edit("n_max = 3", "n_max = 99"));
    assert_err(&e, "grammar.n_max", &["allowed 1..="]);
    let e = err(&edit("n_max = 3", "n_max = -1"));
    assert_err(&e, "grammar.n_max", &["allowed 1..="]);
    let e = err(&edit("n_max = 3", "n_max = 0"));
    assert_err(
        &e,
        "grammar.n_max",
        &["allowed 1..=", "at least one vertex"],
    );
}

#[test]
fn mirror_symmetry_of_g0_is_checked() {
    let text = BASE.to_owned()
        + "[[initial_graph.vertices]]\nid = \"v3\"\nxy = [1.0, -1.0]\ntype = \"terminal\"\n"
        + "[[initial_graph.creases]]\nfrom = \"v2\"\nto = \"v3\"\nleft = \"f3\"\nright = \"f2\"\n";
    assert_err(
        &err(&text),
        "symmetry.mirror_xz",
        &["not symmetric", "(1, 1)"],
    );
    Task::from_toml_str(
        &text.replace("mirror_xz = true", "mirror_xz = false"),
        "ok.toml",
    )
    .unwrap();
}

#[test]
fn design_fields_are_checked() {
    let with = |extra: &str| BASE.to_owned() + extra;
    let e = err(&with("[motion]\nt_max = 4\n"));
    assert_err(&e, "motion.t_max", &["within [-pi, pi]"]);
    let e = err(&with("[motion]\nt_max = 0\n"));
    assert_err(&e, "motion.t_max", &["nonzero"]);
    let b = |l_min: &str, l_max: &str, a_min: &str, a_max: &str| {
        with(&format!(
            "[bounds]\nl_min = {l_min}\nl_max = {l_max}\nalpha_min = {a_min}\nalpha_max = {a_max}\n"
        ))
    };
    assert_err(&err(&b("0", "1.5", "0.1", "3")), "bounds.l_min", &["> 0"]);
    assert_err(
        &err(&b("0.1", "0.1", "0.1", "3")),
        "bounds.l_max",
        &["exceed l_min"],
    );
    assert_err(
        &err(&b("0.1", "1.5", "0", "3")),
        "bounds.alpha_min",
        &["(0, pi)"],
    );
    assert_err(
        &err(&b("0.1", "1.5", "0.1", "\"pi\"")),
        "bounds.alpha_max",
        &["(alpha_min"],
    );
    let e = err(&with(
        "[bounds]\nl_min = 0.1\nl_max = 1.5\nalpha_min = 0.1\n",
    ));
    assert!(e.message.contains("missing field `alpha_max`"), "{e}");
    let obj = |t: &str, extra: &str| {
        with(&format!(
            "[motion]\nt_max = \"pi/2\"\n[objective]\nthreshold = 1e-5\n[[objective.targets]]\nt = {t}\npoint = [0, 0, 1]\n{extra}"
        ))
    };
    assert_err(
        &err(&obj("2", "")),
        "objective.targets[0].t",
        &["outside the motion range"],
    );
    assert_err(
        &err(&obj("1", "weight = -1\n")),
        "objective.targets[0].weight",
        &["> 0"],
    );
    Task::from_toml_str(&obj("\"pi/4\"", "weight = 2\n"), "ok.toml").unwrap();
    let e = err(&with(
        "[objective]\nthreshold = 1\n[[objective.targets]]\nt = 1\npoint = [0, 0, 1]\n",
    ));
    assert_err(&e, "objective", &["needs the motion range"]);
    let e = err(&with(
        "[motion]\nt_max = 1\n[objective]\nthreshold = 1\ntargets = []\n",
    ));
    assert_err(&e, "objective.targets", &["at least one"]);
    let e = err(&with("[check]\nstates = 1\n"));
    assert_err(&e, "check.states", &["at least 2"]);
    let e = err(&with(
        "[check]\nstates = 16\n[[check.cylinders]]\nradius = 0.25\nfrom = [0, 0, 0]\nto = [0, 0, 0]\n",
    ));
    assert_err(&e, "check.cylinders[0].to", &["distinct"]);
    let e = err(&with(
        "[check]\nstates = 16\n[[check.cylinders]]\nradius = -1\nfrom = [0, 0, 0]\nto = [0, 1, 0]\n",
    ));
    assert_err(&e, "check.cylinders[0].radius", &["> 0"]);
}

#[test]
fn unreadable_files_and_syntax_errors_are_reported() {
    let e = Task::load("/nonexistent/task.toml").unwrap_err();
    assert_eq!(e.file, "/nonexistent/task.toml");
    assert!(e.message.contains("cannot read"), "{e}");
    let e = err("[grammar\nn_max = 3\n");
    assert!(e.message.contains("line 1"), "{e}");
    let e = err("[grammar]\nn_max = 3\n");
    assert!(e.message.contains("missing field `initial_graph`"), "{e}");
    let e = err(&edit("n_max = 3", "n_max = \"three\""));
    assert!(e.message.contains("line 3"), "{e}");
}

#[test]
fn values_that_were_silently_accepted_are_refused() {
    // Issue 13: a third coordinate was dropped, 1e308 made every objective NaN, a G0
    // without an extendable vertex gave "0 meaningful graphs", a huge state count aborted.
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [1.0, 0.0, 2.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy",
        &["3 values", "exactly 2"],
    );
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [1.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy",
        &["1 values", "exactly 2"],
    );
    let e = err(&edit("xy = [1.0, 0.0]", "xy = [1e308, 0.0]"));
    assert_err(
        &e,
        "initial_graph.vertices[1].xy[0]",
        &["1e308", "±1000000"],
    );
    // The echo of a 309-digit number is short.
    assert!(e.to_string().len() < 300, "{e}");
    let e = err(&edit("type = \"extendable\"", "type = \"terminal\""));
    assert_err(&e, "initial_graph.vertices", &["extendable"]);
    let e = err(&(BASE.to_owned() + "[check]\nstates = 1000000000\n"));
    assert_err(&e, "check.states", &["at most 1000"]);
    let e = err(&(BASE.to_owned()
        + "[motion]\nt_max = 1\n[objective]\nthreshold = 1\n[[objective.targets]]\nt = 1\npoint = [0, 0]\n"));
    assert_err(&e, "objective.targets[0].point", &["exactly 3"]);
}

#[test]
fn a_task_name_is_a_safe_directory_name() {
    for bad in ["../../victim", "/abs/path", "a/b", "..", ".", "x\\\\y"] {
        let e = err(&format!("name = \"{bad}\"\n{BASE}"));
        assert_err(&e, "name", &[]);
    }
    let e = err(&format!("name = \"{}\"\n{BASE}", "n".repeat(65)));
    assert_err(&e, "name", &["64 characters"]);
    let t =
        Task::from_toml_str(&format!("name = \"{}\"\n{BASE}", "n".repeat(64)), "ok.toml").unwrap();
    assert_eq!(t.name.len(), 64);
    // The digest tells an edited file from the original.
    let a = Task::from_toml_str(BASE, "a.toml").unwrap();
    let b = Task::from_toml_str(&(BASE.to_owned() + "# edited\n"), "b.toml").unwrap();
    assert_ne!(a.digest, b.digest);
    assert_eq!(
        a.digest,
        Task::from_toml_str(BASE, "c.toml").unwrap().digest
    );
}

#[test]
fn robustness_defaults_and_settings() {
    use foldsynth::task::{DEFAULT_CLEARANCE, DEFAULT_MIN_FEATURE, DEFAULT_RIGID_MARGIN};
    // Absent: 1° and 1% of G0's crease.
    let t = Task::from_toml_str(BASE, "ok.toml").unwrap();
    assert_eq!(t.robustness.rigid_margin, PI / 180.0);
    assert_eq!(t.robustness.rigid_margin, DEFAULT_RIGID_MARGIN);
    assert_eq!(t.robustness.clearance, DEFAULT_CLEARANCE);
    assert_eq!(t.robustness.obstacle_clearance, 0.01);
    assert_eq!(t.robustness.min_feature, DEFAULT_MIN_FEATURE);
    assert_eq!(DEFAULT_MIN_FEATURE, 0.015);
    // Given (expressions allowed), the others keep their defaults; zeros are allowed.
    let t = Task::from_toml_str(
        &(BASE.to_owned() + "[robustness]\nrigid_margin = \"pi/90\"\nclearance = 0\n"),
        "ok.toml",
    )
    .unwrap();
    assert_eq!(t.robustness.rigid_margin, PI / 90.0);
    assert_eq!(t.robustness.clearance, 0.0);
    assert_eq!(t.robustness.obstacle_clearance, DEFAULT_CLEARANCE);
    let t = Task::from_toml_str(
        &(BASE.to_owned() + "[robustness]\nmin_feature = \"3/200\"\n"),
        "ok.toml",
    )
    .unwrap();
    assert_eq!(t.robustness.min_feature, 0.015);
    let t = Task::from_toml_str(
        &(BASE.to_owned() + "[robustness]\nmin_feature = 0\n"),
        "ok.toml",
    )
    .unwrap();
    assert_eq!(t.robustness.min_feature, 0.0);
    // The optimizer's states default to 9.
    let t = Task::from_toml_str(&(BASE.to_owned() + "[check]\nstates = 16\n"), "ok.toml").unwrap();
    assert_eq!(t.check.unwrap().optimize_states, 9);
}

#[test]
fn bad_robustness_values_are_refused_with_file_and_field() {
    let with = |extra: &str| BASE.to_owned() + extra;
    let e = err(&with("[robustness]\nrigid_margin = -0.1\n"));
    assert_err(&e, "robustness.rigid_margin", &["-0.1", "≥ 0"]);
    let e = err(&with("[robustness]\nclearance = nan\n"));
    assert_err(&e, "robustness.clearance", &["not a finite number"]);
    let e = err(&with("[robustness]\nobstacle_clearance = -1e-3\n"));
    assert_err(&e, "robustness.obstacle_clearance", &["≥ 0"]);
    let e = err(&with("[robustness]\nclearance = inf\n"));
    assert_err(&e, "robustness.clearance", &["not a finite number"]);
    // Larger than the pattern: G0's crease is 1 (the unit of lengths).
    let e = err(&with("[robustness]\nclearance = 1.5\n"));
    assert_err(
        &e,
        "robustness.clearance",
        &["larger than the pattern", "[0, 1)"],
    );
    let e = err(&with("[robustness]\nobstacle_clearance = 2\n"));
    assert_err(
        &e,
        "robustness.obstacle_clearance",
        &["larger than the pattern"],
    );
    // No vertex triangle has an Eq. 25 margin of 2π/3 or more.
    let e = err(&with("[robustness]\nrigid_margin = \"2*pi/3\"\n"));
    assert_err(&e, "robustness.rigid_margin", &["2π/3"]);
    let e = err(&with("[robustness]\nrigid_margin = \"pi/\"\n"));
    assert_eq!(e.field, "robustness.rigid_margin");
    // The flat layout's smallest feature (issue 20): paper units, below G0's crease.
    let e = err(&with("[robustness]\nmin_feature = -0.01\n"));
    assert_err(&e, "robustness.min_feature", &["-0.01", "≥ 0"]);
    let e = err(&with("[robustness]\nmin_feature = nan\n"));
    assert_err(&e, "robustness.min_feature", &["not a finite number"]);
    let e = err(&with("[robustness]\nmin_feature = 1\n"));
    assert_err(
        &e,
        "robustness.min_feature",
        &["larger than the pattern", "[0, 1)"],
    );
    let e = err(&with("[robustness]\nmargin = 1\n"));
    assert!(e.message.contains("unknown field"), "{e}");
    let e = err(&with("[check]\nstates = 16\noptimize_states = 1\n"));
    assert_err(&e, "check.optimize_states", &["at least 2"]);
}
