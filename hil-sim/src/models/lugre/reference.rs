//! f64 reference of the LuGre model for the MR clutch, written from seed 000 eq. 7–8 (not
//! from model-core):
//!
//! `T = (β/α)·z + c·Ḃ + k·B + (ε/α)·ż + T₀`,  `ż = α·Ḃ − α·|Ḃ|·z`.
//!
//! Parameter vector order as model-core's `lugre`: `alpha, beta, epsilon, c, k, t0`.
//! Cases: seed 000 Table 4, the five per-frequency sets and the average, with B mapped to
//! 0…3 (amplitude 1.5, offset 1.5).

use crate::models::reference::{Case, Command, Input, InputScale, Reference};

/// Continuous-time LuGre in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuGreRef {
    pub alpha: f64,
    pub beta: f64,
    pub epsilon: f64,
    pub c: f64,
    pub k: f64,
    pub t0: f64,
}

impl LuGreRef {
    /// From a vector in `alpha, beta, epsilon, c, k, t0` order (missing entries 0).
    pub fn from_params(p: &[f32]) -> Self {
        let g = |i: usize| p.get(i).copied().map_or(0.0, f64::from);
        Self { alpha: g(0), beta: g(1), epsilon: g(2), c: g(3), k: g(4), t0: g(5) }
    }

    fn zdot(&self, z: f64, bd: f64) -> f64 {
        self.alpha * bd - self.alpha * bd.abs() * z
    }
}

impl Reference for LuGreRef {
    fn dim(&self) -> usize {
        1
    }

    fn init(&self, _first: &Input) -> Vec<f64> {
        vec![0.0]
    }

    fn rhs(&self, s: &[f64], input: &Input, ds: &mut [f64]) {
        let z = s.first().copied().unwrap_or(0.0);
        if let Some(d) = ds.first_mut() {
            *d = self.zdot(z, input.dx);
        }
    }

    fn output(&self, s: &[f64], input: &Input) -> f64 {
        let z = s.first().copied().unwrap_or(0.0);
        self.beta / self.alpha * z
            + self.c * input.dx
            + self.k * input.x
            + self.epsilon / self.alpha * self.zdot(z, input.dx)
            + self.t0
    }
}

/// Published parameter sets to check.
pub fn cases() -> Vec<Case> {
    // Table 4 columns: α, β, ε, c, k, T₀.
    let table4: [(&str, [f32; 6]); 6] = [
        ("1 Hz", [5.315, 6.251, 0.042, -0.443, 4.441, 5.508]),
        ("3 Hz", [3.590, 6.456, 0.017, -0.144, 4.947, 5.326]),
        ("5 Hz", [5.695, 5.831, 0.000, -0.105, 3.469, 5.146]),
        ("7 Hz", [3.062, 5.783, -0.030, -0.026, 4.859, 5.036]),
        ("9 Hz", [3.899, 4.534, -0.014, -0.038, 3.769, 5.110]),
        ("average", [4.312, 5.771, 0.003, -0.151, 4.297, 5.225]),
    ];
    table4
        .iter()
        .map(|(f, p)| Case {
            model: <model_core::models::lugre::Registered as model_core::Model>::ID,
            label: format!("seed 000 Table 4 {f}"),
            params: p.to_vec(),
            reference: Box::new(LuGreRef::from_params(p)),
            scale: InputScale { amplitude: 1.5, offset: 1.5 },
            command: Command::None,
            on_dyke_recording: false,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::bouc_wen::reference::check;
    use model_core::models::lugre::LuGre;
    use model_core::Model;

    #[test]
    fn cases_are_valid_model_parameters() {
        for c in cases() {
            assert_eq!(c.params.len(), LuGre::N_PARAMS);
            LuGre::from_params(&c.params, 1.0 / 500.0).unwrap();
        }
    }

    #[test]
    fn rhs_is_eq8() {
        let r = LuGreRef { alpha: 2.0, beta: 3.0, epsilon: 0.5, c: 0.1, k: 4.0, t0: 1.0 };
        let mut d = [0.0];
        let i = Input { x: 1.5, dx: -2.0, ddx: 0.0, u: 0.0 };
        r.rhs(&[0.25], &i, &mut d);
        assert!((d[0] - (2.0 * -2.0 - 2.0 * 2.0 * 0.25)).abs() < 1e-12);
        let want = 1.5 * 0.25 + 0.1 * -2.0 + 4.0 * 1.5 + 0.25 * d[0] + 1.0;
        assert!((r.output(&[0.25], &i) - want).abs() < 1e-12);
    }

    #[test]
    fn f32_core_within_half_percent() {
        let worst = check::worst::<LuGre>(&cases());
        assert!(worst <= 5e-3, "worst R-RMSE {worst}");
    }
}
