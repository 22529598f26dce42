//! The thesis's vertex notation (Eq. 24) and driving-angle expressions.
//!
//! `v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))`: the mode, then three units;
//! a unit is `(α)` for a single sector or `((α1, …, αm), (ρ1, …, ρm-1))`. Sectors are in
//! degrees; driving angles are small expressions in `t` (radians): numbers, `t`, `pi`,
//! `+ - * /`, unary minus and parentheses. The thesis's transposition mark `^T` after a
//! tuple is accepted and ignored. Errors point at the offending character.

use super::{Scalar, Unit};
use std::fmt;

/// A parse or validation error with the position of the offending character.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NotationError {
    /// The text that was parsed.
    pub input: String,
    /// Byte offset of the offending character.
    pub pos: usize,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl fmt::Display for NotationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let col = self.input[..self.input.floor_char_boundary(self.pos)]
            .chars()
            .count();
        // A long input is shown as a window around the error, not echoed whole.
        let (shown, at) = crate::text::window(&self.input, col, 80);
        write!(
            f,
            "{} (at column {})\n  {}\n  {}^",
            self.message,
            col + 1,
            shown,
            " ".repeat(at)
        )
    }
}

impl std::error::Error for NotationError {}

/// A driving-angle expression in `t`.
#[derive(Clone, Debug, PartialEq)]
pub enum DriveExpr {
    /// A number.
    Num(f64),
    /// The driving parameter `t`.
    T,
    /// `-e`
    Neg(Box<DriveExpr>),
    /// `a + b`
    Add(Box<DriveExpr>, Box<DriveExpr>),
    /// `a - b`
    Sub(Box<DriveExpr>, Box<DriveExpr>),
    /// `a * b`
    Mul(Box<DriveExpr>, Box<DriveExpr>),
    /// `a / b`
    Div(Box<DriveExpr>, Box<DriveExpr>),
}

impl DriveExpr {
    /// Parse a whole string as an expression in `t`.
    pub fn parse(text: &str) -> Result<DriveExpr, NotationError> {
        size_check(text)?;
        let mut p = Parser::new(text);
        let e = p.expr()?;
        p.skip_ws();
        if p.pos < p.src.len() {
            return Err(p.error("unexpected character after the expression"));
        }
        Ok(e)
    }

    /// Evaluate at `t`, in any [`Scalar`].
    pub fn eval<S: Scalar>(&self, t: &S) -> S {
        match self {
            DriveExpr::Num(v) => S::from_f64(*v),
            DriveExpr::T => t.clone(),
            DriveExpr::Neg(a) => -a.eval(t),
            DriveExpr::Add(a, b) => a.eval(t) + b.eval(t),
            DriveExpr::Sub(a, b) => a.eval(t) - b.eval(t),
            DriveExpr::Mul(a, b) => a.eval(t) * b.eval(t),
            DriveExpr::Div(a, b) => a.eval(t) / b.eval(t),
        }
    }
}

impl fmt::Display for DriveExpr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DriveExpr::Num(v) => write!(f, "{v}"),
            DriveExpr::T => write!(f, "t"),
            DriveExpr::Neg(a) => write!(f, "-{}", Paren(a)),
            DriveExpr::Add(a, b) => write!(f, "{a}+{b}"),
            DriveExpr::Sub(a, b) => write!(f, "{a}-{}", Paren(b)),
            DriveExpr::Mul(a, b) => write!(f, "{}*{}", Paren(a), Paren(b)),
            DriveExpr::Div(a, b) => write!(f, "{}/{}", Paren(a), Paren(b)),
        }
    }
}

/// Prints an operand, parenthesized unless it is atomic.
struct Paren<'a>(&'a DriveExpr);

impl fmt::Display for Paren<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            DriveExpr::Num(_) | DriveExpr::T => write!(f, "{}", self.0),
            e => write!(f, "({e})"),
        }
    }
}

