//! A small evaluator for the formulas of pattern files: trajectories `x(t)` and crease
//! angles `ρ(t)`.
//!
//! Grammar (usual precedence; `^` binds tighter than unary minus and is right-associative,
//! so `-t^2 = -(t^2)` and `2^3^2 = 2^9`):
//!
//! ```text
//! expr  := term (("+" | "-") term)*
//! term  := unary (("*" | "/") unary)*
//! unary := ("-" | "+") unary | power
//! power := atom ("^" unary)?
//! atom  := number | "t" | "pi" | func "(" expr ")" | "(" expr ")"
//! func  := "sin" | "cos" | "tan" | "sqrt"
//! ```
//!
//! Numbers are decimal with an optional exponent (`2`, `0.5`, `.5`, `1e-3`). There is no
//! implicit multiplication: `2pi` is an error, `2*pi` is not. Errors carry the character
//! position and print the formula with a caret under the offending character.
//!
//! ```
//! use foldsynth::simulate::Formula;
//! let f = Formula::parse("1 + 2*cos(t)").unwrap();
//! assert_eq!(f.eval(0.0), 3.0);
//! let err = Formula::parse("2*co(t)").unwrap_err();
//! assert_eq!(err.position, 2);
//! ```

use std::fmt;

/// A parse error in a formula, pointing at a character.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormulaError {
    /// The formula as written.
    pub source: String,
    /// 0-based character (not byte) position of the offending character.
    pub position: usize,
    /// What is wrong there.
    pub message: String,
}

impl fmt::Display for FormulaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (shown, at) = crate::text::window(&self.source, self.position, 80);
        write!(
            f,
            "{} at character {} of \"{}\"\n    {}\n    {}^",
            self.message,
            self.position + 1,
            crate::text::excerpt(&self.source, 80),
            shown,
            " ".repeat(at)
        )
    }
}

impl std::error::Error for FormulaError {}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Func {
    Sin,
    Cos,
    Tan,
    Sqrt,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

#[derive(Clone, Debug, PartialEq)]
enum Node {
    Num(f64),
    T,
    Neg(Box<Node>),
    Bin(BinOp, Box<Node>, Box<Node>),
    Call(Func, Box<Node>),
}

impl Node {
    fn eval(&self, t: f64) -> f64 {
        match self {
            Node::Num(x) => *x,
            Node::T => t,
            Node::Neg(a) => -a.eval(t),
            Node::Bin(op, a, b) => {
                let (a, b) = (a.eval(t), b.eval(t));
                match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    BinOp::Mul => a * b,
                    BinOp::Div => a / b,
                    BinOp::Pow => a.powf(b),
                }
            }
            Node::Call(f, a) => {
                let a = a.eval(t);
                match f {
                    Func::Sin => a.sin(),
                    Func::Cos => a.cos(),
                    Func::Tan => a.tan(),
                    Func::Sqrt => a.sqrt(),
                }
            }
        }
    }
}

/// A parsed formula in the variable `t`.
#[derive(Clone, Debug, PartialEq)]
pub struct Formula {
    source: String,
    root: Node,
}

impl Formula {
    /// Parse `source`.
    pub fn parse(source: &str) -> Result<Formula, FormulaError> {
        if let Err((position, message)) = crate::limits::check_expression(source) {
            return Err(FormulaError {
                source: source.to_string(),
                position,
                message,
            });
        }
        let chars: Vec<char> = source.chars().collect();
        let mut p = Parser {
            src: source,
            chars: &chars,
            pos: 0,
        };
        p.skip_ws();
        if p.pos == chars.len() {
            return Err(p.error(
                0,
                "empty formula; expected a number, t, pi, a function or '('",
            ));
        }
        let root = p.expr()?;
        p.skip_ws();
        if p.pos < chars.len() {
            let msg = match chars[p.pos] {
                ')' => "unmatched ')'".to_string(),
                c if c.is_alphanumeric() || c == '(' || c == '.' => format!(
                    "expected an operator (+ - * / ^) before '{c}' (there is no implicit multiplication)"
                ),
                c => format!("unexpected '{c}'"),
            };
            return Err(p.error(p.pos, &msg));
        }
        Ok(Formula {
            source: source.to_string(),
            root,
        })
    }

    /// A constant formula.
    pub fn constant(x: f64) -> Formula {
        Formula {
            source: format!("{x}"),
            root: Node::Num(x),
        }
    }

    /// Evaluate at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.root.eval(t)
    }

    /// The formula as written.
    pub fn source(&self) -> &str {
        &self.source
    }
}

struct Parser<'a> {
    src: &'a str,
    chars: &'a [char],
    pos: usize,
}

