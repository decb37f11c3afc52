//! `algebraic` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 000 eq. 14, linear in its parameters (closed-form least squares).

use model_core::models::algebraic::Registered;
use model_core::Kin;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::{HostModel, MAX_REGRESSORS};

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, ym, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            vec![
                p("k", -1e3 * y / x, 1e3 * y / x, 0.0),
                p("c", -1e3 * y / v, 1e3 * y / v, 0.0),
                p("alpha", -1e3 * y / x.powi(4), 1e3 * y / x.powi(4), 0.0),
                p("t0", -big_y, big_y, ym),
            ],
            Strategy::Linear,
        ))
    }

    /// `T = k·B + c·Ḃ + α·|B|·B³ + T₀`
    fn regressors(k: &Kin, row: &mut [f64; MAX_REGRESSORS]) -> Option<usize> {
        let (x, dx) = (f64::from(k.x), f64::from(k.dx));
        row[..4].copy_from_slice(&[x, dx, x.abs() * x.powi(3), 1.0]);
        Some(4)
    }
}
