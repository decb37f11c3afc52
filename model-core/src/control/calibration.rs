//! ADC counts → physical units, and the zero-current calibration routine.
//!
//! `B = (counts − offset)·gain` (T), `i = (counts − offset)·gain` (A). The gains come from
//! the configuration (sensor datasheet, e.g. Infineon TLE4990 sensitivity, and the shunt
//! amplifier); the offsets are measured at power-up with the bridge off and the coil
//! current zero: the core is then in its virgin (or demagnetised) state, so the Hall
//! reading is the sensor offset alone.

/// Convert ADC counts to a physical value: `(counts − offset)·gain`.
#[inline]
pub fn counts_to_units(counts: u16, offset: f32, gain: f32) -> f32 {
    (f32::from(counts) - offset) * gain
}

/// Settings of the zero-current calibration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// Samples averaged (≥ 1).
    pub samples: u16,
    /// Largest admissible max − min spread of the Hall counts during calibration.
    pub max_spread: u16,
    /// Nominal offsets (counts) and how far a measured offset may lie from them.
    pub nominal_hall: f32,
    pub nominal_current: f32,
    pub max_offset_error: f32,
}

/// Accumulator of the calibration state machine.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CalibState {
    pub n: u16,
    pub sum_hall: u32,
    pub sum_current: u32,
    pub min: u16,
    pub max: u16,
}

/// What one calibration sample gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibResult {
    /// Still accumulating.
    Pending,
    /// Offsets in counts (Hall, current).
    Done { hall_offset: f32, current_offset: f32 },
    /// Too noisy or offset out of its window.
    Failed,
}

impl Calibration {
    /// Feed one sample taken with the bridge off.
    pub fn step(&self, s: &mut CalibState, hall: u16, current: u16) -> CalibResult {
        if s.n == 0 {
            *s = CalibState { n: 0, sum_hall: 0, sum_current: 0, min: hall, max: hall };
        }
        s.n = s.n.saturating_add(1);
        s.sum_hall = s.sum_hall.saturating_add(u32::from(hall));
        s.sum_current = s.sum_current.saturating_add(u32::from(current));
        s.min = s.min.min(hall);
        s.max = s.max.max(hall);
        if s.n < self.samples.max(1) {
            return CalibResult::Pending;
        }
        let n = f32::from(s.n);
        let hall_offset = s.sum_hall as f32 / n;
        let current_offset = s.sum_current as f32 / n;
        let ok = s.max - s.min <= self.max_spread
            && crate::math::abs(hall_offset - self.nominal_hall) <= self.max_offset_error
            && crate::math::abs(current_offset - self.nominal_current) <= self.max_offset_error;
        *s = CalibState::default();
        if ok {
            CalibResult::Done { hall_offset, current_offset }
        } else {
            CalibResult::Failed
        }
    }
}

#[cfg(test)]
mod tests;
