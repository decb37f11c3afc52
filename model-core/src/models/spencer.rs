//! Modified Bouc–Wen model of an MR damper (Spencer, Dyke, Sain & Carlson 1997), seed 001
//! eq. 3–7 (also seed 002 eq. 1–7, seed 003 §4.3), with the voltage-dependent
//! coefficients of eq. 6 and the first-order command filter of eq. 7.
//!
//! # Equations
//!
//! ```text
//! F  = c1·ẏ + k1·(x − x0)                                        (seed 002 eq. 1 ≡ seed 001 eq. 3)
//! ẏ  = (α·z + c0·ẋ + k0·(x − y)) / (c0 + c1)                     (eq. 5)
//! ż  = −γ·|ẋ − ẏ|·z·|z|ⁿ⁻¹ − β·(ẋ − ẏ)·|z|ⁿ + A·(ẋ − ẏ)           (eq. 4)
//! α = αa + αb·u,  c1 = c1a + c1b·u,  c0 = c0a + c0b·u             (eq. 6)
//! u̇ = −η·(u − v)                                                 (eq. 7)
//! ```
//!
//! `x` is the damper displacement ([`Kin::x`]), `v` the command voltage ([`Kin::u`]),
//! `u` the filtered ("effective") voltage. Units are whatever the parameters were fitted in;
//! Spencer's set for the Dyke damper (x in cm, F in N, v in V) is [`Spencer::dyke_1997`].
//!
//! **Command range.** Eq. 6 was fitted for 0 ≤ v ≤ 2.25 V and the current driver is
//! unipolar, so a negative command is taken as 0 V (`v = max(Kin::u, 0)`). Together with
//! the sign constraints checked by [`Spencer::new`] this keeps `α ≥ 0`, `c0, c1 ≥ 0` and
//! `c0 + c1 > 0` for every command, which the update below relies on. (The real command
//! `Y` of `ranran_50.csv` dips to −0.43 V.)
//!
//! # Discretisation (one step per sample)
//!
//! Write `w = x − y` (the stroke of the Bouc–Wen element) and `S = c0 + c1`. Then
//!
//! ```text
//! ẇ = (c1·ẋ − α·z − k0·w) / S,        dz/dw = g(z, sgn ẇ)
//! g = A − β·|z|ⁿ − γ·sgn(ẇ)·z·|z|ⁿ⁻¹     (g ≥ 0 for |z| ≤ z_max under the checked bounds)
//! ```
//!
//! i.e. `z` is a rate-independent function of the path of `w`. The stiffness that makes
//! explicit Runge–Kutta blow up at 3 kHz (RK4 needs 8–16 sub-steps) comes from two places,
//! handled separately:
//!
//! 1. **Post-yield saturation of `z`** (`∂ż/∂z = −n·(β+γ)·|z|ⁿ⁻¹·ẇ`, ~10⁴ s⁻¹ with the
//!    published set): `z` is advanced by the *exact* flow `z₁ = Φ(z₀, Δw)` of
//!    `dz/dw = g` along the increment `Δw`, so it can never overshoot the bound
//!    `|z| ≤ z_max = (A/(β+γ))^(1/n)`. With `ζ = sgn(Δw)·z` and `D = |Δw|`:
//!    - loading (`ζ ≥ 0`): `dζ/dD = A − (β+γ)·ζⁿ`;
//!    - unloading (`ζ < 0`): `dζ/dD = A − (β−γ)·|ζ|ⁿ`, run until `ζ` reaches 0; the
//!      rest of `D` continues on the loading branch.
//!
//!    For `n = 2` both branches are Riccati equations with closed forms
//!    (`q = √(A·(β+γ))`, `T = tanh(q·D)`):
//!    `ζ₁ = z_max·(ζ₀ + z_max·T)/(z_max + ζ₀·T)` when loading; when unloading the same
//!    `tanh` form for `β > γ`, a straight line `ζ₀ + A·D` for `β = γ` (Spencer's set), or
//!    `r·tan(atan(ζ₀/r) + q'·D)` for `β < γ`. For `n = 1` both branches are exponentials
//!    (`ζ₁ = ζ₀ + (z_max − ζ₀)·(1 − e^{−(β+γ)D})` when loading). Any other `n`: in
//!    normalised units `q = ζ/z_max`, `s = A·D/z_max`, the loading branch
//!    `dq/ds = (1 − q²)·r(q)`, `r = (1 − qⁿ)/(1 − q²)`, keeps the saturating factor exact
//!    (a `tanh` step) with the smooth `r` frozen at the midpoint (two halves), the unloading
//!    branch (smooth, `dq/ds ≥ 1 − ρ`, `ρ = (β−γ)/(β+γ)`) uses two RK4 steps and a
//!    Gauss–Legendre estimate of the distance to `q = 0`: within 0.3 % of `z_max` of the
//!    exact flow even for `D` of twice the pre-yield stroke.
//! 2. **The `z`–`w` feedback loop** (rate `λ = (k0 + α·g)/S`, ~1.6·10³ s⁻¹ at 2.25 V,
//!    `λT ≈ 0.54` at 3 kHz) is integrated with an exponentially fitted θ-method:
//!
//!    ```text
//!    Δw = (1−θ)·(c1₀·T·ẋ₀ − T·α₀·z₀ − T·k0·w₀)/S₀
//!       +    θ ·(c1₁·T·ẋ₁ − T·α₁·z₁ − T·k0·w₁)/S₁,     z₁ = Φ(z₀, Δw), w₁ = w₀ + Δw
//!    θ  = 1/(1 − e^{−λT}) − 1/(λT)        (→ ½ as λT → 0: the trapezoidal rule)
//!    ```
//!
//!    with `λ` taken at the start of the step on the branch the step moves along. This θ
//!    makes the step *exact* for a linear system driven by a force linear in time (it equals
//!    the second-order exponential integrator ETD2): exact in Spencer's linear unloading
//!    branch (`β = γ`, `g = A`) at constant command, second order elsewhere, A-stable and
//!    L-stable as `λT → ∞`. The velocity is taken linear over the step, from
//!    `ẋ₀ = 2·Δx/T − ẋ_k` to the sample's `ẋ₁ = ẋ_k`, so that it integrates exactly to the
//!    measured increment `Δx = x_k − x_{k−1}` (the previous sample is kept in the state): for
//!    a piecewise-linear displacement with backward-difference rates this is the constant
//!    segment velocity, for a smooth one it tracks the instantaneous velocity the quasi-static
//!    `z` follows. The one unknown `D = |Δw|` solves the scalar equation
//!    `H(D) = a·D + b·(ζ(D) − ζ₀) − |R| = 0` (`a = 1 + θ·T·k0/S₁`, `b = θ·T·α₁/S₁`), which is
//!    strictly increasing with its root in `[0, |R|/a]`: a bracketed Newton iteration
//!    (derivative `a + b·g(ζ)`, at most [`NEWTON_ITERS`] flow evaluations, 1.1 per solve on
//!    the Dyke recording with a fitted set) finds it. When a Newton step converges, `ζ` at the
//!    new `D` is taken along the slope `g` already computed (the step is ~1e-6 of `D`)
//!    instead of from one more flow.
//!
//!    *Reversals.* When the frozen-state prediction of `ẇ` changes sign inside the step,
//!    the step is split at the predicted turning point so that each part moves `w` one way
//!    (otherwise the `z` path "out along the saturated branch and back" collapses to its net
//!    increment). At 3 kHz this happens in 0.2 % of the Dyke samples.
//!
//!    *Stiff steps.* One stage is taken while `λ_max·T ≤` [`STAGE_LAMBDA_T`] (`λ_max` with the
//!    largest slope `g` on the bound, at the step's command); a stiffer step is cut into
//!    `⌈λ_max·T⌉ ≤` [`MAX_STAGES`] equal stages. With the published set this is one stage at
//!    3 kHz for every command below ≈ 4.6 V (the recording's command stays below 2.7 V), so
//!    the firmware rate pays one stage per sample. At 500 Hz and 2.25 V (`λT ≈ 3.2`) four
//!    stages are used: one stage there gives 0.38 % instead of 0.036 % on a 9 Hz, 1 cm sine
//!    (still within 0.5 %; set `MAX_STAGES = 1` for a strict single stage). Worst case per
//!    sample: `MAX_STAGES × 2 × NEWTON_ITERS` flow evaluations.
//! 3. **The command filter** (eq. 7) is advanced exactly for a raw command linear between
//!    samples and clamped at 0 V (`CommandFilter` in `kernels::command_filter`, shared
//!    with [`dahl`](super::dahl)): for `v ≥ 0`,
//!    `u₁ = v₁ + (u₀ − v₀)·e^{−ηT} − (v₁ − v₀)·(1 − e^{−ηT})/(ηT)`, a step crossing 0 V is
//!    split at the crossing. The coefficients of eq. 6 use `u` at both ends of each stage.
//!
//! The force is eq. 1 at the end of the step with `ẏ` from eq. 5 and the sample's `ẋ`.
//!
//! **First sample.** There is no previous sample to integrate from: the first step (or the
//! first after [`Model::initial_state`]) only sets the rest state `y = x`, `z = 0`,
//! `u = max(v, 0)` and returns eq. 1 there (the f64 reference starts from the same state).
//!
//! **Measured** (f32 one step per sample vs an f64 RK4 reference with 100–200 sub-steps;
//! tests here and in `hil-sim/src/reference/spencer.rs`): R-RMSE of the difference 0.046 %
//! (max 11.5 N) over the whole of `ranran_50.csv` (74 068 samples at 3005 Hz) with the
//! published set and the recorded command `Y`, one stage per sample throughout (0.048 % on
//! the first 5 s); on 1–9 Hz, 1 cm sines, multi-sine and swept sine at 0–2.25 V: ≤ 0.02 % at
//! 3 kHz, ≤ 0.08 % at 500 Hz. About 160 ns per step on the host.
//!
//! # State
//!
//! `y`, `z` (|z| ≤ z_max), the filtered command `u`, the previous displacement and raw
//! command sample, and whether the first sample has been seen.

