//! Cross-validation: the bar-and-hinge simulator against the PTU (issue 8, thesis Sec. 3
//! against Sec. 4–5).
//!
//! A PTU design comes as a [`Pattern`]: its flat layout, its facets and the folded frames
//! the model computed. The simulator gets the same flat layout and facets, and the motion
//! the PTU prescribes for the design task's actuation (SPEC §4), [`G0Drive`]:
//!
//! * a symmetric fold (the gripper's one crease): the two ends of the driven crease stay at
//!   their flat positions; every vertex of the facet left of the crease (tail → head)
//!   turns by +ρ(t)/2 about the crease, every vertex of the facet right of it by −ρ(t)/2;
//! * a driven central facet (`grammar/flasher_cuboid.toml`, `grammar/star.toml`): the
//!   fixed facet's vertices stay at their flat positions; across each driven crease (each
//!   side's two halves), the facet turns by that crease's ρ(t) about it;
//! * every other vertex is free: only the bars place it.
//!
//! Both are one list of prescribed facets with their rigid maps
//! ([`G0Drive::prescribed_facets`]); a vertex on several (a corner of the central facet,
//! a side's midpoint) is fixed when one of them keeps it, and must be placed alike by all.
//!
//! Why trajectories and not crease drives: the PTU *defines* the maps of those facets as
//! exactly these rotations ([`crate::model::geometry::fold`]), so prescribing their
//! vertices is exact, adds no approximation, and leaves the simulated states in the PTU's
//! own frame — positions compare directly, without aligning frames. A crease drive of the
//! symmetric fold would move the whole pattern by the rigid motion Rot(−ρ/2) relative to
//! the PTU, exact too, but only after an alignment that could hide an error of its own.
//!
//! The flat state is a bifurcation (every crease can start either way), so the first step
//! starts from the PTU's own first state ([`SimInput::first_step_offsets`] = X(t₁) − X(0)
//! for the free vertices); from there continuation follows the branch.
//!
//! Then every simulated state j ≥ 1 whose t has a frame is compared with it: the largest
//! distance between a simulated vertex and the PTU's. Tolerances, [`GAMMA_TOL`] and
//! [`POSITION_TOL`], are explained where they are defined.
//!
//! ```no_run
//! use foldsynth::grammar::CreaseGraph;
//! use foldsynth::model::Model;
//! use foldsynth::simulate::crossval::{CrossvalOptions, crossval_design};
//! use foldsynth::task::Task;
//! let task = Task::load(std::path::Path::new("grammar/gripper.toml")).unwrap();
//! let graph = CreaseGraph::from_sequence(&task, "2").unwrap();
//! let model = Model::new(&graph, &task, 0).unwrap();
//! let mid: Vec<f64> = model.free.iter().map(|&i| {
//!     let (lo, hi) = model.var_bounds(i);
//!     0.5 * (lo + hi)
//! }).collect();
//! let r = crossval_design(&model, model.full_vars(&mid), vec![1.0], 30,
//!                         &CrossvalOptions::default()).unwrap();
//! println!("Γ = {:e}, max |x − X_PTU| = {:e}", r.gamma, r.max_position_error);
//! ```

use std::sync::Arc;

use nalgebra::{Rotation3, Unit, Vector3};
use serde::Serialize;
use thiserror::Error;

use super::input::{AngleFn, Drive, PathFn, SimInput, SolverSettings};
use super::run::{RIGID_DELTA, SimError, SimReport, simulate_with_checker};
use super::solver::{Bars, jacobian};
use crate::check::{CheckError, Checker};
use crate::geom;
use crate::model::Model;
use crate::model::numeric::{Evaluated, sample_times};
use crate::pattern::{EdgeKind, Pattern};

/// Largest Γ (Eq. 4, squared-length units) of a design that folds rigidly. A rigid step
/// converges to rounding (δ ~ 1e-15 … 1e-13 on the gripper's designs); the issue's 1e-8
/// leaves room for ill-conditioned states near a vertex's rigid limit (Eq. 33 keeps
/// optimized designs 1e-8 inside it), and sits four orders below the thesis's 1e-4.
pub const GAMMA_TOL: f64 = 1e-8;

/// Largest distance between a simulated and a PTU vertex (paper units: G0's crease has
/// length 1). The two are solved independently to rounding, but positions inherit the
/// conditioning of the state: where a vertex's unit triangle is nearly degenerate (close
/// to the rigid limit, or to the flat state) a bar residual ε moves a vertex by up to
/// ~√ε, i.e. ~1e-8 for ε ~ 1e-15 … 1e-16. 1e-7 is a decade above that and far below any
/// geometric difference a wrong branch or a wrong kinematics would make (≥ 1e-3).
pub const POSITION_TOL: f64 = 1e-7;

/// Most a position tolerance is widened to at an ill-conditioned state (see
/// [`widened_tolerance`]): branches that differ by more are told apart whatever the bound.
pub const MAX_WIDENED_TOL: f64 = 1e-3;

/// The position tolerance at a state with the simulation's error bound `bound`
/// ([`StateComparison::error_bound`]): `position_tol`, or twice the bound where that is
/// larger (first order, hence the factor), but never above [`MAX_WIDENED_TOL`].
///
/// Why: a design may end a hair short of a vertex's rigid limit (Eq. 33 keeps only 1e-8),
/// and there the bar Jacobian is nearly singular (σ_min ~ 1e-7 on the gripper's
/// g06-c2-uu at t_max, against ~1 elsewhere). Levenberg–Marquardt on its normal
/// equations (condition σ_max²/σ_min² ~ 1e15) then stops at residuals ~1e-10, which leave
/// the vertices ~‖r‖/σ_min ~ 1e-4 from the exact state: the bars do not say more there,
/// and the PTU's state is within that reach.
pub fn widened_tolerance(position_tol: f64, bound: Option<f64>) -> f64 {
    match bound {
        Some(b) if b.is_finite() => position_tol.max((2.0 * b).min(MAX_WIDENED_TOL)),
        _ => position_tol,
    }
}

