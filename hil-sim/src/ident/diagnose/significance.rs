//! When a held-out gain is more than chance: a one-sided paired test over contiguous
//! blocks of the held-out part, plus a minimum size.
//!
//! The held-out samples are cut into [`BLOCKS`] contiguous blocks; in each, the drop in
//! mean squared error from the reference to the candidate is one observation. Blocks are
//! long (seconds), so the residual's own correlation stays mostly inside a block and the
//! block means are close to independent. The candidate is kept when the mean drop is
//! [`T_MIN`] standard errors above zero (one-sided p ≈ 0.8 % for 9 degrees of freedom,
//! about 8 % family-wise over the ten or so candidates of a round), or when Wilcoxon's
//! signed-rank test on the same drops gives p ≤ [`P_RANK_MAX`] (a gain that nearly every
//! block shows, but of very different sizes: a held-out sweep, whose blocks are different
//! frequencies, gave t < 3 for a 40 % gain), **and** the held-out
//! RMSE falls by at least [`MIN_GAIN`]: a recording with nothing missing should produce no
//! finding, not a statistically real but useless one. The diagnosis also asks that what
//! the term changes in the prediction (RMS) be at least [`MIN_TERM_OF_NOISE`] × the
//! residual's sample-to-sample noise floor: a change smaller than one sample's noise is
//! below what the recording resolves, however significant its average. A term kept as a
//! finding must gain at least [`MIN_FINDING_GAIN`] and lower the held-out R-RMSE by at least
//! [`MIN_FINDING_DROP`] of the output; [`MIN_GAIN`] stays the bar of the test
//! itself (which also compares the contending bases' first rounds). A candidate the tail
//! alone leaves undecided can be tested again on the recording's head ([`super::replicate`]),
//! the blocks of both splits [`pooled`].

use serde::Serialize;

/// Held-out blocks of the paired test.
pub const BLOCKS: usize = 10;
/// Smallest t statistic of the mean per-block drop in squared error.
pub const T_MIN: f64 = 3.0;
/// Smallest relative drop of the held-out RMSE.
pub const MIN_GAIN: f64 = 0.03;
/// Smallest relative drop of the held-out RMSE for a term to be kept as a finding.
/// Calibrated on 96 null and 480 effect recordings of the bench (development, fresh2 and
/// fresh3 seeds, 2026-11-27): of the findings kept at [`MIN_GAIN`], 4 of the 9 on null
/// recordings gained less than 7 %, none of the 434 right ones did. Raised to 10 % on the
/// fresh17–fresh26 runs (400 nulls, 2,000 effect cases, development since their reports,
/// 2026-11-28): 4 of the 9 first findings on nulls gained 7–9 %, 3 of the 1,582 right ones did.
pub const MIN_FINDING_GAIN: f64 = 0.10;
/// Smallest drop of the held-out R-RMSE (seed 000 eq. 20, a share of the output's RMS) for a
/// term to be kept as a finding: 0.05 % of the output, sixty times below the smallest effect
/// the bench conceals (3 % of the span). Below it the term polishes a base model that already
/// predicts to a few tenths of a per cent, it does not add missing physics. Calibrated on the
/// kept first findings of the fresh2–fresh10 runs (2026-11-27): 1 of the 1,612 right ones
/// dropped less, and 7 of the 30 on null recordings and 9 of the 97 naming the wrong effect.
pub const MIN_FINDING_DROP: f64 = 0.0005;
/// Smallest RMS change of the prediction, in units of the residual's noise floor.
pub const MIN_TERM_OF_NOISE: f64 = 0.75;
/// Largest one-sided p of the signed-rank test that counts as significant on its own
/// (about the t test's at [`T_MIN`]).
pub const P_RANK_MAX: f64 = 0.005;

/// The outcome of one paired test.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Test {
    /// Mean per-block drop in squared error over its standard error.
    pub t: f64,
    /// Relative drop of the held-out RMSE, `1 − rmse_after / rmse_before`.
    pub gain: f64,
    /// Blocks whose error dropped.
    pub blocks_better: usize,
    pub blocks: usize,
    /// One-sided p of Wilcoxon's signed-rank test on the per-block drops (exact).
    pub p_rank: f64,
    pub significant: bool,
}

