//! Hammerstein–Wiener model, seed 000 eq. 15–17 and §6 (evaluator only; training lives in
//! `hil-sim`):
//!
//! `x(t) = H(B(t))`,  `v(t) = [B(q)/F(q)]·x(t − 1)`,  `T(t) = W(v(t))`.
//!
//! - H and W are scalar sigmoid networks (MATLAB's `sigmoidnet` form)
//!   `N(u) = lin·u + d + Σᵢ aᵢ·σ(wᵢ·u + bᵢ)`, `σ(s) = 1/(1 + e^{−s})`, with `NH` and `NW`
//!   units. Seed 000 used wavelet networks; a sigmoid network is one of the toolbox's
//!   options the paper lists, is cheaper on the Cortex-M4F (one `exp` per unit) and is
//!   bounded apart from its linear term.
//! - The linear block has two zeros, five poles and one sample of input delay (seed 000
//!   §6): `v(t) = b₀x(t−1) + b₁x(t−2) + b₂x(t−3) − f₁v(t−1) − … − f₅v(t−5)`.
//!
//! # Parameters (flat vector order)
//! `h_a[NH], h_w[NH], h_b[NH], h_lin, h_d, lin_b[3], lin_f[5], w_a[NW], w_w[NW], w_b[NW],
//! w_lin, w_d, v_min, v_max` — `3·NH + 3·NW + 14` values; [`Registered`] (`NH = 14`,
//! `NW = 13`) has 95, about seed 000's 94 units.
//!
//! # Guards
//! `new` checks that every weight is finite with `|·| ≤ 1e6`, that `v_min < v_max`, and
//! that `1 + f₁z⁻¹ + … + f₅z⁻⁵` has all poles strictly inside the unit circle (Schur–Cohn
//! step-down recursion on the coefficients, in f64). In the step `x` is clamped to
//! `±1e20` and `v` to `[v_min, v_max]` (a non-finite v holds the previous value), so the
//! state stays finite for any finite input.
//!
//! The state starts at the steady state of the first sample (`x` repeated, `v` at the DC
//! gain `Σb/(1 + Σf)` times x, clamped), so a constant input gives a constant output.

use crate::error::{check, count, time_step};
use crate::math::clamp;
use crate::model::write_flat;
use crate::models::kernels::flat::take;
use crate::models::kernels::names::BlockName;
use crate::models::kernels::sigmoid::sigmoid;
pub use crate::models::kernels::sigmoid::W_MAX;
use crate::{Finite, Kin, Model, ParamError};

/// Clamp of the Hammerstein output x.
const X_LIM: f32 = 1.0e20;

/// A scalar sigmoid network `lin·u + d + Σ aᵢ·σ(wᵢ·u + bᵢ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmoidNet<const N: usize> {
    pub a: [f32; N],
    pub w: [f32; N],
    pub b: [f32; N],
    pub lin: f32,
    pub d: f32,
}

impl<const N: usize> SigmoidNet<N> {
    /// Evaluate the network at `u`.
    #[inline]
    pub fn eval(&self, u: f32) -> f32 {
        let mut y = self.lin * u + self.d;
        for ((a, w), b) in self.a.iter().zip(self.w.iter()).zip(self.b.iter()) {
            y += a * sigmoid(w * u + b);
        }
        y
    }

    fn read(it: &mut core::slice::Iter<'_, f32>, names: [&'static str; 5]) -> Result<Self, ParamError> {
        let [na, nw, nb, nl, nd] = names;
        Ok(Self {
            a: take::<N>(it, na, -W_MAX, W_MAX)?,
            w: take::<N>(it, nw, -W_MAX, W_MAX)?,
            b: take::<N>(it, nb, -W_MAX, W_MAX)?,
            lin: take::<1>(it, nl, -W_MAX, W_MAX)?[0],
            d: take::<1>(it, nd, -W_MAX, W_MAX)?[0],
        })
    }

    fn write<'a>(&self, out: &'a mut [f32]) -> (&'a mut [f32], usize) {
        let mut n = 0;
        let mut rest = out;
        for block in [&self.a[..], &self.w[..], &self.b[..], &[self.lin], &[self.d]] {
            let k = write_flat(block, rest);
            n += k;
            rest = rest.get_mut(k..).unwrap_or_default();
        }
        (rest, n)
    }
}