/// Two values of t name the same state when they differ by at most this (relative).
const SAME_T: f64 = 1e-9;

/// Why a cross-validation could not run.
#[derive(Debug, Error)]
pub enum CrossvalError {
    /// No edge is marked as the driven crease.
    #[error(
        "no crease is marked as driven (a foldsynth design marks G0's crease; name it with --driven EDGE)"
    )]
    NoDrivenCrease,
    /// Several edges are marked driven, but neither on one line between the same two
    /// facets (a symmetric fold) nor all bounding one facet (a fixed central facet).
    #[error(
        "edges {0:?} are all marked as driven, but they neither lie between the same two facets nor all bound one facet that could stay fixed (name one crease with --driven EDGE)"
    )]
    SeveralDrivenCreases(Vec<usize>),
    /// The fixed facet does not exist.
    #[error("facet {face} does not exist (the pattern has {count} facets, 0-based)")]
    FaceOutOfRange {
        /// The facet asked for.
        face: usize,
        /// Number of facets.
        count: usize,
    },
    /// A driven crease of a fixed-facet actuation does not bound the fixed facet.
    #[error("driven crease {edge} does not bound the fixed facet {face}")]
    NotOnFixedFacet {
        /// The crease.
        edge: usize,
        /// The fixed facet.
        face: usize,
    },
    /// Two prescribed facets would put one vertex at different places.
    #[error(
        "vertex {vertex} is moved differently by prescribed facet {face} (by {gap:e} at the end of the motion): the driven creases do not move the paper consistently"
    )]
    ConflictingPrescription {
        /// The vertex.
        vertex: usize,
        /// The facet that disagrees with the vertex's first prescription.
        face: usize,
        /// Distance between the two places at t_end.
        gap: f64,
    },
    /// The driven edge does not exist.
    #[error("edge {edge} does not exist (the pattern has {count} edges, 0-based)")]
    EdgeOutOfRange {
        /// The edge asked for.
        edge: usize,
        /// Number of edges.
        count: usize,
    },
    /// The driven edge is a side of the paper.
    #[error("edge {0} is a boundary edge, not a crease")]
    BoundaryEdge(usize),
    /// The driven crease does not have one facet on each side.
    #[error(
        "crease {edge} ({tail}→{head}) must have exactly one facet on each side; found {left} traversing {tail}→{head} and {right} traversing {head}→{tail}"
    )]
    NotBetweenTwoFacets {
        /// The edge.
        edge: usize,
        /// Its tail.
        tail: usize,
        /// Its head.
        head: usize,
        /// Facets traversing tail → head.
        left: usize,
        /// Facets traversing head → tail.
        right: usize,
    },
    /// The drive does not start flat (the simulation starts from the flat layout).
    #[error(
        "the driven crease's fold angle at t_start = {t_start} is {angle} rad; the simulation starts from the flat layout, so it must be 0"
    )]
    NotFlatAtStart {
        /// Start of the motion.
        t_start: f64,
        /// The fold angle there.
        angle: f64,
    },
    /// The fold angle cannot be read from the frames.
    #[error("{0}")]
    Angle(String),
    /// The range of t is missing or empty.
    #[error("{0}")]
    Motion(String),
    /// The facets cannot be checked for intersection.
    #[error("intersection check: {0}")]
    Check(#[from] CheckError),
    /// The simulation failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// One driven crease of the design task's actuation (SPEC §4): edge `edge` of the pattern,
/// run tail → head (`edges[edge].v[0] → v[1]`), folded to `angle(t)`.
#[derive(Clone)]
pub struct DrivenCrease {
    /// Index into [`Pattern::edges`].
    pub edge: usize,
    /// The fold angle ρ(t), valley positive; ρ(t_start) must be 0.
    pub angle: AngleFn,
    /// Where the angle comes from, for reports (`t`, a formula, "frames").
    pub source: String,
}

impl std::fmt::Debug for DrivenCrease {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DrivenCrease")
            .field("edge", &self.edge)
            .field("source", &self.source)
            .finish_non_exhaustive()
    }
}

impl DrivenCrease {
    /// Crease `edge` with the fold angle its frames show: `ρ(t) = t` when every frame has
    /// exactly that (the design tasks' `drive = "t"`, then exact at every t); otherwise the
    /// piecewise-linear interpolation of the frames' angles (exact at the frames, which are
    /// the states compared; between them it only guides the solver's trial half steps).
    pub fn from_frames(pattern: &Pattern, edge: usize) -> Result<DrivenCrease, CrossvalError> {
        check_edge(pattern, edge)?;
        let mut pts: Vec<(f64, f64)> = pattern
            .frames
            .iter()
            .filter_map(|f| f.fold_angles.get(edge).map(|&a| (f.t, a)))
            .collect();
        if pts.is_empty() {
            return Err(CrossvalError::Angle(format!(
                "the pattern has no frames with a fold angle for crease {edge}; give the angle as a formula in t (--angle)"
            )));
        }
        if pts.iter().any(|(t, a)| !t.is_finite() || !a.is_finite()) {
            return Err(CrossvalError::Angle(
                "a frame has a non-finite t or fold angle".into(),
            ));
        }
        if pts
            .iter()
            .all(|(t, a)| (a - t).abs() <= SAME_T * t.abs().max(1.0))
        {
            return Ok(DrivenCrease {
                edge,
                angle: Arc::new(|t| t),
                source: "t".into(),
            });
        }
        if pts.len() < 2 {
            return Err(CrossvalError::Angle(format!(
                "one frame cannot define the fold angle of crease {edge} over the motion; give it as a formula in t (--angle)"
            )));
        }
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if pts.windows(2).any(|w| w[1].0 <= w[0].0) {
            return Err(CrossvalError::Angle(
                "two frames have the same t; the fold angle cannot be interpolated".into(),
            ));
        }
        // Frames store angles wrapped into (−π, π]: unwrap so the interpolation is continuous.
        for k in 1..pts.len() {
            let prev = pts[k - 1].1;
            let tau = std::f64::consts::TAU;
            pts[k].1 -= tau * ((pts[k].1 - prev) / tau).round();
        }
        Ok(DrivenCrease {
            edge,
            angle: Arc::new(move |t| interpolate(&pts, t)),
            source: "frames (interpolated)".into(),
        })
    }
}

