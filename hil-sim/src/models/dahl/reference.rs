//! f64 reference of the modified Dahl model (Zhou & Qu; seed 001 eq. 8–11), written from
//! the equations, independently of model-core's discretisation. State `[z, u]`:
//!
//! ```text
//! ż = σ·ẋ·(1 − z·sgn(ẋ))                  (eq. 9)
//! u̇ = −η·(u − max(V, 0))                  (eq. 11)
//! C0 = C0s + C0d·u,  Fd = Fds + Fdu·u      (eq. 10)
//! F = K0·x + C0·ẋ + Fd·z − f0             (eq. 8)
//! ```
//!
//! A negative command is 0 V (unipolar driver, as in model-core's `dahl`). Initial state:
//! `z = 0`, `u = max(V, 0)` at the first instant.

use crate::models::reference::{Case, Command, Input, InputScale, Reference};

/// The 8 parameters in model-core's order: C0s, C0d, Fds, Fdu, K0, sigma, f0, eta.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dahl {
    pub c0s: f64,
    pub c0d: f64,
    pub fds: f64,
    pub fdu: f64,
    pub k0: f64,
    pub sigma: f64,
    pub f0: f64,
    pub eta: f64,
}

/// Seed 001 publishes no values for the modified Dahl model (only its error norms). This is
/// a plausible set for the Dyke damper in cm and N, matched to the force levels of
/// Spencer's 1997 set for the same damper (yield ≈ 85 N at 0 V, ≈ 985 N at 2.25 V, post-yield
/// slope ≈ 20 N·s/cm, accumulator 5 N/cm with 71.5 N offset), pre-yield stroke ≈ 0.2 cm
/// (σ = 15 /cm) and Spencer's η = 190 /s. Same values as model-core's
/// `dahl::DYKE_PLAUSIBLE`.
pub const DYKE_PLAUSIBLE: Dahl =
    Dahl { c0s: 20.0, c0d: 3.0, fds: 85.0, fdu: 400.0, k0: 5.0, sigma: 15.0, f0: 71.5, eta: 190.0 };

impl Dahl {
    /// Flat vector in model-core's parameter order.
    pub fn flat(&self) -> Vec<f32> {
        [self.c0s, self.c0d, self.fds, self.fdu, self.k0, self.sigma, self.f0, self.eta]
            .iter()
            .map(|&v| v as f32)
            .collect()
    }
}

fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl Reference for Dahl {
    fn dim(&self) -> usize {
        2
    }

    fn init(&self, first: &Input) -> Vec<f64> {
        vec![0.0, first.u.max(0.0)]
    }

    fn rhs(&self, s: &[f64], input: &Input, ds: &mut [f64]) {
        if let ([z, u], [dz, du]) = (s, ds) {
            *dz = self.sigma * input.dx * (1.0 - z * sgn(input.dx));
            *du = -self.eta * (u - input.u.max(0.0));
        }
    }

    fn output(&self, s: &[f64], input: &Input) -> f64 {
        match s {
            [z, u] => {
                let c0 = self.c0s + self.c0d * u;
                let fd = self.fds + self.fdu * u;
                self.k0 * input.x + c0 * input.dx + fd * z - self.f0
            }
            _ => f64::NAN,
        }
    }
}

/// The plausible Dyke-damper set at 0, 1 and 2.25 V (displacement ±1 cm), and on the Dyke
/// recording (its own command `Y`).
pub fn cases() -> Vec<Case> {
    [0.0, 1.0, 2.25]
        .iter()
        .enumerate()
        .map(|(i, &volt)| Case {
            model: <model_core::models::dahl::Registered as model_core::Model>::ID,
            label: format!(
                "plausible Dyke-damper set (not published; see hil-sim reference/dahl.rs), x in cm, F in N, {volt} V"
            ),
            params: DYKE_PLAUSIBLE.flat(),
            reference: Box::new(DYKE_PLAUSIBLE),
            scale: InputScale { amplitude: 1.0, offset: 0.0 },
            command: Command::Constant(volt),
            on_dyke_recording: i == 0,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::spencer::reference::tests::{integrate, pwl, r_rmse, read_dyke, run_core};
    use model_core::models::dahl::Dahl as Core;
    use model_core::Model;

    #[test]
    fn core_matches_reference() {
        let r = DYKE_PLAUSIBLE;
        for &fs in &[500.0, 3000.0] {
            let dt = 1.0 / fs;
            let n = (1.5 * fs) as usize;
            let w = 2.0 * std::f64::consts::PI * 9.0;
            let sine = |t: f64| Input { x: (w * t).sin(), dx: w * (w * t).cos(), ddx: 0.0, u: 2.25 };
            let x: Vec<f64> = (0..n).map(|i| sine(i as f64 * dt).x).collect();
            let dx: Vec<f64> = (0..n).map(|i| sine(i as f64 * dt).dx).collect();
            let u = vec![2.25; n];
            let core = Core::from_params(&r.flat(), dt as f32).expect("set");
            let e = r_rmse(&run_core(&core, &x, &dx, &u), &integrate(&r, dt, n, &sine, &dx, 200));
            println!("dahl 9 Hz 1 cm sine, 2.25 V at {fs} Hz: R-RMSE {:.4} %", 100.0 * e);
            assert!(e <= 0.005);
        }
        let (x, u, fs) = read_dyke(5.0);
        let dt = 1.0 / fs;
        let n = x.len();
        let bdx: Vec<f64> = (0..n).map(|i| if i == 0 { 0.0 } else { (x[i] - x[i - 1]) / dt }).collect();
        let core = Core::from_params(&r.flat(), dt as f32).expect("set");
        let e = r_rmse(&run_core(&core, &x, &bdx, &u), &integrate(&r, dt, n, &pwl(dt, &x, &u), &bdx, 200));
        println!("dahl on ranran_50.csv (first 5 s, command Y): R-RMSE {:.4} %", 100.0 * e);
        assert!(e <= 0.005);
    }
}
