//! The `[constraints]` table: design constraints beyond the thesis's (`kawasaki = true`:
//! every internal vertex of even degree folds flat).

use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawConstraints {
    #[serde(default)]
    kawasaki: bool,
}

/// Whether Kawasaki's condition is imposed (off when the table or the key is absent).
pub(crate) fn kawasaki(raw: Option<&RawConstraints>) -> bool {
    raw.is_some_and(|c| c.kawasaki)
}
