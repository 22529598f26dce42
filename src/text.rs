//! Text shown to the user: echoes of their input cut to a readable length, numbers in a
//! form that reads (a 309-digit number is `1e308`).

/// `s` cut to at most `max` characters, saying how many were left out (long digit runs
/// cut first, see [`cut_digit_runs`]).
pub fn excerpt(s: &str, max: usize) -> String {
    let s = &cut_digit_runs(s);
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

/// Every line of `message` cut to about `max` characters, keeping its start and its end
/// (where a usage error names the option): the last guard against echoing a huge input
/// back whole.
pub fn cut_lines(message: &str, max: usize) -> String {
    message
        .lines()
        .map(|l| {
            let l = &cut_digit_runs(l);
            let n = l.chars().count();
            if n <= max {
                return l.to_string();
            }
            let (head, tail) = (max * 2 / 3, max / 3);
            let start: String = l.chars().take(head).collect();
            let end: String = l.chars().skip(n - tail).collect();
            format!("{start}… ({} characters cut) …{end}", n - head - tail)
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs of more than 24 digits (a parser echoing `1e308` in full) cut to their first six
/// and their length: `100000… (309 digits)`.
pub fn cut_digit_runs(s: &str) -> String {
    const KEEP: usize = 6;
    const LONG: usize = 24;
    let mut out = String::with_capacity(s.len().min(4096));
    let mut run = String::new();
    let flush = |run: &mut String, out: &mut String| {
        if run.len() > LONG {
            out.push_str(&run[..KEEP]);
            out.push_str(&format!("… ({} digits)", run.len()));
        } else {
            out.push_str(run);
        }
        run.clear();
    };
    for c in s.chars() {
        if c.is_ascii_digit() {
            run.push(c);
        } else {
            flush(&mut run, &mut out);
            out.push(c);
        }
    }
    flush(&mut run, &mut out);
    out
}

/// A window of at most `width` characters of `input` around character `pos`, and the
/// column of `pos` in it: to point at an error in a long input without echoing it whole.
pub fn window(input: &str, pos: usize, width: usize) -> (String, usize) {
    let chars: Vec<char> = input.chars().collect();
    let pos = pos.min(chars.len());
    if chars.len() <= width {
        return (input.to_string(), pos);
    }
    let start = pos
        .saturating_sub(width / 2)
        .min(chars.len().saturating_sub(width));
    let end = (start + width).min(chars.len());
    let mut s = String::new();
    let mut col = pos - start;
    if start > 0 {
        s.push('…');
        col += 1;
    }
    s.extend(&chars[start..end]);
    if end < chars.len() {
        s.push('…');
    }
    (s, col)
}

/// When `text` is clearly another kind of foldsynth file than `expected` ("task" or
/// "pattern"), say which and which command takes it: a task file given to `simulate`
/// should not read as "unknown field `bounds`".
pub fn other_kind(text: &str, expected: &str) -> Option<String> {
    let start = text.trim_start();
    if start.starts_with('{') || start.starts_with('[') && start[1..].trim_start().starts_with('{')
    {
        return Some(format!(
            "this is JSON (a FOLD or design file?), not a {expected} file: `foldsynth verify` and `foldsynth simulate` take FOLD files, `foldsynth export` and `foldsynth simulate` design files"
        ));
    }
    let table: toml::Table = text.parse().ok()?;
    let task = table.contains_key("initial_graph") || table.contains_key("grammar");
    let pattern = table.contains_key("vertices") && table.contains_key("faces");
    match expected {
        "pattern" if task && !pattern => Some(
            "this is a task file (it has [grammar] and [initial_graph]): `foldsynth simulate` takes a pattern file (such as grammar/flasher_adapted.toml), a FOLD file (.fold) or a design JSON (.json). A task's designs come from `foldsynth synthesize TASK`; `foldsynth simulate --crossval OUT` simulates them all".into(),
        ),
        "task" if pattern && !task => Some(
            "this is a pattern file of the bar-and-hinge simulator (it has vertices and faces): `foldsynth simulate FILE` runs it; this command takes a task file (such as grammar/gripper.toml)".into(),
        ),
        _ => None,
    }
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
        let (w, col) = window(&long, 50_000, 20);
        assert_eq!(w.chars().count(), 22);
        assert_eq!(col, 11);
        assert_eq!(window("abc", 1, 20), ("abc".to_string(), 1));
        let huge = format!(
            "invalid type: floating point `1{}`, expected",
            "0".repeat(308)
        );
        assert_eq!(
            cut_lines(&huge, 1000),
            "invalid type: floating point `100000… (309 digits)`, expected"
        );
        assert_eq!(cut_digit_runs("12345 and 1.5"), "12345 and 1.5");
    }
}
