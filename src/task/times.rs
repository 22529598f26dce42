//! Values of the driving parameter in a task file: one value (`t = "pi/2"`) or a range
//! with a number of samples (`t = "0 .. pi/2"`, `samples = 11`), within the motion.

use super::{Ctx, Motion, Number, TaskError};

/// The motion's range `[lo, hi]` (`[0, t_max]`, or `[t_max, 0]` when `t_max < 0`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Span {
    lo: f64,
    hi: f64,
}

/// Slack at the motion's ends: a value written as `"pi/2"` for `t_max = pi/2` may differ
/// in its last bits when computed another way.
const SLACK: f64 = 1e-12;

impl Span {
    pub(crate) fn of(motion: Motion) -> Span {
        if motion.t_max > 0.0 {
            Span {
                lo: 0.0,
                hi: motion.t_max,
            }
        } else {
            Span {
                lo: motion.t_max,
                hi: 0.0,
            }
        }
    }

    fn contains(&self, t: f64) -> bool {
        t >= self.lo - SLACK && t <= self.hi + SLACK
    }

    fn shown(&self) -> String {
        format!(
            "[{}, {}]",
            crate::text::num(self.lo),
            crate::text::num(self.hi)
        )
    }
}

/// Sample `k` of `n` of the range `a .. b`: `a` for k = 0, `b` for k = n − 1, and
/// `a + (k·(b − a))/(n − 1)` between (so `"0 .. pi/2"` with 11 samples gives the bits of
/// `k*pi/20`).
pub fn sample(a: f64, b: f64, n: usize, k: usize) -> f64 {
    if k == 0 {
        a
    } else if k + 1 == n {
        b
    } else {
        a + (k as f64 * (b - a)) / (n - 1) as f64
    }
}

/// The two ends of `"a .. b"`, or `None` when `n` is not a range.
fn range_ends(n: &Number) -> Option<(&str, &str)> {
    match n {
        Number::Expr(s) => s.split_once(".."),
        Number::Literal(_) => None,
    }
}

/// One value of `t` within the motion (`field` names it); a range is refused.
pub(crate) fn one(cx: &Ctx<'_>, field: &str, t: &Number, span: Span) -> Result<f64, TaskError> {
    if range_ends(t).is_some() {
        return Err(cx.err(
            field,
            format!("{t} is a range: this t is one value of the driving parameter"),
        ));
    }
    let v = cx.num(field, t)?;
    if !span.contains(v) {
        return Err(cx.err(
            field,
            format!(
                "{} is outside the motion range {}",
                crate::text::num(v),
                span.shown()
            ),
        ));
    }
    Ok(v)
}

/// The values of `t` an entry names: one value, or a range's samples. `entry` is the
/// entry's TOML path (`objective.targets[0]`); its fields are `t` and `samples`.
pub(crate) fn values(
    cx: &Ctx<'_>,
    entry: &str,
    t: &Number,
    samples: Option<i64>,
    span: Span,
) -> Result<Vec<f64>, TaskError> {
    let field = format!("{entry}.t");
    let max = crate::limits::PATH_SAMPLES_MAX;
    let Some((a, b)) = range_ends(t) else {
        if samples.is_some() {
            return Err(cx.err(
                format!("{entry}.samples"),
                format!(
                    "samples is given but t = {t} is one value: write t as a range \"a .. b\" to sample it, or drop samples"
                ),
            ));
        }
        return Ok(vec![one(cx, &field, t, span)?]);
    };
    if b.starts_with('.') || b.contains("..") {
        return Err(cx.err(
            &field,
            format!("{t}: write a range as \"a .. b\", with one \"..\" between two values"),
        ));
    }
    let end = |s: &str, which: &str| -> Result<f64, TaskError> {
        cx.num(&field, &Number::Expr(s.to_owned()))
            .map_err(|e| cx.err(&field, format!("the range's {which}: {}", e.message)))
    };
    let (a, b) = (end(a, "start")?, end(b, "end")?);
    if a > b {
        return Err(cx.err(
            &field,
            format!("{t} runs backwards: write the range from its smaller end to its larger"),
        ));
    }
    if a == b {
        return Err(cx.err(
            &field,
            format!("{t} is empty (both ends are equal): give that one value of t instead"),
        ));
    }
    if !span.contains(a) || !span.contains(b) {
        return Err(cx.err(
            &field,
            format!(
                "the range [{}, {}] reaches outside the motion range {}",
                crate::text::num(a),
                crate::text::num(b),
                span.shown()
            ),
        ));
    }
    let Some(n) = samples else {
        return Err(cx.err(
            format!("{entry}.samples"),
            format!("missing: a range of t needs samples = N (2 ≤ N ≤ {max}, both ends included)"),
        ));
    };
    if !(2..=max as i64).contains(&n) {
        return Err(cx.err(
            format!("{entry}.samples"),
            format!("{n} is not allowed: 2 ≤ samples ≤ {max} (both ends of the range are samples)"),
        ));
    }
    let n = n as usize;
    Ok((0..n).map(|k| sample(a, b, n, k)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_samples_of_a_quarter_turn_are_the_hand_written_values() {
        for k in 0..11 {
            let want = crate::task::number::Expr::parse(&format!("{k}*pi/20"))
                .unwrap()
                .eval();
            assert_eq!(sample(0.0, PI / 2.0, 11, k).to_bits(), want.to_bits());
        }
        assert_eq!(sample(-1.0, 2.0, 4, 3), 2.0);
        assert_eq!(sample(-1.0, 2.0, 4, 1), 0.0);
    }
}
