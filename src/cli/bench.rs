//! `foldsynth bench …`: speed measured in one run and reported as ratios.
//!
//! One sub-subcommand per benchmark; add a variant to [`BenchCommand`] and a match arm
//! in [`run`] to add one.

use crate::compile::vertex::{self, VertexModel};
use crate::compile::{Dual, Options, compile};
use crate::cpu_time::Stopwatch;
use crate::expr::Tape;
use crate::geom::max_or_nan;
use crate::kinematics::VertexSpec;
use crate::kinematics::foldability::{self, RIGID_TOL};
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `foldsynth bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// What to measure.
    #[command(subcommand)]
    pub what: BenchCommand,
}

/// The benchmarks.
#[derive(Debug, clap::Subcommand)]
pub enum BenchCommand {
    /// One vertex: value+gradient of φ1+φ2+φ3 by JIT, interpreter, f64 + central
    /// differences and dual numbers, and the compile latency.
    Vertex(VertexBenchArgs),
    /// One design model: objective and constraints with gradients by JIT, interpreter and
    /// f64 + central differences, and the compile latency.
    Model(super::bench_model::ModelBenchArgs),
    /// One folding motion of one design: the compiled PTU model against the bar-and-hinge
    /// simulation (thesis Sec. 3), same states.
    Numeric(super::bench_numeric::NumericBenchArgs),
    /// One design's files, part by part (FOLD, SVG, meshes, pictures, GIF frames and their
    /// LZW against the gif crate's), on one thread.
    Export(super::bench_export::ExportBenchArgs),
}

/// Run `foldsynth bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        BenchCommand::Vertex(a) => run_vertex(a),
        BenchCommand::Model(a) => super::bench_model::run(a),
        BenchCommand::Numeric(a) => super::bench_numeric::run(a),
        BenchCommand::Export(a) => super::bench_export::run(a),
    }
}

/// A peer implementation to measure in the same run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Peer {
    /// CasADi SX, reverse-mode gradient, generated C compiled with `gcc -O3`.
    Casadi,
    /// Symbolica: its canonical form, its derivatives, its optimized evaluator, SymJIT
    /// (needs the `symbolica` cargo feature).
    Symbolica,
}

/// Arguments of `foldsynth bench vertex`.
#[derive(Debug, clap::Args)]
pub struct VertexBenchArgs {
    /// The vertex in the thesis's notation, e.g.
    /// "v(up, ((40,50,45,35,40),(t,-t,t,-t)), (55), (95))".
    pub spec: String,
    /// Make the sector angles variables (gradient with respect to all of them); otherwise
    /// the gradient is with respect to t.
    #[arg(long)]
    pub symbolic_sectors: bool,
    /// Print one JSON object (times in nanoseconds, compile times in milliseconds).
    #[arg(long)]
    pub json: bool,
    /// Also run peer implementations in this invocation (repeat or separate by commas:
    /// `--peer casadi,symbolica`).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub peer: Vec<Peer>,
    /// The driving parameter at which to evaluate (default: the most rigid sample of
    /// (0, π), away from singular states).
    #[arg(long, allow_hyphen_values = true)]
    pub t: Option<f64>,
    /// Milliseconds of measurement per row (split into rounds of batches; the fastest
    /// round's median batch is reported).
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(1..=crate::limits::BENCH_MILLIS_MAX))]
    pub millis: u64,
    /// The peer script (default: the crate's benches/peers/casadi_vertex.py).
    #[arg(long)]
    pub peer_script: Option<PathBuf>,
}

