//! Nonlinear ARX model, seed 000 eq. 18–19, in simulation mode (evaluator only; training
//! lives in `hil-sim`).
//!
//! Regressors (normalised): `r = [ŷ(t−1), û(t), û(t−1), …, û(t−5)]` with
//! `û = (u − u_mean)/u_scale`, `ŷ = (y − y_mean)/y_scale`. The model output is
//!
//! `ŷ(t) = L·r + Σⱼ aⱼ·σ(wⱼ·r + bⱼ) + offset`,  `y(t) = clamp(y_mean + y_scale·ŷ(t), y_min, y_max)`,
//!
//! i.e. the linear mapping L of eq. 19 (7 weights W₁…W₇), the nonlinear mapping f of eq. 18
//! and the offset. `y(t−1)` is the model's own previous (clamped) output.
//!
//! **Sigmoid instead of wavelet.** Seed 000 used MATLAB's wavelet network. Here f is a
//! one-hidden-layer logistic sigmoid network (`σ(s) = 1/(1+e^{−s})`, MATLAB's
//! `sigmoidnet`, one of the options the paper names): a universal approximator like the
//! wavelet net, smooth for gradient training, one `exp` per unit on the Cortex-M4F (a
//! radial wavelet needs an exp plus a norm per unit and a separate scaling-function part),
//! and bounded, so the nonlinear part can never exceed `Σ|aⱼ|`.
//!
//! **Feedback clamp.** `W₁·y(t−1)` with `|W₁| ≥ 1` (or the net) could make the recursion
//! diverge; the output — and hence what is fed back — is clamped to the validated range
//! `[y_min, y_max]`. Normalised inputs are clamped to `±1e6`.
//!
//! # Parameters (flat vector order)
//! `u_mean, u_scale, y_mean, y_scale, lin[7], hid_w[7·H] (unit-major: the 7 weights of unit
//! 0, then unit 1, …), hid_b[H], out_a[H], offset, y_min, y_max` — `9·H + 14` values.
//! [`Registered`] has `H = 8`: 86 values, the board's size; [`Seed000`] has `H = 71`: 653
//! values (seed 000's NARX: 656 units). Weights `|·| ≤ 1e6`,
//! scales in `[1e−12, 1e12]`, `y_min < y_max`.
//!
//! State: the five past inputs (raw) and the last output. It starts at the first sample
//! repeated and at a fixed point `y = f(y)` of the clamped map for that constant input
//! (32 bisection steps on `f(y) − y` over `[y_min, y_max]`, which always bracket one), so a
//! constant input starts in steady state even when the output feedback carries a slow
//! state (W₁ close to 1, see `hil-sim`'s training), which plain iteration of the map would
//! take thousands of steps to settle.

use crate::error::{check, count, time_step};
use crate::math::clamp;
use crate::model::write_flat;
use crate::models::kernels::flat::take;
use crate::models::kernels::names::BlockName;
use crate::models::kernels::sigmoid::{sigmoid, W_MAX};
use crate::{Finite, Kin, Model, ParamError};

/// Clamp of the normalised inputs.
const U_LIM: f32 = 1.0e6;

/// Coefficients of the NARX model with `H` hidden sigmoid units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Narx<const H: usize> {
    u_mean: f32,
    u_scale: f32,
    y_mean: f32,
    y_scale: f32,
    /// W₁…W₇ of eq. 19 (on ŷ(t−1), û(t), …, û(t−5)).
    lin: [f32; 7],
    /// Hidden-layer weights, one row of 7 per unit.
    hid_w: [[f32; 7]; H],
    hid_b: [f32; H],
    out_a: [f32; H],
    offset: f32,
    y_min: f32,
    y_max: f32,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const H: usize> Narx<H> {
    /// Mean of the input subtracted before scaling.
    #[inline]
    pub fn u_mean(&self) -> f32 {
        self.u_mean
    }

    /// Scale of the input: `û = (u − u_mean)/u_scale`.
    #[inline]
    pub fn u_scale(&self) -> f32 {
        self.u_scale
    }

    /// Mean of the output: `ŷ = (y − y_mean)/y_scale`.
    #[inline]
    pub fn y_mean(&self) -> f32 {
        self.y_mean
    }

    /// Scale of the normalised output.
    #[inline]
    pub fn y_scale(&self) -> f32 {
        self.y_scale
    }

    /// W₁…W₇ of eq. 19 (on ŷ(t−1), û(t), …, û(t−5)).
    #[inline]
    pub fn lin(&self) -> &[f32; 7] {
        &self.lin
    }

    /// Hidden-layer weights, one row of 7 per unit.
    #[inline]
    pub fn hid_w(&self) -> &[[f32; 7]; H] {
        &self.hid_w
    }

    /// Hidden-layer biases, one per unit.
    #[inline]
    pub fn hid_b(&self) -> &[f32; H] {
        &self.hid_b
    }

    /// Output weights, one per hidden unit.
    #[inline]
    pub fn out_a(&self) -> &[f32; H] {
        &self.out_a
    }

    /// Output offset of the network (normalised units).
    #[inline]
    pub fn offset(&self) -> f32 {
        self.offset
    }

    /// Lower clamp of the output y.
    #[inline]
    pub fn y_min(&self) -> f32 {
        self.y_min
    }

    /// Upper clamp of the output y.
    #[inline]
    pub fn y_max(&self) -> f32 {
        self.y_max
    }
}