use crate::error::{check, count, finite, time_step};
use crate::math::{abs, powf, sqrt};
use crate::model::write_flat;
use crate::models::kernels::command_filter::{command, raw_command, CommandFilter};
use crate::{Finite, Kin, Model, ParamError};
use solver::stage_count;

mod flow;
mod solver;

/// Maximum number of flow evaluations in the Newton solve for `Δw`.
pub const NEWTON_ITERS: usize = 6;
/// Largest `λ·T` one stage takes; a stiffer step is split into equal stages.
pub const STAGE_LAMBDA_T: f32 = 1.0;
/// Most stages per step (bounds the worst-case cost).
pub const MAX_STAGES: usize = 4;

/// The 14 parameters of eq. 3–7 in the paper's form (seed 001 §3.1.3 lists them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// c0a: viscous damping at large velocity at 0 V, N·s per unit x (eq. 6), ≥ 0.
    pub c0a: f32,
    /// c0b: its voltage slope, N·s per unit x per V (eq. 6), ≥ 0.
    pub c0b: f32,
    /// k0: stiffness at large velocity, N per unit x (eq. 5), ≥ 0.
    pub k0: f32,
    /// c1a: roll-off dashpot at 0 V, N·s per unit x (eq. 6), ≥ 0; `c0a + c1a > 0`.
    pub c1a: f32,
    /// c1b: its voltage slope, N·s per unit x per V (eq. 6), ≥ 0.
    pub c1b: f32,
    /// k1: accumulator stiffness, N per unit x (eq. 3), any finite value.
    pub k1: f32,
    /// x0: initial displacement of the accumulator spring k1, unit of x (eq. 3).
    pub x0: f32,
    /// αa: Bouc–Wen force scale at 0 V, N (per unit z) (eq. 6), ≥ 0.
    pub alpha_a: f32,
    /// αb: its voltage slope, N per V (eq. 6), ≥ 0.
    pub alpha_b: f32,
    /// γ: Bouc–Wen shape, per unit xⁿ (eq. 4), ≥ 0.
    pub gamma: f32,
    /// β: Bouc–Wen shape, per unit xⁿ (eq. 4), `β + γ > 0`.
    pub beta: f32,
    /// A: Bouc–Wen pre-yield slope of z per unit x (eq. 4), > 0.
    pub a: f32,
    /// n: Bouc–Wen exponent (eq. 4), in [1, 10]; 1 and 2 use closed forms.
    pub n: f32,
    /// η: command filter rate, s⁻¹ (eq. 7), > 0.
    pub eta: f32,
}

