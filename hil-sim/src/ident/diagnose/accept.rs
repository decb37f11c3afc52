//! Stage 4 of a diagnosis, modelling: in the round's ranking, the first candidate that
//! lowers the training error, gains on the information criterion, passes the held-out
//! block test ([`super::significance`]) with a gain of at least
//! [`significance::MIN_FINDING_GAIN`] (and [`significance::MIN_FINDING_DROP`] of the output),
//! changes the prediction by more than the
//! residual's noise floor resolves and is physically possible ([`super::physical`]) is
//! kept; every candidate is recorded as tested. One that meets all of it but the block
//! test, and would predict the tail best, is given the reversed split ([`super::replicate`]).
//! When none is kept, one the tail barely excites is given the split where it acts
//! ([`super::acting`]).

use super::acting::{self, Acting};
use super::augment::{Fitted, Problem};
use super::candidates::Candidate;
use super::diagnosis::{Finding, Tested};
use super::lag_or_delay::{self, Mixture, Side};
use super::physical::Reading;
use super::rank::Scored;
use super::replicate::{self, Replication, Reversed};
use super::significance::{self, Test};
use super::zero_phase;
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
    /// What it stands for ([`super::physical::reading`]).
    pub reading: Reading,
    pub test: Test,
    pub after: Metrics,
    /// The reversed split, when the tail alone did not settle it.
    pub replication: Option<Replication>,
    /// The field lag and the delay given together, when that settled a tie between them.
    pub lag_or_delay: Option<Mixture>,
    /// The split where it acts, when the tail barely excited it.
    pub acting: Option<Acting>,
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

    /// Judge the `ranked` candidates of round `round` (1-based) of `prob` against `reference`: of the
    /// eligible ones (a training gain, significant on the held-out blocks, resolvable above
    /// the noise, physically possible, not read as the effect of a finding `named` in an earlier round), the
    /// one with the lowest held-out error is kept — the
    /// term that predicts data it was not fitted on best, not the one that fits the
    /// training part best (a wrong term on a misfitting base can fit more and predict less).
    /// The candidates that would predict better still but miss only the block test get the
    /// reversed split, best first ([`replicate`]), and so do the best and another effect's
    /// eligible candidates within [`replicate::NEAR`] of its held-out error: of those, the one
    /// that predicts both held-out parts best is kept.
    pub fn round(
        &self,
        round: usize,
        prob: &Problem<'_>,
        cands: &[Candidate],
        reference: &Fitted,
        ranked: Vec<Scored>,
        named: &[Finding],
    ) -> Verdict {
        let before = self.heldout(&reference.pred);
        let mut tested = Vec::with_capacity(ranked.len());
        // Per candidate: every condition but the block test met, the block test passed.
        let mut judged = Vec::with_capacity(ranked.len());
        for s in ranked {
            let (c, f) = (&cands[s.index], &s.fitted);
            let test = significance::test(self.y, &reference.pred, &f.pred, self.held);
            let after = self.heldout(&f.pred);
            // What the term changes in the prediction must be resolvable above the noise.
            let change_of_noise = acting::rms_change(&f.pred, &reference.pred, self.rows) / self.noise_rms.max(1e-300);
            let resolvable = change_of_noise >= significance::MIN_TERM_OF_NOISE;
            let (n_old, x) = (reference.terms.len(), &prob.data.input);
            let impossible = super::physical::impossible(c, f, n_old, s.value, self.dt, x);
            let reading = super::physical::reading(c, f, n_old, x);
            let fits = impossible.is_none() && s.bic_gain > 0.0 && f.train_mse < reference.train_mse && resolvable;
            let tail_share = acting::tail_share(&f.pred, &reference.pred, self.held, &prob.train);
            let named_before = named.iter().any(|n| n.effect == reading.effect);
            let otherwise = fits
                && !named_before
                && test.gain >= significance::MIN_FINDING_GAIN
                && before.r_rmse - after.r_rmse >= significance::MIN_FINDING_DROP;
            tested.push(Tested {
                round,
                effect: reading.effect.to_owned(),
                label: reading.label.clone(),
                value: c.grid_name.clone().map(|n| (n, s.value)),
                bic_gain: s.bic_gain,
                heldout_r_rmse_before: before.r_rmse,
                heldout_r_rmse_after: after.r_rmse,
                test,
                change_of_noise,
                tail_share,
                kept: false,
                impossible,
                named_before,
                replication: None,
                lag_or_delay: None,
                acting: None,
                zero_phase: None,
                barred: false,
            });
            let quiet = fits && tail_share < acting::QUIET_TAIL;
            let significant = test.significant;
            judged.push(Judged { otherwise, significant, quiet, tail_share, scored: s, test, after, reading });
        }
        let reversed = Reversed::new(prob, reference);
        // Candidates barred from being kept: a field lag that did not beat its zero-phase
        // control bars every field lag of the round, and the round chooses again.
        let mut barred = vec![false; judged.len()];
        let best = loop {
            let replicate = |k: usize| {
                let s = &judged[k].scored;
                let tail = significance::blocks(self.y, &reference.pred, &s.fitted.pred, self.held);
                reversed.replicate(&cands[s.index], s, &tail)
            };
            let effect = |k: usize| judged[k].reading.effect;
            let mixture = |lag: usize, delay: usize| {
                let (l, d) = (&judged[lag].scored, &judged[delay].scored);
                lag_or_delay::profile(prob, reference, (&cands[l.index], l), (&cands[d.index], d))
            };
            let best = choose(&judged, &barred, &mut tested, Ties { replicate, mixture, effect }).or_else(|| {
                let act = |k: usize| {
                    let j = &judged[k];
                    acting::acting(prob, reference, &cands[j.scored.index], &j.scored, j.tail_share)
                };
                where_it_acts(&judged, &barred, &mut tested, act)
            });
            let Some(k) = best.filter(|&k| effect(k) == "field_lag") else { break best };
            tested[k].zero_phase = zero_phase::control(prob, reference, &judged[k].scored, self.y, self.held);
            if tested[k].zero_phase.is_none_or(|c| c.passed) {
                break best;
            }
            for (i, (b, j)) in barred.iter_mut().zip(&judged).enumerate() {
                if j.reading.effect == "field_lag" {
                    *b = true;
                    tested[i].barred = i != k;
                }
            }
        };
        let accepted = best.map(|k| {
            tested[k].kept = true;
            let (replication, lag_or_delay, acting) = (tested[k].replication, tested[k].lag_or_delay, tested[k].acting);
            let Judged { scored, test, after, reading, .. } = judged.swap_remove(k);
            Accepted { scored, reading, test, after, replication, lag_or_delay, acting }
        });
        Verdict { before, tested, accepted }
    }
}

