//! Plots as hand-written SVG: the search tree (thesis Fig. 48) and the distribution of
//! designs over the number of rule applications (Fig. 51).

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::{ExportError, Result};

/// Escape text for XML/HTML content and attribute values.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// What became of a generated graph (thesis Fig. 48 colours).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NodeStatus {
    /// Kept and optimized (yellow in the thesis).
    Meaningful,
    /// Semantically invalid: not optimized, descendants kept.
    Invalid,
    /// Mirror image of an earlier graph: dropped with its descendants.
    Mirror,
    /// Isomorphic to an earlier graph.
    Isomorphic,
}

impl NodeStatus {
    fn style(self) -> (&'static str, &'static str, &'static str) {
        // (fill, stroke, dash)
        match self {
            NodeStatus::Meaningful => ("#f5c400", "#7a6200", ""),
            NodeStatus::Invalid => ("#ffffff", "#333333", ""),
            NodeStatus::Mirror => ("#ffffff", "#888888", " stroke-dasharray=\"2 1.5\""),
            NodeStatus::Isomorphic => ("#cfcfcf", "#888888", ""),
        }
    }
    fn name(self) -> &'static str {
        match self {
            NodeStatus::Meaningful => "meaningful",
            NodeStatus::Invalid => "invalid",
            NodeStatus::Mirror => "mirror",
            NodeStatus::Isomorphic => "isomorphic",
        }
    }
}

/// One node of the search tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeNode {
    /// Unique id.
    pub id: usize,
    /// The id of the graph this one was derived from (`None` for the roots).
    pub parent: Option<usize>,
    /// The rule sequence, e.g. `"2, 3, (4, 8)"`.
    pub label: String,
    /// Number of rule applications (the row of the tree).
    pub level: usize,
    /// What became of it.
    pub status: NodeStatus,
}

/// The search tree as SVG: one row per number of rule applications, edges parent → child,
/// node colour by status, the rule sequence below each node (and as a hover title).
pub fn search_tree_svg(nodes: &[TreeNode]) -> Result<String> {
    check_tree(nodes)?;
    let t = TreeLayout::new(nodes);
    let mut s = t.header(nodes);
    for n in nodes {
        if let Some(p) = n.parent {
            let _ = writeln!(
                s,
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#9a9a9a\" stroke-width=\"0.8\"/>",
                t.xpos[&p],
                t.ypos[&p] + 5.0,
                t.xpos[&n.id],
                t.ypos[&n.id] - 5.0
            );
        }
    }
    for n in nodes {
        let (x, y) = (t.xpos[&n.id], t.ypos[&n.id]);
        let (fill, stroke, dash) = n.status.style();
        let label = xml_escape(&n.label);
        let _ = writeln!(
            s,
            "<g><title>{label} ({})</title><circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"5\" fill=\"{fill}\" stroke=\"{stroke}\"{dash}/><text x=\"{x:.1}\" y=\"{:.1}\" font-size=\"9\" transform=\"rotate(90 {x:.1} {:.1})\" dominant-baseline=\"middle\">{label}</text></g>",
            n.status.name(),
            y + 9.0,
            y + 9.0
        );
    }
    s.push_str("</svg>");
    Ok(s)
}

