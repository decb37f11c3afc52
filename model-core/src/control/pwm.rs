//! Duty of a bipolar H-bridge and the demagnetising pulse.
//!
//! `d = V/V_supply`, limited to `±duty_max` and quantised to the timer's compare counts
//! (sign-magnitude drive: the sign selects the diagonal, `|d|` the on-time). When the
//! command returns to zero after a large value, a short reverse pulse drives the core
//! round a minor loop towards B = 0, removing most of the remanent field and with it the
//! remanent torque (the usual degaussing practice for MR clutches, e.g. Shafer &
//! Kermani's clutch, seed 000 ref. 20).

use super::pi::clamp;

/// Duty in `[−duty_max, duty_max]` for voltage `v` at supply `supply` (V), quantised to
/// `counts`; returns `(duty, compare)`. A non-finite `v` or supply, or a non-positive
/// supply, gives 0.
#[inline]
pub fn duty(v: f32, supply: f32, duty_max: f32, counts: f32) -> (f32, i32) {
    if !(supply.is_finite() && supply > 0.0 && v.is_finite()) {
        return (0.0, 0);
    }
    let d = clamp(v / supply, -duty_max, duty_max);
    let compare = libm::roundf(d * counts);
    (compare / counts, compare as i32)
}

/// Duty `d` (finite, |d| ≤ 1) quantised to `counts` ≤ 65535 per unit duty, rounded to
/// the nearest count (halves up), without a libm call; returns `(duty, compare)`.
#[inline(always)]
pub fn quantise(d: f32, counts: f32) -> (f32, i32) {
    // `as` truncates toward zero (VCVT); shifted positive by 2¹⁶ counts it is a floor, so
    // `⌊q + ½⌋` is the nearest count.
    const SHIFT: f32 = 65536.0;
    let compare = (d * counts + (SHIFT + 0.5)) as i32 - SHIFT as i32;
    (compare as f32 / counts, compare)
}

/// Demagnetising pulse settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Demag {
    pub duty: f32,
    pub samples: u16,
    /// |command| that arms the pulse; it fires when |command| falls below a quarter of it.
    pub threshold: f32,
}

/// Pulse state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DemagState {
    /// Samples of the running pulse still to drive.
    pub remaining: u16,
    /// The current before the pulse, A (its sign sets the pulse's: stored as it is, the
    /// sign is taken only while the pulse runs).
    pub sign: f32,
    /// |command| below which the pulse fires: a quarter of [`Demag::threshold`] while
    /// armed, 0 (never, as |command| ≥ 0) otherwise. One compare tests "armed and
    /// released".
    pub level: f32,
}

impl Demag {
    /// Feed the command and the coil current; `Some(duty)` while the pulse
    /// overrides the loop.
    #[inline(always)]
    pub fn step(&self, s: &mut DemagState, command: f32, i: f32) -> Option<f32> {
        if s.remaining > 0 {
            s.remaining -= 1;
            return Some(self.pulse(s));
        }
        let mag = crate::math::abs(command);
        if mag >= self.threshold {
            s.level = 0.25 * self.threshold;
            s.sign = i;
        } else if mag < s.level {
            s.level = 0.0;
            if self.samples > 0 {
                s.remaining = self.samples - 1;
                return Some(self.pulse(s));
            }
        }
        None
    }

    /// The pulse's duty: against the current before it (0 counts as positive).
    #[inline(always)]
    fn pulse(&self, s: &DemagState) -> f32 {
        if s.sign < 0.0 {
            self.duty
        } else {
            -self.duty
        }
    }
}

#[cfg(test)]
mod tests;
