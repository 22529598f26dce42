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
    // Every error test below edits BASE: it must load, as the file it spells out.
    let t = Task::from_toml_str(BASE, "ok.toml").unwrap();
    assert_eq!(t.n_max, 3);
    assert!(t.symmetry.mirror_xz);
    let g0 = &t.initial;
    assert_eq!(g0.vertices.len(), 2);
    assert_eq!(
        (g0.vertices[1].xy, g0.vertices[1].ty),
        ([1.0, 0.0], VertexType::Extendable)
    );
    assert_eq!(g0.creases.len(), 1);
    assert_eq!((g0.creases[0].tail, g0.creases[0].head), (0, 1));
    assert_eq!(g0.creases[0].drive.as_ref().unwrap().as_str(), "t");
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
    // Undriven, v1 → v2 is v1's outgoing crease: an extendable v1 would have no incoming one.
    let e =
        err(&edit("type = \"terminal\"", "type = \"extendable\"").replace("drive = \"t\"\n", ""));
    assert_err(
        &e,
        "initial_graph.vertices[0].type",
        &["no incoming crease", "terminal"],
    );
    // Driven, the crease between two extendable vertices enters both ends (Fig. 32's
    // double-sided arrows): G0 holds it as two halves from a source at its midpoint.
    let t = Task::from_toml_str(
        &edit("type = \"terminal\"", "type = \"extendable\""),
        "ok.toml",
    )
    .unwrap();
    assert_eq!(t.initial.vertices.len(), 3);
    assert_eq!(t.initial.vertices[2].xy, [0.5, 0.0]);
    assert_eq!(t.initial.split.len(), 1);
    for v in 0..2 {
        assert_eq!(
            t.initial.vertices[v].preds.len(),
            1,
            "v{} has the drive as its p1",
            v + 1
        );
    }
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

/// `BASE` with the motion `[0, pi/2]` and `extra`.
fn moving(extra: &str) -> String {
    format!("{BASE}[motion]\nt_max = \"pi/2\"\n{extra}")
}

/// An objective with one target whose fields are `fields`.
fn target(fields: &str) -> String {
    moving(&format!(
        "[objective]\nthreshold = 0.1\n[[objective.targets]]\n{fields}\n"
    ))
}

