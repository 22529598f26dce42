//! `foldsynth compile TASK --graph SEQ [--candidate K] [--modes …] [--emit obj,so,header,all]
//! [--name NAME] --out DIR`: one design model compiled ahead of time into a relocatable
//! object, a shared library, a C header and a JSON manifest.

use super::model::parse_modes;
use crate::compile::Options;
use crate::compile::aot;
use crate::grammar::CreaseGraph;
use crate::model::compiled::CompiledModel;
use crate::model::{Model, Plan, interface};
use crate::task::Task;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

/// What `foldsynth compile` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Emit {
    /// The relocatable object NAME.o (link it with -lm).
    Obj,
    /// The shared library libNAME.so (linked by the system C compiler, `$CC` or `cc`).
    So,
    /// The C header NAME.h.
    Header,
    /// All of the above.
    All,
}

/// Arguments of `foldsynth compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// The graph as a rule sequence, e.g. "2, 3, (4, 8), 4, (7, 8)".
    #[arg(long)]
    pub graph: String,
    /// Gripping candidate: 1, 2 or 3 (the successors s1, s2, s3 of the vertex extended last).
    #[arg(long, default_value_t = 1)]
    pub candidate: usize,
    /// The modes the library reports as its default parameters, e.g. "up,down,up"
    /// (default: all up). Every call may pass other modes.
    #[arg(long)]
    pub modes: Option<String>,
    /// What to write (comma-separated; the JSON manifest NAME.json is always written).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    pub emit: Vec<Emit>,
    /// Prefix of every exported symbol (a C identifier; default: the task's name).
    #[arg(long)]
    pub name: Option<String>,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
}

/// Run `foldsynth compile`.
pub fn run(args: CompileArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    let graph = CreaseGraph::from_sequence(&task, &args.graph)
        .with_context(|| format!("--graph '{}'", args.graph))?;
    if !(1..=3).contains(&args.candidate) {
        bail!("--candidate must be 1, 2 or 3 (the successors of the vertex extended last)");
    }
    let name = match &args.name {
        Some(n) => {
            aot::check_name(n).context("--name")?;
            n.clone()
        }
        None => aot::c_name(&task.name),
    };
    let model = Model::from_plan(Plan::new(&graph)?, &task, args.candidate - 1)?;
    let modes = parse_modes(args.modes.as_deref(), model.plan.n_modes)?;
    let opts = Options::default();
    let compiled = CompiledModel::new(&model, &opts)?;
    let iface = interface::interface(&task.name, &model, &compiled, &modes, &name);
    let layout = &compiled.compiled.layout;
    let emit = |e: Emit| args.emit.contains(&e) || args.emit.contains(&Emit::All);

    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the directory {}", args.out.display()))?;
    let mut written = Vec::new();
    let t0 = std::time::Instant::now();
    if emit(Emit::Obj) || emit(Emit::So) {
        let n_params = iface.params.len();
        let bytes = aot::object(
            &compiled.compiled.graph,
            &compiled.compiled.outputs,
            layout,
            n_params,
            &iface,
            opts.opt_level,
        )?;
        let obj = aot::write_file(&args.out.join(format!("{name}.o")), &bytes)?;
        if emit(Emit::So) {
            let so = args.out.join(aot::library_file_name(&name));
            let linked = aot::link_shared(&obj, &so);
            if !emit(Emit::Obj) {
                let _ = std::fs::remove_file(&obj);
            } else {
                written.push(obj);
            }
            linked?;
            written.push(so);
        } else {
            written.push(obj);
        }
    }
    if emit(Emit::Header) {
        let h = aot::header(&iface, layout);
        written.push(aot::write_file(
            &args.out.join(format!("{name}.h")),
            h.as_bytes(),
        )?);
    }
    let manifest = interface::manifest(&task.name, &model, &compiled, &modes, &iface);
    let text = serde_json::to_string_pretty(&manifest)?;
    written.push(aot::write_file(
        &args.out.join(format!("{name}.json")),
        text.as_bytes(),
    )?);
    let ms = compiled.total_ms + t0.elapsed().as_secs_f64() * 1e3;
    println!(
        "{name}: {} of task '{}' (candidate {}), {} variables, {} parameters, {} constraints, out[{}]; {:.0} ms",
        model.plan.sequence,
        task.name,
        args.candidate,
        compiled.n_vars,
        iface.params.len(),
        compiled.n_constraints,
        layout.len(),
        ms
    );
    for f in &written {
        println!("  {}", f.display());
    }
    Ok(())
}
