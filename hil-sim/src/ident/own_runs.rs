//! Seed 000 averages each model's per-recording fits; averaging is only meaningful when the
//! fits agree. This check replays the averaged set on the held-out part of the recordings it
//! came from and compares its squared error with the recordings' own fits, sample by sample:
//! when the averaged set is worse by more than chance, the per-run fits compensate each other
//! (one parameter up where another goes down) and the average is not a model of the device.
//!
//! "More than chance": the paired difference of squared residuals `d = e_avg² − e_own²` is
//! averaged in blocks (20 per recording, so that neighbouring samples' correlation stays
//! inside a block) and the mean of the block means is compared with its standard error: more
//! than 3 standard errors above zero is not chance.

use serde::Serialize;

/// The averaged set against the recordings' own fits, on their held-out parts.
#[derive(Clone, Debug, Serialize)]
pub struct OwnRunsCheck {
    /// RMSE of the averaged set over the held-out parts of the identification recordings.
    pub averaged_rmse: f64,
    /// RMSE of each recording's own fit there (pooled).
    pub own_rmse: f64,
    /// (mean squared-error difference) / (its standard error); > 3 is not chance.
    pub z: f64,
    /// Whether the averaged set is worse than the own fits by more than chance.
    pub worse: bool,
}

/// Blocks per recording for the standard error.
const BLOCKS: usize = 20;
/// Standard errors above zero that are not chance.
const Z_LIMIT: f64 = 3.0;

/// One recording's part of the check: measured output, its own fit's output, the averaged
/// set's output, and the samples to compare on.
pub type Part<'a> = (&'a [f64], &'a [f64], &'a [f64], Vec<usize>);

/// Compare, per recording, the residuals of the averaged set (`avg`) and of the recording's
/// own fit (`own`) against the measured `y`, on `rows`. Each item is `(y, own, avg, rows)`.
pub fn check(parts: &[Part<'_>]) -> Option<OwnRunsCheck> {
    let (mut sa, mut so, mut n) = (0.0, 0.0, 0usize);
    let mut blocks = Vec::new();
    for (y, own, avg, rows) in parts {
        let d: Vec<f64> = rows
            .iter()
            .filter_map(|&i| {
                let (y, o, a) = (y.get(i)?, own.get(i)?, avg.get(i)?);
                sa += (a - y).powi(2);
                so += (o - y).powi(2);
                n += 1;
                Some((a - y).powi(2) - (o - y).powi(2))
            })
            .collect();
        let size = (d.len() / BLOCKS).max(1);
        blocks.extend(d.chunks(size).filter(|c| c.len() == size).map(|c| c.iter().sum::<f64>() / size as f64));
    }
    if n == 0 || blocks.len() < 2 {
        return None;
    }
    let k = blocks.len() as f64;
    let mean = blocks.iter().sum::<f64>() / k;
    let var = blocks.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (k - 1.0);
    let se = (var / k).sqrt();
    let z = if se > 0.0 {
        mean / se
    } else if mean > 0.0 {
        f64::INFINITY
    } else {
        0.0
    };
    Some(OwnRunsCheck {
        averaged_rmse: (sa / n as f64).sqrt(),
        own_rmse: (so / n as f64).sqrt(),
        z,
        worse: z > Z_LIMIT,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worse_only_beyond_chance() {
        let n = 2000;
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin()).collect();
        // Own fits: small pseudo-random errors; a set equally good (other errors of the same size)
        // is chance, a set with a systematic error is not.
        let noise = |seed: u64| -> Vec<f64> {
            let mut s = seed;
            (0..n)
                .map(|_| {
                    s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    ((s >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.1
                })
                .collect()
        };
        let own: Vec<f64> = y.iter().zip(noise(1)).map(|(a, e)| a + e).collect();
        let same: Vec<f64> = y.iter().zip(noise(2)).map(|(a, e)| a + e).collect();
        let biased: Vec<f64> = same.iter().map(|v| v + 0.05).collect();
        let rows: Vec<usize> = (0..n).collect();
        let c = check(&[(&y, &own, &same, rows.clone())]).unwrap();
        assert!(!c.worse, "z {}", c.z);
        let c = check(&[(&y, &own, &biased, rows)]).unwrap();
        assert!(c.worse && c.averaged_rmse > c.own_rmse, "z {}", c.z);
    }
}
