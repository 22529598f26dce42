//! How robust a folded motion is, measured independently of the optimizer's constraints
//! (issue 12): the smallest rigid-foldability margin, self clearance, clearance to the
//! rotated copy and to the obstacles over a dense sweep of states, each with where and
//! when it occurs.
//!
//! Nothing here shares code with the model's clearance constraints (`model::clearance`,
//! separating planes fitted by Gilbert's algorithm): the facets are triangulated as for
//! the Möller check and every distance is exact and closed form —
//! - facets sharing no vertex: the triangle–triangle distance (0 when Möller's test finds
//!   them crossing, else the least of the six point–triangle and nine segment–segment
//!   distances);
//! - facets sharing one vertex: the angle θ between their cones at that vertex (the
//!   spherical polygons they cut from the unit sphere around it; 0 when those overlap),
//!   reported as the chord `2 sin(θ/2)`, the gap at unit distance from the vertex; the
//!   same about the midpoint of the two tips for the facets of a two-armed gripper's tips,
//!   which meet at the target by design (the tips are that apex: the cones are spanned by
//!   the facets' other vertices);
//! - facets sharing a crease: `2 sin((π − |ρ|)/2)` with the fold angle measured from the
//!   two facets' geometry (the flip test's angle);
//! - a facet and a cylinder: the triangle–segment distance to the axis minus the radius
//!   (clearance from the capsule around the axis, which contains the flat-capped cylinder);
//! - rigid margins: `U_j + U_k − U_i` from the angles between the three creases that bound
//!   the units of each internal vertex in the folded 3D state (not the PTU's formulas),
//!   divided by `(t/t_max)²` (the flat state is degenerate; see `task::Robustness`);
//! - the smallest feature of the arm's flat layout (`check::features`: vertex pairs, vertex
//!   to edge, edge lengths), reported at t = 0.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::cylinder::Cylinder;
use super::distance::{
    SLACK, apart_beyond, bounding_sphere, point_segment_distance, projected_gap,
};
pub use super::distance::{segment_triangle_distance, triangle_distance};
use super::features::{self, FeatureKind};
use super::self_intersection::{CheckError, Checker};
use super::shapes::facet_clearance;
use super::tri_tri::Tri;
use crate::pattern::{Frame, Pattern};
use crate::scene::{Obstacle, Shape};
use crate::task::{DEFAULT_CLEARANCE, DEFAULT_MIN_FEATURE, DEFAULT_RIGID_MARGIN, Robustness};

type V = Vector3<f64>;

/// One margin of a design: its smallest value over the sweep, the setting it is held to,
/// where and when.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MarginReport {
    /// The smallest value found.
    pub value: f64,
    /// The task's setting for it.
    pub setting: f64,
    /// The state where it occurs.
    pub t: Option<f64>,
    /// Which vertex, facet pair or obstacle.
    #[serde(rename = "where")]
    pub location: String,
}

/// The robustness of a design (the `robustness` field of records and design files).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobustnessReport {
    /// The smallest of the present margins, each divided by its setting (settings of 0 are
    /// skipped; when all are 0, each is divided by its default instead).
    pub score: f64,
    /// Smallest Eq. 25 margin over the motion (rad, normalized by (t/t_max)²).
    pub rigid_margin: MarginReport,
    /// Smallest clearance between facets of the arm (paper units).
    pub self_clearance: Option<MarginReport>,
    /// Smallest clearance between the arm and its rotated copy.
    pub arm_clearance: Option<MarginReport>,
    /// Smallest clearance between a facet and an obstacle.
    pub obstacle_clearance: Option<MarginReport>,
    /// Smallest feature of the flat layout (issue 20; paper units, at t = 0): the least
    /// vertex–vertex or vertex–edge distance or edge length. Absent with a single vertex.
    pub min_feature: Option<MarginReport>,
}

impl RobustnessReport {
    /// Whether every present margin is at least its setting.
    pub fn meets_settings(&self) -> bool {
        self.margins().all(|m| m.value >= m.setting)
    }

    /// The present margins.
    pub fn margins(&self) -> impl Iterator<Item = &MarginReport> {
        std::iter::once(&self.rigid_margin)
            .chain(self.self_clearance.as_ref())
            .chain(self.arm_clearance.as_ref())
            .chain(self.obstacle_clearance.as_ref())
            .chain(self.min_feature.as_ref())
    }
}

