//! `report.html`: one file that carries everything it shows, and works in a real browser.
//!
//! Without a browser: the page loads nothing from anywhere (no `src`, no stylesheet links,
//! no network), its embedded geometry is the design's (positions, the facets' areas,
//! assignments), its table rows carry the design ids and the robustness margins, and a
//! search writes it (with `--no-export` too), names it, shows progress off a terminal and
//! numbers the gripping vertex one way everywhere (the number that, in the FOLD file,
//! points at the vertex that reaches the target).
//!
//! In headless Chromium (`tests/browser/report_check.mjs`, puppeteer-core over the DevTools
//! protocol), on copies of report.html alone in an empty folder: no console errors and no
//! requests, the 3D view is drawn, the slider, a mouse drag and play change the picture,
//! clicking a header sorts the rows by that column, the filters keep exactly the matching
//! rows, and clicking a row shows that design. Skips with a printed reason where Chromium,
//! Node.js or `tests/browser/node_modules` is missing, unless `FOLDSYNTH_REQUIRE_BROWSER=1`
//! (set by `.ci/run`), which turns the skip into a failure. `FOLDSYNTH_CHROMIUM` names
//! another Chromium binary.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use foldsynth::export::fold::assignments;
use foldsynth::export::plots::{DistributionPlot, NodeStatus, Series, TreeNode};
use foldsynth::export::report::{
    CountRow, Fact, ReportDesign, ReportInput, ReportSummary, TimingRow, write_report,
};
use foldsynth::export::verify::{VerifyOptions, verify_file};
use foldsynth::export::{DesignMeta, ExportOptions, samples, write_all};
use serde_json::{Value, json};

fn margin(value: f64, setting: f64, t: f64, at: &str) -> Value {
    json!({"value": value, "setting": setting, "t": t, "where": at})
}

/// Three sample designs with different levels, objectives and robustness records. The
/// scores follow the contract: min over the present margins of value / setting.
fn sample_designs() -> Vec<ReportDesign> {
    let (pg, mut mg) = samples::demo_gripper();
    mg.objective = Some(3e-7);
    mg.extra.insert("key".into(), json!("2|2|down"));
    let rob_g = json!({
        "score": (0.05_f64 / 0.0175).min(0.02 / 0.01).min(0.1 / 0.01),
        "rigid_margin": margin(0.05, 0.0175, 1.2, "v1"),
        "self_clearance": margin(0.02, 0.01, 0.5, "facets f1–f3"),
        "arm_clearance": null,
        "obstacle_clearance": margin(0.1, 0.01, 1.5, "facet f2 ↔ cylinder 1"),
        "min_feature": null,
    });
    let (pa, mut ma) = samples::demo_arm();
    ma.objective = Some(1e-3);
    let rob_a = json!({
        "score": 0.014 / 0.0175,
        "rigid_margin": margin(0.014, 0.0175, 0.3, "v2"),
        "self_clearance": null, "arm_clearance": null, "obstacle_clearance": null, "min_feature": null,
    });
    let p4 = samples::degree4(1.1, 1.2, 7);
    let m4 = DesignMeta {
        task: "demo <degree 4>".into(),
        rule_sequence: "2, 3".into(),
        modes: vec![foldsynth::export::Mode::Up],
        gripping_vertex: Some(2),
        objective: Some(5e-9),
        ..DesignMeta::default()
    };
    let design = |id: &str, level, candidate, pattern, meta, robustness| ReportDesign {
        id: id.into(),
        level,
        candidate,
        pattern,
        geometry: None,
        meta,
        robustness,
        area: None,
        facts: vec![Fact::new("note", "a \"quoted\" <value>")],
        design_file: None,
        files: None,
        verify: None,
        thick: None,
        in_full: true,
    };
    vec![
        design("d-arm", 2, None, pa, ma, Some(rob_a)),
        design("d-grip", 1, Some(2), pg, mg, Some(rob_g)),
        design("d-deg4", 1, Some(1), p4, m4, None),
    ]
}

