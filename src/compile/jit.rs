//! Cranelift JIT: a set of outputs becomes one native, straight-line function
//! `extern "C" fn(vars: *const f64, params: *const f64, out: *mut f64)`.
//!
//! Transcendentals are calls to imported symbols that wrap Rust's `f64` methods (the
//! interpreter's very functions, so results agree bit for bit); `sqrt` is the native
//! instruction; `sgn`, `clamp` and `select` are `fcmp` + `select`, with exactly the NaN
//! behaviour of [`Node::eval_with`].

use crate::expr::{ExprGraph, FxHashMap, Node, NodeId, ShapeError, check_indices};
use crate::kinematics::acos_clamped;
use cranelift_codegen::Context;
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{
    AbiParam, FuncRef, InstBuilder, MemFlagsData, Signature, StackSlotData, StackSlotKind,
    UserFuncName, Value, types,
};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{FuncId, Linkage, Module, default_libcall_names};
use std::mem::ManuallyDrop;

/// Why compilation failed.
#[derive(Debug, thiserror::Error)]
pub enum CompileError {
    /// The outputs use variables or parameters beyond the declared counts.
    #[error(transparent)]
    Shape(#[from] ShapeError),
    /// The host is not supported by Cranelift.
    #[error("unsupported host: {0}")]
    Host(String),
    /// Cranelift rejected a setting, the function or the linking step.
    #[error("code generation failed: {0}")]
    Codegen(String),
}

extern "C" fn fs_sin(x: f64) -> f64 {
    x.sin()
}
extern "C" fn fs_cos(x: f64) -> f64 {
    x.cos()
}
extern "C" fn fs_acos(x: f64) -> f64 {
    acos_clamped(x)
}
extern "C" fn fs_atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
unsafe extern "C" {
    /// glibc's `sincos`: one range reduction for both; bit-identical to `sin` and `cos`
    /// (glibc computes all three with the same kernels; a test checks it).
    fn sincos(x: f64, s: *mut f64, c: *mut f64);
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
extern "C" fn sincos(x: f64, s: *mut f64, c: *mut f64) {
    // SAFETY: the generated code passes two distinct, writable stack slots.
    unsafe {
        *s = x.sin();
        *c = x.cos();
    }
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
}

// SAFETY: after `finalize_definitions` the module is never mutated again; the only thing
// used is the code pointer, and the generated code is reentrant (it reads its arguments,
// writes its output slice and calls thread-safe libm functions). Dropping from another
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

fn cg<E: std::fmt::Display>(e: E) -> CompileError {
    CompileError::Codegen(e.to_string())
}

/// Cranelift's optimization level.
///
/// The graph arrives hash-consed and constant-folded, so Cranelift's mid-end finds little
/// to improve, and on large straight-line functions its cost grows faster than linearly.
/// Measured here (2 busy cores, so ±15%): on design models of 7.5k and 18k operations
/// `None` compiled in 30 and 92 ms against 62 and 320 ms for `Speed`, and ran as fast;
/// on the degree-7 vertex (~420 operations) both compile in ~1.7 ms and `Speed` runs a
/// few percent faster. Counter-example: the symmetric degree-360 vertex (35k operations,
/// its gradient re-reads forward values across the whole function) compiles in ~210 ms
/// with `Speed` and ~550 ms with `None`; choose `Speed` explicitly for such graphs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OptLevel {
    /// `Speed` up to [`AUTO_SPEED_MAX_NODES`] reachable nodes, `None` above.
    #[default]
    Auto,
    /// Cranelift's `opt_level = "speed"`.
    Speed,
    /// Cranelift's `opt_level = "none"` (instruction selection and register allocation
    /// only).
    None,
}

/// The size up to which [`OptLevel::Auto`] optimizes for speed.
pub const AUTO_SPEED_MAX_NODES: usize = 2000;

impl CompiledFn {
    /// Compile `outputs` of `graph` over `n_vars` variables and `n_params` parameters.
    pub fn new(
        graph: &ExprGraph,
        outputs: &[NodeId],
        n_vars: usize,
        n_params: usize,
    ) -> Result<CompiledFn, CompileError> {
        Self::with_opt_level(graph, outputs, n_vars, n_params, OptLevel::Auto)
    }