/// An internal vertex and the far ends of the three creases that bound its units (the
/// slots s1, s2, s3 of rule r1).
#[derive(Clone, Debug, PartialEq)]
pub struct UnitCreases {
    /// The vertex (pattern index).
    pub vertex: usize,
    /// Far ends of s1, s2, s3.
    pub ends: [usize; 3],
    /// Its name for reports ("v4").
    pub label: String,
}

/// What the measurement needs besides the pattern.
#[derive(Clone, Debug)]
pub struct RobustnessInput<'a> {
    /// The pattern with frames at the sweep; for two-armed tasks the arm's faces first,
    /// then their rotated copies (as `check::two_armed` builds it).
    pub pattern: &'a Pattern,
    /// Number of the arm's faces (all of them for one-armed tasks).
    pub arm_faces: usize,
    /// Names of the arm's faces ("f3"); copies get a prime.
    pub face_names: Vec<String>,
    /// Names of the pattern's vertices ("v4"; copies "v4′").
    pub vertex_names: Vec<String>,
    /// Obstacles.
    pub cylinders: &'a [Cylinder],
    /// The internal vertices.
    pub units: Vec<UnitCreases>,
    /// For a two-armed task whose arms meet at the target: the arm's gripping vertex and
    /// its copy (pattern indices).
    pub tip: Option<(usize, usize)>,
    /// End of the motion.
    pub t_max: f64,
    /// The settings margins are held to.
    pub settings: Robustness,
    /// The arm alone: its flat layout's features are measured.
    pub arm: &'a Pattern,
}

/// How two faces relate.
#[derive(Clone, Copy, Debug)]
enum Relation {
    Apart,
    Wedge(usize),
    /// The facets of two tips meeting at the target: the arm's vertex and its copy's.
    Tip(usize, usize),
    Crease(usize),
}

/// Least value, its t and where.
#[derive(Clone, Debug)]
struct Least {
    value: f64,
    t: Option<f64>,
    location: String,
}

impl Least {
    fn new() -> Least {
        Least {
            value: f64::INFINITY,
            t: None,
            location: String::new(),
        }
    }
    /// Keep `value` if it is the least so far; of equal values the earliest state's (the
    /// sweep is visited from its end, where the least values usually are).
    fn offer(&mut self, value: f64, t: f64, location: impl FnOnce() -> String) {
        if value < self.value || (value == self.value && self.t.is_some_and(|s| t < s)) {
            self.value = value;
            self.t = Some(t);
            self.location = location();
        }
    }
    fn report(self, setting: f64) -> Option<MarginReport> {
        self.t.map(|_| MarginReport {
            value: self.value,
            setting,
            t: self.t,
            location: self.location,
        })
    }
}

/// What [`measure`] does not know of a task's scene (issue 31): obstacles of every shape
/// and the tips of n copies. The default adds nothing: [`measure`] is
/// `measure_scene(input, &SceneMargins::default())`.
#[derive(Clone, Debug, Default)]
pub struct SceneMargins<'a> {
    /// Obstacles judged by [`super::shapes::facet_clearance`] besides `input.cylinders`
    /// (pass the scene's obstacles: its cylinders are skipped here, they are the
    /// `cylinders`' and keep today's arithmetic).
    pub obstacles: &'a [Obstacle],
    /// For n copies whose tips meet on the axis: the arm's gripping vertex and its copy in
    /// each further copy (pattern indices), as `input.tip` is for the half-turn copy.
    pub tips: Vec<(usize, usize)>,
}

/// Measure the robustness of the motion in `input.pattern` (see the module docs).
pub fn measure(input: &RobustnessInput<'_>) -> Result<RobustnessReport, CheckError> {
    measure_scene(input, &SceneMargins::default())
}

