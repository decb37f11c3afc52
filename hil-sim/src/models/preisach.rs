//! `preisach` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 004 eq. 5–9.

use model_core::models::preisach::Registered;

use super::search::{ModelSpec, ParamSpec, Scales, SearchBox, Spreads, Strategy, Structure};
use super::HostModel;

impl HostModel for Registered {
    const STRUCTURE: Structure = Structure::PreisachProjection;

    /// Seed 004 eq. 5–9 (Table A1: σ_HM ∈ [0, 10], μ_HM ∈ [0, 20], σ_HC ∈ [0, 1],
    /// μ_HC ∈ [0, 0.1] on the normalised input). The grid spans the training range, set
    /// from the data by the fit; y₀ and the scale are solved in closed form.
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, y, ym, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            vec![
                p("sigma_hm", 0.05, 10.0, 3.2).log(),
                p("mu_hm", -20.0, 20.0, 0.5),
                p("sigma_hc", 1e-3, 1.0, 0.05).log(),
                p("mu_hc", 0.0, 0.3, 0.0),
                p("y0", ym, ym, ym).fixed(ym),
                p("scale", y, y, y).fixed(y),
                p("x_min", s.x_mean - 2.0 * x, s.x_mean - 2.0 * x, s.x_mean - 2.0 * x).fixed(s.x_mean - 2.0 * x),
                p("x_max", s.x_mean + 2.0 * x, s.x_mean + 2.0 * x, s.x_mean + 2.0 * x).fixed(s.x_mean + 2.0 * x),
                p("density", 1.0, 1.0, 1.0).fixed(1.0),
            ],
            Strategy::Projected,
        ))
    }

    /// Gauss–Gauss after seed 004's better Gauss–Cauchy.
    fn variant(sp: &ModelSpec, k: usize, _s: &Scales) -> Option<ModelSpec> {
        (k == 1).then(|| {
            let mut v = sp.clone();
            v.hold("density", 0.0);
            v
        })
    }
}
