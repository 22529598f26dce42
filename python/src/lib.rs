//! The `foldsynth` Python package: a thin layer over the foldsynth library.
//!
//! `Task.load(path)` → `task.enumerate(n_max)` (graphs) → `task.model(graph, candidate)`
//! (the compiled design model: objective, constraints and all gradients in one native
//! call) → `model.value_and_grad(x, modes)` / `model.constraints_and_jacobian(x, modes)`
//! on NumPy arrays, `model.optimize()`; `task.synthesize(out)` runs the whole method;
//! `vertex(spec, t)` is the PTU of one vertex. Native code runs with the GIL released;
//! errors are Python exceptions carrying foldsynth's messages.

use foldsynth::compile::Options;
use foldsynth::grammar::{CreaseGraph, Enumeration, Filters};
use foldsynth::kinematics::foldability::RIGID_TOL;
use foldsynth::kinematics::{
    Mode, VertexSpec, closure_residual, flat_foldable, solve_vertex, wrap_angle,
};
use foldsynth::model::compiled::{CompiledModel, ModelProblem, objective_target};
use foldsynth::model::{Model as FsModel, Plan};
use foldsynth::task::Task as FsTask;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;
use std::sync::Arc;

mod run;

/// A NumPy vector handed to Python.
type Vector<'py> = Bound<'py, PyArray1<f64>>;
/// A NumPy matrix handed to Python.
type Matrix<'py> = Bound<'py, PyArray2<f64>>;

pyo3::create_exception!(
    foldsynth,
    FoldsynthError,
    PyValueError,
    "An error reported by foldsynth: a bad task file, graph, vertex notation or search setting."
);

/// foldsynth's message (with its causes) as a Python exception.
fn fs_err(e: impl Into<anyhow::Error>) -> PyErr {
    FoldsynthError::new_err(format!("{:#}", e.into()))
}

/// A 1-D float array (NumPy float64 arrays without conversion, any other sequence of
/// numbers through NumPy), copied while the GIL is held.
fn read_f64s(ob: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    if let Ok(a) = ob.cast::<PyArray1<f64>>() {
        return Ok(match a.to_vec() {
            Ok(v) => v,
            Err(_) => a.to_owned_array().to_vec(),
        });
    }
    if let Ok(v) = ob.extract::<Vec<f64>>() {
        return Ok(v);
    }
    let np = ob.py().import("numpy")?;
    let arr = np.call_method1("asarray", (ob, "float64")).map_err(|_| {
        PyTypeError::new_err(format!(
            "{what}: expected a 1-D array of numbers, got {}",
            type_name(ob)
        ))
    })?;
    match arr.cast::<PyArray1<f64>>() {
        Ok(a) => Ok(a.to_owned_array().to_vec()),
        Err(_) => Err(PyValueError::new_err(format!(
            "{what}: expected a 1-D array of numbers, got shape {}",
            arr.getattr("shape")?
        ))),
    }
}

