//! The steady loop under a triangular input and the crossing-branch check of seed 004 §6.2.

use super::BoucWenAsym;

/// Intervals per branch of [`BoucWenAsym::steady_loop`].
pub const LOOP_POINTS: usize = 256;

/// Rising and falling branch of a steady loop (z at equally spaced inputs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Branches {
    pub up: [f32; LOOP_POINTS + 1],
    pub down: [f32; LOOP_POINTS + 1],
}

impl BoucWenAsym {
    /// The steady loop for a triangular input between `x_lo` and `x_hi` at the constant
    /// rate `rate` (unit of x per second): z on the rising branch and on the falling
    /// branch at the `LOOP_POINTS + 1` inputs `x_lo + i·(x_hi − x_lo)/LOOP_POINTS`, after
    /// eight settling cycles from z(0). `None` for invalid arguments.
    pub fn steady_loop(&self, x_lo: f32, x_hi: f32, rate: f32) -> Option<Branches> {
        const M: usize = LOOP_POINTS;
        if !(x_lo.is_finite() && x_hi.is_finite() && x_hi > x_lo && rate.is_finite() && rate > 0.0) {
            return None;
        }
        let step = (x_hi - x_lo) / M as f32;
        let t = step / rate;
        if !(t.is_finite() && t > 0.0) {
            return None;
        }
        let xi = |i: usize| x_lo + step * i as f32;
        let mut z = self.z0;
        for _ in 0..8 {
            for i in 1..=M {
                z = self.advance(z, xi(i - 1), xi(i), t);
            }
            for i in (0..M).rev() {
                z = self.advance(z, xi(i + 1), xi(i), t);
            }
        }
        let mut b = Branches { up: [0.0; M + 1], down: [0.0; M + 1] };
        for (i, u) in b.up.iter_mut().enumerate() {
            if i > 0 {
                z = self.advance(z, xi(i - 1), xi(i), t);
            }
            *u = z;
        }
        for (i, dn) in b.down.iter_mut().enumerate().rev() {
            if i < M {
                z = self.advance(z, xi(i + 1), xi(i), t);
            }
            *dn = z;
        }
        Some(b)
    }

    /// Whether the loading and unloading branches of the steady loop cross.
    ///
    /// Seed 004 §6.2 reports that eq. 30 can produce non-physical crossing loops: the
    /// asymmetry term opposes (δ·A < 0) or reinforces the Bouc–Wen loop in proportion to
    /// x and to the time spent, so at some excitation rates it turns the loop round
    /// near the upper end of the range only, and the branches cross. The loop is traced
    /// by [`BoucWenAsym::steady_loop`] for a triangular input between `x_lo` and `x_hi` at
    /// the constant rate `rate` (unit of x per second; the answer depends on it — seed
    /// 004's excitation is 0.05 Hz over the normalised range, rate 0.1 s⁻¹). The branches
    /// cross when `z_down − z_up` takes both signs, each by more than 0.1 % of its largest
    /// magnitude, at interior points. Invalid arguments give `false`.
    pub fn crossing_risk(&self, x_lo: f32, x_hi: f32, rate: f32) -> bool {
        let Some(b) = self.steady_loop(x_lo, x_hi, rate) else { return false };
        let mut lo = 0.0f32;
        let mut hi = 0.0f32;
        for (u, dn) in b.up.iter().zip(b.down.iter()).skip(1).take(LOOP_POINTS - 1) {
            let diff = dn - u;
            lo = lo.min(diff);
            hi = hi.max(diff);
        }
        let tol = 1e-3 * hi.max(-lo);
        tol > 0.0 && hi > tol && lo < -tol
    }
}
