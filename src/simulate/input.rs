//! The simulator's plain input: positions, facets, supports, drives, the range of `t`.
//!
//! Any source can build it — a pattern file ([`super::pattern_file`]), a FOLD file, or a
//! PTU design — so the simulator itself knows nothing about files.

use std::fmt;
use std::sync::Arc;

use nalgebra::{Rotation3, Unit, Vector3};
use thiserror::Error;

use super::formula::Formula;

/// A prescribed vertex path `t ↦ x(t)`.
pub type PathFn = Arc<dyn Fn(f64) -> [f64; 3] + Send + Sync>;

/// A prescribed crease angle `t ↦ ρ(t)` (radians, valley positive).
pub type AngleFn = Arc<dyn Fn(f64) -> f64 + Send + Sync>;

/// What drives the motion.
#[derive(Clone)]
pub enum Drive {
    /// Vertex `vertex` follows `path(t)`. `path(t_start)` must be its initial position.
    Trajectory {
        /// The driven vertex.
        vertex: usize,
        /// Its position as a function of `t`.
        path: PathFn,
    },
    /// The crease `p–q` between two facets has the fold angle `angle(t)` (valley positive;
    /// `angle(t_start)` must be the crease's initial fold angle, 0 when flat). The facet
    /// `fixed_face` is held in place and `moving_face` is rotated rigidly about the crease:
    /// its vertices become prescribed positions.
    Crease {
        /// One end of the crease.
        p: usize,
        /// The other end of the crease.
        q: usize,
        /// The facet held in place.
        fixed_face: usize,
        /// The facet rotated about the crease.
        moving_face: usize,
        /// The fold angle as a function of `t`.
        angle: AngleFn,
    },
}

impl fmt::Debug for Drive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Drive::Trajectory { vertex, .. } => f
                .debug_struct("Trajectory")
                .field("vertex", vertex)
                .finish_non_exhaustive(),
            Drive::Crease {
                p,
                q,
                fixed_face,
                moving_face,
                ..
            } => f
                .debug_struct("Crease")
                .field("p", p)
                .field("q", q)
                .field("fixed_face", fixed_face)
                .field("moving_face", moving_face)
                .finish_non_exhaustive(),
        }
    }
}

impl Drive {
    /// A trajectory from three formulas in `t`.
    pub fn trajectory_from_formulas(vertex: usize, x: Formula, y: Formula, z: Formula) -> Drive {
        Drive::Trajectory {
            vertex,
            path: Arc::new(move |t| [x.eval(t), y.eval(t), z.eval(t)]),
        }
    }

    /// A trajectory that turns `vertex`, starting at `initial`, about the axis through
    /// `origin` along `axis` by `angle(t)` (right-handed). The thesis's G0 drive is two of
    /// these per facet vertex: f1's vertices by +t/2 and f2's by −t/2 about the x-axis.
    pub fn rotation_about_axis(
        vertex: usize,
        initial: [f64; 3],
        origin: [f64; 3],
        axis: [f64; 3],
        angle: AngleFn,
    ) -> Drive {
        let o = Vector3::from(origin);
        let axis = Unit::new_normalize(Vector3::from(axis));
        let p = Vector3::from(initial) - o;
        Drive::Trajectory {
            vertex,
            path: Arc::new(move |t| {
                let x = o + Rotation3::from_axis_angle(&axis, angle(t)) * p;
                [x.x, x.y, x.z]
            }),
        }
    }

    /// A crease drive from a formula for the angle.
    pub fn crease_from_formula(
        p: usize,
        q: usize,
        fixed_face: usize,
        moving_face: usize,
        angle: Formula,
    ) -> Drive {
        Drive::Crease {
            p,
            q,
            fixed_face,
            moving_face,
            angle: Arc::new(move |t| angle.eval(t)),
        }
    }
}

/// Most solver iterations one reported step may spend on refinement, by default
/// ([`SolverSettings::refine_budget`]). A step that follows
/// a branch refines along one path; near a flat or singular state that can take a few
/// hundred thousand (352,111 for the last step of the gripper's g06-c2-uu at N_max = 2,
/// seed 1), so the budget is several times that. A motion that no step size can follow
/// would otherwise refine every half down to `max_refine`, 2^18 substeps: hours, found
/// by fuzzing.
pub const REFINE_ITERATION_BUDGET: usize = 2_000_000;