/// True when every root of `zⁿ + a₁zⁿ⁻¹ + … + aₙ` lies strictly inside the unit circle
/// (Schur–Cohn / Jury step-down: all reflection coefficients |kᵢ| < 1; a margin of 1e−6
/// rejects poles on the circle up to the coefficients' f32 rounding).
pub fn schur_stable(a: &[f32; 5]) -> bool {
    let mut p = [1.0f64, 0.0, 0.0, 0.0, 0.0, 0.0];
    for (d, s) in p.iter_mut().skip(1).zip(a.iter()) {
        *d = f64::from(*s);
    }
    let mut m = p.len() - 1;
    while m > 0 {
        let k = p.get(m).copied().unwrap_or(0.0);
        if !(k.abs() < 1.0 - 1.0e-6 && k.is_finite()) {
            return false;
        }
        let den = 1.0 - k * k;
        let mut q = [0.0f64; 6];
        for i in 0..m {
            let ai = p.get(i).copied().unwrap_or(0.0);
            let ar = p.get(m - i).copied().unwrap_or(0.0);
            if let Some(qi) = q.get_mut(i) {
                *qi = (ai - k * ar) / den;
            }
        }
        p = q;
        m -= 1;
    }
    true
}

/// Coefficients of the H–W model with `NH` input and `NW` output sigmoid units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HammersteinWiener<const NH: usize, const NW: usize> {
    /// Input nonlinearity H (eq. 15).
    h: SigmoidNet<NH>,
    /// Numerator b₀, b₁, b₂ (two zeros), acting on x(t−1), x(t−2), x(t−3).
    lin_b: [f32; 3],
    /// Denominator f₁ … f₅ of `1 + f₁q⁻¹ + … + f₅q⁻⁵` (five poles).
    lin_f: [f32; 5],
    /// Output nonlinearity W (eq. 17).
    w: SigmoidNet<NW>,
    /// Range the internal v is clamped to.
    v_min: f32,
    v_max: f32,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const NH: usize, const NW: usize> HammersteinWiener<NH, NW> {
    /// Input nonlinearity H (eq. 15).
    #[inline]
    pub fn h(&self) -> &SigmoidNet<NH> {
        &self.h
    }

    /// Numerator b₀, b₁, b₂ (two zeros), acting on x(t−1), x(t−2), x(t−3).
    #[inline]
    pub fn lin_b(&self) -> &[f32; 3] {
        &self.lin_b
    }

    /// Denominator f₁ … f₅ of `1 + f₁q⁻¹ + … + f₅q⁻⁵` (five poles).
    #[inline]
    pub fn lin_f(&self) -> &[f32; 5] {
        &self.lin_f
    }

    /// Output nonlinearity W (eq. 17).
    #[inline]
    pub fn w(&self) -> &SigmoidNet<NW> {
        &self.w
    }

    /// Range the internal v is clamped to.
    #[inline]
    pub fn v_min(&self) -> f32 {
        self.v_min
    }

    /// Upper end of the range the internal v is clamped to.
    #[inline]
    pub fn v_max(&self) -> f32 {
        self.v_max
    }
}

/// Past values of the linear block: `xs = [x(t−1), x(t−2), x(t−3)]`, `vs = [v(t−1), …, v(t−5)]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    pub xs: [f32; 3],
    pub vs: [f32; 5],
}

impl Finite for State {
    fn is_finite(&self) -> bool {
        self.xs.is_finite() && self.vs.is_finite()
    }
}

/// 14 + 13 sigmoid units: 95 parameters (seed 000: 94 units).
pub type Registered = HammersteinWiener<14, 13>;

impl<const NH: usize, const NW: usize> HammersteinWiener<NH, NW> {
    const N_H_A: BlockName = BlockName::new("h_a", NH);
    const N_H_W: BlockName = BlockName::new("h_w", NH);
    const N_H_B: BlockName = BlockName::new("h_b", NH);
    const N_W_A: BlockName = BlockName::new("w_a", NW);
    const N_W_W: BlockName = BlockName::new("w_w", NW);
    const N_W_B: BlockName = BlockName::new("w_b", NW);

