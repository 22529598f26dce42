//! `foldsynth synthesize` end to end on the gripper task with N_max = 2 (66 alternatives):
//! same seed, same results (whatever the number of workers); a run killed halfway and
//! resumed gives the same results; every exported FOLD file passes `foldsynth verify` and
//! folds, in the bar-and-hinge simulation, onto the PTU's states; bad task files are clear
//! errors.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

#[path = "common/runs.rs"]
#[allow(dead_code)] // only the records reader is used here
mod runs;
use runs::records;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

fn foldsynth(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .output()
        .expect("run foldsynth")
}

fn synthesize(out: &Path, extra: &[&str]) -> Value {
    let o = out.to_str().unwrap();
    let mut args = vec!["synthesize", GRIPPER, "--n-max", "2", "--out", o, "--json"];
    args.extend_from_slice(extra);
    let r = foldsynth(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    serde_json::from_slice(&r.stdout).unwrap()
}

fn counts(s: &Value) -> Vec<u64> {
    [
        "alternatives",
        "meets_target",
        "no_self_intersection",
        "no_intersection",
        "feasible",
        "verification_failures",
    ]
    .iter()
    .map(|k| s[k].as_u64().unwrap())
    .collect()
}

#[test]
fn same_seed_same_results_and_a_resumed_run_matches() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    let sa = synthesize(&a, &["--no-export", "--jobs", "2", "--seed", "7"]);
    let sb = synthesize(&b, &["--no-export", "--jobs", "1", "--seed", "7"]);
    assert_eq!(counts(&sa), counts(&sb));
    assert_eq!(sa["alternatives"], 66);
    assert_eq!(sa["verification_failures"], 0);
    assert!(sa["meets_target"].as_u64().unwrap() > 0);
    let (ra, rb) = (records(&a), records(&b));
    assert_eq!(ra.len(), 66);
    assert_eq!(ra, rb, "same seed, different results");

    // Kill halfway: a run of the same settings (its manifest and settings) with the first
    // half of the lines and a torn line, then resume.
    std::fs::create_dir_all(&c).unwrap();
    for f in ["manifest.json", "settings.json"] {
        std::fs::copy(a.join(f), c.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(a.join("alternatives.jsonl")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut partial = lines[..lines.len() / 2].join("\n");
    partial.push('\n');
    partial.push_str(&lines[lines.len() / 2][..20]);
    std::fs::write(c.join("alternatives.jsonl"), partial).unwrap();
    let sc = synthesize(
        &c,
        &["--no-export", "--jobs", "2", "--seed", "7", "--resume"],
    );
    assert_eq!(sc["settings"]["resumed"], lines.len() / 2);
    // The torn line is reported as dropped, with its line number.
    let dropped = sc["settings"]["resume"]["dropped"].as_array().unwrap();
    assert_eq!(dropped.len(), 1, "{dropped:?}");
    assert_eq!(dropped[0]["line"], lines.len() / 2 + 1);
    assert!(dropped[0]["why"].as_str().unwrap().contains("torn"));
    assert_eq!(counts(&sc), counts(&sa));
    assert_eq!(records(&c), ra, "resumed run differs");
    assert_eq!(sc["designs"], sa["designs"]);

    // Resuming with another seed would mix two searches: refused.
    let r = foldsynth(&[
        "synthesize",
        GRIPPER,
        "--n-max",
        "2",
        "--out",
        c.to_str().unwrap(),
        "--no-export",
        "--seed",
        "8",
        "--resume",
    ]);
    assert!(!r.status.success());
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("other settings"));
}

#[test]
fn exported_designs_verify_and_the_report_exists() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x");
    let s = synthesize(&out, &["--seed", "1"]);
    let designs = s["designs"].as_array().unwrap();
    assert!(!designs.is_empty(), "no feasible design at N_max = 2");
    assert!(out.join("report.html").exists());
    for id in designs {
        let id = id.as_str().unwrap();
        let design: Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("designs").join(format!("{id}.json"))).unwrap(),
        )
        .unwrap();
        // A feasible design meets the target and is rigid over the whole motion.
        assert!(design["objective"].as_f64().unwrap() <= 1e-5);
        assert_eq!(design["verification"]["rigid_over_motion"], true);
        assert!(design["verification"]["isometry_max"].as_f64().unwrap() <= 1e-9);
        // Every design's FOLD file (crease pattern, folded form) and, for the 20 most
        // robust, the one with the whole motion verify.
        let folded = out.join("designs").join(format!("{id}.fold"));
        let full = out.join("designs").join(id).join(format!("{id}.fold"));
        let rank = design["rank"].as_u64().unwrap();
        assert_eq!(full.exists(), rank <= 20, "{id}: rank {rank}");
        for fold in [&folded, &full].into_iter().filter(|f| f.exists()) {
            let r = foldsynth(&["verify", fold.to_str().unwrap()]);
            assert!(
                r.status.success(),
                "{id}: {}",
                String::from_utf8_lossy(&r.stdout)
            );
        }
        // The motion (the FOLD file's frames, or the design JSON's, whose fold angles are
        // read from its positions), simulated by the bar-and-hinge model, folds rigidly
        // onto the PTU's states.
        let moving = if full.exists() {
            full
        } else {
            out.join("designs").join(format!("{id}.json"))
        };
        let r = foldsynth(&["simulate", moving.to_str().unwrap(), "--json"]);
        assert!(
            r.status.success(),
            "{id}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        let sim: Value = serde_json::from_slice(&r.stdout).unwrap();
        assert_eq!(sim["agrees_with_ptu"], true, "{id}: {sim}");
    }
    // Every design at once, from the output directory (issue 8's cross-validation).
    let r = foldsynth(&["simulate", "--crossval", out.to_str().unwrap(), "--json"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let cv: Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(cv["count"].as_u64().unwrap() as usize, designs.len());
    assert_eq!(cv["agree"], cv["count"]);
    assert!(cv["max_gamma"].as_f64().unwrap() <= 1e-8);
    assert!(cv["max_position_error"].as_f64().unwrap() <= 1e-7);
    // The numeric benchmark takes a design file and measures the same motion both ways.
    let first = out
        .join("designs")
        .join(format!("{}.json", designs[0].as_str().unwrap()));
    let r = foldsynth(&[
        "bench",
        "numeric",
        first.to_str().unwrap(),
        "--task",
        GRIPPER,
        "--millis",
        "10",
        "--steps",
        "8",
        "--json",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let b: Value = serde_json::from_slice(&r.stdout).unwrap();
    assert!(b["jit_vs_f64_max"].as_f64().unwrap() <= 1e-12, "{b}");
    assert!(b["sim_panels_end_gap"].as_f64().unwrap() <= 1e-7, "{b}");
}

#[test]
fn bad_task_files_are_clear_errors() {
    let base = std::fs::read_to_string(GRIPPER).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str, &str); 5] = [
        ("no_target", "point = [0.0, 0.0, 1.0]\n", "", "target"),
        ("zero_radius", "radius = 0.25", "radius = 0.0", "radius"),
        ("t_max", "t_max = \"pi/2\"", "t_max = 4.0", "t_max"),
        ("lengths", "l_min = 0.1", "l_min = 2.0", "l_min"),
        ("n_max", "n_max = 3", "n_max = 0", "n_max"),
    ];
    for (name, from, to, field) in cases {
        let text = if name == "no_target" {
            // Drop the whole [[objective.targets]] entry.
            let start = base.find("[[objective.targets]]").unwrap();
            let end = base[start..].find(from).unwrap() + start + from.len();
            format!("{}{}", &base[..start], &base[end..])
        } else {
            assert!(base.contains(from), "{name}");
            base.replace(from, to)
        };
        let path = dir.path().join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let r = foldsynth(&[
            "synthesize",
            path.to_str().unwrap(),
            "--no-export",
            "--out",
            dir.path().to_str().unwrap(),
        ]);
        assert!(!r.status.success(), "{name} should fail");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(field), "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.toml")) || name == "no_target",
            "{name}: names the file: {err}"
        );
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}