/// The design task's actuation (SPEC §4, `model::plan::Actuation`): how the driven creases
/// move the paper.
#[derive(Clone, Debug)]
pub enum G0Drive {
    /// One crease folded mirror-symmetrically (the gripper's G0): the facet left of it
    /// (tail → head) turns by +ρ(t)/2 about it, the facet right of it by −ρ(t)/2.
    Symmetric(DrivenCrease),
    /// A facet that stays in place (a driven central facet, thesis Sec. 3.4, 4.3) and the
    /// driven creases that bound it: across each, the other facet turns by that crease's
    /// ρ(t) about it, +ρ about tail → head when it lies left of the crease, −ρ when right
    /// (`model::geometry::fold`: crossing a crease from its right facet to its left turns
    /// by +ρ).
    Fixed {
        /// The fixed facet (index into [`Pattern::faces`]).
        face: usize,
        /// Every driven crease; each has `face` on one side.
        creases: Vec<DrivenCrease>,
    },
}

impl G0Drive {
    /// The edges of `pattern` marked as driven creases (at least one).
    pub fn marked_edges(pattern: &Pattern) -> Result<Vec<usize>, CrossvalError> {
        let driven = pattern.driven_edges();
        if driven.is_empty() {
            return Err(CrossvalError::NoDrivenCrease);
        }
        Ok(driven)
    }

    /// The actuation of a pattern with these driven creases, read as the task language
    /// reads G0 (docs/tasks.md, `initial_graph.fixed`): one crease, or several between the
    /// same two facets (one line split at degree-2 vertices), folds symmetrically by the
    /// first crease's angle; several that all bound one facet keep that facet fixed.
    pub fn of_creases(
        pattern: &Pattern,
        creases: Vec<DrivenCrease>,
    ) -> Result<G0Drive, CrossvalError> {
        let edges: Vec<usize> = creases.iter().map(|c| c.edge).collect();
        for &e in &edges {
            check_edge(pattern, e)?;
        }
        let bounds_all = |f: &Vec<usize>| {
            edges.iter().all(|&e| {
                let [p, q] = pattern.edges[e].v;
                traverses(f, p, q) || traverses(f, q, p)
            })
        };
        let common: Vec<usize> = (0..pattern.faces.len())
            .filter(|&f| bounds_all(&pattern.faces[f]))
            .collect();
        let mut creases = creases;
        match (creases.len(), common.as_slice()) {
            (0, _) => Err(CrossvalError::NoDrivenCrease),
            (1, _) | (_, [_, _]) => Ok(G0Drive::Symmetric(creases.swap_remove(0))),
            (_, [face]) => Ok(G0Drive::Fixed {
                face: *face,
                creases,
            }),
            _ => Err(CrossvalError::SeveralDrivenCreases(edges)),
        }
    }

    /// The actuation of `pattern`'s marked creases ([`G0Drive::of_creases`]) with the fold
    /// angles its frames show ([`DrivenCrease::from_frames`]).
    pub fn from_frames(pattern: &Pattern) -> Result<G0Drive, CrossvalError> {
        let creases = G0Drive::marked_edges(pattern)?
            .into_iter()
            .map(|e| DrivenCrease::from_frames(pattern, e))
            .collect::<Result<Vec<_>, _>>()?;
        G0Drive::of_creases(pattern, creases)
    }

    /// The driven creases (the symmetric fold's one first).
    pub fn creases(&self) -> &[DrivenCrease] {
        match self {
            G0Drive::Symmetric(c) => std::slice::from_ref(c),
            G0Drive::Fixed { creases, .. } => creases,
        }
    }

    /// The fixed facet, if any.
    pub fn fixed_face(&self) -> Option<usize> {
        match self {
            G0Drive::Symmetric(_) => None,
            G0Drive::Fixed { face, .. } => Some(*face),
        }
    }

    /// Where the angles come from: the one source, or every crease's where they differ.
    pub fn source(&self) -> String {
        let all: Vec<&str> = self.creases().iter().map(|c| c.source.as_str()).collect();
        if all.iter().all(|s| *s == all[0]) {
            all[0].to_string()
        } else {
            all.join("; ")
        }
    }

    /// The facets this actuation moves, each with its rigid motion (see
    /// [`PrescribedFacet`]): the symmetric fold's two, or the fixed facet and the facet
    /// across each driven crease.
    pub fn prescribed_facets(
        &self,
        pattern: &Pattern,
    ) -> Result<Vec<PrescribedFacet>, CrossvalError> {
        match self {
            G0Drive::Symmetric(c) => {
                let [left, right] = facets_of(pattern, c.edge)?;
                Ok([(left, 0.5), (right, -0.5)]
                    .into_iter()
                    .map(|(face, scale)| PrescribedFacet {
                        face,
                        turn: Some(Turn::of(pattern, c, scale)),
                    })
                    .collect())
            }
            G0Drive::Fixed { face, creases } => {
                if creases.is_empty() {
                    return Err(CrossvalError::NoDrivenCrease);
                }
                if *face >= pattern.faces.len() {
                    return Err(CrossvalError::FaceOutOfRange {
                        face: *face,
                        count: pattern.faces.len(),
                    });
                }
                let mut out = vec![PrescribedFacet {
                    face: *face,
                    turn: None,
                }];
                for c in creases {
                    let [left, right] = facets_of(pattern, c.edge)?;
                    let (moving, scale) = if right == *face {
                        (left, 1.0)
                    } else if left == *face {
                        (right, -1.0)
                    } else {
                        return Err(CrossvalError::NotOnFixedFacet {
                            edge: c.edge,
                            face: *face,
                        });
                    };
                    out.push(PrescribedFacet {
                        face: moving,
                        turn: Some(Turn::of(pattern, c, scale)),
                    });
                }
                Ok(out)
            }
        }
    }
}

