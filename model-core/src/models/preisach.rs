//! Discrete Preisach model, seed 004 eq. 5–9 (de la Morena et al. 2025):
//!
//! `Φ[x] = y₀ + s·Σ_{i=1..N} Σ_{j=1..i} p(H_M, H_C)·H_{αᵢ,βⱼ}[x]`  (eq. 9, with an output
//! scale `s`; `s = 1` is the paper's model)
//!
//! with delayed relays (eq. 5) `H = 1` for `x ≥ α`, `0` for `x ≤ β`, unchanged between,
//! and a density that is the product of two distributions in the Preisach-plane
//! coordinates `H_M = (α+β)/2` (bias) and `H_C = (α−β)/2` (half-width), eq. 6:
//! `p(α, β) = p_M(H_M)·p_C(H_C)`, with `p_M` Gaussian (eq. 7) and `p_C` Gaussian or
//! Cauchy (eq. 8) — seed 004's "GG" and "GC" models (Tables A1–A6).
//!
//! **Grid.** The thresholds are `N` equally spaced values over the input range
//! (`uᵢ = (i − ½)/N` of the normalised input `u = (x − x_min)/(x_max − x_min)`, a
//! resolution of `1/N` as in the paper's "50 operators … resolution of 0.02"), and every
//! pair `αᵢ ≥ βⱼ` (`j ≤ i`) carries one relay: `N(N+1)/2` relays. The densities are
//! evaluated in normalised coordinates, exactly as seed 004 fits them on data
//! normalised to 0…1, so Tables A1–A6 apply with `x_min = 0, x_max = 1, s = 1`. As in
//! the paper the weights are the density values themselves (no cell-area factor), so
//! they scale with `N`; the paper fits each `N` separately.
//!
//! **State.** The relays of one row `αᵢ` that are on always form a prefix
//! `β₁ … β_{mᵢ}` (a relay with a lower β is switched off only by a lower input), so the
//! relay states are stored exactly as one count `mᵢ ∈ 0..=i` per row (`[u8; N]`).
//! The weights' prefix sums are precomputed in `new`; a step is `O(N)` with no
//! transcendental function.
//!
//! **Initial state.** [`Model::initial_state`] is negative saturation — every relay off,
//! the paper's `H[x(0)] = 0` — after which the first sample switches on every relay
//! with `α ≤ x(0)` (so, as the paper notes, no initial loading curve from a
//! demagnetised state). [`Preisach::demagnetised_state`] gives the AC-demagnetised
//! staircase (relays with `H_M` below the range centre on) for callers that want it.

use crate::error::{check, count, finite, time_step};
use crate::math::{exp, sqrt};
use crate::model::write_flat;
use crate::{Finite, Kin, Model, ParamError};

/// Largest grid size (row counts are stored as `u8`).
pub const MAX_GRID: usize = 255;

/// Which distribution `p_C(H_C)` is (`p_M(H_M)` is always Gaussian).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Density {
    /// Gaussian–Gaussian ("GG", flat value 0).
    GaussGauss,
    /// Gaussian–Cauchy ("GC", flat value 1).
    GaussCauchy,
}

impl Density {
    fn from_code(v: f32) -> Result<Self, ParamError> {
        if v == 0.0 {
            Ok(Self::GaussGauss)
        } else if v == 1.0 {
            Ok(Self::GaussCauchy)
        } else {
            check("density", v, 0.0, 1.0)?;
            Err(ParamError::Constraint { what: "density must be 0 (Gauss-Gauss) or 1 (Gauss-Cauchy)" })
        }
    }
    fn code(self) -> f32 {
        match self {
            Self::GaussGauss => 0.0,
            Self::GaussCauchy => 1.0,
        }
    }
}

/// Gaussian density, eq. 7 (f32 maths of crate::math, result widened for summing).
fn gauss(k: f64, mu: f64, sigma: f64) -> f64 {
    let d = ((k - mu) / sigma) as f32;
    let norm = sqrt(2.0 * core::f32::consts::PI) as f64 * sigma;
    f64::from(exp(-0.5 * d * d)) / norm
}

/// Cauchy density, eq. 8.
fn cauchy(k: f64, mu: f64, sigma: f64) -> f64 {
    let d = (k - mu) / sigma;
    1.0 / (core::f64::consts::PI * sigma * (1.0 + d * d))
}

