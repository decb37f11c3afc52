//! The physics check of a configuration page's model, run before the page is committed:
//! the page's own estimator (its model, its rate estimator, its time step) is driven
//! through a slow sweep of the field over the range the controller uses, and the page is
//! refused when the estimate there is not what a clutch does — not finite, beyond the
//! clutch's rating, or not rising with the field ([`PhysicsFault`]).
//!
//! # The sweep
//!
//! One sample per time step `dt` of the page, from rest at 0 up to [`ControlConfig::b_max`]
//! in `T_h` (the rising branch) and back to 0 in `T_h` (the falling branch), each a
//! smoothstep `B = b_max·u²·(3 − 2u)` of the branch's elapsed share `u ∈ [0, 1]`: the rate
//! is zero at both ends and at the top, so the estimate at `B = 0` and at `B = b_max` is
//! the static one (no `c·Ḃ` in it) and the turn at the top has no jump of the rate. (A
//! polynomial rather than a raised cosine: the Cortex-M4F has no double-precision unit,
//! and libm's `sinf` works in f64, hundreds of instructions a sample.)
//!
//! - **Range.** The torque loop drives the coil with a current in `[0, i_max]` and its
//!   feed-forward asks for a field in `[0, b_max]`: the clutch is run on the positive side
//!   only. A negative field is reached only by the demagnetising pulse's undershoot, during
//!   which the loop does not act on the estimate (its integrators are reset), and the
//!   fitted clutch models are not odd in B (a torque offset `T₀`, sigmoid nets, a
//!   one-sided command), so a requirement there would refuse good sets: the negative side
//!   is not swept.
//! - **Command.** Models with a command input get the coil current the page's static slope
//!   gives for that field, `u = B / b_per_amp` (as the control step feeds the measured coil
//!   current).
//! - **Duration** ([`SWEEP_HALF_S`], 0.5 s each way). The rate-dependent parts of the clutch
//!   models are viscous terms `c·Ḃ` (algebraic, tanh, LuGre, Bouc–Wen, Dahl's `C0·ẋ`; the
//!   seed-000 fits have `c/k` of 10–35 ms) and first-order lags (Dahl's and Spencer's command
//!   filter `η = 190 s⁻¹`, 5 ms; the rate estimators', 1 ms at 150 Hz). The hysteretic
//!   states of Bouc–Wen, LuGre and Dahl are rate independent (functions of the path of B),
//!   so their branches do not depend on the speed. At `T_h = 0.5 s` the peak rate is
//!   `1.5·b_max/T_h`, 2.4 T/s for 0.8 T: the viscous part is at most `(c/k)·1.5/T_h`,
//!   3–11 % of `k·b_max` at mid-branch and zero at the ends, and a 5 ms lag shifts a branch
//!   by at most 1.5 % of `b_max`. That is below the rate a 1 Hz fitting sine of 0.6 T
//!   reaches (3.8 T/s), so the check asks nothing of a set outside the rates it was fitted
//!   on. A longer sweep costs the board linearly: `2·T_h/dt` steps (20 001 at 20 kHz).
//!
//! # The requirements
//!
//! - Every estimate finite: the estimator rolls a step back that would make its output or
//!   state non-finite ([`Flags::OVERFLOW`](crate::Flags::OVERFLOW)); the first such step
//!   refuses the page ([`PhysicsFault::NonFinite`]).
//! - `|estimate| ≤ RATING_MARGIN·torque_max` over the whole sweep
//!   ([`PhysicsFault::ExceedsRating`], with the largest one), see [`RATING_MARGIN`].
//! - Along the rising branch the estimate never falls below its running maximum by more
//!   than [`DROP_SHARE`] of the branch's span ([`PhysicsFault::Decreasing`]), and it ends
//!   at `b_max` at least [`MIN_RISE_SHARE`]`·torque_max` above its value at zero field
//!   ([`PhysicsFault::NotRising`]). The falling branch is not held to a direction: a
//!   rate-driven model (tanh) legitimately rises there as its rate term relaxes.
//!
//! The rising branch is judged at the top, before the rest of the sweep: a set that falls
//! with the field is reported as such even where its estimate also exceeds the rating.
//!
//! # Cost and chunks
//!
//! [`Sweep::advance`] runs at most `max_steps` samples and returns, so the firmware can
//! yield to its other tasks between chunks; nothing allocates, nothing panics, every
//! figure is a number in the result. [`check`] runs a whole sweep at once (the host).

