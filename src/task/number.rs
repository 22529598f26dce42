//! Numbers in task files: a float, an integer, or a short expression such as `"pi/18"`,
//! `"17*pi/18"` or `"1 + 2*cos(pi/20)"`.
//!
//! Angles like π/18 are exact in the thesis; writing them as expressions keeps the task
//! files readable and free of truncated decimals. Where a task allows it (a target's point,
//! a line's or plane's point), an expression may use the driving parameter `t`
//! ([`Expr::parse_with_t`], [`Number::value_at`]); everywhere else `t` is an unknown name.
//! (Driving angles of G0's creases are parsed by the kinematics module's `DriveExpr`.)

use std::fmt;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize, Serializer};

/// A number as written in a task file: kept as text for messages, evaluated on validation.
#[derive(Clone, Debug, PartialEq)]
pub enum Number {
    /// A literal float or integer.
    Literal(f64),
    /// An expression in numbers, `pi`, `+ - * / ^`, parentheses, `sin`, `cos`, `sqrt`
    /// (and `t` where the field allows it).
    Expr(String),
}

impl Number {
    /// The value of a constant; `Err` names what is wrong with the expression (`t` is an
    /// unknown name here).
    pub fn value(&self) -> Result<f64, String> {
        match self {
            Number::Literal(v) => Ok(*v),
            Number::Expr(s) => Ok(Expr::parse(s)?.eval()),
        }
    }

    /// The value at `t` of a number that may use `t`; `Err` names what is wrong with the
    /// expression.
    pub fn value_at(&self, t: f64) -> Result<f64, String> {
        Ok(self.parse_with_t()?.eval_at(t))
    }

    /// The number as an expression that may use `t` (a literal is a constant), parsed once
    /// to be evaluated at many `t`.
    pub fn parse_with_t(&self) -> Result<Expr, String> {
        match self {
            Number::Literal(v) => Ok(Expr::Const(*v)),
            Number::Expr(s) => Expr::parse_with_t(s),
        }
    }
}

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Number::Literal(v) => f.write_str(&crate::text::num(*v)),
            Number::Expr(s) => write!(f, "\"{}\"", crate::text::excerpt(s, 60)),
        }
    }
}

impl Serialize for Number {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Number::Literal(v) => s.serialize_f64(*v),
            Number::Expr(e) => s.serialize_str(e),
        }
    }
}

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number or a string expression such as \"pi/18\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Number, E> {
                Ok(Number::Literal(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number::Literal(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number::Literal(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Number, E> {
                Ok(Number::Expr(v.to_owned()))
            }
        }
        d.deserialize_any(V)
    }
}

/// A parsed arithmetic expression: constants, and the variable `t` when parsed with
/// [`Expr::parse_with_t`].
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A constant.
    Const(f64),
    /// The driving parameter `t`.
    Var,
    /// Negation.
    Neg(Box<Expr>),
    /// A binary operation: one of `+ - * / ^`.
    Bin(char, Box<Expr>, Box<Expr>),
    /// A function call: `sin`, `cos` or `sqrt`.
    Call(&'static str, Box<Expr>),
}

impl Expr {
    /// Parse the constant expression `s` (`t` is an unknown name).
    pub fn parse(s: &str) -> Result<Expr, String> {
        Expr::parse_in(s, false)
    }

    /// Parse `s`, which may use the driving parameter `t`.
    pub fn parse_with_t(s: &str) -> Result<Expr, String> {
        Expr::parse_in(s, true)
    }

    fn parse_in(s: &str, with_t: bool) -> Result<Expr, String> {
        crate::limits::check_expression(s).map_err(|(at, m)| {
            format!(
                "{m} (at character {} of \"{}\")",
                at + 1,
                crate::text::excerpt(s, 60)
            )
        })?;
        let mut p = Parser {
            src: s,
            pos: 0,
            with_t,
        };
        p.skip_ws();
        if p.pos == s.len() {
            return Err("empty expression".into());
        }
        let e = p.sum()?;
        p.skip_ws();
        if p.pos != s.len() {
            return Err(format!(
                "unexpected `{}` at character {} of \"{}\"",
                crate::text::excerpt(&s[p.pos..], 40),
                p.pos + 1,
                crate::text::excerpt(s, 60)
            ));
        }
        Ok(e)
    }

    /// The value of a constant expression (one that uses `t` evaluates to NaN: parse it
    /// with [`Expr::parse_with_t`] and use [`Expr::eval_at`]).
    pub fn eval(&self) -> f64 {
        self.eval_at(f64::NAN)
    }

    /// The value at `t`: the same floating-point operations in the same order as the
    /// expression with `t`'s value written in (so `"2*cos(t)"` at `t = pi/20` gives the
    /// bits of `"2*cos(pi/20)"`).
    pub fn eval_at(&self, t: f64) -> f64 {
        match self {
            Expr::Const(c) => *c,
            Expr::Var => t,
            Expr::Neg(a) => -a.eval_at(t),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.eval_at(t), b.eval_at(t));
                match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    '/' => a / b,
                    _ => a.powf(b),
                }
            }
            Expr::Call(f, a) => {
                let a = a.eval_at(t);
                match *f {
                    "sin" => a.sin(),
                    "cos" => a.cos(),
                    _ => a.sqrt(),
                }
            }
        }
    }
}

