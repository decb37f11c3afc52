//! Trigonometric (Pacejka "magic formula" type) MR damper model, seed 002 eq. 10–12, with
//! the parameters as quadratic polynomials of the coil current (eq. 31–37):
//!
//! ```text
//! f     = D·sin(C·atan(φ − k·sign(ẍ))) + c·ẋ + S_v        (eq. 10)
//! φ     = B_vel + 0.1·atan(B_vel)                          (eq. 11, curvature factor fixed at 0.1)
//! B_vel = B·(ẋ + S_h)                                      (eq. 12)
//! P(i)  = P0 + P1·i + P2·i²   for P ∈ {D, C, B, S_h, S_v, k, c}   (eq. 31–37)
//! ```
//!
//! `D` peak factor (force unit), `C` shape factor, `B` stiffness factor (s per unit x),
//! `S_h` horizontal shift (unit x per s), `S_v` vertical shift (force unit), `k` hysteresis
//! magnitude, `c` post-yield viscous slope (force·s per unit x). Seed 002 works in kN and
//! mm/s (Table 1: D 0.15–0.2, B 0.005–0.1, S_h −17…10, c 0.00025–0.00035 at 0 A, 2 Hz).
//! `i` is the command ([`Kin::u`], coil current in A), used as is.
//!
//! **Flat vector.** Seven blocks of three, `[P0, P1, P2]` per parameter in the order
//! D, C, B, S_h, S_v, k, c: the current-dependent form of eq. 31–37 directly, the constant
//! (single-current, eq. 10–12 only) form with `P1 = P2 = 0`.
//!
//! **Bounds.** Table 1 is the genetic-algorithm search box for one current and frequency
//! (its `k` bounds are even printed inverted, 1.2 > 0.8), not an admissible range, so it is
//! not enforced literally. What is enforced is the sign structure it implies, over the
//! current range `0 ≤ i ≤ I_MAX = 2 A` of the RD-1005-3 (seeds 002/003): `D(i) ≥ 0`,
//! `0 ≤ C(i) ≤ 2` (one hump of the sine over the arctan range), `B(i) ≥ 0`, `k(i) ≥ 0`,
//! `c(i) ≥ 0`; `S_h`, `S_v` any finite value. The published polynomials (eq. 31–37) pass.
//! Outside `[0, I_MAX]` the polynomials are evaluated as they are.
//!
//! **Chattering.** `k·sign(ẍ)` switches the branch on the sign of the acceleration
//! estimate; with noisy `ẍ` (backward differences) it flips near velocity extrema and at
//! slow motion, and the force jumps between the two branches (up to
//! `2·D·sin(C·…)`-sized steps). Seed 002 estimates `ẋ`, `ẍ` with a Kalman filter
//! (eq. 19–27) for that reason: use `RateParams::kalman` (or `filtered`). `sign(0) = 0`.

use crate::error::{count, finite, time_step};
use crate::math::{atan, sign, sin};
use crate::model::write_flat;
use crate::models::kernels::poly::poly;
use crate::{Kin, Model, ParamError};

/// Upper end of the current range the constructor checks the polynomials over, A.
pub const I_MAX: f32 = 2.0;
/// Curvature factor of eq. 11 (fixed by seed 002).
pub const CURVATURE: f32 = 0.1;

/// Quadratic coefficients `[P0, P1, P2]` of each parameter in the command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// D: peak factor (eq. 31).
    pub d: [f32; 3],
    /// C: shape factor (eq. 32).
    pub c_shape: [f32; 3],
    /// B: stiffness factor (eq. 33).
    pub b: [f32; 3],
    /// S_h: horizontal shift (eq. 34).
    pub sh: [f32; 3],
    /// S_v: vertical shift (eq. 35).
    pub sv: [f32; 3],
    /// k: hysteresis magnitude (eq. 36).
    pub k: [f32; 3],
    /// c: viscous slope (eq. 37).
    pub c: [f32; 3],
}

/// Seed 002 eq. 31–37 (RD-1005-3, kN, mm/s, A).
pub const SEED002: Params = Params {
    d: [0.1532, 2.1713, -0.8226],
    c_shape: [0.5544, 1.6884, -0.7485],
    b: [0.0125, -0.0101, 0.0047],
    sh: [-9.452, 20.321, -8.1556],
    sv: [0.0397, 0.1931, -0.0726],
    k: [1.1351, -1.0508, 0.4617],
    c: [0.0007, 0.0005, 0.0],
};

impl Params {
    /// The flat order of [`Trig::PARAM_NAMES`].
    pub fn flat(&self) -> [f32; 21] {
        let mut out = [0.0; 21];
        let blocks = [self.d, self.c_shape, self.b, self.sh, self.sv, self.k, self.c];
        for (o, v) in out.iter_mut().zip(blocks.iter().flatten()) {
            *o = *v;
        }
        out
    }

