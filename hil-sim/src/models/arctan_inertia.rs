//! `arctan_inertia` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 001 eq. 17 (modified algebraic, m·ẍ).

use model_core::models::arctan_inertia::Registered;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { y, a, .. } = Spreads::of(s);
        let mut ps = super::arctan::search_box(s);
        ps.push(ParamSpec::new("m", -10.0 * y / a, 10.0 * y / a, 0.0));
        Some((ps, Strategy::Global))
    }
}