/// Stopping rules of the per-step least-squares solve, and the step control.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Most Levenberg–Marquardt iterations per solve.
    pub max_iterations: usize,
    /// Stop when a step changes no coordinate by more than this, relative to the largest
    /// coordinate magnitude.
    pub step_tolerance: f64,
    /// Stop when the largest |l² − l_t²| is at most this (absolute, squared length units).
    pub residual_tolerance: f64,
    /// Continuation step control: a (sub)step is halved when the solve has to move the
    /// free vertices from the predicted start by more than this fraction of the step's
    /// whole displacement (largest coordinate change each). A corrector that large means
    /// the predictor was poor, and near a bifurcation it may have converged to the
    /// neighbouring branch; smaller steps make the predictor better (its error falls as
    /// the step squared) while branches stay apart. `f64::INFINITY` (the default) turns
    /// it off; the cross-validation uses 0.02 (see [`super::crossval`]).
    pub max_correction: f64,
    /// Most halvings of one step (default 6: up to 2^6 = 64 substeps). Near a vertex's
    /// rigid limit its creases turn like √(t_lim − t), arbitrarily fast, and a design that
    /// ends just short of its limit (Eq. 33 keeps only 1e-8) needs many more to follow
    /// its branch; the cross-validation allows 18.
    pub max_refine: usize,
    /// Most solver iterations one reported step may spend on refinement (default
    /// [`REFINE_ITERATION_BUDGET`]); where it stops, the step is taken as it
    /// stands and reported as capped.
    pub refine_budget: usize,
}

impl Default for SolverSettings {
    /// Tight by default: a rigid pattern converges to rounding level (δ ~ 1e-13 and below).
    fn default() -> Self {
        SolverSettings {
            max_iterations: 200,
            step_tolerance: 1e-15,
            residual_tolerance: 1e-15,
            max_correction: f64::INFINITY,
            max_refine: 6,
            refine_budget: REFINE_ITERATION_BUDGET,
        }
    }
}

/// Everything one simulation needs.
#[derive(Clone, Debug)]
pub struct SimInput {
    /// Vertex positions at `t_start`. They need not be flat (the thesis also simulates
    /// non-developable starts); bar target lengths are measured here.
    pub initial: Vec<[f64; 3]>,
    /// Facets as vertex lists, counter-clockwise seen from +z in the initial state
    /// (projected on the xy-plane). Bars join every pair of a facet's vertices: its sides
    /// and all its diagonals (Eq. 2).
    pub faces: Vec<Vec<usize>>,
    /// Additional bars beyond the facets' sides and diagonals (rarely needed).
    pub extra_bars: Vec<[usize; 2]>,
    /// Vertices held at their initial positions (e.g. the vertices of a fixed facet).
    pub fixed: Vec<usize>,
    /// What drives the motion.
    pub drives: Vec<Drive>,
    /// Start of the driving parameter.
    pub t_start: f64,
    /// End of the driving parameter (may be below `t_start`).
    pub t_end: f64,
    /// Number of folding steps J (states t_1 … t_J after t_0 = t_start).
    pub steps: usize,
    /// The displacement of these vertices over the first step on the branch to follow,
    /// e.g. X(t₁) − X(t₀) of a reference motion (not a change of the target lengths). It
    /// picks a branch at a bifurcation such as the flat state, where the thesis relied on
    /// non-developable starts: every solve within the first step, from a state at t′ to
    /// t, starts its free vertices at `x(t′) + offset·(t − t′)/(t₁ − t₀)`, so a first
    /// step refined into substeps follows it too. Offsets of prescribed or fixed vertices
    /// are ignored.
    pub first_step_offsets: Vec<(usize, [f64; 3])>,
    /// Check self-intersection at every step (θ); off, θ is reported as 0.
    pub check_intersections: bool,
    /// Solver stopping rules.
    pub solver: SolverSettings,
}

