//! Classical Prandtl–Ishlinskii (CPI) model, seed 004 eq. 10–15 (de la Morena et al. 2025):
//!
//! `Φ[x](t) = p₀·x(t) + Σᵢ pᵢ·Γ_{rᵢ}[x](t)`  (eq. 15)
//!
//! with the play operator of radius `r ≥ 0` (eq. 10–11)
//!
//! `Γ_r[x](t_k) = max{x(t_k) − r, min{x(t_k) + r, Γ_r[x](t_{k−1})}}`,
//! `Γ_r[x](0) = max{x(0) − r, min{x(0) + r, M₀}}`.
//!
//! The model is rate-independent and exact at any sample rate (the play operator is
//! defined on the sampled input). x in the unit the parameters were fitted in (seed 004
//! normalises the input to 0…1; here the Hall flux density B), `rᵢ` and `M₀` in the unit
//! of x, `p₀` and `pᵢ` in output units per unit x. Radii and weights are free (seed 004
//! Tables A7–A8 fit them unsorted, some zero); one initial condition `M₀` is shared by
//! every play operator as in the paper.
//!
//! The inverse model ([`PrandtlIshlinskii::inverse`]) is again a PI model with play
//! operators on the output; see [`Inverse`].

use crate::error::{check, count, finite, time_step};
use crate::model::write_flat;
use crate::models::kernels::names::{block_names, pick};
pub use crate::models::kernels::operators::MAX_OPERATORS;
use crate::models::kernels::operators::{operator_count, to_array};
use crate::{Finite, Kin, Model, ParamError};

const R_BLOCKS: [&str; MAX_OPERATORS + 1] = block_names!("r");
const P_BLOCKS: [&str; MAX_OPERATORS + 1] = block_names!("p");

/// One play operator step, eq. 10: `max{x − r, min{x + r, prev}}`.
///
/// The result always lies in `[x − r, x + r]` (for `r ≥ 0`).
#[inline(always)]
pub fn play(x: f32, r: f32, prev: f32) -> f32 {
    (x + r).min(prev).max(x - r)
}

/// Coefficients of eq. 15 with `N` play operators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrandtlIshlinskii<const N: usize> {
    /// Linear (non-hysteretic) gain p₀ ≥ 0, output units per unit x.
    p0: f32,
    /// Initial condition M₀ of every play operator (eq. 11), unit of x.
    m0: f32,
    /// Radii rᵢ ≥ 0 (any order, repeats allowed), unit of x.
    r: [f32; N],
    /// Weights pᵢ ≥ 0, output units per unit x.
    p: [f32; N],
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const N: usize> PrandtlIshlinskii<N> {
    /// Linear (non-hysteretic) gain p₀ ≥ 0, output units per unit x.
    #[inline]
    pub fn p0(&self) -> f32 {
        self.p0
    }

    /// Initial condition M₀ of every play operator (eq. 11), unit of x.
    #[inline]
    pub fn m0(&self) -> f32 {
        self.m0
    }

    /// Radii rᵢ ≥ 0 (any order, repeats allowed), unit of x.
    #[inline]
    pub fn r(&self) -> &[f32; N] {
        &self.r
    }

    /// Weights pᵢ ≥ 0, output units per unit x.
    #[inline]
    pub fn p(&self) -> &[f32; N] {
        &self.p
    }
}

/// Outputs of the `N` play operators (unit of x).
pub type State<const N: usize> = crate::model::OperatorStates<N>;

/// Seed 004 fits 5 and 10 operators (Tables A7, A8); 10 is the registered size.
pub type Registered = PrandtlIshlinskii<10>;