/// [`measure`] with the scene's other obstacles and copies' tips: the obstacle clearance
/// is the least over the cylinders and every other shape; face pairs between the arm and
/// every copy (`input.pattern` holds the arm's facets, then each copy's, as
/// [`super::copies::with_copies`] builds it) count as `arm_clearance`.
pub fn measure_scene(
    input: &RobustnessInput<'_>,
    scene: &SceneMargins<'_>,
) -> Result<RobustnessReport, CheckError> {
    let pat = input.pattern;
    let checker = Checker::from_pattern(pat)?;
    let names = Names { input };
    let pairs = face_pairs(input, &checker, &scene.tips);
    let mut least = Leasts {
        rigid: Least::new(),
        own: Least::new(),
        arm: Least::new(),
        obstacle: Least::new(),
    };
    // From the end of the motion, where the pattern is most folded: the least values are
    // found early and prune more of the rest. Pruning only skips what is provably above
    // the least value so far (strictly, with slack for rounding), so the report is the
    // one a full evaluation gives.
    for frame in pat.frames.iter().rev() {
        let t = frame.t;
        checker.validate_state(&frame.coords, t)?;
        let x: Vec<V> = frame.coords.iter().map(|c| V::from(*c)).collect();
        if t != 0.0 {
            rigid_margins(&input.units, input.t_max, &x, t, &mut least.rigid);
        }
        let state = State::new(input, &checker, &names, frame, x);
        for &(fa, fb, rel) in &pairs {
            let least = if fb < input.arm_faces {
                &mut least.own
            } else {
                &mut least.arm
            };
            state.pair_clearance(fa, fb, rel, least);
        }
        state.obstacle_clearances(input.cylinders, &mut least.obstacle);
        state.shape_clearances(scene.obstacles, &mut least.obstacle);
    }
    Ok(report(input, least, &names))
}

/// The least values of the sweep so far.
struct Leasts {
    rigid: Least,
    /// Arm–arm face pairs.
    own: Least,
    /// Arm–copy face pairs.
    arm: Least,
    obstacle: Least,
}

/// The report of the least values found, scored.
fn report(input: &RobustnessInput<'_>, least: Leasts, names: &Names<'_, '_>) -> RobustnessReport {
    let s = &input.settings;
    let rigid_margin = least.rigid.report(s.rigid_margin).unwrap_or(MarginReport {
        value: f64::INFINITY,
        setting: s.rigid_margin,
        t: None,
        location: "no internal vertex".into(),
    });
    let mut report = RobustnessReport {
        score: 0.0,
        rigid_margin,
        self_clearance: least.own.report(s.clearance),
        arm_clearance: least.arm.report(s.clearance),
        obstacle_clearance: least.obstacle.report(s.obstacle_clearance),
        min_feature: features::pattern_min_feature(input.arm).map(|f| MarginReport {
            value: f.value,
            setting: s.min_feature,
            t: Some(0.0),
            location: feature_location(&f.kind, |v| names.vertex(v)),
        }),
    };
    report.score = score(&report);
    report
}

/// The names of faces and vertices in reports (`#k` where the input has none).
struct Names<'a, 'b> {
    input: &'a RobustnessInput<'b>,
}

impl Names<'_, '_> {
    /// Face `f`'s name; a copy's gets a prime.
    fn face(&self, f: usize) -> String {
        let input = self.input;
        if f < input.arm_faces {
            input.face_names.get(f).cloned().unwrap_or(format!("#{f}"))
        } else if f < 2 * input.arm_faces {
            format!(
                "{}′",
                input
                    .face_names
                    .get(f - input.arm_faces)
                    .cloned()
                    .unwrap_or(format!("#{f}"))
            )
        } else {
            // Copy k ≥ 2 of n: the arm's name and the copy's number.
            let (k, g) = (f / input.arm_faces, f % input.arm_faces);
            let name = input.face_names.get(g).cloned().unwrap_or(format!("#{g}"));
            format!("{name}′{k}")
        }
    }

    /// Vertex `v`'s name.
    fn vertex(&self, v: usize) -> String {
        self.input
            .vertex_names
            .get(v)
            .cloned()
            .unwrap_or(format!("#{v}"))
    }
}

