//! Coil electrics behind a bipolar H-bridge: `L·di/dt = v − R(θ)·i`, `R(θ) = R₂₀·(1 + α_Cu·(θ − 20 °C))`.
//!
//! PWM is simulated switch by switch: in each sub-step the bridge applies `sign(d)·V_s`
//! for the part of the sub-step inside the centred on-window of width `|d|·T_pwm` and 0
//! (slow decay through the low-side switches) outside it; the RL equation is solved
//! exactly over the sub-step for that average voltage. With the bridge disabled all
//! switches are off and the current decays through the body diodes against the supply
//! (`v = −sign(i)·(V_s + 2·V_d)`, fast decay) until it reaches zero.
//!
//! Numbers: R₂₀ = 4 Ω, L = 20 mH (τ = 5 ms) — a coil that needs 12 V for 3 A from a 24 V
//! bridge, the size of the coils of Shafer & Kermani's MR clutch (seed 000 ref. 20); α_Cu =
//! 0.00393 /K (copper); V_d = 0.7 V.

use serde::{Deserialize, Serialize};

/// Coil and bridge parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CoilParams {
    /// Resistance at 20 °C, Ω.
    pub r20: f64,
    /// Inductance, H.
    pub l: f64,
    /// Copper temperature coefficient, 1/K.
    pub alpha_cu: f64,
    /// Bridge supply, V.
    pub supply_v: f64,
    /// PWM frequency, Hz.
    pub pwm_hz: f64,
    /// Body diode drop, V.
    pub diode_v: f64,
    /// Resistance and inductance of a short across the coil terminals (fault), Ω and H.
    pub short_r: f64,
    pub short_l: f64,
}

impl Default for CoilParams {
    fn default() -> Self {
        Self {
            r20: 4.0,
            l: 0.02,
            alpha_cu: 0.00393,
            supply_v: 24.0,
            pwm_hz: 20_000.0,
            diode_v: 0.7,
            short_r: 0.1,
            short_l: 20e-6,
        }
    }
}

/// Electrical faults of the coil circuit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CoilFault {
    #[default]
    None,
    /// Broken wire: no current can flow.
    Open,
    /// Terminals shorted: the bridge drives the short, the coil freewheels through it.
    Short,
}

/// Bridge drive during one sub-step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Duty in [−1, 1].
    pub duty: f64,
    /// False: all switches off.
    pub enabled: bool,
    /// Supply voltage, V.
    pub supply_v: f64,
}

/// Exact solution of `L·di/dt = v − R·i` over `h` seconds.
fn rl(i: f64, v: f64, r: f64, l: f64, h: f64) -> f64 {
    let inf = v / r;
    inf + (i - inf) * (-h * r / l).exp()
}

/// Current decaying through the diodes against `v_clamp` (> 0) over `h`, stopping at 0.
fn diode_decay(i: f64, v_clamp: f64, r: f64, l: f64, h: f64) -> f64 {
    if i == 0.0 {
        return 0.0;
    }
    let s = i.signum();
    let next = rl(i.abs(), -v_clamp, r, l, h);
    if next <= 0.0 {
        0.0
    } else {
        s * next
    }
}

/// Coil state: coil current and, with a short, the bridge current through the short.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Coil {
    pub i: f64,
    pub i_bridge: f64,
}

impl Coil {
    /// Fraction of `[φ0, φ1]` (PWM phase, periods) inside the centred on-window of width `d`.
    pub fn on_fraction(phi0: f64, phi1: f64, d: f64) -> f64 {
        let (a, b) = (0.5 - 0.5 * d, 0.5 + 0.5 * d);
        let overlap = (phi1.min(b) - phi0.max(a)).max(0.0);
        if phi1 > phi0 {
            overlap / (phi1 - phi0)
        } else {
            0.0
        }
    }

    /// Advance `h` seconds from PWM phase `phi0` (periods within the current period).
    pub fn step(&mut self, p: &CoilParams, fault: CoilFault, drive: Drive, theta: f64, phi0: f64, h: f64) {
        let r = p.r20 * (1.0 + p.alpha_cu * (theta - 20.0));
        let phi1 = phi0 + h * p.pwm_hz;
        let d = drive.duty.clamp(-1.0, 1.0);
        let v_avg = d.signum() * drive.supply_v * Self::on_fraction(phi0, phi1, d.abs());
        let clamp_v = drive.supply_v.max(0.0) + 2.0 * p.diode_v;
        match fault {
            CoilFault::Open => {
                self.i = 0.0;
                self.i_bridge = 0.0;
            }
            CoilFault::None => {
                self.i =
                    if drive.enabled { rl(self.i, v_avg, r, p.l, h) } else { diode_decay(self.i, clamp_v, r, p.l, h) };
                self.i_bridge = self.i;
            }
            CoilFault::Short => {
                self.i = rl(self.i, 0.0, r, p.l, h);
                self.i_bridge = if drive.enabled {
                    rl(self.i_bridge, v_avg, p.short_r, p.short_l, h)
                } else {
                    diode_decay(self.i_bridge, clamp_v, p.short_r, p.short_l, h)
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pwm_average_reaches_v_over_r_and_diodes_de_energise() {
        let p = CoilParams::default();
        let mut c = Coil::default();
        let subs = 16;
        let h = 1.0 / (p.pwm_hz * subs as f64);
        for k in 0..(0.05 / h) as usize {
            let phi = (k % subs) as f64 / subs as f64;
            c.step(&p, CoilFault::None, Drive { duty: 0.5, enabled: true, supply_v: 24.0 }, 20.0, phi, h);
        }
        assert!((c.i - 3.0).abs() < 0.02, "{}", c.i);
        let mut t = 0.0;
        while c.i > 0.0 && t < 0.1 {
            c.step(&p, CoilFault::None, Drive { duty: 0.5, enabled: false, supply_v: 24.0 }, 20.0, 0.0, h);
            t += h;
        }
        // Fast decay: (L/R)·ln(1 + R·i0/V) = 5 ms·ln(1 + 12/25.4) ≈ 1.93 ms from 3 A.
        assert!(c.i == 0.0 && (1.8e-3..2.1e-3).contains(&t), "{} A after {t} s", c.i);
        assert!((Coil::on_fraction(0.0, 1.0, 0.3) - 0.3).abs() < 1e-12);
        assert_eq!(Coil::on_fraction(0.0, 0.25, 0.3), 0.0);
    }
}