/// The rigid body mode of a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// M↑: internal angles turned counter-clockwise (`M = +1`).
    Up,
    /// M↓: internal angles turned clockwise (`M = -1`).
    Down,
}

impl Mode {
    /// `+1` for up, `-1` for down.
    pub fn sign(self) -> f64 {
        match self {
            Mode::Up => 1.0,
            Mode::Down => -1.0,
        }
    }

    /// Parse `up`/`down` (also `↑`, `↓`, `+1`, `-1`).
    pub fn parse(text: &str) -> Option<Mode> {
        match text.trim() {
            "up" | "Up" | "UP" | "↑" | "M↑" | "+1" | "1" => Some(Mode::Up),
            "down" | "Down" | "DOWN" | "↓" | "M↓" | "-1" => Some(Mode::Down),
            _ => None,
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mode::Up => "up",
            Mode::Down => "down",
        })
    }
}

/// One unit as written: sectors in degrees and driving-angle expressions.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitSpec {
    /// Sector angles in degrees.
    pub sectors_deg: Vec<f64>,
    /// Driving angles between consecutive sectors.
    pub driving: Vec<DriveExpr>,
}

/// A vertex in the notation of Eq. 24.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexSpec {
    /// The rigid body mode.
    pub mode: Mode,
    /// The three units u1, u2, u3.
    pub units: [UnitSpec; 3],
}

impl VertexSpec {
    /// Parse and validate a vertex: every sector in (0°, 180°), a unit of m sectors has
    /// m − 1 driving angles, at least 4 sectors in all.
    pub fn parse(text: &str) -> Result<VertexSpec, NotationError> {
        size_check(text)?;
        let mut p = Parser::new(text);
        let spec = p.vertex()?;
        p.skip_ws();
        if p.pos < p.src.len() {
            return Err(p.error("unexpected text after the vertex"));
        }
        Ok(spec)
    }

    /// The vertex degree (number of sectors).
    pub fn degree(&self) -> usize {
        self.units.iter().map(|u| u.sectors_deg.len()).sum()
    }

    /// All sector angles in radians, counter-clockwise from the first sector of u1.
    pub fn sectors_rad(&self) -> Vec<f64> {
        self.units
            .iter()
            .flat_map(|u| u.sectors_deg.iter().map(|a| a.to_radians()))
            .collect()
    }

    /// The units at parameter `t` with the given sector angles (radians, in the order of
    /// [`VertexSpec::sectors_rad`]); sectors may be symbolic.
    pub fn units_with<S: Scalar>(&self, sectors: &[S], t: &S) -> [Unit<S>; 3] {
        let mut k = 0;
        let mut build = |u: &UnitSpec| {
            let s: Vec<S> = sectors[k..k + u.sectors_deg.len()].to_vec();
            k += u.sectors_deg.len();
            Unit::new(s, u.driving.iter().map(|d| d.eval(t)).collect())
        };
        [
            build(&self.units[0]),
            build(&self.units[1]),
            build(&self.units[2]),
        ]
    }

    /// The numeric units at parameter `t`.
    pub fn units_at(&self, t: f64) -> [Unit<f64>; 3] {
        self.units_with(&self.sectors_rad(), &t)
    }
}

impl fmt::Display for VertexSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "v({}", self.mode)?;
        for u in &self.units {
            let s: Vec<String> = u.sectors_deg.iter().map(|a| format!("{a}")).collect();
            if u.driving.is_empty() {
                write!(f, ", ({})", s.join(","))?;
            } else {
                let d: Vec<String> = u.driving.iter().map(|e| e.to_string()).collect();
                write!(f, ", (({}),({}))", s.join(","), d.join(","))?;
            }
        }
        write!(f, ")")
    }
}

/// Refuse inputs too deeply nested or too long for the recursive parser and evaluator.
fn size_check(text: &str) -> Result<(), NotationError> {
    crate::limits::check_expression(text).map_err(|(at, message)| NotationError {
        input: text.to_string(),
        pos: text.char_indices().nth(at).map_or(text.len(), |(b, _)| b),
        message,
    })
}

