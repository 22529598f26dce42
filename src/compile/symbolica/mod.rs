//! Symbolica as a second pipeline and printer (cargo feature `symbolica`, off by default).
//!
//! Our expression graph goes to Symbolica ([`convert`]: shared nodes as aliases, every body
//! in Symbolica's canonical form), Symbolica differentiates it, builds its optimized
//! evaluator (Horner schemes, common subexpressions) and JIT-compiles that (SymJIT).
//! [`Peer`] is that pipeline for `foldsynth bench vertex|model --peer symbolica`;
//! [`print()`] is the printer of `foldsynth formulas --backend symbolica`.
//!
//! **One thread.** Without a licence key Symbolica is a restricted instance: one Symbolica
//! thread per user (a second thread, or a second process of the same user, aborts the
//! process), and it shrinks rayon's global pool to one thread the first time it runs.
//! So every Symbolica call happens on one dedicated thread that owns all Symbolica state,
//! with a channel in front of it ([`call`]); it starts on the first call (only commands
//! that ask for Symbolica make one), never inside a rayon pool, after rayon's global pool
//! is built at its normal size. Before starting, the per-user lock is probed so that a
//! second foldsynth already using Symbolica is an error rather than an abort. The banner
//! Symbolica prints on stdout is switched off by `SYMBOLICA_HIDE_BANNER` (the binary sets
//! it first thing in `main`, so that `--json` output stays JSON); a one-line notice of
//! the restricted licence goes to stderr instead. Without a key Symbolica is for
//! non-commercial use only.

mod convert;

use crate::expr::{ExprGraph, Names, NodeId};
use ::symbolica::atom::{Atom, AtomCore};
use ::symbolica::evaluate::{
    ExpressionEvaluator, JITCompilationSettings, JITCompiledEvaluator, OperationCount,
    OptimizationSettings,
};
use ::symbolica::printer::PrintOptions;
use convert::{Converted, Funcs, Gradients};
use std::collections::HashMap;
use std::panic::AssertUnwindSafe;
use std::path::PathBuf;
use std::sync::OnceLock;
use std::sync::mpsc;
use std::time::Instant;

/// What can go wrong on the way to Symbolica.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The Symbolica thread could not be started.
    #[error("cannot start Symbolica: {0}")]
    Start(String),
    /// The Symbolica thread is gone.
    #[error("the Symbolica thread stopped")]
    Stopped,
    /// Symbolica refused or failed.
    #[error("Symbolica: {0}")]
    Symbolica(String),
}

/// The state the Symbolica thread owns.
#[derive(Default)]
struct State {
    funcs: Option<Funcs>,
    peers: HashMap<u64, Compiled>,
    next_peer: u64,
}

impl State {
    fn funcs(&mut self) -> Result<Funcs, String> {
        if self.funcs.is_none() {
            self.funcs = Some(Funcs::new()?);
        }
        self.funcs.ok_or_else(|| "no functions".to_string())
    }
}

type Task = Box<dyn FnOnce(&mut State) + Send>;

static SERVICE: OnceLock<Result<mpsc::Sender<Task>, String>> = OnceLock::new();

/// The lock file of Symbolica's restricted mode (one thread per user), as its licence
/// code finds it: `$SYMBOLICA_LOCK_DIR`, else the per-user runtime or cache directory.
fn restricted_lock() -> Option<PathBuf> {
    let name = "symbolica-restricted-thread-0.lock";
    if let Some(d) = std::env::var_os("SYMBOLICA_LOCK_DIR") {
        return Some(PathBuf::from(d).join(name));
    }
    let dirs = directories::ProjectDirs::from("io", "symbolica", "symbolica")?;
    let base = dirs.runtime_dir().unwrap_or_else(|| dirs.cache_dir());
    Some(base.join("locks").join(name))
}