impl Params {
    /// The flat [`Model::from_params`] order
    /// (`c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, A, n, eta`).
    pub const fn flat(&self) -> [f32; 14] {
        let p = self;
        [p.c0a, p.c0b, p.k0, p.c1a, p.c1b, p.k1, p.x0, p.alpha_a, p.alpha_b, p.gamma, p.beta, p.a, p.n, p.eta]
    }
}

/// How `z` is advanced along `Δw` (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    One,
    Two,
    General,
}

/// Validated coefficients of the modified Bouc–Wen model at one time step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spencer {
    /// The parameters as given.
    p: Params,
    dt: f32,
    /// `(A/(β+γ))^(1/n)`, the bound of |z|.
    zmax: f32,
    shape: Shape,
    /// Loading rate constant: `√(A(β+γ))` for n = 2, `β+γ` for n = 1.
    q_load: f32,
    /// Unloading constants for n = 2: `r = √(A/|β−γ|)`, `q = √(A·|β−γ|)`.
    r_un: f32,
    q_un: f32,
    /// Largest slope `dz/dw` within the bound, `A·(1 + max(0, γ−β)/(β+γ))`.
    slope_max: f32,
    /// Command filter over the whole step.
    filter: CommandFilter,
    /// Command filter over 1/m of the step, m = 1 ..= MAX_STAGES.
    stage_filters: [CommandFilter; MAX_STAGES],
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl Spencer {
    /// The parameters as given.
    #[inline]
    pub fn params(&self) -> &Params {
        &self.p
    }
}

