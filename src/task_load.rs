//! Loading a task file: the task's own checks ([`crate::task`], table by table) and the
//! checks of G0 that need the grammar's graph ([`crate::grammar`]): every facet's boundary
//! is one chain, and a mirror-symmetric G0 orders its creases like its mirror image. It
//! sits above both because the grammar reads the task.

use std::path::Path;
use std::sync::Arc;

use crate::grammar::CreaseGraph;
use crate::task::parse::Draft;
use crate::task::{Ctx, InitialGraph, Task, TaskError, mirror_map};

impl Task {
    /// Load and validate a task file.
    pub fn load(path: impl AsRef<Path>) -> Result<Task, TaskError> {
        let path = path.as_ref();
        let label = path.display().to_string();
        let text = crate::limits::read_text(path).map_err(|e| TaskError {
            file: label.clone(),
            field: "(file)".into(),
            message: format!("cannot read the task file: {e}"),
        })?;
        let dir = path.parent().unwrap_or(Path::new(""));
        let mut task = Task::from_toml_str_in(&text, &label, dir)?;
        task.source = Some(path.to_owned());
        if task.name.is_empty() {
            // The file stem, cut to the limit (the output directory is made safe from it).
            task.name = path
                .file_stem()
                .map(|s| {
                    s.to_string_lossy()
                        .chars()
                        .take(crate::limits::NAME_MAX)
                        .collect()
                })
                .unwrap_or_default();
        }
        Ok(task)
    }

    /// Parse and validate task text; `file` labels the messages. Mesh files named by a
    /// relative path are read from the current directory.
    pub fn from_toml_str(text: &str, file: &str) -> Result<Task, TaskError> {
        Task::from_toml_str_in(text, file, Path::new(""))
    }

    /// Parse and validate task text; `file` labels the messages, mesh files named by a
    /// relative path are read from `dir` (the task file's folder).
    pub fn from_toml_str_in(text: &str, file: &str, dir: &Path) -> Result<Task, TaskError> {
        let mut draft = Draft::parse(text, file)?;
        check_facets(&draft.cx, &draft.initial)?;
        draft.actuate()?;
        if draft.symmetry.mirror_xz {
            draft.initial.mirror = Some(mirror_map(&draft.cx, &draft.initial, draft.tol)?);
            check_mirror_order(&draft.cx, &draft.initial)?;
        }
        draft.finish(dir)
    }
}

/// Every facet's boundary must be one chain (closed, or open at the paper's edge).
fn check_facets(cx: &Ctx<'_>, g: &InitialGraph) -> Result<(), TaskError> {
    let graph = CreaseGraph::from_initial(Arc::new(g.clone()));
    if let Err(e) = graph.facet_boundaries() {
        return Err(cx.err(
            "initial_graph.creases",
            format!("inconsistent facet labels: {e}"),
        ));
    }
    Ok(())
}

/// G0 with its mirror map must be its own mirror image as the grammar's graphs compare.
fn check_mirror_order(cx: &Ctx<'_>, g: &InitialGraph) -> Result<(), TaskError> {
    let graph = CreaseGraph::from_initial(Arc::new(g.clone()));
    if g.mirror.is_some() && graph.mirror_code().as_ref() != Some(&graph.canonical_code()) {
        return Err(cx.err(
            "symmetry.mirror_xz",
            "the mirror image of G0 orders its creases differently from G0 (check the facet labels of creases on the x-axis)",
        ));
    }
    Ok(())
}
