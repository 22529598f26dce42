//! `OUT/report.html`: one self-contained, interactive page that works when moved alone.
//!
//! Everything is inline: the CSS, the search tree and distribution plots (SVG), the
//! design table (rendered here, sorted and filtered in the page), the geometry of every
//! design as JSON (flat and folded vertex positions per frame, triangles, edges, crease
//! assignments; rounded to 1e-4 of G0's crease), three.js (vendored from npm as
//! `vendor/three/three.bundle.min.js`, see its README) and the page's own script
//! (`app.js`). No fonts, no images, no network. The only relative links are to the files
//! written beside the report (design JSON, FOLD, SVG, OBJ, STL, pictures); the writer
//! refuses links to files that do not exist, and the page does not need them.
//!
//! The page: the task (G0, targets, obstacles, N_max, bounds, search settings), the
//! counts and timings, a table of the feasible designs (id, rule sequence, level,
//! gripping candidate and vertex, modes, Ω*, and the robustness margins when the records
//! carry them) that sorts by any column and filters by level, modes, objective and
//! margins, and for the selected design a three.js view of its folding motion (slider for
//! t, play/pause, target points, trajectory, goal lines, planes and surfaces, obstacles of
//! every shape, containment boxes, every copy of the arm, the gripping vertex and its
//! path; rotate with the mouse) beside its
//! crease pattern, with its figures and files below.

mod scene_data;
mod thick_view;

pub use thick_view::thick_json;

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use super::fold::assignments;
use super::plots::{DistributionPlot, TreeNode, distribution_svg, search_tree_svg, xml_escape};
use super::verify::VerifyReport;
use super::{DesignMeta, ExportError, Files, Result, validate_meta, validate_pattern};
use crate::check::triangulate::triangulate_faces;
use crate::pattern::Pattern;

/// three.js (r187, MIT; see `vendor/three/`): the parts the page uses, one classic script
/// defining the global `FoldsynthThree`.
pub const THREE_JS: &str = include_str!("../../../vendor/three/three.bundle.min.js");
/// The page's script: table sorting and filtering, the 3D view, the crease pattern.
const APP_JS: &str = include_str!("app.js");
/// The page's style sheet.
const CSS: &str = include_str!("page.css");

/// One row of the counts table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CountRow {
    /// What is counted, e.g. `"alternatives evaluated"`.
    pub label: String,
    /// Our count.
    pub value: u64,
    /// The thesis's figure for comparison, if any.
    #[serde(default)]
    pub thesis: Option<u64>,
}

/// One row of the timings table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimingRow {
    /// Stage name, e.g. `"optimize"`.
    pub stage: String,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// A labelled fact, shown as one table row (`key`: `value`, both plain text).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fact {
    /// What, e.g. `"N_max"`.
    pub key: String,
    /// Its value as text, e.g. `"3"`.
    pub value: String,
}

impl Fact {
    /// A fact from anything printable.
    pub fn new(key: impl Into<String>, value: impl std::fmt::Display) -> Fact {
        Fact {
            key: key.into(),
            value: value.to_string(),
        }
    }
}

/// The summary at the top of the report.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReportSummary {
    /// Page title.
    pub title: String,
    /// Task name.
    pub task: String,
    /// Counts (alternatives, meeting the target, free of self-intersection, …).
    pub counts: Vec<CountRow>,
    /// Time per stage.
    pub timings: Vec<TimingRow>,
    /// Free-form remarks (settings, seeds, versions).
    pub notes: Vec<String>,
}