    /// [`CompiledFn::new`] with a chosen optimization level.
    pub fn with_opt_level(
        graph: &ExprGraph,
        outputs: &[NodeId],
        n_vars: usize,
        n_params: usize,
        opt: OptLevel,
    ) -> Result<CompiledFn, CompileError> {
        let mark = check_indices(graph, outputs, n_vars, n_params)?;
        let mut flags = settings::builder();
        let n_nodes = mark.iter().filter(|m| **m).count();
        let speed = match opt {
            OptLevel::Speed => true,
            OptLevel::None => false,
            OptLevel::Auto => n_nodes <= AUTO_SPEED_MAX_NODES,
        };
        flags
            .set("opt_level", if speed { "speed" } else { "none" })
            .map_err(cg)?;
        flags.set("is_pic", "false").map_err(cg)?;
        flags.set("use_colocated_libcalls", "false").map_err(cg)?;
        // The IR is generated, not hand-written; verifying it costs compile time.
        flags
            .set(
                "enable_verifier",
                if cfg!(debug_assertions) {
                    "true"
                } else {
                    "false"
                },
            )
            .map_err(cg)?;
        let isa = cranelift_native::builder()
            .map_err(|e| CompileError::Host(e.to_string()))?
            .finish(settings::Flags::new(flags))
            .map_err(cg)?;
        let mut jb = JITBuilder::with_isa(isa, default_libcall_names());
        jb.symbol("foldsynth_sin", fs_sin as *const u8);
        jb.symbol("foldsynth_cos", fs_cos as *const u8);
        jb.symbol("foldsynth_acos", fs_acos as *const u8);
        jb.symbol("foldsynth_atan2", fs_atan2 as *const u8);
        jb.symbol("foldsynth_sincos", sincos as *const u8);
        let mut module = JITModule::new(jb);
        let result = build(&mut module, graph, outputs, &mark);
        match result {
            Ok((func_id, n_instructions, n_calls)) => {
                if let Err(e) = module.finalize_definitions() {
                    // SAFETY: nothing points into the module yet.
                    unsafe { module.free_memory() };
                    return Err(cg(e));
                }
                let ptr = module.get_finalized_function(func_id);
                // SAFETY: the function was defined with exactly this signature (three
                // pointers, no return value, the platform's C calling convention).
                let func = unsafe { std::mem::transmute::<*const u8, RawFn>(ptr) };
                Ok(CompiledFn {
                    module: ManuallyDrop::new(module),
                    func,
                    n_vars,
                    n_params,
                    n_outputs: outputs.len(),
                    n_instructions,
                    n_calls,
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
    /// Number of calls to libm in the generated code (a `sin` and a `cos` of one
    /// argument are one `sincos` call).
    pub fn n_calls(&self) -> usize {
        self.n_calls
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

struct Imports {
    sin: Option<FuncRef>,
    cos: Option<FuncRef>,
    acos: Option<FuncRef>,
    atan2: Option<FuncRef>,
    sincos: Option<FuncRef>,
}

fn build(
    module: &mut JITModule,
    graph: &ExprGraph,
    outputs: &[NodeId],
    mark: &[bool],
) -> Result<(FuncId, usize, usize), CompileError> {
    let ptr = module.target_config().pointer_type();
    let mut sig = module.make_signature();
    for _ in 0..3 {
        sig.params.push(AbiParam::new(ptr));
    }
    let func_id = module
        .declare_function("foldsynth_eval", Linkage::Local, &sig)
        .map_err(cg)?;

    let mut sig1 = module.make_signature();
    sig1.params.push(AbiParam::new(types::F64));
    sig1.returns.push(AbiParam::new(types::F64));
    let mut sig2: Signature = sig1.clone();
    sig2.params.push(AbiParam::new(types::F64));
    let mut declare = |name: &str, sig: &Signature| {
        module
            .declare_function(name, Linkage::Import, sig)
            .map_err(cg)
    };
    let mut sig_sc = sig1.clone();
    sig_sc.returns.clear();
    sig_sc.params.push(AbiParam::new(ptr));
    sig_sc.params.push(AbiParam::new(ptr));
    let ids = [
        declare("foldsynth_sin", &sig1)?,
        declare("foldsynth_cos", &sig1)?,
        declare("foldsynth_acos", &sig1)?,
        declare("foldsynth_atan2", &sig2)?,
        declare("foldsynth_sincos", &sig_sc)?,
    ];
    // sin x and cos x of one x, both needed: one sincos call.
    let fused: Vec<bool> = graph
        .nodes()
        .iter()
        .enumerate()
        .map(|(i, n)| {
            mark[i]
                && match *n {
                    Node::Sin(a) => graph.lookup(&Node::Cos(a)).is_some_and(|c| mark[c.index()]),
                    Node::Cos(a) => graph.lookup(&Node::Sin(a)).is_some_and(|c| mark[c.index()]),
                    _ => false,
                }
        })
        .collect();

    let mut ctx: Context = module.make_context();
    ctx.func.signature = sig;
    ctx.func.name = UserFuncName::user(0, func_id.as_u32());
    let mut fctx = FunctionBuilderContext::new();
    let target = module.target_config();
    let mut n_inst = 0usize;
    let mut n_calls = 0usize;
    {
        let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
        let block = b.create_block();
        b.append_block_params_for_function_params(block);
        b.switch_to_block(block);
        let p = b.block_params(block).to_vec();
        let (vars_p, params_p, out_p) = (p[0], p[1], p[2]);
        let mem = MemFlagsData::trusted();
        let mut imports = Imports {
            sin: None,
            cos: None,
            acos: None,
            atan2: None,
            sincos: None,
        };
        let slot =
            b.create_sized_stack_slot(StackSlotData::new(StackSlotKind::ExplicitSlot, 16, 3));
        let mut slot_addr: Option<Value> = None;
        // Results of fused sincos calls, by argument node.
        let mut sincos_done: FxHashMap<NodeId, (Value, Value)> = FxHashMap::default();
        let mut import = |slot: &mut Option<FuncRef>, id: FuncId, b: &mut FunctionBuilder| {
            *slot.get_or_insert_with(|| module.declare_func_in_func(id, b.func))
        };
        let mut val: Vec<Option<Value>> = vec![None; graph.len()];
        // Operand values. Constants are materialized at each use rather than once: a
        // constant shared by thousands of nodes would otherwise be one value live across
        // the whole function (and across every libm call).
        let operand = |b: &mut FunctionBuilder, val: &[Option<Value>], id: NodeId| -> Value {
            match *graph.node(id) {
                Node::Const(c) => b.ins().f64const(c),
                _ => val[id.index()].expect("children are emitted first"),
            }
        };
        // Node order (children first): the forward pass with its libm calls comes first,
        // the arithmetic of the gradients after it. (A depth-first schedule that emits
        // each node just before its first use compiled 2× slower on design models.)
        for (i, node) in graph.nodes().iter().enumerate() {
            if !mark[i] || matches!(node, Node::Const(_)) {
                continue;
            }
            let mut o = [None; 3];
            for (k, c) in node.children().into_iter().enumerate() {
                // A fused sin/cos whose partner already called sincos needs no operand.
                if fused[i] && sincos_done.contains_key(&c) {
                    continue;
                }
                o[k] = Some(operand(&mut b, &val, c));
            }
            let v = |k: usize| o[k].expect("operand emitted");
            let x = match *node {
                Node::Const(_) => unreachable!("constants are emitted at their uses"),
                Node::Var(k) => b.ins().load(types::F64, mem, vars_p, 8 * k as i32),
                Node::Param(k) => b.ins().load(types::F64, mem, params_p, 8 * k as i32),
                Node::Add(..) => b.ins().fadd(v(0), v(1)),
                Node::Sub(..) => b.ins().fsub(v(0), v(1)),
                Node::Mul(..) => b.ins().fmul(v(0), v(1)),
                Node::Div(..) => b.ins().fdiv(v(0), v(1)),
                Node::Neg(_) => b.ins().fneg(v(0)),
                Node::Sqrt(_) => b.ins().sqrt(v(0)),
                Node::Sin(a) | Node::Cos(a) if fused[i] => {
                    let (sv, cv) = match sincos_done.get(&a) {
                        Some(&r) => r,
                        None => {
                            let f = import(&mut imports.sincos, ids[4], &mut b);
                            let addr =
                                *slot_addr.get_or_insert_with(|| b.ins().stack_addr(ptr, slot, 0));
                            let c_ptr = b.ins().iadd_imm_s(addr, 8);
                            b.ins().call(f, &[v(0), addr, c_ptr]);
                            n_calls += 1;
                            let sv = b.ins().load(types::F64, mem, addr, 0);
                            let cv = b.ins().load(types::F64, mem, addr, 8);
                            sincos_done.insert(a, (sv, cv));
                            (sv, cv)
                        }
                    };
                    if matches!(node, Node::Sin(_)) { sv } else { cv }
                }
                Node::Sin(_) | Node::Cos(_) | Node::Acos(_) => {
                    let (slot, id) = match node {
                        Node::Sin(_) => (&mut imports.sin, ids[0]),
                        Node::Cos(_) => (&mut imports.cos, ids[1]),
                        _ => (&mut imports.acos, ids[2]),
                    };
                    let f = import(slot, id, &mut b);
                    let call = b.ins().call(f, &[v(0)]);
                    n_calls += 1;
                    b.inst_results(call)[0]
                }
                Node::Atan2(..) => {
                    let f = import(&mut imports.atan2, ids[3], &mut b);
                    let call = b.ins().call(f, &[v(0), v(1)]);
                    n_calls += 1;
                    b.inst_results(call)[0]
                }
                Node::Sgn(_) => {
                    let a = v(0);
                    let zero = b.ins().f64const(0.0);
                    let one = b.ins().f64const(1.0);
                    let mone = b.ins().f64const(-1.0);
                    let gt = b.ins().fcmp(FloatCC::GreaterThan, a, zero);
                    let lt = b.ins().fcmp(FloatCC::LessThan, a, zero);
                    let neg_or_zero = b.ins().select(lt, mone, zero);
                    b.ins().select(gt, one, neg_or_zero)
                }
                Node::Clamp(_) => {
                    // As f64::clamp: NaN fails both comparisons and stays NaN.
                    let a = v(0);
                    let one = b.ins().f64const(1.0);
                    let mone = b.ins().f64const(-1.0);
                    let lt = b.ins().fcmp(FloatCC::LessThan, a, mone);
                    let lo = b.ins().select(lt, mone, a);
                    let gt = b.ins().fcmp(FloatCC::GreaterThan, lo, one);
                    b.ins().select(gt, one, lo)
                }
                Node::Select(..) => {
                    let zero = b.ins().f64const(0.0);
                    let gt = b.ins().fcmp(FloatCC::GreaterThan, v(0), zero);
                    b.ins().select(gt, v(1), v(2))
                }
            };
            n_inst += 1;
            val[i] = Some(x);
        }
        for (k, o) in outputs.iter().enumerate() {
            let x = operand(&mut b, &val, *o);
            b.ins().store(mem, x, out_p, 8 * k as i32);
        }
        b.ins().return_(&[]);
        b.seal_all_blocks();
        b.finalize(target);
    }
    module.define_function(func_id, &mut ctx).map_err(cg)?;
    module.clear_context(&mut ctx);
    Ok((func_id, n_inst, n_calls))
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
                    o[0] == (k as f64).sin() * (k as f64).cos()
                })
            })
            .collect();
        assert!(hs.into_iter().all(|h| h.join().unwrap()));
    }
}
