//! Ahead-of-time compilation: the function the JIT builds ([`super::codegen`], the same
//! Cranelift IR), written as a relocatable object through `cranelift-object`, linked into
//! a shared library by the system C compiler, and described by a C header and a JSON
//! manifest.
//!
//! The object exports `void NAME_eval(const double *vars, const double *params, double
//! *out)` and small functions that report the sizes, names, bounds, default parameters
//! and constants of an [`Interface`]; all of it is generated code and data (the
//! transcendentals inline, [`Math::Inline`]: the same bits as the JIT), so the only
//! run-time dependency is the C library's `sin` and `cos`, called for arguments beyond
//! 10⁶ only.
//! The code is for the host's architecture with baseline features (any CPU of that
//! architecture runs it) and position independent.

use super::Layout;
use super::codegen::{self, CompileError, Math, OptLevel, Target, cg};
use crate::expr::{ExprGraph, NodeId, check_indices};
use cranelift_codegen::Context;
use cranelift_codegen::ir::{AbiParam, InstBuilder, UserFuncName};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_module::{DataDescription, DataId, Linkage, Module, default_libcall_names};
use cranelift_object::{ObjectBuilder, ObjectModule};
use serde_json::{Value as Json, json};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A variable of the compiled function, `vars[i]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// Its name (UTF-8).
    pub name: String,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
}

/// A parameter of the compiled function, `params[i]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Its name (an ASCII identifier).
    pub name: String,
    /// What it means (one line).
    pub doc: String,
    /// The value reported by `NAME_default_params()`.
    pub default: f64,
}

/// A named `size_t` constant reported by `size_t NAME_<name>(void)` and the macro
/// `NAME_<NAME>` (for the sizes and offsets a caller of this particular function needs).
#[derive(Clone, Debug, PartialEq)]
pub struct Constant {
    /// Lower-case identifier, e.g. `jacobian_offset`.
    pub name: String,
    /// Its value.
    pub value: usize,
    /// What it is (one line).
    pub doc: String,
}

/// Everything a library reports about its function besides the code.
#[derive(Clone, Debug, PartialEq)]
pub struct Interface {
    /// Prefix of every symbol: a C identifier.
    pub name: String,
    /// What the function computes, for the header's opening comment (lines of text).
    pub doc: Vec<String>,
    /// The variables, in the order of `vars`.
    pub vars: Vec<Variable>,
    /// The parameters, in the order of `params`.
    pub params: Vec<Parameter>,
    /// Labels of the outputs (before the gradients), in the order of `out`.
    pub outputs: Vec<String>,
    /// Further constants (beyond `n_vars`, `n_params`, `n_outputs`, `n_out`).
    pub constants: Vec<Constant>,
}

/// Why writing a library failed.
#[derive(Debug, thiserror::Error)]
pub enum AotError {
    /// Code generation failed.
    #[error(transparent)]
    Compile(#[from] CompileError),
    /// The interface does not match the function, or a name is not allowed.
    #[error("{0}")]
    Interface(String),
    /// Reading or writing a file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// The C compiler could not be run or failed to link.
    #[error("linking the shared library: {0}")]
    Link(String),
}

/// Whether `name` can prefix C symbols: `[A-Za-z_][A-Za-z0-9_]*`, at most 64 characters,
/// not starting with `__`.
pub fn check_name(name: &str) -> Result<(), AotError> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && !name.starts_with("__")
        && name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(AotError::Interface(format!(
            "'{name}' is not a usable C name: use letters, digits and '_' (at most 64, not starting with a digit or '__')"
        )))
    }
}

/// A C identifier made from free text (a task name): other characters become `_`, a
/// leading digit gets a `m_` prefix.
pub fn c_name(text: &str) -> String {
    let mut s: String = text
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .take(60)
        .collect();
    s = s.trim_start_matches('_').to_string();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s = format!("m_{s}");
    }
    s
}

impl Interface {
    /// The base constants every library reports, then [`Interface::constants`].
    fn all_constants(&self, layout: &Layout) -> Vec<Constant> {
        let c = |name: &str, value: usize, doc: &str| Constant {
            name: name.into(),
            value,
            doc: doc.into(),
        };
        let mut all = vec![
            c("n_vars", self.vars.len(), "variables: the length of vars"),
            c(
                "n_params",
                self.params.len(),
                "parameters: the length of params",
            ),
            c(
                "n_outputs",
                layout.n_outputs,
                "outputs (values before the gradients)",
            ),
            c("n_out", layout.len(), "the length of out"),
        ];
        all.extend(self.constants.iter().cloned());
        all
    }

