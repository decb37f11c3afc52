//! `dahl` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 001 eq. 8–11 (modified Dahl).

pub(crate) mod reference;

use model_core::models::dahl::Registered;

use super::reference::Case;
use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, ym, no_u, u, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            vec![
                p("C0s", 0.0, 20.0 * y / v, 0.1 * y / v),
                p("C0d", 0.0, 20.0 * y / (v * u), 0.1 * y / (v * u)).fixed_if(no_u, 0.0),
                p("Fds", 0.0, 10.0 * y, 0.3 * y),
                p("Fdu", 0.0, 10.0 * y / u, y / u).fixed_if(no_u, 0.0),
                p("K0", -10.0 * y / x, 10.0 * y / x, 0.0),
                p("sigma", 1e-2 / x, 1e4 / x, 3.0 / x).log(),
                p("f0", -big_y, big_y, -ym),
                p("eta", 1.0, 1e4, 190.0).log().fixed_if(no_u, 190.0),
            ],
            Strategy::Global,
        ))
    }

    fn reference_cases() -> Vec<Case> {
        reference::cases()
    }
}
