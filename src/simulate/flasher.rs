//! The adapted-flasher design task of thesis Sec. 3.4–3.7 and its simulated annealing.
//!
//! The pattern is `grammar/flasher_adapted.toml` (its comments list what was reconstructed
//! and assumed). The task: choose the starting positions of v3, v4, v5 (Eq. 5) so that the
//! flasher folds rigidly, without self-intersection, into the cuboid −1 ≤ x, y ≤ 1,
//! −4 ≤ z < 0, with the largest projected area.
//!
//! * **Variables (Eq. 5)**: `x3 = x1 + l3·s(θ3, ϑ3)`, `x4 = x2 + l4·s(θ4, ϑ4)`,
//!   `x5 = x2''' + l5·s(θ5, ϑ5)` with `s(θ, ϑ) = (cos θ cos ϑ, cos θ sin ϑ, sin θ)`: θ is the
//!   "polar" angle measured as an elevation from the xy-plane (its bounds [−45°, 0°] put v3
//!   at or below the plane), ϑ the azimuth from +x, both in the global frame, and
//!   `x2''' = (3, 0, 0)` is v2 turned by −90°. This reading puts the thesis's best design
//!   (Sec. 3.7) inside all nine bounds, which no other choice of v2's rotation does.
//! * **A**: the area of the initial (unfolded, possibly non-developable) pattern projected
//!   on the xy-plane — the sum of the facets' signed projected areas.
//! * **Ω**: for every vertex at the end of the motion, the distances to the cuboid along x,
//!   y and z, summed (Sec. 3.6); `z < 0` is taken as `z ≤ 0` for the distance (the fixed
//!   facet f1 lies at z = 0; touching it from below is the intersection check's business).
//! * **θ**: the simulator's share of steps with a self-intersection; a design whose initial
//!   state already intersects itself, or whose facets are not counter-clockwise in the
//!   projection, gets θ = 1.
//! * **Objective**: −A/50 + (Γ + θ + Ω). Feasible: every δ(j) ≤ 1e-4, θ = 0 and Ω = 0 (up
//!   to [`OMEGA_TOL`], rounding of positions that end on the cuboid's faces).
//! * **Annealing** (Sec. 3.6): argmin's simulated annealing, start temperature 200,
//!   temperature multiplied by 0.89 per outer loop of 50 evaluations, 50 × 50 = 2500
//!   evaluations. argmin lowers the temperature at every iteration, so the per-iteration
//!   factor is 0.89^(1/50): the same temperature as the thesis's stepwise schedule at the end
//!   of every outer loop. A move adds to every variable a uniform step of at most one tenth
//!   of its range (the thesis's neighbourhood), clamped to the bounds. argmin accepts a worse
//!   point with probability 1/(1 + exp(Δ/T)). The start point is drawn uniformly within the
//!   bounds (or given). Everything is seeded: the same seed gives the same run.

use std::cell::RefCell;
use std::f64::consts::PI;
use std::rc::Rc;

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::simulatedannealing::{Anneal, SATempFunc, SimulatedAnnealing};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::pattern_file::{PatternFile, PatternFileError};
use super::run::{checker_for, simulate_with_checker};

/// The pattern file of the adapted flasher, as shipped in `grammar/`.
pub const FLASHER_TOML: &str = include_str!("../../grammar/flasher_adapted.toml");

/// Names of Eq. 5's variables, in order.
pub const VARIABLE_NAMES: [&str; 9] = [
    "l3",
    "theta3",
    "vartheta3",
    "l4",
    "theta4",
    "vartheta4",
    "l5",
    "theta5",
    "vartheta5",
];

const DEG: f64 = PI / 180.0;

/// Eq. 5's bounds (lengths in pattern units, angles in radians), in [`VARIABLE_NAMES`] order.
pub const BOUNDS: [(f64, f64); 9] = [
    (0.4, 1.5),
    (-45.0 * DEG, 0.0),
    (20.0 * DEG, 70.0 * DEG),
    (0.5, 3.0),
    (-30.0 * DEG, 30.0 * DEG),
    (45.0 * DEG, 135.0 * DEG),
    (0.5, 3.0),
    (-30.0 * DEG, 30.0 * DEG),
    (45.0 * DEG, 135.0 * DEG),
];

