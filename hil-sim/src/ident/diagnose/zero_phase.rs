//! A field lag against the same smoothing without its phase.
//!
//! The hysteresis models' state moves with every increment of the input as read (LuGre's
//! `dx = x_k − x_{k−1}`), and a Hall reading's 12-bit steps and noise go back and forth
//! and wear the loop down; a lag of the input smooths them. On Dahl nulls fitted with LuGre
//! a 1–3 ms lag gained 15–21 % on the tail for that alone (three of five false alarms of
//! fresh40–fresh45). What a lag of the field has that smoothing has not is its phase: before
//! a field lag is kept, the round's reference is refitted with its input smoothed
//! zero-phase instead ([`Transform::Smooth`], τ tuned from the lag's equal-amplitude value),
//! and the lag must predict the held-out tail at least [`significance::MIN_GAIN`] better
//! than that control. Not the block test's significance as well: on a sweep the phase
//! shows only in the blocks of the fast part (fresh44 `524016056`, a two-pole lag on a
//! 10 kHz sweep: 35 % better than the control, 6 of 10 blocks, t = 1.8), while on the Dahl
//! nulls the control predicted the tail as well as the lag or better (`568708399`: −2.2 %).

use serde::Serialize;

use super::augment::{Fitted, Problem};
use super::candidates::{Candidate, Piece};
use super::rank::{Scored, POLISH_ITERATIONS, SCREEN_ITERATIONS};
use super::refit::refit_candidate;
use super::significance::{self, Test};
use super::transform::Transform;

/// The zero-phase control of a field lag.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Control {
    /// The smoothing's fitted time constant (each direction), s.
    pub tau_s: f64,
    /// The lag against the control on the held-out blocks.
    pub test: Test,
    /// The lag's held-out RMSE is at least [`significance::MIN_GAIN`] below the control's:
    /// the lag may be kept.
    pub passed: bool,
}

/// The smoothing with the lag's amplitude at low frequencies: `1/√(1 + (ωτ)²)` of a
/// first-order lag, `1/(1 + (ωτ/2)²)` of the two-pole one, against `1/(1 + (ωτ_s)²)`.
fn equal_amplitude(lag: &Transform) -> Option<f64> {
    match *lag {
        Transform::Lag { tau_s } => Some(tau_s / std::f64::consts::SQRT_2),
        Transform::Lag2 { tau_s } => Some(0.5 * tau_s),
        _ => None,
    }
}

/// The control of the field lag `lag` (its transform the last of its fit's) kept on top of
/// `reference`, judged on the held-out `held` rows of `y`; `None` when the lag is not a
/// lag or the control's refit diverges (then the lag stands as it was judged).
pub fn control(prob: &Problem<'_>, reference: &Fitted, lag: &Scored, y: &[f64], held: &[usize]) -> Option<Control> {
    let tau = equal_amplitude(lag.fitted.transforms.last()?)?;
    let dt = prob.data.dt;
    let smoothing = Candidate {
        effect: "zero_phase_control",
        label: "the input smoothed without a shift of phase".into(),
        grid_name: Some("tau_s".into()),
        grid: vec![0.25 * dt, 0.3_f64.max(4.0 * dt)],
        build: Box::new(|g| Piece { transform: Some(Transform::Smooth { tau_s: g }), terms: vec![] }),
        channel: None,
    };
    let starts = [(tau, None), (0.5 * tau, None)];
    let (smoothed, tau_s) =
        refit_candidate(prob, &smoothing, reference, &starts, SCREEN_ITERATIONS + POLISH_ITERATIONS)?;
    let test = significance::test(y, &smoothed.pred, &lag.fitted.pred, held);
    Some(Control { tau_s, test, passed: test.gain >= significance::MIN_GAIN })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smoothing_has_the_lags_amplitude_and_no_phase() {
        let dt = 1e-3;
        let n = 4000;
        let w = 2.0 * std::f64::consts::PI * 20.0;
        let x: Vec<f64> = (0..n).map(|k| (w * k as f64 * dt).sin()).collect();
        let tau = 0.004;
        let lag = Transform::Lag { tau_s: tau };
        let smooth = Transform::Smooth { tau_s: equal_amplitude(&lag).expect("a lag") };
        let (l, s) = (lag.apply(&x, dt), smooth.apply(&x, dt));
        // Steady-state middle: amplitude and phase against the input.
        let mid = 1000..3000;
        let proj = |v: &[f64], c: fn(f64) -> f64| -> f64 {
            mid.clone().map(|k| v[k] * c(w * k as f64 * dt)).sum::<f64>() * 2.0 / mid.len() as f64
        };
        let (ls, lc) = (proj(&l, f64::sin), proj(&l, f64::cos));
        let (ss, sc) = (proj(&s, f64::sin), proj(&s, f64::cos));
        let (la, sa) = (ls.hypot(lc), ss.hypot(sc));
        assert!((la - sa).abs() < 0.01 * la, "amplitudes {la} {sa}");
        assert!(lc.abs() > 0.2 * la, "the lag shifts the phase: {lc}");
        assert!(sc.abs() < 0.002 * sa, "the smoothing does not: {sc}");
        assert!(equal_amplitude(&Transform::Delay { delay_s: 0.01 }).is_none());
    }
}