/// Err if another process of this user holds Symbolica's restricted-mode lock.
fn probe_restricted_lock() -> Result<(), String> {
    if std::env::var_os("SYMBOLICA_LICENSE").is_some() {
        return Ok(());
    }
    let Some(path) = restricted_lock() else {
        return Ok(());
    };
    let Ok(file) = std::fs::File::open(&path) else {
        return Ok(()); // nobody has created it yet
    };
    match file.try_lock() {
        Ok(()) => {
            let _ = file.unlock();
            Ok(())
        }
        Err(std::fs::TryLockError::WouldBlock) => Err(format!(
            "another process of this user is using Symbolica (lock {}); without a licence key Symbolica allows one thread per user, so run one Symbolica command at a time",
            path.display()
        )),
        // Cannot tell: let Symbolica decide.
        Err(std::fs::TryLockError::Error(_)) => Ok(()),
    }
}

fn start() -> Result<mpsc::Sender<Task>, String> {
    // Symbolica builds rayon's global pool with one thread unless it already exists.
    let _ = rayon::ThreadPoolBuilder::new().build_global();
    probe_restricted_lock()?;
    if std::env::var_os("SYMBOLICA_LICENSE").is_none() {
        eprintln!(
            "note: Symbolica {} without a licence key: a restricted instance (non-commercial use only, one Symbolica thread per user); set SYMBOLICA_LICENSE to use a key",
            ::symbolica::license::LicenseManager::get_version()
        );
    }
    let (tx, rx) = mpsc::channel::<Task>();
    std::thread::Builder::new()
        .name("symbolica".into())
        .spawn(move || {
            let mut state = State::default();
            while let Ok(task) = rx.recv() {
                task(&mut state);
            }
        })
        .map_err(|e| e.to_string())?;
    Ok(tx)
}

/// Run `f` on the Symbolica thread (starting it on first use) and wait for its result.
/// A panic inside `f` comes back as an error and leaves the thread running.
fn call<R: Send + 'static>(
    f: impl FnOnce(&mut State) -> Result<R, String> + Send + 'static,
) -> Result<R, Error> {
    let tx = SERVICE
        .get_or_init(start)
        .as_ref()
        .map_err(|e| Error::Start(e.clone()))?;
    let (rtx, rrx) = mpsc::sync_channel(1);
    tx.send(Box::new(move |state: &mut State| {
        let r = std::panic::catch_unwind(AssertUnwindSafe(|| f(state))).unwrap_or_else(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(format!("panicked: {msg}"))
        });
        let _ = rtx.send(r);
    }))
    .map_err(|_| Error::Stopped)?;
    rrx.recv()
        .map_err(|_| Error::Stopped)?
        .map_err(Error::Symbolica)
}

/// Whether the Symbolica thread has been started in this process.
pub fn started() -> bool {
    SERVICE.get().is_some_and(|r| r.is_ok())
}

/// The id of the Symbolica thread (to check that every call ran there).
pub fn thread_id() -> Result<std::thread::ThreadId, Error> {
    call(|_| Ok(std::thread::current().id()))
}

/// One model or vertex handed to Symbolica: named outputs of a graph over `n_vars`
/// variables and `n_params` parameters.
#[derive(Clone, Debug)]
pub struct Job {
    /// The graph.
    pub graph: ExprGraph,
    /// The outputs, with their printed names.
    pub outputs: Vec<(String, NodeId)>,
    /// Variable and parameter names.
    pub names: Names,
    /// Number of variables (the gradient's length).
    pub n_vars: usize,
    /// Number of parameters.
    pub n_params: usize,
}

impl Job {
    fn convert(&self, funcs: &Funcs) -> Result<Converted, String> {
        convert::convert(
            funcs,
            &self.graph,
            &self.outputs,
            &self.names,
            self.n_vars,
            self.n_params,
        )
    }
}

/// Symbolica's operation count of an evaluator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Ops {
    /// Additions (an n-term sum counts n - 1).
    pub additions: usize,
    /// Multiplications (integer powers count their multiplications).
    pub multiplications: usize,
    /// Inversions (negative powers).
    pub inversions: usize,
    /// Calls (sin, cos, sqrt, our functions, powers with non-integer exponents).
    pub calls: usize,
}

impl Ops {
    fn of(c: OperationCount) -> Ops {
        Ops {
            additions: c.additions,
            multiplications: c.multiplications,
            inversions: c.inversions,
            calls: c.function_calls,
        }
    }
    /// All operations.
    pub fn total(&self) -> usize {
        self.additions + self.multiplications + self.inversions + self.calls
    }
}