/// One feasible design: its geometry (always) and the files written for it (with export).
#[derive(Clone, Debug)]
pub struct ReportDesign {
    /// The design id the files are named after (e.g. `g01-c2-d`).
    pub id: String,
    /// Number of rule applications of its graph.
    pub level: usize,
    /// Gripping candidate (1, 2, 3), if the task has candidates.
    pub candidate: Option<usize>,
    /// The crease pattern and its folded frames: the 3D view and the crease pattern are
    /// drawn from this (its frames may be dropped when `geometry` is given).
    pub pattern: Pattern,
    /// The page's geometry of the design as [`geometry_text`] makes it, when the caller
    /// made it beforehand and dropped the frames from `pattern` (a search holds every
    /// design until the report is written: the text is a fifth of the frames' memory);
    /// `None`: made from `pattern`.
    pub geometry: Option<String>,
    /// Rule sequence, modes, gripping vertex, objective, targets, trajectory, obstacle,
    /// second arm.
    pub meta: DesignMeta,
    /// The robustness record (the shared contract: `score`, and margins `rigid_margin`,
    /// `self_clearance`, `arm_clearance`, `obstacle_clearance`, `min_feature`, each
    /// `{value, setting, t, where}` or null); `None` when not computed.
    pub robustness: Option<Value>,
    /// The area of an area task (`[objective.area]`: flat, or flat over the folded
    /// footprint), as the independent check measured it: a column of the table.
    pub area: Option<f64>,
    /// Further figures shown below the views (verification, variables, …).
    pub facts: Vec<Fact>,
    /// The design JSON (`designs/<id>.json`), when written.
    pub design_file: Option<PathBuf>,
    /// The exported files (FOLD, SVG, OBJ, STL, pictures, GIF), when written.
    pub files: Option<Files>,
    /// The result of verifying its FOLD file, when exported.
    pub verify: Option<VerifyReport>,
    /// Its thick panels and the bill of the build ([`thick_json`]), for a task with
    /// `[fabrication]`: drawn in the 3D view, the bill as a table.
    pub thick: Option<Value>,
    /// Shown in full: its card, 3D view and crease pattern are in the page. `false`: a row
    /// of the table only (a large run's page carries the most robust designs in full and
    /// every design as a row, so it stays one file a browser opens in seconds); `pattern`,
    /// `geometry`, `facts` and `files` are then not read, and selecting the row says how
    /// to draw the design.
    pub in_full: bool,
}

/// Everything the report shows.
#[derive(Clone, Debug, Default)]
pub struct ReportInput {
    /// Counts and timings.
    pub summary: ReportSummary,
    /// The task: G0, targets, obstacles, N_max, bounds, search settings.
    pub task: Vec<Fact>,
    /// The search tree (Fig. 48); omitted when empty.
    pub tree: Vec<TreeNode>,
    /// The distribution plot (Fig. 51).
    pub distribution: Option<DistributionPlot>,
    /// The feasible designs, in the search's order.
    pub designs: Vec<ReportDesign>,
}

/// Rows of the design table the page draws at a time.
pub const PAGE_ROWS: usize = 100;

/// The robustness margins of the shared contract, in column order, with their labels.
pub const MARGINS: [(&str, &str); 5] = [
    ("rigid_margin", "rigid margin"),
    ("self_clearance", "self clearance"),
    ("arm_clearance", "arm clearance"),
    ("obstacle_clearance", "obstacle clearance"),
    ("min_feature", "min feature"),
];

/// Round to 1e-4: the page draws with these, a ten-thousandth of G0's crease is far below a
/// pixel, and it keeps the embedded geometry small.
fn r4(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

/// Path of `p` relative to `out_dir`, percent-encoded for a URL; `p` must exist.
fn rel(out_dir: &Path, p: &Path) -> Result<String> {
    if !p.is_file() {
        return Err(ExportError::invalid(
            "report link",
            format!("{} does not exist", p.display()),
        ));
    }
    let r = p.strip_prefix(out_dir).map_err(|_| {
        ExportError::invalid(
            "report link",
            format!(
                "{} is not inside the report directory {}",
                p.display(),
                out_dir.display()
            ),
        )
    })?;
    Ok(r.components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .chars()
                .map(|c| match c {
                    'a'..='z' | 'A'..='Z' | '0'..='9' | '-' | '_' | '.' | '~' => c.to_string(),
                    _ => c.to_string().bytes().map(|b| format!("%{b:02X}")).collect(),
                })
                .collect::<String>()
        })
        .collect::<Vec<_>>()
        .join("/"))
}