/// The target cuboid (min and max corner).
pub const CUBOID: ([f64; 3], [f64; 3]) = ([-1.0, -1.0, -4.0], [1.0, 1.0, 0.0]);

/// The thesis's best design (Sec. 3.7): starting positions of v3, v4, v5.
pub const THESIS_BEST: [[f64; 3]; 3] =
    [[1.50, 1.39, -0.10], [0.53, 5.28, 0.03], [2.15, 1.78, -0.43]];

/// Ω at or below this counts as 0 for feasibility (rounding of vertices on the cuboid).
pub const OMEGA_TOL: f64 = 1e-9;

/// The area weight w of the objective.
pub const AREA_WEIGHT: f64 = 50.0;

/// Objective given to designs the simulator cannot run at all.
const FAILED: f64 = 1e6;

/// The outcome of one evaluation of a design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlasherEvaluation {
    /// The Eq. 5 variables (angles in radians).
    pub variables: [f64; 9],
    /// Starting positions of v3, v4, v5.
    pub positions: [[f64; 3]; 3],
    /// −A/50 + (Γ + θ + Ω).
    pub objective: f64,
    /// Projected area A of the initial pattern.
    pub area: f64,
    /// Rigidity error Γ.
    pub gamma: f64,
    /// Largest δ(j).
    pub max_delta: f64,
    /// Self-intersection measure θ.
    pub theta: f64,
    /// Spatial feasibility Ω.
    pub omega: f64,
    /// Every δ(j) ≤ 1e-4.
    pub rigid: bool,
    /// Rigid, θ = 0 and Ω ≤ [`OMEGA_TOL`].
    pub feasible: bool,
}

/// The flasher task: the pattern and where v1, v2, v2''' are.
#[derive(Clone, Debug)]
pub struct FlasherTask {
    file: PatternFile,
    x1: [f64; 3],
    x2: [f64; 3],
    x2r: [f64; 3],
}

impl FlasherTask {
    /// The task on the shipped `grammar/flasher_adapted.toml`.
    pub fn shipped() -> Result<FlasherTask, PatternFileError> {
        let file = PatternFile::parse(FLASHER_TOML, "grammar/flasher_adapted.toml")?;
        Self::new(file)
    }

    /// The task on a pattern file that has vertices v1…v5 and four-fold symmetry.
    pub fn new(file: PatternFile) -> Result<FlasherTask, PatternFileError> {
        let bad = |message: String| PatternFileError {
            origin: file.name.clone(),
            field: "vertices".into(),
            message,
        };
        if file.rotations != 4 {
            return Err(bad("the flasher task needs [symmetry] rotations = 4".into()));
        }
        for n in ["v1", "v2", "v3", "v4", "v5"] {
            if file.copies(n).is_none() {
                return Err(bad(format!("the flasher task needs a vertex named {n}")));
            }
        }
        let at = |n: &str| file.vertex(n).map(|i| file.input.initial[i]);
        let (Some(x1), Some(x2), Some(x2r)) = (at("v1"), at("v2"), at("v2@3")) else {
            return Err(bad("v1, v2 and v2@3 must exist".into()));
        };
        Ok(FlasherTask { file, x1, x2, x2r })
    }

    /// The pattern file (with the positions of the last evaluation).
    pub fn file(&self) -> &PatternFile {
        &self.file
    }

    /// Starting positions of v3, v4, v5 for Eq. 5's variables.
    pub fn positions(&self, v: &[f64; 9]) -> [[f64; 3]; 3] {
        let sph = |o: [f64; 3], l: f64, th: f64, ph: f64| {
            [
                o[0] + l * th.cos() * ph.cos(),
                o[1] + l * th.cos() * ph.sin(),
                o[2] + l * th.sin(),
            ]
        };
        [
            sph(self.x1, v[0], v[1], v[2]),
            sph(self.x2, v[3], v[4], v[5]),
            sph(self.x2r, v[6], v[7], v[8]),
        ]
    }

