//! The one function builder behind the JIT ([`super::jit`]) and the ahead-of-time object
//! ([`super::aot`]): a set of outputs becomes one straight-line function
//! `void f(const double *vars, const double *params, double *out)` in any
//! [`cranelift_module::Module`], so the in-process evaluator and the shared library are
//! the same Cranelift IR and cannot drift.
//!
//! `sin`, `cos`, `atan2` and `acos` are [`crate::trig`]'s kernels, the very functions the
//! interpreter and the `f64` kinematics use, so every backend computes the same bits:
//! - [`Math::Batch`] (the JIT): the transcendentals are grouped by how many transcendentals
//!   lie below them; each group is one call of [`crate::trig::trig_batch`] (four lanes of
//!   AVX2 at a time) through a stack buffer, and uses reload the results from there. A
//!   call costs more than the call (every value live across it is in a caller-saved
//!   register, spilled and reloaded), so one call per group instead of one per function
//!   pays twice;
//! - [`Math::Inline`] (the self-contained library): the kernels as straight-line IR in the
//!   function, with the C library's `sin`/`cos` on a cold path for `|x| > 10⁶`.
//!
//! `sqrt` is the native instruction; `sgn`, `clamp`, `select` and the clamp in front of
//! `acos` are `fcmp` + `select`, with exactly the NaN behaviour of [`Node::eval_with`].

use crate::expr::{ExprGraph, FxHashMap, Node, NodeId, ShapeError};
use crate::trig::{self, Ops};
use cranelift_codegen::Context;
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{
    AbiParam, BlockArg, FuncRef, InstBuilder, MemFlagsData, Signature, StackSlot, StackSlotData,
    StackSlotKind, UserFuncName, Value, types,
};
use cranelift_codegen::isa::{OwnedTargetIsa, TargetFrontendConfig};
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

/// How the generated code computes `sin`, `cos`, `atan2` and `acos` (the same bits either
/// way: [`crate::trig`]'s kernels).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Math {
    /// Grouped calls of [`crate::trig::trig_batch`] (in-process code only).
    #[default]
    Batch,
    /// The kernels inlined as IR (what a library without foldsynth needs); the C
    /// library's `sin` and `cos` on a cold path for arguments beyond
    /// [`crate::trig::SIN_COS_MAX_ARG`].
    Inline,
}

/// The size up to which [`OptLevel::Auto`] optimizes for speed. The gripper's design
/// models (about 1,500 nodes with gradients) compile in 5.5 ms of Cranelift with `None`
/// against 7.3 with `Speed` and run as fast (582–631 against 610–614 ns, `bench model`);
/// its search at N_max = 3 spent 2.65 CPU s compiling instead of 3.25 (6 Dec 2026).
pub const AUTO_SPEED_MAX_NODES: usize = 1000;

/// The C library's functions that [`Math::Inline`] code may call (on its cold path).
pub const MATH_SYMBOLS: [&str; 2] = ["sin", "cos"];

/// The symbol the JIT binds to [`crate::trig::trig_batch`].
pub(crate) const TRIG_BATCH_SYMBOL: &str = "foldsynth_trig_batch";

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
    /// IR instructions emitted for the nodes (kernels and batches included).
    pub n_instructions: usize,
    /// Calls emitted (batches, or the cold-path calls of inline code).
    pub n_calls: usize,
    /// Values stored in the spill slot (used far from their definition).
    pub n_spilled: usize,
}

/// The Cranelift backend of [`trig`]'s kernels.
struct Ir<'a, 'f> {
    b: &'a mut FunctionBuilder<'f>,
}

