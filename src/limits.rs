//! The limit of every count a user can give, checked before anything is allocated.
//!
//! Each limit is far above what a task needs (the thesis's tasks use N_max = 3, 16 states,
//! 16 starts) and low enough that the run fits in memory and ends: a value beyond it is
//! refused with a message naming the limit, never attempted. The table in docs/limits.md
//! lists them.

/// Largest N_max (task files and `--n-max`). The graphs grow about twentyfold per
/// internal vertex; enumeration and search stream them (memory does not grow with N_max),
/// but time does: N_max = 5 is a cluster's job (`foldsynth slurm`), 6 a large cluster's.
pub const N_MAX: usize = 6;
/// Most shards of one search (`--shard K/N`, `slurm --shards N`).
pub const SHARDS_MAX: usize = 100_000;
/// Most starting points per alternative (`--starts`).
pub const STARTS_MAX: usize = 1_000;
/// Most states of the verification sweep (`--sweep`, `model --sweep`).
pub const SWEEP_MAX: usize = 10_000;
/// Most states of the intersection check (`check.states`).
pub const STATES_MAX: usize = 1_000;
/// Most samples of `vertex --t A:B:N`.
pub const SAMPLES_MAX: usize = 100_000;
/// Most samples of one range of `t` in a task file (`t = "a .. b"`, `samples = N`: a
/// path target, an orientation over a range): each sample is a term of the compiled model.
pub const PATH_SAMPLES_MAX: usize = 1_000;
/// Most targets of a task after its ranges are expanded into samples (each is a term of
/// the compiled objective).
pub const TARGETS_MAX: usize = 10_000;
/// Most entries of each list of a task file (`[[objective.targets]]`, `[[obstacles]]`,
/// `[[constraints.orientation]]`, `[[constraints.fold_limits]]`, `[[constraints.inside]]`).
pub const TERMS_MAX: usize = 1_000;
/// Most rotational copies of the arm (`[copies] n`): the model keeps the arm clear of
/// ⌊n/2⌋ of them at every state.
pub const COPIES_MAX: usize = 12;
/// Most triangles of all the meshes one task names together (each mesh holds at most
/// [`crate::scene::mesh::MESH_TRIANGLES_MAX`]).
pub const MESH_TRIANGLES_TOTAL_MAX: usize = 100_000;
/// Most worker threads (`--jobs`).
pub const JOBS_MAX: usize = 256;
/// The largest CPU budget of a guided search: a year of one core's time.
pub const BUDGET_CPU_MAX: f64 = 3.2e7;
/// Most folding steps of the bar-and-hinge simulation (`--steps`, `motion.steps`).
pub const STEPS_MAX: u64 = 100_000;
/// Most evaluations of `optimize-flasher --evals`.
pub const EVALS_MAX: u64 = 10_000_000;
/// Longest task name (it names the output directory).
pub const NAME_MAX: usize = 64;
/// Longest timing budget of `bench … --millis`.
pub const BENCH_MILLIS_MAX: u64 = 60_000;
/// Largest picture side in pixels (`export --size`).
pub const IMAGE_SIDE_MAX: u32 = 4096;
/// Largest magnitude of a coordinate, length or target in task, pattern and design
/// files: squared distances of larger numbers overflow, and no origami is 10^6 units.
pub const COORD_MAX: f64 = 1e6;
/// Largest input file (task, pattern, FOLD, design).
pub const FILE_BYTES_MAX: u64 = 256 << 20;

/// `value` checked against `min..=max`; the error names what and the limit.
pub fn check_count(what: &str, value: u64, min: u64, max: u64) -> Result<(), String> {
    if value < min {
        Err(format!("{what} {value} is too small: at least {min}"))
    } else if value > max {
        Err(format!(
            "{what} {value} is over the limit of {max} (foldsynth's limits keep every run in bounded memory and time; see docs/limits.md)"
        ))
    } else {
        Ok(())
    }
}

/// A command-line count in `MIN..=MAX` (a clap value parser).
pub fn count<const MIN: u64, const MAX: u64>(s: &str) -> Result<usize, String> {
    let v: u64 = s.trim().parse().map_err(|_| {
        format!(
            "'{}' is not a whole number (allowed: {MIN} to {MAX})",
            crate::text::excerpt(s, 40)
        )
    })?;
    if v < MIN || v > MAX {
        return Err(format!(
            "{v} is out of range: allowed {MIN} to {MAX} (see docs/limits.md)"
        ));
    }
    usize::try_from(v).map_err(|_| format!("{v} does not fit this machine's word size"))
}

/// Read a file of at most [`FILE_BYTES_MAX`] bytes as text.
pub fn read_text(path: &std::path::Path) -> std::io::Result<String> {
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "is a directory, not a file",
        ));
    }
    if meta.len() > FILE_BYTES_MAX {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "{} bytes: larger than foldsynth reads ({FILE_BYTES_MAX} bytes)",
                meta.len()
            ),
        ));
    }
    std::fs::read_to_string(path)
}

/// Deepest nesting of parentheses in an expression or a vertex notation: recursive
/// descent and evaluation need stack in proportion.
pub const EXPR_DEPTH_MAX: usize = 64;
/// Most operators and parentheses in one expression or vertex notation: the expression
/// tree (evaluated and dropped recursively) stays shallow.
pub const EXPR_OPS_MAX: usize = 1000;

/// Check the size of an expression before parsing it: `Err((character position,
/// message))` at the first excess.
pub fn check_expression(text: &str) -> Result<(), (usize, String)> {
    let (mut depth, mut ops) = (0usize, 0usize);
    for (i, c) in text.chars().enumerate() {
        match c {
            '(' => {
                depth += 1;
                ops += 1;
                if depth > EXPR_DEPTH_MAX {
                    return Err((
                        i,
                        format!("parentheses nested deeper than {EXPR_DEPTH_MAX} levels"),
                    ));
                }
            }
            ')' => depth = depth.saturating_sub(1),
            '+' | '-' | '*' | '/' | '^' => ops += 1,
            _ => {}
        }
        if ops > EXPR_OPS_MAX {
            return Err((
                i,
                format!("more than {EXPR_OPS_MAX} operators and parentheses"),
            ));
        }
    }
    Ok(())
}