use super::config::ControlConfig;
use super::page::{ConfigImage, PageError};
use crate::{Estimator, EstimatorState, Model};

/// Duration of each branch of the sweep, s (see the module documentation: slow against
/// the models' viscous and lag time constants, within the rates the sets are fitted on).
pub const SWEEP_HALF_S: f32 = 0.5;
/// Samples of a branch at most: [`SWEEP_HALF_S`] at the firmware's fastest control rate
/// (20 kHz). A page at a faster rate sweeps in the same number of samples, over a shorter
/// time, so the cost stays bounded.
pub const MAX_HALF_STEPS: u32 = 10_000;
/// Samples of a branch at least (a page with a very long time step still samples the
/// branch finely enough to see its shape).
pub const MIN_HALF_STEPS: u32 = 64;

/// Largest |estimate| accepted, as a multiple of the page's `torque_max`.
///
/// `torque_max` is the largest torque the loop is ever asked for; a clutch is built with
/// field headroom above it, so at `b_max` it may transmit somewhat more (the simulated
/// clutch gives 15.1 N·m at 3 A for a 15 N·m rating; an algebraic set fitted there,
/// extrapolated to 0.8 T, peaks at 15.2 N·m), and hysteresis and the viscous term add a
/// little on the branches. An MR fluid's yield stress saturates with the field, so no
/// field makes a clutch transmit many times its rating. Twice the rating leaves that
/// headroom and separates clutch sets by a wide margin from sets in the wrong units or of
/// another device, which are off by 10²–10³ (a set fitted with B in mT run on tesla, a
/// damper's force in N).
pub const RATING_MARGIN: f32 = 2.0;

/// Largest fall of the estimate along the rising branch (below its running maximum), as a
/// share of the branch's span (its largest minus its smallest estimate).
///
/// A torque loop on an estimate that falls by `d` past a peak can lose every reference in
/// a band of width `d`: an overshoot past the peak makes the estimate fall away from the
/// reference and the integrator then drives the coil to `i_max`. A third keeps at least
/// two thirds of the branch's torque range on a rising estimate. A wrong-signed stiffness
/// falls over the whole span (share 1); a fitted polynomial that turns over past the field
/// its recording reached falls by about a fifth (an algebraic fit of a 0–3 A sine: 15.2 N·m
/// at 0.62 T, 12.2 N·m at 0.8 T) and passes; the rate terms' humps along a slow sweep are
/// below 1 % of the span.
pub const DROP_SHARE: f32 = 1.0 / 3.0;

/// Smallest rise of the estimate from zero field to `b_max`, as a share of `torque_max`.
///
/// A set whose estimate barely moves with the field gives the torque loop no authority:
/// every reference above its zero-field torque would drive the coil to `i_max`. 5 % of the
/// rating (0.75 N·m for 15 N·m) is far below what any clutch set spans and far above the
/// numerical noise of a flat one.
pub const MIN_RISE_SHARE: f32 = 0.05;

/// An estimate and the field it was taken at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reading {
    /// Flux density, T.
    pub b: f32,
    /// Torque estimate, N·m.
    pub torque: f32,
}

/// Why a page's model fails the physics check, with its figures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PhysicsFault {
    /// The estimate turned non-finite at field `b` (T): the estimator rolled the step back.
    NonFinite { b: f32 },
    /// The largest |estimate| of the sweep, `at`, is beyond `limit` (N·m,
    /// [`RATING_MARGIN`] times `torque_max`).
    ExceedsRating { at: Reading, limit: f32 },
    /// Along the rising branch the estimate fell from `high` to `low` (the field rising
    /// from `high.b` to `low.b`), more than [`DROP_SHARE`] of the branch's `span` (N·m).
    Decreasing { high: Reading, low: Reading, span: f32 },
    /// From `at_zero` to `at_max` (zero field to `b_max`) the estimate rose by less than
    /// `needed` (N·m, [`MIN_RISE_SHARE`] times `torque_max`).
    NotRising { at_zero: Reading, at_max: Reading, needed: f32 },
}

