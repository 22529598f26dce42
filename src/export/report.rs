//! `OUT/report.html`: one self-contained page (inline CSS and SVG, no scripts, no fonts,
//! no network) with the run's summary, the plots, and a card per feasible design.
//! Pictures and files are linked by relative paths below the report's directory; the
//! writer refuses links to files that do not exist, so the page never shows a broken
//! image.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::plots::{DistributionPlot, TreeNode, distribution_svg, search_tree_svg, xml_escape};
use super::verify::VerifyReport;
use super::{DesignMeta, ExportError, Files, Result, write_file};

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

/// One feasible design for the report: what [`super::write_all`] wrote for it.
#[derive(Clone, Debug)]
pub struct ReportDesign {
    /// Card title (e.g. the rule sequence and modes).
    pub title: String,
    /// The design's metadata.
    pub meta: DesignMeta,
    /// Its files (must lie below the report's directory).
    pub files: Files,
    /// The result of verifying its FOLD file, if run.
    pub verify: Option<VerifyReport>,
    /// Its robustness margins as (label, text) rows; cards come most robust first.
    pub margins: Vec<(String, String)>,
}

/// Everything the report shows.
#[derive(Clone, Debug, Default)]
pub struct ReportInput {
    /// Counts and timings.
    pub summary: ReportSummary,
    /// The search tree (Fig. 48); omitted when empty.
    pub tree: Vec<TreeNode>,
    /// The distribution plot (Fig. 51).
    pub distribution: Option<DistributionPlot>,
    /// One card per design.
    pub designs: Vec<ReportDesign>,
}

