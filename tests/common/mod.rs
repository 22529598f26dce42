//! Helpers shared by the integration tests.

use foldsynth::model::compiled::ModelProblem;
use foldsynth::optimize::{Evaluation, Problem};

/// The model's constraints alone (objective 0): minimizing it finds points satisfying ψ.
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
