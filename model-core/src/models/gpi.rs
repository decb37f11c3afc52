//! Generalized Prandtl–Ishlinskii (GPI) model, seed 004 eq. 16–22 (de la Morena et al.
//! 2025, after Al Janaideh et al.):
//!
//! generalized play operator (eq. 16–17)
//! `Γ_r^α[x](t_k) = max{α_R(x(t_k)) − r, min{α_L(x(t_k)) + r, Γ_r^α[x](t_{k−1})}}`,
//! `Γ_r^α[x](0) = max{α_R(x(0)) − r, min{α_L(x(0)) + r, M₀}}`,
//!
//! output (eq. 18, with the linear `G[x] = p₀·x` the paper uses)
//! `Φ = p₀·x + Σᵢ pᵢ·Γ_{rᵢ}^α[x]`,
//!
//! `N` radii equally spaced over the input range, `rᵢ = (i−1)/(N−1)·(x_max − x_min)`
//! (the paper's "n equally spaced values between min(x) and max(x)", which for its
//! normalised 0…1 input are the radii 0…1), and the exponential density (eq. 22)
//! `pᵢ = δ₁·exp(−δ₂·rᵢ)`, precomputed at construction.
//!
//! Envelope functions, one family for both sides (eq. 19–21), `j = R, L`:
//! - polynomial `α_j(x) = x² + a_j·x + b_j` (c_j unused),
//! - hyperbolic tangent `α_j(x) = a_j·tanh(x + b_j) + c_j`,
//! - Gaussian `α_j(x) = a_j·exp(−(x − b_j)²/(2·c_j))` (`c_j ≠ 0`).
//!
//! **How the asymmetry enters.** The rising branch of every operator follows the
//! envelope `α_R(x) − r` (the `max` in eq. 16 is active while x increases) and the
//! falling branch follows `α_L(x) + r` (the `min`). With `α_R = α_L = α` the operator is
//! a classical play on the transformed input `α(x)` and, for an `α` odd about the centre
//! of a symmetric excitation (e.g. tanh with `b = −centre`, `c = 0`), the loop is
//! point-symmetric like the classical PI loop. Different loading/unloading envelopes
//! bend the two branches differently, which is what lets the GPI fit seed 004's
//! asymmetric loops (Tables A9–A14). The order-preservation condition of the paper
//! (`α_R(x) − r ≤ α_L(x) + r`) is not enforced: where it fails the `max` wins and the
//! operator follows `α_R(x) − r` (still well defined); [`Gpi::order_preserving`] checks it.
//!
//! Units: x in the unit of the fit (seed 004: normalised 0…1), envelope values in the
//! unit of x (so a, b, c of the polynomial and tanh in that unit), `p₀` output units per
//! unit x, `δ₁` output units per unit x, `δ₂` per unit x, `M₀` unit of x.

use crate::error::{check, count, finite, time_step};
use crate::math::{exp, tanh};
use crate::model::write_flat;
use crate::models::prandtl_ishlinskii::operator_count;
use crate::{Finite, Kin, Model, ParamError};

/// Envelope family of eq. 19–21.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Envelope {
    /// Eq. 19, `x² + a·x + b` (flat value 0).
    Polynomial,
    /// Eq. 20, `a·tanh(x + b) + c` (flat value 1).
    Tanh,
    /// Eq. 21, `a·exp(−(x − b)²/(2c))` (flat value 2).
    Gaussian,
}

impl Envelope {
    fn from_code(v: f32) -> Result<Self, ParamError> {
        if v == 0.0 {
            Ok(Self::Polynomial)
        } else if v == 1.0 {
            Ok(Self::Tanh)
        } else if v == 2.0 {
            Ok(Self::Gaussian)
        } else {
            check("envelope", v, 0.0, 2.0)?;
            Err(ParamError::Constraint { what: "envelope must be 0 (polynomial), 1 (tanh) or 2 (Gaussian)" })
        }
    }
    fn code(self) -> f32 {
        match self {
            Self::Polynomial => 0.0,
            Self::Tanh => 1.0,
            Self::Gaussian => 2.0,
        }
    }
}

