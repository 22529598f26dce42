//! `foldsynth vertex SPEC [--t T | --t A:B:N] [--json]`: the PTU applied to one vertex.

use crate::kinematics::foldability::{self, RIGID_TOL};
use crate::kinematics::{DriveExpr, VertexSpec, closure_residual, flat_foldable, solve_vertex};
use anyhow::{Context, Result, bail};
use serde_json::json;

/// Arguments of `foldsynth vertex`.
#[derive(Debug, clap::Args)]
pub struct VertexArgs {
    /// The vertex in the thesis's notation (Eq. 24), sectors in degrees, e.g.
    /// "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))".
    pub spec: String,
    /// One value of the driving parameter `T`, or a range `A:B:N` (N samples from A to B).
    /// Numbers may be expressions such as `pi/2`.
    #[arg(long = "t", default_value = "0:pi:19", allow_hyphen_values = true)]
    pub t: String,
    /// Print JSON (radians) instead of a table (degrees).
    #[arg(long)]
    pub json: bool,
}

/// The sampled values of `t`.
fn parse_range(text: &str) -> Result<Vec<f64>> {
    let constant = |part: &str, what: &str| -> Result<f64> {
        let e = DriveExpr::parse(part)
            .with_context(|| format!("--t: bad {what} '{}'", crate::text::excerpt(part, 40)))?;
        let v = e.eval(&f64::NAN);
        if v.is_finite() && v.abs() > crate::limits::COORD_MAX {
            bail!(
                "--t: the {what} {} is out of range: ±{} radians at most",
                crate::text::num(v),
                crate::text::num(crate::limits::COORD_MAX)
            );
        }
        if !v.is_finite() {
            bail!(
                "--t: the {what} '{}' must be a number (it may use pi, not t)",
                crate::text::excerpt(part, 40)
            );
        }
        Ok(v)
    };
    let parts: Vec<&str> = text.split(':').collect();
    match parts.as_slice() {
        [one] => Ok(vec![constant(one, "value")?]),
        [a, b, n] => {
            let (a, b) = (constant(a, "range start")?, constant(b, "range end")?);
            let n: usize = n.trim().parse().map_err(|_| {
                anyhow::anyhow!(
                    "--t: the sample count '{}' must be a whole number from 2 to {}",
                    crate::text::excerpt(n, 40),
                    crate::limits::SAMPLES_MAX
                )
            })?;
            if n < 2 {
                bail!("--t: a range needs at least 2 samples, got {n}");
            }
            if n > crate::limits::SAMPLES_MAX {
                bail!(
                    "--t: {n} samples is over the limit of {} (each sample is a row of output)",
                    crate::limits::SAMPLES_MAX
                );
            }
            if a >= b {
                bail!(
                    "--t: the range {}:{} is empty; the start must be smaller than the end",
                    crate::text::num(a),
                    crate::text::num(b)
                );
            }
            Ok((0..n)
                .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
                .collect())
        }
        _ => bail!(
            "--t: expected a value T or a range A:B:N, got '{}'",
            crate::text::excerpt(text, 40)
        ),
    }
}

/// One evaluated sample.
struct Sample {
    t: f64,
    state: crate::kinematics::VertexState<f64>,
    rigid: bool,
    closure: f64,
}

/// The PTU at `t`: the state (φ wrapped), rigidity and closure residual.
fn sample(spec: &VertexSpec, mode: &f64, t: f64) -> Sample {
    let units = spec.units_at(t);
    let mut state = solve_vertex(&units, mode);
    // φ can carry full turns (Sec. 4.4); report the fold angle in (−π, π].
    state.phi = state.phi.map(crate::kinematics::wrap_angle);
    let margin = state.margins.iter().copied().fold(f64::INFINITY, f64::min);
    let rigid = margin >= -RIGID_TOL;
    let closure = closure_residual(&units, &state.phi);
    Sample {
        t,
        state,
        rigid,
        closure,
    }
}

/// What the vertex is, over the samples.
struct Summary {
    samples: Vec<Sample>,
    intervals: Vec<[f64; 2]>,
    flat: bool,
    u_pi: [f64; 3],
    closure_max: f64,
    d4: Option<foldability::Degree4>,
    sector_sum: f64,
    developable: bool,
}

impl Summary {
    fn new(spec: &VertexSpec, ts: &[f64]) -> Summary {
        let mode = spec.mode.sign();
        let samples: Vec<Sample> = ts.iter().map(|&t| sample(spec, &mode, t)).collect();
        let intervals = if ts.len() > 1 {
            foldability::rigid_intervals(ts, 1e-11, |t| foldability::min_margin(spec, t))
        } else {
            samples
                .iter()
                .filter(|s| s.rigid)
                .map(|s| [s.t, s.t])
                .collect()
        };
        let (flat, u_pi) = flat_foldable(&spec.units_at(0.0), 1e-9);
        let closure_max = samples
            .iter()
            .filter(|s| s.rigid)
            .map(|s| s.closure)
            .fold(0.0, f64::max);
        let d4 = foldability::degree4(spec);
        let sector_sum: f64 = spec.sectors_rad().iter().sum();
        let developable = (sector_sum - 2.0 * std::f64::consts::PI).abs() < 1e-9;
        Summary {
            samples,
            intervals,
            flat,
            u_pi,
            closure_max,
            d4,
            sector_sum,
            developable,
        }
    }
}

