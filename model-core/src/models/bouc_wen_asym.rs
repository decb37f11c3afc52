//! Asymmetric Bouc–Wen model (ABW), seed 004 eq. 26–31 (de la Morena et al. 2025):
//!
//! `ż = D⁻¹·(A·ẋ − β·|ẋ|·|z|ⁿ⁻¹·z − γ·ẋ·|z|ⁿ + ψ[x])`   (eq. 28; eq. 26 with ψ = 0)
//! `Φ = α·κ·x + (1 − α)·D·κ·z`                         (eq. 29 = eq. 27)
//!
//! with one of the two asymmetry functions of the paper:
//! - variant 1, eq. 30 (ABW₁): `ψ = δ·x·sgn(ẋ)`,
//! - variant 2, eq. 31 (ABW₂): `ψ = δ·[1 + sgn(ẋ)]·(1/(1 + e^{−p(x−q)}) − ½)`,
//!   computed as `δ·[1 + sgn(ẋ)]·½·tanh(p(x−q)/2)` (the same function, bounded for any x).
//!
//! `sgn(0) = 0` as in seed 004 eq. 24. Units: x in the unit of the fit (seed 004:
//! normalised 0…1; here B), z in the unit of x, D and A dimensionless, β and γ in
//! (unit of x)⁻ⁿ, ψ and δ in unit of x per second (ψ is added to the rate ż, not
//! multiplied by ẋ, so the asymmetry term is rate-dependent: its effect on a loop grows
//! as the excitation slows down), p in (unit of x)⁻¹, q in unit of x, α ∈ [0, 1], κ in
//! output units per unit x.
//!
//! # Integrator (one step per sample, no substeps)
//!
//! The Bouc–Wen part is rate-independent: along the input path it reads
//! `dz/dx = D⁻¹·(A − (β·sgn(ẋ·z) + γ)·|z|ⁿ)`, i.e. `c = β + γ` multiplies `|z|ⁿ` where z
//! has the sign of the motion ("loading") and `c = γ − β` where it has the opposite sign. Each step goes from `x_{k−1}` (kept in the
//! state) to `x_k` and is split (Strang) as: half the asymmetry forcing
//! `z += (T/2)·ψ(x_{k−1})/D`, the exact Bouc–Wen flow along `Δx = x_k − x_{k−1}`, the
//! other half `z += (T/2)·ψ(x_k)/D`, with `sgn(ẋ) = sgn(Δx)` over the step.
//!
//! The flow along `Δx` is solved per sign region of `u = sgn(Δx)·z`, with the path
//! length `σ = |Δx|/D`: `du/dσ = |A| − c₁·uⁿ` for `u ≥ 0` (stable fixed point
//! `z̄ = (|A|/c₁)^{1/n}`), `dv/dσ = −|A| + c₂·vⁿ` for `v = −u > 0` until v reaches 0
//! (then the remaining path is spent in the first region):
//! - `n = 1`: exact exponential solution, and the exact crossing point of `z = 0`;
//! - `n = 2`: exact Riccati solution (tanh form; tan form when `c₂ < 0`), exact crossing;
//! - general `n`: an exponential step about the region's fixed point `e`,
//!   `u₁ = e + (u₀ − e)·exp(λ̄σ)` with the secant rate `λ(u) = f(u)/(u − e)` taken at the
//!   step midpoint (the implicit midpoint equation solved by two fixed-point
//!   corrections after an explicit predictor). It is exact for `n = 1`,
//!   second order otherwise, never overshoots the fixed point however stiff (`|λσ| ≫ 1`)
//!   the step is, and gives the crossing point with the same secant.
//!
//! Finally z is clamped to `±z_lim` (see below) as a last resort.
//!
//! # Bounds
//!
//! The model needs `A ≠ 0`, `β ≥ 0` and `c₁ = β + γ·sgn(A) > 0` (Ikhouane–Rodellar's
//! bounded class; with `β < 0` the unloading branch diverges). Then the classical part
//! keeps `|z| ≤ max(|z(0)|, z̄)`. With `c₂ = γ·sgn(A) − β > 0`, |z| beyond
//! `z_run = (|A|/c₂)^{1/n}` would diverge on unloading, so `|z(0)| ≤ z_run` is required.
//! The asymmetry term has no such bound (eq. 31 drifts at standstill, eq. 30 dominates at
//! vanishing rates), so z is limited to `z_lim = max(|z(0)|, min(2·z̄, z_run))`. The limit
//! is inactive for any excitation whose rate dominates ψ (all of seed 004's fits at the
//! 1–9 Hz of this project).