/// A candidate as judged: every condition but the block test met (`otherwise`), the block
/// test passed, its score, test, held-out metrics and what it stands for.
struct Judged {
    otherwise: bool,
    significant: bool,
    /// Every condition but the tail's met, and the tail barely excites it ([`acting`]).
    quiet: bool,
    tail_share: f64,
    scored: Scored,
    test: Test,
    after: Metrics,
    reading: Reading,
}

/// How [`choose`] breaks what the tail leaves open, per judged candidate: its reversed split,
/// the profile of a lag (first index) against a delay (second), its effect.
struct Ties<R, M, E> {
    replicate: R,
    mixture: M,
    effect: E,
}

/// The index of the candidate kept, if any: of the eligible ones and the best undecided one
/// that passes on the reversed split (`replicate`, recorded in `tested`), the lowest held-out
/// error; when other effects' eligible candidates (`effect`) come within
/// [`replicate::NEAR`] of it, the one the lag and the delay given together name when the tie
/// is between those two ([`lag_or_delay`]), else the one of them all with the best pooled gain.
fn choose<R, M, E>(judged: &[Judged], barred: &[bool], tested: &mut [Tested], ties: Ties<R, M, E>) -> Option<usize>
where
    R: Fn(usize) -> Option<Replication>,
    M: Fn(usize, usize) -> Option<Mixture>,
    E: Fn(usize) -> &'static str,
{
    let Ties { replicate, mixture, effect } = ties;
    let by_error = |a: &usize, b: &usize| judged[*a].after.rmse.total_cmp(&judged[*b].after.rmse);
    let open = |k: &usize| judged[*k].otherwise && !barred[*k];
    let mut eligible: Vec<usize> = (0..judged.len()).filter(open).filter(|&k| judged[k].significant).collect();
    let bar = eligible.iter().min_by(|a, b| by_error(a, b)).map_or(f64::INFINITY, |&k| judged[k].after.rmse);
    let mut undecided: Vec<usize> =
        (0..judged.len()).filter(open).filter(|&k| !judged[k].significant && judged[k].after.rmse < bar).collect();
    undecided.sort_by(by_error);
    for k in undecided.into_iter().take(replicate::MAX_TRIED) {
        tested[k].replication = replicate(k);
        if tested[k].replication.is_some_and(|r| r.passed) {
            eligible.push(k);
            break;
        }
    }
    let best = eligible.iter().copied().min_by(by_error)?;
    // Another effect's eligible term within `NEAR` of the best on the tail: the tail alone
    // cannot tell them apart, and both splits together decide.
    let near: Vec<usize> = eligible
        .iter()
        .copied()
        .filter(|&k| {
            k != best
                && effect(k) != effect(best)
                && judged[k].after.rmse <= (1.0 + replicate::NEAR) * judged[best].after.rmse
        })
        .collect();
    if near.is_empty() {
        return Some(best);
    }
    if let Some(k) = lag_against_delay(best, &near, judged, tested, mixture, &effect) {
        return Some(k);
    }
    for &k in near.iter().chain([&best]) {
        if tested[k].replication.is_none() {
            tested[k].replication = replicate(k);
        }
    }
    // Without the best one's own reversed split there is nothing to weigh a rival against.
    let pooled = |k: usize| tested[k].replication.map(|r| r.both.gain);
    let Some(bar) = pooled(best) else { return Some(best) };
    let winner = near
        .iter()
        .filter_map(|&k| pooled(k).map(|g| (k, g)))
        .filter(|&(_, g)| g > bar)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k);
    Some(winner.unwrap_or(best))
}

