//! The rate the diagnosis works at. A recording sampled faster than [`TARGET_HZ`] (5 and
//! 10 kHz clutch benches) is diagnosed on the means of blocks of `q` samples: every
//! catalog effect a clutch shows lives below a few hundred hertz (the labs' own low-pass is
//! at 100–400 Hz), while the profile's window, the noise floor from second differences and
//! the cost of every refit are counted in samples. At 10 kHz the profile saw the first
//! 1.2 s of a 4 s recording, and the blind bench named the concealed effect in 11 of 29
//! cases (32 of 39 at 500 Hz).
//!
//! A block mean is a zero-phase boxcar (its time is the block's mean time), applied alike to
//! every channel, so a delay between channels is kept; at 10 kHz and `q = 5` it passes
//! 100 Hz at 99.6 %. Blocks never straddle a run join; a block holding a flagged sample is
//! flagged, one holding a gross outlier is unusable, and one that straddles the split is
//! held out.

use crate::ident::dataset::{Dataset, RunSpan};

/// Highest sampling rate the diagnosis runs at, Hz.
pub const TARGET_HZ: f64 = 2000.0;

/// Samples per block for a step of `dt` seconds: `⌊1 / (dt · TARGET_HZ)⌋`, 1 when that is
/// below 2 (or `dt` is not a positive number).
pub fn factor(dt: f64) -> usize {
    let q = (1.0 / (dt * TARGET_HZ)).floor();
    if q.is_finite() && q >= 2.0 {
        q as usize
    } else {
        1
    }
}

/// A dataset on block means, with its auxiliary channels and the run joins mapped.
pub struct Decimated {
    pub data: Dataset,
    pub aux: Vec<(String, Vec<f64>)>,
    /// `boundaries` as block indices.
    pub boundaries: Vec<usize>,
}

/// `data` on the means of blocks of `q` samples within each run (the last block of a run
/// may be shorter); `aux` channels alike, `boundaries` (sample indices) mapped to blocks.
pub fn decimate(data: &Dataset, aux: Vec<(String, Vec<f64>)>, boundaries: &[usize], q: usize) -> Decimated {
    let q = q.max(1);
    let spans = data.spans();
    // The blocks, as sample ranges, run by run, and each run's span in blocks.
    let mut blocks: Vec<std::ops::Range<usize>> = Vec::new();
    let mut runs = Vec::with_capacity(spans.len());
    for s in &spans {
        let start = blocks.len();
        let mut a = s.start;
        while a < s.end {
            let b = (a + q).min(s.end);
            blocks.push(a..b);
            a = b;
        }
        let train_end = start + (s.train_end.saturating_sub(s.start)) / q;
        runs.push(RunSpan { start, train_end, end: blocks.len(), ..s.clone() });
    }
    let mean = |v: &[f64]| -> Vec<f64> {
        blocks
            .iter()
            .map(|r| {
                let part = v.get(r.clone()).unwrap_or(&[]);
                part.iter().sum::<f64>() / part.len().max(1) as f64
            })
            .collect()
    };
    let block_of = |i: usize| blocks.partition_point(|r| r.end <= i);
    let mut unusable: Vec<usize> = data.unusable.iter().map(|&i| block_of(i)).collect();
    unusable.dedup();
    let excluded = blocks.iter().map(|r| data.excluded.get(r.clone()).is_some_and(|e| e.iter().any(|&x| x))).collect();
    let single = data.runs.is_empty();
    let out = Dataset {
        dt: data.dt * q as f64,
        time: mean(&data.time),
        input: mean(&data.input),
        output: mean(&data.output),
        command: data.command.as_deref().map(mean),
        train_end: runs.first().map_or(0, |r| r.train_end),
        excluded,
        unusable,
        rates: data.rates.as_ref().map(|(r, a)| (mean(r), mean(a))),
        runs: if single { Vec::new() } else { runs },
    };
    let aux = aux.into_iter().map(|(name, v)| (name, mean(&v))).collect();
    let boundaries = boundaries.iter().map(|&i| block_of(i)).collect();
    Decimated { data: out, aux, boundaries }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dataset(n: usize, dt: f64) -> Dataset {
        let time: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let mut excluded = vec![false; n];
        excluded[7] = true;
        Dataset {
            dt,
            input: time.iter().map(|t| (40.0 * t).sin()).collect(),
            output: time.iter().map(|t| 2.0 * (40.0 * t).sin()).collect(),
            time,
            command: None,
            train_end: 702,
            excluded,
            unusable: vec![13, 14, 998],
            rates: None,
            runs: Vec::new(),
        }
    }

    #[test]
    fn only_faster_recordings_are_decimated() {
        assert_eq!(factor(1e-4), 5);
        assert_eq!(factor(2e-4), 2);
        assert_eq!(factor(1.0 / 3000.0), 1);
        assert_eq!(factor(5e-4), 1);
        assert_eq!(factor(0.0), 1);
        assert_eq!(factor(f64::NAN), 1);
    }

    #[test]
    fn block_means_keep_time_split_flags_and_joins() {
        let d = dataset(1003, 1e-4);
        let aux = vec![("i".to_owned(), d.input.iter().map(|v| 3.0 * v).collect())];
        let r = decimate(&d, aux, &[500], 5);
        assert_eq!(r.data.len(), 201, "200 whole blocks and one of 3 samples");
        assert!((r.data.dt - 5e-4).abs() < 1e-15);
        // The block's mean time: 2 samples after its first.
        assert!((r.data.time[10] - 52.0 * 1e-4).abs() < 1e-12);
        assert!((r.data.time[200] - 1001.0 * 1e-4).abs() < 1e-12);
        // The block straddling the split (700..705, split at 702) is held out.
        assert_eq!(r.data.train_end, 140);
        assert_eq!(r.data.excluded.iter().filter(|&&e| e).count(), 1);
        assert!(r.data.excluded[1]);
        assert_eq!(r.data.unusable, vec![2, 199]);
        assert_eq!(r.boundaries, vec![100]);
        let (a, y) = (&r.aux[0].1, &r.data.output);
        assert!(a.iter().zip(&r.data.input).all(|(a, x)| (a - 3.0 * x).abs() < 1e-12));
        assert!(y.iter().zip(&r.data.input).all(|(y, x)| (y - 2.0 * x).abs() < 1e-12));
    }

    #[test]
    fn blocks_do_not_straddle_a_run_join() {
        let mut d = dataset(1000, 1e-4);
        let run = |start, train_end, end| RunSpan {
            file: std::path::PathBuf::new(),
            role: crate::io::manifest::Role::Train,
            start,
            train_end,
            end,
        };
        d.runs = vec![run(0, 300, 403), run(403, 800, 1000)];
        let r = decimate(&d, Vec::new(), &[], 5);
        let spans: Vec<(usize, usize, usize)> = r.data.runs.iter().map(|s| (s.start, s.train_end, s.end)).collect();
        // 403 samples: 80 whole blocks and one of 3; 597: 119 and one of 2.
        assert_eq!(spans, vec![(0, 60, 81), (81, 160, 201)]);
        assert_eq!(r.data.run_starts(), vec![0, 81]);
        assert!((r.data.time[81] - 405.0 * 1e-4).abs() < 1e-12, "the second run's first block starts at its start");
    }
}