/// Why an input cannot be simulated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InputError {
    /// A vertex index points past the vertex list.
    #[error("{what} refers to vertex {vertex}, but there are only {count} vertices")]
    VertexOutOfRange {
        /// Where the reference is.
        what: String,
        /// The offending index.
        vertex: usize,
        /// Number of vertices.
        count: usize,
    },
    /// A facet index points past the facet list.
    #[error("{what} refers to facet {face}, but there are only {count} facets")]
    FaceOutOfRange {
        /// Where the reference is.
        what: String,
        /// The offending index.
        face: usize,
        /// Number of facets.
        count: usize,
    },
    /// A number is NaN or infinite.
    #[error("{what} is not a finite number")]
    NonFinite {
        /// What was not finite.
        what: String,
    },
    /// Fewer than one step.
    #[error("steps must be at least 1, got {0}")]
    NoSteps(usize),
    /// A facet with fewer than three vertices, or a repeated vertex.
    #[error("facet {face} must list at least 3 distinct vertices")]
    BadFace {
        /// The facet.
        face: usize,
    },
    /// A vertex is driven twice, or driven and fixed.
    #[error(
        "vertex {vertex} is {first} and also {second}; a vertex can have only one prescribed motion"
    )]
    Conflict {
        /// The vertex.
        vertex: usize,
        /// Its first role.
        first: String,
        /// Its second role.
        second: String,
    },
    /// A crease drive whose facets do not both contain the crease.
    #[error(
        "crease drive {p}–{q}: facets {fixed_face} and {moving_face} must both contain the crease as a side"
    )]
    NotACrease {
        /// One end.
        p: usize,
        /// Other end.
        q: usize,
        /// The fixed facet.
        fixed_face: usize,
        /// The moving facet.
        moving_face: usize,
    },
    /// A drive does not start where the pattern is.
    #[error(
        "{what}: at t_start = {t_start} the drive prescribes {prescribed}, but the pattern has {actual}"
    )]
    DriveStartMismatch {
        /// Which drive.
        what: String,
        /// Start of the motion.
        t_start: f64,
        /// What the drive gives at `t_start`.
        prescribed: String,
        /// What the initial state has.
        actual: String,
    },
    /// Nothing moves.
    #[error("nothing drives the motion: give at least one trajectory or crease drive")]
    NoDrive,
}

/// Which vertices are free, fixed or prescribed, and how prescribed ones move.
#[derive(Clone)]
pub(crate) struct Supports {
    /// For each vertex: `None` when free, `Some(k)` for prescribed source `k`.
    pub(crate) role: Vec<Option<Source>>,
}

#[derive(Clone)]
pub(crate) enum Source {
    Fixed,
    Path(PathFn),
    /// Rotation of the initial position about the axis through `origin` along `axis`
    /// by `sign·(angle(t) − angle0)`.
    Rotate {
        origin: Vector3<f64>,
        axis: Unit<Vector3<f64>>,
        angle: AngleFn,
        angle0: f64,
    },
}

impl Supports {
    /// Prescribed position of vertex `v` at `t` (None when free).
    pub(crate) fn position(&self, v: usize, t: f64, initial: &[f64; 3]) -> Option<[f64; 3]> {
        match self.role[v].as_ref()? {
            Source::Fixed => Some(*initial),
            Source::Path(f) => Some(f(t)),
            Source::Rotate {
                origin,
                axis,
                angle,
                angle0,
            } => {
                let r = Rotation3::from_axis_angle(axis, angle(t) - angle0);
                let x = origin + r * (Vector3::from(*initial) - origin);
                Some([x.x, x.y, x.z])
            }
        }
    }
}

fn fmt3(p: [f64; 3]) -> String {
    format!("({:.6}, {:.6}, {:.6})", p[0], p[1], p[2])
}

/// The fold angle (valley positive) of crease `p → q` with facet `a` on its left and facet
/// `b` on its right, measured with the farthest vertex of each facet from the crease.
pub(crate) fn crease_angle(x: &[[f64; 3]], p: usize, q: usize, a: &[usize], b: &[usize]) -> f64 {
    let v = |i: usize| Vector3::from(x[i]);
    let (xp, e) = (v(p), v(q) - v(p));
    let perp = |i: usize| {
        let r = v(i) - xp;
        r - e * (e.dot(&r) / e.norm_squared())
    };
    let far = |f: &[usize]| {
        f.iter()
            .map(|&i| perp(i))
            .max_by(|s, t| s.norm_squared().total_cmp(&t.norm_squared()))
            .unwrap_or_else(Vector3::zeros)
    };
    let (ua, ub) = (far(a), far(b));
    ua.cross(&ub).dot(&e).atan2(-ua.dot(&ub) * e.norm())
}