use crate::error::{check, count, finite, time_step};
use crate::math::{abs, clamp, powf, sign, sqrt, tanh};
use crate::model::write_flat;
use crate::{Finite, Kin, Model, ParamError};
use flow::Fall;
pub use steady::{Branches, LOOP_POINTS};

mod flow;
mod steady;

/// Which asymmetry function ψ (flat parameter `variant`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Asymmetry {
    /// Eq. 30, `ψ = δ·x·sgn(ẋ)` (ABW₁, flat value 1).
    Linear,
    /// Eq. 31, the sigmoid-gated term (ABW₂, flat value 2).
    Sigmoid,
}

impl Asymmetry {
    fn from_code(v: f32) -> Result<Self, ParamError> {
        if v == 1.0 {
            Ok(Self::Linear)
        } else if v == 2.0 {
            Ok(Self::Sigmoid)
        } else {
            check("variant", v, 1.0, 2.0)?;
            Err(ParamError::Constraint { what: "variant must be 1 (eq. 30) or 2 (eq. 31)" })
        }
    }
    fn code(self) -> f32 {
        match self {
            Self::Linear => 1.0,
            Self::Sigmoid => 2.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Order {
    One,
    Two,
    General,
}

/// Everything `new` derives once so that `step` only does the flow.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Derived {
    /// sgn(A): the flow is integrated for `w = sgn(A)·z`, which has `A > 0`.
    sa: f32,
    /// |A|.
    aa: f32,
    /// Loading and unloading coefficients of |w|ⁿ.
    c1: f32,
    c2: f32,
    inv_d: f32,
    /// Stable fixed point of the loading region.
    zbar: f32,
    zlim: f32,
    /// Fixed point of the unloading flow (signed: `+z_run` for c₂ > 0, negative virtual
    /// point for c₂ < 0, unused for c₂ = 0).
    e2: f32,
    /// λ at the fixed points (the limits of the secant rates).
    lam1_eq: f32,
    lam2_eq: f32,
    /// √(|A|·c₁), √(|A|·|c₂|) for n = 2.
    om1: f32,
    om2: f32,
    order: Order,
    /// Output gains ακ and (1−α)Dκ.
    kx: f32,
    kz: f32,
}

/// Coefficients of eq. 28–31.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWenAsym {
    /// Linear/hysteretic split α ∈ [0, 1].
    alpha: f32,
    /// Output scale κ > 0.
    kappa: f32,
    /// D > 0.
    d: f32,
    /// A ≠ 0.
    a: f32,
    /// β ≥ 0.
    beta: f32,
    /// γ (β + γ·sgn(A) > 0).
    gamma: f32,
    /// Exponent n ∈ [1, 8].
    n: f32,
    /// Initial hysteretic state z(0).
    z0: f32,
    /// Asymmetry gain δ.
    delta: f32,
    /// Sigmoid rate p ≥ 0 (eq. 31 only).
    p: f32,
    /// Sigmoid centre q (eq. 31 only).
    q: f32,
    asymmetry: Asymmetry,
    k: Derived,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl BoucWenAsym {
    /// Linear/hysteretic split α ∈ [0, 1].
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// Output scale κ > 0.
    #[inline]
    pub fn kappa(&self) -> f32 {
        self.kappa
    }

    /// D > 0.
    #[inline]
    pub fn d(&self) -> f32 {
        self.d
    }

    /// A ≠ 0.
    #[inline]
    pub fn a(&self) -> f32 {
        self.a
    }

    /// β ≥ 0.
    #[inline]
    pub fn beta(&self) -> f32 {
        self.beta
    }

    /// γ (β + γ·sgn(A) > 0).
    #[inline]
    pub fn gamma(&self) -> f32 {
        self.gamma
    }

    /// Exponent n ∈ [1, 8].
    #[inline]
    pub fn n(&self) -> f32 {
        self.n
    }

    /// Initial hysteretic state z(0).
    #[inline]
    pub fn z0(&self) -> f32 {
        self.z0
    }

    /// Asymmetry gain δ.
    #[inline]
    pub fn delta(&self) -> f32 {
        self.delta
    }

    /// Sigmoid rate p ≥ 0 (eq. 31 only).
    #[inline]
    pub fn p(&self) -> f32 {
        self.p
    }

    /// Sigmoid centre q (eq. 31 only).
    #[inline]
    pub fn q(&self) -> f32 {
        self.q
    }

    /// Which asymmetry function ψ (flat parameter `variant`).
    #[inline]
    pub fn asymmetry(&self) -> Asymmetry {
        self.asymmetry
    }
}

/// Hysteretic state z, the previous input, and whether a first sample was seen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    pub z: f32,
    pub x_prev: f32,
    pub primed: bool,
}

impl Finite for State {
    fn is_finite(&self) -> bool {
        self.z.is_finite() && self.x_prev.is_finite()
    }
}

pub type Registered = BoucWenAsym;

impl BoucWenAsym {
    /// Paper form (seed 004 Tables A17–A18 order). Bounds: see the module docs.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::bouc_wen_asym::{Asymmetry, BoucWenAsym, SEED004_A17};
    /// use model_core::{Kin, Model};
    ///
    /// let [alpha, kappa, d, a, beta, gamma, n, z0, delta, p, q, _variant] = SEED004_A17;
    /// let model = BoucWenAsym::new(alpha, kappa, d, a, beta, gamma, n, z0, delta, p, q, Asymmetry::Linear, 1e-3)?;
    /// let mut state = model.initial_state(&Kin::new(0.5, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(0.51, 10.0, 0.0, 0.0));
    /// assert!(y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        alpha: f32,
        kappa: f32,
        d: f32,
        a: f32,
        beta: f32,
        gamma: f32,
        n: f32,
        z0: f32,
        delta: f32,
        p: f32,
        q: f32,
        asymmetry: Asymmetry,
        dt: f32,
    ) -> Result<Self, ParamError> {
        let alpha = check("alpha", alpha, 0.0, 1.0)?;
        let kappa = check("kappa", kappa, f32::MIN_POSITIVE, f32::MAX)?;
        let d = check("d", d, f32::MIN_POSITIVE, f32::MAX)?;
        let a = finite("a", a)?;
        if a == 0.0 {
            return Err(ParamError::Constraint { what: "A must be non-zero" });
        }
        let beta = check("beta", beta, 0.0, f32::MAX)?;
        let gamma = finite("gamma", gamma)?;
        let n = check("n", n, 1.0, 8.0)?;
        let z0 = finite("z0", z0)?;
        let delta = finite("delta", delta)?;
        let p = check("p", p, 0.0, f32::MAX)?;
        let q = finite("q", q)?;
        let dt = time_step(dt)?;

        let sa = if a > 0.0 { 1.0 } else { -1.0 };
        let aa = abs(a);
        let c1 = beta + sa * gamma;
        let c2 = sa * gamma - beta;
        if c1 <= 0.0 || !c1.is_finite() {
            return Err(ParamError::Constraint { what: "beta + gamma*sgn(A) must be > 0 (bounded Bouc-Wen)" });
        }
        let inv_n = 1.0 / n;
        let zbar = powf(aa / c1, inv_n);
        let zrun = if c2 > 0.0 { powf(aa / c2, inv_n) } else { f32::INFINITY };
        if abs(z0) > zrun {
            return Err(ParamError::Constraint { what: "|z0| beyond (|A|/(gamma - beta))^(1/n): unloading diverges" });
        }
        let zlim = abs(z0).max((2.0 * zbar).min(zrun));
        let e2 = if c2 > 0.0 {
            zrun
        } else if c2 < 0.0 {
            -powf(aa / -c2, inv_n)
        } else {
            0.0
        };
        let order = if n == 1.0 {
            Order::One
        } else if n == 2.0 {
            Order::Two
        } else {
            Order::General
        };
        let k = Derived {
            sa,
            aa,
            c1,
            c2,
            inv_d: 1.0 / d,
            zbar,
            zlim,
            e2,
            lam1_eq: -c1 * n * powf(zbar, n - 1.0),
            lam2_eq: c2 * n * powf(abs(e2), n - 1.0),
            om1: sqrt(aa * c1),
            om2: sqrt(aa * abs(c2)),
            order,
            kx: alpha * kappa,
            kz: (1.0 - alpha) * d * kappa,
        };
        let derived = [k.inv_d, k.zbar, k.zlim, k.e2, k.lam1_eq, k.lam2_eq, k.om1, k.om2, k.kx, k.kz];
        if !(derived.iter().all(|v| v.is_finite()) && zbar > 0.0) {
            return Err(ParamError::Constraint { what: "Bouc-Wen coefficients out of f32 range" });
        }
        Ok(Self { alpha, kappa, d, a, beta, gamma, n, z0, delta, p, q, asymmetry, k, dt })
    }

