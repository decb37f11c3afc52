//! Limits and parameter plumbing shared by the operator models
//! ([`prandtl_ishlinskii`](super::super::prandtl_ishlinskii), [`gpi`](super::super::gpi),
//! [`maxwell_slip`](super::super::maxwell_slip)).

use crate::ParamError;

/// Largest operator count with a parameter name table (`r[N]`, `p[N]`).
pub const MAX_OPERATORS: usize = 64;

/// `1 ≤ n ≤ MAX_OPERATORS`.
pub(crate) fn operator_count(n: usize) -> Result<(), ParamError> {
    if n == 0 || n > MAX_OPERATORS {
        Err(ParamError::Constraint { what: "operator count must be 1..=64" })
    } else {
        Ok(())
    }
}

/// Copy `src` into a fixed array (length checked by the caller).
pub(crate) fn to_array<const N: usize>(src: &[f32]) -> [f32; N] {
    let mut a = [0.0; N];
    for (o, s) in a.iter_mut().zip(src) {
        *o = *s;
    }
    a
}