    fn check(&self, layout: &Layout) -> Result<(), AotError> {
        check_name(&self.name)?;
        let bad = |m: String| Err(AotError::Interface(m));
        if self.vars.len() != layout.n_vars {
            return bad(format!(
                "{} variable names for {} variables",
                self.vars.len(),
                layout.n_vars
            ));
        }
        if self.outputs.len() != layout.n_outputs {
            return bad(format!(
                "{} output labels for {} outputs",
                self.outputs.len(),
                layout.n_outputs
            ));
        }
        let mut seen = std::collections::HashSet::new();
        for k in self.all_constants(layout) {
            if !seen.insert(k.name.clone()) {
                return bad(format!("the constant '{}' is defined twice", k.name));
            }
            check_name(&k.name)?;
        }
        for reserved in [
            "eval",
            "var_names",
            "param_names",
            "output_names",
            "lower_bounds",
            "upper_bounds",
            "default_params",
        ] {
            if seen.contains(reserved) {
                return bad(format!("the constant name '{reserved}' is reserved"));
            }
        }
        Ok(())
    }
}

/// The relocatable object: `NAME_eval` computing `outputs` of `graph` (values, then the
/// gradients, as `layout` says) over `n_params` parameters, with the reporting functions
/// of `iface`.
pub fn object(
    graph: &ExprGraph,
    outputs: &[NodeId],
    layout: &Layout,
    n_params: usize,
    iface: &Interface,
    opt: OptLevel,
) -> Result<Vec<u8>, AotError> {
    iface.check(layout)?;
    if outputs.len() != layout.len() {
        return Err(AotError::Interface(format!(
            "{} outputs for a layout of {}",
            outputs.len(),
            layout.len()
        )));
    }
    if iface.params.len() != n_params {
        return Err(AotError::Interface(format!(
            "{} parameter names for {n_params} parameters",
            iface.params.len()
        )));
    }
    let mark =
        check_indices(graph, outputs, layout.n_vars, n_params).map_err(CompileError::from)?;
    let n_nodes = mark.iter().filter(|m| **m).count();
    let isa = codegen::isa(Target::Object, opt, n_nodes)?;
    let builder =
        ObjectBuilder::new(isa, iface.name.as_bytes(), default_libcall_names()).map_err(cg)?;
    let mut module = ObjectModule::new(builder);
    let name = &iface.name;
    // Self-contained: the transcendentals as inline code (the same bits as the JIT's).
    codegen::define_eval(
        &mut module,
        &format!("{name}_eval"),
        Linkage::Export,
        graph,
        outputs,
        &mark,
        Math::Inline,
        // Baseline features have no FMA; the library rounds as the interpreter does.
        usize::MAX,
    )?;
    for k in iface.all_constants(layout) {
        define_size_fn(&mut module, &format!("{name}_{}", k.name), k.value)?;
    }
    let strings = |list: Vec<&str>| list.into_iter().map(str::to_string).collect::<Vec<_>>();
    let tables = [
        (
            "var_names",
            strings(iface.vars.iter().map(|v| v.name.as_str()).collect()),
        ),
        (
            "param_names",
            strings(iface.params.iter().map(|p| p.name.as_str()).collect()),
        ),
        ("output_names", iface.outputs.clone()),
    ];
    for (what, list) in tables {
        let data = string_table(&mut module, &list)?;
        define_pointer_fn(&mut module, &format!("{name}_{what}"), data)?;
    }
    let arrays = [
        (
            "lower_bounds",
            iface.vars.iter().map(|v| v.lower).collect::<Vec<_>>(),
        ),
        ("upper_bounds", iface.vars.iter().map(|v| v.upper).collect()),
        (
            "default_params",
            iface.params.iter().map(|p| p.default).collect(),
        ),
    ];
    for (what, values) in arrays {
        let data = f64_array(&mut module, &values)?;
        define_pointer_fn(&mut module, &format!("{name}_{what}"), data)?;
    }
    let mut product = module.finish();
    if product.object.format() == object::BinaryFormat::Elf {
        // Without this note, linkers assume the object needs an executable stack (and
        // current glibc refuses to load such a library).
        product.object.add_section(
            Vec::new(),
            b".note.GNU-stack".to_vec(),
            object::SectionKind::Elf(object::elf::SHT_PROGBITS),
        );
    }
    Ok(product.emit().map_err(cg)?)
}