/// Coefficients of eq. 9 on an `N × N` threshold grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preisach<const N: usize> {
    /// σ of p_M(H_M) (> 0, normalised input units).
    sigma_hm: f32,
    /// μ of p_M(H_M) (normalised input units).
    mu_hm: f32,
    /// σ of p_C(H_C) (> 0).
    sigma_hc: f32,
    /// μ of p_C(H_C).
    mu_hc: f32,
    /// Output offset y₀ (output units).
    y0: f32,
    /// Output scale s (output units per unit weight); 1 in seed 004.
    scale: f32,
    /// Input range mapped to the normalised 0…1 of the grid (unit of x).
    x_min: f32,
    x_max: f32,
    density: Density,
    /// Thresholds αᵢ = βᵢ in the unit of x, ascending.
    thresholds: [f32; N],
    /// `cum[i][j] = s·Σ_{l ≤ j} p(αᵢ, β_l)` for `j ≤ i` (output units).
    cum: [[f32; N]; N],
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const N: usize> Preisach<N> {
    /// σ of p_M(H_M) (> 0, normalised input units).
    #[inline]
    pub fn sigma_hm(&self) -> f32 {
        self.sigma_hm
    }

    /// μ of p_M(H_M) (normalised input units).
    #[inline]
    pub fn mu_hm(&self) -> f32 {
        self.mu_hm
    }

    /// σ of p_C(H_C) (> 0).
    #[inline]
    pub fn sigma_hc(&self) -> f32 {
        self.sigma_hc
    }

    /// μ of p_C(H_C).
    #[inline]
    pub fn mu_hc(&self) -> f32 {
        self.mu_hc
    }

    /// Output offset y₀ (output units).
    #[inline]
    pub fn y0(&self) -> f32 {
        self.y0
    }

    /// Output scale s (output units per unit weight); 1 in seed 004.
    #[inline]
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// Input range mapped to the normalised 0…1 of the grid (unit of x).
    #[inline]
    pub fn x_min(&self) -> f32 {
        self.x_min
    }

    /// Upper end of the input range mapped to the grid.
    #[inline]
    pub fn x_max(&self) -> f32 {
        self.x_max
    }

    /// The density family of p_M, p_C.
    #[inline]
    pub fn density(&self) -> Density {
        self.density
    }
}

/// Relay states: `on[i]` relays of row `αᵢ` are on, namely those with `β₁ … β_{on[i]}`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<const N: usize> {
    pub on: [u8; N],
}

impl<const N: usize> Default for State<N> {
    /// Negative saturation: every relay off.
    fn default() -> Self {
        Self { on: [0; N] }
    }
}

impl<const N: usize> Finite for State<N> {
    fn is_finite(&self) -> bool {
        true
    }
}

impl<const N: usize> State<N> {
    /// Whether the counts describe a reachable Preisach staircase: `on[i] ≤ i + 1`, and a
    /// relay `(αᵢ, βⱼ)` that is on implies `(α_l, βⱼ)` on for every `l < i` with `j ≤ l`.
    pub fn is_valid(&self) -> bool {
        let mut ok = true;
        let mut need = 0usize; // max over later rows of on[l], restricted below
        for (i, &m) in self.on.iter().enumerate().rev() {
            let m = usize::from(m);
            ok &= m <= i + 1;
            ok &= m >= need.min(i + 1);
            need = need.max(m);
        }
        ok
    }
}

/// Seed 004 finds 50 thresholds the point beyond which the fit stops improving
/// (Tables A2, A5); 50 is the registered size (1275 relays, 10 KB of weights).
pub type Registered = Preisach<50>;

