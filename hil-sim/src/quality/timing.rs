//! The unit of the time column: whole numbers stepping by 1 or more are a sample counter
//! or milliseconds, not seconds (read as seconds they make a 1 kHz recording a 1 Hz one,
//! and the rate estimators fail on it).

use thiserror::Error;

use crate::numerics::stats::median;

/// A time column that does not count seconds.
#[derive(Clone, Debug, Error, PartialEq)]
#[error(
    "time column `{column}` steps by {step} in whole numbers, {hz} Hz if these were seconds: \
     if it counts milliseconds (or samples), give the time in seconds"
)]
pub struct TimeUnitError {
    pub column: String,
    pub step: f64,
    pub hz: f64,
}

/// Refuse a time column `t` (named `column`) of whole numbers with a median step of 1 or more.
pub fn check_time_unit(column: &str, t: &[f64]) -> Result<(), TimeUnitError> {
    if t.len() < 2 || t.iter().any(|v| v.fract() != 0.0) {
        return Ok(());
    }
    let steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let step = median(&steps);
    if step >= 1.0 {
        return Err(TimeUnitError { column: column.to_owned(), step, hz: 1.0 / step });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_milliseconds_are_refused_and_seconds_pass() {
        let ms: Vec<f64> = (0..100).map(f64::from).collect();
        assert_eq!(check_time_unit("t", &ms).unwrap_err().step, 1.0);
        let s: Vec<f64> = (0..100).map(|i| f64::from(i) * 1e-3).collect();
        assert_eq!(check_time_unit("t", &s), Ok(()));
    }
}