/// Relations of the face pairs that count: arm–arm and arm–copy (copy–copy pairs are
/// arm–arm pairs turned by 180°).
fn face_pairs(
    input: &RobustnessInput<'_>,
    checker: &Checker,
    copy_tips: &[(usize, usize)],
) -> Vec<(usize, usize, Relation)> {
    let pat = input.pattern;
    let nf = pat.faces.len();
    let mut pairs: Vec<(usize, usize, Relation)> = Vec::new();
    for fa in 0..input.arm_faces.min(nf) {
        for fb in fa + 1..nf {
            let shared: Vec<usize> = pat.faces[fa]
                .iter()
                .copied()
                .filter(|v| pat.faces[fb].contains(v))
                .collect();
            let meet = |(g, c): (usize, usize)| {
                fb >= input.arm_faces && pat.faces[fa].contains(&g) && pat.faces[fb].contains(&c)
            };
            let tips = input
                .tip
                .filter(|&gc| meet(gc))
                .or_else(|| copy_tips.iter().copied().find(|&gc| meet(gc)));
            let rel = match (shared.as_slice(), tips) {
                ([], None) => Relation::Apart,
                ([], Some((g, c))) => Relation::Tip(g, c),
                ([v], None) => Relation::Wedge(*v),
                // Touching at a shared vertex and at the tips: the intersection check's.
                ([_], Some(_)) => continue,
                _ => match checker
                    .hinges()
                    .iter()
                    .position(|h| (h.face_a, h.face_b) == (fa, fb))
                {
                    Some(h) => Relation::Crease(h),
                    None => continue,
                },
            };
            pairs.push((fa, fb, rel));
        }
    }
    pairs
}

/// Rigid margins from the folded crease directions at state `t` (positions `x`),
/// normalized by `(t/t_max)²`.
fn rigid_margins(units: &[UnitCreases], t_max: f64, x: &[V], t: f64, rigid: &mut Least) {
    let scale = (t_max / t).powi(2);
    for u in units {
        let d = u.ends.map(|e| x[e] - x[u.vertex]);
        let ang = |p: &V, q: &V| p.cross(q).norm().atan2(p.dot(q));
        let (u1, u2, u3) = (ang(&d[2], &d[0]), ang(&d[0], &d[1]), ang(&d[1], &d[2]));
        let m = (u2 + u3 - u1).min(u1 + u3 - u2).min(u1 + u2 - u3);
        rigid.offer(m * scale, t, || u.label.clone());
    }
}

/// One state of the sweep: the positions, and the bounding spheres of the faces and
/// triangles for the pruning of far pairs.
struct State<'a> {
    input: &'a RobustnessInput<'a>,
    checker: &'a Checker,
    names: &'a Names<'a, 'a>,
    frame: &'a Frame,
    x: Vec<V>,
    spheres: Vec<(V, f64)>,
    tri_spheres: Vec<Vec<(V, f64)>>,
}

