//! The thesis's rule-sequence notation (Sec. 5.5.2): `2, 3, (4, 8), 4, (7, 8)` is r1 on v2,
//! r1 on v3, r2 on v4 and v8, … with the names as they are when each rule applies. A primed
//! pair is r2′ (Sec. 5.7, Fig. 52b): `2, 3, 4, 8, (9, 14)'` (`′` is read as `'`).

use super::StepRecord;
use super::graph::CreaseGraph;
use super::rules::RuleError;
use super::step::Step;
use crate::task::Task;

/// A sequence string that does not parse, or a step that does not apply.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NotationError {
    /// The text is not a sequence.
    #[error("cannot read rule sequence \"{text}\" at character {pos}: {message}")]
    Syntax {
        /// The sequence.
        text: String,
        /// 1-based character position.
        pos: usize,
        /// What was expected.
        message: String,
    },
    /// A step does not match.
    #[error("rule sequence \"{text}\", step {index} `{step}` (after \"{before}\"): {error}")]
    Rule {
        /// The sequence.
        text: String,
        /// 1-based index of the step.
        index: usize,
        /// The step.
        step: Step,
        /// The steps applied before it.
        before: String,
        /// Why it does not apply.
        error: RuleError,
    },
}

/// Write a sequence: steps joined by `", "`.
pub fn format_sequence(steps: &[Step]) -> String {
    steps
        .iter()
        .map(Step::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Read a sequence such as `2, 3, (4, 8), 4, (7, 8)` or `2, 3, 4, 8, (9, 14)'` (spaces
/// optional; the empty string is G0 itself).
pub fn parse_sequence(text: &str) -> Result<Vec<Step>, NotationError> {
    let b = text.as_bytes();
    let mut i = 0;
    let err = |pos: usize, message: &str| NotationError::Syntax {
        text: text.to_owned(),
        pos: pos + 1,
        message: message.to_owned(),
    };
    let skip = |i: &mut usize| {
        while *i < b.len() && b[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    let number = |i: &mut usize| -> Result<usize, NotationError> {
        skip(i);
        let start = *i;
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
        if start == *i {
            return Err(err(start, "expected a vertex name (a positive integer)"));
        }
        match text[start..*i].parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(err(start, "vertex names are positive integers")),
        }
    };
    // Primes right after a pair or a name (ASCII ' or U+2032 ′), counted.
    let prime = |i: &mut usize| -> usize {
        let mut k = 0;
        loop {
            skip(i);
            if *i < b.len() && b[*i] == b'\'' {
                *i += 1;
            } else if text[*i..].starts_with('′') {
                *i += '′'.len_utf8();
            } else {
                return k;
            }
            k += 1;
        }
    };
    let mut steps = Vec::new();
    skip(&mut i);
    if i == b.len() {
        return Ok(steps);
    }
    loop {
        skip(&mut i);
        if i < b.len() && b[i] == b'(' {
            i += 1;
            let x = number(&mut i)?;
            skip(&mut i);
            if i >= b.len() || b[i] != b',' {
                return Err(err(i, "expected `,` between the two names of a pair"));
            }
            i += 1;
            let y = number(&mut i)?;
            skip(&mut i);
            if i >= b.len() || b[i] != b')' {
                return Err(err(i, "expected `)` closing the pair"));
            }
            i += 1;
            if x == y {
                return Err(err(i - 1, "a pair needs two different vertices"));
            }
            match prime(&mut i) {
                0 => steps.push(Step::Combine(x, y)),
                1 => steps.push(Step::Straight(x, y)),
                _ => {
                    return Err(err(
                        i - 1,
                        "one prime marks r2′: write (a, b) for r2 or (a, b)' for r2′",
                    ));
                }
            }
        } else {
            steps.push(Step::Extend(number(&mut i)?));
            let at = i;
            if prime(&mut i) > 0 {
                return Err(err(
                    at,
                    "a prime marks a pair combined by r2′, written (a, b)'; a single name is r1",
                ));
            }
        }
        skip(&mut i);
        if i == b.len() {
            return Ok(steps);
        }
        if b[i] != b',' {
            return Err(err(i, "expected `,` between steps"));
        }
        i += 1;
    }
}

impl CreaseGraph {
    /// The steps that built this graph, in the notation.
    pub fn sequence_steps(&self) -> Vec<Step> {
        self.steps
            .iter()
            .filter(|s| match s {
                StepRecord::R1(r) => !r.image,
                StepRecord::R2(r) => !r.image,
            })
            .map(|s| match s {
                StepRecord::R1(r) => Step::Extend(r.name),
                StepRecord::R2(r) if r.straight.is_some() => Step::Straight(r.names.0, r.names.1),
                StepRecord::R2(r) => Step::Combine(r.names.0, r.names.1),
            })
            .collect()
    }

    /// The rule sequence that built this graph, e.g. `2, 3, (4, 8)`.
    pub fn sequence(&self) -> String {
        format_sequence(&self.sequence_steps())
    }

    /// Rebuild a graph from G0 of `task` and a rule sequence, applying the rules in order.
    /// Every step must match (N_max is not enforced: that is the enumeration's limit).
    pub fn from_sequence(task: &Task, text: &str) -> Result<CreaseGraph, NotationError> {
        let steps = parse_sequence(text)?;
        let mut g = CreaseGraph::initial(task);
        for (k, &step) in steps.iter().enumerate() {
            g.apply_step(step).map_err(|error| NotationError::Rule {
                text: text.to_owned(),
                index: k + 1,
                step,
                before: format_sequence(&steps[..k]),
                error,
            })?;
        }
        Ok(g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_formats() {
        let s = parse_sequence("2, 3, (4, 8), 4, (7, 8)").unwrap();
        assert_eq!(
            s,
            vec![
                Step::Extend(2),
                Step::Extend(3),
                Step::Combine(4, 8),
                Step::Extend(4),
                Step::Combine(7, 8)
            ]
        );
        assert_eq!(format_sequence(&s), "2, 3, (4, 8), 4, (7, 8)");
        assert_eq!(parse_sequence("2,3,(4,8)").unwrap().len(), 3);
        assert!(parse_sequence("  ").unwrap().is_empty());
    }

    #[test]
    fn rejects_bad_text() {
        for t in ["2,", "2 3", "(4 8)", "(4, 8", "x", "0", "(4, 4)", "2,,3"] {
            assert!(parse_sequence(t).is_err(), "{t}");
        }
    }
}
