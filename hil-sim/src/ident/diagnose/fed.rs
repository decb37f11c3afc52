//! What the base model is fed through a chain of input transforms: the transformed input
//! and its kinematics (the zero-phase rate made again, then the core's estimator), kept for
//! the chains asked for last.
//!
//! A diagnosis refits hundreds of models, and most feed the base a chain it was fed before:
//! the recorded input itself for every additive candidate, the round's kept transforms for
//! every candidate of the next round, the same grid values of a lag for each contender's
//! profile. Making those again (a zero-phase filter and the estimator over every sample)
//! was a sixth of the time of `diagnose --model auto`; kept here they are made once, for
//! every contender of `auto` alike (their problems share one [`Feeds`]: with one each, a
//! 30 s, 2 kHz recording made 1,336 feeds of 1,001 chains). The values are the same to
//! the bit: a kept entry is what [`super::augment::Problem`] would make again, and a chain
//! matches only when its rates (the estimator, unless the rates are given) and every value
//! in it have the same bits.

use std::sync::{Arc, Mutex};

use super::transform::Transform;

/// Chains kept: the recorded input, the kept transforms of a few rounds and the grid values
/// of the profiles in flight, of every contender (each entry is 24 bytes per sample).
const KEPT: usize = 16;

/// The base model's feed for one chain of transforms.
pub struct Fed {
    /// The recorded input through the chain.
    pub x: Vec<f64>,
    /// The core's kinematics of `x`.
    pub kin: Vec<model_core::Kin>,
}

/// The [`KEPT`] feeds asked for last, the latest first; shared by every problem on the same
/// recording and cutoff ([`super::augment::Problem::sharing`], [`super::augment::Problem::on_rows`]).
#[derive(Default)]
pub struct Feeds(Mutex<Vec<(FedKey, Arc<Fed>)>>);

/// What a kept feed is told apart by: its rates and its chain.
type FedKey = (Rates, Key);

/// A chain of transforms as bits ([`key`]).
pub(super) type Key = Vec<(u8, u64)>;

/// The rate estimator a feed's kinematics come from, as bits; `None` when the rates are
/// given (the estimator's are then unused).
pub type Rates = Option<(u8, u32, u32)>;

/// [`Rates`] of the estimator `rate`.
pub fn rates(rate: model_core::control::RateSpec) -> Rates {
    use model_core::control::RateSpec;
    Some(match rate {
        RateSpec::Backward => (0, 0, 0),
        RateSpec::Filtered { fc } => (1, fc.to_bits(), 0),
        RateSpec::Kalman { q, r } => (2, q.to_bits(), r.to_bits()),
    })
}

/// A chain as bits: the kind of each transform and its value's bits (so `0.0` and `-0.0`,
/// which some transforms may treat alike, are still two chains).
pub(super) fn key(chain: &[Transform]) -> Key {
    chain
        .iter()
        .map(|t| match *t {
            Transform::Delay { delay_s } => (0, delay_s.to_bits()),
            Transform::Lag { tau_s } => (1, tau_s.to_bits()),
            Transform::Lag2 { tau_s } => (2, tau_s.to_bits()),
            Transform::Saturate { b_sat } => (3, b_sat.to_bits()),
            Transform::SaturateKnee { b_sat } => (4, b_sat.to_bits()),
            Transform::Offset { b_0 } => (5, b_0.to_bits()),
            Transform::Smooth { tau_s } => (6, tau_s.to_bits()),
        })
        .collect()
}

impl Feeds {
    /// The feed of `chain` with the rates `rates`: kept, or made by `make` and kept (not when
    /// `make` fails: a chain that diverges is tried again, as before).
    pub fn get_or_make(
        &self,
        rates: Rates,
        chain: &[Transform],
        make: impl FnOnce() -> Option<Fed>,
    ) -> Option<Arc<Fed>> {
        let k = (rates, key(chain));
        if let Ok(mut kept) = self.0.lock() {
            if let Some(i) = kept.iter().position(|(c, _)| *c == k) {
                // The latest asked for first.
                kept[..=i].rotate_right(1);
                return kept.first().map(|(_, fed)| Arc::clone(fed));
            }
        }
        // Made outside the lock: the columns of a Jacobian ask side by side.
        let fed = Arc::new(make()?);
        if let Ok(mut kept) = self.0.lock() {
            if let Some(i) = kept.iter().position(|(c, _)| *c == k) {
                kept.remove(i);
            }
            kept.insert(0, (k, Arc::clone(&fed)));
            kept.truncate(KEPT);
        }
        Some(fed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fed(v: f64) -> Option<Fed> {
        Some(Fed { x: vec![v], kin: vec![] })
    }

    #[test]
    fn a_chain_is_made_once_and_told_apart_by_its_bits() {
        let feeds = Feeds::default();
        let lag = [Transform::Lag { tau_s: 0.01 }];
        let made = std::cell::Cell::new(0);
        let make = |v| {
            made.set(made.get() + 1);
            fed(v)
        };
        let a = feeds.get_or_make(None, &lag, || make(1.0)).unwrap();
        let b = feeds.get_or_make(None, &lag, || make(2.0)).unwrap();
        assert!(Arc::ptr_eq(&a, &b) && made.get() == 1);
        // The same kind at another value, another kind at the same value, and -0.0 against 0.0.
        feeds.get_or_make(None, &[Transform::Lag { tau_s: 0.02 }], || make(3.0)).unwrap();
        feeds.get_or_make(None, &[Transform::Lag2 { tau_s: 0.01 }], || make(4.0)).unwrap();
        feeds.get_or_make(None, &[Transform::Offset { b_0: 0.0 }], || make(5.0)).unwrap();
        let neg = feeds.get_or_make(None, &[Transform::Offset { b_0: -0.0 }], || make(6.0)).unwrap();
        assert_eq!((made.get(), neg.x[0]), (5, 6.0));
        // The same chain from other rates is another feed; given rates are one.
        let backward = rates(model_core::control::RateSpec::Backward);
        let filtered = rates(model_core::control::RateSpec::Filtered { fc: 50.0 });
        feeds.get_or_make(backward, &lag, || make(8.0)).unwrap();
        let f = feeds.get_or_make(filtered, &lag, || make(9.0)).unwrap();
        let given = feeds.get_or_make(None, &lag, || make(10.0)).unwrap();
        assert_eq!((made.get(), f.x[0], given.x[0]), (7, 9.0, 1.0));
        // A failed make is not kept.
        assert!(feeds.get_or_make(None, &[], || None).is_none());
        assert_eq!(feeds.get_or_make(None, &[], || make(11.0)).unwrap().x[0], 11.0);
    }

    #[test]
    fn the_chain_asked_for_longest_ago_goes_first() {
        let feeds = Feeds::default();
        let delay = |i: usize| [Transform::Delay { delay_s: i as f64 }];
        for i in 0..KEPT {
            feeds.get_or_make(None, &delay(i), || fed(i as f64)).unwrap();
        }
        // Chain 0 asked for again, then one chain more: chain 1 is dropped, 0 kept.
        feeds.get_or_make(None, &delay(0), || fed(-1.0)).unwrap();
        feeds.get_or_make(None, &delay(KEPT), || fed(-1.0)).unwrap();
        let zero = feeds.get_or_make(None, &delay(0), || fed(-1.0)).unwrap();
        let one = feeds.get_or_make(None, &delay(1), || fed(-1.0)).unwrap();
        assert_eq!((zero.x[0], one.x[0]), (0.0, -1.0));
    }
}