impl Ops for Ir<'_, '_> {
    type V = Value;
    fn c(&mut self, x: f64) -> Value {
        self.b.ins().f64const(x)
    }
    fn add(&mut self, a: Value, b: Value) -> Value {
        self.b.ins().fadd(a, b)
    }
    fn sub(&mut self, a: Value, b: Value) -> Value {
        self.b.ins().fsub(a, b)
    }
    fn mul(&mut self, a: Value, b: Value) -> Value {
        self.b.ins().fmul(a, b)
    }
    fn div(&mut self, a: Value, b: Value) -> Value {
        self.b.ins().fdiv(a, b)
    }
    fn sqrt(&mut self, a: Value) -> Value {
        self.b.ins().sqrt(a)
    }
    fn abs(&mut self, a: Value) -> Value {
        self.b.ins().fabs(a)
    }
    fn copysign(&mut self, a: Value, b: Value) -> Value {
        self.b.ins().fcopysign(a, b)
    }
    fn lt_select(&mut self, a: Value, b: Value, x: Value, y: Value) -> Value {
        let c = self.b.ins().fcmp(FloatCC::LessThan, a, b);
        self.b.ins().select(c, x, y)
    }
    fn eq_select(&mut self, a: Value, b: Value, x: Value, y: Value) -> Value {
        let c = self.b.ins().fcmp(FloatCC::Equal, a, b);
        self.b.ins().select(c, x, y)
    }
    fn sign_select(&mut self, m: Value, x: Value, y: Value) -> Value {
        let flags = MemFlagsData::new();
        let bits = self.b.ins().bitcast(types::I64, flags, m);
        let mask = self.b.ins().sshr_imm_u(bits, 63);
        let mask = self.b.ins().bitcast(types::F64, flags, mask);
        self.b.ins().bitselect(mask, x, y)
    }
    fn bit_to_sign(&mut self, v: Value, bit: u32) -> Value {
        let flags = MemFlagsData::new();
        let bits = self.b.ins().bitcast(types::I64, flags, v);
        let bits = self.b.ins().ishl_imm_u(bits, i64::from(63 - bit));
        self.b.ins().bitcast(types::F64, flags, bits)
    }
    fn flip_sign(&mut self, a: Value, m: Value) -> Value {
        let sign = self.b.ins().f64const(-0.0);
        let s = self.b.ins().band(m, sign);
        self.b.ins().bxor(a, s)
    }
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

fn is_trig(n: &Node) -> bool {
    matches!(
        n,
        Node::Sin(_) | Node::Cos(_) | Node::Atan2(..) | Node::Acos(_)
    )
}

/// One group of transcendentals handed to [`trig::trig_batch`] in one call.
#[derive(Default)]
struct Batch {
    /// Arguments of sin/cos (each once), atan2 nodes, acos nodes.
    sc: Vec<NodeId>,
    at: Vec<usize>,
    ac: Vec<usize>,
    /// Where the group's buffer starts in the function's batch slot (in f64s).
    base: u32,
}

impl Batch {
    fn len(&self) -> usize {
        3 * self.sc.len() + 3 * self.at.len() + 2 * self.ac.len()
    }

