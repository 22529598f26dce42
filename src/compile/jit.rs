//! Cranelift JIT: a set of outputs becomes one native, straight-line function
//! `extern "C" fn(vars: *const f64, params: *const f64, out: *mut f64)` in this process.
//!
//! The function body comes from [`super::codegen`], the builder the ahead-of-time object
//! ([`super::aot`]) uses too. Its transcendentals are [`crate::trig`]'s kernels, the
//! interpreter's very functions, so results agree bit for bit (except sums of products
//! fused on request, [`CompiledFn::with_fma_from`]): the batch symbol is bound to
//! [`crate::trig::trig_batch`], and `sin`/`cos` (the inline code's cold path) to Rust's
//! `f64` methods, which [`crate::trig`] uses there too.

use super::codegen::{self, CompileError, Math, OptLevel, Target, cg};
use crate::expr::{ExprGraph, NodeId, ShapeError, check_indices};
use crate::trig;
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, default_libcall_names};
use std::mem::ManuallyDrop;

extern "C" fn fs_sin(x: f64) -> f64 {
    x.sin()
}
extern "C" fn fs_cos(x: f64) -> f64 {
    x.cos()
}

type RawFn = unsafe extern "C" fn(*const f64, *const f64, *mut f64);

/// A natively compiled set of outputs. Owns its machine code (freed on drop).
///
/// Calls are pure: the code reads `vars` and `params`, writes `out` and touches no other
/// state, so one `CompiledFn` can be shared by many threads.
pub struct CompiledFn {
    module: ManuallyDrop<JITModule>,
    func: RawFn,
    n_vars: usize,
    n_params: usize,
    n_outputs: usize,
    n_instructions: usize,
    n_calls: usize,
    n_spilled: usize,
}

// SAFETY: after `finalize_definitions` the module is never mutated again; the only thing
// used is the code pointer, and the generated code is reentrant (it reads its arguments,
// writes its output slice and calls pure functions: the batch kernels work in the
// caller's stack buffer). Dropping from another
// thread only unmaps memory this value owns.
unsafe impl Send for CompiledFn {}
unsafe impl Sync for CompiledFn {}

impl std::fmt::Debug for CompiledFn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompiledFn")
            .field("n_vars", &self.n_vars)
            .field("n_params", &self.n_params)
            .field("n_outputs", &self.n_outputs)
            .field("n_instructions", &self.n_instructions)
            .field("n_calls", &self.n_calls)
            .field("n_spilled", &self.n_spilled)
            .finish()
    }
}

impl Drop for CompiledFn {
    fn drop(&mut self) {
        // SAFETY: `func` (the only pointer into the module's memory) dies with `self`.
        unsafe {
            let module = ManuallyDrop::take(&mut self.module);
            module.free_memory();
        }
    }
}

impl CompiledFn {
    /// Compile `outputs` of `graph` over `n_vars` variables and `n_params` parameters.
    pub fn new(
        graph: &ExprGraph,
        outputs: &[NodeId],
        n_vars: usize,
        n_params: usize,
    ) -> Result<CompiledFn, CompileError> {
        Self::with_options(
            graph,
            outputs,
            n_vars,
            n_params,
            OptLevel::Auto,
            Math::Batch,
        )
    }

    /// [`CompiledFn::new`] with a chosen optimization level and way of calling the
    /// transcendentals.
    pub fn with_options(
        graph: &ExprGraph,
        outputs: &[NodeId],
        n_vars: usize,
        n_params: usize,
        opt: OptLevel,
        math: Math,
    ) -> Result<CompiledFn, CompileError> {
        Self::with_fma_from(graph, outputs, n_vars, n_params, opt, math, usize::MAX)
    }

