//! The fitted delays on the way in and out of a fit: the closed-form models' scan over
//! whole-sample delays ([`scan_delay`]), and the data as the fitted model saw them ([`Seen`]).

use std::borrow::Cow;

use model_core::Sample;
use rayon::prelude::*;

use super::Dataset;

/// The input, the command and the given rates as the model saw them: shifted by the fitted
/// delays within each run, borrowed from the dataset where a delay is zero (a shift by zero
/// is the channel itself), so the samples the core steps through are made one at a time.
pub(super) struct Seen<'a> {
    pub input: Channel<'a>,
    command: Option<Channel<'a>>,
    rates: Option<(Channel<'a>, Channel<'a>)>,
}

/// One channel of [`Seen`]: the dataset's own, or its shifted copy.
type Channel<'a> = Cow<'a, [f64]>;

impl<'a> Seen<'a> {
    pub fn of(data: &'a Dataset, (delay, delay_u): (f64, f64), starts: &[usize]) -> Self {
        let shift = |v: &'a [f64], d: f64| -> Cow<'a, [f64]> {
            if d == 0.0 {
                Cow::Borrowed(v)
            } else {
                Cow::Owned(crate::models::alignment::shift_runs(v, d, starts))
            }
        };
        Self {
            input: shift(&data.input, delay),
            command: data.command.as_deref().map(|u| shift(u, delay_u)),
            rates: data.rates.as_ref().map(|(dx, ddx)| (shift(dx, delay), shift(ddx, delay))),
        }
    }

    /// The sample at `i`, as [`crate::models::replay::samples_with_rates`] makes it.
    pub fn sample(&self, i: usize) -> Sample {
        let mut s = crate::models::replay::sample_at(&self.input, self.command.as_deref(), i);
        if let Some((dx, ddx)) = &self.rates {
            s.dx = dx.get(i).map(|v| *v as f32);
            s.ddx = ddx.get(i).map(|v| *v as f32);
        }
        s
    }
}

/// Above this many samples the delay scan runs one delay at a time (a shifted copy of the
/// kinematics is 16 bytes a sample: 16 MiB here, per core when run side by side).
const PARALLEL_SCAN_SAMPLES: usize = 1 << 20;

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
    let fit_into = |shifted: &mut Vec<model_core::Kin>, d: f64| {
        crate::models::alignment::shift_kin_runs(kin, d, 0.0, starts, shifted);
        at(shifted).map(|(r, c)| (r, c, d))
    };
    let fit_shifted = |d: f64| fit_into(&mut Vec::new(), d);
    // One shifted copy per worker, reused across the delays it fits. A long recording's
    // delays are fitted one after another: a copy per core would hold the kinematics as many
    // times as there are cores, and memory must stay a fixed multiple of the recording.
    let mut grid: Vec<Option<(T, f64, f64)>> = if kin.len() > PARALLEL_SCAN_SAMPLES {
        let mut shifted = Vec::new();
        (-m..=m).map(|d| fit_into(&mut shifted, f64::from(d))).collect()
    } else {
        (-m..=m).into_par_iter().map_init(Vec::new, |shifted, d| fit_into(shifted, f64::from(d))).collect()
    };
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