    /// The arguments the call reads, each with its f64 offset in the group's buffer:
    /// the sin/cos arguments, atan2's `y`s, atan2's `x`s, acos's arguments.
    fn stores(&self, nodes: &[Node]) -> Vec<(NodeId, usize)> {
        let (nsc, nat) = (self.sc.len(), self.at.len());
        let mut stores: Vec<(NodeId, usize)> = Vec::new();
        for (k, &a) in self.sc.iter().enumerate() {
            stores.push((a, k));
        }
        for (k, &i) in self.at.iter().enumerate() {
            let [y, x] = [0, 1].map(|j| nodes[i].children().as_slice()[j]);
            stores.push((y, nsc + k));
            stores.push((x, nsc + nat + k));
        }
        for (k, &i) in self.ac.iter().enumerate() {
            stores.push((nodes[i].children().as_slice()[0], nsc + 2 * nat + k));
        }
        stores
    }
}

/// Where a node's value comes from.
#[derive(Clone, Copy)]
enum Source {
    /// Not emitted yet.
    None,
    /// An SSA value.
    Value(Value),
    /// The batch slot at this f64 offset (reloaded at each use).
    Slot(u32),
    /// An SSA value computed at this position of the emission order and stored at this
    /// f64 offset of the spill slot: uses more than [`SPILL_WINDOW`] positions later
    /// reload it from there.
    Spilled(Value, usize, u32),
}

/// A value used more than this many positions of the emission order after its definition
/// is stored once and reloaded there (see [`define_eval`]). Robotic-arm model (11k
/// operations with gradients), 2 Dec 2026: Cranelift 55 → 32 ms at 16 or 64, 44 ms at 1024;
/// the code ran as fast at 64 and 256 as without, ~15 % slower at 16.
const SPILL_WINDOW: usize = 64;

/// The transcendentals of the reachable nodes grouped for [`Math::Batch`] by depth (how
/// many transcendentals lie on the deepest path below them): a group's arguments only need
/// smaller depths. Returns every node's depth and the groups, laid out one after the other
/// in the batch slot.
fn group_by_depth(nodes: &[Node], mark: &[bool]) -> (Vec<u32>, Vec<Batch>) {
    let mut depth = vec![0u32; nodes.len()];
    let mut batches: Vec<Batch> = Vec::new();
    for (i, n) in nodes.iter().enumerate() {
        if mark[i] {
            depth[i] = n
                .children()
                .into_iter()
                .map(|c| depth[c.index()] + u32::from(is_trig(&nodes[c.index()])))
                .max()
                .unwrap_or(0);
        }
    }
    let mut seen: FxHashMap<(u32, NodeId), ()> = FxHashMap::default();
    for (i, n) in nodes.iter().enumerate() {
        if !mark[i] || !is_trig(n) {
            continue;
        }
        let d = depth[i] as usize;
        if batches.len() <= d {
            batches.resize_with(d + 1, Batch::default);
        }
        match *n {
            Node::Sin(a) | Node::Cos(a) => {
                if seen.insert((d as u32, a), ()).is_none() {
                    batches[d].sc.push(a);
                }
            }
            Node::Atan2(..) => batches[d].at.push(i),
            _ => batches[d].ac.push(i),
        }
    }
    let mut base = 0u32;
    for bt in &mut batches {
        bt.base = base;
        base += bt.len() as u32;
    }
    (depth, batches)
}

/// The emission order: node order (children first), so the forward pass precedes the
/// arithmetic of the gradients (a depth-first schedule that emits each node just before
/// its first use compiled 2× slower on design models). With batches (`n_batches` groups
/// by `depth`): by depth, each depth's plain nodes, then its batch.
fn emission_order(
    nodes: &[Node],
    mark: &[bool],
    mode: Math,
    depth: &[u32],
    n_batches: usize,
) -> Vec<Vec<usize>> {
    if mode == Math::Batch {
        // A plain node is at most one deeper than the deepest batch.
        let mut by_depth = vec![Vec::new(); n_batches + 1];
        for (i, n) in nodes.iter().enumerate() {
            if mark[i] && !is_trig(n) && !matches!(n, Node::Const(_)) {
                by_depth[depth[i] as usize].push(i);
            }
        }
        by_depth
    } else {
        vec![
            (0..nodes.len())
                .filter(|&i| mark[i] && !matches!(nodes[i], Node::Const(_)))
                .collect(),
        ]
    }
}

/// Positions in the emission order (each emitted node, then each depth's batch) and the
/// spill slot's layout.
///
/// Values used far from where they are computed (the forward values the gradients
/// re-read) are stored once in a spill slot, and uses beyond [`SPILL_WINDOW`] positions
/// reload them: their SSA values stay short-lived, so the register allocator has no long
/// live ranges to split (the arm's models compile in 40 % less time, and run as fast).
/// Stores and loads move the bits unchanged.
struct Schedule {
    /// Each emitted node's position (`usize::MAX`: not emitted on its own).
    pos: Vec<usize>,
    /// Each depth's batch position.
    batch_pos: Vec<usize>,
    /// The number of positions (the outputs are read after all of them).
    n_pos: usize,
    /// Each spilled node's f64 offset in the spill slot (`u32::MAX`: not spilled).
    spill_off: Vec<u32>,
    /// The spill slot's length in f64s.
    spill_len: u32,
}

impl Schedule {
    fn new(
        nodes: &[Node],
        order: &[Vec<usize>],
        fused: &[bool],
        batches: &[Batch],
        outputs: &[NodeId],
    ) -> Schedule {
        let mut pos = vec![usize::MAX; nodes.len()];
        let mut batch_pos = vec![usize::MAX; order.len()];
        let mut last_use = vec![0usize; nodes.len()];
        let mut n_pos = 0usize;
        for (d, phase) in order.iter().enumerate() {
            for &i in phase {
                if fused[i] {
                    continue;
                }
                pos[i] = n_pos;
                let mut read = |r: NodeId| last_use[r.index()] = last_use[r.index()].max(n_pos);
                for c in nodes[i].children() {
                    if fused[c.index()] {
                        // A fused product's factors are read by its user.
                        nodes[c.index()].children().into_iter().for_each(&mut read);
                    } else {
                        read(c);
                    }
                }
                n_pos += 1;
            }
            if let Some(bt) = batches.get(d) {
                batch_pos[d] = n_pos;
                let args = bt.sc.iter().copied().chain(
                    bt.at
                        .iter()
                        .chain(&bt.ac)
                        .flat_map(|&i| nodes[i].children()),
                );
                for a in args {
                    last_use[a.index()] = last_use[a.index()].max(n_pos);
                }
                n_pos += 1;
            }
        }
        for o in outputs {
            last_use[o.index()] = n_pos;
        }
        let mut spill_off = vec![u32::MAX; nodes.len()];
        let mut spill_len = 0u32;
        for i in 0..nodes.len() {
            if pos[i] != usize::MAX && last_use[i].saturating_sub(pos[i]) > SPILL_WINDOW {
                spill_off[i] = spill_len;
                spill_len += 1;
            }
        }
        Schedule {
            pos,
            batch_pos,
            n_pos,
            spill_off,
            spill_len,
        }
    }
}

/// An explicit stack slot of `len` f64s (none when empty).
fn f64_slot(b: &mut FunctionBuilder, len: u32) -> Option<StackSlot> {
    (len > 0).then(|| {
        b.create_sized_stack_slot(StackSlotData::new(StackSlotKind::ExplicitSlot, 8 * len, 3))
    })
}

/// Define `name` in `module`: the function computing `outputs` of `graph` (`mark`: the
/// nodes they reach, from [`crate::expr::check_indices`]) with transcendentals by `mode`.
///
/// Where the ISA has fused multiply-add, a sum or difference at node index `fuse_from` or
/// above whose operand is a product used nowhere else becomes one `fma` (one rounding
/// instead of two, and one instruction: the gradients [`super::compile`] appends are
/// mostly sums of products). Nodes below `fuse_from` round as the interpreter does, bit
/// for bit; `usize::MAX` fuses nothing.
#[allow(clippy::too_many_arguments)]
pub(crate) fn define_eval<M: Module>(
    module: &mut M,
    name: &str,
    linkage: Linkage,
    graph: &ExprGraph,
    outputs: &[NodeId],
    mark: &[bool],
    mode: Math,
    fuse_from: usize,
) -> Result<Built, CompileError> {
    let ptr = module.target_config().pointer_type();
    let mut sig = module.make_signature();
    for _ in 0..3 {
        sig.params.push(AbiParam::new(ptr));
    }
    let func_id = module.declare_function(name, linkage, &sig).map_err(cg)?;
    let nodes = graph.nodes();
    let (depth, batches) = if mode == Math::Batch {
        group_by_depth(nodes, mark)
    } else {
        (vec![0u32; nodes.len()], Vec::new())
    };
    let slot_len: u32 = batches.iter().map(|b| b.len() as u32).sum();
    let fused = fusable_products(
        graph,
        outputs,
        mark,
        fuse_from,
        module.isa().has_native_fma(),
    );
    let order = emission_order(nodes, mark, mode, &depth, batches.len());
    let plan = Schedule::new(nodes, &order, &fused, &batches, outputs);

    let mut ctx: Context = module.make_context();
    ctx.func.signature = sig;
    ctx.func.name = UserFuncName::user(0, func_id.as_u32());
    let mut fctx = FunctionBuilderContext::new();
    let target = module.target_config();
    let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    let p = b.block_params(block).to_vec();
    let slot = f64_slot(&mut b, slot_len);
    let spill = f64_slot(&mut b, plan.spill_len);
    let mut e = Emitter {
        module: &mut *module,
        b,
        graph,
        fused: &fused,
        spill_off: &plan.spill_off,
        ptr,
        mem: MemFlagsData::trusted(),
        args: [p[0], p[1], p[2]],
        slot,
        spill,
        src: vec![Source::None; nodes.len()],
        sincos_done: FxHashMap::default(),
        batch_fn: None,
        libm_fns: None,
        n_inst: 0,
        n_calls: 0,
    };
    for (d, phase) in order.iter().enumerate() {
        for &i in phase {
            // A fused product is emitted inside its one user's fma.
            if !fused[i] {
                e.node(i, plan.pos[i]);
            }
        }
        if let Some(bt) = batches.get(d)
            && bt.len() > 0
        {
            e.batch(bt, d, plan.batch_pos[d], &depth, mark);
        }
    }
    let (n_inst, n_calls) = e.finish(outputs, plan.n_pos, target);
    module.define_function(func_id, &mut ctx).map_err(cg)?;
    module.clear_context(&mut ctx);
    Ok(Built {
        id: func_id,
        n_instructions: n_inst,
        n_calls,
        n_spilled: plan.spill_len as usize,
    })
}

/// The function under construction: the builder, where each node's value is, and the
/// callees imported so far.
struct Emitter<'a, 'f, M: Module> {
    module: &'a mut M,
    b: FunctionBuilder<'f>,
    graph: &'a ExprGraph,
    /// Products emitted inside their user's `fma` (from [`fusable_products`]).
    fused: &'a [bool],
    /// [`Schedule::spill_off`].
    spill_off: &'a [u32],
    ptr: types::Type,
    mem: MemFlagsData,
    /// The function's parameters: `vars`, `params`, `out`.
    args: [Value; 3],
    /// The batch slot and the spill slot, where needed.
    slot: Option<StackSlot>,
    spill: Option<StackSlot>,
    src: Vec<Source>,
    /// Inline sin/cos by argument node.
    sincos_done: FxHashMap<NodeId, (Value, Value)>,
    /// Imported lazily: the batch function, or libm's sin and cos for the cold path.
    batch_fn: Option<FuncRef>,
    libm_fns: Option<(FuncRef, FuncRef)>,
    n_inst: usize,
    n_calls: usize,
}

/// A node's operands as [`Emitter::operands`] emits them: the children's values by
/// position, and a product fused into this node as `(position, factor, factor)`.
type Operands = ([Option<Value>; 3], Option<(usize, Value, Value)>);

impl<M: Module> Emitter<'_, '_, M> {
    /// The value of node `id` for a use at position `at` of the emission order.
    /// Constants are materialized at each use rather than once: a constant shared by
    /// thousands of nodes would otherwise be one value live across the whole function (and
    /// across every call); batch results likewise are reloaded from their slot.
    fn operand(&mut self, id: NodeId, at: usize) -> Value {
        match (*self.graph.node(id), self.src[id.index()]) {
            (Node::Const(c), _) => self.b.ins().f64const(c),
            (_, Source::Value(v)) => v,
            (_, Source::Spilled(v, def, _)) if at - def <= SPILL_WINDOW => v,
            (_, Source::Spilled(_, _, off)) => self.b.ins().stack_load(
                self.ptr,
                types::F64,
                self.spill.expect("a spill slot exists"),
                8 * off as i32,
            ),
            (_, Source::Slot(off)) => self.b.ins().stack_load(
                self.ptr,
                types::F64,
                self.slot.expect("a slot exists"),
                8 * off as i32,
            ),
            (_, Source::None) => unreachable!("children are emitted first"),
        }
    }

