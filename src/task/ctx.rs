//! The [`TaskError`]s of one task file: the builder that names the file in every message,
//! the checked reading of numbers and points, and TOML syntax errors.

use super::{Number, TaskError};

/// Builds errors for one file.
pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
}

impl Ctx<'_> {
    pub(crate) fn err(&self, field: impl Into<String>, message: impl Into<String>) -> TaskError {
        TaskError {
            file: self.file.to_owned(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// A finite number within ±[`crate::limits::COORD_MAX`], evaluated.
    pub(crate) fn num(&self, field: &str, n: &Number) -> Result<f64, TaskError> {
        let v = n.value().map_err(|m| self.err(field, m))?;
        if !v.is_finite() {
            return Err(self.err(field, format!("{n} is not a finite number")));
        }
        if v.abs() > crate::limits::COORD_MAX {
            return Err(self.err(
                field,
                format!(
                    "{} is out of range: numbers in a task file lie within ±{} (beyond that, squared distances overflow)",
                    crate::text::num(v),
                    crate::text::num(crate::limits::COORD_MAX)
                ),
            ));
        }
        Ok(v)
    }

    /// Exactly `N` numbers (a point), each checked by [`Ctx::num`].
    pub(crate) fn point<const N: usize>(
        &self,
        field: &str,
        p: &[Number],
    ) -> Result<[f64; N], TaskError> {
        if p.len() != N {
            return Err(self.err(
                field,
                format!(
                    "{} values given; exactly {N} are needed ({})",
                    p.len(),
                    if N == 2 { "x, y" } else { "x, y, z" }
                ),
            ));
        }
        let mut out = [0.0; N];
        for (i, n) in p.iter().enumerate() {
            out[i] = self.num(&format!("{field}[{i}]"), n)?;
        }
        Ok(out)
    }
}

/// A TOML syntax or schema error, located by line and column, with the offending key when
/// the span covers one.
pub(crate) fn syntax_error(file: &str, text: &str, e: &toml::de::Error) -> TaskError {
    let (field, loc) = match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            let snippet = text.get(span.clone()).unwrap_or("").trim();
            let field = if !snippet.is_empty() && snippet.len() <= 40 && !snippet.contains('\n') {
                format!("`{snippet}`")
            } else {
                "(syntax)".to_owned()
            };
            (field, format!("line {line}, column {col}: "))
        }
        None => ("(syntax)".to_owned(), String::new()),
    };
    TaskError {
        file: file.to_owned(),
        field,
        message: format!("{loc}{}", crate::text::excerpt(e.message().trim(), 300)),
    }
}
