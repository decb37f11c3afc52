//! Error metrics of the papers, computed in f64.
//!
//! - `rmse`: root mean square error, output units.
//! - `r_rmse`: seed 000 eq. 20, `sqrt(Σ(y−ŷ)² / Σy²)`.
//! - `r2`: seed 000 eq. 23, `1 − Σ(y−ŷ)² / Σ(y−ȳ)²`.
//! - `gof`: seed 004 §2.4, `1 − NRMSE = 1 − sqrt(Σ(y−ŷ)² / Σ(y−ȳ)²)`.
//! - `e_t`, `e_x`, `e_xdot`: seed 001 eq. 18–20 (time, rate- and acceleration-weighted
//!   normalised errors), when the input's rate is known.
//! - `mean_dev`, `avg_dev`: seed 001 eq. 21–22 (samples with a zero measurement skipped).

use serde::Serialize;

/// All metrics of one comparison.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Metrics {
    pub n: usize,
    pub rmse: f64,
    pub r_rmse: f64,
    pub r2: f64,
    pub gof: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e_t: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e_x: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e_xdot: Option<f64>,
    pub mean_dev: f64,
    pub avg_dev: f64,
}

fn sq(v: f64) -> f64 {
    v * v
}

/// Metrics of `model` against `measured`. `dx`, `ddx`: the input's rate and its
/// derivative at each sample, for seed 001's E_x and E_ẋ.
pub fn metrics(measured: &[f64], model: &[f64], rates: Option<(&[f64], &[f64])>) -> Metrics {
    let n = measured.len().min(model.len());
    let pair = |k: usize| (measured[k], model[k]);
    let weights =
        rates.filter(|(dx, ddx)| dx.len() >= n && ddx.len() >= n).map(|(dx, ddx)| move |k: usize| (dx[k], ddx[k]));
    summed(n, pair, weights, rates.is_some())
}

/// [`metrics`] of the samples `rows` (indices into every slice), without copying them out:
/// the same sums in the same order, so the same figures as [`metrics`] of the picked samples.
pub fn metrics_at(rows: &[usize], measured: &[f64], model: &[f64], rates: Option<(&[f64], &[f64])>) -> Metrics {
    let at = |v: &[f64], k: usize| rows.get(k).and_then(|&i| v.get(i)).copied().unwrap_or(f64::NAN);
    let pair = |k: usize| (at(measured, k), at(model, k));
    let weights = rates.map(|(dx, ddx)| move |k: usize| (at(dx, k), at(ddx, k)));
    summed(rows.len(), pair, weights, rates.is_some())
}

/// The metrics of `n` pairs (measured, model) given by `pair`, with the input's rate and
/// acceleration by `weights` when known; `rated`: a rate was given (E_t is reported).
fn summed(
    n: usize,
    pair: impl Fn(usize) -> (f64, f64),
    weights: Option<impl Fn(usize) -> (f64, f64)>,
    rated: bool,
) -> Metrics {
    if n == 0 {
        return Metrics::default();
    }
    let mean = (0..n).map(|k| pair(k).0).sum::<f64>() / n as f64;
    let sse: f64 = (0..n).map(&pair).map(|(a, b)| sq(a - b)).sum();
    let sst: f64 = (0..n).map(|k| sq(pair(k).0 - mean)).sum();
    let ssy: f64 = (0..n).map(|k| sq(pair(k).0)).sum();
    let ratio = |num: f64, den: f64| if den > 0.0 { num / den } else { f64::NAN };
    let (mut md, mut ad, mut nd) = (0.0, 0.0, 0usize);
    for (a, b) in (0..n).map(&pair) {
        if a != 0.0 {
            let d = (a - b) / a;
            md += d.abs();
            ad += d;
            nd += 1;
        }
    }
    let weighted = |w: &dyn Fn(usize) -> f64| {
        let num: f64 = (0..n).map(|k| (pair(k), w(k))).map(|((a, b), w)| sq(a - b) * w.abs()).sum();
        let den: f64 = (0..n).map(|k| sq(pair(k).0 - mean) * w(k).abs()).sum();
        ratio(num, den).sqrt()
    };
    let (e_x, e_xdot) = match &weights {
        Some(w) => (Some(weighted(&|k| w(k).0)), Some(weighted(&|k| w(k).1))),
        None => (None, None),
    };
    let nrmse = ratio(sse, sst).sqrt();
    Metrics {
        n,
        rmse: (sse / n as f64).sqrt(),
        r_rmse: ratio(sse, ssy).sqrt(),
        r2: 1.0 - ratio(sse, sst),
        gof: 1.0 - nrmse,
        e_t: rated.then_some(nrmse),
        e_x,
        e_xdot,
        mean_dev: if nd > 0 { md / nd as f64 } else { 0.0 },
        avg_dev: if nd > 0 { ad / nd as f64 } else { 0.0 },
    }
}

