//! One-node thermal model of fluid, discs and coil: `C·dθ/dt = T·ω + i²R − (θ − θ_amb)/R_th`.
//!
//! C = 400 J/K (≈ 0.9 kg of steel and fluid), R_th = 0.8 K/W (natural convection from a
//! ≈ 0.1 m² housing at ≈ 12 W/(m²K)): time constant ≈ 5 min, and 100 W of slip power
//! heats the fluid by ≈ 15 K per minute.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ThermalParams {
    pub enabled: bool,
    pub capacity: f64,
    pub r_th: f64,
}

impl Default for ThermalParams {
    fn default() -> Self {
        Self { enabled: true, capacity: 400.0, r_th: 0.8 }
    }
}

impl ThermalParams {
    /// Temperature after `h` s with heat input `power` (W) at ambient `ambient` (°C).
    pub fn step(&self, theta: f64, power: f64, ambient: f64, h: f64) -> f64 {
        if !self.enabled {
            return theta;
        }
        theta + h * (power - (theta - ambient) / self.r_th) / self.capacity
    }
}