/// Coefficients `(a, b, c)` of one envelope function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvelopeCoeffs {
    pub a: f32,
    pub b: f32,
    pub c: f32,
}

impl EnvelopeCoeffs {
    pub const fn new(a: f32, b: f32, c: f32) -> Self {
        Self { a, b, c }
    }
}

/// Coefficients of eq. 16–22 with `N` generalized play operators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gpi<const N: usize> {
    /// Linear gain p₀ (G[x] = p₀·x).
    pub p0: f32,
    /// Initial condition M₀ of every operator.
    pub m0: f32,
    /// Density scale δ₁ ≥ 0.
    pub delta1: f32,
    /// Density decay δ₂ ≥ 0.
    pub delta2: f32,
    /// Loading (rising) envelope α_R.
    pub rising: EnvelopeCoeffs,
    /// Unloading (falling) envelope α_L.
    pub falling: EnvelopeCoeffs,
    /// Input range the radii span.
    pub x_min: f32,
    pub x_max: f32,
    pub envelope: Envelope,
    /// Radii rᵢ (unit of x), ascending from 0 to x_max − x_min.
    r: [f32; N],
    /// Weights pᵢ = δ₁·exp(−δ₂·rᵢ).
    w: [f32; N],
    /// 1/(2c) of the Gaussian envelopes (0 otherwise).
    inv2c: [f32; 2],
    dt: f32,
}

/// Outputs of the `N` generalized play operators (unit of x).
pub type State<const N: usize> = crate::model::OperatorStates<N>;

/// Seed 004 fits 10 and 15 operators (Tables A9–A14); 10 is the registered size.
pub type Registered = Gpi<10>;

impl<const N: usize> Gpi<N> {
    /// Paper form. `δ₁, δ₂ ≥ 0`, `x_min < x_max`, every coefficient finite, `c ≠ 0`
    /// for Gaussian envelopes, `1 ≤ N ≤ 64`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        envelope: Envelope,
        p0: f32,
        m0: f32,
        delta1: f32,
        delta2: f32,
        rising: EnvelopeCoeffs,
        falling: EnvelopeCoeffs,
        x_min: f32,
        x_max: f32,
        dt: f32,
    ) -> Result<Self, ParamError> {
        operator_count(N)?;
        let p0 = finite("p0", p0)?;
        let m0 = finite("m0", m0)?;
        let delta1 = check("delta1", delta1, 0.0, f32::MAX)?;
        let delta2 = check("delta2", delta2, 0.0, f32::MAX)?;
        for (name, v) in [
            ("a_r", rising.a),
            ("b_r", rising.b),
            ("c_r", rising.c),
            ("a_l", falling.a),
            ("b_l", falling.b),
            ("c_l", falling.c),
        ] {
            finite(name, v)?;
        }
        let x_min = finite("x_min", x_min)?;
        let x_max = finite("x_max", x_max)?;
        let span = x_max - x_min;
        if !(span > 0.0 && span.is_finite()) {
            return Err(ParamError::Constraint { what: "x_min < x_max (finite span)" });
        }
        let mut inv2c = [0.0; 2];
        if envelope == Envelope::Gaussian {
            for (o, c) in inv2c.iter_mut().zip([rising.c, falling.c]) {
                *o = 0.5 / c;
                if c == 0.0 || !o.is_finite() {
                    return Err(ParamError::Constraint { what: "Gaussian envelope needs c != 0" });
                }
            }
        }
        let mut r = [0.0; N];
        let mut w = [0.0; N];
        let last = N.saturating_sub(1).max(1) as f32;
        for (i, (ri, wi)) in r.iter_mut().zip(w.iter_mut()).enumerate() {
            *ri = span * (i as f32 / last);
            *wi = delta1 * exp(-delta2 * *ri);
        }
        if !w.is_finite() {
            return Err(ParamError::Constraint { what: "GPI weights overflow" });
        }
        Ok(Self { p0, m0, delta1, delta2, rising, falling, x_min, x_max, envelope, r, w, inv2c, dt: time_step(dt)? })
    }

    /// Radii rᵢ (unit of x).
    pub fn radii(&self) -> &[f32; N] {
        &self.r
    }

    /// Weights pᵢ (eq. 22).
    pub fn weights(&self) -> &[f32; N] {
        &self.w
    }

    #[inline]
    fn eval(&self, e: &EnvelopeCoeffs, inv2c: f32, x: f32) -> f32 {
        match self.envelope {
            Envelope::Polynomial => x * x + e.a * x + e.b,
            Envelope::Tanh => e.a * tanh(x + e.b) + e.c,
            Envelope::Gaussian => {
                let d = x - e.b;
                e.a * exp(-(d * d) * inv2c)
            }
        }
    }

    /// `(α_R(x), α_L(x))`.
    #[inline]
    pub fn envelopes(&self, x: f32) -> (f32, f32) {
        let [ir, il] = self.inv2c;
        (self.eval(&self.rising, ir, x), self.eval(&self.falling, il, x))
    }

    /// Whether `α_R(x) − r ≤ α_L(x) + r` holds for every radius at `samples` points
    /// of `[x_min, x_max]` (the paper's order-preservation condition; the smallest
    /// radius is 0, so this is `α_R ≤ α_L` on the range).
    pub fn order_preserving(&self, samples: usize) -> bool {
        let n = samples.max(2);
        (0..n).all(|i| {
            let x = self.x_min + (self.x_max - self.x_min) * (i as f32 / (n - 1) as f32);
            let (ar, al) = self.envelopes(x);
            ar <= al
        })
    }
}