impl std::fmt::Display for Ops {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} operations ({} +, {} ×, {} inversions, {} calls)",
            self.total(),
            self.additions,
            self.multiplications,
            self.inversions,
            self.calls
        )
    }
}

fn optimized() -> OptimizationSettings {
    OptimizationSettings::default()
}

/// The evaluator of `exprs` over the job's inputs with `aliases`; `optimize` false gives
/// the straight translation (for the operation count before optimization).
fn evaluator(
    exprs: &[Atom],
    inputs: &[Atom],
    aliases: &[(Atom, Atom)],
    optimize: bool,
) -> Result<ExpressionEvaluator<f64>, String> {
    let settings = if optimize {
        optimized()
    } else {
        OptimizationSettings::default().horner_iterations(0)
    };
    let e = Atom::evaluator_multiple(exprs, inputs)
        .add_aliases(aliases.iter().cloned())
        .map_err(|e| e.to_string())?
        .optimization_settings(settings)
        .build()
        .map_err(|e| e.to_string())?;
    Ok(e.map_coeff(&|c| c.re.to_f64()))
}

/// Output formats of [`print()`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrintFormat {
    /// Symbolica's own notation.
    Plain,
    /// LaTeX (`aligned`).
    Latex,
    /// Mathematica (`ArcCos[Clip[…]]`, `ArcTan[x, y]`, `If[c > 0, a, b]`).
    Mathematica,
}

/// What [`print()`] returns: the text and Symbolica's counts.
#[derive(Clone, Debug)]
pub struct Printed {
    /// The formulas: one line per alias, then the outputs (and gradients).
    pub text: String,
    /// Aliases (shared subexpressions) printed.
    pub aliases: usize,
    /// Operations of the canonical form, translated straight to an evaluator.
    pub before: Ops,
    /// Operations after Symbolica's optimization (Horner schemes, common subexpressions).
    pub after: Ops,
    /// Whether the gradients are Symbolica's.
    pub gradient: bool,
    /// Milliseconds on the Symbolica thread.
    pub millis: f64,
}

impl Printed {
    /// Header lines describing Symbolica's side.
    pub fn header(&self) -> Vec<String> {
        let pct = 100.0 * (self.before.total() as f64 - self.after.total() as f64)
            / self.before.total().max(1) as f64;
        vec![
            format!(
                "printed by Symbolica {} in its canonical form ({} shared subexpressions as aliases{}; {:.1} ms)",
                ::symbolica::license::LicenseManager::get_version(),
                self.aliases,
                if self.gradient {
                    ", gradients by Symbolica's derivatives with the chain rule through the aliases"
                } else {
                    ""
                },
                self.millis
            ),
            format!("Symbolica, canonical form: {}", self.before),
            format!(
                "Symbolica, optimized evaluator (Horner, common subexpressions): {} ({pct:.1}% fewer)",
                self.after
            ),
        ]
    }
}

fn print_options(format: PrintFormat) -> PrintOptions {
    let mut o = match format {
        PrintFormat::Plain => PrintOptions::file(),
        PrintFormat::Latex => PrintOptions::latex(),
        PrintFormat::Mathematica => PrintOptions::mathematica(),
    };
    o.hide_all_namespaces = true;
    o
}