/// Past inputs `u(t−1) … u(t−5)` (raw units) and the last output `y(t−1)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    pub u: [f32; 5],
    pub y: f32,
}

impl Finite for State {
    fn is_finite(&self) -> bool {
        self.u.is_finite() && self.y.is_finite()
    }
}

/// The board's size: 8 hidden units, 86 parameters (344 B of weights), small enough for the
/// configuration page and a 20 kHz control step. `hil-sim fit` trains this size
/// (issue 7: seed 000's network was rejected for the controller at 656 units).
pub type Registered = Narx<8>;

/// Seed 000's size: 71 hidden units, 653 parameters (seed 000: 656 units).
pub type Seed000 = Narx<71>;

impl<const H: usize> Narx<H> {
    const N_HID_W: BlockName = BlockName::new("hid_w", 7 * H);
    const N_HID_B: BlockName = BlockName::new("hid_b", H);
    const N_OUT_A: BlockName = BlockName::new("out_a", H);

    /// Validate and build (bounds in the module doc).
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::narx::Narx;
    /// use model_core::{Kin, Model};
    ///
    /// let model = Narx::<2>::new(
    ///     (1.0, 2.0, 0.5, 4.0), // u_mean, u_scale, y_mean, y_scale
    ///     [0.6, 0.3, -0.2, 0.1, 0.05, -0.05, 0.02], // linear part
    ///     [[0.1, 0.2, 0.3, -0.1, 0.0, 0.5, -0.4], [-0.3, 0.1, 0.0, 0.2, 0.2, -0.1, 0.3]], // hidden weights
    ///     [0.1, -0.2], // hidden biases
    ///     [1.5, -0.7], // output weights
    ///     0.05,        // offset
    ///     (-100.0, 100.0), // output clamp
    ///     1e-3,
    /// )?;
    /// let mut state = model.initial_state(&Kin::new(1.0, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(1.2, 0.0, 0.0, 0.0));
    /// assert!(y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        (u_mean, u_scale, y_mean, y_scale): (f32, f32, f32, f32),
        lin: [f32; 7],
        hid_w: [[f32; 7]; H],
        hid_b: [f32; H],
        out_a: [f32; H],
        offset: f32,
        (y_min, y_max): (f32, f32),
        dt: f32,
    ) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        let u_mean = check("u_mean", u_mean, -1.0e15, 1.0e15)?;
        let u_scale = check("u_scale", u_scale, 1.0e-12, 1.0e12)?;
        let y_mean = check("y_mean", y_mean, -1.0e15, 1.0e15)?;
        let y_scale = check("y_scale", y_scale, 1.0e-12, 1.0e12)?;
        for v in lin {
            check("lin", v, -W_MAX, W_MAX)?;
        }
        for row in &hid_w {
            for v in row {
                check("hid_w", *v, -W_MAX, W_MAX)?;
            }
        }
        for v in hid_b {
            check("hid_b", v, -W_MAX, W_MAX)?;
        }
        for v in out_a {
            check("out_a", v, -W_MAX, W_MAX)?;
        }
        let offset = check("offset", offset, -W_MAX, W_MAX)?;
        let y_min = check("y_min", y_min, -1.0e15, 1.0e15)?;
        let y_max = check("y_max", y_max, -1.0e15, 1.0e15)?;
        if y_min >= y_max {
            return Err(ParamError::Constraint { what: "NARX y_min must be < y_max" });
        }
        Ok(Self { u_mean, u_scale, y_mean, y_scale, lin, hid_w, hid_b, out_a, offset, y_min, y_max, dt })
    }

    #[inline]
    fn norm_u(&self, u: f32) -> f32 {
        clamp((u - self.u_mean) / self.u_scale, -U_LIM, U_LIM)
    }

    /// One evaluation of eq. 18–19 from the previous output, the current input and the
    /// five past inputs (raw units); returns the clamped output.
    #[inline]
    fn eval(&self, y_prev: f32, u: f32, past: &[f32; 5]) -> f32 {
        let [p1, p2, p3, p4, p5] = *past;
        let r = [
            (y_prev - self.y_mean) / self.y_scale,
            self.norm_u(u),
            self.norm_u(p1),
            self.norm_u(p2),
            self.norm_u(p3),
            self.norm_u(p4),
            self.norm_u(p5),
        ];
        let dot = |w: &[f32; 7]| w.iter().zip(r.iter()).map(|(a, b)| a * b).sum::<f32>();
        let mut yn = dot(&self.lin) + self.offset;
        for ((w, b), a) in self.hid_w.iter().zip(self.hid_b.iter()).zip(self.out_a.iter()) {
            yn += a * sigmoid(dot(w) + b);
        }
        clamp(self.y_mean + self.y_scale * yn, self.y_min, self.y_max)
    }
}

