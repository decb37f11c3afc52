//! FDCAN nominal bit timing (RM0440 §44.3.3, CiA 601-3 sample point), and the oscillator
//! tolerance it gives (Bosch, "The Configuration of the CAN Bit Timing", eq. for df):
//! `df ≤ min(SJW / (20·N), min(PS1, PS2) / (2·(13·N − PS2)))` with N time quanta a bit.
//!
//! From the Nucleo's 24 MHz crystal at 1 Mbit/s: 24 quanta, TSEG1 19, TSEG2 4, SJW 4,
//! sample point 83 %, tolerance 0.65 % (a crystal needs 0.01 %). The previous set-up
//! from the 16 MHz HSI (10 quanta, SJW 1: 0.5 % by the same formula) was below the HSI's
//! own ±1 %.

/// Bit timing in time quanta: prescaler, TSEG1 (propagation + phase 1), TSEG2, SJW.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BitTiming {
    pub prescaler: u16,
    pub seg1: u8,
    pub seg2: u8,
    pub sjw: u8,
}

impl BitTiming {
    /// Time quanta per bit.
    pub const fn quanta(&self) -> u32 {
        1 + self.seg1 as u32 + self.seg2 as u32
    }

    /// Sample point as a fraction of the bit.
    pub fn sample_point(&self) -> f32 {
        (1 + self.seg1 as u32) as f32 / self.quanta() as f32
    }

    /// Largest relative clock error between two nodes that still synchronises.
    pub fn tolerance(&self) -> f32 {
        let n = self.quanta() as f32;
        let (ps1, ps2, sjw) = (f32::from(self.seg1), f32::from(self.seg2), f32::from(self.sjw));
        let a = sjw / (20.0 * n);
        let b = ps1.min(ps2) / (2.0 * (13.0 * n - ps2));
        a.min(b)
    }
}

/// The timing with the most quanta a bit (8–25, FDCAN's TSEG2 ≤ 128) for an exact bit rate
/// from `kernel_hz`, sample point nearest 80 %, SJW = TSEG2. `None` when no prescaler
/// divides exactly.
pub fn nominal(kernel_hz: u32, bitrate: u32) -> Option<BitTiming> {
    if bitrate == 0 {
        return None;
    }
    (8u32..=25).rev().find_map(|n| {
        let per_bit = bitrate.checked_mul(n)?;
        if !kernel_hz.is_multiple_of(per_bit) {
            return None;
        }
        let prescaler = u16::try_from(kernel_hz / per_bit).ok().filter(|p| (1..=512).contains(p))?;
        // Sample point: (1 + seg1) / n ≈ 0.8.
        let seg1 = (4 * n).div_ceil(5) - 1;
        let seg2 = n - 1 - seg1;
        Some(BitTiming { prescaler, seg1: seg1 as u8, seg2: seg2 as u8, sjw: seg2 as u8 })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crystal_at_one_megabit() {
        let t = nominal(24_000_000, 1_000_000).expect("timing");
        assert_eq!(t.prescaler, 1);
        assert_eq!(t.quanta(), 24);
        assert!((0.75..=0.875).contains(&t.sample_point()), "{}", t.sample_point());
        assert!(t.tolerance() > 0.005, "{}", t.tolerance());
    }

    #[test]
    fn the_old_hsi_timing_was_below_the_hsi_tolerance() {
        let old = BitTiming { prescaler: 1, seg1: 7, seg2: 2, sjw: 1 };
        assert!(old.tolerance() < 0.01, "HSI is ±1 %: {}", old.tolerance());
        let new = nominal(24_000_000, 1_000_000).expect("timing");
        assert!(new.tolerance() > old.tolerance() && old.sjw < new.sjw);
    }

    #[test]
    fn every_timing_is_exact_and_in_range() {
        for (k, b) in [(24_000_000, 500_000), (85_000_000, 1_000_000), (16_000_000, 250_000)] {
            if let Some(t) = nominal(k, b) {
                assert_eq!(u32::from(t.prescaler) * t.quanta() * b, k);
                assert!(t.seg2 >= 1 && t.sjw <= t.seg2);
            }
        }
        assert!(nominal(1_000, 1_000_000).is_none());
    }
}