/// The geometry the page draws: flat layout, triangles (per facet, by ear clipping),
/// edges with their assignment (`B`, `M`, `V`, `F`), driven creases, and per frame its t and
/// the 3D position of every vertex (flattened x, y, z, …).
pub fn geometry_json(p: &Pattern) -> Result<Value> {
    validate_pattern(p)?;
    let tris = triangulate_faces(&p.vertices, &p.faces)
        .map_err(|e| ExportError::invalid("pattern.faces", e.to_string()))?;
    let tris: Vec<usize> = tris.into_iter().flatten().flatten().collect();
    let assign: String = assignments(p).iter().map(|a| a.as_str()).collect();
    let driven = p.driven_edges();
    let frames: Vec<Vec<f64>> = p
        .frames
        .iter()
        .map(|f| f.coords.iter().flatten().map(|&x| r4(x)).collect())
        .collect();
    Ok(json!({
        "flat": p.vertices.iter().map(|v| [r4(v[0]), r4(v[1])]).collect::<Vec<_>>(),
        "edges": p.edges.iter().map(|e| e.v).collect::<Vec<_>>(),
        "assign": assign,
        "driven": driven,
        "tris": tris,
        "t": p.frames.iter().map(|f| r4(f.t)).collect::<Vec<_>>(),
        "frames": frames,
    }))
}

/// [`geometry_json`] as the text the page embeds.
pub fn geometry_text(p: &Pattern) -> Result<String> {
    Ok(script_json(&geometry_json(p)?))
}

/// One margin `{value, setting, t, where}` of a robustness record, if present.
fn margin<'a>(rob: Option<&'a Value>, key: &str) -> Option<&'a Value> {
    rob?.get(key)
        .filter(|m| m.get("value").is_some_and(Value::is_f64))
}

/// A number for a table cell: 4 significant digits.
fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&x.abs()) {
        let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.3e}")
    }
}

/// The modes as shown: `up, down`, or `–` for a design without internal vertices.
fn modes_text(m: &DesignMeta) -> String {
    if m.modes.is_empty() {
        return "–".into();
    }
    m.modes
        .iter()
        .map(|x| x.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The per-design data the page's script reads, but for its geometry ([`design_text`]).
fn design_json(out_dir: &Path, d: &ReportDesign) -> Result<Value> {
    let m = &d.meta;
    let mut files: Vec<(String, String)> = Vec::new();
    if let Some(j) = &d.design_file {
        files.push(("design JSON".into(), rel(out_dir, j)?));
    }
    if let Some(f) = &d.files {
        for (name, p) in [
            ("FOLD", &f.fold),
            ("crease pattern SVG", &f.svg),
            ("OBJ", &f.obj),
            ("STL", &f.stl),
        ] {
            // An empty path: not written (a design outside `--export N` has its FOLD file
            // only).
            if !p.as_os_str().is_empty() {
                files.push((name.into(), rel(out_dir, p)?));
            }
        }
        if let Some(g) = &f.gif {
            files.push(("GIF".into(), rel(out_dir, g)?));
        }
        for p in &f.pngs {
            let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned());
            files.push((
                format!("PNG {}", stem.unwrap_or_default()),
                rel(out_dir, p)?,
            ));
        }
        for p in &f.folded_svgs {
            let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned());
            files.push((
                format!("state SVG {}", stem.unwrap_or_default()),
                rel(out_dir, p)?,
            ));
        }
    }
    let mut facts: Vec<(String, String)> = vec![
        ("task".into(), m.task.clone()),
        ("rule sequence".into(), m.rule_sequence.clone()),
        ("modes".into(), modes_text(m)),
        (
            "gripping vertex".into(),
            m.gripping_vertex.map_or("–".into(), |g| format!("v{g}")),
        ),
        (
            "objective Ω*".into(),
            m.objective.map_or("–".into(), |o| format!("{o:.3e}")),
        ),
    ];
    facts.extend(d.facts.iter().map(|f| (f.key.clone(), f.value.clone())));
    if let Some(v) = &d.verify {
        let iso = v
            .frames
            .iter()
            .map(|f| f.max_isometry_error)
            .fold(0.0, f64::max);
        facts.push((
            "FOLD file verified".into(),
            format!(
                "{} ({} frames, max isometry error {iso:.1e})",
                if v.ok { "passed" } else { "FAILED" },
                v.frames.len()
            ),
        ));
    }
    Ok(json!({
        "id": d.id,
        "sequence": m.rule_sequence,
        "level": d.level,
        "candidate": d.candidate,
        "gripping": m.gripping_vertex,
        "modes": modes_text(m),
        "objective": m.objective,
        "robustness": d.robustness,
        "facts": facts,
        "files": files,
        "targets": m.targets.iter().map(|t| [r4(t.p[0]), r4(t.p[1]), r4(t.p[2])]).collect::<Vec<_>>(),
        "trajectory": m.trajectory.iter().map(|q| [r4(q[0]), r4(q[1]), r4(q[2])]).collect::<Vec<_>>(),
        "goals": scene_data::goals_json(m),
        "thick": d.thick,
    }))
}