fn type_name(ob: &Bound<'_, PyAny>) -> String {
    ob.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// A design task (a task file: G0, N_max, motion, bounds, objective, checks).
#[pyclass(module = "foldsynth", frozen)]
struct Task {
    task: Arc<FsTask>,
}

#[pymethods]
impl Task {
    /// Load and validate a task file (e.g. grammar/gripper.toml).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Task> {
        let task = FsTask::load(&path).map_err(fs_err)?;
        Ok(Task {
            task: Arc::new(task),
        })
    }

    /// The task's name.
    #[getter]
    fn name(&self) -> &str {
        &self.task.name
    }

    /// N_max: the maximum number of internal vertices.
    #[getter]
    fn n_max(&self) -> usize {
        self.task.n_max
    }

    /// The end of the motion t_max (None when the task defines no motion).
    #[getter]
    fn t_max(&self) -> Option<f64> {
        self.task.motion.as_ref().map(|m| m.t_max)
    }

    /// The meaningful graphs of the task (rules r1 and r2 with the isomorphism, mirror
    /// and validity filters), up to `n_max` internal vertices (default: the task's).
    #[pyo3(signature = (n_max = None))]
    fn enumerate(&self, py: Python<'_>, n_max: Option<usize>) -> PyResult<Vec<Graph>> {
        let n_max = n_max.unwrap_or(self.task.n_max);
        if n_max == 0 {
            return Err(PyValueError::new_err("n_max must be at least 1"));
        }
        let task = &self.task;
        let e = py
            .detach(|| Enumeration::run_limited(task, n_max, Filters::all(), 200_000))
            .map_err(fs_err)?;
        Ok(e.meaningful()
            .map(|node| Graph::new(task, node.graph.clone()))
            .collect())
    }

    /// The compiled design model of `graph` (a Graph from `enumerate` or a rule sequence
    /// such as "2, 3, (4, 8), 4, (7, 8)") gripping with candidate 1, 2 or 3.
    #[pyo3(signature = (graph, candidate = 1))]
    fn model(&self, py: Python<'_>, graph: &Bound<'_, PyAny>, candidate: usize) -> PyResult<Model> {
        let graph = if let Ok(g) = graph.cast::<Graph>() {
            let g = g.get();
            if g.task != self.task.name {
                return Err(PyValueError::new_err(format!(
                    "the graph {} belongs to task '{}', not '{}'",
                    g.sequence, g.task, self.task.name
                )));
            }
            g.graph.clone()
        } else if let Ok(s) = graph.cast::<PyString>() {
            // `to_cow`: the stable ABI (abi3) before Python 3.10 has no borrowed UTF-8 view.
            let s = s.to_cow()?;
            CreaseGraph::from_sequence(&self.task, &s)
                .map_err(|e| FoldsynthError::new_err(format!("graph '{s}': {e}")))?
        } else {
            return Err(PyTypeError::new_err(format!(
                "graph: expected a Graph or a rule sequence string, got {}",
                type_name(graph)
            )));
        };
        if !(1..=3).contains(&candidate) {
            return Err(PyValueError::new_err(
                "candidate must be 1, 2 or 3 (the successors of the vertex extended last)",
            ));
        }
        let task = &self.task;
        let (model, compiled) = py
            .detach(|| -> anyhow::Result<_> {
                let model = FsModel::from_plan(Plan::new(&graph)?, task, candidate - 1)?;
                let compiled = CompiledModel::new(&model, &Options::default())?;
                Ok((model, compiled))
            })
            .map_err(fs_err)?;
        Ok(Model {
            task: self.task.name.clone(),
            model,
            compiled,
        })
    }

    /// Run the whole method (enumerate, optimize every alternative, check, verify,
    /// export) into the directory `out`; returns the summary (as summary.json). `out`
    /// must be new, empty or a run of the same settings unless `force` (as the CLI's
    /// `--force`); every count is checked against its limit (as the CLI).
    /// `foldsynth.synthesize` is the same search returning a `Run`, with progress.
    #[pyo3(signature = (out, *, jobs = 0, starts = 16, seed = 0, resume = false, force = false, n_max = None, sweep = 181, export = true))]
    #[allow(clippy::too_many_arguments)]
    fn synthesize<'py>(
        &self,
        py: Python<'py>,
        out: PathBuf,
        jobs: usize,
        starts: usize,
        seed: u64,
        resume: bool,
        force: bool,
        n_max: Option<usize>,
        sweep: usize,
        export: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        // The thesis's rules (r1, r2); r2′ is `foldsynth.synthesize(rules="r1,r2,r2p")`.
        let (rules, post_check_only) = ("r1,r2", false);
        run::synthesize(
            py,
            self,
            out,
            jobs,
            starts,
            seed,
            resume,
            force,
            n_max,
            sweep,
            export,
            None,
            false,
            None,
            false,
            None,
            false,
            None,
            rules,
            post_check_only,
            "exhaustive",
            None,
            None,
            true,
            None,
        )
    }

    fn __repr__(&self) -> String {
        format!("Task('{}', n_max={})", self.task.name, self.task.n_max)
    }
}

