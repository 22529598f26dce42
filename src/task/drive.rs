//! Driving-angle expressions of the initial graph's driven creases (`"t"`, `"-t"`, `"t/1.2"`).

use std::fmt;

use serde::{Deserialize, Serialize};

use super::number::Expr;

/// A driving-angle expression in the driving parameter `t`, checked on load.
///
/// The text is kept as written: the kinematics module's expression type evaluates it (for
/// `f64` and for symbols); this newtype only guarantees it parses.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Drive(String);

impl Drive {
    /// Check `text` and wrap it. Errors say what is allowed.
    pub fn parse(text: &str) -> Result<Drive, String> {
        let e = Expr::parse(text, true)?;
        if !e.uses_t() {
            return Err(format!(
                "\"{text}\" does not use the driving parameter `t`; a driven crease must move with t (e.g. \"t\", \"-t\", \"t/1.2\")"
            ));
        }
        Ok(Drive(text.trim().to_owned()))
    }

    /// The expression as written.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// The driving angle at parameter `t` (a plain-f64 convenience for checks and tests).
    pub fn eval(&self, t: f64) -> f64 {
        // Parsed once on construction, so this cannot fail.
        Expr::parse(&self.0, true).map_or(f64::NAN, |e| e.eval(t))
    }
}

impl fmt::Display for Drive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
