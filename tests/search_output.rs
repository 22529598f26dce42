//! The output directory of `foldsynth synthesize` (issue 13): a run writes only where it
//! was told, deletes only what an earlier run listed in its manifest, refuses a directory
//! that is not a run of the same settings unless `--force`, and `--resume` never mixes two
//! searches: it reports how many records it reused and why it dropped the others.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");
const ARM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/robotic_arm.toml");

fn foldsynth_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run foldsynth")
}

/// `synthesize TASK --n-max 1 --no-export --out OUT --json EXTRA…` (6 alternatives).
fn small(task: &str, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "synthesize",
        task,
        "--n-max",
        "1",
        "--no-export",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    foldsynth_in(out.parent().unwrap(), &args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn summary(o: &Output) -> Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Every file under `dir`, relative, sorted.
fn tree(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p.clone());
            }
            out.push(p.strip_prefix(dir).unwrap().display().to_string());
        }
    }
    out.sort();
    out
}

#[test]
fn a_task_name_is_never_a_path() {
    let root = tempfile::tempdir().unwrap();
    let work = root.path().join("work");
    std::fs::create_dir_all(work.join("out")).unwrap();
    let victim = root.path().join("victim");
    std::fs::create_dir_all(victim.join("designs")).unwrap();
    std::fs::write(victim.join("designs/keep.txt"), "mine").unwrap();
    let base = std::fs::read_to_string(GRIPPER).unwrap();
    for (i, name) in [
        "../../victim",
        "/tmp/absolute",
        "..",
        "a\\\\b",
        &"x".repeat(65),
    ]
    .iter()
    .enumerate()
    {
        let text = base.replace("name = \"gripper\"", &format!("name = \"{name}\""));
        let path = work.join(format!("t{i}.toml"));
        std::fs::write(&path, text).unwrap();
        let r = foldsynth_in(
            &work,
            &[
                "synthesize",
                path.to_str().unwrap(),
                "--n-max",
                "1",
                "--no-export",
            ],
        );
        assert_eq!(r.status.code(), Some(2), "{name}: {}", stderr(&r));
        assert!(stderr(&r).contains(": name: "), "{name}: {}", stderr(&r));
    }
    // Nothing outside was touched, nothing was written under out/.
    assert_eq!(tree(&victim), ["designs", "designs/keep.txt"]);
    assert!(tree(&work.join("out")).is_empty());

    // A name that is allowed but not a plain file name becomes a safe directory name.
    let text = base.replace("name = \"gripper\"", "name = \"my gripper: v2\"");
    let path = work.join("ok.toml");
    std::fs::write(&path, text).unwrap();
    let r = foldsynth_in(
        &work,
        &[
            "synthesize",
            path.to_str().unwrap(),
            "--n-max",
            "1",
            "--no-export",
        ],
    );
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(work.join("out/my_gripper__v2/summary.json").is_file());
}

#[test]
fn a_directory_that_is_not_a_run_of_these_settings_is_refused_unless_forced() {
    let root = tempfile::tempdir().unwrap();
    // A foreign, non-empty directory.
    let foreign = root.path().join("foreign");
    std::fs::create_dir_all(foreign.join("designs")).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    std::fs::write(foreign.join("designs/old.json"), "mine").unwrap();
    let r = small(GRIPPER, &foreign, &[]);
    assert_eq!(r.status.code(), Some(2));
    assert!(stderr(&r).contains("not a foldsynth run"), "{}", stderr(&r));
    assert_eq!(tree(&foreign), ["designs", "designs/old.json", "notes.txt"]);
    // --force writes into it and deletes nothing it did not write.
    summary(&small(GRIPPER, &foreign, &["--force"]));
    let files = tree(&foreign);
    for f in [
        "notes.txt",
        "designs/old.json",
        "summary.json",
        "manifest.json",
    ] {
        assert!(files.contains(&f.to_string()), "{f}: {files:?}");
    }

    // A run of other settings: refused, then replaced with --force, deleting only its files.
    let run = root.path().join("run");
    let first = summary(&small(GRIPPER, &run, &["--seed", "1"]));
    std::fs::write(run.join("designs/user.txt"), "mine").unwrap();
    let r = small(GRIPPER, &run, &["--seed", "2"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(
        stderr(&r).contains("seed: 1 there, 2 now"),
        "{}",
        stderr(&r)
    );
    let again = summary(&small(GRIPPER, &run, &["--seed", "2", "--force"]));
    assert_eq!(
        std::fs::read_to_string(run.join("designs/user.txt")).unwrap(),
        "mine"
    );
    // The earlier run's designs are gone unless this run wrote them again.
    let ids: Vec<&str> = again["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    for id in first["designs"].as_array().unwrap() {
        let id = id.as_str().unwrap();
        assert_eq!(
            run.join(format!("designs/{id}.json")).exists(),
            ids.contains(&id)
        );
    }
    // The same settings again: allowed without --force.
    summary(&small(GRIPPER, &run, &["--seed", "2"]));

    // A manifest that lists files outside the directory: they are left alone.
    let outside = root.path().join("outside.txt");
    std::fs::write(&outside, "mine").unwrap();
    let m: Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("manifest.json")).unwrap()).unwrap();
    let mut m = m.as_object().unwrap().clone();
    m.insert(
        "files".into(),
        serde_json::json!(["../outside.txt", outside.to_str().unwrap(), "summary.json"]),
    );
    std::fs::write(run.join("manifest.json"), Value::Object(m).to_string()).unwrap();
    summary(&small(GRIPPER, &run, &["--seed", "2"]));
    assert!(outside.exists());

    // --out that is a file: one clear error.
    let file = root.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let r = small(GRIPPER, &file, &[]);
    assert_eq!(r.status.code(), Some(2));
    assert!(stderr(&r).contains("not a directory"), "{}", stderr(&r));
    assert_eq!(stderr(&r).matches("os error").count(), 0, "{}", stderr(&r));
}