    /// Emit node `i` at position `at` of the emission order (stored to the spill slot too
    /// if it is used far away).
    fn node(&mut self, i: usize, at: usize) {
        let node = self.graph.nodes()[i];
        let (o, fma) = self.operands(node, at);
        let x = match fma {
            Some((k, p, q)) => self.fused_sum(node, k, p, q, &o),
            None => self.op(node, &o),
        };
        self.n_inst += 1;
        self.src[i] = if self.spill_off[i] == u32::MAX {
            Source::Value(x)
        } else {
            let slot = self.spill.expect("a spill slot exists");
            self.b
                .ins()
                .stack_store(self.ptr, x, slot, 8 * self.spill_off[i] as i32);
            Source::Spilled(x, at, self.spill_off[i])
        };
    }

    /// The operands of `node` for a use at `at`, in child order.
    fn operands(&mut self, node: Node, at: usize) -> Operands {
        let mut o = [None; 3];
        let mut fma: Option<(usize, Value, Value)> = None;
        for (k, c) in node.children().into_iter().enumerate() {
            // Inline sin/cos whose argument was already done needs no operand.
            if matches!(node, Node::Sin(_) | Node::Cos(_)) && self.sincos_done.contains_key(&c) {
                continue;
            }
            if self.fused[c.index()]
                && let Node::Mul(p, q) = self.graph.nodes()[c.index()]
            {
                let (p, q) = (self.operand(p, at), self.operand(q, at));
                fma = Some((k, p, q));
                continue;
            }
            o[k] = Some(self.operand(c, at));
        }
        (o, fma)
    }