fn build_report(out: &Path, export: bool) -> (PathBuf, ReportInput) {
    let mut designs = sample_designs();
    if export {
        for d in &mut designs {
            let opts = ExportOptions {
                name: d.id.clone(),
                image_size: (120, 90),
                gif_max_frames: 4,
                ..ExportOptions::default()
            };
            let files =
                write_all(&out.join("designs").join(&d.id), &d.pattern, &d.meta, &opts).unwrap();
            d.verify = Some(verify_file(&files.fold, &VerifyOptions::default()).unwrap());
            d.files = Some(files);
        }
    }
    let tree = vec![
        TreeNode {
            id: 0,
            parent: None,
            label: "2".into(),
            level: 1,
            status: NodeStatus::Meaningful,
        },
        TreeNode {
            id: 1,
            parent: Some(0),
            label: "2, 3".into(),
            level: 2,
            status: NodeStatus::Invalid,
        },
    ];
    let input = ReportInput {
        summary: ReportSummary {
            title: "foldsynth report & test".into(),
            task: "demo".into(),
            counts: vec![CountRow {
                label: "alternatives".into(),
                value: 3,
                thesis: Some(1170),
            }],
            timings: vec![TimingRow {
                stage: "export".into(),
                seconds: 0.25,
            }],
            notes: vec!["seed 1".into()],
        },
        task: vec![
            Fact::new("G0 vertices", "v1 at (0, 0); v2 at (1, 0)"),
            Fact::new("target", "(0, 0, 1) at t = 1.5708"),
        ],
        tree,
        distribution: Some(DistributionPlot {
            title: "Designs over rule applications".into(),
            x_label: "rule applications".into(),
            y_label: "designs".into(),
            series: vec![Series {
                name: "all".into(),
                points: vec![[1.0, 1.0], [2.0, 3.0]],
            }],
        }),
        designs,
    };
    std::fs::create_dir_all(out).unwrap();
    (write_report(out, &input).unwrap(), input)
}

/// The page without the text of its inline scripts.
fn markup(html: &str) -> String {
    let mut out = String::new();
    let mut rest = html;
    while let Some(i) = rest.find("<script") {
        let open_end = i + rest[i..].find('>').unwrap() + 1;
        out.push_str(&rest[..open_end]);
        let close = rest[open_end..].find("</script>").unwrap();
        rest = &rest[open_end + close..];
    }
    out.push_str(rest);
    out
}

/// The embedded data (`<script type="application/json" id="foldsynth-data">`).
fn embedded(html: &str) -> Value {
    let key = "<script type=\"application/json\" id=\"foldsynth-data\">";
    let i = html.find(key).unwrap() + key.len();
    let j = html[i..].find("</script>").unwrap();
    serde_json::from_str(&html[i..i + j]).unwrap()
}

/// Every `attr="…"` value in `text`.
fn attrs(text: &str, attr: &str) -> Vec<String> {
    let key = format!(" {attr}=\"");
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find(&key) {
        rest = &rest[i + key.len()..];
        let end = rest.find('"').unwrap();
        out.push(rest[..end].to_string());
        rest = &rest[end..];
    }
    out
}

