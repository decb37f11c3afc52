//! Maxwell-slip model, seed 004 eq. 23–25 (de la Morena et al. 2025): `N` elasto-slide
//! elements (a massless linear spring of stiffness `kᵢ` pulling a block with Coulomb
//! breakaway force `fᵢ`) in parallel,
//!
//! `Fᵢ = kᵢ·(x − x_bᵢ)` while `|kᵢ·(x − x_bᵢ)| < fᵢ`, else `Fᵢ = fᵢ·sgn(ẋ)` and the block
//! follows, `x_bᵢ = x − (fᵢ/kᵢ)·sgn(ẋ)`  (eq. 23–24),
//!
//! `Φ = w₀ + Σᵢ Fᵢ`  (eq. 25), here plus an optional linear term `k₀·x`
//! (`k₀ = 0` is the paper's model).
//!
//! Exact per-step update: the state is each spring's deflection `dᵢ = x − x_bᵢ`. Over a
//! step the input moves by `Δx`; a block only moves once its spring force reaches `fᵢ`,
//! so `dᵢ ← clamp(dᵢ + Δx, −fᵢ/kᵢ, +fᵢ/kᵢ)`. This is eq. 23–24 with `sgn(ẋ) = sgn(Δx)`,
//! rate-independent, and exact for any input that is monotone between samples. The
//! deflections never leave `±fᵢ/kᵢ`.
//!
//! Units: x in the unit it was fitted in, `kᵢ` and `k₀` in output units per unit x,
//! `fᵢ` and `w₀` in output units.

use crate::error::{check, count, finite, time_step};
use crate::math::clamp;
use crate::model::write_flat;
use crate::models::kernels::names::{block_names, pick};
use crate::models::kernels::operators::{operator_count, to_array, MAX_OPERATORS};
use crate::{Finite, Kin, Model, ParamError};

const K_BLOCKS: [&str; MAX_OPERATORS + 1] = block_names!("k");
const F_BLOCKS: [&str; MAX_OPERATORS + 1] = block_names!("f");

/// Coefficients of eq. 23–25 with `N` elasto-slide elements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxwellSlip<const N: usize> {
    /// Output offset w₀ (output units).
    w0: f32,
    /// Spring stiffnesses kᵢ > 0 (output units per unit x).
    k: [f32; N],
    /// Breakaway forces fᵢ ≥ 0 (output units).
    f: [f32; N],
    /// Linear term k₀ (output units per unit x); 0 in seed 004.
    k0: f32,
    /// Deflection limits fᵢ/kᵢ (unit of x).
    lim: [f32; N],
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const N: usize> MaxwellSlip<N> {
    /// Output offset w₀ (output units).
    #[inline]
    pub fn w0(&self) -> f32 {
        self.w0
    }

    /// Spring stiffnesses kᵢ > 0 (output units per unit x).
    #[inline]
    pub fn k(&self) -> &[f32; N] {
        &self.k
    }

    /// Breakaway forces fᵢ ≥ 0 (output units).
    #[inline]
    pub fn f(&self) -> &[f32; N] {
        &self.f
    }

    /// Linear term k₀ (output units per unit x); 0 in seed 004.
    #[inline]
    pub fn k0(&self) -> f32 {
        self.k0
    }
}

/// Previous input and the spring deflections `dᵢ = x − x_bᵢ` (unit of x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<const N: usize> {
    pub x_prev: f32,
    pub d: [f32; N],
}

impl<const N: usize> Default for State<N> {
    fn default() -> Self {
        Self { x_prev: 0.0, d: [0.0; N] }
    }
}

impl<const N: usize> Finite for State<N> {
    fn is_finite(&self) -> bool {
        self.x_prev.is_finite() && self.d.is_finite()
    }
}

/// Seed 004 fits 10 elements (Table A15).
pub type Registered = MaxwellSlip<10>;

impl<const N: usize> MaxwellSlip<N> {
    /// `kᵢ > 0`, `fᵢ ≥ 0` (seed 004 Table A15 bounds 0.01…10 and 0…10), `w₀`, `k₀` finite,
    /// `1 ≤ N ≤ 64`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::maxwell_slip::MaxwellSlip;
    /// use model_core::{Kin, Model};
    ///
    /// // Two elasto-slide elements (stiffness k, slip force f), offset w₀, linear spring k₀.
    /// let model = MaxwellSlip::new(0.1, [1.0, 10.0], [0.5, 0.2], 0.3, 1e-3)?;
    /// let mut state = model.initial_state(&Kin::new(0.0, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(0.04, 0.0, 0.0, 0.0));
    /// assert!(y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(w0: f32, k: [f32; N], f: [f32; N], k0: f32, dt: f32) -> Result<Self, ParamError> {
        operator_count(N)?;
        let mut lim = [0.0; N];
        for ((l, ki), fi) in lim.iter_mut().zip(k).zip(f) {
            let ki = check("k", ki, f32::MIN_POSITIVE, f32::MAX)?;
            let fi = check("f", fi, 0.0, f32::MAX)?;
            *l = fi / ki;
            if !l.is_finite() {
                return Err(ParamError::Constraint { what: "slip deflection f/k overflows" });
            }
        }
        Ok(Self { w0: finite("w0", w0)?, k, f, k0: finite("k0", k0)?, lim, dt: time_step(dt)? })
    }

    /// Deflection limits `fᵢ/kᵢ` (unit of x): the state bound `|dᵢ| ≤ fᵢ/kᵢ`.
    pub fn deflection_limits(&self) -> &[f32; N] {
        &self.lim
    }
}

impl<const N: usize> Model for MaxwellSlip<N> {
    type State = State<N>;
    const ID: &'static str = "maxwell_slip";
    const PARAM_NAMES: &'static [&'static str] = &["w0", pick(&K_BLOCKS, N), pick(&F_BLOCKS, N), "k0"];
    const N_PARAMS: usize = 2 + 2 * N;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        let wrong = ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() };
        let [w0, rest @ .., k0] = v else { return Err(wrong) };
        let (k, f) = rest.split_at_checked(N).ok_or(wrong)?;
        Self::new(*w0, to_array(k), to_array(f), *k0, dt)
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let (head, rest) = out.split_at_mut(out.len().min(1));
        let mut n = write_flat(&[self.w0], head);
        let (ko, rest) = rest.split_at_mut(rest.len().min(N));
        n += write_flat(&self.k, ko);
        let (fo, rest) = rest.split_at_mut(rest.len().min(N));
        n += write_flat(&self.f, fo);
        n += write_flat(&[self.k0], rest);
        n
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    /// Springs relaxed (every block at the first input, `dᵢ = 0`).
    fn initial_state(&self, first: &Kin) -> State<N> {
        State { x_prev: first.x, d: [0.0; N] }
    }

    #[inline]
    fn step(&self, s: &mut State<N>, k: &Kin) -> f32 {
        let x = k.x;
        let dx = x - s.x_prev;
        s.x_prev = x;
        let mut y = self.w0 + self.k0 * x;
        for ((d, lim), ki) in s.d.iter_mut().zip(self.lim).zip(self.k) {
            // NaN-safe: `clamp` maps NaN to the lower limit; ±∞ to the limits.
            *d = clamp(*d + dx, -lim, lim);
            y += ki * *d;
        }
        y
    }
}

#[cfg(test)]
mod tests;
