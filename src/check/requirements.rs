//! The judges of a task's requirements and targets (issue 31), run on the dense sweep of
//! every design and written again from the folded positions alone: nothing here calls
//! `model/` (whose constraints they check). The indices they need (which vertex is "tip",
//! which crease "v1-v2") are facts the caller resolves (`model::select`) and passes in.
//!
//! - orientation: the angle between the crease `tail → head` (or the normal of the facet
//!   left or right of it, Newell's normal of its folded vertices, oriented as the paper's
//!   upper side) and the reference direction, at every listed t;
//! - fold limits and `max_fold`: the largest `|ρ|` of a crease over the sweep, ρ from the
//!   normals of the two facets along it ([`crate::geom::fold_angle`]);
//! - containment: the least signed distance of every vertex of every copy to the box's
//!   walls (negative outside) at its t or at every state; a facet is the convex hull of its
//!   vertices and a box is convex, so its vertices decide;
//! - obstacles: per obstacle the least clearance of every facet of every copy over the
//!   sweep ([`super::shapes`]);
//! - copies: Möller crossings between facets of different copies, and the least distance
//!   between facets of the arm and of a copy that share no vertex;
//! - targets: Ω = Σ w_i d_i recomputed from the positions (point, line, plane, and a mesh
//!   surface by brute-force point–triangle distance);
//! - area: the flat area times the copies, or that over the footprint of the folded
//!   bounding box across the copies' axis.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::copies::{CopiedPattern, copy_crossings, with_copies};
use super::distance::{
    bounding_sphere, closest_on_triangle, projected_gap, sphere_gap, triangle_distance,
};
use super::rotated_copy::RotatedCopyError;
use super::self_intersection::{CheckError, Checker};
use super::shapes::facet_clearance;
use super::tri_tri::Tri;
use crate::geom::{
    V3, cross, dot, fold_angle, newell_normal, norm, normalize, signed_area_2d, sub,
};
use crate::pattern::{EdgeKind, Frame, Pattern};
use crate::scene::{Containment, Copies, Obstacle, OrientedBox, Scene, TriangleMesh};
use crate::task::terms::{
    AreaKind, AreaTerm, CreaseRef, Goal, Objective, Orientation, Pointer, Requirements,
};

type V = Vector3<f64>;

/// How close a frame's t must be to a requested t to be that state.
pub const T_TOL: f64 = 1e-9;

/// The frame at `t` (within [`T_TOL`]·(1 + |t|)), if the sweep has it.
pub fn frame_at(frames: &[Frame], t: f64) -> Option<&Frame> {
    frames
        .iter()
        .find(|f| (f.t - t).abs() <= T_TOL * (1.0 + t.abs()))
}

/// One orientation requirement judged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrientationReport {
    /// Its name.
    pub name: String,
    /// The largest `|angle − wanted|` over its states (rad); `None` when no state could be
    /// measured.
    pub worst_error: Option<f64>,
    /// The state of the largest error.
    pub t: Option<f64>,
    /// Its tolerance (rad).
    pub tolerance: f64,
    /// Listed states the sweep has no frame for (each a failure).
    pub missing: Vec<f64>,
    /// Whether every listed state was measured and within the tolerance.
    pub holds: bool,
}

/// The largest fold angle of a crease (or of every crease, for `max_fold`) over the sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FoldReport {
    /// The crease as the task names it (`"tip"`, `"v1-v2"`; `"every crease"`).
    pub crease: String,
    /// The largest `|ρ|` (rad); `None` when the crease has no two facets or no state.
    pub largest: Option<f64>,
    /// Its state.
    pub t: Option<f64>,
    /// The limit (rad).
    pub max: f64,
    /// Whether the largest `|ρ|` is at most the limit.
    pub holds: bool,
}

/// A containment box judged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContainmentReport {
    /// Its name.
    pub name: String,
    /// The least signed distance of a vertex of any copy to the walls (negative outside);
    /// `None` when no state was measured.
    pub least: Option<f64>,
    /// Its state.
    pub t: Option<f64>,
    /// Which vertex (pattern index of the pattern with its copies).
    pub vertex: Option<usize>,
    /// The clearance required from the walls.
    pub clearance: f64,
    /// Whether `least ≥ clearance`.
    pub holds: bool,
}

