//! `spencer` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 001 eq. 3–7 (modified Bouc–Wen, Spencer et al. 1997).

pub(crate) mod reference;

use model_core::models::spencer::{Registered, DYKE_1997_FLAT};

use super::reference::Case;
use super::search::{published, ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

/// Spencer et al. (1997) for the Dyke damper (x in cm, F in N, v in V), in flat order:
/// model-core's [`DYKE_1997_FLAT`] as published.
pub(crate) fn dyke_1997() -> [f64; 14] {
    DYKE_1997_FLAT.map(published)
}
/// The spreads of `ranran_50.csv` (D, V, F) the published set is rescaled from.
pub(crate) const DYKE_SCALES: (f64, f64, f64) = (0.35, 16.0, 430.0);

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, v, y, no_u, u, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        let (dx0, dv0, dy0) = DYKE_SCALES;
        let (fx, fv, fy) = (x / dx0, v / dv0, y / dy0);
        // Dimensions of each parameter as powers of (x, v, y) and the command.
        let dims: [(f64, f64, f64, f64); 14] = [
            (0.0, -1.0, 1.0, 0.0),  // c0a N·s/cm
            (0.0, -1.0, 1.0, -1.0), // c0b
            (-1.0, 0.0, 1.0, 0.0),  // k0
            (0.0, -1.0, 1.0, 0.0),  // c1a
            (0.0, -1.0, 1.0, -1.0), // c1b
            (-1.0, 0.0, 1.0, 0.0),  // k1
            (1.0, 0.0, 0.0, 0.0),   // x0
            (-1.0, 0.0, 1.0, 0.0),  // alpha_a (z in units of x)
            (-1.0, 0.0, 1.0, -1.0), // alpha_b
            (-2.0, 0.0, 0.0, 0.0),  // gamma
            (-2.0, 0.0, 0.0, 0.0),  // beta
            (0.0, 0.0, 0.0, 0.0),   // A
            (0.0, 0.0, 0.0, 0.0),   // n
            (0.0, 0.0, 0.0, 0.0),   // eta
        ];
        let uu = if no_u { 1.0 } else { u / 2.25 };
        let scaled: Vec<f64> = dyke_1997()
            .iter()
            .zip(dims)
            .map(|(p0, (ex, ev, ey, eu))| p0 * fx.powf(ex) * fv.powf(ev) * fy.powf(ey) * uu.powf(eu))
            .collect();
        let sc = |i: usize| scaled.get(i).copied().unwrap_or(1.0);
        let x0_start = (s.x_mean + sc(6)).clamp(s.x_mean - 300.0 * x, s.x_mean + 300.0 * x);
        Some((
            vec![
                p("c0a", sc(0) / 30.0, sc(0) * 30.0, sc(0)).log(),
                p("c0b", sc(1) / 100.0, sc(1) * 30.0, sc(1)).log().fixed_if(no_u, 0.0),
                p("k0", sc(2) / 100.0, sc(2) * 30.0, sc(2)).log(),
                p("c1a", sc(3) / 30.0, sc(3) * 30.0, sc(3)).log(),
                p("c1b", sc(4) / 100.0, sc(4) * 100.0, sc(4)).log().fixed_if(no_u, 0.0),
                p("k1", -30.0 * y / x, 30.0 * y / x, sc(5)),
                p("x0", s.x_mean - 300.0 * x, s.x_mean + 300.0 * x, x0_start),
                p("alpha_a", sc(7) / 30.0, sc(7) * 30.0, sc(7)).log(),
                p("alpha_b", sc(8) / 100.0, sc(8) * 30.0, sc(8)).log().fixed_if(no_u, 0.0),
                p("gamma", sc(9) / 1e3, sc(9) * 1e3, sc(9)).log(),
                p("beta", sc(10) / 1e3, sc(10) * 1e3, sc(10)).log(),
                p("A", 1.0, 3e3, 301.0).log(),
                // Spencer fixes n = 2 (closed-form update in the core).
                p("n", 2.0, 2.0, 2.0).fixed(2.0),
                p("eta", 5.0, 5e3, 190.0).log().fixed_if(no_u, 190.0),
            ],
            Strategy::Global,
        ))
    }

    fn reference_cases() -> Vec<Case> {
        reference::cases()
    }
}