    /// The state bound `|z| ≤ z_lim` (unit of x).
    pub fn z_limit(&self) -> f32 {
        self.k.zlim
    }

    /// The classical Bouc–Wen bound `z̄ = (|A|/(β + γ·sgn A))^{1/n}` (unit of x).
    pub fn z_bar(&self) -> f32 {
        self.k.zbar
    }

    /// Asymmetry function ψ(x, s) with `s = sgn(ẋ)` (eq. 30 or 31).
    #[inline]
    pub fn psi(&self, x: f32, s: f32) -> f32 {
        match self.asymmetry {
            Asymmetry::Linear => self.delta * x * s,
            Asymmetry::Sigmoid => self.delta * (1.0 + s) * 0.5 * tanh(0.5 * self.p * (x - self.q)),
        }
    }

    /// Add `g·ψ` to w and clamp (a NaN increment — 0·∞ — is ignored).
    #[inline]
    fn force(&self, w: f32, g: f32, x: f32, s: f32) -> f32 {
        let inc = g * self.psi(x, s);
        if inc.is_nan() {
            w
        } else {
            clamp(w + inc, -self.k.zlim, self.k.zlim)
        }
    }

    /// Advance z from input `x0` to `x1` over `t` seconds (see the module docs).
    #[inline]
    pub(super) fn advance(&self, z: f32, x0: f32, x1: f32, t: f32) -> f32 {
        let k = &self.k;
        let dx = x1 - x0;
        let s = sign(dx);
        // Half-step gain of the forcing, expressed for w = sgn(A)·z.
        let g = 0.5 * t * k.inv_d * k.sa;
        let mut w = self.force(k.sa * z, g, x0, s);
        if s != 0.0 {
            let h = abs(dx) * k.inv_d;
            let u = s * w;
            let u1 = if u >= 0.0 {
                self.rise(u, h)
            } else {
                match self.fall(-u, h) {
                    Fall::Stopped(v) => -v,
                    Fall::Crossed(rest) => self.rise(0.0, rest),
                }
            };
            w = clamp(s * u1, -k.zlim, k.zlim);
        }
        w = self.force(w, g, x1, s);
        k.sa * w
    }
}