    /// Eq. 5's variables of the pattern file's own v3, v4, v5.
    pub fn file_variables(&self) -> [f64; 9] {
        let at = |n: &str| {
            self.file
                .vertex(n)
                .map_or([0.0; 3], |i| self.file.input.initial[i])
        };
        self.variables(&[at("v3"), at("v4"), at("v5")])
    }

    /// Eq. 5's variables for starting positions of v3, v4, v5 (the inverse of
    /// [`FlasherTask::positions`]; not clamped to the bounds).
    pub fn variables(&self, x: &[[f64; 3]; 3]) -> [f64; 9] {
        let mut out = [0.0; 9];
        for (k, (o, p)) in [self.x1, self.x2, self.x2r].iter().zip(x).enumerate() {
            let d = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            out[3 * k] = l;
            out[3 * k + 1] = (d[2] / l).asin();
            out[3 * k + 2] = d[1].atan2(d[0]);
        }
        out
    }

    /// Evaluate Eq. 5's variables.
    pub fn evaluate(&self, v: &[f64; 9]) -> FlasherEvaluation {
        let x = self.positions(v);
        self.evaluate_with(*v, x)
    }

    /// Evaluate starting positions of v3, v4, v5 directly.
    pub fn evaluate_positions(&self, x: &[[f64; 3]; 3]) -> FlasherEvaluation {
        self.evaluate_with(self.variables(x), *x)
    }

    fn evaluate_with(&self, variables: [f64; 9], x: [[f64; 3]; 3]) -> FlasherEvaluation {
        let mut file = self.file.clone();
        for (n, p) in ["v3", "v4", "v5"].iter().zip(x) {
            file.set_position(n, p);
        }
        let input = &file.input;
        let area: f64 = input
            .faces
            .iter()
            .map(|f| {
                let n = f.len();
                0.5 * (0..n)
                    .map(|k| {
                        let (p, q) = (input.initial[f[k]], input.initial[f[(k + 1) % n]]);
                        p[0] * q[1] - q[0] * p[1]
                    })
                    .sum::<f64>()
            })
            .sum();
        let checker = checker_for(input).ok();
        let run = simulate_with_checker(input, checker.as_ref());
        // The structure is fixed, so only degenerate geometry fails to simulate.
        let failed = || FlasherEvaluation {
            variables,
            positions: x,
            objective: FAILED,
            area,
            gamma: f64::NAN,
            max_delta: f64::NAN,
            theta: 1.0,
            omega: f64::NAN,
            rigid: false,
            feasible: false,
        };
        let report = match run {
            Ok(r) => r,
            Err(_) => return failed(),
        };
        let theta = if checker.is_none() || !report.initial_intersections.is_empty() {
            1.0
        } else {
            report.theta
        };
        let omega: f64 = report
            .final_positions()
            .iter()
            .map(|p| cuboid_distance(*p))
            .sum();
        let gamma = report.gamma;
        let mut objective = -area / AREA_WEIGHT + (gamma + theta + omega);
        if !objective.is_finite() {
            objective = FAILED;
        }
        FlasherEvaluation {
            variables,
            positions: x,
            objective,
            area,
            gamma,
            max_delta: report.max_delta(),
            theta,
            omega,
            rigid: report.rigid,
            feasible: report.rigid && theta == 0.0 && omega <= OMEGA_TOL,
        }
    }
}

/// Distance of a point to the target cuboid, summed over the x, y and z directions.
pub fn cuboid_distance(p: [f64; 3]) -> f64 {
    let (lo, hi) = CUBOID;
    (0..3)
        .map(|k| (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0))
        .sum()
}

/// Settings of the simulated annealing.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnnealSettings {
    /// Objective evaluations in total (the start point included).
    pub evaluations: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// Start temperature.
    pub start_temperature: f64,
    /// Temperature factor per outer loop.
    pub factor: f64,
    /// Evaluations per outer loop (temperature level).
    pub inner: usize,
    /// Start point (Eq. 5 variables, clamped to the bounds); `None` draws one uniformly
    /// within the bounds from the seed.
    pub start: Option<[f64; 9]>,
}

impl Default for AnnealSettings {
    /// The thesis's schedule (Sec. 3.6).
    fn default() -> Self {
        AnnealSettings {
            evaluations: 2500,
            seed: 1,
            start_temperature: 200.0,
            factor: 0.89,
            inner: 50,
            start: None,
        }
    }
}