/// A facet whose vertices the actuation places: at its flat position (`turn` `None`) or
/// turned rigidly about a driven crease. Vertices on the crease (its two ends) stay where
/// they are; a vertex of several prescribed facets must be placed alike by all.
#[derive(Clone, Debug)]
pub struct PrescribedFacet {
    /// Index into [`Pattern::faces`].
    pub face: usize,
    /// How it turns; `None`: it stays.
    pub turn: Option<Turn>,
}

/// A rigid turn about the line `tail → head` of the flat layout (right-handed) by
/// `scale · (ρ(t) − ρ(t_start))`.
#[derive(Clone)]
pub struct Turn {
    /// The crease's first end.
    pub tail: usize,
    /// Its second end.
    pub head: usize,
    /// Multiplies the fold angle: ±1/2 for the symmetric fold, ±1 about a fixed facet.
    pub scale: f64,
    /// The crease's fold angle ρ(t).
    pub angle: AngleFn,
}

impl std::fmt::Debug for Turn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Turn")
            .field("tail", &self.tail)
            .field("head", &self.head)
            .field("scale", &self.scale)
            .finish_non_exhaustive()
    }
}

impl Turn {
    fn of(pattern: &Pattern, c: &DrivenCrease, scale: f64) -> Turn {
        let [tail, head] = pattern.edges[c.edge].v;
        Turn {
            tail,
            head,
            scale,
            angle: c.angle.clone(),
        }
    }

    /// Whether vertex `v` is on the line it turns about (one of the crease's ends).
    fn keeps(&self, v: usize) -> bool {
        v == self.tail || v == self.head
    }

    /// The path of the flat point `p` under this turn, from `t_start`.
    fn path(&self, initial: &[[f64; 3]], p: [f64; 3], t_start: f64) -> PathFn {
        let origin = Vector3::from(initial[self.tail]);
        let axis = Unit::new_normalize(Vector3::from(initial[self.head]) - origin);
        let p = Vector3::from(p) - origin;
        let (angle, sign) = (self.angle.clone(), self.scale);
        let rho0 = (self.angle)(t_start);
        // Subtract ρ(t_start) so the path starts exactly at the flat position.
        Arc::new(move |t| {
            let r = Rotation3::from_axis_angle(&axis, sign * (angle(t) - rho0));
            let x = origin + r * p;
            [x.x, x.y, x.z]
        })
    }
}

/// Piecewise-linear through `pts` (sorted by t, at least two), extended linearly.
fn interpolate(pts: &[(f64, f64)], t: f64) -> f64 {
    let k = pts.partition_point(|p| p.0 <= t).clamp(1, pts.len() - 1);
    let ((t0, a0), (t1, a1)) = (pts[k - 1], pts[k]);
    a0 + (a1 - a0) * (t - t0) / (t1 - t0)
}

fn check_edge(pattern: &Pattern, edge: usize) -> Result<(), CrossvalError> {
    let e = pattern
        .edges
        .get(edge)
        .ok_or(CrossvalError::EdgeOutOfRange {
            edge,
            count: pattern.edges.len(),
        })?;
    match e.kind {
        EdgeKind::Boundary => Err(CrossvalError::BoundaryEdge(edge)),
        EdgeKind::Crease { .. } => Ok(()),
    }
}

/// Whether facet `f` runs along `p → q`.
fn traverses(f: &[usize], p: usize, q: usize) -> bool {
    (0..f.len()).any(|k| f[k] == p && f[(k + 1) % f.len()] == q)
}

/// The facets left and right of crease `edge` (tail → head), exactly one each.
fn facets_of(pattern: &Pattern, edge: usize) -> Result<[usize; 2], CrossvalError> {
    check_edge(pattern, edge)?;
    let [tail, head] = pattern.edges[edge].v;
    let side = |p: usize, q: usize| -> Vec<usize> {
        (0..pattern.faces.len())
            .filter(|&f| traverses(&pattern.faces[f], p, q))
            .collect()
    };
    let (left, right) = (side(tail, head), side(head, tail));
    match (left.as_slice(), right.as_slice()) {
        ([l], [r]) => Ok([*l, *r]),
        _ => Err(CrossvalError::NotBetweenTwoFacets {
            edge,
            tail,
            head,
            left: left.len(),
            right: right.len(),
        }),
    }
}

/// The simulator input of `pattern` driven by `drive` over `[t_start, t_end]` in `steps`
/// steps, starting from the flat layout: the vertices of the prescribed facets
/// ([`G0Drive::prescribed_facets`]) fixed or on their turns, everything else free. No
/// branch offsets (see [`branch_offsets`]) and no intersection check; the caller adds them.
pub fn g0_input(
    pattern: &Pattern,
    drive: &G0Drive,
    t_start: f64,
    t_end: f64,
    steps: usize,
) -> Result<SimInput, CrossvalError> {
    let facets = drive.prescribed_facets(pattern)?;
    if !t_start.is_finite() || !t_end.is_finite() {
        return Err(CrossvalError::Motion(
            "the range of t must be finite".into(),
        ));
    }
    for c in drive.creases() {
        let rho0 = (c.angle)(t_start);
        if rho0.is_nan() || rho0.abs() > 1e-12 {
            return Err(CrossvalError::NotFlatAtStart {
                t_start,
                angle: rho0,
            });
        }
    }
    let initial = pattern.flat_coords();
    let (fixed, drives) = prescribe(pattern, &facets, &initial, t_start, t_end)?;
    Ok(SimInput {
        initial,
        faces: pattern.faces.clone(),
        extra_bars: Vec::new(),
        fixed,
        drives,
        t_start,
        t_end,
        steps,
        first_step_offsets: Vec::new(),
        check_intersections: false,
        solver: SolverSettings::default(),
    })
}