fn shoelace(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
        / 2.0
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

/// The page's data is the designs' geometry: positions (rounded to 1e-4), triangles that
/// tile every facet (the same total area), edges and assignments as the FOLD writer's.
fn assert_geometry_matches(data: &Value, input: &ReportInput) {
    let ds = data["designs"].as_array().unwrap();
    assert_eq!(ds.len(), input.designs.len());
    for (d, want) in ds.iter().zip(&input.designs) {
        let p = &want.pattern;
        let g = &d["geometry"];
        assert_eq!(d["id"], want.id.as_str());
        let flat = g["flat"].as_array().unwrap();
        assert_eq!(flat.len(), p.vertices.len());
        for (a, b) in flat.iter().zip(&p.vertices) {
            assert!((f(&a[0]) - b[0]).abs() <= 5e-5 && (f(&a[1]) - b[1]).abs() <= 5e-5);
        }
        let frames = g["frames"].as_array().unwrap();
        assert_eq!(frames.len(), p.frames.len());
        for (fr, want) in frames.iter().zip(&p.frames) {
            let xs: Vec<f64> = fr.as_array().unwrap().iter().map(f).collect();
            assert_eq!(xs.len(), 3 * want.coords.len());
            for (k, c) in want.coords.iter().enumerate() {
                for a in 0..3 {
                    assert!((xs[3 * k + a] - c[a]).abs() <= 5e-5);
                }
            }
        }
        let tris: Vec<usize> = g["tris"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        assert_eq!(tris.len() % 3, 0);
        let tri_area: f64 = tris
            .chunks(3)
            .map(|t| shoelace(&[p.vertices[t[0]], p.vertices[t[1]], p.vertices[t[2]]]))
            .sum();
        let face_area: f64 = p
            .faces
            .iter()
            .map(|fc| shoelace(&fc.iter().map(|&v| p.vertices[v]).collect::<Vec<_>>()))
            .sum();
        assert!((tri_area - face_area).abs() < 1e-9 * face_area.max(1.0));
        let assign: String = assignments(p).iter().map(|a| a.as_str()).collect();
        assert_eq!(g["assign"], assign.as_str());
        assert_eq!(g["edges"].as_array().unwrap().len(), p.edges.len());
        assert_eq!(d["gripping"], json!(want.meta.gripping_vertex));
    }
}

#[test]
fn report_is_one_file_with_the_designs_geometry() {
    for export in [true, false] {
        let dir = tempfile::tempdir().unwrap();
        let (report, input) = build_report(dir.path(), export);
        let html = std::fs::read_to_string(&report).unwrap();
        let m = markup(&html);
        // Nothing is loaded: no src, no stylesheets, no CSS urls.
        assert!(attrs(&m, "src").is_empty(), "{:?}", attrs(&m, "src"));
        assert!(!m.contains("<link") && !m.contains("url(") && !m.contains("@import"));
        assert!(!m.contains("<img"));
        // Links only to files beside the report, and only when they were written.
        let hrefs: Vec<String> = embedded(&html)["designs"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|d| d["files"].as_array().unwrap().clone())
            .map(|pair| pair[1].as_str().unwrap().to_string())
            .collect();
        assert_eq!(hrefs.is_empty(), !export);
        for h in &hrefs {
            assert!(!h.contains("://") && !h.starts_with('/'), "{h}");
            assert!(dir.path().join(h).is_file(), "missing: {h}");
        }
        // three.js and the page's script are inline; the data parses and is the geometry.
        assert_eq!(m.matches("<script>").count(), 2);
        assert!(html.contains("FoldsynthThree"));
        assert_geometry_matches(&embedded(&html), &input);
        // Every design id is a table row, in the given order, its values in column order
        // (the page formats them: `vertex` writes a gripping vertex v7).
        let data = embedded(&html);
        let heads = attrs(&m, "data-key");
        let col = |k: &str| heads.iter().position(|h| h == k).unwrap();
        let rows = data["rows"].as_array().unwrap();
        let ids: Vec<&str> = rows.iter().map(|r| r[0].as_str().unwrap()).collect();
        assert_eq!(ids, ["d-arm", "d-grip", "d-deg4"]);
        assert!(rows.iter().any(|r| r[col("gripping")] == 7));
        assert!(m.contains("data-key=\"gripping\" data-numeric=\"false\" data-format=\"vertex\""));
        // Robustness columns exactly for the margins some design has.
        let heads = attrs(&m, "data-key");
        for k in [
            "score",
            "rigid_margin",
            "self_clearance",
            "obstacle_clearance",
        ] {
            assert!(heads.iter().any(|h| h == k), "{k}");
        }
        for k in ["arm_clearance", "min_feature"] {
            assert!(!heads.iter().any(|h| h == k), "{k}");
        }
        // User text escaped; the task at the top.
        assert!(m.contains("foldsynth report &amp; test"));
        assert!(m.contains("demo &lt;degree 4&gt;") || html.contains("demo \\u003cdegree 4>"));
        assert!(m.contains("<th>G0 vertices</th>"));
    }
}

#[test]
fn report_refuses_duplicate_ids_and_out_of_range_gripping_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let (_, mut input) = build_report(dir.path(), false);
    input.designs[0].meta.gripping_vertex = Some(0);
    let e = foldsynth::export::report::report_html(dir.path(), &input)
        .unwrap_err()
        .to_string();
    assert!(e.contains("d-arm") && e.contains("gripping_vertex"), "{e}");
    let (_, mut input) = build_report(dir.path(), false);
    input.designs[2].id = "d-arm".into();
    let e = foldsynth::export::report::report_html(dir.path(), &input)
        .unwrap_err()
        .to_string();
    assert!(e.contains("designs[2].id"), "{e}");
}

fn foldsynth(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

/// A small search: report and summary named at the end, progress lines on stderr (not a
/// terminal) for every phase, and one gripping-vertex number in the report, the design
/// JSON (top level and meta) and the FOLD file, where it indexes (1-based) the vertex that
/// reaches the target P_G = (0, 0, 1).
#[test]
fn search_writes_the_report_names_it_and_numbers_the_gripping_vertex_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("g1");
    let o = foldsynth(&[
        "synthesize",
        "grammar/gripper.toml",
        "--n-max",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stdout}\n{stderr}");
    // The files close the output: the report, the summary, the records (issue 35 added the
    // last); with 6 designs, all under the default --export 20, no "design files" line.
    let lines: Vec<&str> = stdout.lines().collect();
    let n = lines.len();
    assert_eq!(
        lines[n - 3..],
        [
            format!("report: {}", out.join("report.html").display()),
            format!("summary: {}", out.join("summary.json").display()),
            format!(
                "records: {} (and alternatives.parquet)",
                out.join("alternatives.jsonl").display()
            ),
        ]
    );
    for phase in [
        "enumerate graphs: ",
        "compile + optimize + check: 6/6 alternatives in ",
        "write designs and their files: ",
        "write report: done in ",
    ] {
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with(&format!("progress: {phase}"))),
            "{phase} missing in\n{stderr}"
        );
    }
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let ids: Vec<&str> = summary["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert!(!ids.is_empty());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let data = embedded(&html);
    let report_ids: Vec<&str> = data["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["id"].as_str().unwrap())
        .collect();
    assert_eq!(report_ids, ids);
    for (id, d) in ids.iter().zip(data["designs"].as_array().unwrap()) {
        let design: Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("designs").join(format!("{id}.json"))).unwrap(),
        )
        .unwrap();
        let g = design["gripping_vertex"].as_u64().unwrap();
        assert_eq!(design["meta"]["gripping_vertex"], g);
        assert_eq!(d["gripping"], g);
        let fold_path = out.join("designs").join(id).join(format!("{id}.fold"));
        let fold: Value =
            serde_json::from_str(&std::fs::read_to_string(&fold_path).unwrap()).unwrap();
        assert_eq!(fold["foldsynth:grippingVertex"], g);
        let last = fold["file_frames"].as_array().unwrap().last().unwrap();
        let p = &last["vertices_coords"][g as usize - 1];
        let dist = ((f(&p[0])).powi(2) + f(&p[1]).powi(2) + (f(&p[2]) - 1.0).powi(2)).sqrt();
        assert!(dist <= 1e-5, "{id}: v{g} ends {dist} from P_G");
        // The page says the same: the design's row has gripping vertex g.
        let heads = attrs(&html, "data-key");
        let col = heads.iter().position(|h| h == "gripping").unwrap();
        let row = data["rows"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r[0] == *id)
            .unwrap();
        assert_eq!(row[col], g);
    }
}