    /// From the flat order of [`Trig::PARAM_NAMES`].
    pub fn from_flat(v: &[f32; 21]) -> Self {
        let mut blocks = [[0.0f32; 3]; 7];
        for (o, x) in blocks.iter_mut().flatten().zip(v.iter()) {
            *o = *x;
        }
        let [d, c_shape, b, sh, sv, k, c] = blocks;
        Self { d, c_shape, b, sh, sv, k, c }
    }
}

/// Validated coefficients of eq. 10–12, 31–37.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trig {
    p: Params,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl Trig {
    /// The parameters as given.
    #[inline]
    pub fn params(&self) -> &Params {
        &self.p
    }
}

/// No state.
pub type State = ();
pub type Registered = Trig;

/// `(min, max)` of `p0 + p1·i + p2·i²` over `[0, hi]`.
fn quad_range(c: [f32; 3], hi: f32) -> (f32, f32) {
    let [p0, p1, p2] = c;
    let f = |i: f32| p0 + p1 * i + p2 * i * i;
    let (mut lo_v, mut hi_v) = (f(0.0).min(f(hi)), f(0.0).max(f(hi)));
    if p2 != 0.0 {
        let iv = -p1 / (2.0 * p2);
        if iv > 0.0 && iv < hi {
            lo_v = lo_v.min(f(iv));
            hi_v = hi_v.max(f(iv));
        }
    }
    (lo_v, hi_v)
}

/// Check `min ≤ P(i) ≤ max` for `i ∈ [0, I_MAX]`.
fn check_range(name: &'static str, c: [f32; 3], min: f32, max: f32) -> Result<(), ParamError> {
    let (lo, hi) = quad_range(c, I_MAX);
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(ParamError::NotFinite { name });
    }
    if lo < min {
        return Err(ParamError::OutOfRange { name, value: lo, min, max });
    }
    if hi > max {
        return Err(ParamError::OutOfRange { name, value: hi, min, max });
    }
    Ok(())
}

const NAMES: [&str; 21] = [
    "D0", "D1", "D2", "C0", "C1", "C2", "B0", "B1", "B2", "Sh0", "Sh1", "Sh2", "Sv0", "Sv1", "Sv2", "k0", "k1", "k2",
    "c0", "c1", "c2",
];

impl Trig {
    /// Finite coefficients; over `0 ≤ i ≤ I_MAX`: `D, B, k, c ≥ 0` and `0 ≤ C ≤ 2`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::trig::{Trig, SEED002};
    /// use model_core::{Kin, Model};
    ///
    /// let model = Trig::new(SEED002, 1e-3)?;
    /// // 50 mm/s, accelerating, at 1 A.
    /// let force = model.step(&mut (), &Kin::new(0.0, 50.0, 100.0, 1.0));
    /// assert!(force.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(p: Params, dt: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        for (name, v) in NAMES.iter().zip(p.flat().iter()) {
            finite(name, *v)?;
        }
        check_range("D", p.d, 0.0, f32::INFINITY)?;
        check_range("C", p.c_shape, 0.0, 2.0)?;
        check_range("B", p.b, 0.0, f32::INFINITY)?;
        check_range("S_h", p.sh, f32::NEG_INFINITY, f32::INFINITY)?;
        check_range("S_v", p.sv, f32::NEG_INFINITY, f32::INFINITY)?;
        check_range("k", p.k, 0.0, f32::INFINITY)?;
        check_range("c", p.c, 0.0, f32::INFINITY)?;
        Ok(Self { p, dt })
    }

    /// `(D, C, B, S_h, S_v, k, c)` at current `i` (eq. 31–37).
    #[inline]
    pub fn coefficients(&self, i: f32) -> [f32; 7] {
        let p = &self.p;
        [p.d, p.c_shape, p.b, p.sh, p.sv, p.k, p.c].map(|c| poly(&c, i))
    }
}

impl Model for Trig {
    type State = State;
    const ID: &'static str = "trig";
    const PARAM_NAMES: &'static [&'static str] = &NAMES;
    const N_PARAMS: usize = 21;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        let flat: &[f32; 21] =
            v.try_into().map_err(|_| ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() })?;
        Self::new(Params::from_flat(flat), dt)
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(&self.p.flat(), out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    #[inline]
    fn step(&self, _state: &mut (), kin: &Kin) -> f32 {
        let [d, c_shape, b, sh, sv, k, c] = self.coefficients(kin.u);
        let b_vel = b * (kin.dx + sh);
        let phi = b_vel + CURVATURE * atan(b_vel);
        d * sin(c_shape * atan(phi - k * sign(kin.ddx))) + c * kin.dx + sv
    }
}

#[cfg(test)]
mod tests;