impl<'a> State<'a> {
    fn new(
        input: &'a RobustnessInput<'a>,
        checker: &'a Checker,
        names: &'a Names<'a, 'a>,
        frame: &'a Frame,
        x: Vec<V>,
    ) -> State<'a> {
        let spheres: Vec<(V, f64)> = input
            .pattern
            .faces
            .iter()
            .map(|f| {
                let c = f.iter().fold(V::zeros(), |s, v| s + x[*v]) / f.len() as f64;
                let r = f.iter().map(|v| (x[*v] - c).norm()).fold(0.0, f64::max);
                (c, r)
            })
            .collect();
        let tri_spheres: Vec<Vec<(V, f64)>> = checker
            .triangles()
            .iter()
            .map(|ts| {
                ts.iter()
                    .map(|ix| bounding_sphere(&ix.map(|i| x[i])))
                    .collect()
            })
            .collect();
        State {
            input,
            checker,
            names,
            frame,
            x,
            spheres,
            tri_spheres,
        }
    }

    fn tri(&self, ix: &[usize; 3]) -> Tri {
        ix.map(|i| self.x[i])
    }

    /// Offer the clearance of faces `fa` and `fb` (related by `rel`) to `least`, unless it
    /// is provably above the least value so far.
    fn pair_clearance(&self, fa: usize, fb: usize, rel: Relation, least: &mut Least) {
        let (t, x, faces) = (self.frame.t, &self.x, &self.input.pattern.faces);
        let pair = || format!("facets {}–{}", self.names.face(fa), self.names.face(fb));
        match rel {
            Relation::Apart => {
                if apart_beyond(self.spheres[fa], self.spheres[fb], least.value) {
                    return;
                }
                let tris = self.checker.triangles();
                let mut d = f64::INFINITY;
                for (a, sa) in tris[fa].iter().zip(&self.tri_spheres[fa]) {
                    for (b, sb) in tris[fb].iter().zip(&self.tri_spheres[fb]) {
                        let limit = d.min(least.value);
                        if apart_beyond(*sa, *sb, limit) {
                            continue;
                        }
                        let (a, b) = (self.tri(a), self.tri(b));
                        if projected_gap(&a, &b) <= limit {
                            d = d.min(triangle_distance(&a, &b));
                        }
                    }
                }
                least.offer(d, t, pair);
            }
            Relation::Wedge(v) => {
                let Some(theta) =
                    cone_angle_below(x[v], &faces[fa], &faces[fb], x, chord_angle(least.value))
                else {
                    return;
                };
                let chord = 2.0 * (0.5 * theta).sin();
                least.offer(chord, t, || {
                    format!("{} at {}", pair(), self.names.vertex(v))
                });
            }
            Relation::Tip(g, c) => {
                // The tips are the apex (within the target's tolerance of it): the
                // cones are those of the faces' other vertices.
                let other = |f: usize| -> Vec<usize> {
                    faces[f]
                        .iter()
                        .copied()
                        .filter(|v| *v != g && *v != c)
                        .collect()
                };
                let Some(theta) = cone_angle_below(
                    (x[g] + x[c]) * 0.5,
                    &other(fa),
                    &other(fb),
                    x,
                    chord_angle(least.value),
                ) else {
                    return;
                };
                let chord = 2.0 * (0.5 * theta).sin();
                least.offer(chord, t, || format!("{} at the tips", pair()));
            }
            Relation::Crease(h) => {
                let hinge = &self.checker.hinges()[h];
                let rho = hinge.fold_angle(&self.frame.coords);
                let chord = 2.0 * (0.5 * (std::f64::consts::PI - rho.abs())).sin();
                least.offer(chord, t, || {
                    format!(
                        "crease {}–{} between {}",
                        self.names.vertex(hinge.p),
                        self.names.vertex(hinge.q),
                        pair()
                    )
                });
            }
        }
    }

    /// Offer the clearance of every face to every cylinder to `obstacle`.
    fn obstacle_clearances(&self, cylinders: &[Cylinder], obstacle: &mut Least) {
        let t = self.frame.t;
        for (k, cyl) in cylinders.iter().enumerate() {
            let (a, b) = (V::from(cyl.a), V::from(cyl.b));
            let beyond = |(c, r): (V, f64), limit: f64| {
                point_segment_distance(&c, &a, &b) - r - cyl.radius - SLACK > limit
            };
            for (f, ts) in self.checker.triangles().iter().enumerate() {
                if beyond(self.spheres[f], obstacle.value) {
                    continue;
                }
                let mut d = f64::INFINITY;
                for (ix, sph) in ts.iter().zip(&self.tri_spheres[f]) {
                    if !beyond(*sph, (d - cyl.radius).min(obstacle.value)) {
                        d = d.min(segment_triangle_distance(&a, &b, &self.tri(ix)));
                    }
                }
                let d = d - cyl.radius;
                obstacle.offer(d, t, || {
                    format!("facet {} ↔ cylinder {}", self.names.face(f), k + 1)
                });
            }
        }
    }
}

impl State<'_> {
    /// Offer the clearance of every face to every obstacle but the cylinders (which
    /// [`State::obstacle_clearances`] judges) to `obstacle`. Faces whose bounding sphere
    /// keeps off the obstacle's bounding ball by more than the least so far are skipped.
    fn shape_clearances(&self, obstacles: &[Obstacle], obstacle: &mut Least) {
        let t = self.frame.t;
        for ob in obstacles {
            if matches!(ob.shape, Shape::Cylinder(_)) {
                continue;
            }
            let ball = ob.bounding_ball().map(|(c, r)| (V::from(c), r));
            for (f, ts) in self.checker.triangles().iter().enumerate() {
                if ball.is_some_and(|b| apart_beyond(self.spheres[f], b, obstacle.value)) {
                    continue;
                }
                let tris: Vec<Tri> = ts.iter().map(|ix| self.tri(ix)).collect();
                if let Some(d) = facet_clearance(&ob.shape, &tris) {
                    obstacle.offer(d, t, || {
                        format!("facet {} ↔ {}", self.names.face(f), ob.name)
                    });
                }
            }
        }
    }
}

