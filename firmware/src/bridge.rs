//! When the bridge may switch. The timer's compare registers are preloaded (they take a
//! new value at the next update event), so enabling the main output (MOE) in the same
//! period as the first compare write would run one period at whatever compare was left
//! from before the trip. The safe state therefore zeroes the compares, and enabling goes
//! through [`Bridge::Arming`]: compares written, MOE set one period later.
//!
//! The stall latch (the firmware's `controller::STALLED`, set by the deadline monitor or
//! the watchdog task when the control interrupt stops) keeps the step disabled and
//! reporting an overrun fault until a reset command, even if the interrupt resumes.

/// The bridge's state as the control interrupt sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Bridge {
    /// MOE off, compares zero.
    #[default]
    Off,
    /// Compares written this period; MOE goes on at the next sample if still enabled.
    Arming,
    /// MOE on.
    Driving,
}

/// What to do with the timer this sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Safe state: MOE off, compares zero.
    Off,
    /// Write the compares, leave MOE off.
    Arm,
    /// Write the compares, MOE on (if not on already).
    Drive,
}

impl Bridge {
    /// The next state and the action for a step that asks for `pwm_enable`.
    pub const fn next(self, pwm_enable: bool) -> (Self, Action) {
        match (self, pwm_enable) {
            (_, false) => (Self::Off, Action::Off),
            (Self::Off, true) => (Self::Arming, Action::Arm),
            (Self::Arming | Self::Driving, true) => (Self::Driving, Action::Drive),
        }
    }
}

/// The compare values of the two half-bridges for a signed compare (sign-magnitude: the
/// positive side switches A, B's low side on; negative the other way), limited to
/// `max_counts`.
pub fn compares(compare: i32, max_counts: u32) -> (u32, u32) {
    let mag = compare.unsigned_abs().min(max_counts);
    if compare >= 0 {
        (mag, 0)
    } else {
        (0, mag)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moe_comes_one_period_after_the_first_compare() {
        let (s, a) = Bridge::Off.next(true);
        assert_eq!((s, a), (Bridge::Arming, Action::Arm));
        let (s, a) = s.next(true);
        assert_eq!((s, a), (Bridge::Driving, Action::Drive));
        assert_eq!(s.next(false), (Bridge::Off, Action::Off));
        assert_eq!(Bridge::Arming.next(false), (Bridge::Off, Action::Off));
    }

    #[test]
    fn compares_split_by_sign_and_saturate() {
        assert_eq!(compares(100, 4250), (100, 0));
        assert_eq!(compares(-100, 4250), (0, 100));
        assert_eq!(compares(i32::MIN, 4250), (0, 4250));
    }
}