/// State of [`Spencer`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    /// Internal displacement y (unit of x).
    pub y: f32,
    /// Bouc–Wen evolutionary variable, |z| ≤ (A/(β+γ))^(1/n).
    pub z: f32,
    /// Filtered command u of eq. 7 (V).
    pub u: f32,
    /// Previous displacement sample.
    pub x_prev: f32,
    /// Previous raw command sample (V; may be negative).
    pub v_prev: f32,
    /// False until the first sample has been seen: that sample only sets the state
    /// (there is no previous sample to integrate from).
    pub primed: bool,
}

impl Finite for State {
    fn is_finite(&self) -> bool {
        self.y.is_finite()
            && self.z.is_finite()
            && self.u.is_finite()
            && self.x_prev.is_finite()
            && self.v_prev.is_finite()
    }
}

pub type Registered = Spencer;

impl Spencer {
    /// Validate the parameters (bounds in [`Params`]) and precompute the step constants.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::spencer::{Spencer, DYKE_1997};
    /// use model_core::{Kin, Model};
    ///
    /// let dt = 1.0 / 3000.0;
    /// let model = Spencer::new(DYKE_1997, dt)?;
    /// let first = Kin::new(0.0, 0.0, 0.0, 1.0); // x in cm, 1 V
    /// let mut state = model.initial_state(&first);
    /// let _ = model.step(&mut state, &first); // the first sample sets the rest state
    /// let force = model.step(&mut state, &Kin::new(0.001, 3.0, 0.0, 1.0));
    /// assert!(force.is_finite() && state.z.abs() <= model.z_max());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(p: Params, dt: f32) -> Result<Self, ParamError> {
        let big = 1e12;
        let dt = time_step(dt)?;
        check("c0a", p.c0a, 0.0, big)?;
        check("c0b", p.c0b, 0.0, big)?;
        check("k0", p.k0, 0.0, big)?;
        check("c1a", p.c1a, 0.0, big)?;
        check("c1b", p.c1b, 0.0, big)?;
        finite("k1", p.k1)?;
        finite("x0", p.x0)?;
        check("alpha_a", p.alpha_a, 0.0, big)?;
        check("alpha_b", p.alpha_b, 0.0, big)?;
        check("gamma", p.gamma, 0.0, big)?;
        check("beta", p.beta, -big, big)?;
        check("A", p.a, f32::MIN_POSITIVE, big)?;
        check("n", p.n, 1.0, 10.0)?;
        check("eta", p.eta, f32::MIN_POSITIVE, big)?;
        if p.c0a + p.c1a <= 0.0 {
            return Err(ParamError::Constraint { what: "c0a + c1a must be > 0" });
        }
        let sum = p.beta + p.gamma;
        if sum <= 0.0 {
            return Err(ParamError::Constraint { what: "beta + gamma must be > 0" });
        }
        let ratio = p.a / sum;
        let (shape, zmax) = if p.n == 1.0 {
            (Shape::One, ratio)
        } else if p.n == 2.0 {
            (Shape::Two, sqrt(ratio))
        } else {
            (Shape::General, powf(ratio, 1.0 / p.n))
        };
        if !(zmax.is_finite() && zmax > 0.0) {
            return Err(ParamError::Constraint { what: "(A/(beta+gamma))^(1/n) must be finite and > 0" });
        }
        let dif = abs(p.beta - p.gamma);
        let (q_load, r_un, q_un) = match shape {
            Shape::One => (sum, 0.0, 0.0),
            Shape::Two => {
                let (r, q) = if dif > 0.0 { (sqrt(p.a / dif), sqrt(p.a * dif)) } else { (0.0, 0.0) };
                (sqrt(p.a * sum), r, q)
            }
            Shape::General => (0.0, 0.0, 0.0),
        };
        if !(q_load.is_finite() && r_un.is_finite() && q_un.is_finite()) {
            return Err(ParamError::Constraint { what: "Bouc-Wen constants overflow" });
        }
        let slope_max = p.a * (1.0 + (p.gamma - p.beta).max(0.0) / sum);
        let stage_filters = core::array::from_fn(|i| CommandFilter::new(p.eta, dt / (i + 1) as f32));
        Ok(Self {
            p,
            dt,
            zmax,
            shape,
            q_load,
            r_un,
            q_un,
            slope_max,
            filter: CommandFilter::new(p.eta, dt),
            stage_filters,
        })
    }

    /// Spencer et al. (1997) for the prototype damper of `shared/data/dyke` (x in cm,
    /// F in N, v in V; values in `shared/data/dyke/README.md`).
    pub fn dyke_1997(dt: f32) -> Result<Self, ParamError> {
        Self::new(DYKE_1997, dt)
    }

    /// The bound of |z|, `(A/(β+γ))^(1/n)`.
    pub fn z_max(&self) -> f32 {
        self.zmax
    }

    /// `(α, c0, c1)` at filtered command `u` (eq. 6).
    #[inline]
    pub fn coefficients(&self, u: f32) -> (f32, f32, f32) {
        let p = &self.p;
        (p.alpha_a + p.alpha_b * u, p.c0a + p.c0b * u, p.c1a + p.c1b * u)
    }
}