/// Median nanoseconds per call of `f`, over batches filling about `budget`: CPU time of
/// this thread per batch (where the platform has a thread clock), so time the process
/// spends waiting for a core on a busy machine does not count.
pub(crate) fn time_ns(budget: Duration, mut f: impl FnMut()) -> f64 {
    let batch = |f: &mut dyn FnMut(), n: usize| {
        let t = Stopwatch::start();
        for _ in 0..n {
            f();
        }
        t.cpu_ms() * 1e6
    };
    // Calibrate: how many calls take ~1/20 of the budget.
    let target_ns = budget.as_secs_f64() * 1e9 / 20.0;
    let mut n = 1usize;
    loop {
        let e = batch(&mut f, n);
        if e >= target_ns / 4.0 || n >= 1 << 30 {
            let per = e / n as f64;
            n = ((target_ns / per.max(1e-1)) as usize).max(1);
            break;
        }
        n *= 4;
    }
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed() < budget && samples.len() < 41) {
        samples.push(batch(&mut f, n) / n as f64);
    }
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// Median of `reps` runs of `f` in milliseconds.
pub(crate) fn time_ms<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..reps {
        let t = Instant::now();
        let r = f();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some(r);
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last.expect("reps >= 1"))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1.0)
}

/// Run `foldsynth bench vertex`.
pub fn run_vertex(args: VertexBenchArgs) -> Result<()> {
    let spec = VertexSpec::parse(&args.spec).context("invalid vertex")?;
    let t = args.t.unwrap_or_else(|| vertex::most_rigid_t(&spec));
    if !(t.is_finite() && t.abs() <= crate::limits::COORD_MAX) {
        bail!("--t must be a finite number within ±1e6");
    }
    let sym = args.symbolic_sectors;
    let (vars, params) = vertex::point(&spec, sym, t);
    let n = vars.len();
    let budget = Duration::from_millis(args.millis.max(10));

    // Compile latency, stage by stage (median of several runs; the first warms caches).
    let reps = 7;
    let (build_ms, model) = time_ms(reps, || VertexModel::build(&spec, sym));
    let graph = model.ctx.to_graph();
    let out = [model.phi_sum_id()];
    let opts = Options::default();
    let (pipeline_ms, compiled) = time_ms(reps, || {
        compile(&graph, &out, model.n_vars, model.n_params, &opts)
    });
    let compiled = compiled?;
    let value_only = compile(
        &graph,
        &out,
        model.n_vars,
        model.n_params,
        &Options {
            gradients: false,
            ..Options::default()
        },
    )?;
    let rep = &compiled.report;
    let compile_ms = build_ms + pipeline_ms;

    // Everything computes the same numbers: check before timing.
    let mut buf = vec![0.0; compiled.layout.len()];
    compiled.function.call(&vars, &params, &mut buf)?;
    let tape = Tape::new(&compiled.graph, &compiled.outputs, n, params.len())?;
    let mut tbuf = vec![0.0; compiled.layout.len()];
    let mut scratch = Vec::new();
    tape.eval_with(&mut scratch, &vars, &params, &mut tbuf)?;
    let dvars: Vec<Dual> = (0..n).map(|i| Dual::var(vars[i], i, n)).collect();
    let dparams: Vec<Dual> = params.iter().map(|&p| Dual::constant(p)).collect();
    let dual = vertex::phi_sum(&spec, sym, &dvars, &dparams);
    let f64_value = vertex::phi_sum(&spec, sym, &vars, &params);
    let h = 1e-6;
    let central = |v: &[f64]| -> Vec<f64> {
        let mut g = vec![0.0; n];
        let mut x = v.to_vec();
        for i in 0..n {
            let xi = x[i];
            x[i] = xi + h;
            let fp = vertex::phi_sum(&spec, sym, &x, &params);
            x[i] = xi - h;
            let fm = vertex::phi_sum(&spec, sym, &x, &params);
            x[i] = xi;
            g[i] = (fp - fm) / (2.0 * h);
        }
        g
    };
    let fd = central(&vars);
    let grad: Vec<f64> = buf[compiled.layout.gradient(0)].to_vec();
    let value = buf[0];
    let max_dev_dual =
        max_or_nan((0..n).map(|i| rel(grad[i], dual.g.get(i).copied().unwrap_or(0.0))));
    let max_dev_fd = max_or_nan((0..n).map(|i| rel(grad[i], fd[i])));
    let max_dev_value = rel(buf[0], f64_value).max(rel(buf[0], tbuf[0]));

    // Timings. Every row is measured in each of several rounds (the peer's harness too)
    // and the fastest round is reported: interference from other processes only ever
    // adds time, so the minimum is the most repeatable estimate on a busy machine, and
    // all rows are treated alike.
    let peer_setup = if args.peer.contains(&Peer::Casadi) {
        Some(casadi_setup(&args, &spec, t)?)
    } else {
        None
    };
    let mut symbolica = if args.peer.contains(&Peer::Symbolica) {
        let job = super::bench_symbolica::PeerJob {
            graph: graph.clone(),
            outputs: vec![("phi_sum".to_string(), out[0])],
            names: model.names.clone(),
            n_vars: model.n_vars,
            n_params: model.n_params,
        };
        let inputs: Vec<f64> = vars.iter().chain(&params).copied().collect();
        Some(super::bench_symbolica::SymbolicaPeer::new(
            job, inputs, &buf, 3,
        )?)
    } else {
        None
    };
    let rounds: u32 = 7;
    let slice = budget / rounds;
    let mut vbuf = [0.0];
    let mut rows: [Vec<f64>; 7] = Default::default();
    let mut theirs: Vec<serde_json::Value> = Vec::new();
    let mut harness_error = None;
    for _ in 0..rounds {
        rows[0].push(time_ns(slice, || {
            value_only
                .function
                .call(black_box(&vars), black_box(&params), &mut vbuf)
                .expect("lengths checked above");
            black_box(&vbuf);
        }));
        rows[1].push(time_ns(slice, || {
            compiled
                .function
                .call(black_box(&vars), black_box(&params), &mut buf)
                .expect("lengths checked above");
            black_box(&buf);
        }));
        rows[2].push(time_ns(slice, || {
            tape.eval_with(
                &mut scratch,
                black_box(&vars),
                black_box(&params),
                &mut tbuf,
            )
            .expect("lengths checked above");
            black_box(&tbuf);
        }));
        rows[3].push(time_ns(slice, || {
            black_box(vertex::phi_sum(
                &spec,
                sym,
                black_box(&vars),
                black_box(&params),
            ));
        }));
        rows[4].push(time_ns(slice, || {
            black_box(vertex::phi_sum(
                &spec,
                sym,
                black_box(&vars),
                black_box(&params),
            ));
            black_box(central(black_box(&vars)));
        }));
        rows[5].push(time_ns(slice, || {
            let dv: Vec<Dual> = (0..n).map(|i| Dual::var(vars[i], i, n)).collect();
            black_box(vertex::phi_sum(
                &spec,
                sym,
                black_box(&dv),
                black_box(&dparams),
            ));
        }));
        if let Some(s) = &mut symbolica {
            s.round(slice)?;
        }
        if let Some(PeerSetup::Harness { argv, .. }) = &peer_setup
            && harness_error.is_none()
        {
            match run_harness(argv) {
                Ok(r) => theirs.push(r),
                Err(e) => harness_error = Some(e),
            }
        }
    }
    let fastest = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let jit_value_ns = fastest(&rows[0]);
    let jit_value_grad_ns = fastest(&rows[1]);
    let interpreter_value_grad_ns = fastest(&rows[2]);
    let f64_value_ns = fastest(&rows[3]);
    let f64_central_diff_ns = fastest(&rows[4]);
    let dual_ns = fastest(&rows[5]);
    let peer = match peer_setup {
        None => None,
        Some(PeerSetup::Skipped(v)) => Some(v),
        Some(PeerSetup::Harness { mut info, dir, .. }) => {
            let _ = std::fs::remove_dir_all(&dir);
            if let Some(e) = harness_error {
                return Err(e);
            }
            let ns: Vec<f64> = theirs
                .iter()
                .filter_map(|r| r.get("value_grad_ns").and_then(|v| v.as_f64()))
                .collect();
            if let Some(last) = theirs.last() {
                info["value"] = last["value"].clone();
                info["grad"] = last["grad"].clone();
            }
            info["value_grad_ns"] = json!(if ns.is_empty() {
                None
            } else {
                Some(fastest(&ns))
            });
            info["rounds"] = json!(rounds);
            Some(info)
        }
    };

    // The peer's own numbers against ours (the same function at the same point).
    // `null` is the harness's NaN (JSON has none): CasADi's gradient is NaN outside the
    // rigid interval, where ours is guarded (sqrt at 0). NaN stays NaN in the maximum.
    let peer_nan = |p: &serde_json::Value| -> Vec<String> {
        let mut out = Vec::new();
        if p.get("value").is_some_and(|v| v.is_null()) {
            out.push("value".to_string());
        }
        if let Some(g) = p.get("grad").and_then(|g| g.as_array()) {
            out.extend(
                g.iter()
                    .enumerate()
                    .filter(|(_, x)| x.is_null())
                    .map(|(i, _)| format!("grad[{i}]")),
            );
        }
        out
    };
    let peer_nans = peer.as_ref().map(peer_nan).unwrap_or_default();
    let peer_dev = peer.as_ref().and_then(|p| {
        let v = p.get("value")?;
        let g = p.get("grad")?.as_array()?;
        let num = |x: &serde_json::Value| x.as_f64().unwrap_or(f64::NAN);
        Some(max_or_nan(std::iter::once(rel(num(v), value)).chain(
            g.iter().enumerate().map(|(i, gi)| rel(num(gi), grad[i])),
        )))
    });
    let rigid_here = foldability::min_margin(&spec, t) >= -RIGID_TOL;
    // A NaN or a deviation where the vertex is rigid is a failed check (exit 1).
    let verdict = || -> Result<()> {
        match peer_dev {
            Some(d) if rigid_here && (d.is_nan() || d > 1e-6) => Err(super::CheckFailed(format!(
                "CasADi and foldsynth disagree at t = {t}, where the vertex is rigid: relative deviation {}",
                if d.is_nan() {
                    "NaN".to_string()
                } else {
                    format!("{d:.1e}")
                }
            ))
            .into()),
            _ => Ok(()),
        }
    };

    let ops_before = rep.input.ops;
    let ops_after = rep.simplified.ops;
    let ops_gradient = rep.with_gradients.ops;
    let shrink = 100.0 * (ops_before as f64 - ops_after as f64) / ops_before.max(1) as f64;
    let ratio = jit_value_grad_ns / jit_value_ns;
    let fd_speedup = f64_central_diff_ns / jit_value_grad_ns;

    if args.json {
        let mut o = json!({
            "vertex": spec.to_string(),
            "degree": spec.degree(),
            "symbolic_sectors": sym,
            "n_vars": n,
            "t": t,
            "jit_value_ns": jit_value_ns,
            "jit_value_grad_ns": jit_value_grad_ns,
            "interpreter_value_grad_ns": interpreter_value_grad_ns,
            "f64_value_ns": f64_value_ns,
            "f64_central_diff_ns": f64_central_diff_ns,
            "dual_ns": dual_ns,
            "jit_grad_value_ratio": ratio,
            "compile_ms": compile_ms,
            "build_ms": build_ms,
            "simplify_ms": rep.simplify_ms,
            "diff_ms": rep.diff_ms,
            "jit_ms": rep.jit_ms,
            "ops_before": ops_before,
            "ops_after": ops_after,
            "ops_gradient": ops_gradient,
            "calls_before": rep.input.calls,
            "calls_after": rep.simplified.calls,
            "native_calls_value": value_only.function.n_calls(),
            "native_calls_value_grad": compiled.function.n_calls(),
            "simplify": rep.simplify,
            "max_rel_dev_value": max_dev_value,
            "max_rel_dev_grad_vs_dual": max_dev_dual,
            "max_rel_dev_grad_vs_central_diff": max_dev_fd,
        });
        if let Some(p) = &peer {
            o["peer"] = p.clone();
            if let Some(ns) = p.get("value_grad_ns").and_then(|v| v.as_f64()) {
                o["peer_value_grad_ratio"] = json!(jit_value_grad_ns / ns);
            }
            if let Some(ms) = p.get("total_compile_ms").and_then(|v| v.as_f64()) {
                o["peer_compile_ratio"] = json!(compile_ms / ms);
            }
            o["peer_max_rel_dev"] = json!(peer_dev.filter(|d| d.is_finite()));
            o["peer_nan"] = json!(peer_nans);
            o["rigid_at_t"] = json!(rigid_here);
        }
        if let Some(s) = &symbolica {
            o["symbolica"] = s.json();
            o["symbolica_value_grad_ratio"] = json!(jit_value_grad_ns / s.value_grad_ns());
            o["symbolica_compile_ratio"] = json!(compile_ms / s.compile_ms());
        }
        println!("{}", serde_json::to_string_pretty(&o)?);
        return verdict();
    }

    println!(
        "vertex {spec}  (degree {}, {})",
        spec.degree(),
        if sym {
            format!("symbolic sectors: gradient w.r.t. {n} sector angles")
        } else {
            "numeric sectors: gradient w.r.t. t".to_string()
        }
    );
    println!("value φ1+φ2+φ3 = {:.15} at t = {t}", buf[0]);
    println!(
        "operations: built {ops_before}, simplified {ops_after} ({shrink:.1}% fewer), with gradient {ops_gradient}; transcendental nodes {} -> {}; libm calls in the native code: value {}, value+gradient {} (sin+cos of one argument = one sincos)",
        rep.input.calls,
        rep.simplified.calls,
        value_only.function.n_calls(),
        compiled.function.n_calls()
    );
    println!();
    println!(
        "{:<44} {:>12} {:>12}",
        "value + gradient", "ns/eval", "vs JIT"
    );
    let row = |name: &str, ns: f64| {
        println!("{name:<44} {ns:>12.1} {:>11.2}x", ns / jit_value_grad_ns);
    };
    row("JIT (Cranelift)", jit_value_grad_ns);
    row("DAG interpreter", interpreter_value_grad_ns);
    row(
        &format!("f64 kinematics + central differences ({} evals)", 1 + 2 * n),
        f64_central_diff_ns,
    );
    row("dual numbers (forward mode)", dual_ns);
    if let Some(p) = &peer {
        if let Some(ns) = p.get("value_grad_ns").and_then(|v| v.as_f64()) {
            row("CasADi SX reverse mode, gcc -O3 (peer)", ns);
        } else if let Some(msg) = p.get("skipped").and_then(|v| v.as_str()) {
            println!("CasADi peer skipped: {msg}");
        }
    }
    if let Some(s) = &symbolica {
        row("Symbolica SymJIT (peer)", s.value_grad_ns());
    }
    println!();
    println!("{:<44} {:>12.1}", "JIT value only (ns)", jit_value_ns);
    println!(
        "{:<44} {:>12.1}",
        "f64 kinematics value only (ns)", f64_value_ns
    );
    println!("{:<44} {:>12.2}", "JIT gradient/value cost ratio", ratio);
    println!(
        "{:<44} {:>12.1}",
        "JIT speedup over central differences", fd_speedup
    );
    println!();
    println!(
        "compile latency {compile_ms:.2} ms = build {build_ms:.2} + simplify {:.2} + differentiate {:.2} + JIT {:.2} (+ overhead)",
        rep.simplify_ms, rep.diff_ms, rep.jit_ms
    );
    if let Some(p) = &peer
        && let Some(ms) = p.get("total_compile_ms").and_then(|v| v.as_f64())
    {
        println!(
            "CasADi build + codegen + gcc -O3: {ms:.1} ms (ours is {:.3} of it)",
            compile_ms / ms
        );
    }
    println!(
        "checks: value vs f64/interpreter {max_dev_value:.1e}, gradient vs dual {max_dev_dual:.1e}, vs central differences {max_dev_fd:.1e}"
    );
    match peer_dev {
        Some(d) if d.is_finite() => println!("CasADi's value and gradient vs ours: {d:.1e}"),
        Some(_) => println!(
            "CasADi's value and gradient vs ours: not comparable, CasADi gives NaN for {} at t = {t}{}",
            peer_nans.join(", "),
            if rigid_here {
                ""
            } else {
                " (outside the vertex's rigid interval: its sqrt of a negative number is NaN; ours is guarded)"
            }
        ),
        None => {}
    }
    if let Some(s) = &symbolica {
        println!();
        for l in s.lines(jit_value_grad_ns, compile_ms) {
            println!("{l}");
        }
    }
    verdict()
}

