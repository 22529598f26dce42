//! The compiled PTU against the f64 kinematics: random vertices of degree 4–12, both
//! modes (M is a parameter, so one compiled model serves both), over a thousand random
//! points.
//!
//! - JIT = interpreter = f64 kinematics (≤ 1e-12 relative) for the graph as built;
//! - simplified = as built (≤ 1e-12 relative; angles compared modulo full turns, since
//!   `atan2` may land on either side of its cut when rounding differs);
//! - reverse-mode gradients = dual numbers (≤ 1e-10 relative) and = central differences
//!   where the function is smooth.
//!
//! "Relative" is `|a − b| ≤ tol · max(|a|, |b|, 1)`: the outputs are angles of order 1.

use foldsynth::compile::vertex::{VertexModel, eval_state};
use foldsynth::compile::{CompiledFn, Dual, Options, compile, simplify};
use foldsynth::expr::{NodeId, Tape};
use foldsynth::kinematics::{DriveExpr, Mode, UnitSpec, VertexSpec};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

fn close_mod_turn(a: f64, b: f64, tol: f64) -> bool {
    let d = a - b;
    let d = d - 2.0 * PI * (d / (2.0 * PI)).round();
    d.abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

/// A random vertex of degree `n`: three units of random sizes, sectors of 15°–120°,
/// driving angles ±t, random mode.
fn random_spec(rng: &mut ChaCha8Rng, n: usize) -> VertexSpec {
    let a = rng.random_range(1..=n - 2);
    let b = rng.random_range(1..=n - 1 - a);
    let sizes = [a, b, n - a - b];
    let units = sizes.map(|m| UnitSpec {
        sectors_deg: (0..m).map(|_| rng.random_range(15.0..120.0)).collect(),
        driving: (0..m.saturating_sub(1))
            .map(|_| DriveExpr::parse(if rng.random_bool(0.5) { "t" } else { "-t" }).unwrap())
            .collect(),
    });
    let mode = if rng.random_bool(0.5) {
        Mode::Up
    } else {
        Mode::Down
    };
    VertexSpec { mode, units }
}

/// A random point of the symbolic-sector model: sectors jittered by up to ±5°,
/// t in (0.2, π − 0.2), M = ±1.
fn random_point(rng: &mut ChaCha8Rng, spec: &VertexSpec) -> (Vec<f64>, Vec<f64>) {
    let vars = spec
        .sectors_rad()
        .into_iter()
        .map(|a| a + rng.random_range(-5.0f64..5.0).to_radians())
        .collect();
    let m = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    (vars, vec![rng.random_range(0.2..PI - 0.2), m])
}

fn state_vec(s: &foldsynth::kinematics::VertexState<f64>) -> Vec<f64> {
    s.u.iter().chain(&s.theta).chain(&s.phi).copied().collect()
}

#[test]
fn jit_interpreter_f64_and_simplified_agree_on_random_vertices() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut points = 0;
    for n in 4..=12 {
        for _ in 0..2 {
            let spec = random_spec(&mut rng, n);
            let model = VertexModel::build(&spec, true);
            let named = model.outputs();
            let ids: Vec<NodeId> = named.iter().map(|(_, id)| *id).collect();
            let g = model.ctx.to_graph();
            let (nv, np) = (model.n_vars, model.n_params);
            let tape = Tape::new(&g, &ids, nv, np).unwrap();
            let jit = CompiledFn::new(&g, &ids, nv, np).unwrap();
            let simp = compile(&g, &ids, nv, np, &Options::default()).unwrap();
            let layout = &simp.layout;
            for _ in 0..60 {
                let (x, p) = random_point(&mut rng, &spec);
                let want = state_vec(&eval_state(&spec, true, &x, &p));
                let mut ti = vec![0.0; ids.len()];
                let mut tj = vec![0.0; ids.len()];
                tape.eval(&x, &p, &mut ti).unwrap();
                jit.call(&x, &p, &mut tj).unwrap();
                let mut ts = vec![0.0; layout.len()];
                simp.function.call(&x, &p, &mut ts).unwrap();
                for k in 0..ids.len() {
                    let name = &named[k].0;
                    assert!(
                        close(ti[k], want[k], 1e-12),
                        "{spec} {name}: interpreter {} vs f64 {} at {x:?} {p:?}",
                        ti[k],
                        want[k]
                    );
                    assert!(
                        close(tj[k], ti[k], 1e-12),
                        "{spec} {name}: JIT {} vs interpreter {}",
                        tj[k],
                        ti[k]
                    );
                    let s = ts[layout.value(k)];
                    assert!(
                        close_mod_turn(s, ti[k], 1e-12),
                        "{spec} {name}: simplified {s} vs as built {} at {x:?} {p:?}",
                        ti[k]
                    );
                }
                points += 1;
            }
        }
    }
    assert!(points >= 1000, "{points} points");
}