impl<const N: usize> PrandtlIshlinskii<N> {
    /// Paper form: `p₀ ≥ 0`, `M₀` finite, radii `rᵢ ≥ 0`, weights `pᵢ ≥ 0` (seed 004's
    /// bounds, Tables A7–A8). `1 ≤ N ≤ 64`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::prandtl_ishlinskii::PrandtlIshlinskii;
    /// use model_core::{Kin, Model};
    ///
    /// let model = PrandtlIshlinskii::new(0.5, 0.0, [0.0, 0.1, 0.2], [0.3, 0.2, 0.1], 1e-3)?;
    /// let mut state = model.initial_state(&Kin::new(0.0, 0.0, 0.0, 0.0));
    /// let y = model.step(&mut state, &Kin::new(0.3, 0.0, 0.0, 0.0));
    /// // Every play operator follows x once x leaves its band: p₀·x + Σ pᵢ·(x − rᵢ).
    /// assert!((y - (0.5 * 0.3 + 0.3 * 0.3 + 0.2 * 0.2 + 0.1 * 0.1)).abs() < 1e-6);
    /// // The inverse undoes it.
    /// let inv = model.inverse()?;
    /// let mut inv_state = inv.state_from(&state);
    /// assert!(inv.step(&mut inv_state, y).is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(p0: f32, m0: f32, r: [f32; N], p: [f32; N], dt: f32) -> Result<Self, ParamError> {
        operator_count(N)?;
        for v in r {
            check("r", v, 0.0, f32::MAX)?;
        }
        for v in p {
            check("p", v, 0.0, f32::MAX)?;
        }
        Ok(Self { p0: check("p0", p0, 0.0, f32::MAX)?, m0: finite("m0", m0)?, r, p, dt: time_step(dt)? })
    }

    /// The analytical inverse (a PI model on the output), see [`Inverse`].
    ///
    /// Needs `p₀ > 0`: with `p₀ = 0` the model saturates once every play operator
    /// moves and has no inverse beyond that.
    pub fn inverse(&self) -> Result<Inverse<N>, ParamError> {
        Inverse::of(self)
    }
}

impl<const N: usize> Model for PrandtlIshlinskii<N> {
    type State = State<N>;
    const ID: &'static str = "prandtl_ishlinskii";
    const PARAM_NAMES: &'static [&'static str] = &["p0", "m0", pick(&R_BLOCKS, N), pick(&P_BLOCKS, N)];
    const N_PARAMS: usize = 2 + 2 * N;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        let wrong = ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() };
        let [p0, m0, rest @ ..] = v else { return Err(wrong) };
        let (r, p) = rest.split_at_checked(N).ok_or(wrong)?;
        Self::new(*p0, *m0, to_array(r), to_array(p), dt)
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let (head, rest) = out.split_at_mut(out.len().min(2));
        let mut n = write_flat(&[self.p0, self.m0], head);
        let (ro, po) = rest.split_at_mut(rest.len().min(N));
        n += write_flat(&self.r, ro);
        n += write_flat(&self.p, po);
        n
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    /// Eq. 11: every play operator starts from `M₀`, confined to `[x(0) − r, x(0) + r]`.
    fn initial_state(&self, first: &Kin) -> State<N> {
        let mut s = State::default();
        for (z, r) in s.z.iter_mut().zip(self.r) {
            *z = play(first.x, r, self.m0);
        }
        s
    }

    #[inline]
    fn step(&self, s: &mut State<N>, k: &Kin) -> f32 {
        let x = k.x;
        let mut y = self.p0 * x;
        for ((z, r), p) in s.z.iter_mut().zip(self.r).zip(self.p) {
            *z = play(x, r, *z);
            y += p * *z;
        }
        y
    }
}

/// Inverse of a classical PI model: `x = p̂₀·y + Σⱼ p̂ⱼ·Γ_{r̂ⱼ}[y]`.
///
/// With the operators sorted by radius, `0 ≤ r₁ ≤ … ≤ r_N`, and the partial sums
/// `Pⱼ = p₀ + p₁ + … + pⱼ` (so `P₀ = p₀`), the inverse thresholds and weights are the
/// standard ones (Krasnosel'skii–Pokrovskii; Kuhnen 2003):
///
/// `p̂₀ = 1/p₀`, `r̂ⱼ = Σ_{i=0..j} pᵢ·(rⱼ − rᵢ)` (with `r₀ = 0`),
/// `p̂ⱼ = −pⱼ / (Pⱼ·Pⱼ₋₁)`.
///
/// `y` in output units, `r̂ⱼ` in output units, `p̂ⱼ` in units of x per output unit.
/// The inverse's play states that correspond to a forward state `zᵢ` are
/// `ẑⱼ = Pⱼ·zⱼ + Σ_{i>j} pᵢ·zᵢ` ([`Inverse::state_from`]); started from those, the
/// inverse reproduces the forward model's input exactly (up to rounding) on any path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inverse<const N: usize> {
    /// p̂₀ = 1/p₀.
    q0: f32,
    /// Inverse radii r̂ⱼ, ascending (output units).
    r: [f32; N],
    /// Inverse weights p̂ⱼ ≤ 0.
    q: [f32; N],
    /// Forward operator index of sorted position j.
    order: [usize; N],
    /// Forward partial sums Pⱼ (sorted order).
    partial: [f32; N],
    /// Forward weights in sorted order.
    p_sorted: [f32; N],
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl<const N: usize> Inverse<N> {
    /// p̂₀ = 1/p₀.
    #[inline]
    pub fn q0(&self) -> f32 {
        self.q0
    }

    /// Inverse radii r̂ⱼ, ascending (output units).
    #[inline]
    pub fn r(&self) -> &[f32; N] {
        &self.r
    }

    /// Inverse weights p̂ⱼ ≤ 0.
    #[inline]
    pub fn q(&self) -> &[f32; N] {
        &self.q
    }
}