impl PhysicsFault {
    /// A name for a log line (no numbers: the firmware's log avoids float formatting).
    pub fn reason(&self) -> &'static str {
        match self {
            Self::NonFinite { .. } => "model estimate not finite on the field sweep",
            Self::ExceedsRating { .. } => "model estimate beyond the clutch's rating",
            Self::Decreasing { .. } => "model estimate falls as the field rises",
            Self::NotRising { .. } => "model estimate does not rise with the field",
        }
    }
}

/// The sweep's profile and limits, from the page's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plan {
    b_max: f32,
    /// Coil current per tesla, A/T (`1 / b_per_amp`).
    amp_per_b: f32,
    /// Samples of one branch; the sweep has `2·half + 1`.
    half: u32,
    /// Largest |estimate| accepted, N·m.
    limit: f32,
    /// Smallest rise over the rising branch, N·m.
    min_rise: f32,
}

impl Plan {
    fn new(dt: f32, c: &ControlConfig) -> Self {
        let half = libm::roundf(SWEEP_HALF_S / dt);
        // `as` saturates (and maps NaN to 0); the clamp keeps the count in its bounds.
        let half = (half as u32).clamp(MIN_HALF_STEPS, MAX_HALF_STEPS);
        Self {
            b_max: c.b_max,
            amp_per_b: 1.0 / c.b_per_amp,
            half,
            limit: RATING_MARGIN * c.torque_max,
            min_rise: MIN_RISE_SHARE * c.torque_max,
        }
    }

    /// The field of sample `k` (`0 ..= 2·half`): the smoothstep `b_max·u²·(3 − 2u)` with
    /// `u = k/half` rising, `u = (2·half − k)/half` falling; 0 at both ends, `b_max` at the
    /// top (exactly: `u` is then exactly 0 or 1), never negative.
    fn field(&self, k: u32) -> f32 {
        let from_end = if k <= self.half { k } else { (2 * self.half).saturating_sub(k) };
        let u = from_end as f32 / self.half as f32;
        self.b_max * (u * u) * (3.0 - 2.0 * u)
    }
}

/// The rising branch as it goes: its first reading, its extremes and its worst fall.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Rising {
    first: Reading,
    /// Running maximum.
    peak: Reading,
    lowest: f32,
    /// The worst fall so far: from `drop_from` (a running maximum) to `drop_to`.
    drop_from: Reading,
    drop_to: Reading,
}

impl Rising {
    fn start(r: Reading) -> Self {
        Self { first: r, peak: r, lowest: r.torque, drop_from: r, drop_to: r }
    }

    fn push(&mut self, r: Reading) {
        if r.torque > self.peak.torque {
            self.peak = r;
        }
        if r.torque < self.lowest {
            self.lowest = r.torque;
        }
        if self.peak.torque - r.torque > self.drop_from.torque - self.drop_to.torque {
            self.drop_from = self.peak;
            self.drop_to = r;
        }
    }

    /// The branch judged at its top reading `top` (the field at `b_max`).
    fn verdict(&self, top: Reading, plan: &Plan) -> Result<(), PhysicsFault> {
        let span = self.peak.torque - self.lowest;
        let fall = self.drop_from.torque - self.drop_to.torque;
        if fall > DROP_SHARE * span {
            return Err(PhysicsFault::Decreasing { high: self.drop_from, low: self.drop_to, span });
        }
        // Readings are finite (the estimator's output always is), so the rise is not NaN.
        if top.torque - self.first.torque < plan.min_rise {
            return Err(PhysicsFault::NotRising { at_zero: self.first, at_max: top, needed: plan.min_rise });
        }
        Ok(())
    }
}