const CSS: &str = "
body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;margin:0;background:#f6f6f4;color:#222}
header{background:#2b3a4a;color:#fff;padding:16px 28px}
header h1{margin:0;font-size:22px}
main{padding:20px 28px}
section{margin-bottom:28px}
h2{font-size:18px;border-bottom:1px solid #ccc;padding-bottom:4px}
table{border-collapse:collapse;background:#fff;margin:8px 24px 8px 0;display:inline-table;vertical-align:top}
th,td{border:1px solid #d4d4d4;padding:4px 10px;text-align:left}
td.num{text-align:right;font-variant-numeric:tabular-nums}
.plot{overflow-x:auto;background:#fff;border:1px solid #ddd;padding:6px;margin:8px 0}
.cards{display:flex;flex-wrap:wrap;gap:18px}
.card{background:#fff;border:1px solid #ccc;border-radius:6px;padding:12px;width:min(100%,1000px)}
.card h3{margin:0 0 8px;font-size:16px}
.card .row{display:flex;flex-wrap:wrap;gap:10px;align-items:flex-start}
figure{margin:0}
figcaption{font-size:12px;color:#555;text-align:center}
.cp svg{width:260px;height:auto;border:1px solid #eee;background:#fff}
.cp line{stroke-opacity:1}
.cp line[data-assignment=\"F\"]{stroke:#808080}
img{border:1px solid #eee;background:#fff}
.ok{color:#17803d;font-weight:bold}.fail{color:#b3261e;font-weight:bold}
.files a{margin-right:10px}
";

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
    let parts: Vec<String> = r
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    // Percent-encode what would break a URL path; keep it readable otherwise.
    Ok(parts
        .iter()
        .map(|s| {
            s.chars()
                .map(|c| match c {
                    'a'..='z' | 'A'..='Z' | '0'..='9' | '-' | '_' | '.' | '~' => c.to_string(),
                    _ => c.to_string().bytes().map(|b| format!("%{b:02X}")).collect(),
                })
                .collect::<String>()
        })
        .collect::<Vec<_>>()
        .join("/"))
}

fn strip_prolog(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    }
}

fn design_card(out_dir: &Path, d: &ReportDesign) -> Result<String> {
    let f = &d.files;
    let mut s = format!(
        "<article class=\"card\"><h3>{}</h3>\n",
        xml_escape(&d.title)
    );
    let m = &d.meta;
    s += "<table><tbody>";
    let mut row = |k: &str, v: String| {
        let _ = write!(s, "<tr><th>{k}</th><td>{}</td></tr>", xml_escape(&v));
    };
    row("task", m.task.clone());
    row("rule sequence", m.rule_sequence.clone());
    row(
        "modes",
        m.modes
            .iter()
            .map(|x| x.as_str())
            .collect::<Vec<_>>()
            .join(", "),
    );
    row(
        "gripping vertex",
        m.gripping_vertex.map_or("–".into(), |g| g.to_string()),
    );
    row(
        "objective Ω*",
        m.objective.map_or("–".into(), |o| format!("{o:.3e}")),
    );
    for (k, v) in &m.extra {
        row(k, v.to_string());
    }
    for (k, v) in &d.margins {
        row(k, v.clone());
    }
    s += "</tbody></table>\n";
    if let Some(v) = &d.verify {
        let iso = v
            .frames
            .iter()
            .map(|f| f.max_isometry_error)
            .fold(0.0, f64::max);
        let ang = v
            .frames
            .iter()
            .filter_map(|f| f.max_fold_angle_error_deg)
            .fold(0.0, f64::max);
        let _ = write!(
            s,
            "<table><tbody><tr><th>verify</th><td class=\"{}\">{}</td></tr><tr><th>frames</th><td class=\"num\">{}</td></tr><tr><th>max isometry error</th><td class=\"num\">{iso:.2e}</td></tr><tr><th>max fold-angle error</th><td class=\"num\">{ang:.2e}°</td></tr></tbody></table>",
            if v.ok { "ok" } else { "fail" },
            if v.ok { "passed" } else { "FAILED" },
            v.frames.len()
        );
    }
    s += "<div class=\"row\">";
    let cp = std::fs::read_to_string(&f.svg).map_err(|source| ExportError::Io {
        path: f.svg.clone(),
        source,
    })?;
    rel(out_dir, &f.svg)?;
    let _ = write!(
        s,
        "<figure class=\"cp\">{}<figcaption>crease pattern: red mountain, blue valley, grey flat, black boundary (the SVG file encodes fold angles as opacity for Origami Simulator; drawn opaque here)</figcaption></figure>",
        strip_prolog(&cp)
    );
    if let Some(g) = &f.gif {
        let _ = write!(
            s,
            "<figure><img src=\"{}\" width=\"320\" alt=\"animation of the folding motion\"><figcaption>motion</figcaption></figure>",
            rel(out_dir, g)?
        );
    }
    s += "</div><div class=\"row\">";
    for p in &f.pngs {
        let name = p
            .file_stem()
            .map(|x| x.to_string_lossy().into_owned())
            .unwrap_or_default();
        let _ = write!(
            s,
            "<figure><img src=\"{}\" width=\"240\" alt=\"folded state {}\"><figcaption>{}</figcaption></figure>",
            rel(out_dir, p)?,
            xml_escape(&name),
            xml_escape(&name)
        );
    }
    s += "</div><p class=\"files\">files: ";
    let mut links: Vec<(&str, &PathBuf)> = vec![
        ("FOLD", &f.fold),
        ("SVG", &f.svg),
        ("OBJ", &f.obj),
        ("STL", &f.stl),
    ];
    if let Some(g) = &f.gif {
        links.push(("GIF", g));
    }
    for (name, p) in links {
        let _ = write!(s, "<a href=\"{}\">{name}</a>", rel(out_dir, p)?);
    }
    for (k, p) in f.folded_svgs.iter().enumerate() {
        let _ = write!(
            s,
            "<a href=\"{}\">state SVG {}</a>",
            rel(out_dir, p)?,
            k + 1
        );
    }
    s += "</p></article>\n";
    Ok(s)
}

/// The report page as HTML text; links are relative to `out_dir`.
pub fn report_html(out_dir: &Path, input: &ReportInput) -> Result<String> {
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
    s += "<section><h2>Summary</h2>";
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
        let total: f64 = sm.timings.iter().map(|t| t.seconds).sum();
        for t in &sm.timings {
            let _ = write!(
                s,
                "<tr><td>{}</td><td class=\"num\">{:.3}</td></tr>",
                xml_escape(&t.stage),
                t.seconds
            );
        }
        let _ = write!(
            s,
            "<tr><th>sum</th><td class=\"num\">{total:.3}</td></tr></tbody></table>"
        );
    }
    if !sm.notes.is_empty() {
        s += "<ul>";
        for n in &sm.notes {
            let _ = write!(s, "<li>{}</li>", xml_escape(n));
        }
        s += "</ul>";
    }
    s += "</section>\n";
    if !input.tree.is_empty() {
        let _ = writeln!(
            s,
            "<section><h2>Search tree</h2><div class=\"plot\">{}</div></section>",
            search_tree_svg(&input.tree)?
        );
    }
    if let Some(d) = &input.distribution {
        let _ = writeln!(
            s,
            "<section><h2>Designs over rule applications</h2><div class=\"plot\">{}</div></section>",
            distribution_svg(d)?
        );
    }
    let _ = writeln!(
        s,
        "<section><h2>Feasible designs ({})</h2><div class=\"cards\">",
        input.designs.len()
    );
    for d in &input.designs {
        s += &design_card(out_dir, d)?;
    }
    s += "</div></section>\n</main></body></html>\n";
    Ok(s)
}

/// Write `out_dir/report.html` and return its path.
pub fn write_report(out_dir: &Path, input: &ReportInput) -> Result<PathBuf> {
    let html = report_html(out_dir, input)?;
    let path = out_dir.join("report.html");
    write_file(&path, html)?;
    Ok(path)
}