    /// [`CompiledFn::with_options`] where, if this CPU has fused multiply-add, the sums
    /// of products at node index `fma_from` and above may round once (see
    /// [`super::Options::fma`]); the nodes below agree with the interpreter bit for bit.
    pub fn with_fma_from(
        graph: &ExprGraph,
        outputs: &[NodeId],
        n_vars: usize,
        n_params: usize,
        opt: OptLevel,
        math: Math,
        fma_from: usize,
    ) -> Result<CompiledFn, CompileError> {
        let mark = check_indices(graph, outputs, n_vars, n_params)?;
        let n_nodes = mark.iter().filter(|m| **m).count();
        let isa = codegen::isa(Target::Jit, opt, n_nodes)?;
        let mut jb = JITBuilder::with_isa(isa, default_libcall_names());
        let [sin, cos] = codegen::MATH_SYMBOLS;
        jb.symbol(sin, fs_sin as *const u8);
        jb.symbol(cos, fs_cos as *const u8);
        jb.symbol(codegen::TRIG_BATCH_SYMBOL, trig::trig_batch as *const u8);
        let mut module = JITModule::new(jb);
        let result = codegen::define_eval(
            &mut module,
            "foldsynth_eval",
            Linkage::Local,
            graph,
            outputs,
            &mark,
            math,
            fma_from,
        );
        match result {
            Ok(built) => {
                if let Err(e) = module.finalize_definitions() {
                    // SAFETY: nothing points into the module yet.
                    unsafe { module.free_memory() };
                    return Err(cg(e));
                }
                let ptr = module.get_finalized_function(built.id);
                // SAFETY: the function was defined with exactly this signature (three
                // pointers, no return value, the platform's C calling convention).
                let func = unsafe { std::mem::transmute::<*const u8, RawFn>(ptr) };
                Ok(CompiledFn {
                    module: ManuallyDrop::new(module),
                    func,
                    n_vars,
                    n_params,
                    n_outputs: outputs.len(),
                    n_instructions: built.n_instructions,
                    n_calls: built.n_calls,
                    n_spilled: built.n_spilled,
                })
            }
            Err(e) => {
                // SAFETY: nothing points into the module.
                unsafe { module.free_memory() };
                Err(e)
            }
        }
    }