/// An obstacle judged over the sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObstacleReport {
    /// Its name.
    pub name: String,
    /// Its shape (`"sphere"`, …).
    pub kind: String,
    /// The least clearance of any facet of any copy ([`super::shapes`]); `None` when the
    /// obstacle could not be judged (a mesh not loaded) or there was no state.
    pub least: Option<f64>,
    /// Its state.
    pub t: Option<f64>,
    /// Which facet (index into the pattern with its copies).
    pub facet: Option<usize>,
    /// Whether a facet met the solid (`least ≤ 0`).
    pub hit: bool,
    /// The clearance required.
    pub clearance: f64,
    /// Whether `least ≥ clearance`.
    pub holds: bool,
}

/// The copies judged over the sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CopiesReport {
    /// Number of arms.
    pub n: usize,
    /// Möller crossings between facets of different copies, over all states.
    pub crossings: usize,
    /// The first crossing: the two facets and the state.
    pub first: Option<(usize, usize, f64)>,
    /// The least distance between a facet of the arm and a facet of a copy sharing no
    /// vertex with it (`None`: no such pair).
    pub least_clearance: Option<f64>,
    /// Whether no crossing was found.
    pub holds: bool,
}

/// One target's distance from its goal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetDistance {
    /// The state.
    pub t: f64,
    /// The distance d_i (`None`: no frame at t, or a surface not loaded).
    pub distance: Option<f64>,
    /// Its weight.
    pub weight: f64,
}

/// The objective recomputed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetsReport {
    /// Ω = Σ w_i d_i (`None` when a distance could not be measured).
    pub omega: Option<f64>,
    /// The threshold.
    pub threshold: f64,
    /// Each target.
    pub targets: Vec<TargetDistance>,
    /// Whether Ω ≤ threshold.
    pub meets: bool,
}

/// The area term recomputed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AreaReport {
    /// What was measured.
    pub kind: AreaKind,
    /// Its value (`None`: no frame at the packing state, or a zero footprint).
    pub value: Option<f64>,
    /// The least value the target asks for.
    pub at_least: f64,
    /// Whether `value ≥ at_least`.
    pub meets: bool,
}

/// Every judge's figures for one design, and the verdict (the `requirements` object of
/// records and design files).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RequirementsReport {
    /// Per orientation requirement.
    pub orientations: Vec<OrientationReport>,
    /// `max_fold` over every crease.
    pub max_fold: Option<FoldReport>,
    /// Per fold limit.
    pub fold_limits: Vec<FoldReport>,
    /// Per containment box.
    pub containment: Vec<ContainmentReport>,
    /// Per obstacle.
    pub obstacles: Vec<ObstacleReport>,
    /// The copies (absent for one arm).
    pub copies: Option<CopiesReport>,
    /// The targets' Ω (absent without targets).
    pub targets: Option<TargetsReport>,
    /// The area term (absent without one).
    pub area: Option<AreaReport>,
    /// What failed, one line each (requirements, then targets and area).
    pub failed: Vec<String>,
    /// Whether every requirement holds (orientations, fold limits, boxes, obstacles,
    /// copies); the target is [`RequirementsReport::meets_target`].
    pub holds: bool,
}

impl RequirementsReport {
    /// Whether the requirements hold and the targets (Ω ≤ threshold) and area term
    /// (≥ at_least) are met, where the task has them.
    pub fn meets_target(&self) -> bool {
        self.holds
            && self.targets.as_ref().is_none_or(|t| t.meets)
            && self.area.as_ref().is_none_or(|a| a.meets)
    }
}

/// The least of a running minimum, with its state and place.
#[derive(Clone, Copy, Debug)]
struct Least {
    value: f64,
    t: f64,
    at: usize,
}

impl Least {
    fn offer(slot: &mut Option<Least>, value: f64, t: f64, at: usize) {
        if slot.is_none_or(|l| value < l.value) {
            *slot = Some(Least { value, t, at });
        }
    }
}

