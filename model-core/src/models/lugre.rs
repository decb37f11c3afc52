//! LuGre model adapted to the MR clutch, seed 000 eq. 7–8:
//!
//! `T = (β/α)·z + c·Ḃ + k·B + (ε/α)·ż + T₀`,  `ż = α·Ḃ − α·|Ḃ|·z`.
//!
//! This is also seed 001's modified LuGre (mLF, eq. 12–13, `ż = ẋ − α|ẋ|z'`) with the same
//! α, β, ε: its `z' = z/α`, so `β·z' = (β/α)·z` and `ε·ż' = (ε/α)·ż`.
//!
//! # Parameters (flat vector order)
//! `alpha, beta, epsilon, c, k, t0` (seed 000 Table 2/4 order). `α > 0` (it divides, and
//! α < 0 would make z diverge), `α ≤ 1e6`, β/α and ε/α finite; β, ε, c, k, T₀ any finite
//! value (Table 4 fits negative ε and c).
//!
//! # Bound and integrator
//! The ODE is rate independent: along the input, `dz/dB = α·(1 − sgn(Ḃ)·z)`, so over a
//! monotone leg of length `L = |ΔB|` in direction `s` the exact solution is
//! `z₁ = s + (z₀ − s)·e^{−αL}` — a convex combination of z₀ and ±1, so `|z| ≤ 1` is invariant
//! and the update is exact and unconditionally stable at any step. As in
//! [`bouc_wen`](super::bouc_wen), the state keeps `B_{k−1}`, and an extremum of B inside the
//! step (from the sample's Ḃ, B̈) splits the step into two monotone legs. The `ż` in the
//! output is the analytic `α·(Ḃ − |Ḃ|·z)` at the end of the step with the sample's Ḃ.
//! Error vs fine f64 RK4 of the ODE (output R-RMSE, seed 000 Table 4 sets, sines 1–9 Hz,
//! multi-sine, swept sine, 500 Hz and 3 kHz): ≤ 6e-7, i.e. f32 round-off.
//!
//! # Short steps (the firmware's hot path)
//! At 20 kHz a step moves B by a small fraction of the relaxation length 1/α. When
//! `α·|ΔB| + k_t·|B̈| ≤ 1/16` (see `FAST_Y` here and `TURN_EPS` in `kernels::turning`) the step uses the same update
//! with `1 − e^{−y}` written as `y·φ(y)`, `φ(y) = 1 − y/2 + y²/6 − y³/24` (error ≤ y⁴/120 <
//! 1.3e-7 relative), and without the reversal split, whose effect there is below
//! `TURN_EPS·|z|`. No libm call, no division: about 40 instructions on the Cortex-M4F
//! (`hil-sim budget`). Longer steps and any non-finite value take the exact path above.

use crate::error::{check, count, finite, time_step};
use crate::math::{abs, clamp, expm1};
use crate::model::write_flat;
use crate::models::kernels::turning::{turning_point, TURN_EPS};
use crate::{Finite, Kin, Model, ParamError};

/// Coefficients of eq. 7–8.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuGre {
    /// α > 0, per unit B.
    alpha: f32,
    /// β, N·m (scale of the hysteretic torque, β/α per unit z).
    beta: f32,
    /// ε, N·m·s (damping of ż).
    epsilon: f32,
    /// Viscous coefficient c, N·m·s per unit B.
    c: f32,
    /// Stiffness k, N·m per unit B.
    k: f32,
    /// Residual torque T₀, N·m.
    t0: f32,
    dt: f32,
    beta_a: f32,
    eps_a: f32,
    /// `c + ε` (the output's `c·Ḃ + (ε/α)·α·Ḃ`).
    c_eps: f32,
    /// Weight of |B̈| in the short-step test: `α·dt²·FAST_Y/TURN_EPS`.
    turn_k: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl LuGre {
    /// α > 0, per unit B.
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// β, N·m (scale of the hysteretic torque, β/α per unit z).
    #[inline]
    pub fn beta(&self) -> f32 {
        self.beta
    }

    /// ε, N·m·s (damping of ż).
    #[inline]
    pub fn epsilon(&self) -> f32 {
        self.epsilon
    }

    /// Viscous coefficient c, N·m·s per unit B.
    #[inline]
    pub fn c(&self) -> f32 {
        self.c
    }

    /// Stiffness k, N·m per unit B.
    #[inline]
    pub fn k(&self) -> f32 {
        self.k
    }

    /// Residual torque T₀, N·m.
    #[inline]
    pub fn t0(&self) -> f32 {
        self.t0
    }
}

/// Largest `α·|ΔB|` (plus the reversal term) handled by the short-step series.
pub(crate) const FAST_Y: f32 = 1.0 / 16.0;

/// `(1 − e^{−y})/y` for `|y| ≤ FAST_Y`: Taylor to y³ (error ≤ y⁴/120).
#[inline(always)]
pub(crate) fn phi_series(y: f32) -> f32 {
    1.0 + y * (-0.5 + y * (1.0 / 6.0 - y * (1.0 / 24.0)))
}

/// State: the bristle variable z (|z| ≤ 1) and the previous input.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    pub z: f32,
    pub x_prev: f32,
}

impl Finite for State {
    fn is_finite(&self) -> bool {
        self.z.is_finite() && self.x_prev.is_finite()
    }
}

pub type Registered = LuGre;

