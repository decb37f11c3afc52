//! `lugre` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 000 eq. 7–8.

pub(crate) mod reference;

use model_core::models::lugre::Registered;

use super::reference::Case;
use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, ym, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            vec![
                p("alpha", 1e-2 / x, 1e5 / x, 10.0 / x).log(),
                p("beta", 1e-4 * y / x, 1e7 * y / x, 10.0 * y / x).log(),
                p("epsilon", -10.0 * y / v * 1e3 / x, 10.0 * y / v * 1e3 / x, 0.0),
                p("c", -10.0 * y / v, 10.0 * y / v, 0.1 * y / v),
                p("k", -10.0 * y / x, 10.0 * y / x, 0.0),
                p("t0", -big_y, big_y, ym),
            ],
            Strategy::Global,
        ))
    }

    fn reference_cases() -> Vec<Case> {
        reference::cases()
    }
}