/// Simplify and print `job`'s outputs with Symbolica (and, with `gradient`, their
/// gradients by Symbolica's derivatives).
pub fn print(job: Job, format: PrintFormat, gradient: bool) -> Result<Printed, Error> {
    call(move |state| {
        let t0 = Instant::now();
        let funcs = state.funcs()?;
        let conv = job.convert(&funcs)?;
        let mut aliases = conv.aliases.clone();
        let mut lines: Vec<(String, &Atom)> = Vec::new();
        let grads = if gradient {
            Some(convert::gradients(&conv)?)
        } else {
            None
        };
        let mut exprs: Vec<Atom> = conv.outputs.iter().map(|(_, e)| e.clone()).collect();
        let opts = print_options(format);
        let show = |a: &Atom| format!("{}", a.printer(opts.clone()));
        let mut text = String::new();
        let mut body: Vec<(String, String)> = Vec::new();
        for (w, e) in &conv.aliases {
            body.push((show(w), show(e)));
        }
        for (n, e) in &conv.outputs {
            lines.push((n.clone(), e));
        }
        if let Some(g) = &grads {
            aliases.extend(g.aliases.iter().cloned());
            for (w, e) in &g.aliases {
                body.push((show(w), show(e)));
            }
            for (k, row) in g.outputs.iter().enumerate() {
                for (i, d) in row.iter().enumerate() {
                    lines.push((format!("d{}_d{}", conv.outputs[k].0, conv.var_names[i]), d));
                    exprs.push(d.clone());
                }
            }
        }
        for (n, e) in &lines {
            body.push((n.clone(), show(e)));
        }
        match format {
            PrintFormat::Plain => {
                for (n, e) in &body {
                    text.push_str(&format!("{n} = {e}\n"));
                }
            }
            PrintFormat::Mathematica => {
                for (n, e) in &body {
                    let n: String = n.chars().filter(|c| c.is_ascii_alphanumeric()).collect();
                    text.push_str(&format!("{n} = {e};\n"));
                }
            }
            PrintFormat::Latex => {
                text.push_str("\\begin{aligned}\n");
                for (k, (n, e)) in body.iter().enumerate() {
                    let end = if k + 1 < body.len() { " \\\\" } else { "" };
                    text.push_str(&format!(
                        "\\mathrm{{{}}} &= {e}{end}\n",
                        n.replace('_', "\\_")
                    ));
                }
                text.push_str("\\end{aligned}\n");
            }
        }
        let before = evaluator(&exprs, &conv.inputs, &aliases, false)?.count_operations();
        let after = evaluator(&exprs, &conv.inputs, &aliases, true)?.count_operations();
        Ok(Printed {
            text,
            aliases: aliases.len(),
            before: Ops::of(before),
            after: Ops::of(after),
            gradient,
            millis: t0.elapsed().as_secs_f64() * 1e3,
        })
    })
}

/// The compiled pipeline, kept on the Symbolica thread.
struct Compiled {
    value: JITCompiledEvaluator<f64>,
    value_grad: JITCompiledEvaluator<f64>,
    interpreted: ExpressionEvaluator<f64>,
}

/// Stage times and sizes of building a [`Peer`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct BuildReport {
    /// Milliseconds converting our graph to Symbolica expressions (canonical form).
    pub convert_ms: f64,
    /// Milliseconds in Symbolica's derivatives.
    pub diff_ms: f64,
    /// Milliseconds building the optimized value+gradient evaluator.
    pub optimize_ms: f64,
    /// Milliseconds JIT-compiling it (SymJIT).
    pub jit_ms: f64,
    /// The sum: graph to native value+gradient code.
    pub total_ms: f64,
    /// Aliases for shared subexpressions.
    pub aliases: usize,
    /// Aliases for the total derivatives of aliases.
    pub derivative_aliases: usize,
    /// Operations of the value+gradient evaluator before optimization.
    pub ops_before: Ops,
    /// Operations of the optimized value+gradient evaluator.
    pub ops_after: Ops,
    /// Operations of the optimized value-only evaluator.
    pub ops_value: Ops,
}

/// Symbolica's pipeline for one job: value and value+gradient, JIT-compiled, living on
/// the Symbolica thread. The output buffer has our [`Layout`](crate::compile::Layout):
/// the values, then per output the partial derivatives with respect to every variable.
/// Inputs are the variables followed by the parameters, in one slice.
pub struct Peer {
    id: u64,
    /// How it was built.
    pub report: BuildReport,
    /// Number of outputs.
    pub n_outputs: usize,
    /// Number of variables.
    pub n_vars: usize,
}

/// The evaluators of a [`Peer`], lent to a closure on the Symbolica thread.
pub struct Evaluators<'a>(&'a mut Compiled);

impl Evaluators<'_> {
    /// Values only (JIT); `out` has one entry per output.
    pub fn value(&mut self, inputs: &[f64], out: &mut [f64]) {
        self.0.value.evaluate(inputs, out);
    }
    /// Values and gradients (JIT).
    pub fn value_grad(&mut self, inputs: &[f64], out: &mut [f64]) {
        self.0.value_grad.evaluate(inputs, out);
    }
    /// Values and gradients by Symbolica's evaluator without JIT.
    pub fn value_grad_interpreted(&mut self, inputs: &[f64], out: &mut [f64]) {
        self.0.interpreted.evaluate(inputs, out);
    }
}