/// Where a feature is, with the vertices' names: `"v3 ↔ v7"`, `"edge v2–v5"`,
/// `"v4 ↔ edge v1–v2"`.
fn feature_location(kind: &FeatureKind, name: impl Fn(usize) -> String) -> String {
    match *kind {
        FeatureKind::Vertices { a, b } => format!("{} ↔ {}", name(a), name(b)),
        FeatureKind::Edge { a, b } => format!("edge {}–{}", name(a), name(b)),
        FeatureKind::VertexEdge { v, a, b } => {
            format!("{} ↔ edge {}–{}", name(v), name(a), name(b))
        }
    }
}

/// The smallest margin over its setting (settings of 0 skipped); with every setting 0, over
/// the defaults (1°, 1% of G0's crease, 0.015 for the feature size) so designs still rank
/// by how close they come.
pub fn score(r: &RobustnessReport) -> f64 {
    let ratio = |m: &MarginReport, default: f64| {
        if m.setting > 0.0 {
            (m.value / m.setting, true)
        } else {
            (m.value / default, false)
        }
    };
    let all: Vec<(f64, bool)> = std::iter::once(ratio(&r.rigid_margin, DEFAULT_RIGID_MARGIN))
        .chain(r.self_clearance.iter().map(|m| ratio(m, DEFAULT_CLEARANCE)))
        .chain(r.arm_clearance.iter().map(|m| ratio(m, DEFAULT_CLEARANCE)))
        .chain(
            r.obstacle_clearance
                .iter()
                .map(|m| ratio(m, DEFAULT_CLEARANCE)),
        )
        .chain(r.min_feature.iter().map(|m| ratio(m, DEFAULT_MIN_FEATURE)))
        .filter(|(v, _)| v.is_finite())
        .collect();
    let set: Vec<f64> = all.iter().filter(|(_, s)| *s).map(|(v, _)| *v).collect();
    let pick = if set.is_empty() {
        all.iter().map(|(v, _)| *v).collect()
    } else {
        set
    };
    pick.into_iter().fold(f64::INFINITY, f64::min)
}

/// Rounding allowance of the pruning bounds (paper units or radians).
/// The cone angle whose chord `2 sin(θ/2)` is `chord` (π for chords of 2 or more).
fn chord_angle(chord: f64) -> f64 {
    if chord >= 2.0 {
        std::f64::consts::PI
    } else {
        2.0 * (0.5 * chord).asin()
    }
}

/// [`cone_angle`], or `None` when it is provably above `limit`: each cone lies in the
/// circular cap about its mean direction through its farthest vertex direction (a cap
/// under a hemisphere is convex, so it holds the cone's arcs and inside), and two caps are
/// apart by the angle between their axes less both radii.
fn cone_angle_below(apex: V, fa: &[usize], fb: &[usize], x: &[V], limit: f64) -> Option<f64> {
    let cap = |f: &[usize]| -> Option<(V, f64)> {
        let dirs = f.iter().filter_map(|v| (x[*v] - apex).try_normalize(1e-12));
        let axis = dirs
            .clone()
            .fold(V::zeros(), |s, d| s + d)
            .try_normalize(1e-9)?;
        let cos_r = dirs.map(|d| d.dot(&axis)).fold(1.0_f64, f64::min);
        // Only caps well under a hemisphere.
        (cos_r > 1e-6).then(|| (axis, cos_r.min(1.0).acos()))
    };
    if limit < std::f64::consts::PI
        && let (Some((a, ra)), Some((b, rb))) = (cap(fa), cap(fb))
    {
        let gap = a.cross(&b).norm().atan2(a.dot(&b)) - ra - rb;
        if gap - SLACK > limit {
            return None;
        }
    }
    Some(cone_angle(apex, fa, fb, x))
}

/// Angle from unit vector `p` to the arc from `e1` to `e2` (shorter than π) on the sphere.
fn point_arc_angle(p: &V, e1: &V, e2: &V) -> f64 {
    let ang = |a: &V, b: &V| a.cross(b).norm().atan2(a.dot(b));
    let end = ang(p, e1).min(ang(p, e2));
    let Some(m) = e1.cross(e2).try_normalize(1e-300) else {
        return end;
    };
    let q = p - m * p.dot(&m);
    if q.norm() > 1e-300 && e1.cross(&q).dot(&m) >= 0.0 && q.cross(e2).dot(&m) >= 0.0 {
        return p.dot(&m).abs().atan2(q.norm()).min(end);
    }
    end
}

