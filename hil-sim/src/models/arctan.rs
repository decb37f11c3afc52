//! `arctan` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 001 eq. 16 (Guo).

use model_core::models::arctan::Registered;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        Some((search_box(s), Strategy::Global))
    }
}

/// Guo's ten parameters (each `a + b·u`); the modified form adds `m` ([`super::arctan_inertia`]).
pub(super) fn search_box(s: &Scales) -> Vec<ParamSpec> {
    let Spreads { v, y, ym, no_u, u, big_y, .. } = Spreads::of(s);
    let p = ParamSpec::new;
    let ps = vec![
        p("f0_a", -big_y, big_y, ym),
        p("f0_b", -10.0 * y / u, 10.0 * y / u, 0.0).fixed_if(no_u, 0.0),
        p("cb_a", 0.0, 20.0 * y / v, 0.1 * y / v),
        p("cb_b", -20.0 * y / (v * u), 20.0 * y / (v * u), 0.0).fixed_if(no_u, 0.0),
        p("fy_a", 0.0, 10.0 * y, y),
        p("fy_b", -10.0 * y / u, 10.0 * y / u, 0.0).fixed_if(no_u, 0.0),
        p("k_a", 1e-2 / v, 1e3 / v, 3.0 / v).log(),
        p("k_b", -1e2 / (v * u), 1e2 / (v * u), 0.0).fixed_if(no_u, 0.0),
        p("xd0_a", 0.0, 2.0 * v, 0.1 * v),
        p("xd0_b", -2.0 * v / u, 2.0 * v / u, 0.0).fixed_if(no_u, 0.0),
    ];
    ps
}