    /// The sum or difference `node` whose operand `k` is the fused product `p·q`: one
    /// `fma`.
    fn fused_sum(
        &mut self,
        node: Node,
        k: usize,
        p: Value,
        q: Value,
        o: &[Option<Value>; 3],
    ) -> Value {
        let v = |k: usize| o[k].expect("operand emitted");
        match (node, k) {
            // a·b + c, c + a·b
            (Node::Add(..), k) => self.b.ins().fma(p, q, v(1 - k)),
            // a·b − c
            (Node::Sub(..), 0) => {
                let c = self.b.ins().fneg(v(1));
                self.b.ins().fma(p, q, c)
            }
            // c − a·b
            (Node::Sub(..), _) => {
                let p = self.b.ins().fneg(p);
                self.b.ins().fma(p, q, v(0))
            }
            _ => unreachable!("only sums and differences fuse"),
        }
    }

    /// `node` of operands `o`, unfused.
    fn op(&mut self, node: Node, o: &[Option<Value>; 3]) -> Value {
        let v = |k: usize| o[k].expect("operand emitted");
        let [vars_p, params_p, _] = self.args;
        let b = &mut self.b;
        match node {
            Node::Const(_) => unreachable!("constants are emitted at their uses"),
            Node::Var(k) => b.ins().load(types::F64, self.mem, vars_p, 8 * k as i32),
            Node::Param(k) => b.ins().load(types::F64, self.mem, params_p, 8 * k as i32),
            Node::Add(..) => b.ins().fadd(v(0), v(1)),
            Node::Sub(..) => b.ins().fsub(v(0), v(1)),
            Node::Mul(..) => b.ins().fmul(v(0), v(1)),
            Node::Div(..) => b.ins().fdiv(v(0), v(1)),
            Node::Neg(_) => b.ins().fneg(v(0)),
            Node::Sqrt(_) => b.ins().sqrt(v(0)),
            Node::Sin(a) | Node::Cos(a) => {
                let (sv, cv) = self.sin_cos(a, o[0]);
                if matches!(node, Node::Sin(_)) { sv } else { cv }
            }
            Node::Acos(_) => trig::emit_acos(&mut Ir { b }, v(0)),
            Node::Atan2(..) => trig::emit_atan2(&mut Ir { b }, v(0), v(1)),
            Node::Sgn(_) => sgn(b, v(0)),
            Node::Clamp(_) => clamp_unit(b, v(0)),
            Node::Select(..) => select_positive(b, v(0), v(1), v(2)),
        }
    }