struct Parser<'a> {
    src: &'a str,
    pos: usize,
    /// Whether `t` is a name.
    with_t: bool,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.src[self.pos..].starts_with(char::is_whitespace) {
            self.pos += self.src[self.pos..]
                .chars()
                .next()
                .map_or(1, char::len_utf8);
        }
    }
    fn peek(&mut self) -> Option<char> {
        self.skip_ws();
        self.src[self.pos..].chars().next()
    }
    fn sum(&mut self) -> Result<Expr, String> {
        let mut e = self.product()?;
        while let Some(op @ ('+' | '-')) = self.peek() {
            self.pos += 1;
            e = Expr::Bin(op, Box::new(e), Box::new(self.product()?));
        }
        Ok(e)
    }
    fn product(&mut self) -> Result<Expr, String> {
        let mut e = self.unary()?;
        while let Some(op @ ('*' | '/')) = self.peek() {
            self.pos += 1;
            e = Expr::Bin(op, Box::new(e), Box::new(self.unary()?));
        }
        Ok(e)
    }
    fn unary(&mut self) -> Result<Expr, String> {
        match self.peek() {
            Some('-') => {
                self.pos += 1;
                Ok(Expr::Neg(Box::new(self.unary()?)))
            }
            Some('+') => {
                self.pos += 1;
                self.unary()
            }
            _ => {
                let base = self.atom()?;
                if self.peek() == Some('^') {
                    self.pos += 1;
                    return Ok(Expr::Bin('^', Box::new(base), Box::new(self.unary()?)));
                }
                Ok(base)
            }
        }
    }
    fn atom(&mut self) -> Result<Expr, String> {
        let start = self.pos;
        match self.peek() {
            Some('(') => {
                self.pos += 1;
                let e = self.sum()?;
                if self.peek() != Some(')') {
                    return Err(format!("missing `)` in \"{}\"", self.src));
                }
                self.pos += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => {
                let rest = &self.src[self.pos..];
                let mut end = rest
                    .find(|c: char| !(c.is_ascii_digit() || c == '.'))
                    .unwrap_or(rest.len());
                // Exponent notation: 1e-5, 2.5E3.
                if rest[end..].starts_with(['e', 'E']) {
                    let exp = &rest[end + 1..];
                    let sign = usize::from(exp.starts_with(['+', '-']));
                    let digits = exp[sign..]
                        .find(|c: char| !c.is_ascii_digit())
                        .unwrap_or(exp.len() - sign);
                    if digits > 0 {
                        end += 1 + sign + digits;
                    }
                }
                let text = &rest[..end];
                self.pos += end;
                text.parse::<f64>()
                    .map(Expr::Const)
                    .map_err(|_| format!("`{text}` is not a number"))
            }
            Some(c) if c.is_ascii_alphabetic() => {
                let rest = &self.src[self.pos..];
                let end = rest
                    .find(|c: char| !c.is_ascii_alphanumeric() && c != '_')
                    .unwrap_or(rest.len());
                let word = &rest[..end];
                self.pos += end;
                match word {
                    "pi" | "PI" | "Pi" => Ok(Expr::Const(std::f64::consts::PI)),
                    "t" if self.with_t => Ok(Expr::Var),
                    "sin" | "cos" | "sqrt" => {
                        let name: &'static str = match word {
                            "sin" => "sin",
                            "cos" => "cos",
                            _ => "sqrt",
                        };
                        if self.peek() != Some('(') {
                            return Err(format!("`{name}` needs parentheses: {name}(...)"));
                        }
                        Ok(Expr::Call(name, Box::new(self.atom()?)))
                    }
                    _ if self.with_t => Err(format!(
                        "unknown name `{}` (allowed: numbers, pi, t, sin, cos, sqrt, + - * / ^, parentheses)",
                        crate::text::excerpt(word, 40)
                    )),
                    _ => Err(format!(
                        "unknown name `{}` (allowed: numbers, pi, sin, cos, sqrt, + - * / ^, parentheses; t only in a target's point)",
                        crate::text::excerpt(word, 40)
                    )),
                }
            }
            Some(c) => Err(format!(
                "unexpected `{c}` at character {} of \"{}\"",
                start + 1,
                self.src
            )),
            None => Err(format!("expression \"{}\" ends too early", self.src)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn evaluates_thesis_constants() {
        let v = |s: &str| Expr::parse(s).unwrap().eval();
        assert_eq!(v("pi/18"), PI / 18.0);
        assert_eq!(v("17*pi/18"), 17.0 * PI / 18.0);
        assert_eq!(v("1 + 2*cos(pi/20)"), 1.0 + 2.0 * (PI / 20.0).cos());
        assert_eq!(v("-2^2"), -4.0);
        assert_eq!(v("1e-5"), 1e-5);
        assert_eq!(v("2.5E+1"), 25.0);
        assert_eq!(v("sqrt(4)"), 2.0);
    }

    #[test]
    fn t_evaluates_like_its_value_written_in() {
        // The robotic arm's trajectory, as a path and as the points written out.
        for k in 0..=10 {
            let t = (f64::from(k) * (PI / 2.0)) / 10.0;
            let written = format!("1 + 2*cos({k}*pi/20)");
            let want = Expr::parse(&written).unwrap().eval();
            let got = Expr::parse_with_t("1 + 2*cos(t)").unwrap().eval_at(t);
            assert_eq!(got.to_bits(), want.to_bits(), "k = {k}");
        }
        assert_eq!(Number::Literal(2.5).value_at(9.0), Ok(2.5));
        assert_eq!(Number::Expr("t^2 - t".into()).value_at(3.0), Ok(6.0));
        let e = Number::Expr("2*s".into()).value_at(1.0).unwrap_err();
        assert!(
            e.contains("unknown name `s`") && e.contains("pi, t,"),
            "{e}"
        );
        let e = Number::Expr("t".into()).value().unwrap_err();
        assert!(e.contains("unknown name `t`"), "{e}");
    }

    #[test]
    fn rejects_garbage() {
        for s in ["", "pi/", "(1", "2 3", "foo", "t", "sin 1", "1..2"] {
            assert!(Expr::parse(s).is_err(), "{s}");
        }
    }
}