/// A crease-pattern graph of a task.
#[pyclass(module = "foldsynth", frozen)]
struct Graph {
    task: String,
    graph: CreaseGraph,
    /// The rule sequence, e.g. "2, 3, (4, 8), 4, (7, 8)".
    #[pyo3(get)]
    sequence: String,
    /// Rule applications.
    #[pyo3(get)]
    level: usize,
    /// Internal (extended) vertices.
    #[pyo3(get)]
    n_internal: usize,
    /// Design alternatives: 2^n_internal modes × 3 gripping candidates.
    #[pyo3(get)]
    alternatives: u64,
}

impl Graph {
    fn new(task: &FsTask, graph: CreaseGraph) -> Graph {
        Graph {
            task: task.name.clone(),
            sequence: graph.sequence(),
            level: graph.level(),
            n_internal: graph.internal_count(),
            alternatives: graph.alternatives(),
            graph,
        }
    }
}

#[pymethods]
impl Graph {
    fn __str__(&self) -> &str {
        &self.sequence
    }
    fn __repr__(&self) -> String {
        format!("Graph('{}')", self.sequence)
    }
}

/// A compiled design model: one graph, one gripping candidate, one task. The objective
/// (out[0]) and the constraints g ≥ 0 with all their gradients come from one native call;
/// `modes` are ±1 (or "up"/"down") per internal vertex, `t` the values of the driving
/// parameter the model folds at (default: the task's, t_max first).
#[pyclass(module = "foldsynth", frozen)]
struct Model {
    task: String,
    model: FsModel,
    compiled: CompiledModel,
}

impl Model {
    fn n_modes(&self) -> usize {
        self.model.plan.internal.len()
    }

    fn names_vec(&self) -> Vec<String> {
        self.model
            .free
            .iter()
            .map(|&i| self.model.plan.variables[i].name.clone())
            .collect()
    }

    fn read_x(&self, x: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let x = read_f64s(x, "x")?;
        let n = self.compiled.n_vars;
        if x.len() != n {
            return Err(PyValueError::new_err(format!(
                "x has {} entries; this model has {n} variables ({})",
                x.len(),
                self.names_vec().join(", ")
            )));
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "x[{i}] ({}) is {}; the model needs finite values",
                self.names_vec()[i],
                x[i]
            )));
        }
        Ok(x)
    }

    fn read_modes(&self, modes: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let n = self.n_modes();
        let bad = |what: String| {
            PyValueError::new_err(format!(
                "modes: {what}; give {n} modes (one per internal vertex, in extension order) as +1/-1 or \"up\"/\"down\""
            ))
        };
        let signs: Vec<f64> = if let Ok(s) = modes.cast::<PyString>() {
            s.to_cow()?
                .split(',')
                .map(|m| {
                    Mode::parse(m)
                        .map(Mode::sign)
                        .ok_or_else(|| bad(format!("'{}' is not a mode", m.trim())))
                })
                .collect::<PyResult<_>>()?
        } else if let Ok(v) = read_f64s(modes, "modes") {
            if let Some(k) = v.iter().position(|m| *m != 1.0 && *m != -1.0) {
                return Err(bad(format!("modes[{k}] is {}", v[k])));
            }
            v
        } else if let Ok(v) = modes.extract::<Vec<String>>() {
            v.iter()
                .map(|m| {
                    Mode::parse(m)
                        .map(Mode::sign)
                        .ok_or_else(|| bad(format!("'{m}' is not a mode")))
                })
                .collect::<PyResult<_>>()?
        } else {
            return Err(bad(format!("got {}", type_name(modes))));
        };
        if signs.len() != n {
            return Err(bad(format!("{} were given", signs.len())));
        }
        Ok(signs)
    }

    fn read_times(&self, t: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<f64>> {
        let k = self.model.times.len();
        let Some(t) = t.filter(|t| !t.is_none()) else {
            return Ok(self.model.times.clone());
        };
        let times = match t.extract::<f64>() {
            Ok(v) if k == 1 => vec![v],
            Ok(_) => {
                return Err(PyValueError::new_err(format!(
                    "t: this model folds at {k} values of t (t_max first, then the targets'); pass an array of {k}"
                )));
            }
            Err(_) => read_f64s(t, "t")?,
        };
        if times.len() != k {
            return Err(PyValueError::new_err(format!(
                "t has {} entries; this model folds at {k} values of t (t_max first, then the targets')",
                times.len()
            )));
        }
        if let Some(i) = times.iter().position(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "t[{i}] is {}; t must be finite",
                times[i]
            )));
        }
        Ok(times)
    }

    /// The whole output buffer at x (values, then gradients), computed without the GIL.
    fn eval(
        &self,
        py: Python<'_>,
        x: &Bound<'_, PyAny>,
        modes: &Bound<'_, PyAny>,
        t: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<f64>> {
        let x = self.read_x(x)?;
        let mut params = self.read_modes(modes)?;
        params.extend(self.read_times(t)?);
        let mut buf = vec![0.0; self.compiled.buffer_len()];
        py.detach(|| self.compiled.call(&x, &params, &mut buf));
        Ok(buf)
    }

    fn jacobian<'py>(&self, py: Python<'py>, buf: &[f64]) -> Matrix<'py> {
        let (n, m) = (self.compiled.n_vars, self.compiled.n_constraints);
        let start = self.compiled.compiled.layout.gradient(1).start;
        let jac = PyArray2::<f64>::zeros(py, [m, n], false);
        // SAFETY: the array was just created here, is contiguous and nobody else sees it.
        unsafe { jac.as_slice_mut() }
            .expect("a new array is contiguous")
            .copy_from_slice(&buf[start..start + m * n]);
        jac
    }
}