/// Ids are unique, parents exist, and a child is one level below its parent.
fn check_tree(nodes: &[TreeNode]) -> Result<()> {
    if nodes.is_empty() {
        return Err(ExportError::invalid("tree", "no nodes"));
    }
    let mut by_id: HashMap<usize, &TreeNode> = HashMap::new();
    for (i, n) in nodes.iter().enumerate() {
        if by_id.insert(n.id, n).is_some() {
            return Err(ExportError::invalid(
                format!("tree[{i}].id"),
                format!("id {} appears twice", n.id),
            ));
        }
    }
    for (i, n) in nodes.iter().enumerate() {
        if let Some(p) = n.parent {
            let parent = by_id.get(&p).ok_or_else(|| {
                ExportError::invalid(format!("tree[{i}].parent"), format!("no node has id {p}"))
            })?;
            if parent.level + 1 != n.level {
                return Err(ExportError::invalid(
                    format!("tree[{i}].level"),
                    format!(
                        "{}, but its parent {p} is at level {} (a child is one level below)",
                        n.level, parent.level
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Where the search tree's rows and nodes go.
struct TreeLayout<'a> {
    /// The nodes of each level.
    levels: BTreeMap<usize, Vec<&'a TreeNode>>,
    /// The first level (the top row).
    first: usize,
    width: f64,
    height: f64,
    /// Margins.
    left: f64,
    top: f64,
    right: f64,
    /// Height of a row (room for the longest label, written downward).
    row: f64,
    /// Position of each node by id.
    xpos: HashMap<usize, f64>,
    ypos: HashMap<usize, f64>,
}

impl<'a> TreeLayout<'a> {
    fn new(nodes: &'a [TreeNode]) -> TreeLayout<'a> {
        let mut levels: BTreeMap<usize, Vec<&TreeNode>> = BTreeMap::new();
        for n in nodes {
            levels.entry(n.level).or_default().push(n);
        }
        let widest = levels.values().map(Vec::len).max().unwrap_or(1);
        let longest = nodes
            .iter()
            .map(|n| n.label.chars().count())
            .max()
            .unwrap_or(0);
        let (left, top, right) = (70.0, 70.0, 20.0);
        let spacing = 18.0;
        let width = (widest as f64 * spacing + left + right).max(900.0);
        let row = 34.0 + 5.6 * longest as f64;
        let first = *levels.keys().next().unwrap_or(&0);
        let height = top + row * levels.len() as f64 + 10.0;

        // Place rows top-down; children ordered by their parent's x, then by id.
        let mut xpos: HashMap<usize, f64> = HashMap::new();
        let mut ypos: HashMap<usize, f64> = HashMap::new();
        for (&lvl, row_nodes) in &levels {
            let mut sorted = row_nodes.clone();
            sorted.sort_by(|a, b| {
                let pa = a.parent.and_then(|p| xpos.get(&p)).copied().unwrap_or(-1.0);
                let pb = b.parent.and_then(|p| xpos.get(&p)).copied().unwrap_or(-1.0);
                pa.total_cmp(&pb).then(a.id.cmp(&b.id))
            });
            let usable = width - left - right;
            let step = usable / sorted.len() as f64;
            for (k, n) in sorted.iter().enumerate() {
                xpos.insert(n.id, left + step * (k as f64 + 0.5));
                ypos.insert(n.id, top + row * (lvl - first) as f64);
            }
        }
        TreeLayout {
            levels,
            first,
            width,
            height,
            left,
            top,
            right,
            row,
            xpos,
            ypos,
        }
    }

    /// The picture up to its edges and nodes: title, legend with counts, row lines.
    fn header(&self, nodes: &[TreeNode]) -> String {
        let (width, height, left) = (self.width, self.height, self.left);
        let mut counts: BTreeMap<NodeStatus, usize> = BTreeMap::new();
        for n in nodes {
            *counts.entry(n.status).or_default() += 1;
        }
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" height=\"{height:.0}\" viewBox=\"0 0 {width:.0} {height:.0}\" font-family=\"sans-serif\">\n<rect width=\"{width:.0}\" height=\"{height:.0}\" fill=\"#ffffff\"/>\n"
        );
        let _ = writeln!(
            s,
            "<text x=\"{left}\" y=\"22\" font-size=\"15\" font-weight=\"bold\">Search tree: {} graphs (rows: number of rule applications)</text>",
            nodes.len()
        );
        let mut lx = left;
        for (st, c) in &counts {
            let (fill, stroke, dash) = st.style();
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"42\" r=\"6\" fill=\"{fill}\" stroke=\"{stroke}\"{dash}/><text x=\"{:.1}\" y=\"46\" font-size=\"12\">{} ({c})</text>",
                lx + 6.0,
                lx + 16.0,
                st.name()
            );
            lx += 130.0;
        }
        for &lvl in self.levels.keys() {
            let y = self.top + self.row * (lvl - self.first) as f64;
            let _ = writeln!(
                s,
                "<text x=\"10\" y=\"{:.1}\" font-size=\"12\" fill=\"#555555\">{lvl}</text><line x1=\"28\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#eeeeee\"/>",
                y + 4.0,
                width - self.right
            );
        }
        s
    }
}

/// One line of the distribution plot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Legend text, e.g. `"meets target"`.
    pub name: String,
    /// Points (x, y), e.g. (number of rule applications, number of designs).
    pub points: Vec<[f64; 2]>,
}

/// The distribution plot (thesis Fig. 51).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DistributionPlot {
    /// Title above the plot.
    pub title: String,
    /// Label of the x-axis.
    pub x_label: String,
    /// Label of the y-axis.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
}

/// Round tick steps: 1, 2 or 5 times a power of ten, about `target` ticks over `span`.
fn tick_step(span: f64, target: f64) -> f64 {
    let raw = (span / target).max(1e-12);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

fn fmt_tick(v: f64, step: f64) -> String {
    if step >= 1.0 {
        format!("{}", v.round())
    } else {
        let digits = (-step.log10()).ceil() as usize;
        format!("{v:.digits$}")
    }
}

const PALETTE: [&str; 6] = [
    "#1f4e9c", "#d1495b", "#2e8b57", "#e08e0b", "#6a4c93", "#333333",
];

/// The distribution plot as SVG: axes with ticks, one polyline with markers per series,
/// and a legend.
pub fn distribution_svg(plot: &DistributionPlot) -> Result<String> {
    check_distribution(plot)?;
    let ax = Axes::fit(plot);
    let (w, h, ml) = (ax.w, ax.h, ax.ml);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\">\n<rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>\n"
    );
    let _ = writeln!(
        s,
        "<text x=\"{ml}\" y=\"22\" font-size=\"15\" font-weight=\"bold\">{}</text>",
        xml_escape(&plot.title)
    );
    ax.draw(&mut s, plot);
    for (i, se) in plot.series.iter().enumerate() {
        ax.draw_series(&mut s, i, se);
    }
    s.push_str("</svg>");
    Ok(s)
}

/// Some point to plot, and every number finite.
fn check_distribution(plot: &DistributionPlot) -> Result<()> {
    if plot.series.is_empty() || plot.series.iter().all(|s| s.points.is_empty()) {
        return Err(ExportError::invalid(
            "distribution.series",
            "no points to plot",
        ));
    }
    for (i, se) in plot.series.iter().enumerate() {
        for (k, p) in se.points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(ExportError::invalid(
                    format!("distribution.series[{i}].points[{k}]"),
                    "non-finite number",
                ));
            }
        }
    }
    Ok(())
}

/// The distribution plot's axes: ranges, tick steps, the picture's size and margins.
struct Axes {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    xstep: f64,
    ystep: f64,
    w: f64,
    h: f64,
    /// Margins: left, right (room for the legend), top, bottom.
    ml: f64,
    mr: f64,
    mt: f64,
    mb: f64,
}

impl Axes {
    /// Axes holding every point, the y-axis from 0 (or below), ranges rounded to ticks.
    fn fit(plot: &DistributionPlot) -> Axes {
        let all = plot.series.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        let mut y0 = 0.0f64;
        for p in all {
            x0 = x0.min(p[0]);
            x1 = x1.max(p[0]);
            y0 = y0.min(p[1]);
            y1 = y1.max(p[1]);
        }
        if x1 == x0 {
            x0 -= 1.0;
            x1 += 1.0;
        }
        if y1 == y0 {
            y1 = y0 + 1.0;
        }
        let ystep = tick_step(y1 - y0, 5.0);
        let y1 = (y1 / ystep).ceil() * ystep;
        let y0 = (y0 / ystep).floor() * ystep;
        let xstep = tick_step(x1 - x0, 8.0).max(
            if plot
                .series
                .iter()
                .all(|s| s.points.iter().all(|p| p[0].fract() == 0.0))
            {
                1.0
            } else {
                0.0
            },
        );
        let (w, h) = (640.0, 400.0);
        let (ml, mr, mt, mb) = (70.0, 170.0, 40.0, 50.0);
        Axes {
            x0,
            x1,
            y0,
            y1,
            xstep,
            ystep,
            w,
            h,
            ml,
            mr,
            mt,
            mb,
        }
    }

    /// The pixel column of `x`.
    fn px(&self, x: f64) -> f64 {
        self.ml + (x - self.x0) / (self.x1 - self.x0) * (self.w - self.ml - self.mr)
    }

    /// The pixel row of `y`.
    fn py(&self, y: f64) -> f64 {
        self.h - self.mb - (y - self.y0) / (self.y1 - self.y0) * (self.h - self.mt - self.mb)
    }

    /// Grid, ticks, the axes and their labels.
    fn draw(&self, s: &mut String, plot: &DistributionPlot) {
        let (w, h, ml, mr, mt, mb) = (self.w, self.h, self.ml, self.mr, self.mt, self.mb);
        let (px, py) = (|x| self.px(x), |y| self.py(y));
        let mut y = self.y0;
        while y <= self.y1 + 1e-9 * self.ystep {
            let _ = writeln!(
                s,
                "<line x1=\"{ml}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#e6e6e6\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"end\">{}</text>",
                py(y),
                w - mr,
                py(y),
                ml - 6.0,
                py(y) + 4.0,
                fmt_tick(y, self.ystep)
            );
            y += self.ystep;
        }
        let mut x = (self.x0 / self.xstep).ceil() * self.xstep;
        while x <= self.x1 + 1e-9 * self.xstep {
            let _ = writeln!(
                s,
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#444444\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\">{}</text>",
                px(x),
                h - mb,
                px(x),
                h - mb + 5.0,
                px(x),
                h - mb + 18.0,
                fmt_tick(x, self.xstep)
            );
            x += self.xstep;
        }
        let _ = writeln!(
            s,
            "<line x1=\"{ml}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#444444\"/><line x1=\"{ml}\" y1=\"{mt}\" x2=\"{ml}\" y2=\"{:.1}\" stroke=\"#444444\"/>",
            h - mb,
            w - mr,
            h - mb,
            h - mb
        );
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\">{}</text>",
            0.5 * (ml + w - mr),
            h - 12.0,
            xml_escape(&plot.x_label)
        );
        let _ = writeln!(
            s,
            "<text x=\"16\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\" transform=\"rotate(-90 16 {:.1})\">{}</text>",
            0.5 * (mt + h - mb),
            0.5 * (mt + h - mb),
            xml_escape(&plot.y_label)
        );
    }

    /// Series `i`: its polyline with markers, and its line of the legend.
    fn draw_series(&self, s: &mut String, i: usize, se: &Series) {
        let (w, mr, mt) = (self.w, self.mr, self.mt);
        let c = PALETTE[i % PALETTE.len()];
        let mut pts = se.points.clone();
        pts.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let attr: Vec<String> = pts
            .iter()
            .map(|p| format!("{:.1},{:.1}", self.px(p[0]), self.py(p[1])))
            .collect();
        let _ = writeln!(
            s,
            "<g><title>{}</title><polyline points=\"{}\" fill=\"none\" stroke=\"{c}\" stroke-width=\"2\"/>",
            xml_escape(&se.name),
            attr.join(" ")
        );
        for p in &pts {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{c}\"/>",
                self.px(p[0]),
                self.py(p[1])
            );
        }
        s.push_str("</g>\n");
        let ly = mt + 10.0 + 20.0 * i as f64;
        let _ = writeln!(
            s,
            "<line x1=\"{:.1}\" y1=\"{ly:.1}\" x2=\"{:.1}\" y2=\"{ly:.1}\" stroke=\"{c}\" stroke-width=\"2\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\">{}</text>",
            w - mr + 12.0,
            w - mr + 34.0,
            w - mr + 40.0,
            ly + 4.0,
            xml_escape(&se.name)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(id: usize, parent: Option<usize>, level: usize, status: NodeStatus) -> TreeNode {
        TreeNode {
            id,
            parent,
            label: format!("seq <{id}>"),
            level,
            status,
        }
    }

    #[test]
    fn tree_draws_every_node_and_edge() {
        let nodes = vec![
            node(0, None, 1, NodeStatus::Meaningful),
            node(1, Some(0), 2, NodeStatus::Meaningful),
            node(2, Some(0), 2, NodeStatus::Mirror),
            node(3, Some(1), 3, NodeStatus::Invalid),
            node(4, Some(1), 3, NodeStatus::Isomorphic),
        ];
        let s = search_tree_svg(&nodes).unwrap();
        // 5 node circles + 4 legend circles; 4 tree edges (grey) besides the level rules.
        assert_eq!(s.matches("<circle").count(), 5 + 4);
        assert_eq!(s.matches("stroke=\"#9a9a9a\"").count(), 4);
        assert!(s.contains("seq &lt;3&gt;"));
        assert!(s.contains("meaningful (2)"));
    }

    #[test]
    fn tree_rejects_bad_input() {
        let e = search_tree_svg(&[
            node(0, None, 1, NodeStatus::Meaningful),
            node(1, Some(7), 2, NodeStatus::Invalid),
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("tree[1].parent") && e.contains('7'), "{e}");
        let e = search_tree_svg(&[
            node(0, None, 1, NodeStatus::Meaningful),
            node(1, Some(0), 3, NodeStatus::Invalid),
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("tree[1].level"), "{e}");
        let e = search_tree_svg(&[
            node(0, None, 1, NodeStatus::Meaningful),
            node(0, None, 1, NodeStatus::Invalid),
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("twice"), "{e}");
    }

    #[test]
    fn ticks_are_round() {
        assert_eq!(tick_step(836.0, 5.0), 200.0);
        assert_eq!(tick_step(7.0, 8.0), 1.0);
        assert_eq!(tick_step(0.3, 5.0), 0.1);
    }

    #[test]
    fn distribution_has_one_line_per_series() {
        let plot = DistributionPlot {
            title: "Designs".into(),
            x_label: "rule applications".into(),
            y_label: "designs".into(),
            series: vec![
                Series {
                    name: "all".into(),
                    points: vec![[1.0, 3.0], [2.0, 24.0], [3.0, 42.0]],
                },
                Series {
                    name: "meets target".into(),
                    points: vec![[1.0, 1.0], [2.0, 20.0], [3.0, 30.0]],
                },
            ],
        };
        let s = distribution_svg(&plot).unwrap();
        assert_eq!(s.matches("<polyline").count(), 2);
        assert_eq!(s.matches("r=\"3\"").count(), 6);
        assert!(s.contains(">meets target</text>"));
        let bad = DistributionPlot {
            series: vec![Series {
                name: "x".into(),
                points: vec![[1.0, f64::NAN]],
            }],
            ..plot
        };
        assert!(
            distribution_svg(&bad)
                .unwrap_err()
                .to_string()
                .contains("points[0]")
        );
    }
}