/// Play operator states of the inverse model (output units).
pub type InverseState<const N: usize> = State<N>;

impl<const N: usize> Inverse<N> {
    fn of(m: &PrandtlIshlinskii<N>) -> Result<Self, ParamError> {
        if m.p0 <= 0.0 {
            return Err(ParamError::Constraint { what: "PI inverse needs p0 > 0" });
        }
        let mut idx = [0usize; N];
        for (i, v) in idx.iter_mut().enumerate() {
            *v = i;
        }
        let mut pairs = [(0.0f32, 0.0f32, 0usize); N];
        for ((o, (r, p)), i) in pairs.iter_mut().zip(m.r.iter().zip(m.p.iter())).zip(idx) {
            *o = (*r, *p, i);
        }
        pairs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));

        let mut inv =
            Self { q0: 1.0 / m.p0, r: [0.0; N], q: [0.0; N], order: [0; N], partial: [0.0; N], p_sorted: [0.0; N] };
        // Running sums in f64 so the inverse is as exact as the f32 coefficients allow.
        let mut prev_sum = f64::from(m.p0);
        // Σ_{i≤j} pᵢ·rᵢ including i = 0 (r₀ = 0).
        let mut pr_sum = 0.0f64;
        for (j, &(rj, pj, i)) in pairs.iter().enumerate() {
            let (rj, pj) = (f64::from(rj), f64::from(pj));
            let sum = prev_sum + pj;
            pr_sum += pj * rj;
            let rhat = sum * rj - pr_sum;
            let qhat = -pj / (sum * prev_sum);
            if let (Some(r), Some(q), Some(o), Some(ps), Some(pp)) = (
                inv.r.get_mut(j),
                inv.q.get_mut(j),
                inv.order.get_mut(j),
                inv.partial.get_mut(j),
                inv.p_sorted.get_mut(j),
            ) {
                *r = rhat as f32;
                *q = qhat as f32;
                *o = i;
                *ps = sum as f32;
                *pp = pj as f32;
            }
            prev_sum = sum;
        }
        let all_finite = inv.q0.is_finite() && inv.r.is_finite() && inv.q.is_finite();
        if !all_finite {
            return Err(ParamError::Constraint { what: "PI inverse coefficients overflow" });
        }
        Ok(inv)
    }

    /// Inverse state matching a forward state (play outputs `fwd.z` in forward order).
    pub fn state_from(&self, fwd: &State<N>) -> InverseState<N> {
        let mut zs = [0.0f32; N];
        for (o, &i) in zs.iter_mut().zip(self.order.iter()) {
            *o = fwd.z.get(i).copied().unwrap_or(0.0);
        }
        let mut out = State::default();
        // tail = Σ_{i>j} pᵢ zᵢ, built from the end.
        let mut tail = 0.0f32;
        for (((o, &z), &pj), &sum) in
            out.z.iter_mut().zip(zs.iter()).zip(self.p_sorted.iter()).zip(self.partial.iter()).rev()
        {
            *o = sum * z + tail;
            tail += pj * z;
        }
        out
    }

    /// Inverse state when every forward play operator is relaxed at the current input
    /// (forward `zᵢ = x`): every inverse play starts at the output `y`.
    pub fn relaxed_state(&self, y: f32) -> InverseState<N> {
        State { z: [y; N] }
    }

    /// Input that produces the output `y` (feed-forward: the desired torque in, the
    /// flux density to command out). Cannot fail; finite `y` gives a finite result.
    #[inline]
    pub fn step(&self, s: &mut InverseState<N>, y: f32) -> f32 {
        let mut x = self.q0 * y;
        for ((z, r), q) in s.z.iter_mut().zip(self.r).zip(self.q) {
            *z = play(y, r, *z);
            x += q * *z;
        }
        x
    }
}

#[cfg(test)]
mod tests;
