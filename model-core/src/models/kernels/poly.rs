//! Polynomials in the command: the command-dependent coefficients of
//! [`bingham`](super::super::bingham) (seed 003 eq. 13–14) and [`trig`](super::super::trig)
//! (seed 002 eq. 31–37).

/// Horner evaluation of `c[0] + c[1]·u + c[2]·u² + …`.
#[inline]
pub(crate) fn poly(c: &[f32], u: f32) -> f32 {
    c.iter().rev().fold(0.0, |acc, &ck| acc * u + ck)
}
