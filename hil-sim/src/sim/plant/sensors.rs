//! Sensors: Hall probe and coil-current shunt on 12-bit ADCs, temperature probe, load cell.
//!
//! ADC: `counts = clamp(round(offset + gain·(1 + ε)·x + n), 0, 4095)`, n ~ N(0, σ²).
//! Hall: ±1.25 T full scale (a TLE4990-class linear Hall IC, seed 000), gain error ε = 1 %,
//! offset 12 counts, σ = 1.2 counts. Current shunt amplifier: ±6 A full scale, offset 5
//! counts, σ = 1 count. Load cell (seed 000's SBO-500 through its amplifier): noise
//! 0.02 N·m, first-order low-pass at 200 Hz (the lab's anti-alias filter). Temperature
//! probe: σ = 0.1 K.

use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorParams {
    pub noise: bool,
    pub hall_full_scale_t: f64,
    pub hall_gain_error: f64,
    pub hall_offset_counts: f64,
    pub hall_noise_counts: f64,
    pub current_full_scale_a: f64,
    pub current_offset_counts: f64,
    pub current_noise_counts: f64,
    pub load_noise_nm: f64,
    pub load_cutoff_hz: f64,
    pub temp_noise_k: f64,
}

impl Default for SensorParams {
    fn default() -> Self {
        Self {
            noise: true,
            hall_full_scale_t: 1.25,
            hall_gain_error: 0.01,
            hall_offset_counts: 12.0,
            hall_noise_counts: 1.2,
            current_full_scale_a: 6.0,
            current_offset_counts: 5.0,
            current_noise_counts: 1.0,
            load_noise_nm: 0.02,
            load_cutoff_hz: 200.0,
            temp_noise_k: 0.1,
        }
    }
}

/// Injected Hall faults.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum HallFault {
    #[default]
    None,
    /// Open wire: output pulled to the upper rail.
    Open,
    /// Output shorted to ground.
    Short,
    /// Output frozen at `counts`.
    Stuck(u16),
    /// Extra Gaussian noise of σ counts.
    Noise(f64),
}

/// Noise source with a fixed seed.
pub struct Noise {
    rng: StdRng,
    unit: Normal<f64>,
}

impl Noise {
    pub fn new(seed: u64) -> Self {
        use rand::SeedableRng;
        Self { rng: StdRng::seed_from_u64(seed), unit: Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!()) }
    }
    /// A N(0, σ²) sample.
    pub fn gauss(&mut self, sigma: f64) -> f64 {
        if sigma > 0.0 {
            sigma * self.unit.sample(&mut self.rng)
        } else {
            0.0
        }
    }
}

/// A 12-bit conversion.
pub fn adc(value: f64) -> u16 {
    value.round().clamp(0.0, 4095.0) as u16
}

impl SensorParams {
    /// Counts per tesla of the nominal Hall channel.
    pub fn hall_counts_per_t(&self) -> f64 {
        2048.0 / self.hall_full_scale_t
    }
    pub fn current_counts_per_a(&self) -> f64 {
        2048.0 / self.current_full_scale_a
    }
    fn sigma(&self, s: f64) -> f64 {
        if self.noise {
            s
        } else {
            0.0
        }
    }
    /// Hall ADC counts for flux density `b` (T).
    pub fn hall(&self, b: f64, fault: HallFault, n: &mut Noise) -> u16 {
        let clean = 2048.0 + self.hall_offset_counts + self.hall_counts_per_t() * (1.0 + self.hall_gain_error) * b;
        match fault {
            HallFault::None => adc(clean + n.gauss(self.sigma(self.hall_noise_counts))),
            HallFault::Open => 4095,
            HallFault::Short => 0,
            HallFault::Stuck(c) => c,
            HallFault::Noise(s) => adc(clean + n.gauss(self.sigma(self.hall_noise_counts)) + n.gauss(s)),
        }
    }
    /// Current-sense ADC counts for `i` (A).
    pub fn current(&self, i: f64, n: &mut Noise) -> u16 {
        adc(2048.0
            + self.current_offset_counts
            + self.current_counts_per_a() * i
            + n.gauss(self.sigma(self.current_noise_counts)))
    }
    /// Temperature probe reading, °C.
    pub fn temperature(&self, theta: f64, n: &mut Noise) -> f64 {
        theta + n.gauss(self.sigma(self.temp_noise_k))
    }
    /// Load-cell reading: filter state `y` advanced by `h` s towards `torque` + noise.
    pub fn load_cell(&self, y: f64, torque: f64, h: f64, n: &mut Noise) -> f64 {
        let a = (-2.0 * std::f64::consts::PI * self.load_cutoff_hz * h).exp();
        a * y + (1.0 - a) * (torque + n.gauss(self.sigma(self.load_noise_nm)))
    }
}