/// Two prescriptions of one vertex agree when they differ by at most this at t_end (paper
/// units): rounding of a rotation about a line through the vertex, far below any feature.
const SAME_PLACE: f64 = 1e-9;

/// The fixed vertices and the trajectories of `facets`: a vertex that some prescribed
/// facet keeps (a static facet, or the ends of its crease) is fixed; otherwise it follows
/// the first facet that moves it. Every other facet holding it must put it at the same
/// place at t_end, or the actuation contradicts itself (an error, not a guess).
fn prescribe(
    pattern: &Pattern,
    facets: &[PrescribedFacet],
    initial: &[[f64; 3]],
    t_start: f64,
    t_end: f64,
) -> Result<(Vec<usize>, Vec<Drive>), CrossvalError> {
    let n = initial.len();
    let mut kept = vec![false; n];
    for pf in facets {
        for &v in &pattern.faces[pf.face] {
            kept[v] |= pf.turn.as_ref().is_none_or(|turn| turn.keeps(v));
        }
    }
    let fixed: Vec<usize> = (0..n).filter(|&v| kept[v]).collect();
    let mut drives = Vec::new();
    let mut paths: Vec<Option<PathFn>> = vec![None; n];
    // Facet order, then each facet's vertex order: the order the drives always had.
    for pf in facets {
        let Some(turn) = &pf.turn else { continue };
        for &v in &pattern.faces[pf.face] {
            if kept[v] || paths[v].is_some() || turn.keeps(v) {
                continue;
            }
            let path = turn.path(initial, initial[v], t_start);
            paths[v] = Some(path.clone());
            drives.push(Drive::Trajectory { vertex: v, path });
        }
    }
    for pf in facets {
        for &v in &pattern.faces[pf.face] {
            let here = match &pf.turn {
                Some(turn) if !turn.keeps(v) => turn.path(initial, initial[v], t_start)(t_end),
                _ => initial[v],
            };
            let there = paths[v].as_ref().map_or(initial[v], |p| p(t_end));
            // A NaN (a drive undefined at t_end) is left to the simulation to report.
            let gap = geom::dist(here, there);
            if gap > SAME_PLACE {
                return Err(CrossvalError::ConflictingPrescription {
                    vertex: v,
                    face: pf.face,
                    gap,
                });
            }
        }
    }
    Ok((fixed, drives))
}

/// The apex of a rigid panel: a vertex off the facet's plane joined by bars to every
/// corner of the facet.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PanelApex {
    /// Its vertex index in the simulator input (after the pattern's vertices).
    pub vertex: usize,
    /// The facet it stiffens.
    pub face: usize,
    /// Its height above the facet's centroid (the facet's RMS radius).
    pub height: f64,
}

/// Centroid + height · unit normal (Newell's, right-handed with the facet's vertex order)
/// of facet `face` at `coords`: where a rigid panel's apex is when the facet is where
/// `coords` puts it.
fn apex_at(coords: &[[f64; 3]], face: &[usize], height: f64) -> [f64; 3] {
    let pts: Vec<[f64; 3]> = face.iter().map(|&v| coords[v]).collect();
    let k = pts.len() as f64;
    let c = pts
        .iter()
        .fold([0.0; 3], |c, &p| geom::add(c, geom::scale(p, 1.0 / k)));
    let n = geom::normalize(geom::newell_normal(&pts)).unwrap_or([0.0, 0.0, 1.0]);
    geom::add(c, geom::scale(n, height))
}

/// Make every facet with more than three vertices a rigid panel: one apex vertex above
/// its centroid, joined by bars to all its corners.
///
/// Why: Eq. 2's bars on the sides and diagonals of a *flat* polygon with four or more
/// corners do not hold it flat to first order — a corner moving off the plane of three
/// others changes their bar lengths only at second order (a zero-volume tetrahedron is
/// infinitesimally flexible). The bar model then has a flex at every state, its solution
/// is pinned only to √δ or worse, and a small residual lets the facets bend: positions
/// drift by 1e-7 … 1e-3 with Γ still far below 1e-4. The apex bars make each panel a
/// first-order rigid body, so a rigidly foldable design has isolated solutions that the
/// solver finds to rounding — and a design that is not rigidly foldable cannot hide its
/// distortion in bent panels. Triangles are rigid already and get no apex.
pub fn add_panel_apexes(input: &mut SimInput) -> Vec<PanelApex> {
    let mut apexes = Vec::new();
    for (f, face) in input.faces.iter().enumerate() {
        if face.len() <= 3 {
            continue;
        }
        let k = face.len() as f64;
        let c: [f64; 3] =
            [0, 1, 2].map(|u| face.iter().map(|&v| input.initial[v][u]).sum::<f64>() / k);
        let r2 = face
            .iter()
            .map(|&v| geom::dist(input.initial[v], c).powi(2))
            .sum::<f64>()
            / k;
        let height = r2.sqrt();
        if height.is_nan() || height <= 0.0 {
            continue; // a degenerate facet: nothing to stiffen
        }
        let vertex = input.initial.len();
        input.initial.push(apex_at(&input.initial, face, height));
        for &v in face {
            input.extra_bars.push([vertex, v]);
        }
        apexes.push(PanelApex {
            vertex,
            face: f,
            height,
        });
    }
    apexes
}

