//! `prandtl_ishlinskii` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 004 eq. 10–15.

use model_core::models::prandtl_ishlinskii::Registered;
use model_core::Model;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy, Structure};
use super::HostModel;

impl HostModel for Registered {
    const STRUCTURE: Structure = Structure::PlayOperators;

    /// Seed 004 eq. 10–15: radii and weights set by the closed form (bounds as Table A7
    /// in the recording's units: radii up to the span, weights ≥ 0).
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, y, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        let n = (Self::N_PARAMS - 2) / 2;
        let (r, w) = (*Self::PARAM_NAMES.get(2)?, *Self::PARAM_NAMES.get(3)?);
        let mut ps = vec![p("p0", 0.0, 100.0 * y / x, y / x), p("m0", -big_y, big_y, 0.0)];
        ps.extend((0..n).map(|_| p(r, 0.0, 10.0 * x, x)));
        ps.extend((0..n).map(|_| p(w, 0.0, 100.0 * y / x, 0.0)));
        Some((ps, Strategy::Operator))
    }
}