/// Whether facet `f` runs along `p → q` (as consecutive vertices).
fn traverses(f: &[usize], p: usize, q: usize) -> bool {
    (0..f.len()).any(|k| f[k] == p && f[(k + 1) % f.len()] == q)
}

impl SimInput {
    /// An input for a [`crate::pattern::Pattern`]: its flat layout (z = 0) as the initial
    /// state, its facets, `t` over the range of its frames and one step per frame after the
    /// first (J = frames − 1, at least 1). Drives and supports are left empty for the caller
    /// (e.g. trajectories that follow the model's driven facets).
    pub fn from_pattern(pattern: &crate::pattern::Pattern) -> SimInput {
        let (t_start, t_end) = match (pattern.frames.first(), pattern.frames.last()) {
            (Some(a), Some(b)) => (a.t, b.t),
            _ => (0.0, 0.0),
        };
        SimInput {
            initial: pattern.flat_coords(),
            faces: pattern.faces.clone(),
            extra_bars: Vec::new(),
            fixed: Vec::new(),
            drives: Vec::new(),
            t_start,
            t_end,
            steps: pattern.frames.len().saturating_sub(1).max(1),
            first_step_offsets: Vec::new(),
            check_intersections: true,
            solver: SolverSettings::default(),
        }
    }

    /// Check the input and resolve the supports.
    pub(crate) fn resolve(&self) -> Result<Supports, InputError> {
        let n = self.initial.len();
        self.check_numbers_and_indices()?;
        if self.drives.is_empty() {
            return Err(InputError::NoDrive);
        }
        let mut roles = Roles {
            role: vec![None; n],
            why: vec![String::new(); n],
        };
        for &v in &self.fixed {
            check_vertex("the fixed list".into(), v, n)?;
            roles.assign(v, Source::Fixed, "fixed".into(), true)?;
        }
        for (k, d) in self.drives.iter().enumerate() {
            match d {
                Drive::Trajectory { vertex, path } => {
                    self.trajectory(k, *vertex, path, &mut roles)?;
                }
                Drive::Crease {
                    p,
                    q,
                    fixed_face,
                    moving_face,
                    angle,
                } => {
                    let faces = [*fixed_face, *moving_face];
                    self.crease_drive(k, (*p, *q), faces, angle, &mut roles)?;
                }
            }
        }
        Ok(Supports { role: roles.role })
    }

    /// Steps, finite numbers, vertex indices in range and facets of distinct vertices.
    fn check_numbers_and_indices(&self) -> Result<(), InputError> {
        let n = self.initial.len();
        if self.steps == 0 {
            return Err(InputError::NoSteps(0));
        }
        for (i, p) in self.initial.iter().enumerate() {
            if p.iter().any(|x| !x.is_finite()) {
                return Err(InputError::NonFinite {
                    what: format!("initial position of vertex {i}"),
                });
            }
        }
        for (what, x) in [("t_start", self.t_start), ("t_end", self.t_end)] {
            if !x.is_finite() {
                return Err(InputError::NonFinite { what: what.into() });
            }
        }
        for (f, face) in self.faces.iter().enumerate() {
            for &v in face {
                check_vertex(format!("facet {f}"), v, n)?;
            }
            let mut s = face.clone();
            s.sort_unstable();
            s.dedup();
            if s.len() < 3 || s.len() != face.len() {
                return Err(InputError::BadFace { face: f });
            }
        }
        for (k, b) in self.extra_bars.iter().enumerate() {
            check_vertex(format!("extra bar {k}"), b[0], n)?;
            check_vertex(format!("extra bar {k}"), b[1], n)?;
        }
        for &(v, off) in &self.first_step_offsets {
            check_vertex("a first-step offset".into(), v, n)?;
            if off.iter().any(|x| !x.is_finite()) {
                return Err(InputError::NonFinite {
                    what: format!("first-step offset of vertex {v}"),
                });
            }
        }
        Ok(())
    }

    /// Drive `k`: `vertex` follows `path`, which must start at the vertex.
    fn trajectory(
        &self,
        k: usize,
        vertex: usize,
        path: &PathFn,
        roles: &mut Roles,
    ) -> Result<(), InputError> {
        check_vertex(format!("drive {k}"), vertex, self.initial.len())?;
        let at = path(self.t_start);
        let init = self.initial[vertex];
        let gap = (0..3).map(|i| (at[i] - init[i]).abs()).fold(0.0, f64::max);
        let scale = init.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        if gap.is_nan() || gap > 1e-9 * scale {
            return Err(InputError::DriveStartMismatch {
                what: format!("trajectory of vertex {vertex} (drive {k})"),
                t_start: self.t_start,
                prescribed: fmt3(at),
                actual: fmt3(init),
            });
        }
        roles.assign(
            vertex,
            Source::Path(path.clone()),
            format!("driven by trajectory (drive {k})"),
            false,
        )
    }