/// `size_t NAME(void) { return value; }`.
fn define_size_fn(module: &mut ObjectModule, name: &str, value: usize) -> Result<(), AotError> {
    let ptr = module.target_config().pointer_type();
    define_returning(module, name, |_, b| b.ins().iconst(ptr, value as i64))
}

/// `const T *NAME(void) { return &data; }`.
fn define_pointer_fn(module: &mut ObjectModule, name: &str, data: DataId) -> Result<(), AotError> {
    let ptr = module.target_config().pointer_type();
    define_returning(module, name, |module, b| {
        let gv = module.declare_data_in_func(data, b.func);
        b.ins().symbol_value(ptr, gv)
    })
}

/// An exported function without arguments returning one pointer-sized value.
fn define_returning(
    module: &mut ObjectModule,
    name: &str,
    body: impl FnOnce(&mut ObjectModule, &mut FunctionBuilder) -> cranelift_codegen::ir::Value,
) -> Result<(), AotError> {
    let ptr = module.target_config().pointer_type();
    let mut sig = module.make_signature();
    sig.returns.push(AbiParam::new(ptr));
    let id = module
        .declare_function(name, Linkage::Export, &sig)
        .map_err(cg)?;
    let mut ctx: Context = module.make_context();
    ctx.func.signature = sig;
    ctx.func.name = UserFuncName::user(0, id.as_u32());
    let mut fctx = FunctionBuilderContext::new();
    {
        let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
        let block = b.create_block();
        b.switch_to_block(block);
        let v = body(module, &mut b);
        b.ins().return_(&[v]);
        b.seal_all_blocks();
        b.finalize(module.target_config());
    }
    module.define_function(id, &mut ctx).map_err(cg)?;
    module.clear_context(&mut ctx);
    Ok(())
}

/// Read-only data; never empty (a zero-length object has no address of its own).
fn define_data(
    module: &mut ObjectModule,
    mut bytes: Vec<u8>,
    relocs: impl FnOnce(&mut ObjectModule, &mut DataDescription),
) -> Result<DataId, AotError> {
    if bytes.is_empty() {
        bytes.resize(8, 0);
    }
    let id = module.declare_anonymous_data(false, false).map_err(cg)?;
    let mut desc = DataDescription::new();
    desc.define(bytes.into_boxed_slice());
    desc.set_align(8);
    relocs(module, &mut desc);
    module.define_data(id, &desc).map_err(cg)?;
    Ok(id)
}

/// An array of `const char *` to NUL-terminated UTF-8 strings.
fn string_table(module: &mut ObjectModule, list: &[String]) -> Result<DataId, AotError> {
    let mut text = Vec::new();
    let mut offsets = Vec::with_capacity(list.len());
    for s in list {
        if s.contains('\0') {
            return Err(AotError::Interface(format!("the name {s:?} contains NUL")));
        }
        offsets.push(text.len());
        text.extend_from_slice(s.as_bytes());
        text.push(0);
    }
    let text_id = define_data(module, text, |_, _| {})?;
    let width = module.target_config().pointer_bytes() as usize;
    define_data(module, vec![0; width * list.len()], |module, desc| {
        let gv = module.declare_data_in_data(text_id, desc);
        for (k, off) in offsets.iter().enumerate() {
            desc.write_data_addr((k * width) as u32, gv, *off as i64);
        }
    })
}

/// An array of `double` in the target's byte order (the host's).
fn f64_array(module: &mut ObjectModule, values: &[f64]) -> Result<DataId, AotError> {
    let bytes = values.iter().flat_map(|v| v.to_ne_bytes()).collect();
    define_data(module, bytes, |_, _| {})
}

/// `text` safe inside a C block comment.
fn comment(text: &str) -> String {
    text.replace("*/", "* /")
}

/// A C string literal of UTF-8 text.
fn c_string(text: &str) -> String {
    let mut s = String::from("\"");
    for b in text.bytes() {
        match b {
            b'"' => s.push_str("\\\""),
            b'\\' => s.push_str("\\\\"),
            0x20..=0x7e => s.push(b as char),
            _ => {
                let _ = write!(s, "\\{b:03o}");
            }
        }
    }
    s.push('"');
    s
}

/// A C double literal that reads back exactly.
fn c_double(v: f64) -> String {
    if v.is_finite() {
        let s = format!("{v:?}");
        if s.contains(['.', 'e', 'E']) {
            s
        } else {
            format!("{s}.0")
        }
    } else if v.is_nan() {
        "(0.0 / 0.0)".into()
    } else if v > 0.0 {
        "(1.0 / 0.0)".into()
    } else {
        "(-1.0 / 0.0)".into()
    }
}