#[pymethods]
impl Model {
    /// The variables' names (Φ_opt, the order of x).
    #[getter]
    fn names(&self) -> Vec<String> {
        self.names_vec()
    }

    /// Bounds of the variables: an (n_vars, 2) array of [lower, upper].
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<Vec<f64>> = self
            .model
            .free
            .iter()
            .map(|&i| {
                let (l, h) = self.model.var_bounds(i);
                vec![l, h]
            })
            .collect();
        PyArray2::from_vec2(py, &rows).expect("rows of two")
    }

    /// Number of variables.
    #[getter]
    fn n_vars(&self) -> usize {
        self.compiled.n_vars
    }

    /// Number of constraints g ≥ 0.
    #[getter]
    fn n_constraints(&self) -> usize {
        self.compiled.n_constraints
    }

    /// Number of internal vertices (= number of modes).
    #[getter(n_modes)]
    fn n_modes_py(&self) -> usize {
        self.n_modes()
    }

    /// The values of t the model folds at by default (t_max first, then the targets').
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.times)
    }

    /// A readable label per constraint (equation, vertex, bound).
    #[getter]
    fn constraint_labels(&self) -> Vec<String> {
        (0..self.compiled.n_constraints)
            .map(|k| self.model.constraint_label(k))
            .collect()
    }

    /// The graph's rule sequence.
    #[getter]
    fn graph(&self) -> &str {
        &self.model.plan.sequence
    }

    /// The gripping candidate (1, 2 or 3).
    #[getter]
    fn candidate(&self) -> usize {
        self.model.candidate + 1
    }

    /// The task's success threshold on Ω (Eq. 37/38).
    #[getter]
    fn threshold(&self) -> f64 {
        self.model.threshold
    }

    /// The value of the compiled objective (out[0]) that means the target is met.
    #[getter]
    fn objective_target(&self) -> f64 {
        objective_target(&self.model)
    }

    /// Objective and its gradient at x: `(f, df)` with df an array of n_vars, as
    /// `scipy.optimize.minimize(..., jac=True)` expects.
    #[pyo3(signature = (x, modes, t = None))]
    fn value_and_grad<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        modes: &Bound<'py, PyAny>,
        t: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(f64, Vector<'py>)> {
        let buf = self.eval(py, x, modes, t)?;
        let l = &self.compiled.compiled.layout;
        Ok((buf[0], PyArray1::from_slice(py, &buf[l.gradient(0)])))
    }

    /// Constraints and their Jacobian at x: `(g, J)` with g of n_constraints (satisfied
    /// when ≥ 0) and J of shape (n_constraints, n_vars).
    #[pyo3(signature = (x, modes, t = None))]
    fn constraints_and_jacobian<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        modes: &Bound<'py, PyAny>,
        t: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Vector<'py>, Matrix<'py>)> {
        let buf = self.eval(py, x, modes, t)?;
        let m = self.compiled.n_constraints;
        Ok((
            PyArray1::from_slice(py, &buf[1..1 + m]),
            self.jacobian(py, &buf),
        ))
    }

    /// Everything from one call: `(f, g, df, J)`.
    #[pyo3(signature = (x, modes, t = None))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        modes: &Bound<'py, PyAny>,
        t: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(f64, Vector<'py>, Vector<'py>, Matrix<'py>)> {
        let buf = self.eval(py, x, modes, t)?;
        let m = self.compiled.n_constraints;
        let l = &self.compiled.compiled.layout;
        Ok((
            buf[0],
            PyArray1::from_slice(py, &buf[1..1 + m]),
            PyArray1::from_slice(py, &buf[l.gradient(0)]),
            self.jacobian(py, &buf),
        ))
    }

    /// Ω as the thesis states it (Eq. 37/38): the weighted distance of the gripping
    /// vertex from its targets, computed by the plain f64 kinematics.
    fn omega(&self, x: &Bound<'_, PyAny>, modes: &Bound<'_, PyAny>) -> PyResult<f64> {
        let x = self.read_x(x)?;
        let modes = self.read_modes(modes)?;
        Ok(self.model.omega(&self.model.full_vars(&x), &modes))
    }

    /// foldsynth's optimizer (multi-start augmented Lagrangian with L-BFGS, stopping at
    /// the target): a dict with x, objective, omega, constraints, violation, feasible,
    /// met_target, evaluations, starts_run.
    #[pyo3(signature = (modes = None, starts = 32, seed = 0))]
    fn optimize<'py>(
        &self,
        py: Python<'py>,
        modes: Option<&Bound<'py, PyAny>>,
        starts: usize,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let modes = match modes {
            Some(m) => self.read_modes(m)?,
            None => vec![1.0; self.n_modes()],
        };
        if starts == 0 {
            return Err(PyValueError::new_err("starts must be at least 1"));
        }
        let opts = foldsynth::optimize::Options {
            starts,
            seed,
            target: Some(objective_target(&self.model)),
            ..Default::default()
        };
        let (model, compiled) = (&self.model, &self.compiled);
        let (sol, omega) = py.detach(|| {
            let problem = ModelProblem::new(model, compiled, &modes);
            let sol = foldsynth::optimize::minimize(&problem, &opts);
            let omega = model.omega(&model.full_vars(&sol.x), &modes);
            (sol, omega)
        });
        let d = PyDict::new(py);
        d.set_item("x", PyArray1::from_slice(py, &sol.x))?;
        d.set_item("objective", sol.f)?;
        d.set_item("omega", omega)?;
        d.set_item("constraints", PyArray1::from_slice(py, &sol.g))?;
        d.set_item("violation", sol.violation)?;
        d.set_item("feasible", sol.feasible)?;
        d.set_item("met_target", sol.met_target)?;
        d.set_item("evaluations", sol.evaluations)?;
        d.set_item("starts_run", sol.starts_run)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model('{}', candidate={}, task='{}', n_vars={}, n_constraints={})",
            self.model.plan.sequence,
            self.model.candidate + 1,
            self.task,
            self.compiled.n_vars,
            self.compiled.n_constraints
        )
    }
}