/// Run `foldsynth vertex`.
pub fn run(args: VertexArgs) -> Result<()> {
    let spec = VertexSpec::parse(&args.spec).context("invalid vertex")?;
    let ts = parse_range(&args.t)?;
    let s = Summary::new(&spec, &ts);
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary_json(&spec, &s))?
        );
        return Ok(());
    }
    print_text(&spec, &s);
    Ok(())
}

/// `--json` (radians).
fn summary_json(spec: &VertexSpec, s: &Summary) -> serde_json::Value {
    let samples_json: Vec<_> = s
        .samples
        .iter()
        .map(|s| {
            json!({
                "t": s.t, "U": s.state.u, "theta": s.state.theta, "beta": s.state.beta,
                "delta": s.state.delta, "phi": s.state.phi, "rigid": s.rigid,
                "margins": s.state.margins, "closure": s.closure,
            })
        })
        .collect();
    let mut out = json!({
        "vertex": spec.to_string(),
        "degree": spec.degree(),
        "mode": spec.mode.to_string(),
        "developable": s.developable,
        "samples": samples_json,
        "rigid_intervals": s.intervals,
        "flat_foldable": s.flat,
        "U_pi": s.u_pi,
        "closure_max": s.closure_max,
    });
    if let Some(d) = &s.d4 {
        out["degree4"] = json!({
            "adjacent": d.adjacent, "opposite": d.opposite,
            "eq13_sufficient": d.sufficient, "rho_star": d.rho_star,
        });
    }
    out
}

fn deg(x: f64) -> f64 {
    x.to_degrees()
}

/// The text report (degrees).
fn print_text(spec: &VertexSpec, s: &Summary) {
    println!(
        "vertex {spec}  (degree {}, mode {})",
        spec.degree(),
        spec.mode
    );
    if !s.developable {
        println!(
            "note: sector angles sum to {:.6}°, not 360° (the PTU does not need developability)",
            deg(s.sector_sum)
        );
    }
    println!();
    print_table(&s.samples);
    println!();
    println!(
        "(angles in degrees; t in radians; φ wrapped to (−180°, 180°]; φ1 between u2 and u3, φ2 between u3 and u1, φ3 between u1 and u2)"
    );
    if s.intervals.is_empty() {
        println!("rigid intervals: none in the sampled range");
    } else {
        let list: Vec<String> = s
            .intervals
            .iter()
            .map(|[a, b]| format!("[{a:.10}, {b:.10}]"))
            .collect();
        println!(
            "rigid intervals (Eq. 25, ends by bisection to 1e-10): {}",
            list.join(", ")
        );
    }
    println!(
        "flat foldable (Eq. 26): {}  U(π) = ({:.6}°, {:.6}°, {:.6}°)",
        if s.flat { "yes" } else { "no" },
        deg(s.u_pi[0]),
        deg(s.u_pi[1]),
        deg(s.u_pi[2])
    );
    if let Some(d) = &s.d4 {
        print_degree4(d);
    }
    println!(
        "worst closure residual over the rigid samples: {:.3e}",
        s.closure_max
    );
}

/// One row per sample: U, θ, β, δ, φ and rigidity.
fn print_table(samples: &[Sample]) {
    println!(
        "{:>9} | {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} | {:>9} {:>9} {:>9} | rigid",
        "t",
        "U1",
        "U2",
        "U3",
        "θ1",
        "θ2",
        "θ3",
        "β1",
        "β2",
        "β3",
        "δ1",
        "δ2",
        "δ3",
        "φ1",
        "φ2",
        "φ3"
    );
    for s in samples {
        let st = &s.state;
        println!(
            "{:>9.5} | {:>8.3} {:>8.3} {:>8.3} | {:>8.3} {:>8.3} {:>8.3} | {:>8.3} {:>8.3} {:>8.3} | {:>8.3} {:>8.3} {:>8.3} | {:>9.3} {:>9.3} {:>9.3} | {}",
            s.t,
            deg(st.u[0]),
            deg(st.u[1]),
            deg(st.u[2]),
            deg(st.theta[0]),
            deg(st.theta[1]),
            deg(st.theta[2]),
            deg(st.beta[0]),
            deg(st.beta[1]),
            deg(st.beta[2]),
            deg(st.delta[0]),
            deg(st.delta[1]),
            deg(st.delta[2]),
            deg(st.phi[0]),
            deg(st.phi[1]),
            deg(st.phi[2]),
            if s.rigid { "yes" } else { "no" }
        );
    }
}

/// A degree-4 vertex's sectors, Eq. 13 and the extreme driving angle.
fn print_degree4(d: &foldability::Degree4) {
    println!(
        "degree 4: adjacent sectors ({:.4}°, {:.4}°), opposite ({:.4}°, {:.4}°); Eq. 13 |α1−α4| ≥ |α2−α3|: {}",
        deg(d.adjacent[0]),
        deg(d.adjacent[1]),
        deg(d.opposite[0]),
        deg(d.opposite[1]),
        if d.sufficient {
            "yes, rigid for every driving angle"
        } else {
            "no"
        }
    );
    match d.rho_star {
        Some(r) => println!(
            "          extreme driving angle ρ1* (Eq. 14) = ±{r:.10} rad (±{:.6}°)",
            deg(r)
        ),
        None => println!(
            "          extreme driving angle ρ1* (Eq. 14): none, the driving angle reaches ±π"
        ),
    }
}
