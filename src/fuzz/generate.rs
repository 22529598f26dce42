//! Grammar-based generators for the two notations: expressions in `t` and the vertex
//! notation of Eq. 24. Mostly well-formed, with the odd corruption, so the fuzzer reaches
//! past the parsers into the kinematics.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

/// Numbers worth trying: boundaries, specials, huge and tiny.
pub const NUMBERS: [&str; 24] = [
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "0.5",
    "1e-9",
    "1e-300",
    "5e-324",
    "1e6",
    "1e7",
    "1e15",
    "1e308",
    "-1e308",
    "1e309",
    "180",
    "-180",
    "360",
    "90",
    "179.9999",
    "0.0001",
    "3.141592653589793",
    "18446744073709551616",
    "4294967296",
];

/// A random expression in `t` of at most `depth` levels.
pub fn expr(rng: &mut ChaCha8Rng, depth: u32) -> String {
    if depth == 0 || rng.random_range(0..10) < 3 {
        return match rng.random_range(0..6) {
            0 => "t".into(),
            1 => "pi".into(),
            2 => NUMBERS[rng.random_range(0..NUMBERS.len())].into(),
            3 => format!("{}", rng.random_range(-200..200)),
            4 => format!("{:.3}", rng.random_range(-4.0..4.0)),
            _ => "t".into(),
        };
    }
    let a = expr(rng, depth - 1);
    match rng.random_range(0..11) {
        0 => format!("-{a}"),
        1 => format!("({a})"),
        2 => format!("{a} + {}", expr(rng, depth - 1)),
        3 => format!("{a} - {}", expr(rng, depth - 1)),
        4 => format!("{a}*{}", expr(rng, depth - 1)),
        5 => format!("{a}/{}", expr(rng, depth - 1)),
        6 => format!("{a}^{}", expr(rng, depth - 1)),
        7 => {
            let f = ["sin", "cos", "tan", "sqrt", "exp", "ln", "abs"][rng.random_range(0..7)];
            format!("{f}({a})")
        }
        8 => format!("{a} {}", expr(rng, depth - 1)),
        9 => format!("2{a}"),
        _ => format!("({a})*t"),
    }
}

/// A driving angle as the vertex notation takes it: numbers, `t`, `pi`, `+ - * /`,
/// parentheses.
pub fn drive(rng: &mut ChaCha8Rng, depth: u32) -> String {
    if depth == 0 || rng.random_range(0..10) < 4 {
        return match rng.random_range(0..5) {
            0 | 1 => "t".into(),
            2 => "pi".into(),
            3 => format!("{:.2}", rng.random_range(0.1..3.0)),
            _ => NUMBERS[rng.random_range(0..NUMBERS.len())].into(),
        };
    }
    let a = drive(rng, depth - 1);
    match rng.random_range(0..7) {
        0 => format!("-{a}"),
        1 => format!("({a})"),
        2 => format!("{a} + {}", drive(rng, depth - 1)),
        3 => format!("{a} - {}", drive(rng, depth - 1)),
        4 => format!("{a}*{}", drive(rng, depth - 1)),
        5 => format!("{a}/{}", drive(rng, depth - 1)),
        _ => format!("t/{:.1}", rng.random_range(0.5..3.0)),
    }
}

/// A sector angle in degrees: mostly inside (0°, 180°).
fn sector(rng: &mut ChaCha8Rng) -> String {
    match rng.random_range(0..12) {
        0 => NUMBERS[rng.random_range(0..NUMBERS.len())].into(),
        1 => format!("{}", rng.random_range(-10..400)),
        _ => format!("{}", rng.random_range(1..179)),
    }
}

/// A vertex in the notation `v(MODE, UNIT, UNIT, UNIT)` (Eq. 24).
pub fn vertex(rng: &mut ChaCha8Rng) -> String {
    let mode = ["up", "down", "up", "down", "up", "down", "sideways", ""][rng.random_range(0..8)];
    let mut units = Vec::new();
    let n_units = if rng.random_range(0..10) == 0 {
        rng.random_range(0..6)
    } else {
        3
    };
    for _ in 0..n_units {
        let m: usize = match rng.random_range(0..10) {
            0 => rng.random_range(0..8),
            1..=4 => 1,
            _ => rng.random_range(2..4),
        };
        let sectors: Vec<String> = (0..m).map(|_| sector(rng)).collect();
        if m == 1 && rng.random_bool(0.9) {
            units.push(format!("({})", sectors[0]));
        } else {
            let k = if rng.random_range(0..10) == 0 {
                rng.random_range(0..m + 2)
            } else {
                m.saturating_sub(1)
            };
            let drives: Vec<String> = (0..k).map(|_| drive(rng, 3)).collect();
            units.push(format!("(({}),({}))", sectors.join(","), drives.join(",")));
        }
    }
    let mut s = format!("v({mode}, {})", units.join(", "));
    if rng.random_range(0..16) == 0 {
        // A corruption: drop or duplicate one character.
        let chars: Vec<char> = s.chars().collect();
        if !chars.is_empty() {
            let i = rng.random_range(0..chars.len());
            let mut c = chars.clone();
            if rng.random_bool(0.5) {
                c.remove(i);
            } else {
                c.insert(i, chars[i]);
            }
            s = c.into_iter().collect();
        }
    }
    s
}
