//! Magnetic circuit: hysteretic B(i) and the eddy-current lag of the field.
//!
//! Hysteresis is a Preisach-type operator, a weighted sum of play operators on the coil
//! current (Prandtl–Ishlinskii, seed 004 eq. 10–15), shaped by the saturation of the
//! steel: `p = Σ wⱼ·Γ_{rⱼ}[i]` (Σwⱼ = 1), `B_core = B_sat·tanh(p / i_sat)`. Radii
//! `rⱼ = (j+1)·r_max/n`, weights `wⱼ ∝ exp(−rⱼ/r_w)`, so the coercive current is about
//! `Σ wⱼ rⱼ` (≈ 0.12 A by default: a soft-steel yoke, remanent torque ≈ 5 % of full scale,
//! the order seen in seed 000 Fig. 3).
//!
//! Eddy currents in the solid discs and housing delay the field where the fluid is:
//! `τ_e·dB_f/dt = B_core − B_f` (first order, τ_e = 3 ms; the `field_lag` effect of the
//! project's physics catalogue, a few ms for solid-steel clutches). The Hall sensor sits in
//! the stator near the coil and sees a shorter lag, `τ_h·dB_h/dt = B_core − B_h` (τ_h = 0.3
//! ms), so torque lags the Hall reading as in seed 000 (its fitted `c` of eq. 14 is < 0).

use serde::{Deserialize, Serialize};

/// Magnetic circuit parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MagneticParams {
    /// Saturation flux density in the gap, T.
    pub b_sat: f64,
    /// Current scale of the saturation, A.
    pub i_sat: f64,
    /// Hysteresis on/off, number of play operators, largest radius (A), weight decay (A).
    pub hysteresis: bool,
    pub n_play: usize,
    pub r_max: f64,
    pub r_w: f64,
    /// Eddy-current lag of the fluid field, s (0 = none), and of the Hall location, s.
    pub eddy_tau: f64,
    pub hall_tau: f64,
}

impl Default for MagneticParams {
    fn default() -> Self {
        Self {
            b_sat: 0.9,
            i_sat: 4.0,
            hysteresis: true,
            n_play: 8,
            r_max: 0.4,
            r_w: 0.15,
            eddy_tau: 3e-3,
            hall_tau: 0.3e-3,
        }
    }
}

/// State of the magnetic circuit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Magnetic {
    pub plays: Vec<f64>,
    pub b_core: f64,
    pub b_fluid: f64,
    pub b_hall: f64,
}

impl Magnetic {
    /// Demagnetised (virgin) state.
    pub fn new(p: &MagneticParams) -> Self {
        Self { plays: vec![0.0; p.n_play], ..Default::default() }
    }

    fn weights(p: &MagneticParams) -> impl Iterator<Item = (f64, f64)> + '_ {
        let n = p.n_play.max(1);
        let radius = move |j: usize| (j + 1) as f64 * p.r_max / n as f64;
        let total: f64 = (0..n).map(|j| (-radius(j) / p.r_w).exp()).sum();
        (0..n).map(move |j| (radius(j), (-radius(j) / p.r_w).exp() / total))
    }

    /// Static `B_core` for current `i`, updating the operator states.
    pub fn core(&mut self, p: &MagneticParams, i: f64) -> f64 {
        let x = if p.hysteresis {
            let mut sum = 0.0;
            for (z, (r, w)) in self.plays.iter_mut().zip(Self::weights(p)) {
                *z = (i - r).max((i + r).min(*z));
                sum += w * *z;
            }
            sum
        } else {
            i
        };
        p.b_sat * (x / p.i_sat).tanh()
    }

    /// Advance `h` seconds with coil current `i`.
    pub fn step(&mut self, p: &MagneticParams, i: f64, h: f64) {
        self.b_core = self.core(p, i);
        let lag =
            |b: f64, tau: f64| if tau > 0.0 { self.b_core + (b - self.b_core) * (-h / tau).exp() } else { self.b_core };
        self.b_fluid = lag(self.b_fluid, p.eddy_tau);
        self.b_hall = lag(self.b_hall, p.hall_tau);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hysteresis_leaves_remanence_and_lags_follow() {
        let p = MagneticParams::default();
        let mut m = Magnetic::new(&p);
        let up = m.core(&p, 1.5);
        m.core(&p, 3.0);
        let down = m.core(&p, 1.5);
        assert!(down > up + 0.01, "descending branch above ascending: {down} vs {up}");
        let rem = m.core(&p, 0.0);
        assert!(rem > 0.01 && rem < 0.1, "remanence {rem} T");
        let off = MagneticParams { hysteresis: false, ..p.clone() };
        assert_eq!(Magnetic::new(&off).core(&off, 0.0), 0.0);
        // First-order lag: after τ_e the fluid field is 63 % of a step.
        let mut m = Magnetic::new(&p);
        let h = 1e-6;
        for _ in 0..(p.eddy_tau / h) as usize {
            m.step(&p, 2.0, h);
        }
        let frac = m.b_fluid / m.b_core;
        assert!((frac - 0.632).abs() < 0.01, "{frac}");
        assert!(m.b_hall > 0.99 * m.b_core);
    }
}
