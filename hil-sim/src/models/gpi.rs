//! `gpi` on the host: its search box and start values in the recording's own
//! scales ([`Scales`]). Model: seed 004 eq. 16–22.

use model_core::models::gpi::Registered;

use super::search::{ModelSpec, ParamSpec, Scales, SearchBox, Spreads, Strategy, Structure};
use super::HostModel;

impl HostModel for Registered {
    const STRUCTURE: Structure = Structure::GpiProjection;

    /// Seed 004 eq. 16–22 with hyperbolic-tangent envelopes (its best, Table A9: GOF
    /// 0.974): `α(x) = a·tanh(x + b) + c`. A saturating MR loop is concave, which the
    /// polynomial envelope (curvature fixed at +1) cannot follow; it is tried as the
    /// variant ([`HostModel::variant`]). The paper's normalised bounds (a, b, c ∈ [−5, 5], δ₂ ∈
    /// [0, 35]) are written for the raw input: b moves the bend of tanh over the range,
    /// a and c scale with the span. p₀, δ₁ and the common envelope offset (c_r) are
    /// solved in closed form; c_l is the left envelope's offset relative to the right.
    fn search(s: &Scales) -> Option<SearchBox> {
        let Spreads { x, .. } = Spreads::of(s);
        let p = ParamSpec::new;
        let span = 4.0 * x;
        let x_min = s.x_mean - 2.0 * x;
        let b_lo = -(x_min + span) - 3.0;
        let b_hi = -x_min + 3.0;
        let b0 = -s.x_mean;
        Some((
            vec![
                p("p0", 0.0, 0.0, 0.0).fixed(0.0),
                p("m0", 0.0, 0.0, 0.0).fixed(0.0),
                p("delta1", 1.0, 1.0, 1.0).fixed(1.0),
                p("delta2", 0.0, 35.0 / span, 3.0 / span),
                p("a_r", 0.05 * span, 20.0 * span, span).log(),
                p("b_r", b_lo, b_hi, b0),
                p("c_r", 0.0, 0.0, 0.0).fixed(0.0),
                p("a_l", 0.05 * span, 20.0 * span, span).log(),
                p("b_l", b_lo, b_hi, b0),
                p("c_l", -5.0 * span, 5.0 * span, 0.0),
                p("x_min", x_min, x_min, x_min).fixed(x_min),
                p("x_max", x_min + span, x_min + span, x_min + span).fixed(x_min + span),
                p("envelope", 1.0, 1.0, 1.0).fixed(1.0),
            ],
            Strategy::Projected,
        ))
    }

    /// Polynomial envelopes `x² + a·x + b` (seed 004 Table A11) after tanh: the paper's
    /// a ∈ [−5, 5] on the normalised input is `a_paper·span − 2·x_min` on the raw one;
    /// b_r carries the offset (closed form), b_l the left envelope's relative offset.
    fn variant(sp: &ModelSpec, k: usize, s: &Scales) -> Option<ModelSpec> {
        if k != 1 {
            return None;
        }
        let mut v = sp.clone();
        let span = 4.0 * s.x.max(1e-12);
        let x_min = s.x_mean - 2.0 * s.x;
        let (a_lo, a_hi, a0) = (-5.0 * span - 2.0 * x_min, 5.0 * span - 2.0 * x_min, 2.0 * span - 2.0 * x_min);
        let b = 10.0 * span * span + 10.0 * span * x_min.abs();
        v.hold("envelope", 0.0);
        for name in ["b_r", "c_r", "c_l"] {
            v.hold(name, 0.0);
        }
        for p in v.params.iter_mut() {
            match p.name {
                "a_r" | "a_l" => *p = ParamSpec::new(p.name, a_lo, a_hi, a0),
                "b_l" => *p = ParamSpec::new(p.name, -b, b, 0.0),
                _ => {}
            }
        }
        Some(v)
    }
}
