//! `bouc_wen_asym` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 004 eq. 26–31.

pub(crate) mod reference;

use model_core::models::bouc_wen_asym::Registered;

use super::reference::Case;
use super::search::{ModelSpec, ParamSpec, Scales, SearchBox, Spreads, Strategy, Structure};
use super::HostModel;

impl HostModel for Registered {
    const STRUCTURE: Structure = Structure::AsymmetricBoucWen;

    /// Seed 004 eq. 26–31, Tables A17–A18 (normalised: D ∈ (0, 5], A ∈ [−5, 5],
    /// β, γ ∈ [−50, 50], z(0) ∈ [0, 0.2], δ ∈ [0, 5], p ∈ [0, 2], q ∈ [0, 1]) written
    /// for the raw input; n = 2 (closed-form step, as for `bouc_wen`). Eq. 31 first, eq.
    /// 30 as the variant ([`HostModel::variant`]).
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        let span = 4.0 * x;
        Some((
            vec![
                p("alpha", 0.0, 1.0, 0.5),
                p("kappa", 1e-3 * y / x, 1e3 * y / x, y / x).log(),
                p("d", 0.05, 5.0, 1.0).log(),
                p("a", 0.05, 5.0, 1.0).log(),
                p("beta", 1e-3 / (span * span), 50.0 / (span * span), 1.0 / (span * span)).log(),
                p("gamma", -50.0 / (span * span), 50.0 / (span * span), 1.0 / (span * span)),
                p("n", 2.0, 2.0, 2.0).fixed(2.0),
                p("z0", -0.2 * span, 0.2 * span, 0.0),
                p("delta", -5.0 * v, 5.0 * v, 0.0),
                p("p", 0.0, 20.0 / span, 2.0 / span),
                p("q", s.x_mean - 2.0 * x, s.x_mean + 2.0 * x, s.x_mean),
                p("variant", 2.0, 2.0, 2.0).fixed(2.0),
            ],
            Strategy::Global,
        ))
    }

    /// Eq. 30 (ψ = δ·x·sgn ẋ, one parameter) after eq. 31: δ is then per unit x.
    fn variant(sp: &ModelSpec, k: usize, s: &Scales) -> Option<ModelSpec> {
        if k != 1 {
            return None;
        }
        let mut v = sp.clone();
        v.hold("variant", 1.0);
        v.hold("p", 0.0);
        v.hold("q", 0.0);
        let x_size = s.x_mean.abs().max(s.x).max(1e-12);
        if let Some(p) = v.params.iter_mut().find(|p| p.name == "delta") {
            p.lo /= x_size;
            p.hi /= x_size;
            p.start /= x_size;
        }
        Some(v)
    }

    fn reference_cases() -> Vec<Case> {
        reference::cases()
    }
}