/// Spencer, Dyke, Sain & Carlson (1997) for the prototype damper of `shared/data/dyke`
/// (x in cm, F in N, v in V), as listed in `shared/data/dyke/README.md` and seed 001
/// §3.1.3. [`DYKE_1997_FLAT`] is the same set in [`Model::from_params`] order.
pub const DYKE_1997: Params = Params {
    c0a: 21.0,
    c0b: 3.50,
    k0: 46.9,
    c1a: 283.0,
    c1b: 2.95,
    k1: 5.00,
    x0: 14.3,
    alpha_a: 140.0,
    alpha_b: 695.0,
    gamma: 363.0,
    beta: 363.0,
    a: 301.0,
    n: 2.0,
    eta: 190.0,
};

/// [`DYKE_1997`] in [`Model::from_params`] order
/// (`c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, A, n, eta`).
pub const DYKE_1997_FLAT: [f32; 14] = DYKE_1997.flat();

impl Model for Spencer {
    type State = State;
    const ID: &'static str = "spencer";
    const PARAM_NAMES: &'static [&'static str] =
        &["c0a", "c0b", "k0", "c1a", "c1b", "k1", "x0", "alpha_a", "alpha_b", "gamma", "beta", "A", "n", "eta"];
    const N_PARAMS: usize = 14;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, a, n, eta] => {
                Self::new(Params { c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, a, n, eta }, dt)
            }
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(&self.p.flat(), out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    fn initial_state(&self, first: &Kin) -> State {
        State { y: first.x, z: 0.0, u: command(first.u), x_prev: first.x, v_prev: raw_command(first.u), primed: false }
    }

    #[inline]
    fn step(&self, s: &mut State, k: &Kin) -> f32 {
        let p = &self.p;
        let dt = self.dt;
        if !s.primed {
            *s = State { primed: true, ..self.initial_state(k) };
            let (al, c0, c1) = self.coefficients(s.u);
            return c1 * (al * s.z + c0 * k.dx) / (c0 + c1) + p.k1 * (k.x - p.x0);
        }
        let v1 = raw_command(k.u);
        // Stage count from the stiffness of the z–w loop at the new command (1 at 3 kHz
        // for the published set and any command below ~4.6 V).
        let u_end = self.filter.step(s.u, s.v_prev, v1);
        let (al1, c01, c11) = self.coefficients(u_end);
        let lam_t = dt * (p.k0 + al1 * self.slope_max) / (c01 + c11);
        let m = stage_count(lam_t);
        let (m, filter) = match self.stage_filters.get(m - 1) {
            Some(f) => (m, *f),
            None => (1, self.filter),
        };
        let h = dt / m as f32;
        // Velocity linear over the step, ending at the sample's ẋ and integrating to Δx.
        let dx = k.x - s.x_prev;
        let x_rate0 = 2.0 * dx / dt - k.dx;
        let x_rate1 = k.dx;
        let (mut w, mut z, mut u, mut v) = (s.x_prev - s.y, s.z, s.u, s.v_prev);
        let mut hx0 = h * x_rate0;
        for j in 1..=m {
            let frac = j as f32 / m as f32;
            let hx1 = h * (x_rate0 + (x_rate1 - x_rate0) * frac);
            let v_next = s.v_prev + (v1 - s.v_prev) * frac;
            // Command filter, eq. 7 (over the whole step it is already known).
            let u_next = if m == 1 { u_end } else { filter.step(u, v, v_next) };
            (w, z) = self.stage(w, z, (hx0, hx1), (u, u_next), h);
            (u, v, hx0) = (u_next, v_next, hx1);
        }
        let (w1, z1, u1) = (w, z, u);
        let (al1, c01, c11) = self.coefficients(u1);
        let s1 = c01 + c11;
        *s = State { y: k.x - w1, z: z1, u: u1, x_prev: k.x, v_prev: v1, primed: true };
        // Force, eq. 1 with ẏ from eq. 5.
        let ydot = (al1 * z1 + c01 * k.dx + p.k0 * w1) / s1;
        c11 * ydot + p.k1 * (k.x - p.x0)
    }
}

#[cfg(test)]
mod tests;