#[test]
fn resume_never_mixes_runs_and_says_what_it_reused() {
    let root = tempfile::tempdir().unwrap();
    let full = root.path().join("full");
    let s_full = summary(&small(GRIPPER, &full, &[]));
    let n = s_full["alternatives"].as_u64().unwrap() as usize;
    assert!(n >= 4, "{n} alternatives");

    // A copy with a corrupt middle line and a torn last line: both reported, both
    // evaluated again, the results equal the full run's.
    let part = root.path().join("part");
    std::fs::create_dir_all(&part).unwrap();
    for f in ["manifest.json", "settings.json"] {
        std::fs::copy(full.join(f), part.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(full.join("alternatives.jsonl")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut edited = String::new();
    for (i, l) in lines.iter().enumerate() {
        if i == 1 {
            edited.push_str("{\"key\": garbage\n");
        } else if i == lines.len() - 1 {
            edited.push_str(&l[..10]);
        } else {
            edited.push_str(l);
            edited.push('\n');
        }
    }
    std::fs::write(part.join("alternatives.jsonl"), edited).unwrap();
    let r = small(GRIPPER, &part, &["--resume"]);
    let s = summary(&r);
    assert_eq!(s["settings"]["resumed"], n - 2);
    let dropped = s["settings"]["resume"]["dropped"].as_array().unwrap();
    assert_eq!(dropped.len(), 2);
    assert_eq!(dropped[0]["line"], 2);
    assert!(dropped[0]["why"].as_str().unwrap().contains("not a record"));
    assert_eq!(dropped[1]["line"], n);
    assert!(stderr(&r).contains(&format!("reused {} record(s)", n - 2)));
    for k in ["alternatives", "meets_target", "feasible", "designs"] {
        assert_eq!(s[k], s_full[k], "{k}");
    }

    // Settings missing: resume refused (the records' origin is unknown), --force starts
    // afresh.
    std::fs::remove_file(part.join("settings.json")).unwrap();
    let r = small(GRIPPER, &part, &["--resume"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(
        stderr(&r).contains("settings.json is missing"),
        "{}",
        stderr(&r)
    );
    let s = summary(&small(GRIPPER, &part, &["--resume", "--force"]));
    assert_eq!(s["settings"]["resumed"], 0);
    assert_eq!(s["alternatives"], s_full["alternatives"]);

    // Settings unreadable: refused too.
    std::fs::write(part.join("settings.json"), "{not json").unwrap();
    let r = small(GRIPPER, &part, &["--resume"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(stderr(&r).contains("unreadable"), "{}", stderr(&r));

    // Another task's records with its settings: refused (the 407-vs-175 case).
    let arm = root.path().join("arm");
    summary(&small(ARM, &arm, &[]));
    std::fs::copy(
        full.join("alternatives.jsonl"),
        arm.join("alternatives.jsonl"),
    )
    .unwrap();
    let r = small(GRIPPER, &arm, &["--resume"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(stderr(&r).contains("task:"), "{}", stderr(&r));

    // An edited task file is another task, even under the same name.
    let edited = root.path().join("edited.toml");
    std::fs::write(
        &edited,
        std::fs::read_to_string(GRIPPER)
            .unwrap()
            .replace("mirror_xz = true", "mirror_xz = true  # edited"),
    )
    .unwrap();
    let r = small(edited.to_str().unwrap(), &full, &["--resume"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(stderr(&r).contains("task_digest"), "{}", stderr(&r));
}