/// A column of the design table: header, how to filter it, and the cell of each design
/// (text, the value sorted by, an optional tooltip).
struct Column {
    key: &'static str,
    label: String,
    filter: Filter,
    numeric: bool,
    /// How the page writes a value as text: `text` as it is, `int`, `vertex` (`v7`),
    /// `exp2` (2 decimals in exponent form, as Ω*), `num` (4 significant digits, as
    /// [`num`]); null is `–` in every format. The cells made here use the same rules.
    format: &'static str,
}

#[derive(Clone, Copy, PartialEq)]
enum Filter {
    /// Substring.
    Text,
    /// One of the distinct values.
    Choice,
    /// Value ≤ the input.
    AtMost,
    /// Value ≥ the input.
    AtLeast,
}

/// One cell: shown text (the filters' choices), and the value it sorts by (number or
/// text), which is what the page's data carries.
struct Cell {
    text: String,
    sort: Value,
}

fn cell(text: impl Into<String>, sort: Value) -> Cell {
    Cell {
        text: text.into(),
        sort,
    }
}

/// Columns of the table: the margins only where some design has them.
fn columns(designs: &[ReportDesign]) -> Vec<Column> {
    let col = |key, label: &str, filter, numeric, format| Column {
        key,
        label: label.to_string(),
        filter,
        numeric,
        format,
    };
    let mut cols = vec![
        col("id", "id", Filter::Text, false, "text"),
        col("sequence", "rule sequence", Filter::Text, false, "text"),
        col("level", "level", Filter::Choice, true, "int"),
        col("candidate", "cand.", Filter::Choice, true, "int"),
        col(
            "gripping",
            "gripping vertex",
            Filter::Choice,
            false,
            "vertex",
        ),
        col("modes", "modes", Filter::Choice, false, "text"),
        col("objective", "Ω*", Filter::AtMost, true, "exp2"),
    ];
    if designs.iter().any(|d| d.area.is_some()) {
        cols.push(col("area", "area", Filter::AtLeast, true, "num"));
    }
    let robust = |key: &str| {
        designs
            .iter()
            .any(|d| margin(d.robustness.as_ref(), key).is_some())
    };
    if designs.iter().any(|d| {
        d.robustness
            .as_ref()
            .and_then(|r| r.get("score"))
            .is_some_and(Value::is_f64)
    }) {
        cols.push(col(
            "score",
            "robustness score",
            Filter::AtLeast,
            true,
            "num",
        ));
    }
    for (key, label) in MARGINS {
        if robust(key) {
            cols.push(col(key, label, Filter::AtLeast, true, "num"));
        }
    }
    cols
}

