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
use crate::models::kernels::operators::operator_count;
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
    p0: f32,
    /// Initial condition M₀ of every operator.
    m0: f32,
    /// Density scale δ₁ ≥ 0.
    delta1: f32,
    /// Density decay δ₂ ≥ 0.
    delta2: f32,
    /// Loading (rising) envelope α_R.
    rising: EnvelopeCoeffs,
    /// Unloading (falling) envelope α_L.
    falling: EnvelopeCoeffs,
    /// Input range the radii span.
    x_min: f32,
    x_max: f32,
    envelope: Envelope,
    /// Radii rᵢ (unit of x), ascending from 0 to x_max − x_min.
    r: [f32; N],
    /// Weights pᵢ = δ₁·exp(−δ₂·rᵢ).
    w: [f32; N],
    /// 1/(2c) of the Gaussian envelopes (0 otherwise).
    inv2c: [f32; 2],
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const N: usize> Gpi<N> {
    /// Linear gain p₀ (`G[x] = p₀·x`).
    #[inline]
    pub fn p0(&self) -> f32 {
        self.p0
    }

    /// Initial condition M₀ of every operator.
    #[inline]
    pub fn m0(&self) -> f32 {
        self.m0
    }

    /// Density scale δ₁ ≥ 0.
    #[inline]
    pub fn delta1(&self) -> f32 {
        self.delta1
    }

    /// Density decay δ₂ ≥ 0.
    #[inline]
    pub fn delta2(&self) -> f32 {
        self.delta2
    }

    /// Loading (rising) envelope α_R.
    #[inline]
    pub fn rising(&self) -> EnvelopeCoeffs {
        self.rising
    }

    /// Unloading (falling) envelope α_L.
    #[inline]
    pub fn falling(&self) -> EnvelopeCoeffs {
        self.falling
    }

    /// Input range the radii span.
    #[inline]
    pub fn x_min(&self) -> f32 {
        self.x_min
    }

    /// Upper end of the input range the radii span.
    #[inline]
    pub fn x_max(&self) -> f32 {
        self.x_max
    }

    /// The envelope family of α_R and α_L.
    #[inline]
    pub fn envelope(&self) -> Envelope {
        self.envelope
    }
}

/// Outputs of the `N` generalized play operators (unit of x).
pub type State<const N: usize> = crate::model::OperatorStates<N>;

/// Seed 004 fits 10 and 15 operators (Tables A9–A14); 10 is the registered size.
pub type Registered = Gpi<10>;

impl<const N: usize> Gpi<N> {
    /// Paper form. `δ₁, δ₂ ≥ 0`, `x_min < x_max`, every coefficient finite, `c ≠ 0`
    /// for Gaussian envelopes, `1 ≤ N ≤ 64`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::gpi::{Envelope, EnvelopeCoeffs, Gpi};
    /// use model_core::{Kin, Model};
    ///
    /// // Seed 004 Table A9 (tanh envelopes, 10 operators), signs as printed.
    /// let rising = EnvelopeCoeffs::new(1.2251, 0.5371, 0.2911);
    /// let falling = EnvelopeCoeffs::new(2.1285, 1.9745, 1.7202);
    /// let model = Gpi::<10>::new(Envelope::Tanh, 0.4084, 0.1185, 0.1872, 0.1920, rising, falling, 0.0, 1.0, 1e-3)?;
    /// let mut state = model.initial_state(&Kin::new(0.2, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(0.3, 0.0, 0.0, 0.0));
    /// assert!(y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
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
mod tests;