    /// Validate and build (see the module doc for the checks).
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::hammerstein_wiener::{HammersteinWiener, SigmoidNet};
    /// use model_core::{Kin, Model};
    ///
    /// let h = SigmoidNet { a: [2.0, -1.0], w: [1.5, 0.5], b: [0.1, -0.2], lin: 0.3, d: 0.05 };
    /// let w = SigmoidNet { a: [1.0], w: [0.5], b: [0.0], lin: 1.0, d: 0.0 };
    /// // Numerator b₀…b₂ (two zeros), denominator f₁…f₅ with five poles at 0.5 (stable), v in ±10.
    /// let (lin_b, lin_f) = ([0.5, 0.2, 0.1], [-2.5, 2.5, -1.25, 0.3125, -0.03125]);
    /// let model = HammersteinWiener::new(h, lin_b, lin_f, w, -10.0, 10.0, 1e-3)?;
    /// let mut state = model.initial_state(&Kin::new(1.0, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(1.1, 0.0, 0.0, 0.0));
    /// assert!(y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(
        h: SigmoidNet<NH>,
        lin_b: [f32; 3],
        lin_f: [f32; 5],
        w: SigmoidNet<NW>,
        v_min: f32,
        v_max: f32,
        dt: f32,
    ) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        for (name, blk) in [
            ("h_a", &h.a[..]),
            ("h_w", &h.w[..]),
            ("h_b", &h.b[..]),
            ("w_a", &w.a[..]),
            ("w_w", &w.w[..]),
            ("w_b", &w.b[..]),
        ] {
            for v in blk {
                check(name, *v, -W_MAX, W_MAX)?;
            }
        }
        for (name, v) in [("h_lin", h.lin), ("h_d", h.d), ("w_lin", w.lin), ("w_d", w.d)] {
            check(name, v, -W_MAX, W_MAX)?;
        }
        for v in lin_b {
            check("lin_b", v, -W_MAX, W_MAX)?;
        }
        for v in lin_f {
            check("lin_f", v, -W_MAX, W_MAX)?;
        }
        let v_min = check("v_min", v_min, -1.0e15, 1.0e15)?;
        let v_max = check("v_max", v_max, -1.0e15, 1.0e15)?;
        if v_min >= v_max {
            return Err(ParamError::Constraint { what: "H-W v_min must be < v_max" });
        }
        if !schur_stable(&lin_f) {
            return Err(ParamError::Constraint {
                what: "H-W linear block unstable: a pole of 1/F(q) is on or outside the unit circle",
            });
        }
        Ok(Self { h, lin_b, lin_f, w, v_min, v_max, dt })
    }

    /// DC gain of the linear block, `Σb / (1 + Σf)`.
    pub fn dc_gain(&self) -> f32 {
        let nb: f32 = self.lin_b.iter().sum();
        let df: f32 = 1.0 + self.lin_f.iter().sum::<f32>();
        nb / df
    }

    #[inline]
    fn clamp_v(&self, v: f32, hold: f32) -> f32 {
        if v.is_nan() {
            hold
        } else {
            clamp(v, self.v_min, self.v_max)
        }
    }
}

impl<const NH: usize, const NW: usize> Model for HammersteinWiener<NH, NW> {
    type State = State;
    const ID: &'static str = "hammerstein_wiener";
    const PARAM_NAMES: &'static [&'static str] = &[
        Self::N_H_A.as_str(),
        Self::N_H_W.as_str(),
        Self::N_H_B.as_str(),
        "h_lin",
        "h_d",
        "lin_b[3]",
        "lin_f[5]",
        Self::N_W_A.as_str(),
        Self::N_W_W.as_str(),
        Self::N_W_B.as_str(),
        "w_lin",
        "w_d",
        "v_min",
        "v_max",
    ];
    const N_PARAMS: usize = 3 * NH + 3 * NW + 14;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        let mut it = v.iter();
        let h = SigmoidNet::<NH>::read(&mut it, ["h_a", "h_w", "h_b", "h_lin", "h_d"])?;
        let lin_b = take::<3>(&mut it, "lin_b", -W_MAX, W_MAX)?;
        let lin_f = take::<5>(&mut it, "lin_f", -W_MAX, W_MAX)?;
        let w = SigmoidNet::<NW>::read(&mut it, ["w_a", "w_w", "w_b", "w_lin", "w_d"])?;
        let [v_min] = take::<1>(&mut it, "v_min", f32::NEG_INFINITY, f32::INFINITY)?;
        let [v_max] = take::<1>(&mut it, "v_max", f32::NEG_INFINITY, f32::INFINITY)?;
        Self::new(h, lin_b, lin_f, w, v_min, v_max, dt)
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let (rest, mut n) = self.h.write(out);
        let k = write_flat(&self.lin_b, rest);
        n += k;
        let rest = rest.get_mut(k..).unwrap_or_default();
        let k = write_flat(&self.lin_f, rest);
        n += k;
        let rest = rest.get_mut(k..).unwrap_or_default();
        let (rest, k) = self.w.write(rest);
        n += k;
        n + write_flat(&[self.v_min, self.v_max], rest)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    fn initial_state(&self, first: &Kin) -> State {
        let x = clamp(self.h.eval(first.x), -X_LIM, X_LIM);
        let v = self.clamp_v(self.dc_gain() * x, 0.0);
        let v = if v.is_finite() { v } else { 0.0 };
        State { xs: [x; 3], vs: [v; 5] }
    }

    #[inline]
    fn step(&self, s: &mut State, k: &Kin) -> f32 {
        let x = clamp(self.h.eval(k.x), -X_LIM, X_LIM);
        let [v1, v2, v3, v4, _] = s.vs;
        let mut v = 0.0f32;
        for (b, xp) in self.lin_b.iter().zip(s.xs.iter()) {
            v += b * xp;
        }
        for (f, vp) in self.lin_f.iter().zip(s.vs.iter()) {
            v -= f * vp;
        }
        let v = self.clamp_v(v, v1);
        let [x1, x2, _] = s.xs;
        s.xs = [x, x1, x2];
        s.vs = [v, v1, v2, v3, v4];
        self.w.eval(v)
    }
}

#[cfg(test)]
mod tests;