    /// `(sin x, cos x)` inline for argument node `a` (value `x`, absent when done), once
    /// per argument.
    fn sin_cos(&mut self, a: NodeId, x: Option<Value>) -> (Value, Value) {
        if let Some(&r) = self.sincos_done.get(&a) {
            return r;
        }
        let fns = *self.libm_fns.get_or_insert_with(|| {
            let [s, c] = import_libm(self.module, self.b.func);
            (s, c)
        });
        let r = inline_sin_cos(&mut self.b, x.expect("operand emitted"), fns);
        self.n_calls += 2;
        self.sincos_done.insert(a, r);
        r
    }

    /// The batch `bt` of depth `d` at position `at`: store the arguments, one call; the
    /// results stay in the slot, where the group's nodes read them.
    fn batch(&mut self, bt: &Batch, d: usize, at: usize, depth: &[u32], mark: &[bool]) {
        let slot = self.slot.expect("a slot exists");
        let nodes = self.graph.nodes();
        let (nsc, nat, nac) = (bt.sc.len(), bt.at.len(), bt.ac.len());
        let off = |k: usize| 8 * (bt.base as usize + k) as i32;
        for (id, k) in bt.stores(nodes) {
            let x = self.operand(id, at);
            self.b.ins().stack_store(self.ptr, x, slot, off(k));
        }
        let f = *self
            .batch_fn
            .get_or_insert_with(|| import_batch(self.module, self.b.func, self.ptr));
        let addr = self.b.ins().stack_addr(self.ptr, slot, off(0));
        let n = [nsc, nat, nac].map(|n| self.b.ins().iconst(self.ptr, n as i64));
        self.b.ins().call(f, &[addr, n[0], n[1], n[2]]);
        self.n_calls += 1;
        self.n_inst += 1;
        let out0 = bt.base + (nsc + 2 * nat + nac) as u32;
        let by_arg: FxHashMap<NodeId, usize> =
            bt.sc.iter().enumerate().map(|(k, &a)| (a, k)).collect();
        for (i, n) in nodes.iter().enumerate() {
            if !mark[i] || !is_trig(n) || depth[i] as usize != d {
                continue;
            }
            let k = match *n {
                Node::Sin(a) => by_arg[&a],
                Node::Cos(a) => nsc + by_arg[&a],
                Node::Atan2(..) => 2 * nsc + bt.at.iter().position(|&j| j == i).unwrap_or(0),
                _ => 2 * nsc + nat + bt.ac.iter().position(|&j| j == i).unwrap_or(0),
            };
            self.src[i] = Source::Slot(out0 + k as u32);
        }
    }

