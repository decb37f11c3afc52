//! Stage 4 of a diagnosis, modelling: in the round's ranking, the first candidate that
//! lowers the training error, gains on the information criterion, passes the held-out
//! block test ([`super::significance`]) with a gain of at least
//! [`significance::MIN_FINDING_GAIN`], changes the prediction by more than the
//! residual's noise floor resolves and is physically possible ([`super::physical`]) is
//! kept; every candidate is recorded as tested.

use super::augment::Fitted;
use super::candidates::Candidate;
use super::diagnosis::Tested;
use super::rank::Scored;
use super::significance::{self, Test};
use crate::numerics::metrics::{metrics, Metrics};

/// What a candidate is judged on: the recorded output, its held-out rows (the test), every
/// scored row (the size of a term) and the residual's noise floor.
pub struct Judge<'a> {
    pub y: &'a [f64],
    pub held: &'a [usize],
    pub rows: &'a [usize],
    pub noise_rms: f64,
    /// The sample interval, s.
    pub dt: f64,
}

/// The candidate kept in a round.
pub struct Accepted {
    pub scored: Scored,
    pub test: Test,
    pub after: Metrics,
}

/// A round's outcome: every candidate as tested and the one kept, if any.
pub struct Verdict {
    /// The reference's held-out metrics.
    pub before: Metrics,
    pub tested: Vec<Tested>,
    pub accepted: Option<Accepted>,
}

impl Judge<'_> {
    /// The metrics of the prediction `pred` on the held-out rows.
    pub fn heldout(&self, pred: &[f64]) -> Metrics {
        let pick = |v: &[f64]| -> Vec<f64> { self.held.iter().map(|&i| v[i]).collect() };
        metrics(&pick(self.y), &pick(pred), None)
    }

    /// Judge the `ranked` candidates of round `round` (1-based) against `reference`: of the
    /// eligible ones (a training gain, significant on the held-out blocks, resolvable above
    /// the noise, physically possible), the one with the lowest held-out error is kept — the
    /// term that predicts data it was not fitted on best, not the one that fits the
    /// training part best (a wrong term on a misfitting base can fit more and predict less).
    pub fn round(&self, round: usize, cands: &[Candidate], reference: &Fitted, ranked: Vec<Scored>) -> Verdict {
        let before = self.heldout(&reference.pred);
        let mut tested = Vec::with_capacity(ranked.len());
        let mut judged = Vec::with_capacity(ranked.len());
        for s in ranked {
            let (c, f) = (&cands[s.index], &s.fitted);
            let test = significance::test(self.y, &reference.pred, &f.pred, self.held);
            let after = self.heldout(&f.pred);
            // What the term changes in the prediction must be resolvable above the noise.
            let change = (self.rows.iter().map(|&i| (f.pred[i] - reference.pred[i]).powi(2)).sum::<f64>()
                / self.rows.len().max(1) as f64)
                .sqrt();
            let change_of_noise = change / self.noise_rms.max(1e-300);
            let resolvable = change_of_noise >= significance::MIN_TERM_OF_NOISE;
            let impossible = super::physical::impossible(c, f, reference.terms.len(), s.value, self.dt);
            let eligible = impossible.is_none()
                && s.bic_gain > 0.0
                && f.train_mse < reference.train_mse
                && test.significant
                && test.gain >= significance::MIN_FINDING_GAIN
                && resolvable;
            tested.push(Tested {
                round,
                effect: c.effect.to_owned(),
                label: c.label.clone(),
                value: c.grid_name.clone().map(|n| (n, s.value)),
                bic_gain: s.bic_gain,
                heldout_r_rmse_before: before.r_rmse,
                heldout_r_rmse_after: after.r_rmse,
                test,
                change_of_noise,
                kept: false,
                impossible,
            });
            judged.push((eligible, s, test, after));
        }
        let best =
            (0..judged.len()).filter(|&k| judged[k].0).min_by(|&a, &b| judged[a].3.rmse.total_cmp(&judged[b].3.rmse));
        let accepted = best.map(|k| {
            tested[k].kept = true;
            let (_, s, test, after) = judged.swap_remove(k);
            Accepted { scored: s, test, after }
        });
        Verdict { before, tested, accepted }
    }
}