/// `--no-export` still writes the report (with the 3D views' geometry), and says so.
#[test]
fn no_export_run_writes_a_report_too() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("arm");
    let o = foldsynth(&[
        "synthesize",
        "grammar/robotic_arm.toml",
        "--n-max",
        "1",
        "--no-export",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    // --json keeps stdout one JSON document; the file names go to stderr.
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(stderr.contains(&format!("report: {}", out.join("report.html").display())));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("--no-export: design JSONs only"));
    let data = embedded(&html);
    assert_eq!(
        data["designs"].as_array().unwrap().len(),
        summary["designs"].as_array().unwrap().len()
    );
    for d in data["designs"].as_array().unwrap() {
        assert_eq!(
            d["files"].as_array().unwrap().len(),
            1,
            "only the design JSON"
        );
        assert!(!d["geometry"]["frames"].as_array().unwrap().is_empty());
    }
}

// ---- in the browser -----------------------------------------------------------------------

fn find_in_path(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    for name in names {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// Chromium, node and the driver's node_modules, or why not.
fn browser_tools() -> Result<(PathBuf, PathBuf, PathBuf), String> {
    let chromium = match std::env::var_os("FOLDSYNTH_CHROMIUM").map(PathBuf::from) {
        Some(p) if p.is_file() => p,
        Some(p) => return Err(format!("FOLDSYNTH_CHROMIUM={} is not a file", p.display())),
        None => find_in_path(&["chromium", "chromium-browser"])
            .ok_or("chromium not found in PATH (Debian package `chromium`)")?,
    };
    let node = find_in_path(&["node", "nodejs"]).ok_or("node not found in PATH")?;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser");
    if !dir.join("node_modules/puppeteer-core").is_dir() {
        return Err(format!(
            "{}/node_modules is missing (run `npm ci` there)",
            dir.display()
        ));
    }
    Ok((chromium, node, dir))
}

/// Run the driver on the pages; its JSON observations.
fn drive(pages: &[&Path], broken: &Path) -> Value {
    let (chromium, node, dir) = match browser_tools() {
        Ok(t) => t,
        Err(why) => {
            if std::env::var("FOLDSYNTH_REQUIRE_BROWSER").as_deref() == Ok("1") {
                panic!("FOLDSYNTH_REQUIRE_BROWSER=1 but {why}");
            }
            println!("SKIPPED: {why}");
            return Value::Null;
        }
    };
    let mut cmd = Command::new(node);
    cmd.arg(dir.join("report_check.mjs"))
        .arg("--chromium")
        .arg(&chromium)
        .arg("--broken")
        .arg(broken)
        .args(pages)
        .current_dir(&dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        stdout.read_to_string(&mut s).unwrap();
        s
    });
    let deadline = Instant::now() + Duration::from_secs(240);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("the browser driver ran for more than 240 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let out = reader.join().unwrap();
    assert!(status.success(), "driver failed: {err}\n{out}");
    let v: Value = serde_json::from_str(out.trim())
        .unwrap_or_else(|e| panic!("driver output is not JSON ({e}): {out}\n{err}"));
    assert!(v.get("failure").is_none(), "driver: {}", v["failure"]);
    v
}

/// A copy of `report` alone in a fresh folder.
/// Designs of the large page (issue 34: a run of 100,000 designs).
const LARGE: usize = 100_000;

/// A page that carries some designs as table rows only (the large page of
/// [`report_works_in_headless_chromium_moved_alone`], or a real run's): 100 rows at a time,
/// the next page the next 100 of the same order, and a design carried as a row only
/// selected by its row: its values, and the command that draws it, no 3D view.
fn assert_paged_table_works(r: &Value, data: &Value) {
    let file = &r["file"];
    assert!(
        r["errors"].as_array().unwrap().is_empty(),
        "{file}: {}",
        r["errors"]
    );
    let rows = data["rows"].as_array().unwrap().len();
    let full = data["designs"].as_array().unwrap().len();
    assert!(
        rows > 100 && full < rows,
        "{file}: {rows} rows, {full} in full"
    );
    let pages = rows.div_ceil(100);
    let first = &r["pager"]["first"];
    assert_eq!(first["pages"], pages);
    assert_eq!(first["page"], 0);
    assert_eq!(ids(&first["rows"]).len(), 100);
    assert_eq!(
        first["info"],
        format!("rows 1–100 of {rows} (page 1 of {pages})")
    );
    let next = &r["pager"]["next"];
    assert_eq!(next["page"], 1);
    let (a, b) = (ids(&first["rows"]), ids(&next["rows"]));
    assert_eq!(b.len(), 100.min(rows - 100));
    assert!(a.iter().all(|id| !b.contains(id)), "{file}: pages overlap");
    assert_eq!(
        next["info"],
        format!("rows 101–{} of {rows} (page 2 of {pages})", 200.min(rows))
    );
    // On opening, the page shows the first 100 of the most robust first order.
    assert_eq!(ids(&r["initial"]["table"]["order"]).len(), 100);
    let only = &r["rowOnly"];
    let id = only["selected"].as_str().unwrap();
    assert!(
        !data["designs"]
            .as_array()
            .unwrap()
            .iter()
            .any(|d| d["id"] == id),
        "{id}"
    );
    assert!(only["title"].as_str().unwrap().starts_with(id));
    assert_eq!(only["viewsHidden"], true);
    let files = only["files"].as_str().unwrap();
    assert!(
        files.contains(&format!("foldsynth export designs/{id}.json --format all")),
        "{files}"
    );
    assert!(only["facts"].as_u64().unwrap() >= 7, "{only}");
}

fn alone(report: &Path, dir: &Path, name: &str) -> PathBuf {
    let d = dir.join(name);
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join("report.html");
    std::fs::copy(report, &p).unwrap();
    p
}

fn ids(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

/// Row ids sorted by a numeric column the way a stable sort does: ties (and missing
/// values, always last) keep the original order.
fn expected_order(rows: &[(String, Option<f64>)], dir: f64) -> Vec<String> {
    let mut idx: Vec<usize> = (0..rows.len()).collect();
    idx.sort_by(|&a, &b| match (rows[a].1, rows[b].1) {
        (Some(x), Some(y)) => (dir * x).partial_cmp(&(dir * y)).unwrap().then(a.cmp(&b)),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.cmp(&b),
    });
    idx.into_iter().map(|i| rows[i].0.clone()).collect()
}

/// The numeric value of column `key` per design, from the embedded data.
fn column(data: &Value, key: &str) -> Vec<(String, Option<f64>)> {
    data["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            let v = match key {
                "objective" | "level" | "candidate" => d[key].as_f64(),
                "score" => d["robustness"]["score"].as_f64(),
                m => d["robustness"][m]["value"].as_f64(),
            };
            (d["id"].as_str().unwrap().to_string(), v)
        })
        .collect()
}

/// What every report must show in the browser, whatever its designs: the view
/// ([`assert_view_works`]), and a table whose sorts and filters keep exactly the right rows
/// (a page that carries every design in full).
fn assert_page_works(r: &Value, data: &Value) {
    assert_view_works(r, data);
    let file = &r["file"];
    let designs = data["designs"].as_array().unwrap();
    // Sorting by a numeric column orders the rows by it (stable), both ways.
    for key in [
        "objective",
        "level",
        "score",
        "rigid_margin",
        "self_clearance",
    ] {
        let Some(s) = r["sorts"].get(key) else {
            continue;
        };
        let col = column(data, key);
        assert_eq!(ids(&s["asc"]), expected_order(&col, 1.0), "{file}: {key}");
        assert_eq!(ids(&s["desc"]), expected_order(&col, -1.0), "{file}: {key}");
        assert_eq!(s["aria"], "descending");
    }
    // Filters keep exactly the matching rows.
    let all: Vec<&Value> = designs.iter().collect();
    let keep = |pred: &dyn Fn(&Value) -> bool| -> Vec<String> {
        all.iter()
            .filter(|d| pred(d))
            .map(|d| d["id"].as_str().unwrap().to_string())
            .collect()
    };
    let visible = |k: &str| -> Vec<String> {
        let mut v = ids(&r["filters"][k]["visible"]);
        v.sort();
        v
    };
    let sorted = |mut v: Vec<String>| {
        v.sort();
        v
    };
    let level: f64 = r["filters"]["level"]["value"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(visible("level"), sorted(keep(&|d| f(&d["level"]) == level)));
    let modes = r["filters"]["modes"]["value"].as_str().unwrap().to_string();
    assert_eq!(
        visible("modes"),
        sorted(keep(&|d| d["modes"] == modes.as_str()))
    );
    let limit = f(&r["filters"]["objective"]["value"]);
    assert_eq!(
        visible("objective"),
        sorted(keep(&|d| f(&d["objective"]) <= limit))
    );
    assert_eq!(
        r["filters"]["objective"]["shown"].as_str().unwrap(),
        visible("objective").len().to_string()
    );
    if r["filters"].get("score").is_some() {
        assert_eq!(
            visible("score"),
            sorted(keep(&|d| d["robustness"]["score"]
                .as_f64()
                .is_some_and(|s| s >= 1.5)))
        );
    }
    // Clicking a row shows that design, named by its id.
    let clicked = r["select"]["clicked"].as_str().unwrap();
    assert_eq!(r["select"]["detail"]["selected"], clicked);
    assert!(
        r["select"]["detail"]["title"]
            .as_str()
            .unwrap()
            .starts_with(clicked)
    );
}

/// The page opens without an error or a request, and the selected design's 3D view, slider,
/// drag, play button and crease pattern work.
fn assert_view_works(r: &Value, data: &Value) {
    let file = &r["file"];
    assert_eq!(r["errors"], json!([]), "{file}: console errors");
    assert_eq!(
        r["requests"],
        json!([]),
        "{file}: the page loaded something"
    );
    let designs = data["designs"].as_array().unwrap();
    let init = &r["initial"];
    assert_eq!(init["detail"]["webgl"], true, "{file}");
    // The 3D view is drawn: a good share of the canvas is not background.
    let px = &r["pixels_initial"];
    assert!(
        f(&px["ink"]) > 0.01 * f(&px["total"]),
        "{file}: 3D canvas nearly empty: {px}"
    );
    // The slider: Home is the flat state (t = 0), End the last frame (t = t_max); the
    // picture changes between them.
    let sel = init["detail"]["selected"].as_str().unwrap();
    let d = designs.iter().find(|d| d["id"] == sel).unwrap();
    let ts = d["geometry"]["t"].as_array().unwrap();
    let home = &r["slider_home"]["detail"];
    assert_eq!(home["frame"], 0, "{file}");
    assert!(home["t"].as_str().unwrap().starts_with("t = 0.0000 "));
    let end = &r["slider_end"]["detail"];
    assert_eq!(f(&end["frame"]) as usize, ts.len() - 1, "{file}");
    assert!(
        end["t"]
            .as_str()
            .unwrap()
            .starts_with(&format!("t = {:.4} ", f(ts.last().unwrap()))),
        "{}",
        end["t"]
    );
    assert!(
        f(&r["slider_end"]["changed_vs_home"]) >= 10.0,
        "{file}: moving the slider did not change the picture"
    );
    assert!(f(&r["drag"]["changed_vs_end"]) >= 10.0, "{file}: drag");
    assert_ne!(
        r["play"]["frame_before"], r["play"]["frame_after"],
        "{file}"
    );
    assert_eq!(r["play"]["button"], "play");
    // The crease pattern of the selected design: one line per edge, its assignment, the
    // vertices named v1 … vn, the gripping vertex circled.
    let cp = &init["detail"]["cp"];
    let assign: Vec<String> = d["geometry"]["assign"]
        .as_str()
        .unwrap()
        .chars()
        .map(String::from)
        .collect();
    assert_eq!(ids(&cp["lines"]), assign);
    let n = d["geometry"]["flat"].as_array().unwrap().len();
    assert_eq!(
        ids(&cp["labels"]),
        (1..=n).map(|k| format!("v{k}")).collect::<Vec<_>>()
    );
    assert_eq!(cp["circles"], 1);
}

#[test]
fn report_works_in_headless_chromium_moved_alone() {
    let dir = tempfile::tempdir().unwrap();
    // The sample report (robustness columns, files written), then moved alone.
    let (sample, _) = build_report(&dir.path().join("out"), true);
    let sample = alone(&sample, dir.path(), "sample");
    // A real search's report (gripper, N_max 2, --no-export: fast), moved alone.
    let run = dir.path().join("run");
    let o = foldsynth(&[
        "synthesize",
        "grammar/gripper.toml",
        "--n-max",
        "2",
        "--no-export",
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let real = alone(&run.join("report.html"), dir.path(), "real");
    std::fs::remove_dir_all(dir.path().join("out")).unwrap();
    std::fs::remove_dir_all(&run).unwrap();
    // A deliberately broken page: the driver must see its errors.
    let broken = dir.path().join("broken.html");
    std::fs::write(
        &broken,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>b</title></head><body><script>console.error('boom'); undefined_fn();</script></body></html>",
    )
    .unwrap();

    // A large page: 100,000 designs (issue 34's size), the 3 first carried in full (as
    // `--report-designs 3` makes it), the others rows only, as the search holds them.
    let (_, mut input) = build_report(&dir.path().join("large-src"), false);
    let base = std::mem::take(&mut input.designs);
    input.designs = (0..LARGE)
        .map(|i| {
            let mut d = base[i % base.len()].clone();
            d.id = format!("{}-{i:06}", d.id);
            d.in_full = i < 3;
            if !d.in_full {
                d.pattern.vertices.clear();
                d.pattern.edges.clear();
                d.pattern.faces.clear();
                d.pattern.frames.clear();
                d.facts.clear();
            }
            d
        })
        .collect();
    let large = dir.path().join("large");
    std::fs::create_dir_all(&large).unwrap();
    let large = write_report(&large, &input).unwrap();
    drop(input);
    // Issue 34: a page of 100,000 designs stays under 50 MB.
    let bytes = std::fs::metadata(&large).unwrap().len();
    assert!(bytes <= 50_000_000, "{bytes} bytes");
    println!("the page of {LARGE} designs: {bytes} bytes");

    let v = drive(&[&sample, &real, &large], &broken);
    if v.is_null() {
        return;
    }
    let bad = ids(&v["broken"]["errors"]).join("\n");
    assert!(
        bad.contains("boom") && bad.contains("undefined_fn"),
        "{bad}"
    );
    let reports = v["reports"].as_array().unwrap();
    assert_eq!(reports.len(), 3);
    let data = embedded(&std::fs::read_to_string(&large).unwrap());
    assert_eq!(data["designs"].as_array().unwrap().len(), 3);
    assert_eq!(data["rows"].as_array().unwrap().len(), LARGE);
    assert_paged_table_works(&reports[2], &data);
    println!(
        "the page of {LARGE} designs opened in {} ms",
        reports[2]["open_ms"]
    );
    for (r, page) in reports.iter().zip([&sample, &real]) {
        let data = embedded(&std::fs::read_to_string(page).unwrap());
        assert_page_works(r, &data);
    }
    // The sample has robustness: shown most robust first, margins as columns.
    let s = &reports[0];
    assert_eq!(ids(&s["initial"]["table"]["order"])[0], "d-grip");
    let heads: Vec<String> = s["initial"]["table"]["headers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|h| h[0].as_str().unwrap().to_string())
        .collect();
    assert_eq!(
        heads,
        [
            "id",
            "sequence",
            "level",
            "candidate",
            "gripping",
            "modes",
            "objective",
            "score",
            "rigid_margin",
            "self_clearance",
            "obstacle_clearance"
        ]
    );
    let facts = &s["initial"]["detail"]["facts"];
    let text = facts.to_string();
    assert!(text.contains("self clearance") && text.contains("facets f1–f3"));
    // Sorting reorders: by objective ascending is not the search's order.
    assert_ne!(
        ids(&s["sorts"]["objective"]["asc"]),
        ["d-arm", "d-grip", "d-deg4"]
    );
    // The real report: the search's order, the first design selected, t up to π/2.
    let r = &reports[1];
    let order = ids(&r["initial"]["table"]["order"]);
    let data = embedded(&std::fs::read_to_string(&real).unwrap());
    let want: Vec<String> = data["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["id"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(order, want);
    assert_eq!(r["initial"]["detail"]["selected"], want[0].as_str());
    assert!(
        r["slider_end"]["detail"]["t"]
            .as_str()
            .unwrap()
            .starts_with("t = 1.5708 (90.0°)")
    );
}

/// Issue 34's measurement on a real run: the page named by `FOLDSYNTH_REPORT` (a run of
/// 100,000 designs takes hours of CPU, so CI cannot make one; docs/guided-search.md has the
/// run and the command) is at most 50 MB and in Chromium works as every page does, with its
/// table paged. Prints its size and the time it took to open.
#[test]
#[ignore = "needs FOLDSYNTH_REPORT=path/to/report.html of a large run (see docs/guided-search.md)"]
fn a_large_run_report_works_in_headless_chromium() {
    let page = PathBuf::from(
        std::env::var_os("FOLDSYNTH_REPORT").expect("FOLDSYNTH_REPORT names the report.html"),
    );
    let bytes = std::fs::metadata(&page)
        .unwrap_or_else(|e| panic!("{}: {e}", page.display()))
        .len();
    assert!(bytes <= 50_000_000, "{bytes} bytes");
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.html");
    std::fs::write(
        &broken,
        "<!DOCTYPE html><title>b</title><script>console.error('boom')</script>",
    )
    .unwrap();
    let v = drive(&[&page], &broken);
    assert!(
        !v.is_null(),
        "this test was asked for: it needs the browser"
    );
    let r = &v["reports"][0];
    let data = embedded(&std::fs::read_to_string(&page).unwrap());
    assert_view_works(r, &data);
    assert_paged_table_works(r, &data);
    println!(
        "{}: {bytes} bytes, {} designs ({} in full), opened in {} ms",
        page.display(),
        data["rows"].as_array().unwrap().len(),
        data["designs"].as_array().unwrap().len(),
        r["open_ms"]
    );
}

/// A report of two designs in a scene with every shape: the scene (and its mesh) is
/// embedded once for both, every obstacle, box, copy and goal kind is there, and in the
/// browser the 3D view holds an object for each.
#[test]
fn report_draws_every_shape_of_the_scene_once() {
    let dir = tempfile::tempdir().unwrap();
    let (p, meta) = samples::every_shape(dir.path()).unwrap();
    let design = |id: &str| ReportDesign {
        id: id.into(),
        level: 1,
        candidate: None,
        pattern: p.clone(),
        geometry: None,
        meta: meta.clone(),
        robustness: None,
        area: Some(2.5),
        facts: Vec::new(),
        design_file: None,
        files: None,
        verify: None,
        thick: None,
        in_full: true,
    };
    let input = ReportInput {
        summary: ReportSummary {
            title: "every shape".into(),
            task: "every shape".into(),
            counts: Vec::new(),
            timings: Vec::new(),
            notes: Vec::new(),
        },
        task: Vec::new(),
        tree: Vec::new(),
        distribution: None,
        designs: vec![design("a"), design("b")],
    };
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let report = write_report(&out, &input).unwrap();
    let html = std::fs::read_to_string(&report).unwrap();
    let data = embedded(&html);
    let scenes = data["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 1, "one scene for both designs");
    for d in data["designs"].as_array().unwrap() {
        assert_eq!(d["scene"], 0);
        let kinds: Vec<&str> = d["goals"]
            .as_array()
            .unwrap()
            .iter()
            .map(|g| g["kind"].as_str().unwrap())
            .collect();
        assert_eq!(kinds, ["line", "plane", "surface"]);
    }
    let s = &scenes[0];
    let shapes: Vec<&str> = s["obstacles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["shape"].as_str().unwrap())
        .collect();
    assert_eq!(shapes, ["cylinder", "sphere", "box", "halfspace", "mesh"]);
    // The octahedron's 8 triangles, its 6 vertices moved by scale 0.3 and the translation.
    let mesh = &s["obstacles"][4]["mesh"];
    assert_eq!(mesh["triangles"].as_array().unwrap().len(), 24);
    let v = mesh["vertices"].as_array().unwrap();
    assert_eq!(v.len(), 18);
    assert_eq!((f(&v[0]), f(&v[1]), f(&v[2])), (1.8 + 0.3, 1.2, 0.6));
    assert_eq!(s["surfaces"][0]["triangles"].as_array().unwrap().len(), 24);
    assert_eq!(s["copies"]["n"], 3);
    assert_eq!(s["containment"][0]["corners"].as_array().unwrap().len(), 8);
    // The mesh is embedded once (as the obstacle and the surface), not per design.
    assert_eq!(html.matches("\"triangles\":[").count(), 2);
    // An area task's designs get the area column (the other report has none).
    assert!(html.contains("<th data-key=\"area\""));

    // A missing mesh file: no report, an error naming it.
    std::fs::remove_file(dir.path().join("octahedron.obj")).unwrap();
    let e = write_report(&out, &input).unwrap_err().to_string();
    assert!(e.contains("octahedron.obj"), "{e}");

    let broken = dir.path().join("broken.html");
    std::fs::write(&broken, "<!DOCTYPE html><html><body></body></html>").unwrap();
    let v = drive(&[&report], &broken);
    if v.is_null() {
        return;
    }
    let r = &v["reports"][0];
    assert!(
        r["errors"].as_array().unwrap().is_empty(),
        "{}",
        r["errors"]
    );
    let objects = ids(&r["initial"]["detail"]["objects"]);
    for name in [
        "arm:1",
        "arm:2",
        "arm:3",
        "obstacle:cylinder:post",
        "obstacle:sphere:ball",
        "obstacle:box:crate",
        "obstacle:halfspace:floor",
        "obstacle:mesh:part",
        "containment:workspace",
        "goal:line:0",
        "goal:plane:1",
        "goal:surface:2",
    ] {
        assert!(
            objects.iter().any(|o| o == name),
            "{name} not in {objects:?}"
        );
    }
}
