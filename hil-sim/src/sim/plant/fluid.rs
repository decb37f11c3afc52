//! MR-fluid torque of a disc clutch: field-dependent yield (Bingham) plus viscous slip.
//!
//! For `n` sheared surfaces between radii `r_i` and `r_o` with gap `h` (Bingham plastic,
//! e.g. Carlson & Jolly 2000):
//! `T = sign(ω)·(G_y·τ_y(B_f, θ) + T_seal) + G_v·η(θ)·ω/h`,
//! `G_y = n·2π/3·(r_o³ − r_i³)`, `G_v = n·π/2·(r_o⁴ − r_i⁴)`,
//! `τ_y(B, θ) = τ_sat·tanh(|B|/B_τ)·(1 − k_y·(θ − 20 °C))`,
//! `η(θ) = η₄₀·exp(−k_η·(θ − 40 °C))`.
//!
//! Numbers for an MRF-140CG-class fluid (LORD product bulletin: plastic viscosity
//! 0.28 Pa·s at 40 °C, yield stress ≈ 60 kPa near saturation); τ_y falls ≈ 0.3 %/K
//! and the carrier's viscosity ≈ 2.5 %/K with temperature (orders reported for
//! hydrocarbon-based MR fluids). Geometry (r_i = 25 mm, r_o = 45 mm, 2 surfaces,
//! 0.5 mm gap) gives ≈ 0.8–15 N·m for 0–3 A, the range of seed 000's clutch (its
//! algebraic model, Table 6, gives T₀ ≈ 0.8 N·m and ≈ 4.6 N·m per unit B).
//! `sign(ω)` is smoothed as `tanh(ω/0.5 rad/s)`.

use serde::{Deserialize, Serialize};

/// Fluid and geometry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FluidParams {
    pub tau_sat: f64,
    pub b_tau: f64,
    pub k_yield: f64,
    pub eta40: f64,
    pub k_eta: f64,
    pub r_in: f64,
    pub r_out: f64,
    pub surfaces: f64,
    pub gap: f64,
    /// Seal and bearing drag, N·m.
    pub seal_torque: f64,
    /// Temperature effects on/off.
    pub thermal_effects: bool,
}

impl Default for FluidParams {
    fn default() -> Self {
        Self {
            tau_sat: 60e3,
            b_tau: 0.55,
            k_yield: 0.003,
            eta40: 0.28,
            k_eta: 0.025,
            r_in: 0.025,
            r_out: 0.045,
            surfaces: 2.0,
            gap: 0.5e-3,
            seal_torque: 0.3,
            thermal_effects: true,
        }
    }
}

impl FluidParams {
    /// Transmitted torque, N·m, for fluid field `b` (T), slip `omega` (rad/s), temperature `theta` (°C).
    pub fn torque(&self, b: f64, omega: f64, theta: f64) -> f64 {
        let pi = std::f64::consts::PI;
        let gy = self.surfaces * 2.0 * pi / 3.0 * (self.r_out.powi(3) - self.r_in.powi(3));
        let gv = self.surfaces * pi / 2.0 * (self.r_out.powi(4) - self.r_in.powi(4));
        let dtheta = if self.thermal_effects { theta } else { 20.0 };
        let yield_scale = (1.0 - self.k_yield * (dtheta - 20.0)).max(0.0);
        let tau = self.tau_sat * (b.abs() / self.b_tau).tanh() * yield_scale;
        let eta = self.eta40 * (-self.k_eta * (dtheta.max(-40.0) - 40.0)).exp();
        (omega / 0.5).tanh() * (gy * tau + self.seal_torque) + gv * eta * omega / self.gap
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_and_temperature_trend() {
        let f = FluidParams::default();
        let t0 = f.torque(0.0, 30.0, 20.0);
        let t_max = f.torque(0.57, 30.0, 20.0);
        assert!((0.4..1.5).contains(&t0), "{t0}");
        assert!((12.0..16.0).contains(&t_max), "{t_max}");
        assert!(f.torque(0.4, 30.0, 60.0) < f.torque(0.4, 30.0, 20.0));
        assert!(f.torque(0.4, 0.0, 20.0).abs() < 1e-12);
    }
}
