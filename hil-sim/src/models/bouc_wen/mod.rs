//! `bouc_wen` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 000 eq. 3–4 (and the damper form of seeds 001/003).

pub(crate) mod reference;

use model_core::models::bouc_wen::Registered;

use super::reference::Case;
use super::search::{ModelSpec, ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        Some((
            // δ (Wen's A) is fixed at 1: α and δ only appear as α·δ in the loop amplitude.
            // Then z is in units of x and (β+γ)^(−1/n) is the yield displacement.
            vec![
                p("alpha", 1e-3 * y / x, 1e3 * y / x, y / x).log(),
                p("beta", 1e-4 / x.powi(2), 1e6 / x.powi(2), 10.0 / x.powi(2)).log(),
                p("gamma", 1e-4 / x.powi(2), 1e6 / x.powi(2), 10.0 / x.powi(2)).log(),
                p("delta", 1.0, 1.0, 1.0).fixed(1.0),
                // n = 2 (Spencer's choice): a non-integer n costs a powf per step (~4× slower).
                p("n", 2.0, 2.0, 2.0).fixed(2.0),
                p("c", -10.0 * y / v, 10.0 * y / v, 0.1 * y / v),
                p("k", -10.0 * y / x, 10.0 * y / x, 0.0),
                p("x0", s.x_mean - 1e3 * x, s.x_mean + 1e3 * x, s.x_mean),
            ],
            Strategy::Global,
        ))
    }

    /// `n = 1`, seed 000's own fit of the clutch (eq. 3–4): a sharper knee than `n = 2`.
    /// β and γ multiply `|z|ⁿ` with z in units of x, so their box scales by x once less.
    fn variant(sp: &ModelSpec, k: usize, s: &Scales) -> Option<ModelSpec> {
        if k != 1 {
            return None;
        }
        let mut v = sp.clone();
        v.hold("n", 1.0);
        let x = Spreads::of(s).x;
        for p in v.params.iter_mut().filter(|p| p.name == "beta" || p.name == "gamma") {
            p.lo *= x;
            p.hi *= x;
            p.start *= x;
        }
        Some(v)
    }

    fn reference_cases() -> Vec<Case> {
        reference::cases()
    }
}
