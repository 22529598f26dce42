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
        self.finite(field, n, v, "")
    }

    /// `v` (the value of `n`) checked like [`Ctx::num`]'s; `at` prefixes the message.
    fn finite(&self, field: &str, n: &Number, v: f64, at: &str) -> Result<f64, TaskError> {
        if !v.is_finite() {
            return Err(self.err(field, format!("{at}{n} is not a finite number")));
        }
        if v.abs() > crate::limits::COORD_MAX {
            return Err(self.err(
                field,
                format!(
                    "{at}{} is out of range: numbers in a task file lie within ±{} (beyond that, squared distances overflow)",
                    crate::text::num(v),
                    crate::text::num(crate::limits::COORD_MAX)
                ),
            ));
        }
        Ok(v)
    }

    /// A number that may use `t`, at each of `ts`, each checked like [`Ctx::num`]'s (the
    /// message names the `t` where a value fails).
    pub(crate) fn num_at(
        &self,
        field: &str,
        n: &Number,
        ts: &[f64],
    ) -> Result<Vec<f64>, TaskError> {
        let e = n.parse_with_t().map_err(|m| self.err(field, m))?;
        ts.iter()
            .map(|&t| {
                let at = format!("at t = {}: ", crate::text::num(t));
                self.finite(field, n, e.eval_at(t), &at)
            })
            .collect()
    }

    /// A point whose coordinates may use `t`, at each of `ts`.
    pub(crate) fn point_at(
        &self,
        field: &str,
        p: &[Number],
        ts: &[f64],
    ) -> Result<Vec<[f64; 3]>, TaskError> {
        self.count::<3>(field, p)?;
        let mut out = vec![[0.0; 3]; ts.len()];
        for (i, n) in p.iter().enumerate() {
            let values = self.num_at(&format!("{field}[{i}]"), n, ts)?;
            for (o, v) in out.iter_mut().zip(values) {
                o[i] = v;
            }
        }
        Ok(out)
    }

    /// A number > 0.
    pub(crate) fn positive(&self, field: &str, n: &Number) -> Result<f64, TaskError> {
        let v = self.num(field, n)?;
        if v <= 0.0 {
            return Err(self.err(
                field,
                format!("{} is not allowed: it must be > 0", crate::text::num(v)),
            ));
        }
        Ok(v)
    }

    /// A direction: three numbers, not all zero, made unit length.
    pub(crate) fn direction(&self, field: &str, p: &[Number]) -> Result<[f64; 3], TaskError> {
        let v = self.point::<3>(field, p)?;
        crate::scene::shapes::unit(v).ok_or_else(|| {
            self.err(
                field,
                format!(
                    "{v:?} has (almost) zero length: a direction needs a nonzero vector (it is normalized)"
                ),
            )
        })
    }

    /// A number of entries of a list within [`crate::limits::TERMS_MAX`].
    pub(crate) fn entries(&self, field: &str, n: usize) -> Result<(), TaskError> {
        let max = crate::limits::TERMS_MAX;
        if n > max {
            return Err(self.err(
                field,
                format!("{n} entries: a task lists at most {max} of each kind"),
            ));
        }
        Ok(())
    }

    /// Exactly `N` values.
    fn count<const N: usize>(&self, field: &str, p: &[Number]) -> Result<(), TaskError> {
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
        Ok(())
    }

    /// Exactly `N` numbers (a point), each checked by [`Ctx::num`].
    pub(crate) fn point<const N: usize>(
        &self,
        field: &str,
        p: &[Number],
    ) -> Result<[f64; N], TaskError> {
        self.count::<N>(field, p)?;
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