/// When a round keeps nothing: of the candidates the tail barely excites, the first (by
/// training gain) that passes on the split where it acts (`act`, recorded in `tested`).
fn where_it_acts(
    judged: &[Judged],
    barred: &[bool],
    tested: &mut [Tested],
    act: impl Fn(usize) -> Option<Acting>,
) -> Option<usize> {
    let mut quiet: Vec<usize> = (0..judged.len()).filter(|&k| judged[k].quiet && !barred[k]).collect();
    quiet.sort_by(|a, b| judged[*b].scored.bic_gain.total_cmp(&judged[*a].scored.bic_gain));
    for k in quiet.into_iter().take(acting::MAX_TRIED) {
        tested[k].acting = act(k);
        if tested[k].acting.is_some_and(|a| a.passed) {
            return Some(k);
        }
    }
    None
}

/// When the tie is a field lag against a delay of the torque and nothing else, the one the
/// two given together name ([`lag_or_delay`]), the profile recorded on both; `None` when the
/// tie is another or the profile does not say.
fn lag_against_delay(
    best: usize,
    near: &[usize],
    judged: &[Judged],
    tested: &mut [Tested],
    mixture: impl Fn(usize, usize) -> Option<Mixture>,
    effect: impl Fn(usize) -> &'static str,
) -> Option<usize> {
    let all: Vec<usize> = near.iter().copied().chain([best]).collect();
    if all.iter().any(|&k| !matches!(effect(k), "field_lag" | "transport_delay")) {
        return None;
    }
    let first = |e: &str| {
        all.iter()
            .copied()
            .filter(|&k| effect(k) == e)
            .min_by(|a, b| judged[*a].after.rmse.total_cmp(&judged[*b].after.rmse))
    };
    let (lag, delay) = (first("field_lag")?, first("transport_delay")?);
    let m = mixture(lag, delay)?;
    tested[lag].lag_or_delay = Some(m);
    tested[delay].lag_or_delay = Some(m);
    match m.side()? {
        Side::Lag => Some(lag),
        Side::Delay => Some(delay),
    }
}