/// The design ids of a summary's ranking, most robust first.
fn ranking_ids(summary: &Value) -> Vec<String> {
    summary["ranking"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["id"].as_str().unwrap().to_string())
        .collect()
}

/// The data report.html embeds for its script.
fn report_data(html: &str) -> Value {
    let start = "<script type=\"application/json\" id=\"foldsynth-data\">";
    let data = &html[html.find(start).unwrap() + start.len()..];
    serde_json::from_str(&data[..data.find("</script>").unwrap()]).unwrap()
}

/// `--report-motions N`: the report draws the whole motion (33 frames) of the N most
/// robust designs and, for the others, the folded form alone: the design's last frame, as
/// its JSON has it (the page rounds to 1e-4).
#[test]
fn the_report_draws_the_motion_of_the_most_robust_only() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let s = synthesize(
        &out,
        &["--no-export", "--seed", "1", "--report-motions", "3"],
    );
    let ranking = ranking_ids(&s);
    assert!(ranking.len() > 3);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let data = report_data(&html);
    let designs = data["designs"].as_array().unwrap();
    assert_eq!(designs.len(), ranking.len());
    for d in designs {
        let id = d["id"].as_str().unwrap();
        let rank = ranking.iter().position(|r| r == id).unwrap() + 1;
        let frames = d["geometry"]["frames"].as_array().unwrap();
        let noted = d["facts"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f[0] == "motion");
        let file: Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("designs").join(format!("{id}.json"))).unwrap(),
        )
        .unwrap();
        let motion = file["pattern"]["frames"].as_array().unwrap();
        assert_eq!(motion.len(), 33);
        if rank <= 3 {
            assert_eq!(frames.len(), 33, "{id}");
            assert!(!noted, "{id}");
        } else {
            assert_eq!(frames.len(), 1, "{id}");
            assert!(noted, "{id}");
            let last: Vec<f64> = motion[32]["coords"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|c| c.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
                .collect();
            let drawn: Vec<f64> = frames[0]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            assert_eq!(drawn.len(), last.len());
            for (a, b) in drawn.iter().zip(&last) {
                assert!((a - b).abs() <= 0.5e-4 + 1e-9, "{id}: {a} vs {b}");
            }
        }
    }
    // `all` draws every motion.
    let every = dir.path().join("all");
    synthesize(
        &every,
        &["--no-export", "--seed", "1", "--report-motions", "all"],
    );
    let html = std::fs::read_to_string(every.join("report.html")).unwrap();
    assert!(!html.contains("\"motion\","));
}