impl<const N: usize> Preisach<N> {
    /// Paper form (Tables A1–A6 order) plus output scale and input range.
    /// `σ_HM, σ_HC > 0`, every value finite, `x_min < x_max`, `1 ≤ N ≤ 255`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::preisach::{Density, Preisach};
    /// use model_core::{Kin, Model};
    ///
    /// // Seed 004 Table A2 (GC), on a 10 × 10 grid over the normalised input 0…1.
    /// let (sigma_hm, mu_hm, sigma_hc, mu_hc, y0) = (3.2352, 11.6040, 0.0232, 0.0001, 0.0837);
    /// let (scale, x_min, x_max) = (1.0, 0.0, 1.0);
    /// let density = Density::GaussCauchy;
    /// let model = Preisach::<10>::new(density, sigma_hm, mu_hm, sigma_hc, mu_hc, y0, scale, x_min, x_max, 1e-3)?;
    /// let mut state = model.initial_state(&Kin::new(0.0, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(0.6, 0.0, 0.0, 0.0));
    /// assert!(y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        density: Density,
        sigma_hm: f32,
        mu_hm: f32,
        sigma_hc: f32,
        mu_hc: f32,
        y0: f32,
        scale: f32,
        x_min: f32,
        x_max: f32,
        dt: f32,
    ) -> Result<Self, ParamError> {
        let mut m = Self::ZEROED;
        m.rebuild(density, sigma_hm, mu_hm, sigma_hc, mu_hc, y0, scale, x_min, x_max, dt)?;
        Ok(m)
    }

    /// A placeholder with every field zero (not a validated model): storage for
    /// [`Preisach::rebuild`] / [`Preisach::rebuild_from_params`] to build into, e.g. a
    /// `static` (all zero bytes, so it costs no flash).
    pub const ZEROED: Self = Self {
        sigma_hm: 0.0,
        mu_hm: 0.0,
        sigma_hc: 0.0,
        mu_hc: 0.0,
        y0: 0.0,
        scale: 0.0,
        x_min: 0.0,
        x_max: 0.0,
        density: Density::GaussGauss,
        thresholds: [0.0; N],
        cum: [[0.0; N]; N],
        dt: 0.0,
    };

    /// [`Model::from_params`] built in place: `self` becomes exactly what
    /// `from_params(v, dt)` returns, without a copy of the `N × N` weight table on the stack
    /// (the firmware builds the registered 50 × 50 model, 10 KB, into a static slot).
    /// On an error `self` is left with unspecified (finite or not) values: build it again
    /// before use.
    pub fn rebuild_from_params(&mut self, v: &[f32], dt: f32) -> Result<(), ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [s_hm, m_hm, s_hc, m_hc, y0, scale, x_min, x_max, d] => {
                self.rebuild(Density::from_code(d)?, s_hm, m_hm, s_hc, m_hc, y0, scale, x_min, x_max, dt)
            }
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    /// [`Preisach::new`] in place (see [`Preisach::rebuild_from_params`]): the checks, then
    /// the thresholds and the weights' prefix sums written into `self`.
    #[allow(clippy::too_many_arguments)]
    pub fn rebuild(
        &mut self,
        density: Density,
        sigma_hm: f32,
        mu_hm: f32,
        sigma_hc: f32,
        mu_hc: f32,
        y0: f32,
        scale: f32,
        x_min: f32,
        x_max: f32,
        dt: f32,
    ) -> Result<(), ParamError> {
        if N == 0 || N > MAX_GRID {
            return Err(ParamError::Constraint { what: "Preisach grid size must be 1..=255" });
        }
        let sigma_hm = check("sigma_hm", sigma_hm, f32::MIN_POSITIVE, f32::MAX)?;
        let mu_hm = finite("mu_hm", mu_hm)?;
        let sigma_hc = check("sigma_hc", sigma_hc, f32::MIN_POSITIVE, f32::MAX)?;
        let mu_hc = finite("mu_hc", mu_hc)?;
        let y0 = finite("y0", y0)?;
        let scale = finite("scale", scale)?;
        let x_min = finite("x_min", x_min)?;
        let x_max = finite("x_max", x_max)?;
        let span = x_max - x_min;
        if !(span > 0.0 && span.is_finite()) {
            return Err(ParamError::Constraint { what: "x_min < x_max (finite span)" });
        }
        let dt = time_step(dt)?;

        let n = N as f64;
        let u = |i: usize| (i as f64 + 0.5) / n;
        for (i, t) in self.thresholds.iter_mut().enumerate() {
            *t = (f64::from(x_min) + f64::from(span) * u(i)) as f32;
        }
        let (sm, mm, sc, mc) = (f64::from(sigma_hm), f64::from(mu_hm), f64::from(sigma_hc), f64::from(mu_hc));
        for (i, row) in self.cum.iter_mut().enumerate() {
            let mut acc = 0.0f64;
            for (j, c) in row.iter_mut().enumerate().take(i + 1) {
                let hm = 0.5 * (u(i) + u(j));
                let hc = 0.5 * (u(i) - u(j));
                let pc = match density {
                    Density::GaussGauss => gauss(hc, mc, sc),
                    Density::GaussCauchy => cauchy(hc, mc, sc),
                };
                acc += gauss(hm, mm, sm) * pc;
                *c = (f64::from(scale) * acc) as f32;
            }
            // Above the diagonal: no relay (zero, whatever an earlier build left there).
            row.iter_mut().skip(i + 1).for_each(|c| *c = 0.0);
            if !row.is_finite() {
                return Err(ParamError::Constraint {
                    what: "Preisach weights overflow (sigma too small or scale too large)",
                });
            }
        }
        // The output must stay finite with every relay on.
        let total: f32 = self.cum.iter().enumerate().filter_map(|(i, row)| row.get(i)).sum();
        if !(y0 + total).is_finite() {
            return Err(ParamError::Constraint { what: "Preisach output overflows" });
        }
        (self.sigma_hm, self.mu_hm, self.sigma_hc, self.mu_hc) = (sigma_hm, mu_hm, sigma_hc, mu_hc);
        (self.y0, self.scale, self.x_min, self.x_max) = (y0, scale, x_min, x_max);
        (self.density, self.dt) = (density, dt);
        Ok(())
    }

    /// Thresholds `αᵢ = βᵢ` in the unit of x, ascending.
    pub fn thresholds(&self) -> &[f32; N] {
        &self.thresholds
    }

    /// Weight of relay `(αᵢ, βⱼ)` times the scale (`None` unless `j ≤ i < N`).
    pub fn weight(&self, i: usize, j: usize) -> Option<f32> {
        if j > i {
            return None;
        }
        let row = self.cum.get(i)?;
        let c = *row.get(j)?;
        Some(match j.checked_sub(1) {
            Some(jm) => c - row.get(jm).copied().unwrap_or(0.0),
            None => c,
        })
    }

    /// AC-demagnetised state: relays with `αᵢ + βⱼ < x_min + x_max` (bias below the centre
    /// of the range) on, the rest off.
    pub fn demagnetised_state(&self) -> State<N> {
        let mut s = State::default();
        let centre2 = self.x_min + self.x_max;
        for (i, (m, a)) in s.on.iter_mut().zip(self.thresholds).enumerate() {
            let cnt = self.thresholds.iter().take(i + 1).filter(|&&b| a + b < centre2).count();
            *m = cnt as u8;
        }
        s
    }

    /// Model output for a relay state (eq. 9).
    #[inline]
    pub fn output(&self, s: &State<N>) -> f32 {
        let sum: f32 =
            s.on.iter()
                .zip(self.cum.iter())
                .map(|(&m, row)| usize::from(m).checked_sub(1).and_then(|j| row.get(j)).copied().unwrap_or(0.0))
                .sum();
        self.y0 + sum
    }
}