/// Offsets that start the first step on the PTU's branch: for every vertex, the frame
/// after `t_start` nearest to it minus the flat position, scaled linearly to the first
/// step (exactly X(t₁) − X(0) when a frame sits at t₁); panel apexes follow their
/// facets. Empty without such a frame.
pub fn branch_offsets(
    pattern: &Pattern,
    input: &SimInput,
    apexes: &[PanelApex],
) -> Vec<(usize, [f64; 3])> {
    let dir = (input.t_end - input.t_start).signum();
    let t1 = input.t_start + (input.t_end - input.t_start) / input.steps.max(1) as f64;
    let next = pattern
        .frames
        .iter()
        .filter(|f| {
            (f.t - input.t_start) * dir > SAME_T * input.t_start.abs().max(1.0)
                && f.coords.len() == pattern.vertices.len()
        })
        .min_by(|a, b| ((a.t - input.t_start) * dir).total_cmp(&((b.t - input.t_start) * dir)));
    let Some(f) = next else {
        return Vec::new();
    };
    let s = if same_t(f.t, t1) {
        1.0
    } else {
        (t1 - input.t_start) / (f.t - input.t_start)
    };
    let mut at = f.coords.clone();
    for a in apexes {
        at.push(apex_at(&f.coords, &input.faces[a.face], a.height));
    }
    at.iter()
        .zip(&input.initial)
        .enumerate()
        .map(|(v, (x, x0))| (v, [0, 1, 2].map(|k| s * (x[k] - x0[k]))))
        .filter(|(_, o)| o.iter().all(|c| c.is_finite()))
        .collect()
}

fn same_t(a: f64, b: f64) -> bool {
    (a - b).abs() <= SAME_T * a.abs().max(b.abs()).max(1.0)
}

/// Settings of [`crossval`].
#[derive(Clone, Debug)]
pub struct CrossvalOptions {
    /// Number of steps J (default: one per frame after the first).
    pub steps: Option<usize>,
    /// End of the motion (default: the last frame's t).
    pub t_end: Option<f64>,
    /// Also measure self-intersection (θ) at every step.
    pub check_intersections: bool,
    /// Make facets with more than three vertices rigid panels ([`add_panel_apexes`])
    /// instead of Eq. 2's bars alone.
    pub rigid_panels: bool,
    /// Solver stopping rules.
    pub solver: SolverSettings,
}

impl Default for CrossvalOptions {
    fn default() -> Self {
        CrossvalOptions {
            steps: None,
            t_end: None,
            check_intersections: false,
            rigid_panels: true,
            solver: SolverSettings {
                max_iterations: 2000,
                max_correction: 0.02,
                max_refine: 18,
                ..SolverSettings::default()
            },
        }
    }
}

/// One simulated state next to the PTU's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateComparison {
    /// Step j (0 is the flat start).
    pub j: usize,
    /// t_j.
    pub t: f64,
    /// δ(j) (0 for the start).
    pub delta: f64,
    /// Largest distance between a simulated vertex and the PTU's at t_j (`None` when the
    /// pattern has no frame at t_j).
    pub position_error: Option<f64>,
    /// The simulation's own first-order error bound at this state, ‖r‖/σ_min (bar
    /// residuals r, smallest singular value of the bar Jacobian): how far from an exact
    /// solution its residual can leave the vertices. Computed only where the position
    /// error exceeds [`POSITION_TOL`].
    pub error_bound: Option<f64>,
}

/// The outcome of one cross-validation.
#[derive(Clone, Debug, Serialize)]
pub struct CrossvalReport {
    /// The (first) driven crease (edge index).
    pub driven_edge: usize,
    /// Every driven crease (edge indices).
    pub driven_edges: Vec<usize>,
    /// The facet the actuation keeps fixed (a driven central facet), if any.
    pub fixed_face: Option<usize>,
    /// Where the fold angles came from.
    pub angle_source: String,
    /// J.
    pub steps: usize,
    /// Start of the motion.
    pub t_start: f64,
    /// End of the motion.
    pub t_end: f64,
    /// Rigidity error Γ (Eq. 4).
    pub gamma: f64,
    /// Largest δ(j).
    pub max_delta: f64,
    /// Every δ(j) ≤ 1e-4 (the thesis's verdict).
    pub rigid: bool,
    /// Share of steps with a self-intersection (0 when not checked).
    pub theta: f64,
    /// Every state, with its comparison.
    pub states: Vec<StateComparison>,
    /// Number of simulated states (j ≥ 1) that had a PTU frame to compare with.
    pub compared_states: usize,
    /// Largest position error over the compared states j ≥ 1.
    pub max_position_error: f64,
    /// Compared states whose position error exceeds [`POSITION_TOL`], so that agreement
    /// rests on the widened tolerance of an ill-conditioned state ([`widened_tolerance`]).
    pub widened_states: usize,
    /// Position error at the last state, if the PTU has a frame there.
    pub final_position_error: Option<f64>,
    /// Largest distance between a prescribed vertex (of the facets the actuation moves or
    /// fixes) and the PTU's frame: how exactly the drive reproduces the PTU's actuation.
    pub drive_error: f64,
    /// Largest distance between the PTU's frame at t_start and the flat layout the
    /// simulation starts from (the PTU's own rounding at the flat, singular state).
    pub start_gap: Option<f64>,
    /// Rigid-panel apexes added (0 with Eq. 2's bars alone); their vertices follow the
    /// pattern's in the simulated states.
    pub panel_apexes: usize,
    /// Free vertices of the simulation (apexes included).
    pub free_vertices: usize,
    /// Bars.
    pub bars: usize,
    /// The simulation itself.
    #[serde(skip)]
    pub sim: SimReport,
}

impl CrossvalReport {
    /// Γ ≤ `gamma_tol`, at least the final state compared, and every compared state within
    /// `position_tol`, or, at an ill-conditioned state, within [`widened_tolerance`] of its
    /// error bound.
    pub fn agrees(&self, gamma_tol: f64, position_tol: f64) -> bool {
        self.gamma <= gamma_tol
            && self.max_position_error.is_finite()
            && self.drive_error.is_finite()
            && self.final_position_error.is_some_and(f64::is_finite)
            && self
                .states
                .iter()
                .filter(|s| s.j > 0)
                .all(|s| match s.position_error {
                    None => true,
                    Some(e) => e <= widened_tolerance(position_tol, s.error_bound),
                })
    }
}