    /// Declared number of variables.
    pub fn n_vars(&self) -> usize {
        self.n_vars
    }
    /// Declared number of parameters.
    pub fn n_params(&self) -> usize {
        self.n_params
    }
    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.n_outputs
    }
    /// Number of IR instructions emitted (before Cranelift's own optimizations).
    pub fn n_instructions(&self) -> usize {
        self.n_instructions
    }
    /// Number of calls in the generated code: one per batch of transcendentals (or, inline,
    /// the cold-path calls).
    pub fn n_calls(&self) -> usize {
        self.n_calls
    }
    /// Number of values the generated code stores once and reloads (those used far from
    /// their definition, such as the forward values the gradients re-read).
    pub fn n_spilled(&self) -> usize {
        self.n_spilled
    }

    /// Evaluate into `out` after checking every length.
    #[inline]
    pub fn call(&self, vars: &[f64], params: &[f64], out: &mut [f64]) -> Result<(), ShapeError> {
        ShapeError::check_lengths(
            [self.n_vars, self.n_params, self.n_outputs],
            vars,
            params,
            out,
        )?;
        // SAFETY: lengths checked; the code reads n_vars/n_params and writes n_outputs f64s.
        unsafe { (self.func)(vars.as_ptr(), params.as_ptr(), out.as_mut_ptr()) };
        Ok(())
    }

    /// Evaluate without checks.
    ///
    /// # Safety
    /// `vars` and `params` must be readable for [`n_vars`](Self::n_vars) and
    /// [`n_params`](Self::n_params) f64s, `out` writable for
    /// [`n_outputs`](Self::n_outputs) f64s.
    #[inline]
    pub unsafe fn call_unchecked(&self, vars: *const f64, params: *const f64, out: *mut f64) {
        // SAFETY: the caller upholds the documented contract.
        unsafe { (self.func)(vars, params, out) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{Ctx, Tape};
    use crate::kinematics::Scalar;

    #[test]
    fn jit_equals_interpreter_bitwise() {
        let ctx = Ctx::new();
        let x = ctx.var(0);
        let y = ctx.var(1);
        let t = ctx.param(0);
        let e = ((x.clone() * t.clone()).sin() + y.cos()) / (t.clone() + 3.0);
        let f = (e.clone() * 0.7).acos() + y.atan2(&x) * e.sgn() - (y.clone() * y.clone()).sqrt();
        let g2 = crate::expr::Sym::select(&(x.clone() - y.clone()), &f, &e.clamp_unit());
        let ids = [ctx.node_id(&f), ctx.node_id(&g2), ctx.node_id(&e)];
        let g = ctx.to_graph();
        let jit = CompiledFn::new(&g, &ids, 2, 1).unwrap();
        let tape = Tape::new(&g, &ids, 2, 1).unwrap();
        for &(a, b, c) in &[
            (0.1, 0.2, 0.3),
            (-2.0, 5.0, 1.5),
            (0.0, 0.0, 0.0),
            (3.0, -1.0, -7.0),
        ] {
            let mut r1 = [0.0; 3];
            let mut r2 = [0.0; 3];
            jit.call(&[a, b], &[c], &mut r1).unwrap();
            tape.eval(&[a, b], &[c], &mut r2).unwrap();
            for k in 0..3 {
                assert!(
                    r1[k].to_bits() == r2[k].to_bits() || (r1[k].is_nan() && r2[k].is_nan()),
                    "{k}: {} vs {}",
                    r1[k],
                    r2[k]
                );
            }
        }
        assert!(jit.call(&[1.0], &[0.0], &mut [0.0; 3]).is_err());
        assert!(CompiledFn::new(&g, &ids, 1, 1).is_err());
    }

    #[test]
    fn batched_inline_and_interpreted_transcendentals_are_the_same_bits() {
        let ctx = Ctx::new();
        let (x, y) = (ctx.var(0), ctx.var(1));
        // Several depths of transcendentals, shared arguments, sin and cos of one argument.
        let a = x.sin() * y.cos() + x.cos();
        let b = a.atan2(&y) + (a.clone() * 0.3).acos();
        let c = (b.clone() * x.clone()).sin() - (b.clone() + y.clone()).cos() * a.sin();
        let outs = [a, b, c];
        let ids: Vec<_> = outs.iter().map(|s| ctx.node_id(s)).collect();
        let g = ctx.to_graph();
        let batch = CompiledFn::new(&g, &ids, 2, 0).unwrap();
        let inline =
            CompiledFn::with_options(&g, &ids, 2, 0, OptLevel::Auto, Math::Inline).unwrap();
        let tape = Tape::new(&g, &ids, 2, 0).unwrap();
        assert!(
            batch.n_calls() >= 3,
            "one call per depth: {}",
            batch.n_calls()
        );
        for &(p, q) in &[
            (0.3, -1.2),
            (2.0e6, 0.5),
            (-7.5, 3.0e9),
            (0.0, -0.0),
            (f64::NAN, 1.0),
        ] {
            let mut r = [[0.0; 3]; 3];
            batch.call(&[p, q], &[], &mut r[0]).unwrap();
            inline.call(&[p, q], &[], &mut r[1]).unwrap();
            tape.eval(&[p, q], &[], &mut r[2]).unwrap();
            let want = r[2];
            for (j, got) in r[..2].iter().enumerate() {
                for (k, (&a, &b)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                        "({p}, {q}) output {k}, backend {j}: {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn values_used_far_away_are_reloaded_with_the_same_bits() {
        // A long chain between the first uses of x, y, a and their last ones (as the
        // gradients re-read forward values): those are stored once and reloaded.
        let ctx = Ctx::new();
        let (x, y) = (ctx.var(0), ctx.var(1));
        let a = x.clone() * y.clone() + x.sin();
        let mut c = a.clone();
        for k in 0..200 {
            c = if k % 3 == 0 {
                c.clone() * 0.999 + y.clone()
            } else {
                (c.clone() * 0.5).cos() - c * 0.25
            };
        }
        let outs = [
            c.clone() * a.clone() + x.clone(),
            c / (y.clone() + 3.0) - a.atan2(&x),
        ];
        let ids: Vec<_> = outs.iter().map(|s| ctx.node_id(s)).collect();
        let g = ctx.to_graph();
        let tape = Tape::new(&g, &ids, 2, 0).unwrap();
        for math in [Math::Batch, Math::Inline] {
            for opt in [OptLevel::Speed, OptLevel::None] {
                let jit = CompiledFn::with_options(&g, &ids, 2, 0, opt, math).unwrap();
                assert!(
                    jit.n_spilled() >= 3,
                    "{math:?} {opt:?}: {}",
                    jit.n_spilled()
                );
                for &(p, q) in &[(0.3, -1.2), (2.5, 0.75), (-40.0, 1e-3), (0.0, -0.0)] {
                    let (mut r, mut want) = ([0.0; 2], [0.0; 2]);
                    jit.call(&[p, q], &[], &mut r).unwrap();
                    tape.eval(&[p, q], &[], &mut want).unwrap();
                    for k in 0..2 {
                        assert!(
                            r[k].to_bits() == want[k].to_bits()
                                || (r[k].is_nan() && want[k].is_nan()),
                            "{math:?} {opt:?} ({p}, {q}) output {k}: {} vs {}",
                            r[k],
                            want[k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn shared_across_threads() {
        let ctx = Ctx::new();
        let x = ctx.var(0);
        let f = x.sin() * x.cos();
        let id = ctx.node_id(&f);
        let jit = std::sync::Arc::new(CompiledFn::new(&ctx.to_graph(), &[id], 1, 0).unwrap());
        let hs: Vec<_> = (0..4)
            .map(|k| {
                let jit = jit.clone();
                std::thread::spawn(move || {
                    let mut o = [0.0];
                    jit.call(&[k as f64], &[], &mut o).unwrap();
                    o[0] == trig::sin(k as f64) * trig::cos(k as f64)
                })
            })
            .collect();
        assert!(hs.into_iter().all(|h| h.join().unwrap()));
    }
}