/// A small recursive-descent parser over the notation.
struct Parser<'a> {
    src: &'a str,
    pos: usize,
}

impl<'a> Parser<'a> {
    fn new(src: &'a str) -> Self {
        Parser { src, pos: 0 }
    }

    fn error(&self, message: impl Into<String>) -> NotationError {
        NotationError {
            input: self.src.to_string(),
            pos: self.pos,
            message: message.into(),
        }
    }

    fn error_at(&self, pos: usize, message: impl Into<String>) -> NotationError {
        NotationError {
            input: self.src.to_string(),
            pos,
            message: message.into(),
        }
    }

    fn peek(&self) -> Option<char> {
        self.src[self.pos..].chars().next()
    }

    fn skip_ws(&mut self) {
        while let Some(c) = self.peek() {
            if c.is_whitespace() {
                self.pos += c.len_utf8();
            } else {
                break;
            }
        }
    }

    /// Skip whitespace and return the next character without consuming it.
    fn next_token(&mut self) -> Option<char> {
        self.skip_ws();
        self.peek()
    }

    fn expect(&mut self, c: char) -> Result<(), NotationError> {
        match self.next_token() {
            Some(d) if d == c => {
                self.pos += c.len_utf8();
                Ok(())
            }
            Some(d) => Err(self.error(format!("expected '{c}', found '{d}'"))),
            None => Err(self.error(format!("expected '{c}', found the end of the input"))),
        }
    }

    fn eat(&mut self, c: char) -> bool {
        if self.next_token() == Some(c) {
            self.pos += c.len_utf8();
            true
        } else {
            false
        }
    }

    /// An optional `^T` transposition mark.
    fn transpose_mark(&mut self) -> Result<(), NotationError> {
        if self.eat('^') {
            self.skip_ws();
            if self.peek() == Some('T') {
                self.pos += 1;
            } else {
                return Err(self.error("expected 'T' after '^' (the transposition mark ^T)"));
            }
        }
        Ok(())
    }