impl<const H: usize> Model for Narx<H> {
    type State = State;
    const ID: &'static str = "narx";
    const PARAM_NAMES: &'static [&'static str] = &[
        "u_mean",
        "u_scale",
        "y_mean",
        "y_scale",
        "lin[7]",
        Self::N_HID_W.as_str(),
        Self::N_HID_B.as_str(),
        Self::N_OUT_A.as_str(),
        "offset",
        "y_min",
        "y_max",
    ];
    const N_PARAMS: usize = 9 * H + 14;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        let inf = f32::INFINITY;
        let mut it = v.iter();
        let [u_mean] = take::<1>(&mut it, "u_mean", -inf, inf)?;
        let [u_scale] = take::<1>(&mut it, "u_scale", -inf, inf)?;
        let [y_mean] = take::<1>(&mut it, "y_mean", -inf, inf)?;
        let [y_scale] = take::<1>(&mut it, "y_scale", -inf, inf)?;
        let lin = take::<7>(&mut it, "lin", -inf, inf)?;
        let mut hid_w = [[0.0f32; 7]; H];
        for row in hid_w.iter_mut() {
            *row = take::<7>(&mut it, "hid_w", -inf, inf)?;
        }
        let hid_b = take::<H>(&mut it, "hid_b", -inf, inf)?;
        let out_a = take::<H>(&mut it, "out_a", -inf, inf)?;
        let [offset] = take::<1>(&mut it, "offset", -inf, inf)?;
        let [y_min] = take::<1>(&mut it, "y_min", -inf, inf)?;
        let [y_max] = take::<1>(&mut it, "y_max", -inf, inf)?;
        Self::new((u_mean, u_scale, y_mean, y_scale), lin, hid_w, hid_b, out_a, offset, (y_min, y_max), dt)
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let mut n = 0;
        let mut rest = out;
        let mut put = |src: &[f32], rest: &mut &mut [f32]| {
            let k = write_flat(src, rest);
            n += k;
            let r = core::mem::take(rest);
            *rest = r.get_mut(k..).unwrap_or_default();
        };
        put(&[self.u_mean, self.u_scale, self.y_mean, self.y_scale], &mut rest);
        put(&self.lin, &mut rest);
        for row in &self.hid_w {
            put(row, &mut rest);
        }
        put(&self.hid_b, &mut rest);
        put(&self.out_a, &mut rest);
        put(&[self.offset, self.y_min, self.y_max], &mut rest);
        n
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    fn initial_state(&self, first: &Kin) -> State {
        let u0 = if first.x.is_finite() { first.x } else { self.u_mean };
        let past = [u0; 5];
        // Bisection on eval(y) − y over [y_min, y_max]: eval maps into that range, so
        // eval(y_min) ≥ y_min and eval(y_max) ≤ y_max bracket a fixed point (module doc).
        let (mut lo, mut hi) = (self.y_min, self.y_max);
        for _ in 0..32 {
            let mid = 0.5 * (lo + hi);
            if self.eval(mid, u0, &past) > mid {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        State { u: past, y: self.eval(0.5 * (lo + hi), u0, &past) }
    }

    #[inline]
    fn step(&self, s: &mut State, k: &Kin) -> f32 {
        let y = self.eval(s.y, k.x, &s.u);
        let [p1, p2, p3, p4, _] = s.u;
        s.u = [k.x, p1, p2, p3, p4];
        s.y = y;
        y
    }
}

#[cfg(test)]
mod tests;