enum PeerSetup {
    Skipped(serde_json::Value),
    Harness {
        info: serde_json::Value,
        argv: Vec<String>,
        dir: PathBuf,
    },
}

/// Build the CasADi peer for the same vertex: its compile timings and the command line
/// of its timing harness (or why it was skipped).
fn casadi_setup(args: &VertexBenchArgs, spec: &VertexSpec, t: f64) -> Result<PeerSetup> {
    let script = args.peer_script.clone().unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/peers/casadi_vertex.py")
    });
    if !script.exists() {
        bail!(
            "peer script {} not found (use --peer-script)",
            script.display()
        );
    }
    let units: Vec<_> = spec
        .units
        .iter()
        .map(|u| {
            json!({
                "sectors_deg": u.sectors_deg,
                "driving": u.driving.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
            })
        })
        .collect();
    let rounds = 7;
    let desc = json!({
        "mode": spec.mode.sign(),
        "units": units,
        "symbolic_sectors": args.symbolic_sectors,
        "t": t,
        "millis": (args.millis / rounds).max(10),
    });
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let dir = std::env::temp_dir().join(format!("foldsynth-casadi-{}-{stamp}", std::process::id()));
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg("--vertex-json")
        .arg(desc.to_string())
        .arg("--emit-harness")
        .arg(&dir)
        .output();
    let out = match out {
        Ok(o) => o,
        Err(e) => {
            return Ok(PeerSetup::Skipped(
                json!({ "skipped": format!("cannot run python3: {e}") }),
            ));
        }
    };
    if !out.status.success() {
        let _ = std::fs::remove_dir_all(&dir);
        bail!(
            "peer script failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let info: serde_json::Value = serde_json::from_str(text.lines().last().unwrap_or(""))
        .with_context(|| format!("peer script printed no JSON object: {text}"))?;
    if info.get("skipped").is_some() {
        return Ok(PeerSetup::Skipped(info));
    }
    let argv: Vec<String> = info
        .get("harness")
        .and_then(|h| h.as_array())
        .map(|a| {
            a.iter()
                .filter_map(|x| x.as_str().map(str::to_string))
                .collect()
        })
        .filter(|a: &Vec<String>| !a.is_empty())
        .with_context(|| format!("peer script gave no harness: {text}"))?;
    Ok(PeerSetup::Harness { info, argv, dir })
}

/// Run the peer's timing harness once; its JSON.
fn run_harness(argv: &[String]) -> Result<serde_json::Value> {
    let out = std::process::Command::new(&argv[0])
        .args(&argv[1..])
        .output()
        .with_context(|| format!("cannot run the peer harness {}", argv[0]))?;
    if !out.status.success() {
        bail!(
            "peer harness failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.lines().last().unwrap_or(""))
        .with_context(|| format!("peer harness printed no JSON object: {text}"))
}
