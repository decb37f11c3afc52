//! Why two scores of one fit differ, said in a sentence next to them: the held-out score
//! over every sample against the one over the samples the quality checks did not flag, and
//! a held-out error below the training error because the held-out part moves less (a
//! standstill, a calmer stretch).

use crate::ident::dataset::Dataset;
use crate::ident::fit::FitResult;
use crate::numerics::number::with_unit;
use crate::numerics::stats::{min_max, std};

/// Fraction of the overall span within which a channel counts as not moving.
const STILL_FRACTION: f64 = 0.02;

/// The held-out scores of `r` with the sentences that explain them: `unit` is the output's
/// unit (`"N"`), `output` its name (`"F"`).
pub fn heldout_note(data: &Dataset, r: &FitResult, output: &str, unit: &str) -> String {
    let held = data.heldout_rows().len();
    let mut s = format!(
        "Held-out over all {held} samples: RMSE {}, R² {:.4}, R-RMSE {:.2} %.",
        with_unit(r.heldout.rmse, 4, unit),
        r.heldout.r2,
        100.0 * r.heldout.r_rmse
    );
    if let Some(u) = &r.heldout_unflagged {
        let flagged = held.saturating_sub(data.heldout_unflagged().len());
        let why = if u.rmse < r.heldout.rmse {
            "the flagged samples carry most of the error: the model was fitted without them and cannot follow \
             what the sensor did there (see the quality warnings: e.g. a clipped end stop, a dropout), so the \
             unflagged score is the one that says how well the model fits the physics it models"
        } else {
            "the flagged samples are easier to match than the rest (see the quality warnings: e.g. the input \
             standing still), so the score over every sample looks better than the model's fit of the motion; \
             the unflagged score is the one to compare with training"
        };
        s += &format!(
            " Over the {} held-out samples the quality checks did not flag: RMSE {}, R² {:.4}. The two differ \
             because {flagged} held-out samples are flagged and {why}.",
            held.saturating_sub(flagged),
            with_unit(u.rmse, 4, unit),
            u.r2
        );
    }
    if r.heldout.rmse < r.train.rmse {
        s += &calmer_heldout(data, r, output, unit);
    }
    s
}

/// Why the held-out RMSE is below the training RMSE: the parts' spreads, and the longest
/// standstill of the input in the held-out samples (of every run, in order).
fn calmer_heldout(data: &Dataset, r: &FitResult, output: &str, unit: &str) -> String {
    let rows = data.heldout_rows();
    let pick = |v: &[f64], rows: &[usize]| -> Vec<f64> { rows.iter().filter_map(|&i| v.get(i).copied()).collect() };
    let train_rows: Vec<usize> = (0..data.len()).filter(|&i| data.is_train(i)).collect();
    let (train, held) = (pick(&data.output, &train_rows), pick(&data.output, &rows));
    let (sd_t, sd_h) = (std(&train), std(&held));
    let still = longest_still(&pick(&data.input, &rows), span(&data.input)) as f64 * data.dt;
    let standstill = if still >= 0.5 {
        format!(
            " (the input stands still for {} of its {})",
            with_unit(still, 3, "s"),
            with_unit(held.len() as f64 * data.dt, 3, "s")
        )
    } else {
        String::new()
    };
    format!(
        " The held-out RMSE is below the training RMSE because the held-out part moves less: {output} spreads \
         {} (standard deviation) there against {} in training{standstill}. R-RMSE divides by each part's own \
         spread and compares them fairly: {:.2} % held-out against {:.2} % in training.",
        with_unit(sd_h, 3, unit),
        with_unit(sd_t, 3, unit),
        100.0 * r.heldout.r_rmse,
        100.0 * r.train.r_rmse
    )
}

fn span(v: &[f64]) -> f64 {
    let (lo, hi) = min_max(v);
    if hi > lo {
        hi - lo
    } else {
        0.0
    }
}

/// Samples in the longest stretch of `v` that stays within [`STILL_FRACTION`] of `span`.
fn longest_still(v: &[f64], span: f64) -> usize {
    let tol = STILL_FRACTION * span;
    let (mut best, mut start, mut lo, mut hi) = (0usize, 0usize, f64::INFINITY, f64::NEG_INFINITY);
    for (i, &x) in v.iter().enumerate() {
        lo = lo.min(x);
        hi = hi.max(x);
        if hi - lo > tol {
            (start, lo, hi) = (i, x, x);
        }
        best = best.max(i + 1 - start);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standstill_is_the_longest_quiet_stretch() {
        let mut v: Vec<f64> = (0..100).map(|i| (i as f64 * 0.7).sin()).collect();
        v.extend(std::iter::repeat_n(0.3, 40));
        v.extend((0..20).map(|i| (i as f64).cos()));
        let n = longest_still(&v, 2.0);
        assert!((40..=42).contains(&n), "{n}");
        assert_eq!(longest_still(&[], 1.0), 0);
    }
}