/// The PTU of one vertex in the thesis's notation (Eq. 24, sectors in degrees), e.g.
/// "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))", at t (a number or an array):
/// a dict of unit angles U, internal angles theta, start and end angles beta and delta,
/// dihedral angles phi (wrapped to (-π, π]), rigid margins, rigid, closure residual (all
/// radians; one row of 3 per t), and the vertex's degree, mode, developability, flat
/// foldability and U(π).
#[pyfunction]
fn vertex<'py>(py: Python<'py>, spec: &str, t: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let parsed = VertexSpec::parse(spec)
        .map_err(|e| FoldsynthError::new_err(format!("invalid vertex '{spec}': {e}")))?;
    let scalar = t.extract::<f64>().ok();
    let ts = match scalar {
        Some(v) => vec![v],
        None => read_f64s(t, "t")?,
    };
    if let Some(i) = ts.iter().position(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "t[{i}] is {}; t must be finite",
            ts[i]
        )));
    }
    let mode = parsed.mode.sign();
    let mut rows: [Vec<[f64; 3]>; 6] = Default::default();
    let mut rigid = Vec::with_capacity(ts.len());
    let mut closure = Vec::with_capacity(ts.len());
    for &tv in &ts {
        let units = parsed.units_at(tv);
        let mut st = solve_vertex(&units, &mode);
        st.phi = st.phi.map(wrap_angle);
        rigid.push(st.margins.iter().copied().fold(f64::INFINITY, f64::min) >= -RIGID_TOL);
        closure.push(closure_residual(&units, &st.phi));
        for (r, v) in rows
            .iter_mut()
            .zip([st.u, st.theta, st.beta, st.delta, st.phi, st.margins])
        {
            r.push(v);
        }
    }
    let d = PyDict::new(py);
    let keys = ["U", "theta", "beta", "delta", "phi", "margins"];
    for (key, r) in keys.iter().zip(&rows) {
        if scalar.is_some() {
            d.set_item(*key, PyArray1::from_slice(py, &r[0]))?;
        } else {
            let v: Vec<Vec<f64>> = r.iter().map(|a| a.to_vec()).collect();
            d.set_item(*key, PyArray2::from_vec2(py, &v).expect("rows of three"))?;
        }
    }
    if scalar.is_some() {
        d.set_item("t", ts[0])?;
        d.set_item("rigid", rigid[0])?;
        d.set_item("closure", closure[0])?;
    } else {
        d.set_item("t", PyArray1::from_slice(py, &ts))?;
        d.set_item("rigid", PyArray1::from_slice(py, &rigid))?;
        d.set_item("closure", PyArray1::from_slice(py, &closure))?;
    }
    let (flat, u_pi) = flat_foldable(&parsed.units_at(0.0), 1e-9);
    let sector_sum: f64 = parsed.sectors_rad().iter().sum();
    d.set_item("vertex", parsed.to_string())?;
    d.set_item("degree", parsed.degree())?;
    d.set_item("mode", parsed.mode.to_string())?;
    d.set_item(
        "developable",
        (sector_sum - 2.0 * std::f64::consts::PI).abs() < 1e-9,
    )?;
    d.set_item("flat_foldable", flat)?;
    d.set_item("U_pi", PyArray1::from_slice(py, &u_pi))?;
    Ok(d)
}

/// The native half of the `foldsynth` package (`foldsynth._native`): tasks, graphs,
/// compiled models, the search and the design files; `foldsynth/__init__.py` re-exports
/// them beside the pure-Python `Run`.
#[pymodule]
#[pyo3(name = "_native")]
fn foldsynth_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Task>()?;
    m.add_class::<Graph>()?;
    m.add_class::<Model>()?;
    m.add_function(wrap_pyfunction!(vertex, m)?)?;
    m.add_function(wrap_pyfunction!(run::synthesize, m)?)?;
    m.add_function(wrap_pyfunction!(run::design_fold, m)?)?;
    m.add_function(wrap_pyfunction!(run::design_frames, m)?)?;
    m.add("FoldsynthError", m.py().get_type::<FoldsynthError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
