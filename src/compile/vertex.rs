//! The PTU of one vertex as a model over variables and parameters, in any [`Scalar`]:
//! the kinematics' own generic code, run on [`Sym`] (a graph), `f64` (the reference) or
//! [`Dual`](super::Dual) (forward mode).
//!
//! Layout: with symbolic sectors the variables are the sector angles `α1…αn` (radians,
//! in the order of [`VertexSpec::sectors_rad`]) and the parameters `[t, M]`; otherwise
//! the only variable is `t` and the parameter is `[M]` (M = ±1, the mode).

use crate::expr::{Ctx, Names, NodeId, Sym};
use crate::kinematics::{Scalar, VertexSpec, VertexState, solve_vertex};

/// The vertex's state in any scalar type, from the model's variables and parameters.
pub fn eval_state<S: Scalar>(
    spec: &VertexSpec,
    symbolic_sectors: bool,
    vars: &[S],
    params: &[S],
) -> VertexState<S> {
    let (sectors, t): (Vec<S>, S) = if symbolic_sectors {
        (vars[..spec.degree()].to_vec(), params[0].clone())
    } else {
        (
            spec.sectors_rad().into_iter().map(S::from_f64).collect(),
            vars[0].clone(),
        )
    };
    let mode = params[params.len() - 1].clone();
    let units = spec.units_with(&sectors, &t);
    solve_vertex(&units, &mode)
}

/// `φ1 + φ2 + φ3`: one value that depends on every part of the model (the benchmark's).
pub fn phi_sum<S: Scalar>(
    spec: &VertexSpec,
    symbolic_sectors: bool,
    vars: &[S],
    params: &[S],
) -> S {
    let s = eval_state(spec, symbolic_sectors, vars, params);
    let [a, b, c] = s.phi;
    a + b + c
}

/// Number of variables and parameters of the vertex model.
pub fn dims(spec: &VertexSpec, symbolic_sectors: bool) -> (usize, usize) {
    if symbolic_sectors {
        (spec.degree(), 2)
    } else {
        (1, 1)
    }
}

/// The model's variables and parameters at `t` with the spec's own sectors and mode.
pub fn point(spec: &VertexSpec, symbolic_sectors: bool, t: f64) -> (Vec<f64>, Vec<f64>) {
    let m = spec.mode.sign();
    if symbolic_sectors {
        (spec.sectors_rad(), vec![t, m])
    } else {
        (vec![t], vec![m])
    }
}

/// The symbolic vertex: a graph holding U, θ and φ.
#[derive(Debug)]
pub struct VertexModel {
    /// The graph.
    pub ctx: Ctx,
    /// The symbolic state (U, θ, β, δ, φ, margins).
    pub state: VertexState<Sym>,
    /// `φ1 + φ2 + φ3`.
    pub phi_sum: Sym,
    /// Number of variables.
    pub n_vars: usize,
    /// Number of parameters.
    pub n_params: usize,
    /// Names of the variables and parameters (`alpha1…`, `t`, `M`).
    pub names: Names,
}

impl VertexModel {
    /// Build the graph of `spec`.
    pub fn build(spec: &VertexSpec, symbolic_sectors: bool) -> VertexModel {
        let (n_vars, n_params) = dims(spec, symbolic_sectors);
        let ctx = Ctx::new();
        let vars: Vec<Sym> = (0..n_vars).map(|i| ctx.var(i)).collect();
        let params: Vec<Sym> = (0..n_params).map(|i| ctx.param(i)).collect();
        let state = eval_state(spec, symbolic_sectors, &vars, &params);
        let [a, b, c] = state.phi.clone();
        let phi_sum = a + b + c;
        let names = if symbolic_sectors {
            Names {
                vars: (1..=n_vars).map(|i| format!("alpha{i}")).collect(),
                params: vec!["t".into(), "M".into()],
            }
        } else {
            Names {
                vars: vec!["t".into()],
                params: vec!["M".into()],
            }
        };
        VertexModel {
            ctx,
            state,
            phi_sum,
            n_vars,
            n_params,
            names,
        }
    }

    /// The named outputs U1…3, theta1…3, phi1…3.
    pub fn outputs(&self) -> Vec<(String, NodeId)> {
        let mut v = Vec::new();
        for (name, xs) in [
            ("U", &self.state.u),
            ("theta", &self.state.theta),
            ("phi", &self.state.phi),
        ] {
            for (i, x) in xs.iter().enumerate() {
                v.push((format!("{name}{}", i + 1), self.ctx.node_id(x)));
            }
        }
        v
    }

    /// The node of `φ1 + φ2 + φ3`.
    pub fn phi_sum_id(&self) -> NodeId {
        self.ctx.node_id(&self.phi_sum)
    }
}

/// A driving parameter well inside the rigid range: the sample of `(0, π)` (63 points)
/// with the largest smallest Eq. 25 margin. Benchmarks and tests evaluate there, away
/// from the fold's singular states (flat, or at the end of the rigid range).
pub fn most_rigid_t(spec: &VertexSpec) -> f64 {
    let pi = std::f64::consts::PI;
    (1..64)
        .map(|i| pi * i as f64 / 64.0)
        .map(|t| (t, crate::kinematics::foldability::min_margin(spec, t)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(1.0, |(t, _)| t)
}