fn cells(d: &ReportDesign, cols: &[Column]) -> Vec<Cell> {
    let m = &d.meta;
    cols.iter()
        .map(|c| match c.key {
            "id" => cell(&d.id, json!(d.id)),
            "sequence" => cell(&m.rule_sequence, json!(m.rule_sequence)),
            "level" => cell(d.level.to_string(), json!(d.level)),
            "candidate" => match d.candidate {
                Some(k) => cell(k.to_string(), json!(k)),
                None => cell("–", Value::Null),
            },
            "gripping" => match m.gripping_vertex {
                Some(g) => cell(format!("v{g}"), json!(g)),
                None => cell("–", Value::Null),
            },
            "modes" => cell(modes_text(m), json!(modes_text(m))),
            "objective" => match m.objective {
                Some(o) => cell(format!("{o:.2e}"), json!(o)),
                None => cell("–", Value::Null),
            },
            "area" => match d.area {
                Some(a) => cell(num(a), json!(a)),
                None => cell("–", Value::Null),
            },
            "score" => match d
                .robustness
                .as_ref()
                .and_then(|r| r.get("score"))
                .and_then(Value::as_f64)
            {
                Some(s) => cell(num(s), json!(s)),
                None => cell("–", Value::Null),
            },
            key => match margin(d.robustness.as_ref(), key).and_then(|m| m["value"].as_f64()) {
                Some(v) => cell(num(v), json!(v)),
                None => cell("–", Value::Null),
            },
        })
        .collect()
}

/// The design table's head: the header row (each column's key, whether it is numeric and
/// how the page formats its values) and the filter row. The page draws the rows, a page of
/// [`PAGE_ROWS`] at a time, from the values in the data (`rows`).
fn design_table(designs: &[ReportDesign]) -> String {
    let cols = columns(designs);
    let rows: Vec<Vec<Cell>> = designs.iter().map(|d| cells(d, &cols)).collect();
    let mut s = String::from("<table id=\"design-table\"><thead><tr>");
    for c in &cols {
        let _ = write!(
            s,
            "<th data-key=\"{}\" data-numeric=\"{}\" data-format=\"{}\" aria-sort=\"none\" tabindex=\"0\" title=\"sort by {}\">{}</th>",
            c.key,
            c.numeric,
            c.format,
            xml_escape(&c.label),
            xml_escape(&c.label)
        );
    }
    s += "</tr><tr class=\"filters\">";
    for (k, c) in cols.iter().enumerate() {
        let label = xml_escape(&format!("filter {}", c.label));
        match c.filter {
            Filter::Text => {
                let _ = write!(
                    s,
                    "<td><input type=\"search\" data-key=\"{}\" data-filter=\"text\" placeholder=\"contains\" aria-label=\"{label}\"></td>",
                    c.key
                );
            }
            Filter::Choice => {
                let values: BTreeSet<String> = rows.iter().map(|r| r[k].text.clone()).collect();
                let mut values: Vec<(Value, String)> = values
                    .into_iter()
                    .map(|text| {
                        let sort = rows
                            .iter()
                            .find(|r| r[k].text == text)
                            .map_or(Value::Null, |r| r[k].sort.clone());
                        (sort, text)
                    })
                    .collect();
                values.sort_by(|a, b| match (a.0.as_f64(), b.0.as_f64()) {
                    (Some(x), Some(y)) => x.total_cmp(&y),
                    _ => a.1.cmp(&b.1),
                });
                let _ = write!(
                    s,
                    "<td><select data-key=\"{}\" data-filter=\"choice\" aria-label=\"{label}\"><option value=\"\">all</option>",
                    c.key
                );
                for (_, text) in values {
                    let t = xml_escape(&text);
                    let _ = write!(s, "<option value=\"{t}\">{t}</option>");
                }
                s += "</select></td>";
            }
            Filter::AtMost | Filter::AtLeast => {
                let (kind, ph) = if c.filter == Filter::AtMost {
                    ("max", "≤")
                } else {
                    ("min", "≥")
                };
                let _ = write!(
                    s,
                    "<td><input type=\"text\" inputmode=\"decimal\" data-key=\"{}\" data-filter=\"{kind}\" placeholder=\"{ph}\" aria-label=\"{label} {ph}\"></td>",
                    c.key
                );
            }
        }
    }
    s += "</tr></thead><tbody></tbody></table>";
    s
}

/// JSON text safe inside `<script type="application/json">`: `<` written as `\u003c`, so
/// neither `</script>` nor `<!--` can occur.
fn script_json(v: &Value) -> String {
    v.to_string().replace('<', "\\u003c")
}