/// Whether the arcs `a1 → a2` and `b1 → b2` (each shorter than π, on different great
/// circles) cross.
fn arcs_cross(a1: &V, a2: &V, b1: &V, b2: &V) -> bool {
    let (Some(ma), Some(mb)) = (
        a1.cross(a2).try_normalize(1e-300),
        b1.cross(b2).try_normalize(1e-300),
    ) else {
        return false;
    };
    let Some(l) = ma.cross(&mb).try_normalize(1e-12) else {
        // One great circle: overlapping arcs show as a zero point–arc distance.
        return false;
    };
    let on =
        |q: &V, e1: &V, e2: &V, m: &V| e1.cross(q).dot(m) >= -1e-15 && q.cross(e2).dot(m) >= -1e-15;
    [l, -l]
        .iter()
        .any(|q| on(q, a1, a2, &ma) && on(q, b1, b2, &mb))
}

/// Whether unit vector `u` lies inside the spherical polygon `poly` (vertices in order,
/// spanning less than a hemisphere): the crossing number in the gnomonic projection about
/// the polygon's mean direction, which maps its arcs to straight segments.
fn inside_spherical(u: &V, poly: &[V]) -> bool {
    let Some(c) = poly
        .iter()
        .fold(V::zeros(), |s, p| s + p)
        .try_normalize(1e-300)
    else {
        return false;
    };
    if u.dot(&c) <= 1e-12 || poly.iter().any(|p| p.dot(&c) <= 1e-12) {
        return false;
    }
    let e1 = if c.x.abs() < 0.9 { V::x() } else { V::y() };
    let e1 = c.cross(&e1).normalize();
    let e2 = c.cross(&e1);
    let proj = |p: &V| {
        let q = p / p.dot(&c);
        (q.dot(&e1), q.dot(&e2))
    };
    let (px, py) = proj(u);
    let pts: Vec<(f64, f64)> = poly.iter().map(proj).collect();
    let mut inside = false;
    for k in 0..pts.len() {
        let (ax, ay) = pts[k];
        let (bx, by) = pts[(k + 1) % pts.len()];
        if (ay > py) != (by > py) && px < ax + (py - ay) / (by - ay) * (bx - ax) {
            inside = !inside;
        }
    }
    inside
}