impl Peer {
    /// Convert, differentiate, optimize and JIT-compile `job` with Symbolica.
    pub fn build(job: Job) -> Result<Peer, Error> {
        let (n_outputs, n_vars) = (job.outputs.len(), job.n_vars);
        let (id, report) = call(move |state| {
            let funcs = state.funcs()?;
            let t0 = Instant::now();
            let conv = job.convert(&funcs)?;
            let t1 = Instant::now();
            let Gradients { aliases, outputs } = convert::gradients(&conv)?;
            let t2 = Instant::now();
            let values: Vec<Atom> = conv.outputs.iter().map(|(_, e)| e.clone()).collect();
            let mut all = values.clone();
            all.extend(outputs.into_iter().flatten());
            let mut every_alias = conv.aliases.clone();
            every_alias.extend(aliases.iter().cloned());
            let interpreted = evaluator(&all, &conv.inputs, &every_alias, true)?;
            let t3 = Instant::now();
            let jit = JITCompilationSettings::default();
            let value_grad = interpreted.jit_compile(jit.clone())?;
            let t4 = Instant::now();
            let value_eval = evaluator(&values, &conv.inputs, &conv.aliases, true)?;
            let value = value_eval.jit_compile(jit)?;
            let before = evaluator(&all, &conv.inputs, &every_alias, false)?.count_operations();
            let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
            let report = BuildReport {
                convert_ms: ms(t0, t1),
                diff_ms: ms(t1, t2),
                optimize_ms: ms(t2, t3),
                jit_ms: ms(t3, t4),
                total_ms: ms(t0, t4),
                aliases: conv.aliases.len(),
                derivative_aliases: aliases.len(),
                ops_before: Ops::of(before),
                ops_after: Ops::of(interpreted.count_operations()),
                ops_value: Ops::of(value_eval.count_operations()),
            };
            let id = state.next_peer;
            state.next_peer += 1;
            state.peers.insert(
                id,
                Compiled {
                    value,
                    value_grad,
                    interpreted,
                },
            );
            Ok((id, report))
        })?;
        Ok(Peer {
            id,
            report,
            n_outputs,
            n_vars,
        })
    }

    /// Run `f` with the evaluators on the Symbolica thread (for timing them there).
    pub fn with<R: Send + 'static>(
        &self,
        f: impl FnOnce(&mut Evaluators<'_>) -> R + Send + 'static,
    ) -> Result<R, Error> {
        let id = self.id;
        call(move |state| {
            let c = state.peers.get_mut(&id).ok_or("no such peer")?;
            Ok(f(&mut Evaluators(c)))
        })
    }

    /// Values and gradients at `inputs` (variables, then parameters), by the JIT.
    pub fn eval(&self, inputs: &[f64]) -> Result<Vec<f64>, Error> {
        let len = self.n_outputs * (1 + self.n_vars);
        let inputs = inputs.to_vec();
        self.with(move |e| {
            let mut out = vec![0.0; len];
            e.value_grad(&inputs, &mut out);
            out
        })
    }

    /// Values only at `inputs`, by the value-only JIT.
    pub fn eval_values(&self, inputs: &[f64]) -> Result<Vec<f64>, Error> {
        let len = self.n_outputs;
        let inputs = inputs.to_vec();
        self.with(move |e| {
            let mut out = vec![0.0; len];
            e.value(&inputs, &mut out);
            out
        })
    }

    /// Values and gradients at `inputs` by Symbolica's evaluator without the JIT.
    pub fn eval_interpreted(&self, inputs: &[f64]) -> Result<Vec<f64>, Error> {
        let len = self.n_outputs * (1 + self.n_vars);
        let inputs = inputs.to_vec();
        self.with(move |e| {
            let mut out = vec![0.0; len];
            e.value_grad_interpreted(&inputs, &mut out);
            out
        })
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let id = self.id;
        let _ = call(move |state| {
            state.peers.remove(&id);
            Ok(())
        });
    }
}
