//! Helpers shared by the integration tests.

use foldsynth::model::compiled::{ModelProblem, outputs_f64};
use foldsynth::model::{Model, geometry};
use foldsynth::optimize::{Evaluation, Problem};

/// The model's constraints alone (objective 0): minimizing it finds points satisfying ψ.
#[allow(dead_code)] // not every test crate searches for feasible points
pub struct Feasibility<'a>(pub ModelProblem<'a>);

impl Problem for Feasibility<'_> {
    fn n_vars(&self) -> usize {
        self.0.n_vars()
    }
    fn n_constraints(&self) -> usize {
        self.0.n_constraints()
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        self.0.bounds(i)
    }
    fn eval(&self, x: &[f64], out: &mut Evaluation) {
        self.0.eval(x, out);
        out.f = 0.0;
        out.df.iter_mut().for_each(|d| *d = 0.0);
    }
}

/// Whether every vertex triangle at every time of the model is clear of degeneracy (its
/// margins and its perimeter deficit 2π − ΣU at least 1e-2: a triangle's angles have a
/// square-root kink at both), where central differences mean something.
#[allow(dead_code)] // not every test crate differentiates
pub fn smooth(model: &Model, x: &[f64], modes: &[f64]) -> bool {
    let flat = geometry::flat(&model.plan, &model.full_vars(x));
    model.times.iter().all(|t| {
        let folded = geometry::fold(&model.plan, &flat, modes, t);
        folded.states.iter().flatten().all(|st| {
            let deficit = 2.0 * std::f64::consts::PI - st.u.iter().sum::<f64>();
            st.margins.iter().all(|m| m.abs() >= 1e-2) && deficit >= 1e-2
        })
    })
}

/// The evaluation `e` at `x` (the compiled gradients) against central differences of the
/// f64 model (h = 1e-6, 1e-5 relative), objective and every constraint; `what` names the
/// graph in a failure.
#[allow(dead_code)] // not every test crate differentiates
pub fn assert_gradients(model: &Model, e: &Evaluation, x: &[f64], modes: &[f64], what: &str) {
    let h = 1e-6;
    for j in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[j] += h;
        xm[j] -= h;
        let (fp, gp) = outputs_f64(model, &xp, modes);
        let (fm, gm) = outputs_f64(model, &xm, modes);
        let fd = (fp - fm) / (2.0 * h);
        assert!(
            (fd - e.df[j]).abs() <= 1e-5 * (1.0 + fd.abs()),
            "{what} ∂f/∂x{j}: {fd} vs {}",
            e.df[j]
        );
        for k in 0..gp.len() {
            let fd = (gp[k] - gm[k]) / (2.0 * h);
            let an = e.dg[k * x.len() + j];
            assert!(
                (fd - an).abs() <= 1e-5 * (1.0 + fd.abs()),
                "{what} ∂g{k}/∂x{j}: {fd} vs {an}"
            );
        }
    }
}
