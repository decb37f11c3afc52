//! Input motor at a set speed with torque ripple: `ω = ω_set(t)·(1 + a·sin(k·φ))`, `dφ/dt = ω`.
//!
//! The motor's speed loop is stiff compared with the clutch torque (seed 000's Hacker
//! Q80 through a reduction gear at constant speed); the set speed follows a piecewise
//! linear profile; ripple a = 2 % at k = 6 per revolution (cogging of a 6-slot motor).
//! The output is held by the load cell, so the slip speed is ω.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MotorParams {
    /// `[t (s), ω (rad/s)]` points, linearly interpolated, held after the last.
    pub speed: Vec<[f64; 2]>,
    pub ripple: f64,
    pub ripple_per_rev: f64,
}

impl Default for MotorParams {
    fn default() -> Self {
        Self { speed: vec![[0.0, 30.0]], ripple: 0.02, ripple_per_rev: 6.0 }
    }
}

impl MotorParams {
    /// Set speed at time `t`, rad/s.
    pub fn set_speed(&self, t: f64) -> f64 {
        let mut prev: Option<[f64; 2]> = None;
        for &[tk, wk] in &self.speed {
            if t < tk {
                return match prev {
                    Some([tp, wp]) if tk > tp => wp + (wk - wp) * (t - tp) / (tk - tp),
                    _ => wk,
                };
            }
            prev = Some([tk, wk]);
        }
        prev.map_or(0.0, |p| p[1])
    }

    /// Speed with ripple at shaft angle `phi`, rad/s.
    pub fn speed(&self, t: f64, phi: f64) -> f64 {
        self.set_speed(t) * (1.0 + self.ripple * (self.ripple_per_rev * phi).sin())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_interpolates() {
        let m = MotorParams { speed: vec![[0.0, 10.0], [2.0, 30.0]], ..Default::default() };
        assert_eq!(m.set_speed(-1.0), 10.0);
        assert_eq!(m.set_speed(1.0), 20.0);
        assert_eq!(m.set_speed(5.0), 30.0);
    }
}