/// The folded direction an orientation is about: the crease `tail → head`, or the unit
/// normal of the facet left (traversing `tail → head`) or right of it. `None` when the
/// facet does not exist or the direction is degenerate.
pub fn pointer_direction(
    pattern: &Pattern,
    coords: &[[f64; 3]],
    of: Pointer,
    tail: usize,
    head: usize,
) -> Option<V3> {
    match of {
        Pointer::Crease => normalize(sub(coords[head], coords[tail])),
        Pointer::FacetLeft | Pointer::FacetRight => {
            let (p, q) = if of == Pointer::FacetLeft {
                (tail, head)
            } else {
                (head, tail)
            };
            let f = facet_along(pattern, p, q)?;
            let pts: Vec<V3> = pattern.faces[f].iter().map(|&v| coords[v]).collect();
            normalize(newell_normal(&pts))
        }
    }
}

/// The facet that traverses the directed edge `p → q` (the one left of it).
pub fn facet_along(pattern: &Pattern, p: usize, q: usize) -> Option<usize> {
    pattern
        .faces
        .iter()
        .position(|f| (0..f.len()).any(|k| f[k] == p && f[(k + 1) % f.len()] == q))
}

/// The angle between two unit vectors (rad, in [0, π]).
fn angle(a: V3, b: V3) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Judge an orientation requirement on the arm (`tail → head`: the crease into its
/// vertex, pattern indices).
pub fn judge_orientation(
    arm: &Pattern,
    o: &Orientation,
    tail: usize,
    head: usize,
) -> OrientationReport {
    let mut worst: Option<(f64, f64)> = None;
    let mut missing = Vec::new();
    let reference = normalize(o.direction).unwrap_or(o.direction);
    for &t in &o.t {
        let dir = frame_at(&arm.frames, t)
            .and_then(|fr| pointer_direction(arm, &fr.coords, o.of, tail, head));
        match dir {
            Some(d) => {
                let err = (angle(d, reference) - o.angle).abs();
                if worst.is_none_or(|(w, _)| err > w) {
                    worst = Some((err, t));
                }
            }
            None => missing.push(t),
        }
    }
    OrientationReport {
        name: o.name.clone(),
        worst_error: worst.map(|w| w.0),
        t: worst.map(|w| w.1),
        tolerance: o.tolerance,
        holds: missing.is_empty() && worst.is_some_and(|(w, _)| w <= o.tolerance),
        missing,
    }
}

/// The fold angle of the crease `p → q` (valley positive) in `coords`, from the normals of
/// the facets left and right of it; `None` when it is not a crease between two facets.
pub fn crease_fold_angle(
    pattern: &Pattern,
    coords: &[[f64; 3]],
    p: usize,
    q: usize,
) -> Option<f64> {
    let left = facet_along(pattern, p, q)?;
    let right = facet_along(pattern, q, p)?;
    let pts = |f: usize| -> Vec<V3> { pattern.faces[f].iter().map(|&v| coords[v]).collect() };
    fold_angle(coords[p], coords[q], &pts(left), &pts(right))
}

/// The largest `|ρ|` over the sweep of the creases `(p, q)` named `crease`, against `max`.
pub fn judge_folds(
    arm: &Pattern,
    creases: &[(usize, usize)],
    crease: &str,
    max: f64,
) -> FoldReport {
    let mut largest: Option<(f64, f64)> = None;
    let mut measured = !creases.is_empty();
    for fr in &arm.frames {
        for &(p, q) in creases {
            match crease_fold_angle(arm, &fr.coords, p, q) {
                Some(rho) => {
                    if largest.is_none_or(|(l, _)| rho.abs() > l) {
                        largest = Some((rho.abs(), fr.t));
                    }
                }
                None => measured = false,
            }
        }
    }
    FoldReport {
        crease: crease.to_string(),
        largest: largest.map(|l| l.0),
        t: largest.map(|l| l.1),
        max,
        holds: measured && largest.is_some_and(|(l, _)| l <= max),
    }
}

/// Every crease of the pattern between two facets, as `(tail, head)`.
pub fn creases(pattern: &Pattern) -> Vec<(usize, usize)> {
    pattern
        .edges
        .iter()
        .filter(|e| matches!(e.kind, EdgeKind::Crease { .. }))
        .map(|e| (e.v[0], e.v[1]))
        .filter(|&(p, q)| {
            facet_along(pattern, p, q).is_some() && facet_along(pattern, q, p).is_some()
        })
        .collect()
}

/// Signed distance of `p` to the walls of `b`: inside, the least distance to a face
/// (positive); outside, minus the distance to the box.
pub fn box_wall_distance(b: &OrientedBox, p: V3) -> f64 {
    let q = b.local(p);
    let out: Vec<f64> = (0..3).map(|i| q[i].abs() - b.half[i]).collect();
    if out.iter().all(|d| *d <= 0.0) {
        -out.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    } else {
        -out.iter().map(|d| d.max(0.0).powi(2)).sum::<f64>().sqrt()
    }
}

/// Judge a containment box on the pattern with its copies (`all`: every vertex of every
/// copy), at its state or at every state.
pub fn judge_containment(all: &Pattern, c: &Containment, clearance: f64) -> ContainmentReport {
    let frames: Vec<&Frame> = match c.t {
        Some(t) => frame_at(&all.frames, t).into_iter().collect(),
        None => all.frames.iter().collect(),
    };
    let mut least = None;
    for fr in &frames {
        for (v, p) in fr.coords.iter().enumerate() {
            Least::offer(&mut least, box_wall_distance(&c.bounds, *p), fr.t, v);
        }
    }
    ContainmentReport {
        name: c.name.clone(),
        least: least.map(|l| l.value),
        t: least.map(|l| l.t),
        vertex: least.map(|l| l.at),
        clearance,
        holds: least.is_some_and(|l| l.value >= clearance),
    }
}

/// The triangles of every facet at `coords`.
fn facet_triangles(checker: &Checker, coords: &[[f64; 3]]) -> Vec<Vec<Tri>> {
    checker
        .triangles()
        .iter()
        .map(|ts| ts.iter().map(|ix| ix.map(|i| V::from(coords[i]))).collect())
        .collect()
}

/// Judge every obstacle on the pattern with its copies over its frames.
pub fn judge_obstacles(
    all: &Pattern,
    obstacles: &[Obstacle],
    clearance: f64,
) -> Result<Vec<ObstacleReport>, CheckError> {
    let checker = Checker::from_pattern(all)?;
    let mut least: Vec<Option<Least>> = vec![None; obstacles.len()];
    let mut judged = vec![true; obstacles.len()];
    for fr in &all.frames {
        checker.validate_state(&fr.coords, fr.t)?;
        let tris = facet_triangles(&checker, &fr.coords);
        for (k, ob) in obstacles.iter().enumerate() {
            for (f, ts) in tris.iter().enumerate() {
                match facet_clearance(&ob.shape, ts) {
                    Some(d) => Least::offer(&mut least[k], d, fr.t, f),
                    None => judged[k] &= ts.is_empty(),
                }
            }
        }
    }
    Ok(obstacles
        .iter()
        .zip(least.iter().zip(judged))
        .map(|(ob, (l, ok))| {
            let l = l.filter(|_| ok);
            ObstacleReport {
                name: ob.name.clone(),
                kind: ob.kind().to_string(),
                least: l.map(|l| l.value),
                t: l.map(|l| l.t),
                facet: l.map(|l| l.at),
                hit: l.is_some_and(|l| l.value <= 0.0),
                clearance,
                holds: l.is_some_and(|l| l.value >= clearance),
            }
        })
        .collect())
}

/// Judge the copies: crossings between copies, and the least distance between a facet of
/// the arm and one of a copy sharing no vertex with it.
pub fn judge_copies(copied: &CopiedPattern, n: usize) -> Result<CopiesReport, CheckError> {
    let crossings = copy_crossings(copied)?;
    let pat = &copied.pattern;
    let checker = Checker::from_pattern(pat)?;
    let arm = copied.arm_faces.min(pat.faces.len());
    let apart: Vec<(usize, usize)> = (0..arm)
        .flat_map(|a| (arm..pat.faces.len()).map(move |b| (a, b)))
        .filter(|&(a, b)| !pat.faces[a].iter().any(|v| pat.faces[b].contains(v)))
        .collect();
    let mut least: Option<f64> = None;
    for fr in &pat.frames {
        let tris = facet_triangles(&checker, &fr.coords);
        // Spheres rule out the pairs that cannot beat the least so far; taking the pairs
        // nearest by their spheres first, the first gap past the least ends the frame. The
        // answer is the same as testing every pair.
        let spheres: Vec<Vec<(V, f64)>> = tris
            .iter()
            .map(|ts| ts.iter().map(bounding_sphere).collect())
            .collect();
        let mut near: Vec<(f64, &Tri, &Tri)> = Vec::new();
        for &(a, b) in &apart {
            for (ta, &sa) in tris[a].iter().zip(&spheres[a]) {
                for (tb, &sb) in tris[b].iter().zip(&spheres[b]) {
                    let gap = sphere_gap(sa, sb);
                    if least.is_none_or(|l| gap <= l) {
                        near.push((gap, ta, tb));
                    }
                }
            }
        }
        near.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (gap, ta, tb) in near {
            if least.is_some_and(|l| gap > l) {
                break;
            }
            if least.is_some_and(|l| projected_gap(ta, tb) > l) {
                continue;
            }
            let d = triangle_distance(ta, tb);
            least = Some(least.map_or(d, |l| l.min(d)));
        }
    }
    Ok(CopiesReport {
        n,
        holds: crossings.is_empty(),
        first: crossings.first().map(|x| (x.face_a, x.face_b, x.t)),
        crossings: crossings.len(),
        least_clearance: least,
    })
}

/// Distance of `x` from a goal (surfaces: the meshes of `objective.surfaces`, `None` when
/// not loaded).
pub fn goal_distance(goal: &Goal, x: V3, surfaces: &[Option<&TriangleMesh>]) -> Option<f64> {
    Some(match *goal {
        Goal::Point { point } => norm(sub(x, point)),
        Goal::Line { point, direction } => {
            let w = sub(x, point);
            let u = normalize(direction)?;
            norm(sub(w, crate::geom::scale(u, dot(w, u))))
        }
        Goal::Plane { point, normal } => dot(normalize(normal)?, sub(x, point)).abs(),
        Goal::Surface { index } => {
            let mesh = (*surfaces.get(index)?)?;
            let p = V::from(x);
            (0..mesh.triangles.len())
                .map(|i| {
                    let t = mesh.triangle(i).map(V::from);
                    (p - closest_on_triangle(&p, &t)).norm()
                })
                .fold(f64::INFINITY, f64::min)
        }
    })
}

/// Recompute Ω on the arm: `vertices[i]` is target i's vertex (pattern index).
pub fn judge_targets(arm: &Pattern, objective: &Objective, vertices: &[usize]) -> TargetsReport {
    let surfaces: Vec<Option<&TriangleMesh>> =
        objective.surfaces.iter().map(|m| m.triangles()).collect();
    let targets: Vec<TargetDistance> = objective
        .targets
        .iter()
        .enumerate()
        .map(|(i, tg)| {
            let x = vertices
                .get(i)
                .and_then(|&v| frame_at(&arm.frames, tg.t)?.coords.get(v).copied());
            TargetDistance {
                t: tg.t,
                distance: x.and_then(|x| goal_distance(&tg.goal, x, &surfaces)),
                weight: tg.weight,
            }
        })
        .collect();
    let omega = targets
        .iter()
        .map(|d| d.distance.map(|x| d.weight * x))
        .sum::<Option<f64>>();
    TargetsReport {
        omega,
        threshold: objective.threshold,
        meets: omega.is_some_and(|o| o <= objective.threshold),
        targets,
    }
}

/// The flat area of the arm (shoelace over its facets) times the copies.
pub fn flat_area(arm: &Pattern, n: usize) -> f64 {
    let a: f64 = arm
        .faces
        .iter()
        .map(|f| {
            let pts: Vec<[f64; 2]> = f.iter().map(|&v| arm.vertices[v]).collect();
            signed_area_2d(&pts).abs()
        })
        .sum();
    a * n.max(1) as f64
}

/// Two unit vectors spanning the plane normal to the copies' axis: x and y for the z-axis,
/// else `e1 = normalize(axis × x)` (or `× y` when the axis is near x) and `e2 = axis × e1`.
pub fn footprint_axes(copies: &Copies) -> (V3, V3) {
    let u = copies.direction;
    if u == [0.0, 0.0, 1.0] {
        return ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    }
    let seed = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = normalize(cross(u, seed)).unwrap_or(seed);
    (e1, cross(u, e1))
}

/// The area term of an arm whose pattern with copies is `all`.
pub fn judge_area(arm: &Pattern, all: &Pattern, copies: &Copies, term: &AreaTerm) -> AreaReport {
    let flat = flat_area(arm, copies.n);
    let value = match term.kind {
        AreaKind::Flat => Some(flat),
        AreaKind::Packing { t } => frame_at(&all.frames, t).and_then(|fr| {
            let (e1, e2) = footprint_axes(copies);
            let extent = |e: V3| {
                let s = fr.coords.iter().map(|p| dot(*p, e));
                s.clone().fold(f64::NEG_INFINITY, f64::max) - s.fold(f64::INFINITY, f64::min)
            };
            let foot = extent(e1) * extent(e2);
            (foot > 0.0).then(|| flat / foot)
        }),
    };
    AreaReport {
        kind: term.kind,
        value,
        at_least: term.at_least,
        meets: value.is_some_and(|v| v >= term.at_least),
    }
}

/// What the search passes to [`judge`] for one design: plain numbers and resolved indices.
#[derive(Clone, Debug)]
pub struct JudgeInput<'a> {
    /// The arm with its frames: the dense sweep, and a frame at every t the orientations,
    /// targets, boxes and the packing term name (a listed t without a frame fails).
    pub arm: &'a Pattern,
    /// The scene (obstacles, copies, boxes).
    pub scene: &'a Scene,
    /// The requirements.
    pub requirements: &'a Requirements,
    /// The objective, when its targets and area term are to be recomputed.
    pub objective: Option<&'a Objective>,
    /// Per `requirements.orientations[i]`: the crease `(tail, head)` into its vertex
    /// (pattern indices; `model::select`).
    pub orientation_creases: Vec<(usize, usize)>,
    /// Per `requirements.fold_limits[i]`: the crease's end vertices `(tail, head)`.
    pub fold_limit_creases: Vec<(usize, usize)>,
    /// Per `objective.targets[i]`: its vertex (pattern index).
    pub target_vertices: Vec<usize>,
    /// The task's `obstacle_clearance`: what obstacles and box walls are kept off by.
    pub obstacle_clearance: f64,
}

