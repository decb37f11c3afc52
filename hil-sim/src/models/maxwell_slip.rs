//! `maxwell_slip` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 004 eq. 23–25.

use model_core::models::maxwell_slip::Registered;
use model_core::Model;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy, Structure};
use super::HostModel;

impl HostModel for Registered {
    const STRUCTURE: Structure = Structure::ElastoSlide;

    /// Seed 004 eq. 23–25 (Table A15: kᵢ ∈ [0.01, 10], fᵢ ∈ [0, 10] normalised): the
    /// breakaway deflections fᵢ/kᵢ spread over the range, stiffnesses by the closed form.
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, y, ym, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        let n = (Self::N_PARAMS - 2) / 2;
        let (k, f) = (*Self::PARAM_NAMES.get(1)?, *Self::PARAM_NAMES.get(2)?);
        let mut ps = vec![p("w0", -big_y, big_y, ym)];
        ps.extend((0..n).map(|_| p(k, 0.0, 100.0 * y / x, y / x)));
        ps.extend((0..n).map(|_| p(f, 0.0, 100.0 * y, y)));
        ps.push(p("k0", -100.0 * y / x, 100.0 * y / x, 0.0));
        Some((ps, Strategy::Operator))
    }
}