/// Seed 004 (de la Morena et al. 2025) Table A17, ABW₁ (eq. 30), in [`Model::from_params`]
/// order. The tables' minus signs did not survive the text of the paper: the values are
/// as printed (all positive), which puts them in the bounded class [`BoucWenAsym::new`]
/// accepts. Input and output normalised to 0…1.
pub const SEED004_A17: [f32; 12] =
    [0.6424, 1.5240, 1.7321, 0.7691, 16.9435, 22.2617, 1.0026, 0.0884, 0.0042, 0.0, 0.0, 1.0];
/// Seed 004 Table A18, ABW₂ (eq. 31), signs as printed (see [`SEED004_A17`]).
pub const SEED004_A18: [f32; 12] =
    [0.1426, 2.3705, 3.2796, 0.1191, 1.1090, 2.5201, 1.5, 0.0086, 0.1510, 0.0064, 0.2509, 2.0];
/// Seed 004 Table A16, the classical Bouc–Wen model (eq. 26 = eq. 28 with δ = 0, n = 1),
/// signs as printed (see [`SEED004_A17`]).
pub const SEED004_A16: [f32; 12] = [0.8034, 1.1519, 3.8950, 3.4516, 59.7669, 50.0, 1.0, 0.0961, 0.0, 0.0, 0.0, 1.0];

impl Model for BoucWenAsym {
    type State = State;
    const ID: &'static str = "bouc_wen_asym";
    const PARAM_NAMES: &'static [&'static str] =
        &["alpha", "kappa", "d", "a", "beta", "gamma", "n", "z0", "delta", "p", "q", "variant"];
    const N_PARAMS: usize = 12;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [alpha, kappa, d, a, beta, gamma, n, z0, delta, p, q, variant] => {
                let asym = Asymmetry::from_code(variant)?;
                Self::new(alpha, kappa, d, a, beta, gamma, n, z0, delta, p, q, asym, dt)
            }
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(
            &[
                self.alpha,
                self.kappa,
                self.d,
                self.a,
                self.beta,
                self.gamma,
                self.n,
                self.z0,
                self.delta,
                self.p,
                self.q,
                self.asymmetry.code(),
            ],
            out,
        )
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    /// `z = z(0)`; the first step only records the input (no time has elapsed yet).
    fn initial_state(&self, first: &Kin) -> State {
        State { z: self.z0, x_prev: first.x, primed: false }
    }

    #[inline]
    fn step(&self, s: &mut State, k: &Kin) -> f32 {
        let x = k.x;
        if s.primed {
            s.z = self.advance(s.z, s.x_prev, x, self.dt);
        } else {
            s.primed = true;
        }
        s.x_prev = x;
        self.k.kx * x + self.k.kz * s.z
    }
}

#[cfg(test)]
mod tests;