/// The report page as HTML text; links are relative to `out_dir`.
pub fn report_html(out_dir: &Path, input: &ReportInput) -> Result<String> {
    let mut page = Vec::new();
    let scenes = designs_scenes(input)?;
    write_html(&mut page, out_dir, input, &scenes, Path::new("report.html"))?;
    // Only `str`s were written.
    Ok(String::from_utf8(page).unwrap_or_default())
}

/// Write the report page to `w` piece by piece: a large run's page is hundreds of MB, and
/// it is never held whole in memory (`scenes`: [`designs_scenes`] of `input`; `path`: what
/// to name in an I/O error).
fn write_html(
    w: &mut impl std::io::Write,
    out_dir: &Path,
    input: &ReportInput,
    (scene_of, scenes): &(Vec<usize>, Vec<Value>),
    path: &Path,
) -> Result<()> {
    let io = |source: std::io::Error| ExportError::Io {
        path: path.to_path_buf(),
        source,
    };
    let sm = &input.summary;
    let title = if sm.title.is_empty() {
        "foldsynth report".to_string()
    } else {
        sm.title.clone()
    };
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{}</title><style>{CSS}</style></head><body>\n<header><h1>{}</h1><div>task: {}</div></header>\n<main>\n",
        xml_escape(&title),
        xml_escape(&title),
        xml_escape(&sm.task)
    );
    if !input.task.is_empty() {
        s += "<section id=\"task\"><h2>Task</h2><table class=\"facts\"><tbody>";
        for f in &input.task {
            let _ = write!(
                s,
                "<tr><th>{}</th><td>{}</td></tr>",
                xml_escape(&f.key),
                xml_escape(&f.value)
            );
        }
        s += "</tbody></table></section>\n";
    }
    s += &summary_section(sm);
    w.write_all(s.as_bytes()).map_err(io)?;
    w.write_all(designs_section(&input.designs).as_bytes())
        .map_err(io)?;
    let mut s = String::new();
    if !input.tree.is_empty() {
        let _ = writeln!(
            s,
            "<section id=\"tree\"><h2>Search tree</h2><div class=\"plot\">{}</div></section>",
            search_tree_svg(&input.tree)?
        );
    }
    if let Some(d) = &input.distribution {
        let _ = writeln!(
            s,
            "<section id=\"distribution\"><h2>Designs over rule applications</h2><div class=\"plot\">{}</div></section>",
            distribution_svg(d)?
        );
    }
    // `{"designs": […], "scenes": […]}`, one design at a time.
    s += "</main>\n<script type=\"application/json\" id=\"foldsynth-data\">{\"designs\":[";
    w.write_all(s.as_bytes()).map_err(io)?;
    let in_full = input.designs.iter().filter(|d| d.in_full);
    for (i, (d, &scene)) in in_full.zip(scene_of).enumerate() {
        if i > 0 {
            w.write_all(b",").map_err(io)?;
        }
        w.write_all(design_text(out_dir, d, scene)?.as_bytes())
            .map_err(io)?;
    }
    // The table's rows: per design the value of each column (the page formats the text).
    w.write_all(b"],\"rows\":[").map_err(io)?;
    let cols = columns(&input.designs);
    for (i, d) in input.designs.iter().enumerate() {
        if i > 0 {
            w.write_all(b",").map_err(io)?;
        }
        let row: Vec<Value> = cells(d, &cols).into_iter().map(|c| c.sort).collect();
        w.write_all(script_json(&Value::Array(row)).as_bytes())
            .map_err(io)?;
    }
    write!(
        w,
        "],\"page_size\":{PAGE_ROWS},\"scenes\":{}}}</script>\n<script>{THREE_JS}</script>\n<script>{APP_JS}</script>\n</body></html>\n",
        script_json(&json!(scenes))
    )
    .and_then(|()| w.flush())
    .map_err(io)
}

