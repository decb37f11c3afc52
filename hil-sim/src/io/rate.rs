//! The rate estimator a replay or a fit uses: the firmware's [`RateSpec`] (what the
//! configuration page stores), written and read as text (`backward`, `filtered:FC_HZ`,
//! `kalman` or `kalman:Q:R`).

pub use model_core::control::RateSpec;
use thiserror::Error;

/// Seed 002's Kalman filter as published: jerk intensity and measurement variance.
pub const SEED_002_KALMAN: RateSpec = RateSpec::Kalman { q: 200.0, r: 0.01 };

/// A rate estimator's text that does not parse.
#[derive(Debug, Error, PartialEq)]
pub enum RateParseError {
    #[error("{text}: `{part}` is not a number")]
    NotANumber { text: String, part: String },
    #[error("{0}: expected backward, filtered:FC_HZ or kalman[:Q:R]")]
    Unknown(String),
}

/// Read `backward`, `filtered:FC_HZ`, `kalman` (seed 002's q = 200, r = 0.01) or `kalman:Q:R`.
pub fn parse(text: &str) -> Result<RateSpec, RateParseError> {
    let parts: Vec<&str> = text.split(':').collect();
    let num = |p: &str| {
        p.parse::<f32>().map_err(|_| RateParseError::NotANumber { text: text.to_owned(), part: p.to_owned() })
    };
    Ok(match parts.as_slice() {
        ["backward"] => RateSpec::Backward,
        ["filtered", fc] => RateSpec::Filtered { fc: num(fc)? },
        ["kalman"] => SEED_002_KALMAN,
        ["kalman", q, r] => RateSpec::Kalman { q: num(q)?, r: num(r)? },
        _ => return Err(RateParseError::Unknown(text.to_owned())),
    })
}

/// The text [`parse`] reads back.
pub fn label(rate: RateSpec) -> String {
    match rate {
        RateSpec::Backward => "backward".to_owned(),
        RateSpec::Filtered { fc } => format!("filtered:{fc}"),
        RateSpec::Kalman { q, r } => format!("kalman:{q}:{r}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_what_it_writes() {
        for r in [RateSpec::Backward, RateSpec::Filtered { fc: 50.0 }, RateSpec::Kalman { q: 1e6, r: 1e-6 }] {
            assert_eq!(parse(&label(r)), Ok(r));
        }
        assert_eq!(parse("kalman"), Ok(SEED_002_KALMAN));
        assert!(matches!(parse("filtered:x"), Err(RateParseError::NotANumber { .. })));
        assert!(matches!(parse("euler"), Err(RateParseError::Unknown(_))));
    }
}