/// Simulate `pattern` under `drive` and compare with its frames (see the module docs).
///
/// The motion runs from the first frame's t (0 without frames) to `opts.t_end` or the last
/// frame's t, in `opts.steps` or (frames − 1) steps.
pub fn crossval(
    pattern: &Pattern,
    drive: &G0Drive,
    opts: &CrossvalOptions,
) -> Result<CrossvalReport, CrossvalError> {
    let t_start = pattern.frames.first().map_or(0.0, |f| f.t);
    let t_end = match (opts.t_end, pattern.frames.last()) {
        (Some(t), _) => t,
        (None, Some(f)) if pattern.frames.len() >= 2 => f.t,
        _ => {
            return Err(CrossvalError::Motion(
                "the pattern has fewer than two frames: give the end of the motion (--t-max)"
                    .into(),
            ));
        }
    };
    if same_t(t_start, t_end) {
        return Err(CrossvalError::Motion(format!(
            "the motion is empty: it starts and ends at t = {t_start}"
        )));
    }
    let steps = match opts.steps {
        Some(j) if j >= 1 => j,
        Some(_) => return Err(CrossvalError::Motion("steps must be at least 1".into())),
        None => pattern.frames.len().saturating_sub(1).max(1),
    };
    let mut input = g0_input(pattern, drive, t_start, t_end, steps)?;
    let apexes = if opts.rigid_panels {
        add_panel_apexes(&mut input)
    } else {
        Vec::new()
    };
    input.first_step_offsets = branch_offsets(pattern, &input, &apexes);
    input.check_intersections = opts.check_intersections;
    input.solver = opts.solver;
    let checker = if opts.check_intersections {
        // Apexes belong to no facet: the checker only needs them counted.
        let layout: Vec<[f64; 2]> = input.initial.iter().map(|p| [p[0], p[1]]).collect();
        Some(Checker::new(&layout, &input.faces)?)
    } else {
        None
    };
    let sim = simulate_with_checker(&input, checker.as_ref())?;
    Ok(compare(pattern, drive, &input, apexes.len(), sim))
}

/// Compare a finished simulation with the pattern's frames.
fn compare(
    pattern: &Pattern,
    drive: &G0Drive,
    input: &SimInput,
    panel_apexes: usize,
    sim: SimReport,
) -> CrossvalReport {
    let frame_at = |t: f64| {
        pattern
            .frames
            .iter()
            .find(|f| same_t(f.t, t) && f.coords.len() == pattern.vertices.len())
    };
    let mut prescribed: Vec<usize> = input.fixed.clone();
    prescribed.extend(input.drives.iter().filter_map(|d| match d {
        Drive::Trajectory { vertex, .. } => Some(*vertex),
        Drive::Crease { .. } => None,
    }));
    let mut states = Vec::with_capacity(sim.states.len());
    let (mut max_err, mut drive_err, mut compared) = (0.0_f64, 0.0_f64, 0);
    let mut start_gap = None;
    for (j, x) in sim.states.iter().enumerate() {
        let t = if j == 0 {
            input.t_start
        } else {
            sim.steps[j - 1].t
        };
        let frame = frame_at(t);
        // NaN-propagating maxima: a NaN position must fail the comparison, not vanish.
        let err = frame
            .map(|f| geom::max_or_nan(x.iter().zip(&f.coords).map(|(a, b)| geom::dist(*a, *b))));
        if let Some(f) = frame {
            let d = geom::max_or_nan(prescribed.iter().map(|&v| geom::dist(x[v], f.coords[v])));
            if j == 0 {
                start_gap = err;
            } else {
                drive_err = geom::max_or_nan([drive_err, d]);
                max_err = geom::max_or_nan([max_err, err.unwrap_or(0.0)]);
                compared += 1;
            }
        }
        states.push(StateComparison {
            j,
            t,
            delta: if j == 0 { 0.0 } else { sim.steps[j - 1].delta },
            position_error: err,
            error_bound: match err {
                Some(e) if j > 0 && e > POSITION_TOL => Some(error_bound(input, x)),
                _ => None,
            },
        });
    }
    let widened_states = states.iter().filter(|s| s.error_bound.is_some()).count();
    let driven_edges: Vec<usize> = drive.creases().iter().map(|c| c.edge).collect();
    let final_position_error = states
        .last()
        .filter(|s| s.j > 0)
        .and_then(|s| s.position_error);
    CrossvalReport {
        // `g0_input` refused an actuation without creases, so there is a first.
        driven_edge: driven_edges.first().copied().unwrap_or_default(),
        driven_edges,
        fixed_face: drive.fixed_face(),
        angle_source: drive.source(),
        steps: input.steps,
        t_start: input.t_start,
        t_end: input.t_end,
        gamma: sim.gamma,
        max_delta: sim.max_delta(),
        rigid: sim.steps.iter().all(|s| s.delta <= RIGID_DELTA),
        theta: sim.theta,
        states,
        compared_states: compared,
        max_position_error: max_err,
        widened_states,
        final_position_error,
        drive_error: drive_err,
        start_gap,
        panel_apexes,
        free_vertices: sim.free_vertices,
        bars: sim.bars,
        sim,
    }
}

/// ‖r‖/σ_min of the simulated state `x` (see [`StateComparison::error_bound`]).
fn error_bound(input: &SimInput, x: &[[f64; 3]]) -> f64 {
    let bars = Bars::from_faces(&input.faces, &input.extra_bars, &input.initial);
    let mut prescribed = vec![false; x.len()];
    for &v in &input.fixed {
        prescribed[v] = true;
    }
    for d in &input.drives {
        if let Drive::Trajectory { vertex, .. } = d {
            prescribed[*vertex] = true;
        }
    }
    let mut n_free = 0;
    let slot: Vec<Option<usize>> = prescribed
        .iter()
        .map(|&p| {
            (!p).then(|| {
                n_free += 1;
                n_free - 1
            })
        })
        .collect();
    let r: f64 = bars.residuals(x).iter().map(|v| v * v).sum::<f64>().sqrt();
    if n_free == 0 {
        return 0.0;
    }
    let sigma_min = jacobian(&bars, &slot, n_free, x).singular_values().min();
    r / sigma_min
}

