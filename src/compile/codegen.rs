//! The one function builder behind the JIT ([`super::jit`]) and the ahead-of-time object
//! ([`super::aot`]): a set of outputs becomes one straight-line function
//! `void f(const double *vars, const double *params, double *out)` in any
//! [`cranelift_module::Module`], so the in-process evaluator and the shared library are
//! the same Cranelift IR and cannot drift.
//!
//! Transcendentals are calls to the C library's `sin`, `cos`, `acos`, `atan2` and
//! `sincos` (the JIT binds those names to Rust's `f64` methods, the very functions the
//! interpreter calls; a shared library gets them from libm). `sqrt` is the native
//! instruction; `sgn`, `clamp`, `select` and the clamp in front of `acos` are `fcmp` +
//! `select`, with exactly the NaN behaviour of [`Node::eval_with`].

use crate::expr::{ExprGraph, FxHashMap, Node, NodeId, ShapeError};
use cranelift_codegen::Context;
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{
    AbiParam, FuncRef, InstBuilder, MemFlagsData, Signature, StackSlotData, StackSlotKind,
    UserFuncName, Value, types,
};
use cranelift_codegen::isa::OwnedTargetIsa;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_module::{FuncId, Linkage, Module};

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

pub(crate) fn cg<E: std::fmt::Display>(e: E) -> CompileError {
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

/// The C library's names of the functions the generated code calls, in the order of
/// [`Math`]'s fields: `double sin(double)`, `cos`, `acos`, `double atan2(double, double)`,
/// `void sincos(double, double *, double *)`.
pub const MATH_SYMBOLS: [&str; 5] = ["sin", "cos", "acos", "atan2", "sincos"];

/// Where the code runs: decides the ISA flags, not the IR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Target {
    /// In this process: this CPU's features, absolute addresses.
    Jit,
    /// A relocatable, position-independent object for any CPU of the host's architecture
    /// (baseline features: the library runs wherever the host's OS and libm run).
    Object,
}

/// The Cranelift ISA for `target` at optimization level `opt` for a function of
/// `n_nodes` reachable nodes.
pub(crate) fn isa(
    target: Target,
    opt: OptLevel,
    n_nodes: usize,
) -> Result<OwnedTargetIsa, CompileError> {
    let mut flags = settings::builder();
    let speed = match opt {
        OptLevel::Speed => true,
        OptLevel::None => false,
        OptLevel::Auto => n_nodes <= AUTO_SPEED_MAX_NODES,
    };
    flags
        .set("opt_level", if speed { "speed" } else { "none" })
        .map_err(cg)?;
    let pic = target == Target::Object;
    flags
        .set("is_pic", if pic { "true" } else { "false" })
        .map_err(cg)?;
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
    cranelift_native::builder_with_options(target == Target::Jit)
        .map_err(|e| CompileError::Host(e.to_string()))?
        .finish(settings::Flags::new(flags))
        .map_err(cg)
}

/// What [`define_eval`] built.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Built {
    /// The function.
    pub id: FuncId,
    /// IR instructions emitted for the nodes (before Cranelift's optimizations).
    pub n_instructions: usize,
    /// Calls to the math functions.
    pub n_calls: usize,
}

/// Lazily imported math functions of one function body.
struct Math {
    sin: Option<FuncRef>,
    cos: Option<FuncRef>,
    acos: Option<FuncRef>,
    atan2: Option<FuncRef>,
    sincos: Option<FuncRef>,
}

/// `x` clamped to `[-1, 1]` as `f64::clamp`: NaN fails both comparisons and stays NaN.
fn clamp_unit(b: &mut FunctionBuilder, x: Value) -> Value {
    let one = b.ins().f64const(1.0);
    let mone = b.ins().f64const(-1.0);
    let lt = b.ins().fcmp(FloatCC::LessThan, x, mone);
    let lo = b.ins().select(lt, mone, x);
    let gt = b.ins().fcmp(FloatCC::GreaterThan, lo, one);
    b.ins().select(gt, one, lo)
}

/// Define `name` in `module`: the function computing `outputs` of `graph` (`mark`: the
/// nodes they reach, from [`crate::expr::check_indices`]). With `fuse_sincos`, `sin x` and
/// `cos x` of one `x` are one `sincos` call (glibc and musl have it; macOS's libm does
/// not).
pub(crate) fn define_eval<M: Module>(
    module: &mut M,
    name: &str,
    linkage: Linkage,
    graph: &ExprGraph,
    outputs: &[NodeId],
    mark: &[bool],
    fuse_sincos: bool,
) -> Result<Built, CompileError> {
    let ptr = module.target_config().pointer_type();
    let mut sig = module.make_signature();
    for _ in 0..3 {
        sig.params.push(AbiParam::new(ptr));
    }
    let func_id = module.declare_function(name, linkage, &sig).map_err(cg)?;

    let mut sig1 = module.make_signature();
    sig1.params.push(AbiParam::new(types::F64));
    sig1.returns.push(AbiParam::new(types::F64));
    let mut sig2: Signature = sig1.clone();
    sig2.params.push(AbiParam::new(types::F64));
    let mut sig_sc = sig1.clone();
    sig_sc.returns.clear();
    sig_sc.params.push(AbiParam::new(ptr));
    sig_sc.params.push(AbiParam::new(ptr));
    let sigs = [&sig1, &sig1, &sig1, &sig2, &sig_sc];
    let mut ids = Vec::with_capacity(MATH_SYMBOLS.len());
    for (name, sig) in MATH_SYMBOLS.iter().zip(sigs) {
        ids.push(
            module
                .declare_function(name, Linkage::Import, sig)
                .map_err(cg)?,
        );
    }
    // sin x and cos x of one x, both needed: one sincos call.
    let fused: Vec<bool> = graph
        .nodes()
        .iter()
        .enumerate()
        .map(|(i, n)| {
            fuse_sincos
                && mark[i]
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
        let mut math = Math {
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
                            let f = import(&mut math.sincos, ids[4], &mut b);
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
                    let (slot, id, arg) = match node {
                        Node::Sin(_) => (&mut math.sin, ids[0], v(0)),
                        Node::Cos(_) => (&mut math.cos, ids[1], v(0)),
                        // acos of the clamped argument: `acos_clamped`.
                        _ => (&mut math.acos, ids[2], clamp_unit(&mut b, v(0))),
                    };
                    let f = import(slot, id, &mut b);
                    let call = b.ins().call(f, &[arg]);
                    n_calls += 1;
                    b.inst_results(call)[0]
                }
                Node::Atan2(..) => {
                    let f = import(&mut math.atan2, ids[3], &mut b);
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
                Node::Clamp(_) => clamp_unit(&mut b, v(0)),
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
    Ok(Built {
        id: func_id,
        n_instructions: n_inst,
        n_calls,
    })
}