/// Every design's id unique and the metadata of those in full valid; the distinct scenes
/// of those (usually one: a task's), each once with its meshes, and the index of each one's
/// own (in the order of the designs in full).
fn designs_scenes(input: &ReportInput) -> Result<(Vec<usize>, Vec<Value>)> {
    let mut ids = BTreeSet::new();
    let mut seen: Vec<&DesignMeta> = Vec::new();
    let mut scenes = Vec::new();
    let mut index = Vec::with_capacity(input.designs.len());
    for (i, d) in input.designs.iter().enumerate() {
        if !ids.insert(d.id.as_str()) {
            return Err(ExportError::invalid(
                format!("designs[{i}].id"),
                format!("{:?} appears twice; design ids must be unique", d.id),
            ));
        }
        if !d.in_full {
            continue;
        }
        let invalid =
            |e: ExportError| ExportError::invalid(format!("design {}", d.id), e.to_string());
        validate_meta(&d.meta, &d.pattern).map_err(invalid)?;
        let m = &d.meta;
        let same = |o: &&DesignMeta| o.scene == m.scene && o.surfaces == m.surfaces;
        let k = match seen.iter().position(same) {
            Some(k) => k,
            None => {
                scenes.push(scene_data::scene_json(m).map_err(invalid)?);
                seen.push(m);
                seen.len() - 1
            }
        };
        index.push(k);
    }
    Ok((index, scenes))
}

/// One design's data for the page as JSON text: [`design_json`] with `scene` (the index of
/// its scene) and `geometry`. Each design becomes text as soon as it is built, so memory
/// holds one design's JSON tree at a time.
fn design_text(out_dir: &Path, d: &ReportDesign, scene: usize) -> Result<String> {
    let invalid = |e: ExportError| ExportError::invalid(format!("design {}", d.id), e.to_string());
    let mut v = design_json(out_dir, d).map_err(invalid)?;
    v["scene"] = json!(scene);
    let mut text = script_json(&v);
    // `text` is an object: close it with the geometry, made beforehand or now.
    text.pop();
    text.push_str(",\"geometry\":");
    match &d.geometry {
        Some(g) => text.push_str(g),
        None => text.push_str(&geometry_text(&d.pattern).map_err(invalid)?),
    }
    text.push('}');
    Ok(text)
}

/// The summary section: counts against the thesis, stage timings, notes.
fn summary_section(sm: &ReportSummary) -> String {
    let mut s = String::from("<section id=\"summary\"><h2>Summary</h2>");
    if !sm.counts.is_empty() {
        s +=
            "<table><thead><tr><th>count</th><th>foldsynth</th><th>thesis</th></tr></thead><tbody>";
        for c in &sm.counts {
            let _ = write!(
                s,
                "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
                xml_escape(&c.label),
                c.value,
                c.thesis.map_or("–".into(), |t| t.to_string())
            );
        }
        s += "</tbody></table>";
    }
    if !sm.timings.is_empty() {
        s += "<table><thead><tr><th>stage</th><th>seconds</th></tr></thead><tbody>";
        for t in &sm.timings {
            let _ = write!(
                s,
                "<tr><td>{}</td><td class=\"num\">{:.3}</td></tr>",
                xml_escape(&t.stage),
                t.seconds
            );
        }
        s += "</tbody></table>";
    }
    if !sm.notes.is_empty() {
        s += "<ul>";
        for n in &sm.notes {
            let _ = write!(s, "<li>{}</li>", xml_escape(n));
        }
        s += "</ul>";
    }
    s += "</section>\n";
    s
}

