//! `tanh` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 000 eq. 11–12 (Kwok).

use model_core::models::tanh::Registered;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    /// Eq. 11: `T = c·Ḃ + k·B + α·z + T₀` with `z` free of all four.
    const AFFINE: &'static [&'static str] = &["alpha", "c", "k", "t0"];

    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, ym, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            vec![
                p("alpha", -10.0 * y, 10.0 * y, y),
                p("beta", 1e-3 / v, 1e3 / v, 1.0 / v).log(),
                p("gamma", -3.0, 3.0, 0.0),
                p("c", -10.0 * y / v, 10.0 * y / v, 0.1 * y / v),
                p("k", -10.0 * y / x, 10.0 * y / x, 0.0),
                p("t0", -big_y, big_y, ym),
            ],
            Strategy::Global,
        ))
    }
}
