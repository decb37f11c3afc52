//! PI controller with output limits and clamping anti-windup (conditional integration,
//! Åström & Hägglund, *Advanced PID Control*, 2006, §3.5).
//!
//! `u = ff + kp·e + I`, `I ← I + ki·T·e` only while the output is not saturated in the
//! direction `e` pushes it; `I` is kept within the output limits.

/// Validated gains and limits (built by [`Pi::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pi {
    kp: f32,
    ki_dt: f32,
    lo: f32,
    hi: f32,
}

/// Integrator state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PiState {
    pub integral: f32,
}

impl Pi {
    /// Gains `kp`, `ki` (per second) at time step `dt`, output limited to `[lo, hi]`.
    /// Callers validate the numbers (see [`ControlConfig::validate`](super::ControlConfig::validate)).
    pub const fn new(kp: f32, ki: f32, dt: f32, lo: f32, hi: f32) -> Self {
        Self { kp, ki_dt: ki * dt, lo, hi }
    }

    /// One step with error `e` and feed-forward `ff`; returns the limited output.
    /// A non-finite `e` leaves the state unchanged; a non-finite `ff` counts as 0.
    #[inline]
    pub fn step(&self, s: &mut PiState, e: f32, ff: f32) -> f32 {
        let ff = if ff.is_finite() { ff } else { 0.0 };
        if !e.is_finite() {
            return clamp(ff + s.integral, self.lo, self.hi);
        }
        step_limited(self.kp, self.ki_dt, s, e, ff, self.lo, self.hi)
    }
}

/// The PI step without input guards, for callers whose error and feed-forward are finite
/// by construction (the control step): gains `kp` and `ki_dt` (`ki·T`), output limited to
/// `[lo, hi]` (finite, `lo ≤ hi`). Output and integral stay inside their limits even for
/// a NaN `e` (the output is then `lo`); a non-finite `ff` is the caller's error.
#[inline(always)]
pub fn step_limited(kp: f32, ki_dt: f32, s: &mut PiState, e: f32, ff: f32, lo: f32, hi: f32) -> f32 {
    let raw = ff + kp * e + s.integral;
    let out = clamp(raw, lo, hi);
    // Saturated in the direction `e` pushes (raw > hi with e > 0, or raw < lo with e < 0):
    // the excess and the error have the same sign.
    let pushes_out = (raw - out) * e > 0.0;
    if !pushes_out {
        let i = s.integral + ki_dt * e;
        s.integral = clamp(i, lo - ff, hi - ff);
    }
    out
}

/// `x` limited to `[lo, hi]`; NaN maps to `lo`.
#[inline]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x >= hi {
        hi
    } else if x >= lo {
        x
    } else {
        lo
    }
}

#[cfg(test)]
mod tests;