/// The designs section: the table of designs beside the card of the one selected.
fn designs_section(designs: &[ReportDesign]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<section id=\"designs\"><h2>Feasible designs (<span id=\"shown\">{n}</span> of {n} shown)</h2>",
        n = designs.len()
    );
    if designs.is_empty() {
        s += "<p>No design passed every check.</p>";
    } else {
        s += "<p class=\"hint\">Click a column to sort (again to reverse); the second row filters. Click a row to view the design.";
        let full = designs.iter().filter(|d| d.in_full).count();
        if full < designs.len() {
            let _ = write!(
                s,
                " This page carries the {full} most robust designs in full (<code>--report-designs</code>) and every design as a row; selecting any other gives the command that draws it."
            );
        }
        s += "</p><div class=\"split\"><div class=\"table-wrap\">";
        s += &design_table(designs);
        let _ = write!(
            s,
            "<div class=\"pager\"><button type=\"button\" id=\"page-prev\">previous</button> <span id=\"page-info\"></span> <button type=\"button\" id=\"page-next\">next</button> <span class=\"hint\">({PAGE_ROWS} rows a page)</span></div>"
        );
        s += "</div><article class=\"card\" id=\"detail\"><h3 id=\"detail-title\"></h3>\
<div class=\"views\"><figure class=\"view3d\"><div id=\"view3d\"><canvas id=\"canvas3d\" width=\"640\" height=\"480\"></canvas><p id=\"no-webgl\" hidden>The 3D view needs WebGL, which this browser does not offer; the crease pattern and figures below still apply.</p></div>\
<div class=\"controls\"><button type=\"button\" id=\"play\">play</button><input type=\"range\" id=\"t-slider\" min=\"0\" max=\"1\" step=\"0.01\" value=\"1\" aria-label=\"driving parameter t\"><output id=\"t-value\"></output></div>\
<figcaption>folding motion: drag to rotate, wheel to zoom, right-drag to pan. Paper: orange front, blue back; red mountain, blue valley, grey flat creases; \
black dot and line: the gripping vertex and its path; green: targets, trajectory, goal lines, planes and surfaces; grey: obstacles; purple: boxes to stay inside; lighter: the other copies of the arm.</figcaption></figure>\
<figure class=\"cp\"><svg id=\"cp\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 100 100\" role=\"img\" aria-label=\"crease pattern\"></svg>\
<figcaption>crease pattern: red mountain, blue valley, grey flat, black boundary, thick: driven crease; vertices v1, v2, … as in the rule sequence; circled: the gripping vertex</figcaption></figure></div>\
<table class=\"facts\" id=\"detail-facts\"><tbody></tbody></table><table class=\"facts\" id=\"detail-bill\" hidden><caption>bill of the build</caption><tbody></tbody></table><p class=\"files\" id=\"detail-files\"></p></article></div>";
    }
    s += "</section>\n";
    s
}

/// Write `out_dir/report.html` and return its path.
pub fn write_report(out_dir: &Path, input: &ReportInput) -> Result<PathBuf> {
    let path = out_dir.join("report.html");
    // Judged before the file is touched: a report that cannot be made leaves an earlier
    // one in place (its design ids, metadata and scenes; a design's link to a missing file
    // is found only while writing, and then no half page is left).
    let scenes = designs_scenes(input)?;
    let file = std::fs::File::create(&path).map_err(|source| ExportError::Io {
        path: path.clone(),
        source,
    })?;
    let mut w = std::io::BufWriter::new(file);
    if let Err(e) = write_html(&mut w, out_dir, input, &scenes, &path) {
        // No half page: a report that cannot be made is not there.
        drop(w);
        let _ = std::fs::remove_file(&path);
        return Err(e);
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inline scripts end at the first `</script` whatever the JavaScript says: none of
    /// the inlined texts may contain it (nor `<!--`, which changes how it is parsed).
    #[test]
    fn inlined_scripts_cannot_close_their_element() {
        for (name, text) in [("three", THREE_JS), ("app", APP_JS)] {
            let lower = text.to_ascii_lowercase();
            assert!(!lower.contains("</script"), "{name}");
            assert!(!lower.contains("<!--"), "{name}");
        }
        let v = json!({"x": "</script><!-- a"});
        let t = script_json(&v);
        assert!(!t.contains('<'));
        assert_eq!(serde_json::from_str::<Value>(&t).unwrap(), v);
    }

    #[test]
    fn numbers_keep_four_significant_digits() {
        assert_eq!(num(0.0123456), "0.01235");
        assert_eq!(num(12.3456), "12.35");
        assert_eq!(num(1234.6), "1235");
        assert_eq!(num(2.5e-6), "2.500e-6");
        assert_eq!(r4(0.123456), 0.1235);
    }
}