#[test]
fn reverse_mode_equals_dual_numbers_on_random_vertices() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut points = 0;
    for n in 4..=12 {
        for symbolic in [true, false] {
            let spec = random_spec(&mut rng, n);
            let model = VertexModel::build(&spec, symbolic);
            let ids: Vec<NodeId> = model.outputs().iter().map(|(_, id)| *id).collect();
            let g = model.ctx.to_graph();
            let (nv, np) = (model.n_vars, model.n_params);
            let c = compile(&g, &ids, nv, np, &Options::default()).unwrap();
            for _ in 0..60 {
                let (x, p) = if symbolic {
                    random_point(&mut rng, &spec)
                } else {
                    let m = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                    (vec![rng.random_range(0.2..PI - 0.2)], vec![m])
                };
                let mut out = vec![0.0; c.layout.len()];
                c.function.call(&x, &p, &mut out).unwrap();
                let dx: Vec<Dual> = (0..nv).map(|i| Dual::var(x[i], i, nv)).collect();
                let dp: Vec<Dual> = p.iter().map(|&v| Dual::constant(v)).collect();
                let st = eval_state(&spec, symbolic, &dx, &dp);
                let duals: Vec<&Dual> = st.u.iter().chain(&st.theta).chain(&st.phi).collect();
                for (k, d) in duals.iter().enumerate() {
                    let want = d.grad(nv);
                    let got = &out[c.layout.gradient(k)];
                    for i in 0..nv {
                        assert!(!got[i].is_nan(), "{spec}: NaN gradient of output {k}");
                        assert!(
                            close(got[i], want[i], 1e-10),
                            "{spec}: d out{k}/d x{i}: reverse {} vs dual {} at {x:?} {p:?}",
                            got[i],
                            want[i]
                        );
                    }
                }
                points += 1;
            }
        }
    }
    assert!(points >= 1000, "{points} points");
}

#[test]
fn gradients_match_central_differences_where_smooth() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let (mut tested, mut total) = (0, 0);
    for n in 4..=9 {
        let spec = random_spec(&mut rng, n);
        let model = VertexModel::build(&spec, true);
        let g = model.ctx.to_graph();
        let out = [model.phi_sum_id()];
        let c = compile(&g, &out, model.n_vars, model.n_params, &Options::default()).unwrap();
        let f = |x: &[f64], p: &[f64]| -> f64 {
            let s = eval_state(&spec, true, x, p);
            s.phi.iter().sum()
        };
        for _ in 0..20 {
            let (x, p) = random_point(&mut rng, &spec);
            total += 1;
            let mut buf = vec![0.0; c.layout.len()];
            c.function.call(&x, &p, &mut buf).unwrap();
            let grad = &buf[c.layout.gradient(0)];
            let fd = |h: f64, i: usize| {
                let (mut a, mut b) = (x.clone(), x.clone());
                a[i] += h;
                b[i] -= h;
                (f(&a, &p) - f(&b, &p)) / (2.0 * h)
            };
            // Smooth here: two step sizes agree (no kink, no branch cut within reach).
            let smooth = (0..x.len()).all(|i| close(fd(1e-5, i), fd(1e-6, i), 1e-6));
            if !smooth {
                continue;
            }
            tested += 1;
            for (i, g) in grad.iter().enumerate() {
                let d = fd(1e-6, i);
                assert!(
                    close(*g, d, 1e-6),
                    "{spec}: d phi_sum / d alpha{}: {g} vs central {d}",
                    i + 1
                );
            }
        }
    }
    assert!(
        tested * 2 >= total,
        "only {tested} of {total} points were smooth"
    );
}

#[test]
fn simplification_shrinks_the_degree_8_vertex() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let mut specs = vec![
        VertexSpec::parse("v(up, ((40,50,45,35,40,30),(t,-t,t,-t,t)), (25), (95))").unwrap(),
        VertexSpec::parse("v(down, ((45,45,45),(t,-t)), ((45,45,45),(t,-t)), ((45,45),(t)))")
            .unwrap(),
    ];
    specs.push(random_spec(&mut rng, 8));
    for spec in specs {
        assert_eq!(spec.degree(), 8);
        let model = VertexModel::build(&spec, true);
        let ids: Vec<NodeId> = model.outputs().iter().map(|(_, id)| *id).collect();
        let g = model.ctx.to_graph();
        let (s, outs, rep) = simplify::simplify(&g, &ids, &simplify::Limits::default());
        let before = g.counts(&ids).ops;
        let after = s.counts(&outs).ops;
        assert_eq!((rep.ops_before, rep.ops_after), (before, after));
        assert!(after < before, "{spec}: {before} -> {after} operations");
    }
}

#[test]
fn one_model_serves_both_modes() {
    let spec = VertexSpec::parse("v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))").unwrap();
    let model = VertexModel::build(&spec, false);
    let ids: Vec<NodeId> = model.outputs().iter().map(|(_, id)| *id).collect();
    let c = compile(&model.ctx.to_graph(), &ids, 1, 1, &Options::default()).unwrap();
    for m in [1.0, -1.0] {
        for t in [0.4, 1.3, 2.7] {
            let mut out = vec![0.0; c.layout.len()];
            c.function.call(&[t], &[m], &mut out).unwrap();
            let want = state_vec(&eval_state(&spec, false, &[t], &[m]));
            for k in 0..9 {
                assert!(close_mod_turn(out[k], want[k], 1e-12), "M={m} t={t} out{k}");
            }
        }
    }
}
