//! The play operator (backlash), the loop of the play host's terms ([`super::contenders::plays`]).

/// A play operator (backlash) of radius `r`: its output follows `x` within `±r`, starting
/// at `x[0]`.
pub fn play(x: &[f64], r: f64) -> Vec<f64> {
    let mut s = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|v| {
            s = s.max(v - r).min(v + r);
            s
        })
        .collect()
}
