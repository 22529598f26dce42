//! The `[check]` table: the intersection check's states and obstacles (Sec. 5.4.2).

use serde::Deserialize;

use super::solids::cylinder;
use super::{Ctx, Number, TaskError};

/// A cylinder obstacle (axis segment `a → b` and radius): one of the scene's shapes.
pub use crate::scene::Cylinder;
use crate::scene::{Copies, Obstacle, Shape};

/// Intersection-check setup.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckSpec {
    /// Number of evenly spaced states over [0, t_max] to check (the thesis uses 16).
    pub states: usize,
    /// Number of evenly spaced states over [0, t_max] at which the optimizer imposes the
    /// clearance and margin constraints (more are added where a finer sweep finds the
    /// design closer than allowed).
    pub optimize_states: usize,
}

/// Default of `[check] optimize_states`.
pub const DEFAULT_OPTIMIZE_STATES: usize = 9;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCheck {
    states: i64,
    #[serde(default)]
    cylinders: Vec<RawCylinder>,
    #[serde(default)]
    second_arm: bool,
    optimize_states: Option<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCylinder {
    radius: Number,
    from: Vec<Number>,
    to: Vec<Number>,
}

/// What the `[check]` table says about the scene: the legacy `[[check.cylinders]]`
/// (obstacles `check.cylinders[k]`) and `second_arm = true` (two copies about z, the
/// thesis's gripper, Sec. 5.5.1).
pub(crate) struct LegacyScene {
    /// The cylinders, in file order.
    pub(crate) obstacles: Vec<Obstacle>,
    /// `second_arm = true`.
    pub(crate) copies: Option<Copies>,
}

/// The check setup and what it says about the scene.
pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: Option<&RawCheck>,
) -> Result<(Option<CheckSpec>, LegacyScene), TaskError> {
    let mut legacy = LegacyScene {
        obstacles: Vec::new(),
        copies: None,
    };
    let Some(c) = raw else {
        return Ok((None, legacy));
    };
    cx.entries("check.cylinders", c.cylinders.len())?;
    let max = crate::limits::STATES_MAX as i64;
    if !(2..=max).contains(&c.states) {
        return Err(cx.err(
            "check.states",
            format!(
                "{} is not allowed: at least 2 states (0 and t_max), at most {max}",
                c.states
            ),
        ));
    }
    let optimize_states = c.optimize_states.unwrap_or(DEFAULT_OPTIMIZE_STATES as i64);
    if !(2..=crate::limits::STATES_MAX as i64).contains(&optimize_states) {
        return Err(cx.err(
            "check.optimize_states",
            format!(
                "{optimize_states} is not allowed: at least 2 states (0 and t_max), at most {}",
                crate::limits::STATES_MAX
            ),
        ));
    }
    for (i, cy) in c.cylinders.iter().enumerate() {
        legacy.obstacles.push(Obstacle {
            name: format!("check.cylinders[{i}]"),
            shape: Shape::Cylinder(cylinder(
                cx,
                &format!("check.cylinders[{i}]"),
                &cy.radius,
                &cy.from,
                &cy.to,
            )?),
        });
    }
    legacy.copies = c.second_arm.then(|| Copies::about_z(2));
    let check = CheckSpec {
        states: c.states as usize,
        optimize_states: optimize_states as usize,
    };
    Ok((Some(check), legacy))
}