/// A physics check in progress: the page's estimator (borrowed) and the sweep's state.
/// Advance it in chunks with [`Sweep::advance`] until it returns the verdict.
///
/// ```
/// use model_core::control::physics::{PhysicsFault, Sweep};
/// use model_core::control::ControlConfig;
/// use model_core::models::algebraic::{Algebraic, SEED000_AVERAGE};
/// use model_core::rate::RateParams;
/// use model_core::{Estimator, Model};
///
/// let dt = 5e-5;
/// let control = ControlConfig::defaults(dt);
/// let est = Estimator::new(Algebraic::from_params(&SEED000_AVERAGE, dt)?, RateParams::filtered(dt, 150.0)?)?;
/// let mut sweep = Sweep::new(&est, &control);
/// let verdict = loop {
///     // The firmware yields to its other tasks between chunks.
///     if let Some(v) = sweep.advance(64) {
///         break v;
///     }
/// };
/// assert_eq!(verdict, Ok(()));
/// // The stiffness with the wrong sign: the estimate falls as the field rises.
/// let [k, c, alpha, t0] = SEED000_AVERAGE;
/// let flipped = Estimator::new(Algebraic::new(-k, c, alpha, t0, dt)?, RateParams::filtered(dt, 150.0)?)?;
/// let v = Sweep::new(&flipped, &control).run();
/// assert!(matches!(v, Err(PhysicsFault::Decreasing { .. })));
/// # Ok::<(), model_core::ParamError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Sweep<'a, M: Model> {
    est: &'a Estimator<M>,
    state: EstimatorState<M::State>,
    plan: Plan,
    /// The next sample, `0 ..= 2·half`.
    k: u32,
    rising: Rising,
    /// The largest |estimate| so far.
    worst: Reading,
    verdict: Option<Result<(), PhysicsFault>>,
}

impl<'a, M: Model> Sweep<'a, M> {
    /// A sweep of `est` (built from the page at its time step) over the field range and
    /// against the rating of `control` (the page's settings).
    pub fn new(est: &'a Estimator<M>, control: &ControlConfig) -> Self {
        Self {
            est,
            state: est.state(),
            plan: Plan::new(est.model.dt(), control),
            k: 0,
            rising: Rising::default(),
            worst: Reading::default(),
            verdict: None,
        }
    }

    /// Samples of the whole sweep.
    pub fn steps(&self) -> u32 {
        2 * self.plan.half + 1
    }

    /// Run at most `max_steps` samples: `None` while the sweep goes on, then the verdict
    /// (the same verdict again on every later call).
    pub fn advance(&mut self, max_steps: u32) -> Option<Result<(), PhysicsFault>> {
        for _ in 0..max_steps {
            if self.verdict.is_some() {
                break;
            }
            self.verdict = self.sample();
        }
        self.verdict
    }

    /// The whole sweep at once.
    pub fn run(mut self) -> Result<(), PhysicsFault> {
        loop {
            if let Some(v) = self.advance(u32::MAX) {
                return v;
            }
        }
    }

    /// One sample of the sweep; the verdict once there is one.
    fn sample(&mut self) -> Option<Result<(), PhysicsFault>> {
        let (k, half) = (self.k, self.plan.half);
        let b = self.plan.field(k);
        let out = self.est.step_finite(&mut self.state, b, b * self.plan.amp_per_b);
        if !out.flags.ok() {
            return Some(Err(PhysicsFault::NonFinite { b }));
        }
        let r = Reading { b, torque: out.y };
        if crate::math::abs(r.torque) > crate::math::abs(self.worst.torque) {
            self.worst = r;
        }
        if k == 0 {
            self.rising = Rising::start(r);
        } else if k <= half {
            self.rising.push(r);
        }
        if k == half {
            if let Err(e) = self.rising.verdict(r, &self.plan) {
                return Some(Err(e));
            }
        }
        if k >= 2 * half {
            return Some(self.rating());
        }
        self.k = k + 1;
        None
    }

    /// The rating requirement on the largest |estimate| of the sweep.
    fn rating(&self) -> Result<(), PhysicsFault> {
        if crate::math::abs(self.worst.torque) > self.plan.limit {
            Err(PhysicsFault::ExceedsRating { at: self.worst, limit: self.plan.limit })
        } else {
            Ok(())
        }
    }
}

/// The physics check of `est` against the settings `control`, the whole sweep at once.
pub fn check<M: Model>(est: &Estimator<M>, control: &ControlConfig) -> Result<(), PhysicsFault> {
    Sweep::new(est, control).run()
}

/// The estimator a page describes for model `M`: its parameters by `from_params` at the
/// page's time step, its rate estimator (what the control step is built from).
pub fn page_estimator<M: Model>(img: &ConfigImage) -> Result<Estimator<M>, PageError> {
    let rate = img.rate.build(img.control.get().dt).map_err(PageError::Invalid)?;
    Estimator::new(img.model::<M>()?, rate).map_err(PageError::Invalid)
}

#[cfg(test)]
mod tests;
