//! The fitted delays on the way in and out of a fit: the closed-form models' scan over
//! whole-sample delays ([`scan_delay`]), and the data as the fitted model saw them ([`as_seen`]).

use rayon::prelude::*;

use super::Dataset;

/// The input and the samples as the model saw them: shifted by the fitted delays within each
/// run (`samples`, as recorded, when there are none).
pub(super) fn as_seen(
    data: &Dataset,
    samples: Vec<model_core::Sample>,
    (delay, delay_u): (f64, f64),
    starts: &[usize],
) -> (Vec<f64>, Vec<model_core::Sample>) {
    let shift = |v: &[f64], d: f64| crate::models::alignment::shift_runs(v, d, starts);
    let input = shift(&data.input, delay);
    if delay == 0.0 && delay_u == 0.0 {
        return (input, samples);
    }
    let command = data.command.as_deref().map(|u| shift(u, delay_u));
    let rates = data.rates.as_ref().map(|(dx, ddx)| (shift(dx, delay), shift(ddx, delay)));
    let samples = crate::models::replay::samples_with_rates(&input, command.as_deref(), rates.as_ref());
    (input, samples)
}

/// Fit at every whole-sample delay in ±[`MAX_DELAY_SAMPLES`](crate::models::alignment::MAX_DELAY_SAMPLES)
/// (`at` fits on the shifted kinematics and returns the fit and its training cost), then
/// refine the best by a parabola through it and its neighbours. Returns the best fit and
/// its delay in samples. For the closed-form models, where a fit costs one pass.
pub(super) fn scan_delay<T>(
    kin: &[model_core::Kin],
    starts: &[usize],
    at: impl Fn(&[model_core::Kin]) -> Option<(T, f64)> + Sync,
) -> Option<(T, f64)>
where
    T: Send,
{
    let m = crate::models::alignment::MAX_DELAY_SAMPLES as i32;
    let fit_shifted = |d: f64| {
        let mut shifted = Vec::new();
        crate::models::alignment::shift_kin_runs(kin, d, 0.0, starts, &mut shifted);
        at(&shifted).map(|(r, c)| (r, c, d))
    };
    let mut grid: Vec<Option<(T, f64, f64)>> = (-m..=m).into_par_iter().map(|d| fit_shifted(f64::from(d))).collect();
    let cost_at = |i: usize| grid.get(i).and_then(|g| g.as_ref()).map_or(f64::INFINITY, |g| g.1);
    let best =
        (0..grid.len()).filter(|&i| cost_at(i).is_finite()).min_by(|&a, &b| cost_at(a).total_cmp(&cost_at(b)))?;
    let (c_l, c_0, c_r) = (cost_at(best.wrapping_sub(1)), cost_at(best), cost_at(best + 1));
    let curv = c_l - 2.0 * c_0 + c_r;
    let refined = (curv.is_finite() && curv > 0.0).then(|| 0.5 * (c_l - c_r) / curv).and_then(|off| {
        let d = (best as f64 - f64::from(m)) + off.clamp(-0.5, 0.5);
        fit_shifted(d)
    });
    let coarse = grid.get_mut(best)?.take()?;
    let winner = match refined {
        Some(r) if r.1 < coarse.1 => r,
        _ => coarse,
    };
    Some((winner.0, winner.2))
}