/// The per-block drops of one held-out split, and its summed squared errors.
#[derive(Clone, Debug)]
pub struct Blocks {
    /// Drop in mean squared error, reference to candidate, per contiguous block.
    pub drops: Vec<f64>,
    /// Summed squared error of the reference and of the candidate.
    pub before: f64,
    pub after: f64,
}

/// The [`BLOCKS`] contiguous blocks of the held-out `rows` of `y`, `before` against `after`
/// (predictions).
pub fn blocks(y: &[f64], before: &[f64], after: &[f64], rows: &[usize]) -> Blocks {
    let n = rows.len();
    let k = BLOCKS.min(n / 2).max(1);
    let mut out = Blocks { drops: Vec::with_capacity(k), before: 0.0, after: 0.0 };
    for b in 0..k {
        let chunk = &rows[b * n / k..(b + 1) * n / k];
        let (mut eb, mut ea) = (0.0, 0.0);
        for &i in chunk {
            eb += (y[i] - before[i]).powi(2);
            ea += (y[i] - after[i]).powi(2);
        }
        out.before += eb;
        out.after += ea;
        out.drops.push((eb - ea) / chunk.len().max(1) as f64);
    }
    out
}

/// Test `after` against `before` (predictions) on the held-out `rows` of `y`.
pub fn test(y: &[f64], before: &[f64], after: &[f64], rows: &[usize]) -> Test {
    judged(&blocks(y, before, after, rows))
}

/// The paired test over the blocks of two held-out splits together ([`super::replicate`]);
/// its gain is the pooled one.
pub fn pooled(a: &Blocks, b: &Blocks) -> Test {
    let drops = a.drops.iter().chain(&b.drops).copied().collect();
    judged(&Blocks { drops, before: a.before + b.before, after: a.after + b.after })
}

/// The test on the drops of `b`.
pub fn judged(b: &Blocks) -> Test {
    let drops = &b.drops;
    let k = drops.len() as f64;
    let mean = drops.iter().sum::<f64>() / k;
    let var = drops.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
    let se = (var / k).sqrt();
    let t = if se > 0.0 {
        mean / se
    } else if mean > 0.0 {
        f64::INFINITY
    } else {
        0.0
    };
    let gain = if b.before > 0.0 { 1.0 - (b.after / b.before).sqrt() } else { 0.0 };
    let p_rank = signed_rank_p(drops);
    Test {
        t,
        gain,
        blocks_better: drops.iter().filter(|d| **d > 0.0).count(),
        blocks: drops.len(),
        p_rank,
        significant: (t >= T_MIN || p_rank <= P_RANK_MAX) && gain >= MIN_GAIN,
    }
}