/// The outcome of an annealing run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnnealResult {
    /// The best design found (re-evaluated once after the run).
    pub best: FlasherEvaluation,
    /// The best feasible design among all evaluations (the objective's weights let an
    /// intersecting design with a larger area beat every feasible one, so the overall best
    /// need not be feasible).
    pub best_feasible: Option<FlasherEvaluation>,
    /// The start point's evaluation.
    pub start: FlasherEvaluation,
    /// Objective evaluations the annealing made.
    pub evaluations: usize,
    /// Objective value of every evaluation, in order.
    pub trace: Vec<f64>,
}

struct Annealer {
    task: FlasherTask,
    rng: RefCell<ChaCha8Rng>,
    trace: Rc<RefCell<Vec<f64>>>,
    best_feasible: Rc<RefCell<Option<FlasherEvaluation>>>,
}

fn to_array(p: &[f64]) -> [f64; 9] {
    let mut v = [0.0; 9];
    for (a, b) in v.iter_mut().zip(p) {
        *a = *b;
    }
    v
}

impl CostFunction for Annealer {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Self::Param) -> Result<f64, ArgminError> {
        let e = self.task.evaluate(&to_array(p));
        let c = e.objective;
        self.trace.borrow_mut().push(c);
        if e.feasible {
            let mut best = self.best_feasible.borrow_mut();
            if best.as_ref().is_none_or(|b| c < b.objective) {
                *best = Some(e);
            }
        }
        Ok(c)
    }
}

impl Anneal for Annealer {
    type Param = Vec<f64>;
    type Output = Vec<f64>;
    type Float = f64;

    fn anneal(&self, p: &Self::Param, _temperature: f64) -> Result<Vec<f64>, ArgminError> {
        let mut rng = self.rng.borrow_mut();
        Ok(p.iter()
            .zip(BOUNDS)
            .map(|(&x, (lo, hi))| {
                let w = (hi - lo) / 10.0;
                (x + rng.random_range(-w..=w)).clamp(lo, hi)
            })
            .collect())
    }
}

/// Run the simulated annealing of Sec. 3.6 on the task.
pub fn anneal(task: &FlasherTask, s: &AnnealSettings) -> Result<AnnealResult, ArgminError> {
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let drawn: Vec<f64> = BOUNDS
        .iter()
        .map(|&(lo, hi)| rng.random_range(lo..=hi))
        .collect();
    let start: Vec<f64> = match s.start {
        Some(v) => v
            .iter()
            .zip(BOUNDS)
            .map(|(&x, (lo, hi))| x.clamp(lo, hi))
            .collect(),
        None => drawn,
    };
    let trace = Rc::new(RefCell::new(Vec::with_capacity(s.evaluations)));
    let best_feasible = Rc::new(RefCell::new(None));
    let problem = Annealer {
        task: task.clone(),
        rng: RefCell::new(rng),
        trace: trace.clone(),
        best_feasible: best_feasible.clone(),
    };
    let accept_rng = {
        use rand_xoshiro::rand_core::SeedableRng as _;
        rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(s.seed ^ 0x9E37_79B9_7F4A_7C15)
    };
    let per_iteration = s.factor.powf(1.0 / s.inner.max(1) as f64);
    let solver = SimulatedAnnealing::new_with_rng(s.start_temperature, accept_rng)?
        .with_temp_func(SATempFunc::Exponential(per_iteration));
    let iters = s.evaluations.saturating_sub(1) as u64;
    let result = Executor::new(problem, solver)
        .configure(|state| state.param(start.clone()).max_iters(iters))
        .ctrlc(false)
        .run()?;
    let best_param = result
        .state()
        .get_best_param()
        .cloned()
        .unwrap_or_else(|| start.clone());
    let trace = trace.borrow().clone();
    let best_feasible = best_feasible.borrow().clone();
    Ok(AnnealResult {
        best: task.evaluate(&to_array(&best_param)),
        best_feasible,
        start: task.evaluate(&to_array(&start)),
        evaluations: trace.len(),
        trace,
    })
}