/// Why the judges could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JudgeError {
    /// The pattern could not be checked (triangulation, state sizes).
    #[error(transparent)]
    Check(#[from] CheckError),
    /// The copies could not be built.
    #[error(transparent)]
    Copies(#[from] RotatedCopyError),
    /// The resolved indices do not match the task's terms.
    #[error("{0}")]
    Indices(String),
}

/// A crease as the task names it.
fn crease_name(c: &CreaseRef) -> String {
    match c {
        CreaseRef::Into(v) => v.to_string(),
        CreaseRef::Initial { name, .. } => name.clone(),
    }
}

/// Whether every index is a vertex of the arm and each list matches its terms.
fn check_indices(input: &JudgeInput<'_>) -> Result<(), JudgeError> {
    let nv = input.arm.vertices.len();
    let counts = [
        (
            "orientation_creases",
            input.orientation_creases.len(),
            input.requirements.orientations.len(),
        ),
        (
            "fold_limit_creases",
            input.fold_limit_creases.len(),
            input.requirements.fold_limits.len(),
        ),
        (
            "target_vertices",
            input.target_vertices.len(),
            input.objective.map_or(0, |o| o.targets.len()),
        ),
    ];
    for (what, got, want) in counts {
        if got != want {
            return Err(JudgeError::Indices(format!(
                "{what}: {got} given for {want} terms"
            )));
        }
    }
    let all = input
        .orientation_creases
        .iter()
        .chain(&input.fold_limit_creases)
        .flat_map(|&(a, b)| [a, b])
        .chain(input.target_vertices.iter().copied());
    for v in all {
        if v >= nv {
            return Err(JudgeError::Indices(format!(
                "vertex index {v} is not a vertex of the arm ({nv} vertices)"
            )));
        }
    }
    Ok(())
}

/// Run every judge on one design (see the module docs) and collect the verdict.
pub fn judge(input: &JudgeInput<'_>) -> Result<RequirementsReport, JudgeError> {
    check_indices(input)?;
    let (arm, scene, req) = (input.arm, input.scene, input.requirements);
    let copied = with_copies(arm, &scene.copies)?;
    let all = &copied.pattern;
    let mut r = RequirementsReport {
        orientations: req
            .orientations
            .iter()
            .zip(&input.orientation_creases)
            .map(|(o, &(tail, head))| judge_orientation(arm, o, tail, head))
            .collect(),
        max_fold: req
            .max_fold
            .map(|m| judge_folds(arm, &creases(arm), "every crease", m)),
        fold_limits: req
            .fold_limits
            .iter()
            .zip(&input.fold_limit_creases)
            .map(|(l, &c)| judge_folds(arm, &[c], &crease_name(&l.crease), l.max))
            .collect(),
        containment: scene
            .containment
            .iter()
            .map(|c| judge_containment(all, c, input.obstacle_clearance))
            .collect(),
        obstacles: judge_obstacles(all, &scene.obstacles, input.obstacle_clearance)?,
        copies: (scene.copies.n > 1)
            .then(|| judge_copies(&copied, scene.copies.n))
            .transpose()?,
        targets: input
            .objective
            .filter(|o| !o.targets.is_empty())
            .map(|o| judge_targets(arm, o, &input.target_vertices)),
        area: input
            .objective
            .and_then(|o| o.area.as_ref())
            .map(|a| judge_area(arm, all, &scene.copies, a)),
        failed: Vec::new(),
        holds: false,
    };
    r.failed = failures(&r);
    r.holds = requirements_hold(&r);
    for t in r.targets.iter().filter(|t| !t.meets) {
        r.failed.push(match t.omega {
            Some(o) => format!("targets: Ω = {o:.6} > threshold {}", t.threshold),
            None => "targets: a distance could not be measured".into(),
        });
    }
    for a in r.area.iter().filter(|a| !a.meets) {
        r.failed
            .push(format!("area: {:?} below at_least {}", a.value, a.at_least));
    }
    Ok(r)
}

/// Whether every requirement (not the targets or the area) holds.
fn requirements_hold(r: &RequirementsReport) -> bool {
    r.orientations.iter().all(|o| o.holds)
        && r.max_fold.iter().chain(&r.fold_limits).all(|f| f.holds)
        && r.containment.iter().all(|c| c.holds)
        && r.obstacles.iter().all(|o| o.holds)
        && r.copies.as_ref().is_none_or(|c| c.holds)
}

/// One line per requirement that does not hold.
fn failures(r: &RequirementsReport) -> Vec<String> {
    let mut out = Vec::new();
    let fig = |x: Option<f64>| x.map_or("not measured".to_string(), |v| format!("{v:.6}"));
    for o in r.orientations.iter().filter(|o| !o.holds) {
        out.push(if o.missing.is_empty() {
            format!(
                "orientation {}: error {} rad > tolerance {} (t = {:?})",
                o.name,
                fig(o.worst_error),
                o.tolerance,
                o.t
            )
        } else {
            format!(
                "orientation {}: no folded state at t = {:?}",
                o.name, o.missing
            )
        });
    }
    for f in r.max_fold.iter().chain(&r.fold_limits).filter(|f| !f.holds) {
        out.push(format!(
            "fold limit {}: |ρ| {} > {} (t = {:?})",
            f.crease,
            fig(f.largest),
            f.max,
            f.t
        ));
    }
    for c in r.containment.iter().filter(|c| !c.holds) {
        out.push(format!(
            "inside {}: {} from the walls < {} (t = {:?})",
            c.name,
            fig(c.least),
            c.clearance,
            c.t
        ));
    }
    for o in r.obstacles.iter().filter(|o| !o.holds) {
        out.push(format!(
            "obstacle {} ({}): clearance {} < {} (t = {:?})",
            o.name,
            o.kind,
            fig(o.least),
            o.clearance,
            o.t
        ));
    }
    if let Some(c) = r.copies.as_ref().filter(|c| !c.holds) {
        out.push(format!(
            "copies: {} crossings between the {} arms, first {:?}",
            c.crossings, c.n, c.first
        ));
    }
    out
}