/// `--report-designs N`: the page carries the N most robust designs in full (card and
/// geometry) and every design as a row of its table, with the values of the design's own
/// JSON; the rest of the page does not grow with them.
#[test]
fn the_report_carries_the_most_robust_in_full_and_every_design_as_a_row() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let s = synthesize(
        &out,
        &["--no-export", "--seed", "1", "--report-designs", "5"],
    );
    let ranking = ranking_ids(&s);
    assert!(ranking.len() > 5);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let data = report_data(&html);
    let full: Vec<&str> = data["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["id"].as_str().unwrap())
        .collect();
    assert_eq!(
        full,
        ranking[..5].iter().map(String::as_str).collect::<Vec<_>>()
    );
    // Every design one row, in the ranking's order; its Ω* column is its JSON's objective.
    let heads: Vec<&str> = html
        .split("<th data-key=\"")
        .skip(1)
        .map(|t| &t[..t.find('"').unwrap()])
        .collect();
    let omega = heads.iter().position(|&h| h == "objective").unwrap();
    let rows = data["rows"].as_array().unwrap();
    let ids: Vec<&str> = rows.iter().map(|r| r[0].as_str().unwrap()).collect();
    assert_eq!(ids, ranking.iter().map(String::as_str).collect::<Vec<_>>());
    for r in rows {
        let id = r[0].as_str().unwrap();
        let file: Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("designs").join(format!("{id}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(r[omega], file["meta"]["objective"], "{id}");
        assert_eq!(r.as_array().unwrap().len(), heads.len(), "{id}");
    }
    // The page names the setting where it leaves designs out.
    assert!(
        html.contains("carries the 5 most robust designs in full (<code>--report-designs</code>)")
    );
    // `all`: every design in full.
    let every = dir.path().join("all");
    synthesize(
        &every,
        &["--no-export", "--seed", "1", "--report-designs", "all"],
    );
    let html = std::fs::read_to_string(every.join("report.html")).unwrap();
    assert!(!html.contains("designs in full (<code>--report-designs</code>)"));
    assert!(html.contains("\"rows\":["));
}

/// `--graph SEQ` searches only that meaningful graph (every mode assignment of it), takes
/// the sequence in any spacing, keeps it in the run's settings (a resume with another
/// graph is refused), and refuses a sequence that is not a meaningful graph of the search.
#[test]
fn graph_restricts_the_search_to_one_topology() {
    let flasher = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/flasher_cuboid.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("one");
    let o = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["synthesize", flasher, "--out", o, "--no-export", "--json"];
        args.extend_from_slice(extra);
        foldsynth(&args)
    };
    let r = run(&["--graph", "1,9"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s: Value = serde_json::from_slice(&r.stdout).unwrap();
    // `1, 9` has two extended orbits: 2^2 mode assignments, one area candidate.
    assert_eq!(s["graphs"].as_u64(), Some(1));
    assert_eq!(s["alternatives"].as_u64(), Some(4));
    let recs = records(&out);
    assert_eq!(recs.len(), 4);
    assert!(recs.values().all(|r| r["sequence"] == "1, 9"));
    let settings: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("settings.json")).unwrap()).unwrap();
    assert_eq!(settings["graphs"][0], "1,9");

    let other = run(&["--graph", "1, 10", "--resume"]);
    assert!(!other.status.success());
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(err.contains("graphs"), "{err}");

    let fresh = dir.path().join("bad");
    for (seq, says) in [
        ("1, (9, 20), 10", "not a meaningful graph"),
        ("1, 9, 9", "not extendable"),
        ("1, (2, 3)", "--graph \"1, (2, 3)\""),
        ("1, 11, 23, (10, 21)", "more than N_max = 2"),
    ] {
        let r = foldsynth(&[
            "synthesize",
            flasher,
            "--out",
            fresh.to_str().unwrap(),
            "--no-export",
            "--graph",
            seq,
        ]);
        assert!(!r.status.success(), "{seq} was accepted");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(says), "{seq}: {err}");
    }
}