/// One-sided p of Wilcoxon's signed-rank test that the drops are positive: the chance,
/// with every sign equally likely, of a rank sum of the negative drops no larger than
/// observed (exact: the number of subsets of the ranks 1…k with a sum that small, counted
/// by dynamic programming; ties ranked by order, a zero drop counts as negative). Blocks of
/// very different sizes of gain (a sweep held out across its frequencies) give a low t for
/// a gain every block shows; this test reads the signs and the order of the drops, not
/// their spread.
fn signed_rank_p(drops: &[f64]) -> f64 {
    let k = drops.len();
    if k == 0 {
        return 1.0;
    }
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&a, &b| drops[a].abs().total_cmp(&drops[b].abs()));
    let w_neg: usize = order.iter().enumerate().filter(|(_, &j)| drops[j] <= 0.0).map(|(r, _)| r + 1).sum();
    // ways[s]: subsets of the ranks seen so far summing to s.
    let mut ways = vec![0.0f64; k * (k + 1) / 2 + 1];
    ways[0] = 1.0;
    for r in 1..=k {
        for s in (r..ways.len()).rev() {
            ways[s] += ways[s - r];
        }
    }
    ways[..=w_neg].iter().sum::<f64>() / 2f64.powi(k as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn a_real_gain_passes_and_noise_does_not() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let n = 20_000;
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin()).collect();
        let noise: Vec<f64> = (0..n).map(|_| rng.random::<f64>() - 0.5).collect();
        let noise2: Vec<f64> = (0..n).map(|_| rng.random::<f64>() - 0.5).collect();
        let rows: Vec<usize> = (0..n).collect();
        // A model missing a 0.3-amplitude term against one that has it: both see the noise.
        let before: Vec<f64> = y.iter().zip(&noise).map(|(y, e)| 0.7 * y + e).collect();
        let after: Vec<f64> = y.iter().zip(&noise).map(|(y, e)| y + e).collect();
        let t = test(&y, &before, &after, &rows);
        assert!(t.significant && t.gain > 0.15, "{t:?}");
        // Two models that differ only by independent noise of equal size.
        let other: Vec<f64> = y.iter().zip(&noise2).map(|(y, e)| y + e).collect();
        let t = test(&y, &after, &other, &rows);
        assert!(!t.significant, "{t:?}");
    }

    #[test]
    fn the_signed_rank_p_is_exact() {
        // All ten drops positive: 1 of 1024 sign patterns has a negative rank sum of 0.
        let all: Vec<f64> = (1..=10).map(f64::from).collect();
        assert!((signed_rank_p(&all) - 1.0 / 1024.0).abs() < 1e-15);
        // The smallest negative: rank sums 0 and 1 → 2 of 1024.
        let mut one = all.clone();
        one[0] = -1.0;
        assert!((signed_rank_p(&one) - 2.0 / 1024.0).abs() < 1e-15);
        // Half of them negative, the largest ones: far from significant.
        let half: Vec<f64> = (1..=10).map(|v| if v > 5 { -f64::from(v) } else { f64::from(v) }).collect();
        assert!(signed_rank_p(&half) > 0.9);
    }

    #[test]
    fn the_counted_p_is_the_enumerated_one() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(9);
        for k in 1..=12usize {
            let drops: Vec<f64> = (0..k).map(|_| rng.random::<f64>() - 0.3).collect();
            let mut order: Vec<usize> = (0..k).collect();
            order.sort_by(|&a, &b| drops[a].abs().total_cmp(&drops[b].abs()));
            let w: usize = order.iter().enumerate().filter(|(_, &j)| drops[j] <= 0.0).map(|(r, _)| r + 1).sum();
            let sum_of = |m: u32| (0..k).filter(|r| m & (1 << r) != 0).map(|r| r + 1).sum::<usize>();
            let at_most = (0u32..1 << k).filter(|&m| sum_of(m) <= w).count();
            assert!((signed_rank_p(&drops) - at_most as f64 / f64::from(1u32 << k)).abs() < 1e-12, "k {k}");
        }
    }

    #[test]
    fn two_splits_pooled_are_one_test_over_all_their_blocks() {
        let a = Blocks { drops: vec![1.0, 2.0, 0.5], before: 10.0, after: 6.0 };
        let b = Blocks { drops: vec![0.7, -0.1], before: 5.0, after: 4.0 };
        let t = pooled(&a, &b);
        assert_eq!((t.blocks, t.blocks_better), (5, 4));
        assert!((t.gain - (1.0 - (10.0f64 / 15.0).sqrt())).abs() < 1e-12);
        // Twenty blocks that all gain are significant; neither ten alone can reach that p.
        let ten = Blocks { drops: (1..=10).map(f64::from).collect(), before: 2.0, after: 1.0 };
        assert!(pooled(&ten, &ten).p_rank < 1e-5 && judged(&ten).p_rank > 1e-4);
    }

    #[test]
    fn a_gain_every_block_shows_is_significant_however_uneven() {
        // Drops of 1 to 10⁹ (t ≈ 1.3): the t test misses it, the signed-rank test does not.
        let n = 1000;
        let y = vec![0.0; n];
        let after = vec![0.01; n];
        let before: Vec<f64> = (0..n).map(|i| 0.01 + 10f64.powi((i / 100) as i32)).collect();
        let rows: Vec<usize> = (0..n).collect();
        let t = test(&y, &before, &after, &rows);
        assert!(t.t < T_MIN && t.p_rank < P_RANK_MAX && t.significant, "{t:?}");
    }
}
