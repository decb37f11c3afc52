//! `bingham` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 003 eq. 12–14 with command polynomials, linear in its parameters.

use model_core::models::bingham::Registered;
use model_core::Kin;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::{HostModel, MAX_REGRESSORS};

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { v, y, ym, no_u, u, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            vec![
                p("fc0", 0.0, 10.0 * y, y),
                p("fc1", -10.0 * y / u, 10.0 * y / u, 0.0).fixed_if(no_u, 0.0),
                p("fc2", -10.0 * y / u.powi(2), 10.0 * y / u.powi(2), 0.0).fixed_if(no_u, 0.0),
                p("fc3", -10.0 * y / u.powi(3), 10.0 * y / u.powi(3), 0.0).fixed_if(no_u, 0.0),
                p("c0_0", 0.0, 100.0 * y / v, y / v),
                p("c0_1", -100.0 * y / (v * u), 100.0 * y / (v * u), 0.0).fixed_if(no_u, 0.0),
                p("c0_2", -100.0 * y / (v * u * u), 100.0 * y / (v * u * u), 0.0).fixed_if(no_u, 0.0),
                p("c0_3", -100.0 * y / (v * u.powi(3)), 100.0 * y / (v * u.powi(3)), 0.0).fixed_if(no_u, 0.0),
                p("c0_4", -100.0 * y / (v * u.powi(4)), 100.0 * y / (v * u.powi(4)), 0.0).fixed_if(no_u, 0.0),
                p("f0", -big_y, big_y, ym),
            ],
            Strategy::Linear,
        ))
    }

    /// `F = (fc0 + fc1·u + fc2·u² + fc3·u³)·sgn(ẋ) + (c0_0 + … + c0_4·u⁴)·ẋ + f0`
    fn regressors(k: &Kin, row: &mut [f64; MAX_REGRESSORS]) -> Option<usize> {
        let (dx, u) = (f64::from(k.dx), f64::from(k.u));
        let s = if dx > 0.0 {
            1.0
        } else if dx < 0.0 {
            -1.0
        } else {
            0.0
        };
        *row = [s, s * u, s * u * u, s * u.powi(3), dx, dx * u, dx * u * u, dx * u.powi(3), dx * u.powi(4), 1.0];
        Some(10)
    }
}
