//! A second split for a candidate the held-out tail leaves undecided.
//!
//! The tail of a short recording is short: a term that predicts it 40–60 % better can still
//! fail the paired block test ([`super::significance`]: ten blocks of a tenth of a second,
//! some of them quiet). Such a candidate (every other condition of [`super::accept`] met,
//! its tail gain at least [`significance::MIN_FINDING_GAIN`]) is refitted with the round's
//! reference on the split reversed ([`super::base::reversed_rows`]: the head held out, the
//! rest trained on) and kept when the head gains at least as much and the blocks of both
//! splits together pass the same test ([`significance::pooled`]). A chance gain on the
//! tail must then repeat on a part of the recording the first fit trained on and the
//! second does not see.
//!
//! Two eligible candidates of different effects within [`NEAR`] of each other on the tail
//! (a two-pole field lag and a delay of the torque: at a 1–9 Hz excitation the same phase,
//! a few per cent apart in amplitude) are told apart on both splits: the one whose pooled
//! error over the tail and the head is lower is kept.

use std::sync::OnceLock;

use serde::Serialize;

use super::augment::{Fitted, Problem};
use super::base::reversed_rows;
use super::candidates::Candidate;
use super::rank::{Scored, POLISH_ITERATIONS, SCREEN_ITERATIONS};
use super::refit::refit_candidate;
use super::significance::{self, Blocks, Test};

/// Undecided candidates of one round given the reversed split, at most.
pub const MAX_TRIED: usize = 3;
/// Eligible candidates of other effects within this share of the best one's held-out RMSE
/// are told apart on both splits together.
pub const NEAR: f64 = 0.10;

/// A candidate on the reversed split.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Replication {
    /// The paired test on the head (trained on the rest).
    pub head: Test,
    /// The paired test over the blocks of the tail and of the head together, its gain the
    /// pooled one.
    pub both: Test,
    /// Whether it settles the candidate: `both` significant and the head's gain at least
    /// [`significance::MIN_FINDING_GAIN`].
    pub passed: bool,
}

/// The reversed split of one round: its problem, its held-out head and the round's
/// reference refitted on it (when first asked for).
pub struct Reversed<'p, 'a> {
    prob: Problem<'a>,
    held: Vec<usize>,
    reference: &'p Fitted,
    refitted: OnceLock<Option<Fitted>>,
}

impl<'p, 'a> Reversed<'p, 'a> {
    /// The reversed split of `prob`'s recording, for a round whose reference is `reference`.
    pub fn new(prob: &Problem<'a>, reference: &'p Fitted) -> Self {
        let (train, held) = reversed_rows(prob.data);
        Self { prob: prob.on_rows(train), held, reference, refitted: OnceLock::new() }
    }

    /// Candidate `c` (scored `s` on the tail, whose blocks were `tail`) refitted on the
    /// reversed split from its tail fit; `None` when a refit diverges or the head is too
    /// short to test.
    pub fn replicate(&self, c: &Candidate, s: &Scored, tail: &Blocks) -> Option<Replication> {
        if self.held.len() < 2 * significance::BLOCKS {
            return None;
        }
        let iterations = SCREEN_ITERATIONS + POLISH_ITERATIONS;
        let reference = self
            .refitted
            .get_or_init(|| {
                let r = self.reference;
                self.prob.refit(&r.transforms, &r.terms, None, &r.theta, iterations).map(|f| f.0)
            })
            .as_ref()?;
        let start = [(s.value, Some(s.fitted.theta.clone()))];
        let (f, _) = refit_candidate(&self.prob, c, reference, &start, iterations)?;
        let head = significance::blocks(&self.prob.data.output, &reference.pred, &f.pred, &self.held);
        let both = significance::pooled(tail, &head);
        let head = significance::judged(&head);
        let passed =
            both.significant && head.gain >= significance::MIN_FINDING_GAIN && f.train_mse < reference.train_mse;
        Some(Replication { head, both, passed })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::diagnose::tests::{recording, round_one};
    use crate::ident::diagnose::transform::Transform;

    /// The first-order field lag candidate of round 1 on a Bouc–Wen base, replicated on the
    /// reversed split of `data`.
    fn lag_replicated(data: &crate::ident::fit::Dataset) -> Replication {
        round_one(data, |prob, cands, reference, ranked| {
            let k = cands.iter().position(|c| c.label.starts_with("first-order lag")).unwrap();
            let s = ranked.iter().find(|s| s.index == k).unwrap();
            let (_, held) = crate::ident::diagnose::base::rows(data);
            let tail = significance::blocks(&data.output, &reference.pred, &s.fitted.pred, &held);
            Reversed::new(prob, reference).replicate(&cands[k], s, &tail).unwrap()
        })
    }

    #[test]
    fn a_lag_the_clutch_has_gains_on_the_head_too_and_one_it_lacks_does_not() {
        let real = lag_replicated(&recording(Some(Transform::Lag { tau_s: 0.004 }), 4));
        assert!(real.passed && real.head.gain > 0.2 && real.both.blocks == 20, "{real:?}");
        let none = lag_replicated(&recording(None, 5));
        assert!(!none.passed && none.head.gain < significance::MIN_FINDING_GAIN, "{none:?}");
    }
}
