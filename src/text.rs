//! Text shown to the user: echoes of their input cut to a readable length, numbers in a
//! form that reads (a 309-digit number is `1e308`).

/// `s` cut to at most `max` characters, saying how many were left out.
pub fn excerpt(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let head: String = s.chars().take(max).collect();
    format!("{head}… ({} more characters)", n - max)
}

/// A number for a message: as Rust prints it when that is short, in scientific notation
/// when it is very large or very small.
pub fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-5..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Every line of `message` cut to `max` characters: the last guard against echoing a
/// huge input back whole.
pub fn cut_lines(message: &str, max: usize) -> String {
    message
        .lines()
        .map(|l| excerpt(l, max))
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_echoes_are_cut_and_numbers_stay_short() {
        let long = "x".repeat(100_000);
        let cut = excerpt(&long, 50);
        assert!(cut.starts_with(&"x".repeat(50)));
        assert!(cut.ends_with("(99950 more characters)"));
        assert_eq!(num(1e308), "1e308");
        assert_eq!(num(0.25), "0.25");
        assert_eq!(num(-3e-9), "-3e-9");
        assert_eq!(num(f64::INFINITY), "inf");
    }
}
