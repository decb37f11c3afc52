//! A change to what the base model is fed: the recorded input delayed, lagged, saturated or
//! offset before the base responds to it (the catalog's input-side effects), or smoothed
//! without a shift of phase (the control a field lag must beat, never a finding).

use serde::Serialize;

/// A change to what the base model is fed.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Transform {
    /// The output responds to the input `delay_s` later: the model sees `x(t − delay_s)`.
    Delay { delay_s: f64 },
    /// First-order lag `τ·ẋ_f = x − x_f` (Spencer's η filter with η = 1/τ).
    Lag { tau_s: f64 },
    /// Two first-order lags of `τ/2` each in series (a field diffusing through two layers:
    /// its step response starts flat, between a first-order lag and a delay).
    Lag2 { tau_s: f64 },
    /// `b_s · tanh(x / b_s)`.
    Saturate { b_sat: f64 },
    /// A sharper knee, `x / (1 + (x / b_s)⁴)^¼`: linear up to near `b_s`, then flat (steel
    /// saturating in a narrow range of the field).
    SaturateKnee { b_sat: f64 },
    /// The recorded input reads `b_0` high: the model sees `x − b_0`.
    Offset { b_0: f64 },
    /// First-order lags of `τ` forward and backward in time: the input smoothed without a
    /// shift of phase. Never a finding: the control a field lag must beat ([`super::zero_phase`]).
    Smooth { tau_s: f64 },
}

impl Transform {
    /// The transformed input; `dt` is the sample interval (s).
    pub fn apply(&self, x: &[f64], dt: f64) -> Vec<f64> {
        match *self {
            Self::Delay { delay_s } => crate::models::alignment::shift(x, -delay_s / dt),
            Self::Lag { tau_s } => {
                let a = if tau_s > 0.0 { (-dt / tau_s).exp() } else { 0.0 };
                let mut f = x.first().copied().unwrap_or(0.0);
                x.iter()
                    .map(|v| {
                        f = a * f + (1.0 - a) * v;
                        f
                    })
                    .collect()
            }
            Self::Lag2 { tau_s } => {
                let half = Self::Lag { tau_s: 0.5 * tau_s };
                half.apply(&half.apply(x, dt), dt)
            }
            Self::Saturate { b_sat } => x.iter().map(|v| b_sat * (v / b_sat).tanh()).collect(),
            Self::SaturateKnee { b_sat } => x.iter().map(|v| v / (1.0 + (v / b_sat).powi(4)).powf(0.25)).collect(),
            Self::Offset { b_0 } => x.iter().map(|v| v - b_0).collect(),
            Self::Smooth { tau_s } => {
                let lag = Self::Lag { tau_s };
                let mut f = lag.apply(x, dt);
                f.reverse();
                let mut b = lag.apply(&f, dt);
                b.reverse();
                b
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_do_what_they_say() {
        let dt = 1e-3;
        let x: Vec<f64> = (0..200).map(|i| (i as f64 * 0.05).sin()).collect();
        // A delay of 3 samples: the model sees x three samples earlier.
        let d = Transform::Delay { delay_s: 3e-3 }.apply(&x, dt);
        assert!((d[50] - x[47]).abs() < 1e-12);
        // A first-order lag keeps a constant and attenuates a step's start.
        let step: Vec<f64> = (0..100).map(|i| if i < 10 { 0.0 } else { 1.0 }).collect();
        let l = Transform::Lag { tau_s: 5e-3 }.apply(&step, dt);
        assert!((l[14] - (1.0 - (-5.0f64 / 5.0).exp())).abs() < 1e-9, "{}", l[14]);
        assert!((l[99] - 1.0).abs() < 1e-6);
        let s = Transform::Saturate { b_sat: 0.5 }.apply(&[2.0, -2.0, 0.0], dt);
        assert!(s[0] < 0.5 && s[0] > 0.49 && s[1] == -s[0] && s[2] == 0.0);
        assert_eq!(Transform::Offset { b_0: 0.1 }.apply(&[1.0], dt), vec![0.9]);
    }
}