impl<const N: usize> Model for Preisach<N> {
    type State = State<N>;
    const ID: &'static str = "preisach";
    const PARAM_NAMES: &'static [&'static str] =
        &["sigma_hm", "mu_hm", "sigma_hc", "mu_hc", "y0", "scale", "x_min", "x_max", "density"];
    const N_PARAMS: usize = 9;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [s_hm, m_hm, s_hc, m_hc, y0, scale, x_min, x_max, d] => {
                Self::new(Density::from_code(d)?, s_hm, m_hm, s_hc, m_hc, y0, scale, x_min, x_max, dt)
            }
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(
            &[
                self.sigma_hm,
                self.mu_hm,
                self.sigma_hc,
                self.mu_hc,
                self.y0,
                self.scale,
                self.x_min,
                self.x_max,
                self.density.code(),
            ],
            out,
        )
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    /// Negative saturation (every relay off), seed 004's `H[x(0)] = 0`.
    fn initial_state(&self, _first: &Kin) -> State<N> {
        State::default()
    }

    #[inline]
    fn step(&self, s: &mut State<N>, k: &Kin) -> f32 {
        let x = k.x;
        // Rows with α ≤ x switch fully on; in the other rows every relay with β ≥ x
        // switches off, i.e. at most the `below` relays with β < x stay on.
        let at_or_below = self.thresholds.partition_point(|&a| a <= x);
        let below = self.thresholds.partition_point(|&b| b < x);
        let below = u8::try_from(below).unwrap_or(u8::MAX);
        for (i, m) in s.on.iter_mut().enumerate() {
            if i < at_or_below {
                *m = u8::try_from(i + 1).unwrap_or(u8::MAX);
            } else {
                *m = (*m).min(below);
            }
        }
        self.output(s)
    }
}

#[cfg(test)]
mod tests;