    /// Drive `k`: crease p–q folds by `angle`, facet `fixed_face` held, `moving_face`
    /// turning about the crease; the angle must start at the pattern's.
    fn crease_drive(
        &self,
        k: usize,
        (p, q): (usize, usize),
        [fixed_face, moving_face]: [usize; 2],
        angle: &AngleFn,
        roles: &mut Roles,
    ) -> Result<(), InputError> {
        let n = self.initial.len();
        check_vertex(format!("crease drive {k}"), p, n)?;
        check_vertex(format!("crease drive {k}"), q, n)?;
        for f in [fixed_face, moving_face] {
            if f >= self.faces.len() {
                return Err(InputError::FaceOutOfRange {
                    what: format!("crease drive {k}"),
                    face: f,
                    count: self.faces.len(),
                });
            }
        }
        let (fa, fb) = (&self.faces[fixed_face], &self.faces[moving_face]);
        let not_crease = InputError::NotACrease {
            p,
            q,
            fixed_face,
            moving_face,
        };
        if fixed_face == moving_face {
            return Err(not_crease);
        }
        // Orient the crease so that the fixed facet is on its left (it runs p→q).
        let (p, q) = if traverses(fa, p, q) && traverses(fb, q, p) {
            (p, q)
        } else if traverses(fa, q, p) && traverses(fb, p, q) {
            (q, p)
        } else {
            return Err(not_crease);
        };
        let angle0 = crease_angle(&self.initial, p, q, fa, fb);
        let a0 = angle(self.t_start);
        if (a0 - angle0).is_nan() || (a0 - angle0).abs() > 1e-9 {
            return Err(InputError::DriveStartMismatch {
                what: format!("crease drive {k} ({p}–{q})"),
                t_start: self.t_start,
                prescribed: format!("fold angle {a0:.9}"),
                actual: format!("fold angle {angle0:.9}"),
            });
        }
        let origin = Vector3::from(self.initial[p]);
        let e = Vector3::from(self.initial[q]) - origin;
        // With the fixed facet A on the left of ê, the fold angle grows when the
        // right facet turns by −Δ about ê (see check::self_intersection).
        let axis = Unit::new_normalize(-e);
        for &v in fa {
            roles.assign(
                v,
                Source::Fixed,
                format!("on the fixed facet of crease drive {k}"),
                true,
            )?;
        }
        for &v in fb {
            if v == p || v == q {
                continue;
            }
            roles.assign(
                v,
                Source::Rotate {
                    origin,
                    axis,
                    angle: angle.clone(),
                    angle0,
                },
                format!("on the moving facet of crease drive {k}"),
                false,
            )?;
        }
        Ok(())
    }
}

/// Vertex index `v` of `what` is below the vertex count `n`.
fn check_vertex(what: String, v: usize, n: usize) -> Result<(), InputError> {
    if v >= n {
        Err(InputError::VertexOutOfRange {
            what,
            vertex: v,
            count: n,
        })
    } else {
        Ok(())
    }
}

/// The supports being resolved: each vertex's source and why it has it.
struct Roles {
    role: Vec<Option<Source>>,
    why: Vec<String>,
}

impl Roles {
    /// Give vertex `v` its source; a second one is a conflict, except fixing a fixed vertex
    /// again where `allow_fixed_twice`.
    fn assign(
        &mut self,
        v: usize,
        src: Source,
        label: String,
        allow_fixed_twice: bool,
    ) -> Result<(), InputError> {
        if let Some(old) = &self.role[v] {
            let both_fixed = matches!(old, Source::Fixed) && matches!(src, Source::Fixed);
            if both_fixed && allow_fixed_twice {
                return Ok(());
            }
            return Err(InputError::Conflict {
                vertex: v,
                first: self.why[v].clone(),
                second: label,
            });
        }
        self.role[v] = Some(src);
        self.why[v] = label;
        Ok(())
    }
}
