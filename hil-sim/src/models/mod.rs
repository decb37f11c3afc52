//! What each model needs on the host, reached by identifier through model-core's
//! registry ([`visit`]): running it over samples ([`replay()`]), its search box and start
//! values for identification, its f64 reference, the accuracy check of the f32 core.

pub mod accuracy;
pub mod reference;
pub mod replay;

use model_core::rate::RateParams;
use model_core::{Estimator, Model, ParamError, Sample};
use thiserror::Error;

pub use model_core::registry::{visit, Visit};

/// Which rate estimator a replay uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateChoice {
    Backward,
    /// First-order filtered differentiator, cutoff in Hz.
    Filtered(f32),
    /// Seed 002's Kalman filter with jerk intensity `q` and measurement variance `r`.
    Kalman {
        q: f32,
        r: f32,
    },
}

impl RateChoice {
    /// `backward`, `filtered:FC_HZ`, `kalman` (seed 002's q = 200, r = 0.01) or `kalman:Q:R`.
    pub fn parse(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(':').collect();
        let num = |p: &str| p.parse::<f32>().map_err(|_| format!("--rate {s}: `{p}` is not a number"));
        Ok(match parts.as_slice() {
            ["backward"] => Self::Backward,
            ["filtered", fc] => Self::Filtered(num(fc)?),
            ["kalman"] => Self::Kalman { q: 200.0, r: 0.01 },
            ["kalman", q, r] => Self::Kalman { q: num(q)?, r: num(r)? },
            _ => return Err(format!("--rate {s}: expected backward, filtered:FC_HZ or kalman[:Q:R]")),
        })
    }

    /// The form the firmware's configuration page stores.
    pub fn spec(self) -> model_core::control::RateSpec {
        use model_core::control::RateSpec;
        match self {
            Self::Backward => RateSpec::Backward,
            Self::Filtered(fc) => RateSpec::Filtered { fc },
            Self::Kalman { q, r } => RateSpec::Kalman { q, r },
        }
    }

    pub fn build(self, dt: f32) -> Result<RateParams, ParamError> {
        match self {
            Self::Backward => RateParams::backward(dt),
            Self::Filtered(fc) => RateParams::filtered(dt, fc),
            Self::Kalman { q, r } => RateParams::kalman(dt, q, r),
        }
    }
}

/// Why a replay could not start.
#[derive(Debug, Error)]
pub enum ReplayError {
    #[error("unknown model `{0}` (see `hil-sim models`)")]
    UnknownModel(String),
    #[error("model `{model}`: {source}")]
    Params { model: String, source: ParamError },
}

/// Result of running samples through the f32 core.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Replay {
    pub y: Vec<f32>,
    /// Samples whose output was held (non-finite input or overflow).
    pub held: usize,
}

struct Run<'a> {
    params: &'a [f32],
    dt: f32,
    rate: RateChoice,
    samples: &'a [Sample],
}

impl Visit for Run<'_> {
    type Out = Result<Replay, ParamError>;
    fn visit<M: Model>(self) -> Self::Out {
        let model = M::from_params(self.params, self.dt)?;
        let est = Estimator::new(model, self.rate.build(self.dt)?)?;
        let mut st = est.state();
        let mut out = Replay { y: Vec::with_capacity(self.samples.len()), held: 0 };
        for s in self.samples {
            let o = est.step(&mut st, *s);
            out.held += usize::from(!o.flags.ok());
            out.y.push(o.y);
        }
        Ok(out)
    }
}

/// Run `samples` through model `id` with flat parameters `params`, one step per sample
/// of `dt` seconds, in f32 — the code the firmware runs.
pub fn replay(id: &str, params: &[f32], dt: f32, rate: RateChoice, samples: &[Sample]) -> Result<Replay, ReplayError> {
    visit(id, Run { params, dt, rate, samples })
        .ok_or_else(|| ReplayError::UnknownModel(id.to_owned()))?
        .map_err(|source| ReplayError::Params { model: id.to_owned(), source })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registered_id_dispatches() {
        struct Id;
        impl Visit for Id {
            type Out = &'static str;
            fn visit<M: Model>(self) -> &'static str {
                M::ID
            }
        }
        for info in model_core::MODELS.iter() {
            assert_eq!(visit(info.id, Id), Some(info.id));
        }
        assert_eq!(visit("nope", Id), None);
    }

    #[test]
    fn algebraic_replay_and_errors() {
        let s: Vec<Sample> = (0..4).map(|i| Sample::new(i as f32)).collect();
        let r = replay("algebraic", &[2.0, 0.0, 0.0, 1.0], 0.01, RateChoice::Backward, &s).unwrap();
        assert_eq!(r.y, vec![1.0, 3.0, 5.0, 7.0]);
        assert!(matches!(replay("nope", &[], 0.01, RateChoice::Backward, &s), Err(ReplayError::UnknownModel(_))));
        let e = replay("algebraic", &[1.0], 0.01, RateChoice::Backward, &s).unwrap_err();
        assert!(e.to_string().contains("expected 4 parameters"), "{e}");
    }
}