    /// Store the outputs (read at position `at`, after every other) and close the
    /// function. Returns the instructions and calls emitted.
    fn finish(
        mut self,
        outputs: &[NodeId],
        at: usize,
        target: TargetFrontendConfig,
    ) -> (usize, usize) {
        for (k, o) in outputs.iter().enumerate() {
            let x = self.operand(*o, at);
            self.b.ins().store(self.mem, x, self.args[2], 8 * k as i32);
        }
        self.b.ins().return_(&[]);
        self.b.seal_all_blocks();
        self.b.finalize(target);
        (self.n_inst, self.n_calls)
    }
}

/// `sgn(a)`: 1, −1 or 0 (NaN gives 0, as [`Node::eval_with`]).
fn sgn(b: &mut FunctionBuilder, a: Value) -> Value {
    let zero = b.ins().f64const(0.0);
    let one = b.ins().f64const(1.0);
    let mone = b.ins().f64const(-1.0);
    let gt = b.ins().fcmp(FloatCC::GreaterThan, a, zero);
    let lt = b.ins().fcmp(FloatCC::LessThan, a, zero);
    let neg_or_zero = b.ins().select(lt, mone, zero);
    b.ins().select(gt, one, neg_or_zero)
}

/// `select(c, u, v)`: `u` where `c > 0`, else `v` (NaN selects `v`).
fn select_positive(b: &mut FunctionBuilder, c: Value, u: Value, v: Value) -> Value {
    let zero = b.ins().f64const(0.0);
    let gt = b.ins().fcmp(FloatCC::GreaterThan, c, zero);
    b.ins().select(gt, u, v)
}

/// Which products [`define_eval`] fuses into their user (`fma` on): a `Mul` used exactly
/// once among the marked nodes and not an output, whose user is an `Add` or `Sub` at
/// index `fuse_from` or above (one product per user).
fn fusable_products(
    graph: &ExprGraph,
    outputs: &[NodeId],
    mark: &[bool],
    fuse_from: usize,
    fma: bool,
) -> Vec<bool> {
    let nodes = graph.nodes();
    let mut fused = vec![false; nodes.len()];
    if !fma || fuse_from >= nodes.len() {
        return fused;
    }
    let mut uses = vec![0u32; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        if mark[i] {
            for c in n.children() {
                uses[c.index()] += 1;
            }
        }
    }
    for o in outputs {
        uses[o.index()] += 1;
    }
    for (i, n) in nodes.iter().enumerate().skip(fuse_from) {
        if mark[i]
            && matches!(n, Node::Add(..) | Node::Sub(..))
            && let Some(c) = n
                .children()
                .into_iter()
                .find(|c| uses[c.index()] == 1 && matches!(nodes[c.index()], Node::Mul(..)))
        {
            fused[c.index()] = true;
        }
    }
    fused
}

/// Import `void foldsynth_trig_batch(double *, size_t, size_t, size_t)`.
fn import_batch<M: Module>(
    module: &mut M,
    func: &mut cranelift_codegen::ir::Function,
    ptr: types::Type,
) -> FuncRef {
    let mut sig = module.make_signature();
    for _ in 0..4 {
        sig.params.push(AbiParam::new(ptr));
    }
    let id = module
        .declare_function(TRIG_BATCH_SYMBOL, Linkage::Import, &sig)
        .expect("the batch function's one signature");
    module.declare_func_in_func(id, func)
}

/// Import libm's `double sin(double)` and `double cos(double)`.
fn import_libm<M: Module>(
    module: &mut M,
    func: &mut cranelift_codegen::ir::Function,
) -> [FuncRef; 2] {
    let mut sig: Signature = module.make_signature();
    sig.params.push(AbiParam::new(types::F64));
    sig.returns.push(AbiParam::new(types::F64));
    MATH_SYMBOLS.map(|name| {
        let id = module
            .declare_function(name, Linkage::Import, &sig)
            .expect("libm's one signature");
        module.declare_func_in_func(id, func)
    })
}

/// `(sin x, cos x)` inline: the kernel, or the C library on a cold path beyond
/// [`trig::SIN_COS_MAX_ARG`] (as [`trig::sin_cos`]).
fn inline_sin_cos(b: &mut FunctionBuilder, x: Value, libm: (FuncRef, FuncRef)) -> (Value, Value) {
    let hot = b.create_block();
    let cold = b.create_block();
    let join = b.create_block();
    let s = b.append_block_param(join, types::F64);
    let c = b.append_block_param(join, types::F64);
    let ax = b.ins().fabs(x);
    let lim = b.ins().f64const(trig::SIN_COS_MAX_ARG);
    let far = b.ins().fcmp(FloatCC::GreaterThan, ax, lim);
    b.ins().brif(far, cold, &[], hot, &[]);
    b.switch_to_block(hot);
    let (hs, hc) = trig::emit_sin_cos(&mut Ir { b }, x);
    b.ins()
        .jump(join, &[BlockArg::Value(hs), BlockArg::Value(hc)]);
    b.switch_to_block(cold);
    b.set_cold_block(cold);
    let cs = b.ins().call(libm.0, &[x]);
    let cs = b.inst_results(cs)[0];
    let cc = b.ins().call(libm.1, &[x]);
    let cc = b.inst_results(cc)[0];
    b.ins()
        .jump(join, &[BlockArg::Value(cs), BlockArg::Value(cc)]);
    b.switch_to_block(join);
    (s, c)
}