    fn word(&mut self) -> &'a str {
        self.skip_ws();
        let start = self.pos;
        while let Some(c) = self.peek() {
            if c.is_alphanumeric() || c == '_' || c == '↑' || c == '↓' || c == '+' || c == '-' {
                self.pos += c.len_utf8();
            } else {
                break;
            }
        }
        &self.src[start..self.pos]
    }

    fn number(&mut self) -> Result<f64, NotationError> {
        self.skip_ws();
        let start = self.pos;
        let bytes = self.src.as_bytes();
        let mut end = start;
        if end < bytes.len() && (bytes[end] == b'+' || bytes[end] == b'-') {
            end += 1;
        }
        while end < bytes.len() && (bytes[end].is_ascii_digit() || bytes[end] == b'.') {
            end += 1;
        }
        if end < bytes.len() && (bytes[end] == b'e' || bytes[end] == b'E') {
            let mut k = end + 1;
            if k < bytes.len() && (bytes[k] == b'+' || bytes[k] == b'-') {
                k += 1;
            }
            if k < bytes.len() && bytes[k].is_ascii_digit() {
                end = k;
                while end < bytes.len() && bytes[end].is_ascii_digit() {
                    end += 1;
                }
            }
        }
        let text = &self.src[start..end];
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => {
                self.pos = end;
                Ok(v)
            }
            _ => Err(self.error_at(start, "expected a number")),
        }
    }

    fn vertex(&mut self) -> Result<VertexSpec, NotationError> {
        if self.next_token() != Some('v') {
            return Err(
                self.error("a vertex starts with 'v(' as in v(up, (60), (120), ((90,90),(t)))")
            );
        }
        self.pos += 1;
        self.expect('(')?;
        self.skip_ws();
        let mode_pos = self.pos;
        let word = self.word();
        let mode = Mode::parse(word).ok_or_else(|| {
            self.error_at(
                mode_pos,
                format!(
                    "unknown mode '{}': use up or down",
                    crate::text::excerpt(word, 40)
                ),
            )
        })?;
        let mut units = Vec::with_capacity(3);
        for k in 0..3 {
            self.expect(',').map_err(|e| {
                if k == 0 {
                    e
                } else {
                    NotationError {
                        message: format!("{} (a vertex has exactly three units)", e.message),
                        ..e
                    }
                }
            })?;
            units.push(self.unit()?);
        }
        if self.next_token() == Some(',') {
            return Err(self.error("a vertex has exactly three units"));
        }
        self.expect(')')?;
        let degree: usize = units.iter().map(|u: &UnitSpec| u.sectors_deg.len()).sum();
        if degree < 4 {
            return Err(self.error_at(
                0,
                format!("a vertex needs at least 4 sectors, this one has {degree}"),
            ));
        }
        let units: [UnitSpec; 3] = units.try_into().expect("three units were parsed");
        Ok(VertexSpec { mode, units })
    }

    fn unit(&mut self) -> Result<UnitSpec, NotationError> {
        let open = {
            self.skip_ws();
            self.pos
        };
        self.expect('(')?;
        if self.next_token() == Some('(') {
            // ((α1, …, αm), (ρ1, …))
            let sectors_pos = self.pos;
            self.expect('(')?;
            let sectors = self.sector_list()?;
            self.expect(')')?;
            self.transpose_mark()?;
            self.expect(',')?;
            self.expect('(')?;
            let mut driving = vec![self.expr()?];
            while self.eat(',') {
                driving.push(self.expr()?);
            }
            self.expect(')')?;
            self.transpose_mark()?;
            self.expect(')')?;
            if driving.len() + 1 != sectors.len() {
                return Err(self.error_at(
                    sectors_pos,
                    format!(
                        "a unit of {} sectors needs {} driving angles, found {}",
                        sectors.len(),
                        sectors.len() - 1,
                        driving.len()
                    ),
                ));
            }
            Ok(UnitSpec {
                sectors_deg: sectors,
                driving,
            })
        } else {
            let sectors = self.sector_list()?;
            self.expect(')')?;
            if sectors.len() != 1 {
                return Err(self.error_at(
                    open,
                    format!(
                        "a unit of {} sectors needs its driving angles: write (({}), (ρ1, …))",
                        sectors.len(),
                        sectors
                            .iter()
                            .map(|a| a.to_string())
                            .collect::<Vec<_>>()
                            .join(",")
                    ),
                ));
            }
            Ok(UnitSpec {
                sectors_deg: sectors,
                driving: Vec::new(),
            })
        }
    }

    fn sector_list(&mut self) -> Result<Vec<f64>, NotationError> {
        let mut out = Vec::new();
        loop {
            self.skip_ws();
            let at = self.pos;
            let a = self.number()?;
            if !(a > 0.0 && a < 180.0) {
                return Err(self.error_at(
                    at,
                    format!(
                        "sector angle {}° is outside (0°, 180°)",
                        crate::text::num(a)
                    ),
                ));
            }
            out.push(a);
            if !self.eat(',') {
                return Ok(out);
            }
        }
    }

    fn expr(&mut self) -> Result<DriveExpr, NotationError> {
        let mut lhs = self.term()?;
        loop {
            if self.eat('+') {
                lhs = DriveExpr::Add(Box::new(lhs), Box::new(self.term()?));
            } else if self.eat('-') {
                lhs = DriveExpr::Sub(Box::new(lhs), Box::new(self.term()?));
            } else {
                return Ok(lhs);
            }
        }
    }

    fn term(&mut self) -> Result<DriveExpr, NotationError> {
        let mut lhs = self.unary()?;
        loop {
            if self.eat('*') {
                lhs = DriveExpr::Mul(Box::new(lhs), Box::new(self.unary()?));
            } else if self.eat('/') {
                lhs = DriveExpr::Div(Box::new(lhs), Box::new(self.unary()?));
            } else {
                return Ok(lhs);
            }
        }
    }

    fn unary(&mut self) -> Result<DriveExpr, NotationError> {
        if self.eat('-') {
            return Ok(DriveExpr::Neg(Box::new(self.unary()?)));
        }
        if self.eat('+') {
            return self.unary();
        }
        self.atom()
    }

    fn atom(&mut self) -> Result<DriveExpr, NotationError> {
        match self.next_token() {
            Some('(') => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect(')')?;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => Ok(DriveExpr::Num(self.number()?)),
            Some(c) if c.is_alphabetic() || c == 'π' => {
                let at = self.pos;
                let mut end = self.pos;
                for ch in self.src[self.pos..].chars() {
                    if ch.is_alphanumeric() || ch == '_' || ch == 'π' {
                        end += ch.len_utf8();
                    } else {
                        break;
                    }
                }
                let name = &self.src[at..end];
                self.pos = end;
                match name {
                    "t" => Ok(DriveExpr::T),
                    "pi" | "π" | "Pi" | "PI" => Ok(DriveExpr::Num(std::f64::consts::PI)),
                    _ => Err(self.error_at(
                        at,
                        format!(
                            "unknown name '{}': use t, pi or numbers",
                            crate::text::excerpt(name, 40)
                        ),
                    )),
                }
            }
            Some(c) => Err(self.error(format!("expected a number, t, pi or '(', found '{c}'"))),
            None => Err(self.error("expected an expression, found the end of the input")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_thesis_examples() {
        let v = VertexSpec::parse("v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))").unwrap();
        assert_eq!(v.mode, Mode::Up);
        assert_eq!(v.degree(), 7);
        assert_eq!(v.units[2].sectors_deg, vec![20.0]);
        let w = VertexSpec::parse("v(down, (60), (120), ((90,90)^T,(t/1.2)))").unwrap();
        assert_eq!(w.mode, Mode::Down);
        assert!((w.units[2].driving[0].eval(&1.2_f64) - 1.0).abs() < 1e-15);
        // Display round-trips.
        assert_eq!(VertexSpec::parse(&v.to_string()).unwrap(), v);
        assert_eq!(VertexSpec::parse(&w.to_string()).unwrap(), w);
    }

    #[test]
    fn drive_expressions_follow_precedence() {
        let e = DriveExpr::parse("-t + 2*t/4 - (1 - t)").unwrap();
        let t = 0.3_f64;
        assert!((e.eval(&t) - (-t + 2.0 * t / 4.0 - (1.0 - t))).abs() < 1e-15);
        assert!(
            (DriveExpr::parse("pi/2").unwrap().eval(&0.0) - std::f64::consts::FRAC_PI_2).abs()
                < 1e-15
        );
    }

    #[test]
    fn errors_point_at_the_offending_character() {
        let cases = [
            ("v(up, (60), (120), ((90,90),(t))", "expected ')'", 32),
            ("v(sideways, (60), (120), ((90,90),(t)))", "unknown mode", 2),
            (
                "v(up, (60), (190), ((90,90),(t)))",
                "outside (0°, 180°)",
                13,
            ),
            (
                "v(up, (60), (120), ((90,90),(t,t)))",
                "needs 1 driving angles",
                20,
            ),
            ("v(up, (60), (120), (90))", "at least 4 sectors", 0),
            ("v(up, (60), (120), ((90,90),(x)))", "unknown name 'x'", 29),
            (
                "v(up, (60), (120), (90,90))",
                "needs its driving angles",
                19,
            ),
            (
                "v(up, (60), (120), ((90,90),(t)), (5))",
                "exactly three units",
                32,
            ),
            ("v(up, (0), (120), ((90,90),(t)))", "outside (0°, 180°)", 7),
        ];
        for (text, msg, pos) in cases {
            let e = VertexSpec::parse(text).unwrap_err();
            assert!(e.message.contains(msg), "{text}: {}", e.message);
            assert_eq!(e.pos, pos, "{text}: {e}");
        }
    }
}