/// A mesh fixture's absolute path.
fn mesh(name: &str) -> String {
    format!("{}/tests/data/meshes/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn bad_targets_are_refused_with_file_and_field() {
    let f = "objective.targets[0]";
    let cases: &[(&str, String, &[&str])] = &[
        // Expressions with t: an unknown name is named.
        (
            "t = 1\npoint = [\"2*s\", 0, 0]",
            format!("{f}.point[0]"),
            &["unknown name `s`", "t,"],
        ),
        (
            "t = \"0 .. 1\"\nsamples = 3\npoint = [\"1/(t - 0.5)\", 0, 0]",
            format!("{f}.point[0]"),
            &["at t = 0.5", "not a finite number"],
        ),
        (
            "t = 1\npoint = [\"nan\", 0, 0]",
            format!("{f}.point[0]"),
            &["unknown name `nan`"],
        ),
        // Ranges and samples.
        (
            "t = \"0 .. 1\"\nsamples = 1\npoint = [0, 0, 1]",
            format!("{f}.samples"),
            &["2 ≤ samples ≤ 1000"],
        ),
        (
            "t = \"0 .. 1\"\nsamples = 1001\npoint = [0, 0, 1]",
            format!("{f}.samples"),
            &["2 ≤ samples ≤ 1000"],
        ),
        (
            "t = \"0 .. 1\"\npoint = [0, 0, 1]",
            format!("{f}.samples"),
            &["missing", "samples = N"],
        ),
        (
            "t = 1\nsamples = 3\npoint = [0, 0, 1]",
            format!("{f}.samples"),
            &["one value"],
        ),
        (
            "t = \"1 .. 0\"\nsamples = 3\npoint = [0, 0, 1]",
            format!("{f}.t"),
            &["backwards"],
        ),
        (
            "t = \"1 .. 1\"\nsamples = 3\npoint = [0, 0, 1]",
            format!("{f}.t"),
            &["empty"],
        ),
        (
            "t = \"0 .. 2\"\nsamples = 3\npoint = [0, 0, 1]",
            format!("{f}.t"),
            &["outside the motion range"],
        ),
        (
            "t = \"0 .. t\"\nsamples = 3\npoint = [0, 0, 1]",
            format!("{f}.t"),
            &["end", "unknown name `t`"],
        ),
        (
            "t = \"0 .. 1 .. 2\"\nsamples = 3\npoint = [0, 0, 1]",
            format!("{f}.t"),
            &["\"a .. b\""],
        ),
        // Vertices and goals.
        (
            "vertex = \"s4\"\nt = 1\npoint = [0, 0, 1]",
            format!("{f}.vertex"),
            &["unknown vertex \"s4\"", "tip, s1, s2, s3, last", "v1, v2"],
        ),
        ("t = 1", f.to_owned(), &["no goal", "exactly one of point"]),
        (
            "t = 1\npoint = [0, 0, 1]\nplane = { point = [0, 0, 1], normal = [0, 0, 1] }",
            f.to_owned(),
            &["2 goals (point, plane)"],
        ),
        (
            "t = 1\nline = { point = [0, 0, 1], direction = [0, 0, 0] }",
            format!("{f}.line.direction"),
            &["zero length"],
        ),
        (
            "t = 1\nplane = { point = [0, 0, 1], normal = [0, \"1e-300\", 0] }",
            format!("{f}.plane.normal"),
            &["zero length"],
        ),
        (
            "t = 1\nplane = { point = [0, inf, 1], normal = [0, 0, 1] }",
            format!("{f}.plane.point[1]"),
            &["not a finite number"],
        ),
        (
            "t = 1\npoint = [0, 0, 1]\nweight = 0",
            format!("{f}.weight"),
            &["> 0"],
        ),
    ];
    for (fields, field, words) in cases {
        assert_err(&err(&target(fields)), field, words);
    }
}

#[test]
fn bad_surfaces_and_mesh_obstacles_name_the_file_and_the_field() {
    let surface = |file: &str, extra: &str| {
        target(&format!("t = 1\nsurface = {{ file = \"{file}\"{extra} }}"))
    };
    let f = "objective.targets[0].surface";
    for (name, words) in [
        ("garbage.stl", &["not a readable STL"][..]),
        ("no_faces.obj", &["no triangles"][..]),
        ("empty.stl", &["no triangles"][..]),
        ("huge_count.stl", &["30000", "20000"][..]),
        ("sheet.ply", &["unknown mesh format", "STL", "OBJ"][..]),
        ("missing.stl", &["cannot read the mesh file"][..]),
    ] {
        let e = err(&surface(&mesh(name), ""));
        assert_err(&e, &format!("{f}.file"), words);
        assert!(e.message.contains(&mesh(name)), "{e}");
    }
    let e = err(&surface(&mesh("sheet.obj"), ", scale = 0"));
    assert_err(&e, &format!("{f}.scale"), &["> 0"]);
    let e = err(&surface(&mesh("sheet.obj"), ", translate = [0, 0]"));
    assert_err(&e, &format!("{f}.translate"), &["exactly 3"]);
    let e = err(&surface(
        &mesh("sheet.obj"),
        ", scale = 1e6, translate = [1e6, 0, 0]",
    ));
    assert_err(&e, &format!("{f}.scale"), &["sheet.obj", "beyond"]);
    let e = err(&surface(&mesh(""), ""));
    assert_err(&e, &format!("{f}.file"), &["meshes", "not a regular file"]);
    let e = err(&surface("", ""));
    assert_err(&e, &format!("{f}.file"), &["empty"]);
    // The same checks for a mesh obstacle.
    let e = err(&format!(
        "{BASE}[[obstacles]]\nshape = \"mesh\"\nfile = \"{}\"\n",
        mesh("garbage.stl")
    ));
    assert_err(&e, "obstacles[0].file", &["garbage.stl", "STL"]);
    // Relative paths start from the task file's folder.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes");
    let text = format!("{BASE}[[obstacles]]\nshape = \"mesh\"\nfile = \"tetra.stl\"\n");
    Task::from_toml_str_in(&text, "ok.toml", &dir).unwrap();
    let e = Task::from_toml_str_in(&text, "bad.toml", std::path::Path::new("/nonexistent"))
        .unwrap_err();
    assert_err(
        &e,
        "obstacles[0].file",
        &["/nonexistent/tetra.stl", "cannot read"],
    );
}

#[test]
fn bad_area_terms_are_refused() {
    let area = |fields: &str| moving(&format!("[objective.area]\n{fields}\n"));
    let f = "objective.area";
    let cases: &[(&str, String, &[&str])] = &[
        (
            "kind = \"volume\"",
            format!("{f}.kind"),
            &["\"flat\"", "\"packing\""],
        ),
        (
            "kind = \"flat\"\nt = 1",
            format!("{f}.t"),
            &["only for kind = \"packing\""],
        ),
        ("kind = \"packing\"", format!("{f}.t"), &["missing"]),
        (
            "kind = \"packing\"\nt = 3",
            format!("{f}.t"),
            &["outside the motion range"],
        ),
        (
            "kind = \"packing\"\nt = \"0 .. 1\"",
            format!("{f}.t"),
            &["is a range"],
        ),
        (
            "kind = \"flat\"\nweight = 0",
            format!("{f}.weight"),
            &["> 0"],
        ),
        (
            "kind = \"flat\"\nweight = -inf",
            format!("{f}.weight"),
            &["not a finite number"],
        ),
        (
            "kind = \"flat\"\nat_least = -1",
            format!("{f}.at_least"),
            &["≥ 0"],
        ),
    ];
    for (fields, field, words) in cases {
        assert_err(&err(&area(fields)), field, words);
    }
    // Targets need a threshold; without targets an area term alone is an objective.
    let e = err(&moving(
        "[objective]\n[[objective.targets]]\nt = 1\npoint = [0, 0, 1]\n",
    ));
    assert_err(&e, "objective.threshold", &["missing"]);
    let e = err(&moving("[objective]\nthreshold = 1\n"));
    assert_err(&e, "objective.targets", &["[objective.area]"]);
}

#[test]
fn bad_requirements_are_refused_with_file_and_field() {
    let c = "constraints";
    let ori = |fields: &str| {
        moving(&format!(
            "[[constraints.orientation]]\ndirection = [0, 0, -1]\ntolerance = 0.1\n{fields}\n"
        ))
    };
    let o = "constraints.orientation[0]";
    let cases: Vec<(String, String, &[&str])> = vec![
        (
            ori("t = 1\nvertex = \"v9\""),
            format!("{o}.vertex"),
            &["unknown vertex \"v9\""],
        ),
        (
            ori("t = 1\nof = \"facet\""),
            format!("{o}.of"),
            &["\"facet_left\""],
        ),
        (
            moving("[[constraints.orientation]]\ndirection = [0, 0, 0]\ntolerance = 0.1\nt = 1\n"),
            format!("{o}.direction"),
            &["zero length"],
        ),
        (
            ori("t = 1\nangle = 4"),
            format!("{o}.angle"),
            &["0 ≤ angle ≤ pi"],
        ),
        (
            moving("[[constraints.orientation]]\ndirection = [0, 0, 1]\ntolerance = 0\nt = 1\n"),
            format!("{o}.tolerance"),
            &["> 0"],
        ),
        (
            ori("t = \"0 .. 1\"\nsamples = 1"),
            format!("{o}.samples"),
            &["2 ≤ samples"],
        ),
        (
            ori("t = 2"),
            format!("{o}.t"),
            &["outside the motion range"],
        ),
        (
            ori("t = 1\nname = \"\""),
            format!("{o}.name"),
            &["1 to 64 characters"],
        ),
        (
            format!(
                "{BASE}[[constraints.orientation]]\ndirection = [0, 0, 1]\ntolerance = 0.1\nt = 1\n"
            ),
            format!("{c}.orientation"),
            &["[motion]"],
        ),
        (
            moving("[constraints]\nmax_fold = \"pi\""),
            format!("{c}.max_fold"),
            &["0 < max < pi"],
        ),
        (
            moving("[constraints]\nmax_fold = 0"),
            format!("{c}.max_fold"),
            &["0 < max < pi"],
        ),
        (
            moving("[[constraints.fold_limits]]\ncrease = \"v1-v3\"\nmax = 1"),
            format!("{c}.fold_limits[0].crease"),
            &["unknown crease", "v1, v2"],
        ),
        (
            moving("[[constraints.fold_limits]]\ncrease = \"v1-v1\"\nmax = 1"),
            format!("{c}.fold_limits[0].crease"),
            &["no crease of G0 joins"],
        ),
        (
            moving("[[constraints.fold_limits]]\ncrease = \"tip\"\nmax = -1"),
            format!("{c}.fold_limits[0].max"),
            &["0 < max < pi"],
        ),
    ];
    for (text, field, words) in &cases {
        assert_err(&err(text), field, words);
    }
}

#[test]
fn degenerate_boxes_and_bad_obstacles_are_refused() {
    let inside = |fields: &str| moving(&format!("[[constraints.inside]]\n{fields}\n"));
    let i = "constraints.inside[0]";
    let obstacle = |fields: &str| format!("{BASE}[[obstacles]]\n{fields}\n");
    let b = "obstacles[0]";
    let cases: Vec<(String, String, &[&str])> = vec![
        (
            inside("min = [0, 0, 0]\nmax = [1, 0, 1]"),
            format!("{i}.max[1]"),
            &["max must exceed min"],
        ),
        (
            inside("min = [0, 0, 0]\nmax = [1, -1, 1]"),
            format!("{i}.max[1]"),
            &["max must exceed min"],
        ),
        (inside("min = [0, 0, 0]"), format!("{i}.max"), &["missing"]),
        (
            inside("min = [0, 0, 0]\nmax = [1, 1, 1]\ncenter = [0, 0, 0]"),
            format!("{i}.center"),
            &["one form"],
        ),
        (
            inside("center = [0, 0, 0]\nhalf_extents = [1, 0, 1]"),
            format!("{i}.half_extents[1]"),
            &["> 0"],
        ),
        (
            inside(
                "center = [0, 0, 0]\nhalf_extents = [1, 1, 1]\nx_axis = [1, 0, 0]\ny_axis = [2, 0, 0]",
            ),
            format!("{i}.y_axis"),
            &["parallel"],
        ),
        (
            inside("center = [0, 0, 0]\nhalf_extents = [1, 1, 1]\nx_axis = [0, 0, 0]"),
            format!("{i}.x_axis"),
            &["zero length"],
        ),
        (
            inside("min = [0, 0, 0]\nmax = [1, 1, 1]\nt = 5"),
            format!("{i}.t"),
            &["outside the motion range"],
        ),
        (
            inside("min = [0, 0, \"-inf\"]\nmax = [1, 1, 1]"),
            format!("{i}.min[2]"),
            &["unknown name"],
        ),
        (
            inside("min = [0, 0, -inf]\nmax = [1, 1, 1]"),
            format!("{i}.min[2]"),
            &["not a finite number"],
        ),
        (
            obstacle("shape = \"cone\""),
            format!("{b}.shape"),
            &[
                "\"cylinder\"",
                "\"sphere\"",
                "\"box\"",
                "\"halfspace\"",
                "\"mesh\"",
            ],
        ),
        (
            obstacle("shape = \"sphere\"\ncenter = [0, 0, 0]"),
            format!("{b}.radius"),
            &["missing"],
        ),
        (
            obstacle("shape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0"),
            format!("{b}.radius"),
            &["> 0"],
        ),
        (
            obstacle("shape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nnormal = [0, 0, 1]"),
            format!("{b}.normal"),
            &["belongs to another shape"],
        ),
        (
            obstacle("shape = \"cylinder\"\nradius = 1\nfrom = [0, 0, 1]\nto = [0, 0, 1]"),
            format!("{b}.to"),
            &["distinct"],
        ),
        (
            obstacle("shape = \"box\"\nmin = [0, 0, 0]\nmax = [0, 1, 1]"),
            format!("{b}.max[0]"),
            &["max must exceed min"],
        ),
        (
            obstacle("shape = \"box\"\ncenter = [0, 0, 0]\nhalf_extents = [1, 1, -1]"),
            format!("{b}.half_extents[2]"),
            &["> 0"],
        ),
        (
            obstacle("shape = \"halfspace\"\npoint = [0, 0, 0]\nnormal = [0, 0, 0]"),
            format!("{b}.normal"),
            &["zero length"],
        ),
        (
            obstacle("shape = \"mesh\""),
            format!("{b}.file"),
            &["missing"],
        ),
        (
            obstacle("shape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nname = \"a\\nb\""),
            format!("{b}.name"),
            &["control characters"],
        ),
    ];
    for (text, field, words) in &cases {
        assert_err(&err(text), field, words);
    }
}

#[test]
fn bad_copies_are_refused() {
    let copies = |fields: &str| format!("{BASE}[copies]\n{fields}\n");
    assert_err(&err(&copies("n = 0")), "copies.n", &["1 ≤ n ≤ 12"]);
    assert_err(&err(&copies("n = 13")), "copies.n", &["1 ≤ n ≤ 12"]);
    assert_err(
        &err(&copies("n = 3\naxis = { direction = [0, 0, 0] }")),
        "copies.axis.direction",
        &["zero length"],
    );
    assert_err(
        &err(&copies("n = 3\naxis = { point = [0, nan, 0] }")),
        "copies.axis.point[1]",
        &["not a finite number"],
    );
    let e = err(&format!(
        "{BASE}[check]\nstates = 4\nsecond_arm = true\n[copies]\nn = 2\n"
    ));
    assert_err(&e, "copies", &["second_arm", "both"]);
}

#[test]
fn meshes_over_the_limits_are_refused() {
    let dir = std::env::temp_dir().join(format!("foldsynth_limits_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Over the byte limit (a sparse file: nothing is written).
    let big = dir.join("big.stl");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(foldsynth::scene::mesh::MESH_BYTES_MAX + 1)
        .unwrap();
    let text = format!("{BASE}[[obstacles]]\nshape = \"mesh\"\nfile = \"big.stl\"\n");
    let e = Task::from_toml_str_in(&text, "bad.toml", &dir).unwrap_err();
    assert_err(
        &e,
        "obstacles[0].file",
        &["big.stl", "limited to 33554432 bytes"],
    );
    // A part of 20,000 triangles (the limit of one mesh), named six times: over the limit
    // of all the meshes of a task together.
    let n = foldsynth::scene::mesh::MESH_TRIANGLES_MAX;
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&(n as u32).to_le_bytes());
    for k in 0..n {
        stl.extend_from_slice(&[0u8; 12]);
        let x = k as f32;
        for p in [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]] {
            for c in p {
                stl.extend_from_slice(&c.to_le_bytes());
            }
        }
        stl.extend_from_slice(&[0, 0]);
    }
    std::fs::write(dir.join("part.stl"), &stl).unwrap();
    let one = "[[obstacles]]\nshape = \"mesh\"\nfile = \"part.stl\"\n";
    let text = format!("{BASE}{}", one.repeat(5));
    let t = Task::from_toml_str_in(&text, "ok.toml", &dir).unwrap();
    assert_eq!(t.scene.obstacles.len(), 5);
    let text = format!("{BASE}{}", one.repeat(6));
    let e = Task::from_toml_str_in(&text, "bad.toml", &dir).unwrap_err();
    assert_err(
        &e,
        "obstacles[5].file",
        &["part.stl", "120000 triangles", "100000"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_fabrication_table_is_read_with_its_defaults() {
    use foldsynth::task::fabrication::{FabMethod, Sides};
    assert!(
        Task::from_toml_str(BASE, "ok.toml")
            .unwrap()
            .fabrication
            .is_none()
    );
    let t = Task::from_toml_str(
        &(BASE.to_owned() + "[fabrication]\nthickness = 2\nscale = 100\n"),
        "ok.toml",
    )
    .unwrap();
    let f = t.fabrication.unwrap();
    assert_eq!((f.thickness, f.scale), (2.0, 100.0));
    assert_eq!((f.method, f.sides), (FabMethod::Tapered, Sides::One));
    assert_eq!((f.hinge_gap, f.min_width), (0.5, 2.0));
    assert_eq!(
        t.laminate,
        foldsynth::task::fabrication::Laminate::default()
    );
    let t = Task::from_toml_str(
        &(BASE.to_owned()
            + "[fabrication]\nthickness = 2\nscale = 100\nkerf = 0.15\ntab_width = 1\nhole = 4\nsheet = \"600x400\"\n"),
        "ok.toml",
    )
    .unwrap();
    let l = t.laminate;
    assert_eq!(
        (l.kerf, l.tab_width, l.hole, l.sheet),
        (0.15, 1.0, 4.0, Some([600.0, 400.0]))
    );
    // 2 mm at 100 mm per unit, one side: every panel point within 0.02 units of its facet.
    assert_eq!(f.reach_units(), 0.02);
    let t = Task::from_toml_str(
        &(BASE.to_owned()
            + "[fabrication]\nthickness = \"3/2\"\nscale = 50\nmethod = \"tapered\"\nsides = \"both\"\nhinge_gap = 0\nmin_width = 1\n"),
        "ok.toml",
    )
    .unwrap();
    let f = t.fabrication.unwrap();
    assert_eq!(
        (f.thickness, f.sides, f.hinge_gap, f.min_width),
        (1.5, Sides::Both, 0.0, 1.0)
    );
    assert_eq!(f.reach_units(), 0.015);
    // The table is part of the task: another thickness is another task (a resume refuses it).
    let a = Task::from_toml_str(
        &(BASE.to_owned() + "[fabrication]\nthickness = 2\nscale = 100\n"),
        "a.toml",
    )
    .unwrap();
    let b = Task::from_toml_str(
        &(BASE.to_owned() + "[fabrication]\nthickness = 3\nscale = 100\n"),
        "a.toml",
    )
    .unwrap();
    assert_ne!(a.digest, b.digest);
}

#[test]
fn bad_fabrication_values_are_refused_with_file_and_field() {
    let with = |extra: &str| BASE.to_owned() + "[fabrication]\n" + extra;
    for (text, field, words) in [
        (
            "thickness = 0\nscale = 100\n",
            "fabrication.thickness",
            &["(0, "][..],
        ),
        (
            "thickness = -2\nscale = 100\n",
            "fabrication.thickness",
            &["-2"][..],
        ),
        (
            "thickness = nan\nscale = 100\n",
            "fabrication.thickness",
            &["not a finite number"][..],
        ),
        (
            "thickness = inf\nscale = 100\n",
            "fabrication.thickness",
            &["not a finite number"][..],
        ),
        ("scale = 100\n", "fabrication.thickness", &["missing"][..]),
        (
            "thickness = 2\nscale = 0\n",
            "fabrication.scale",
            &["(0, "][..],
        ),
        (
            "thickness = 2\n",
            "fabrication.scale",
            &["missing", "mm per paper unit"][..],
        ),
        (
            "thickness = 2\nscale = 100\nmethod = \"glued\"\n",
            "fabrication.method",
            &["\"glued\"", "\"tapered\""][..],
        ),
        (
            "thickness = 2\nscale = 100\nsides = \"three\"\n",
            "fabrication.sides",
            &["\"one\"", "\"both\""][..],
        ),
        (
            "thickness = 2\nscale = 100\nhinge_gap = -0.5\n",
            "fabrication.hinge_gap",
            &["[0, "][..],
        ),
        (
            "thickness = 2\nscale = 100\nkerf = -0.1\n",
            "fabrication.kerf",
            &["[0, "][..],
        ),
        (
            "thickness = 2\nscale = 100\ntab_width = -1\n",
            "fabrication.tab_width",
            &["[0, "][..],
        ),
        (
            "thickness = 2\nscale = 100\nhole = 0\n",
            "fabrication.hole",
            &["(0, "][..],
        ),
        (
            "thickness = 2\nscale = 100\nsheet = \"axb\"\n",
            "fabrication.sheet",
            &["WxH"][..],
        ),
        (
            "thickness = 2\nscale = 100\nmin_width = 150\n",
            "fabrication.min_width",
            &["no panel"][..],
        ),
        // One side: two panels reach 2·thickness/scale; with the default clearance 0.01 the
        // limit is thickness/scale < 0.495 of G0's unit crease.
        (
            "thickness = 50\nscale = 100\n",
            "fabrication.thickness",
            &["leaves no panel"][..],
        ),
        (
            "thickness = 2\nscale = 100\nwidth = 3\n",
            "fabrication",
            &["width"][..],
        ),
    ] {
        let e = err(&with(text));
        if field == "fabrication" {
            assert!(e.to_string().contains("width"), "{e}");
            continue;
        }
        assert_err(&e, field, words);
    }
    // Just below the limit is a task (0.49 · 2 + 0.01 < 1).
    Task::from_toml_str(&with("thickness = 49\nscale = 100\n"), "ok.toml").unwrap();
}
