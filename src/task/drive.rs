//! Driving-angle expressions of the initial graph's driven creases (`"t"`, `"-t"`, `"t/1.2"`).

use std::fmt;

use crate::kinematics::{DriveExpr, Scalar};

/// A driving-angle expression in the driving parameter `t`, parsed on load by the
/// kinematics module's [`DriveExpr`], with the text as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    text: String,
    expr: DriveExpr,
}

impl Drive {
    /// Parse `text`. Errors say what is allowed.
    pub fn parse(text: &str) -> Result<Drive, String> {
        let expr = DriveExpr::parse(text).map_err(|e| {
            format!(
                "\"{text}\" is not a driving-angle expression: {}",
                e.message
            )
        })?;
        if !uses_t(&expr) {
            return Err(format!(
                "\"{text}\" does not use the driving parameter `t`; a driven crease moves with t (e.g. \"t\", \"-t\", \"t/1.2\")"
            ));
        }
        Ok(Drive {
            text: text.trim().to_owned(),
            expr,
        })
    }

    /// The expression as written.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// The parsed expression.
    pub fn expr(&self) -> &DriveExpr {
        &self.expr
    }

    /// The driving angle at parameter `t`, in any [`Scalar`].
    pub fn eval<S: Scalar>(&self, t: &S) -> S {
        self.expr.eval(t)
    }
}

fn uses_t(e: &DriveExpr) -> bool {
    match e {
        DriveExpr::Num(_) => false,
        DriveExpr::T => true,
        DriveExpr::Neg(a) => uses_t(a),
        DriveExpr::Add(a, b)
        | DriveExpr::Sub(a, b)
        | DriveExpr::Mul(a, b)
        | DriveExpr::Div(a, b) => uses_t(a) || uses_t(b),
    }
}

impl fmt::Display for Drive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}
