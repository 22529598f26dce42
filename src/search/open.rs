//! Opening the output directory for a search: the settings that decide its records and
//! the directory opened for them (see [`super::output`] for what may be used and deleted).

use super::options::{SearchError, SearchOptions};
use super::output::{OutputDir, RunSettings, SETTINGS, ShardSpec};
use super::strategy::Strategy;
use crate::grammar::Rules;
use crate::task::Task;

/// The settings of a search of `task` at `n_max` with `opts` (and of shard `shard`).
pub fn settings(
    task: &Task,
    n_max: usize,
    opts: &SearchOptions,
    shard: Option<ShardSpec>,
) -> RunSettings {
    RunSettings {
        task: task.name.clone(),
        task_digest: task.digest.clone(),
        n_max,
        starts: opts.starts,
        seed: opts.seed,
        sweep: opts.sweep,
        foldsynth: env!("CARGO_PKG_VERSION").into(),
        rules: (opts.rules != Rules::default()).then(|| opts.rules.names()),
        post_check_only: opts.post_check_only,
        shard,
        guided: (shard.is_some() && opts.strategy == Strategy::Guided).then_some(
            super::strategy::Selection {
                alternatives: opts.budget.alternatives,
            },
        ),
        graphs: opts.graphs.clone(),
    }
}

/// Open the output directory for a run of `settings` and write its settings file.
pub fn open_output(
    settings: &RunSettings,
    opts: &SearchOptions,
) -> Result<(OutputDir, bool), SearchError> {
    let opened = OutputDir::open(&opts.out, settings, opts.resume, opts.force)?;
    for note in &opened.notes {
        eprintln!("note: {note}");
    }
    let out = opened.dir;
    out.write(
        SETTINGS,
        serde_json::to_string_pretty(settings).unwrap_or_default() + "\n",
    )?;
    Ok((out, opened.resume))
}
