//! `trig` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 002 eq. 10–12, 31–37.

use model_core::models::trig::Registered;

use super::search::{ParamSpec, Scales, SearchBox, Spreads, Strategy};
use super::HostModel;

impl HostModel for Registered {
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { v, y, ym, no_u, u, big_y, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        // Seven quadratic polynomials in the command (seed 002 eq. 31–37): [P0, P1, P2].
        let mut ps = Vec::with_capacity(21);
        let blocks: [(&'static str, f64, f64, f64, bool); 7] = [
            ("D", 0.0, 5.0 * y, y, false),
            ("C", 0.0, 2.0, 1.0, false),
            ("B", 1e-3 / v, 1e2 / v, 1.0 / v, true),
            ("S_h", -v, v, 0.0, false),
            ("S_v", -big_y, big_y, ym, false),
            ("k", 0.0, 2.0, 0.5, false),
            ("c", 0.0, 20.0 * y / v, 0.1 * y / v, false),
        ];
        const NAMES: [[&str; 3]; 7] = [
            ["D0", "D1", "D2"],
            ["C0", "C1", "C2"],
            ["B0", "B1", "B2"],
            ["Sh0", "Sh1", "Sh2"],
            ["Sv0", "Sv1", "Sv2"],
            ["k0", "k1", "k2"],
            ["c0", "c1", "c2"],
        ];
        for ((_, lo, hi, st, log), names) in blocks.iter().zip(NAMES) {
            let [n0, n1, n2] = names;
            let base = if *log { p(n0, *lo, *hi, *st).log() } else { p(n0, *lo, *hi, *st) };
            let span = hi - lo;
            ps.push(base);
            ps.push(p(n1, -span / u, span / u, 0.0).fixed_if(no_u, 0.0));
            // The quadratic term is held at zero: the linear one is identified first.
            ps.push(p(n2, -span / (u * u), span / (u * u), 0.0).fixed(0.0));
        }
        Some((ps, Strategy::Global))
    }
}