/// The angle between the cones from `apex` over two faces (vertex lists into `x`): 0 when
/// they overlap, else the least angle from a vertex direction of one to an edge arc of the
/// other. A face through the apex gives a planar cone (its arcs lie on one great circle).
fn cone_angle(apex: V, fa: &[usize], fb: &[usize], x: &[V]) -> f64 {
    let dirs = |f: &[usize]| -> Vec<V> {
        f.iter()
            .filter_map(|v| (x[*v] - apex).try_normalize(1e-12))
            .collect()
    };
    let (da, db) = (dirs(fa), dirs(fb));
    if da.is_empty() || db.is_empty() {
        return std::f64::consts::PI;
    }
    let arcs = |d: &[V]| -> Vec<(V, V)> {
        match d.len() {
            1 => Vec::new(),
            2 => vec![(d[0], d[1])],
            n => (0..n).map(|k| (d[k], d[(k + 1) % n])).collect(),
        }
    };
    let (aa, ab) = (arcs(&da), arcs(&db));
    for (a1, a2) in &aa {
        for (b1, b2) in &ab {
            if arcs_cross(a1, a2, b1, b2) {
                return 0.0;
            }
        }
    }
    if db.iter().any(|u| inside_spherical(u, &da)) || da.iter().any(|u| inside_spherical(u, &db)) {
        return 0.0;
    }
    let ang = |a: &V, b: &V| a.cross(b).norm().atan2(a.dot(b));
    let mut best = f64::INFINITY;
    for (p, arcs) in da
        .iter()
        .map(|p| (p, &ab))
        .chain(db.iter().map(|p| (p, &aa)))
    {
        for (e1, e2) in arcs.iter() {
            best = best.min(point_arc_angle(p, e1, e2));
        }
    }
    for p in &da {
        for q in &db {
            best = best.min(ang(p, q));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_angle_of_two_wedges() {
        // Apex at the origin; face A in the xy-plane between +x and +y, face B in the
        // plane z = 0 rotated up about the y-axis … simplest: B between directions at
        // angles 120° and 150° in the xy-plane, so 30° from A's edge +y.
        let x = [
            V::zeros(),
            V::new(1.0, 0.0, 0.0),
            V::new(0.0, 1.0, 0.0),
            V::new(
                (120f64).to_radians().cos(),
                (120f64).to_radians().sin(),
                0.0,
            ),
            V::new(
                (150f64).to_radians().cos(),
                (150f64).to_radians().sin(),
                0.0,
            ),
        ];
        let th = cone_angle(x[0], &[0, 1, 2], &[0, 3, 4], &x);
        assert!((th - 30f64.to_radians()).abs() < 1e-12, "{th}");
        // Lift B out of the plane: rotate its points about the y-axis… the angle to A's
        // cone is then the angle of its nearest ray to the quarter plane.
        let up = |p: V| V::new(p.x, p.y * 0.5f64.cos(), p.y * 0.5f64.sin());
        let x2 = [x[0], x[1], x[2], up(x[3]), up(x[4])];
        let th2 = cone_angle(x2[0], &[0, 1, 2], &[0, 3, 4], &x2);
        let ray = up(x[3]).normalize();
        let want = point_arc_angle(&ray, &x[1], &x[2]);
        assert!((th2 - want).abs() < 1e-12 && th2 > th, "{th2} {want}");
        // Overlapping wedges: 0.
        let x3 = [
            x[0],
            x[1],
            x[2],
            V::new(0.5, 0.5, 0.0),
            V::new(-1.0, 0.2, 0.0),
        ];
        assert_eq!(cone_angle(x3[0], &[0, 1, 2], &[0, 3, 4], &x3), 0.0);
        // Crossing out of plane: B's arc pierces A's quarter plane.
        let x4 = [
            x[0],
            x[1],
            x[2],
            V::new(0.5, 0.5, 1.0),
            V::new(0.5, 0.5, -1.0),
        ];
        assert_eq!(cone_angle(x4[0], &[0, 1, 2], &[0, 3, 4], &x4), 0.0);
    }

    /// The pruning bounds of `measure` never exceed what they bound: two bounding spheres'
    /// gap is at most the triangles' distance, and two cones' cap gap at most their cone
    /// angle; so nothing at or below the least value so far is skipped. Random triangles and
    /// fans about a common apex, spread from touching to far apart.
    #[test]
    fn pruning_bounds_never_exceed_the_exact_values() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut rnd = move || rng.random_range(-1.0..1.0);
        let mut pruned = 0;
        for k in 0..4000 {
            let spread = [0.1, 0.5, 2.0, 5.0][k % 4];
            let mut tri = |c: f64| -> Tri {
                let o = V::new(c, 0.0, 0.0);
                [(); 3].map(|_| o + V::new(rnd(), rnd(), rnd()))
            };
            let (a, b) = (tri(0.0), tri(spread));
            let d = triangle_distance(&a, &b);
            assert!(!apart_beyond(bounding_sphere(&a), bounding_sphere(&b), d));
            pruned += usize::from(apart_beyond(
                bounding_sphere(&a),
                bounding_sphere(&b),
                0.5 * d,
            ));
            // Two faces about an apex at the origin (x[0]): the apex and three or four
            // vertices each, around a direction of their own.
            let mut x = vec![V::zeros()];
            let mut face = |dir: V| -> Vec<usize> {
                let n = 3 + (k % 2);
                let mut f = vec![0];
                for _ in 0..n {
                    x.push(dir + V::new(rnd(), rnd(), rnd()) * 0.4);
                    f.push(x.len() - 1);
                }
                f
            };
            let fa = face(V::new(1.0, 0.0, 0.0));
            let turn = spread.min(3.0);
            let fb = face(V::new(turn.cos(), turn.sin(), 0.0));
            let theta = cone_angle(V::zeros(), &fa, &fb, &x);
            assert_eq!(
                cone_angle_below(V::zeros(), &fa, &fb, &x, theta),
                Some(theta)
            );
            pruned +=
                usize::from(cone_angle_below(V::zeros(), &fa, &fb, &x, 0.5 * theta).is_none());
        }
        // The bounds do prune: not vacuous.
        assert!(pruned > 1000, "{pruned}");
    }
}