/// Cross-validate a design of `model` (full variable vector, ±1 modes) over `[0, t_max]`
/// in `steps` steps: the PTU's frames are computed at exactly the simulator's t_j, and the
/// driven creases follow the task's drive expressions (exact at every t), by the model's
/// actuation ([`design_drive`]: one crease folded symmetrically, or a fixed central
/// facet).
pub fn crossval_design(
    model: &Model,
    full_vars: Vec<f64>,
    modes: Vec<f64>,
    steps: usize,
    opts: &CrossvalOptions,
) -> Result<CrossvalReport, CrossvalError> {
    let design = Evaluated::new(&model.plan, full_vars, modes);
    // Same formula as the simulator's t_j = t_start + (t_end − t_start)·j/J, so the frames
    // land on the simulated states bit for bit.
    let pattern = design.pattern(&sample_times(model.t_max, steps.max(1) + 1));
    let drive = design_drive(model)?;
    crossval(
        &pattern,
        &drive,
        &CrossvalOptions {
            steps: Some(steps),
            t_end: Some(model.t_max),
            ..opts.clone()
        },
    )
}

/// The G0 drive of a model, as `model::geometry::fold` applies the plan's actuation:
/// without a fixed facet, the symmetric fold of its actuated crease; with one (a driven
/// central facet), that facet fixed and every driven crease turning its other facet.
/// Creases come first among a design pattern's edges, in plan order, and the pattern's
/// facets are the plan's polygons with at least three corners.
pub fn design_drive(model: &Model) -> Result<G0Drive, CrossvalError> {
    let plan = &model.plan;
    let crease = |k: usize| {
        let expr = plan.creases[k].drive.clone().ok_or_else(|| {
            CrossvalError::Angle(format!("the model's actuated crease {k} has no drive"))
        })?;
        Ok::<_, CrossvalError>(DrivenCrease {
            edge: k,
            source: expr.to_string(),
            angle: Arc::new(move |t| expr.eval(&t)),
        })
    };
    let Some(fixed) = plan.actuation.fixed else {
        return Ok(G0Drive::Symmetric(crease(plan.actuation.crease)?));
    };
    let corners = |f: usize| plan.polygons.get(f).map_or(0, |(p, _)| p.len());
    if corners(fixed) < 3 {
        return Err(CrossvalError::Angle(format!(
            "the model's fixed facet {fixed} is not a polygon of the pattern"
        )));
    }
    Ok(G0Drive::Fixed {
        face: (0..fixed).filter(|&f| corners(f) >= 3).count(),
        creases: plan
            .actuation
            .driven
            .iter()
            .map(|&k| crease(k))
            .collect::<Result<_, _>>()?,
    })
}

/// Steps of the bar-and-hinge simulation that judges a cyclic design (the thesis's 30).
pub const CYCLIC_STEPS: usize = 30;

/// The bar-and-hinge side of a cyclic design's verdict.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct SimulationVerdict {
    /// Steps J.
    pub steps: usize,
    /// Rigidity error Γ (Eq. 4).
    pub gamma: f64,
    /// Largest δ(j).
    pub max_delta: f64,
    /// Largest distance between a simulated vertex and the PTU's.
    pub max_position_error: f64,
    /// Γ ≤ [`GAMMA_TOL`] and every state within the position tolerance.
    pub agrees: bool,
}

/// Both verifications of a cyclic design (r2′): the dense PTU sweep
/// ([`crate::check::cycle`]) and the bar-and-hinge simulation driven by G0's actuation,
/// which decides.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct CyclicVerdict {
    /// The sweep: compatibility residual and position disagreement.
    pub sweep: crate::check::cycle::CycleReport,
    /// The simulation (absent when the sweep already failed, or with `error`).
    pub simulation: Option<SimulationVerdict>,
    /// Why the simulation could not run.
    pub error: Option<String>,
    /// The sweep within [`crate::check::cycle::CYCLE_TOL`] and the simulation agreeing.
    pub passes: bool,
}

/// Verify a cyclic design of `model` (full variables, ±1 modes): the sweep over
/// `sweep` states of [0, t_max], then, if it passes, [`CYCLIC_STEPS`] steps of the
/// bar-and-hinge simulation compared with the PTU ([`crossval_design`]).
pub fn verify_cyclic(
    model: &Model,
    full_vars: &[f64],
    modes: &[f64],
    sweep: usize,
    geometry_margin: f64,
) -> CyclicVerdict {
    use crate::check::cycle::{CYCLE_TOL, verify_cycles};
    let design = Evaluated::new(&model.plan, full_vars.to_vec(), modes.to_vec());
    let report = verify_cycles(&design, &sample_times(model.t_max, sweep), geometry_margin);
    let mut v = CyclicVerdict {
        passes: false,
        simulation: None,
        error: None,
        sweep: report,
    };
    if !v.sweep.passes(CYCLE_TOL) {
        return v;
    }
    match simulate_design(model, full_vars, modes) {
        Ok(s) => {
            v.passes = s.agrees;
            v.simulation = Some(s);
        }
        Err(e) => v.error = Some(e.to_string()),
    }
    v
}

/// The bar-and-hinge simulation of a design of `model` (full variables, ±1 modes) over
/// [`CYCLIC_STEPS`] steps of its motion, driven as its task drives it, against the PTU's
/// states: the verdict a cyclic design's folding rests on, and for an acyclic design with
/// a driven central facet the independent check of its several drives.
pub fn simulate_design(
    model: &Model,
    full_vars: &[f64],
    modes: &[f64],
) -> Result<SimulationVerdict, CrossvalError> {
    let r = crossval_design(
        model,
        full_vars.to_vec(),
        modes.to_vec(),
        CYCLIC_STEPS,
        &CrossvalOptions::default(),
    )?;
    Ok(SimulationVerdict {
        steps: r.steps,
        gamma: r.gamma,
        max_delta: r.max_delta,
        max_position_error: r.max_position_error,
        agrees: r.agrees(GAMMA_TOL, POSITION_TOL),
    })
}
