//! Reading validated fixed-size blocks out of a flat parameter vector
//! ([`Model::from_params`](crate::Model::from_params) order).

use crate::error::check;
use crate::ParamError;

/// Read `N` values from a flat-vector iterator, validating each.
pub(crate) fn take<const N: usize>(
    it: &mut core::slice::Iter<'_, f32>,
    name: &'static str,
    lo: f32,
    hi: f32,
) -> Result<[f32; N], ParamError> {
    let mut out = [0.0f32; N];
    for o in out.iter_mut() {
        let v = *it.next().ok_or(ParamError::Constraint { what: "parameter vector too short" })?;
        *o = check(name, v, lo, hi)?;
    }
    Ok(out)
}