impl LuGre {
    /// Validate eq. 7–8's coefficients: `0 < α ≤ 1e6`, the others finite, `β/α` and `ε/α`
    /// finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::lugre::{LuGre, SEED000_AVERAGE};
    /// use model_core::rate::RateParams;
    /// use model_core::{Estimator, Model, Sample};
    ///
    /// let dt = 1e-4;
    /// let [alpha, beta, epsilon, c, k, t0] = SEED000_AVERAGE;
    /// let model = LuGre::new(alpha, beta, epsilon, c, k, t0, dt)?;
    /// assert_eq!(model.dt(), dt);
    /// let est = Estimator::new(model, RateParams::filtered(dt, 200.0)?)?;
    /// let mut state = est.state();
    /// for i in 0..200 {
    ///     let b = 1.5 + 1.5 * (core::f32::consts::TAU * 5.0 * i as f32 * dt).sin();
    ///     let out = est.step(&mut state, Sample::new(b));
    ///     assert!(out.flags.ok() && out.y.is_finite());
    /// }
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(alpha: f32, beta: f32, epsilon: f32, c: f32, k: f32, t0: f32, dt: f32) -> Result<Self, ParamError> {
        let alpha = check("alpha", alpha, f32::MIN_POSITIVE, 1.0e6)?;
        let beta = finite("beta", beta)?;
        let epsilon = finite("epsilon", epsilon)?;
        let beta_a = beta / alpha;
        let eps_a = epsilon / alpha;
        if !(beta_a.is_finite() && eps_a.is_finite()) {
            return Err(ParamError::Constraint { what: "LuGre beta/alpha and epsilon/alpha must be finite" });
        }
        let c = finite("c", c)?;
        let dt = time_step(dt)?;
        Ok(Self {
            alpha,
            beta,
            epsilon,
            c,
            k: finite("k", k)?,
            t0: finite("t0", t0)?,
            dt,
            beta_a,
            eps_a,
            c_eps: c + epsilon,
            turn_k: alpha * dt * dt * (FAST_Y / TURN_EPS),
        })
    }

    /// Exact z after a monotone input increment `dx`.
    #[inline]
    fn advance(&self, z0: f32, dx: f32) -> f32 {
        let l = abs(dx);
        let moving = l > 0.0;
        if !moving {
            return z0;
        }
        let s = if dx > 0.0 { 1.0 } else { -1.0 };
        // z₁ = z₀ + (s − z₀)(1 − e^{−αL})
        let z1 = z0 - (s - z0) * expm1(-self.alpha * l);
        clamp(z1, -1.0, 1.0)
    }
}

/// Seed 000 (Yang & Kermani 2023) Table 4, the five per-frequency fits and their average
/// (clutch input B, T in N·m), in [`Model::from_params`] order `alpha, beta, epsilon, c, k, t0`.
pub const SEED000_TABLE4: [(&str, [f32; 6]); 6] = [
    ("1 Hz", [5.315, 6.251, 0.042, -0.443, 4.441, 5.508]),
    ("3 Hz", [3.590, 6.456, 0.017, -0.144, 4.947, 5.326]),
    ("5 Hz", [5.695, 5.831, 0.000, -0.105, 3.469, 5.146]),
    ("7 Hz", [3.062, 5.783, -0.030, -0.026, 4.859, 5.036]),
    ("9 Hz", [3.899, 4.534, -0.014, -0.038, 3.769, 5.110]),
    ("average", SEED000_AVERAGE),
];

/// The average row of [`SEED000_TABLE4`].
pub const SEED000_AVERAGE: [f32; 6] = [4.312, 5.771, 0.003, -0.151, 4.297, 5.225];

impl Model for LuGre {
    type State = State;
    const ID: &'static str = "lugre";
    const PARAM_NAMES: &'static [&'static str] = &["alpha", "beta", "epsilon", "c", "k", "t0"];
    const N_PARAMS: usize = 6;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [alpha, beta, epsilon, c, k, t0] => Self::new(alpha, beta, epsilon, c, k, t0, dt),
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(&[self.alpha, self.beta, self.epsilon, self.c, self.k, self.t0], out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    fn initial_state(&self, first: &Kin) -> State {
        State { z: 0.0, x_prev: if first.x.is_finite() { first.x } else { 0.0 } }
    }

    #[inline]
    fn step(&self, s: &mut State, k: &Kin) -> f32 {
        let dx = k.x - s.x_prev;
        let l = abs(dx);
        let y = self.alpha * l;
        // NaN anywhere fails the test and takes the exact path.
        let short = y + self.turn_k * abs(k.ddx) <= FAST_Y;
        if !short {
            return self.step_exact(s, k);
        }
        // z₀ + (s − z₀)(1 − e^{−y}) = z₀ + (α·ΔB − y·z₀)·φ(y): a convex combination of z₀
        // and ±1, so |z| ≤ 1 holds.
        let z0 = s.z;
        let z = z0 + (self.alpha * dx - y * z0) * phi_series(y);
        s.z = z;
        s.x_prev = k.x;
        self.output(z, k)
    }
}

impl LuGre {
    /// `(β/α)·z + c·Ḃ + k·B + (ε/α)·α(Ḃ − |Ḃ|z) + T₀`.
    #[inline(always)]
    fn output(&self, z: f32, k: &Kin) -> f32 {
        z * (self.beta_a - self.epsilon * abs(k.dx)) + self.c_eps * k.dx + self.k * k.x + self.t0
    }

    /// The exact step (reversal split, `expm1`).
    #[inline(never)]
    fn step_exact(&self, s: &mut State, k: &Kin) -> f32 {
        let z0 = clamp(s.z, -1.0, 1.0);
        let z = match turning_point(s.x_prev, k, self.dt) {
            Some(xt) => self.advance(self.advance(z0, xt - s.x_prev), k.x - xt),
            None => self.advance(z0, k.x - s.x_prev),
        };
        if k.x.is_finite() {
            s.x_prev = k.x;
        }
        s.z = z;
        self.output(z, k)
    }
}

#[cfg(test)]
mod tests;