/// One generalized play step, eq. 16. The result lies between `α_R − r` and `α_L + r`.
#[inline(always)]
fn gplay(ar: f32, al: f32, r: f32, prev: f32) -> f32 {
    (al + r).min(prev).max(ar - r)
}

impl<const N: usize> Model for Gpi<N> {
    type State = State<N>;
    const ID: &'static str = "gpi";
    const PARAM_NAMES: &'static [&'static str] =
        &["p0", "m0", "delta1", "delta2", "a_r", "b_r", "c_r", "a_l", "b_l", "c_l", "x_min", "x_max", "envelope"];
    const N_PARAMS: usize = 13;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [p0, m0, d1, d2, ar, br, cr, al, bl, cl, x_min, x_max, env] => Self::new(
                Envelope::from_code(env)?,
                p0,
                m0,
                d1,
                d2,
                EnvelopeCoeffs::new(ar, br, cr),
                EnvelopeCoeffs::new(al, bl, cl),
                x_min,
                x_max,
                dt,
            ),
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let (r, l) = (self.rising, self.falling);
        write_flat(
            &[
                self.p0,
                self.m0,
                self.delta1,
                self.delta2,
                r.a,
                r.b,
                r.c,
                l.a,
                l.b,
                l.c,
                self.x_min,
                self.x_max,
                self.envelope.code(),
            ],
            out,
        )
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    /// Eq. 17: every operator starts from `M₀`, confined by the envelopes at `x(0)`.
    fn initial_state(&self, first: &Kin) -> State<N> {
        let (ar, al) = self.envelopes(first.x);
        let mut s = State::default();
        for (z, r) in s.z.iter_mut().zip(self.r) {
            *z = gplay(ar, al, r, self.m0);
        }
        s
    }

    #[inline]
    fn step(&self, s: &mut State<N>, k: &Kin) -> f32 {
        let x = k.x;
        let (ar, al) = self.envelopes(x);
        let mut y = self.p0 * x;
        for ((z, r), w) in s.z.iter_mut().zip(self.r).zip(self.w) {
            *z = gplay(ar, al, r, *z);
            y += w * *z;
        }
        y
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;

    fn kin(x: f32) -> Kin {
        Kin::new(x, 0.0, 0.0, 0.0)
    }

    /// Seed 004 Table A9 (tanh envelopes, 10 operators), signs as printed.
    fn table_a9() -> Gpi<10> {
        Gpi::new(
            Envelope::Tanh,
            0.4084,
            0.1185,
            0.1872,
            0.1920,
            EnvelopeCoeffs::new(1.2251, 0.5371, 0.2911),
            EnvelopeCoeffs::new(2.1285, 1.9745, 1.7202),
            0.0,
            1.0,
            1e-3,
        )
        .unwrap()
    }

    #[test]
    fn radii_weights_and_envelopes_by_hand() {
        let m = table_a9();
        assert!((m.radii()[0]).abs() < 1e-7 && (m.radii()[9] - 1.0).abs() < 1e-6);
        assert!((m.radii()[3] - 1.0 / 3.0).abs() < 1e-6);
        let want = 0.1872 * (-0.1920f64 / 3.0).exp();
        assert!((f64::from(m.weights()[3]) - want).abs() < 1e-6);
        let (ar, al) = m.envelopes(0.3);
        assert!((f64::from(ar) - (1.2251 * (0.8371f64).tanh() + 0.2911)).abs() < 1e-5);
        assert!((f64::from(al) - (2.1285 * (2.2745f64).tanh() + 1.7202)).abs() < 1e-5);
        let poly = Gpi::<3>::new(
            Envelope::Polynomial,
            0.0,
            0.0,
            1.0,
            0.0,
            EnvelopeCoeffs::new(0.7144, 0.3616, 0.0),
            EnvelopeCoeffs::new(0.8169, 0.4579, 0.0),
            0.0,
            1.0,
            1e-3,
        )
        .unwrap();
        let (ar, _) = poly.envelopes(0.5);
        assert!((ar - (0.25 + 0.3572 + 0.3616)).abs() < 1e-6);
        let gauss = Gpi::<3>::new(
            Envelope::Gaussian,
            0.0,
            0.0,
            1.0,
            0.0,
            EnvelopeCoeffs::new(4.9515, 1.6332, 2.3430),
            EnvelopeCoeffs::new(2.8279, 1.2269, 4.6150),
            0.0,
            1.0,
            1e-3,
        )
        .unwrap();
        let (ar, al) = gauss.envelopes(0.5);
        let want_r = 4.9515 * (-(0.5f64 - 1.6332).powi(2) / (2.0 * 2.3430)).exp();
        let want_l = 2.8279 * (-(0.5f64 - 1.2269).powi(2) / (2.0 * 4.6150)).exp();
        assert!((f64::from(ar) - want_r).abs() < 1e-5 && (f64::from(al) - want_l).abs() < 1e-5);
    }

    /// Eq. 16–18 by hand for two operators with polynomial envelopes.
    #[test]
    fn operator_by_hand() {
        // α_R = x² + 0·x − 0.1, α_L = x² + 0·x + 0.1; radii 0 and 1; weights 1, e^{-1}.
        let m = Gpi::<2>::new(
            Envelope::Polynomial,
            0.5,
            0.0,
            1.0,
            1.0,
            EnvelopeCoeffs::new(0.0, -0.1, 0.0),
            EnvelopeCoeffs::new(0.0, 0.1, 0.0),
            0.0,
            1.0,
            1e-3,
        )
        .unwrap();
        let mut s = m.initial_state(&kin(0.0));
        // x=0: op1 in [−0.1, 0.1] from M0 = 0 → 0; op2 in [−1.1, 1.1] → 0.
        assert_eq!(s.z, [0.0, 0.0]);
        // x = 0.8: α_R = 0.54, α_L = 0.74 → op1 = 0.54, op2 = max(−0.46, min(1.74, 0)) = 0
        let y = m.step(&mut s, &kin(0.8));
        assert!((y - (0.4 + 0.54)).abs() < 1e-6, "{y}");
        // x = 0.5: α_R = 0.15, α_L = 0.35 → op1 = min(0.35, 0.54) = 0.35
        let y = m.step(&mut s, &kin(0.5));
        assert!((y - (0.25 + 0.35)).abs() < 1e-6, "{y}");
    }

    /// One period of the steady loop for `x = c + a·sin`.
    fn steady_loop(m: &Gpi<10>, c: f32, a: f32, n: usize) -> Vec<f32> {
        let x = |i: usize| c + a * (2.0 * core::f32::consts::PI * (i % n) as f32 / n as f32).sin();
        let mut s = m.initial_state(&kin(x(0)));
        let mut ys = Vec::new();
        for i in 0..4 * n {
            ys.push(m.step(&mut s, &kin(x(i))));
        }
        ys.split_off(3 * n)
    }

    /// Point-symmetry defect of a loop: max |y(t) + y(t+T/2) − 2ȳ| / range.
    fn asymmetry(y: &[f32]) -> f32 {
        let n = y.len();
        let yc = y.iter().sum::<f32>() / n as f32;
        let range = y.iter().cloned().fold(f32::MIN, f32::max) - y.iter().cloned().fold(f32::MAX, f32::min);
        (0..n / 2).map(|i| (y[i] + y[i + n / 2] - 2.0 * yc).abs()).fold(0.0, f32::max) / range
    }

    /// Seed 004 Table A11 (polynomial envelopes, 10 operators), signs as printed.
    fn table_a11() -> Gpi<10> {
        Gpi::new(
            Envelope::Polynomial,
            0.1060,
            0.0485,
            0.1752,
            2.7863,
            EnvelopeCoeffs::new(0.7144, 0.3616, 0.0),
            EnvelopeCoeffs::new(0.8169, 0.4579, 0.0),
            0.0,
            1.0,
            1e-3,
        )
        .unwrap()
    }

    /// Different loading/unloading envelopes give a loop that is not point-symmetric;
    /// the same odd envelope on both sides gives a point-symmetric one.
    #[test]
    fn asymmetry_enters_through_the_envelopes() {
        let y = steady_loop(&table_a11(), 0.5, 0.5, 400);
        let asym = asymmetry(&y);
        assert!(asym > 0.05, "asymmetric GPI loop index {asym}");
        let width = (y[0] - y[200]).abs();
        assert!(width > 0.01, "asymmetric loop width {width}");

        // Symmetric configuration: α_R = α_L = tanh(x − 0.5), odd about the centre 0.5.
        let e = EnvelopeCoeffs::new(1.0, -0.5, 0.0);
        let sym = Gpi::<10>::new(Envelope::Tanh, 0.4, 0.0, 0.5, 0.5, e, e, 0.0, 1.0, 1e-3).unwrap();
        let y = steady_loop(&sym, 0.5, 0.5, 400);
        let s = asymmetry(&y);
        eprintln!("GPI asymmetry index: Table A11 {asym:.4}, symmetric tanh {s:.2e}");
        assert!(s < 1e-3, "symmetric GPI loop index {s}");
        // …and it really is a loop (non-zero width), not a single curve.
        let width = (y[0] - y[200]).abs();
        assert!(width > 0.01, "loop width {width}");
    }

    #[test]
    fn order_preservation_check() {
        assert!(table_a9().order_preserving(101));
        let bad = Gpi::<2>::new(
            Envelope::Polynomial,
            0.0,
            0.0,
            1.0,
            0.0,
            EnvelopeCoeffs::new(0.0, 0.2, 0.0),
            EnvelopeCoeffs::new(0.0, 0.0, 0.0),
            0.0,
            1.0,
            1e-3,
        )
        .unwrap();
        assert!(!bad.order_preserving(11));
    }

    #[test]
    fn rejects_bad_params() {
        let ok = [0.4, 0.1, 0.2, 0.2, 1.2, 0.5, 0.3, 2.1, 1.9, 1.7, 0.0, 1.0, 1.0];
        let m = Gpi::<10>::from_params(&ok, 1e-3).unwrap();
        let mut out = [0.0; 13];
        assert_eq!(m.write_params(&mut out), 13);
        assert_eq!(out, ok);
        for (i, v) in [(2, -0.1), (3, -1.0), (10, 2.0), (12, 3.0), (12, 0.5), (0, f32::NAN)] {
            let mut bad = ok;
            bad[i] = v;
            assert!(Gpi::<10>::from_params(&bad, 1e-3).is_err(), "index {i} = {v}");
        }
        let mut gauss0 = ok;
        gauss0[12] = 2.0;
        gauss0[6] = 0.0;
        assert!(Gpi::<10>::from_params(&gauss0, 1e-3).is_err());
        assert!(Gpi::<10>::from_params(&ok[..12], 1e-3).is_err());
    }
}