/// Comparisons over no sample have no score.
#[derive(Clone, Copy, Debug, thiserror::Error, PartialEq)]
#[error("no sample to score")]
pub struct NoSamples;

/// [`metrics`], refusing an empty comparison (which would read as a perfect score).
pub fn try_metrics(measured: &[f64], model: &[f64], rates: Option<(&[f64], &[f64])>) -> Result<Metrics, NoSamples> {
    if measured.is_empty() || model.is_empty() {
        return Err(NoSamples);
    }
    Ok(metrics(measured, model, rates))
}

/// R-RMSE (seed 000 eq. 20) of `a` against the reference `reference`.
pub fn r_rmse(reference: &[f64], a: &[f64]) -> f64 {
    metrics(reference, a, None).r_rmse
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_rows_are_those_of_the_picked_samples() {
        let y: Vec<f64> = (0..50).map(|i| (i as f64 * 0.3).sin() + 0.1).collect();
        let m: Vec<f64> = y.iter().enumerate().map(|(i, v)| v + 0.01 * (i % 7) as f64 - 0.02).collect();
        let dx: Vec<f64> = (0..50).map(|i| (i as f64 * 0.3).cos()).collect();
        let rows: Vec<usize> = (3..47).filter(|i| i % 3 != 0).collect();
        let pick = |v: &[f64]| -> Vec<f64> { rows.iter().map(|&i| v[i]).collect() };
        let want = metrics(&pick(&y), &pick(&m), Some((&pick(&dx), &pick(&y))));
        assert_eq!(metrics_at(&rows, &y, &m, Some((&dx, &y))), want);
        assert_eq!(metrics_at(&rows, &y, &m, None), metrics(&pick(&y), &pick(&m), None));
        assert!(want.e_x.is_some() && want.n == rows.len());
    }

    #[test]
    fn perfect_and_known_errors() {
        let y = [1.0, 2.0, 3.0, 4.0];
        let m = metrics(&y, &y, None);
        assert_eq!(m.rmse, 0.0);
        assert_eq!(m.r2, 1.0);
        assert_eq!(m.gof, 1.0);
        // Constant error of 1: rmse 1, r_rmse = sqrt(4/30), r2 = 1 − 4/5.
        let e = [2.0, 3.0, 4.0, 5.0];
        let m = metrics(&y, &e, None);
        assert!((m.rmse - 1.0).abs() < 1e-12);
        assert!((m.r_rmse - (4.0f64 / 30.0).sqrt()).abs() < 1e-12);
        assert!((m.r2 - 0.2).abs() < 1e-12);
        assert!((m.gof - (1.0 - 0.8f64.sqrt())).abs() < 1e-12);
        assert!((m.avg_dev - (-(1.0 + 0.5 + 1.0 / 3.0 + 0.25) / 4.0)).abs() < 1e-12);
    }

    #[test]
    fn no_sample_is_no_score() {
        assert_eq!(try_metrics(&[], &[], None), Err(NoSamples));
        assert!(try_metrics(&[1.0], &[1.0], None).is_ok());
    }

    #[test]
    fn rate_weighted_errors_ignore_standstill() {
        // Error only where the rate is zero: E_x sees none of it.
        let y = [1.0, -1.0, 1.0, -1.0];
        let m = [1.0, -1.0, 3.0, -1.0];
        let dx = [1.0, 1.0, 0.0, 1.0];
        let r = metrics(&y, &m, Some((&dx, &dx)));
        assert_eq!(r.e_x, Some(0.0));
        assert!(r.e_t.is_some_and(|v| v > 0.0));
    }
}
