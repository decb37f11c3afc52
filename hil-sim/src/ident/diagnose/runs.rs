//! The base model's outputs for the parameters it was run with last, kept for the runs that
//! come again.
//!
//! A diagnosis runs the base model tens of thousands of times, and some runs are asked for
//! again with the same parameters on the same feed: every candidate's first Jacobian is
//! taken at the round's reference, the Jacobian's column of a candidate's own value (a time
//! constant of its terms) leaves the base's parameters where they were, and a linearised
//! scan runs the reference once per grid value. On a 30 s, 2 kHz recording about a tenth of
//! the samples stepped were such repeats. A kept output is what the run would write again,
//! to the bit: the run is deterministic, and an entry matches only when its chain of
//! transforms, its parameters and its length have the same bits.

use std::sync::Mutex;

use super::fed::{key, Key};
use super::transform::Transform;

/// Most bytes of outputs kept per problem (with its [`super::augment::Problem::on_rows`]
/// problems)…
const KEPT_BYTES: usize = 32 << 20;
/// …and most outputs, whatever their length.
const KEPT_MAX: usize = 64;

/// One kept output: the chain it was fed, its parameters' bits and the output.
struct Kept {
    chain: Key,
    theta: Vec<u64>,
    out: Vec<f64>,
}

impl Kept {
    fn is(&self, chain: &Key, theta: &[f64], len: usize) -> bool {
        self.out.len() == len
            && self.chain == *chain
            && self.theta.len() == theta.len()
            && self.theta.iter().zip(theta).all(|(a, b)| *a == b.to_bits())
    }
}

/// The outputs run last, the latest (or the latest read) first.
#[derive(Default)]
pub struct Runs(Mutex<Vec<Kept>>);

impl Runs {
    /// Writes into `out` the output of the base model at `theta` fed `chain`, over
    /// `out.len()` samples: a kept one, or one `run` writes (kept when it succeeds). `false`
    /// when `run` fails.
    pub fn run_into(
        &self,
        chain: &[Transform],
        theta: &[f64],
        out: &mut [f64],
        run: impl FnOnce(&mut [f64]) -> bool,
    ) -> bool {
        let chain = key(chain);
        if let Ok(mut kept) = self.0.lock() {
            if let Some(i) = kept.iter().position(|k| k.is(&chain, theta, out.len())) {
                kept[..=i].rotate_right(1);
                if let Some(k) = kept.first() {
                    out.copy_from_slice(&k.out);
                    return true;
                }
            }
        }
        if !run(out) {
            return false;
        }
        let most = (KEPT_BYTES / (8 * out.len().max(1))).min(KEPT_MAX);
        if most == 0 {
            return true;
        }
        if let Ok(mut kept) = self.0.lock() {
            // The buffer of the entry dropped is written over (no allocation once full).
            let mut entry = if kept.len() >= most { kept.pop() } else { None }.unwrap_or_else(|| Kept {
                chain: Vec::new(),
                theta: Vec::new(),
                out: Vec::new(),
            });
            entry.chain = chain;
            entry.theta.clear();
            entry.theta.extend(theta.iter().map(|v| v.to_bits()));
            entry.out.clear();
            entry.out.extend_from_slice(out);
            kept.insert(0, entry);
            kept.truncate(most);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_is_made_once_per_chain_parameters_and_length() {
        let runs = Runs::default();
        let count = std::cell::Cell::new(0);
        let made = &count;
        let run = |v: f64| {
            move |out: &mut [f64]| {
                made.set(made.get() + 1);
                out.fill(v);
                true
            }
        };
        let lag = [Transform::Lag { tau_s: 0.01 }];
        let mut out = vec![0.0; 4];
        assert!(runs.run_into(&lag, &[1.0, 2.0], &mut out, run(1.0)));
        out.fill(9.0);
        assert!(runs.run_into(&lag, &[1.0, 2.0], &mut out, run(2.0)));
        assert_eq!((made.get(), out[3]), (1, 1.0));
        // Another chain, other parameters (-0.0 against 0.0 too), another length: run again.
        assert!(runs.run_into(&[], &[1.0, 2.0], &mut out, run(3.0)));
        assert!(runs.run_into(&lag, &[1.0, -0.0], &mut out, run(4.0)));
        assert!(runs.run_into(&lag, &[1.0, 0.0], &mut out, run(5.0)));
        let mut short = vec![0.0; 3];
        assert!(runs.run_into(&lag, &[1.0, 2.0], &mut short, run(6.0)));
        assert_eq!((made.get(), short[0]), (5, 6.0));
        // A failed run is not kept.
        assert!(!runs.run_into(&lag, &[7.0], &mut out, |_| false));
        assert!(runs.run_into(&lag, &[7.0], &mut out, run(7.0)));
        assert_eq!((made.get(), out[0]), (6, 7.0));
    }

    #[test]
    fn the_run_read_longest_ago_goes_first() {
        let runs = Runs::default();
        let mut out = vec![0.0; 2];
        let fill = |v: f64| {
            move |o: &mut [f64]| -> bool {
                o.fill(v);
                true
            }
        };
        for i in 0..KEPT_MAX {
            runs.run_into(&[], &[i as f64], &mut out, fill(i as f64));
        }
        // Run 0 read again, then one run more: run 1 is dropped, 0 kept.
        runs.run_into(&[], &[0.0], &mut out, fill(-1.0));
        runs.run_into(&[], &[KEPT_MAX as f64], &mut out, fill(-1.0));
        runs.run_into(&[], &[0.0], &mut out, fill(-1.0));
        assert_eq!(out[0], 0.0);
        runs.run_into(&[], &[1.0], &mut out, fill(-1.0));
        assert_eq!(out[0], -1.0);
    }

    #[test]
    fn long_outputs_are_kept_fewer() {
        let runs = Runs::default();
        let long = KEPT_BYTES / 8 / 2;
        let mut out = vec![0.0; long];
        for i in 0..3 {
            runs.run_into(&[], &[i as f64], &mut out, |o| {
                o.fill(i as f64);
                true
            });
        }
        assert_eq!(runs.0.lock().unwrap().len(), 2);
    }
}