impl Parser<'_> {
    fn error(&self, position: usize, message: &str) -> FormulaError {
        FormulaError {
            source: self.src.to_string(),
            position,
            message: message.to_string(),
        }
    }

    fn skip_ws(&mut self) {
        while self.pos < self.chars.len() && self.chars[self.pos].is_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_ws();
        self.chars.get(self.pos).copied()
    }

    fn expr(&mut self) -> Result<Node, FormulaError> {
        let mut lhs = self.term()?;
        while let Some(c @ ('+' | '-')) = self.peek() {
            self.pos += 1;
            let rhs = self.term()?;
            let op = if c == '+' { BinOp::Add } else { BinOp::Sub };
            lhs = Node::Bin(op, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }

    fn term(&mut self) -> Result<Node, FormulaError> {
        let mut lhs = self.unary()?;
        while let Some(c @ ('*' | '/')) = self.peek() {
            self.pos += 1;
            let rhs = self.unary()?;
            let op = if c == '*' { BinOp::Mul } else { BinOp::Div };
            lhs = Node::Bin(op, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Node, FormulaError> {
        match self.peek() {
            Some('-') => {
                self.pos += 1;
                Ok(Node::Neg(Box::new(self.unary()?)))
            }
            Some('+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Node, FormulaError> {
        let base = self.atom()?;
        if self.peek() == Some('^') {
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(Node::Bin(BinOp::Pow, Box::new(base), Box::new(exp)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Node, FormulaError> {
        let Some(c) = self.peek() else {
            return Err(self.error(
                self.pos,
                "formula ends too early; expected a number, t, pi, a function or '('",
            ));
        };
        let start = self.pos;
        if c == '(' {
            self.pos += 1;
            let inner = self.expr()?;
            if self.peek() != Some(')') {
                return Err(self.error(
                    self.pos,
                    &format!("expected ')' to close the '(' at character {}", start + 1),
                ));
            }
            self.pos += 1;
            return Ok(inner);
        }
        if c.is_ascii_digit() || c == '.' {
            return self.number();
        }
        if c.is_alphabetic() || c == '_' {
            while self.pos < self.chars.len()
                && (self.chars[self.pos].is_alphanumeric() || self.chars[self.pos] == '_')
            {
                self.pos += 1;
            }
            let name: String = self.chars[start..self.pos].iter().collect();
            let func = match name.as_str() {
                "t" => return Ok(Node::T),
                "pi" => return Ok(Node::Num(std::f64::consts::PI)),
                "sin" => Func::Sin,
                "cos" => Func::Cos,
                "tan" => Func::Tan,
                "sqrt" => Func::Sqrt,
                _ => {
                    return Err(self.error(
                        start,
                        &format!("unknown name '{name}'; allowed are t, pi, sin, cos, tan, sqrt"),
                    ));
                }
            };
            if self.peek() != Some('(') {
                return Err(self.error(
                    self.pos,
                    &format!("expected '(' after the function '{name}'"),
                ));
            }
            let open = self.pos;
            self.pos += 1;
            let arg = self.expr()?;
            if self.peek() != Some(')') {
                return Err(self.error(
                    self.pos,
                    &format!("expected ')' to close the '(' at character {}", open + 1),
                ));
            }
            self.pos += 1;
            return Ok(Node::Call(func, Box::new(arg)));
        }
        Err(self.error(
            start,
            &format!("unexpected '{c}'; expected a number, t, pi, a function or '('"),
        ))
    }

    fn number(&mut self) -> Result<Node, FormulaError> {
        let start = self.pos;
        let n = self.chars.len();
        while self.pos < n && (self.chars[self.pos].is_ascii_digit() || self.chars[self.pos] == '.')
        {
            self.pos += 1;
        }
        if self.pos < n && matches!(self.chars[self.pos], 'e' | 'E') {
            let save = self.pos;
            self.pos += 1;
            if self.pos < n && matches!(self.chars[self.pos], '+' | '-') {
                self.pos += 1;
            }
            if self.pos < n && self.chars[self.pos].is_ascii_digit() {
                while self.pos < n && self.chars[self.pos].is_ascii_digit() {
                    self.pos += 1;
                }
            } else {
                self.pos = save; // not an exponent; leave 'e' for the caller to reject
            }
        }
        let text: String = self.chars[start..self.pos].iter().collect();
        text.parse::<f64>()
            .map(Node::Num)
            .map_err(|_| self.error(start, &format!("'{text}' is not a number")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn ev(s: &str, t: f64) -> f64 {
        Formula::parse(s).unwrap().eval(t)
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(ev("1 + 2 * 3", 0.0), 7.0);
        assert_eq!(ev("(1 + 2) * 3", 0.0), 9.0);
        assert_eq!(ev("2^3^2", 0.0), 512.0);
        assert_eq!(ev("-t^2", 3.0), -9.0);
        assert_eq!(ev("2^-1", 0.0), 0.5);
        assert_eq!(ev("8 / 4 / 2", 0.0), 1.0);
        assert_eq!(ev("1 - 2 - 3", 0.0), -4.0);
        assert_eq!(ev("--t", 2.0), 2.0);
        assert_eq!(ev("1e-3 * 2E2", 0.0), 0.2);
        assert_eq!(ev(".5", 0.0), 0.5);
    }

    #[test]
    fn functions_and_constants() {
        assert!((ev("sin(pi/2)", 0.0) - 1.0).abs() < 1e-15);
        assert!((ev("1 + 2*cos(t)", PI) + 1.0).abs() < 1e-15);
        assert!((ev("-2*sin(t)", -PI / 2.0) - 2.0).abs() < 1e-15);
        assert_eq!(ev("sqrt(16)", 0.0), 4.0);
        assert!((ev("tan(t)", 0.25) - 0.25f64.tan()).abs() < 1e-15);
    }

    #[test]
    fn errors_point_at_the_offending_character() {
        let cases = [
            ("2*co(t)", 2),
            ("1 +", 3),
            ("(1 + t", 6),
            ("2pi", 1),
            ("1 + 2)", 5),
            ("sin t", 4),
            ("1..2", 0),
            ("x", 0),
            ("", 0),
            ("3 $ 4", 2),
        ];
        for (src, pos) in cases {
            let e = Formula::parse(src).unwrap_err();
            assert_eq!(e.position, pos, "{src}: {e}");
            let shown = e.to_string();
            assert!(shown.contains(&format!("{}^", " ".repeat(pos))), "{shown}");
        }
    }
}