/// The C header documenting every symbol of the object of `iface`.
pub fn header(iface: &Interface, layout: &Layout) -> String {
    let name = &iface.name;
    let up = name.to_ascii_uppercase();
    let mut h = String::new();
    header_preamble(&mut h, iface, &up);
    header_sizes(&mut h, iface, layout, &up);
    header_buffers(&mut h, iface, layout, &up);
    header_functions(&mut h, iface, &up);
    h
}

/// The header's opening comment (the interface's docs) and include guard.
fn header_preamble(w: &mut String, iface: &Interface, up: &str) {
    let name = &iface.name;
    let _ = writeln!(
        w,
        "/* {name}.h: generated by foldsynth {}; do not edit.\n *",
        env!("CARGO_PKG_VERSION")
    );
    for line in &iface.doc {
        let line = format!(" * {}", comment(line));
        let _ = writeln!(w, "{}", line.trim_end());
    }
    let _ = writeln!(
        w,
        " *\n * Link with lib{name}.so (or {name}.o and -lm). The code is pure: {name}_eval reads vars and\n * params, writes out and touches nothing else, so any number of threads may call it.\n * Names are UTF-8. The reporting functions return pointers to static, read-only data.\n */"
    );
    let _ = writeln!(
        w,
        "#ifndef {up}_H\n#define {up}_H\n\n#include <stddef.h>\n\n#ifdef __cplusplus\nextern \"C\" {{\n#endif\n"
    );
}

/// The sizes and offsets, as macros and as functions.
fn header_sizes(w: &mut String, iface: &Interface, layout: &Layout, up: &str) {
    let name = &iface.name;
    let _ = writeln!(
        w,
        "/* Sizes and offsets: macros for static arrays, functions for code that loads the\n * library at run time. */"
    );
    for k in iface.all_constants(layout) {
        let _ = writeln!(
            w,
            "#define {up}_{} {} /* {} */",
            k.name.to_ascii_uppercase(),
            k.value,
            comment(&k.doc)
        );
    }
    let _ = writeln!(w);
    for k in iface.all_constants(layout) {
        let _ = writeln!(
            w,
            "size_t {name}_{}(void); /* {up}_{} */",
            k.name,
            k.name.to_ascii_uppercase()
        );
    }
}

/// What `vars`, `params` and `out` hold.
fn header_buffers(w: &mut String, iface: &Interface, layout: &Layout, up: &str) {
    let _ = writeln!(
        w,
        "\n/* Variables vars[i] with their bounds [lower, upper]: */"
    );
    for (i, v) in iface.vars.iter().enumerate() {
        let _ = writeln!(
            w,
            "/*   vars[{i}] {}  [{}, {}] */",
            comment(&v.name),
            c_double(v.lower),
            c_double(v.upper)
        );
    }
    let _ = writeln!(w, "/* Parameters params[i] (default value): */");
    for (i, p) in iface.params.iter().enumerate() {
        let _ = writeln!(
            w,
            "/*   params[{i}] {} = {}: {} */",
            p.name,
            c_double(p.default),
            comment(&p.doc)
        );
    }
    let _ = writeln!(
        w,
        "\n/* The output buffer out[{up}_N_OUT]: first the {} outputs,",
        layout.n_outputs
    );
    for (i, o) in iface.outputs.iter().enumerate() {
        let _ = writeln!(w, " *   out[{i}] {}", comment(o));
    }
    if layout.gradients {
        let _ = writeln!(
            w,
            " * then the gradient of every output with respect to vars, one row of {up}_N_VARS\n * per output: out[{up}_N_OUTPUTS + k * {up}_N_VARS + i] = d out[k] / d vars[i]."
        );
    }
    let _ = writeln!(w, " */");
}

/// The functions' declarations, the names as initializers, and the closing guard.
fn header_functions(w: &mut String, iface: &Interface, up: &str) {
    let name = &iface.name;
    let _ = writeln!(
        w,
        "void {name}_eval(const double *vars, const double *params, double *out);\n"
    );
    let _ = writeln!(
        w,
        "/* Names: arrays of {up}_N_VARS, {up}_N_PARAMS and {up}_N_OUTPUTS strings. */"
    );
    for what in ["var_names", "param_names", "output_names"] {
        let _ = writeln!(w, "const char *const *{name}_{what}(void);");
    }
    let _ = writeln!(
        w,
        "/* Bounds of the variables ({up}_N_VARS each) and the default parameters ({up}_N_PARAMS). */"
    );
    for what in ["lower_bounds", "upper_bounds", "default_params"] {
        let _ = writeln!(w, "const double *{name}_{what}(void);");
    }
    // The names again as literals: usable without calling into the library.
    let _ = writeln!(
        w,
        "\n/* The same names as initializers, e.g. static const char *names[] = {up}_VAR_NAMES; */"
    );
    let list = |v: Vec<&str>| v.iter().map(|s| c_string(s)).collect::<Vec<_>>().join(", ");
    let _ = writeln!(
        w,
        "#define {up}_VAR_NAMES {{ {} }}",
        list(iface.vars.iter().map(|v| v.name.as_str()).collect())
    );
    let _ = writeln!(
        w,
        "#define {up}_PARAM_NAMES {{ {} }}",
        list(iface.params.iter().map(|p| p.name.as_str()).collect())
    );
    let _ = writeln!(
        w,
        "\n#ifdef __cplusplus\n}} /* extern \"C\" */\n#endif\n\n#endif /* {up}_H */"
    );
}

/// The facts of the header as JSON (`name`, `symbols`, `constants`, `variables`,
/// `parameters`, `outputs`, `layout`, `target`).
pub fn manifest(iface: &Interface, layout: &Layout) -> Json {
    let name = &iface.name;
    let constants: serde_json::Map<String, Json> = iface
        .all_constants(layout)
        .into_iter()
        .map(|k| (k.name, json!(k.value)))
        .collect();
    let mut symbols = vec![json!({
        "name": format!("{name}_eval"),
        "c": format!("void {name}_eval(const double *vars, const double *params, double *out)"),
    })];
    for k in iface.all_constants(layout) {
        symbols.push(json!({
            "name": format!("{name}_{}", k.name),
            "c": format!("size_t {name}_{}(void)", k.name),
            "doc": k.doc,
        }));
    }
    for what in ["var_names", "param_names", "output_names"] {
        symbols.push(json!({
            "name": format!("{name}_{what}"),
            "c": format!("const char *const *{name}_{what}(void)"),
        }));
    }
    for what in ["lower_bounds", "upper_bounds", "default_params"] {
        symbols.push(json!({
            "name": format!("{name}_{what}"),
            "c": format!("const double *{name}_{what}(void)"),
        }));
    }
    json!({
        "name": name,
        "generator": format!("foldsynth {}", env!("CARGO_PKG_VERSION")),
        "target": {
            "arch": std::env::consts::ARCH,
            "os": std::env::consts::OS,
            "cpu": "baseline",
            "libm": codegen::MATH_SYMBOLS,
        },
        "doc": iface.doc,
        "symbols": symbols,
        "constants": constants,
        "variables": iface.vars.iter().map(|v| json!({"name": v.name, "lower": v.lower, "upper": v.upper})).collect::<Vec<_>>(),
        "parameters": iface.params.iter().map(|p| json!({"name": p.name, "doc": p.doc, "default": p.default})).collect::<Vec<_>>(),
        "outputs": iface.outputs,
        "layout": {
            "values": {"offset": 0, "len": layout.n_outputs},
            "gradients": if layout.gradients {
                json!({"offset": layout.n_outputs, "rows": layout.n_outputs, "cols": layout.n_vars, "order": "row-major: out[n_outputs + k*n_vars + i] = d out[k] / d vars[i]"})
            } else {
                Json::Null
            },
            "len": layout.len(),
        },
    })
}

/// The file name of the shared library `name` on this platform (`libNAME.so`).
pub fn library_file_name(name: &str) -> String {
    format!(
        "{}{name}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    )
}

/// Link `object` into the shared library `out` with the system C compiler (`$CC`, else
/// `cc`) and libm.
pub fn link_shared(object: &Path, out: &Path) -> Result<(), AotError> {
    let cc = std::env::var("CC")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .unwrap_or_else(|| "cc".to_string());
    let output = Command::new(&cc)
        .arg("-shared")
        .arg("-o")
        .arg(out)
        .arg(object)
        .arg("-lm")
        .output()
        .map_err(|e| {
            AotError::Link(format!(
                "cannot run the C compiler '{cc}' ({e}); install one (e.g. gcc) or set CC"
            ))
        })?;
    if !output.status.success() {
        return Err(AotError::Link(format!(
            "'{cc} -shared' failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    Ok(())
}

/// Write `bytes` to `path`.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<PathBuf, AotError> {
    std::fs::write(path, bytes).map_err(|source| AotError::Io {
        path: path.display().to_string(),
        source,
    })?;
    Ok(path.to_path_buf())
}
