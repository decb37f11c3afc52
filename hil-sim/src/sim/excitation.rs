//! The papers' excitation signals, with analytic first and second derivatives.
//! Each is a unit signal (range within −1…1) mapped onto a model input by the caller.

use std::f64::consts::PI;

/// Value, first and second time derivative at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point {
    pub x: f64,
    pub dx: f64,
    pub ddx: f64,
}

/// A continuous-time test signal.
#[derive(Clone, Debug, PartialEq)]
pub enum Excitation {
    /// `sin(2π f t)`, seed 000's fitting sines (1–9 Hz).
    Sine { f: f64 },
    /// Seed 000 eq. 21: `Σ aᵢ sin(ωᵢ t)`, 11 sines uniformly spread over 1–10 Hz with
    /// different magnitudes (normalised so `Σ|aᵢ| = 1`).
    MultiSine { f: Vec<f64>, a: Vec<f64> },
    /// Seed 000 eq. 22: `sin(2π(f0 t + (f1 − f0) t² / (2T)))`, here 0.1 → 5 Hz.
    SweptSine { f0: f64, f1: f64, duration: f64 },
    /// Seed 004's triangle, period `1/f`, peak 1.
    Triangle { f: f64 },
}

impl Excitation {
    /// Seed 000 eq. 21 with fixed, reproducible magnitudes: frequencies 1, 1.9, …, 10 Hz,
    /// magnitudes decreasing roughly as 1/f with a deterministic spread.
    pub fn seed000_multisine() -> Self {
        let n = 11;
        let f: Vec<f64> = (0..n).map(|i| 1.0 + 9.0 * i as f64 / (n - 1) as f64).collect();
        let raw: Vec<f64> = f.iter().enumerate().map(|(i, fi)| (1.0 + 0.35 * ((i * 7 % 5) as f64)) / fi).collect();
        let s: f64 = raw.iter().sum();
        Self::MultiSine { f, a: raw.iter().map(|v| v / s).collect() }
    }

    /// Seed 000 eq. 22: 0.1 → 5 Hz over `duration` seconds.
    pub fn seed000_swept(duration: f64) -> Self {
        Self::SweptSine { f0: 0.1, f1: 5.0, duration }
    }

    /// Short, stable name for tables and file names.
    pub fn name(&self) -> String {
        match self {
            Self::Sine { f } => format!("sine {f} Hz"),
            Self::MultiSine { .. } => "multi-sine (eq. 21)".into(),
            Self::SweptSine { f0, f1, .. } => format!("swept-sine {f0}-{f1} Hz (eq. 22)"),
            Self::Triangle { f } => format!("triangle {f} Hz"),
        }
    }

    /// Value and derivatives at time `t` seconds.
    pub fn at(&self, t: f64) -> Point {
        match self {
            Self::Sine { f } => {
                let w = 2.0 * PI * f;
                Point { x: (w * t).sin(), dx: w * (w * t).cos(), ddx: -w * w * (w * t).sin() }
            }
            Self::MultiSine { f, a } => {
                let mut p = Point::default();
                for (fi, ai) in f.iter().zip(a) {
                    let w = 2.0 * PI * fi;
                    p.x += ai * (w * t).sin();
                    p.dx += ai * w * (w * t).cos();
                    p.ddx -= ai * w * w * (w * t).sin();
                }
                p
            }
            Self::SweptSine { f0, f1, duration } => {
                let k = (f1 - f0) / (2.0 * duration);
                let phase = 2.0 * PI * (f0 * t + k * t * t);
                let dphase = 2.0 * PI * (f0 + 2.0 * k * t);
                let ddphase = 2.0 * PI * 2.0 * k;
                Point {
                    x: phase.sin(),
                    dx: dphase * phase.cos(),
                    ddx: ddphase * phase.cos() - dphase * dphase * phase.sin(),
                }
            }
            Self::Triangle { f } => {
                let ph = (t * f).rem_euclid(1.0);
                // Starts at 0 rising: 0 → 1 → −1 → 0.
                let (x, s) = if ph < 0.25 {
                    (4.0 * ph, 1.0)
                } else if ph < 0.75 {
                    (2.0 - 4.0 * ph, -1.0)
                } else {
                    (4.0 * ph - 4.0, 1.0)
                };
                Point { x, dx: 4.0 * f * s, ddx: 0.0 }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let h = 1e-6;
        for e in [Excitation::Sine { f: 3.0 }, Excitation::seed000_multisine(), Excitation::seed000_swept(40.0)] {
            for &t in &[0.1, 1.3, 7.77, 33.3] {
                let (a, b, c) = (e.at(t - h), e.at(t), e.at(t + h));
                let dx = (c.x - a.x) / (2.0 * h);
                let ddx = (c.x - 2.0 * b.x + a.x) / (h * h);
                assert!((dx - b.dx).abs() < 1e-4 * (1.0 + b.dx.abs()), "{} dx at {t}", e.name());
                assert!((ddx - b.ddx).abs() < 1e-2 * (1.0 + b.ddx.abs()), "{} ddx at {t}", e.name());
            }
        }
    }

    #[test]
    fn unit_range_and_multisine_spec() {
        let Excitation::MultiSine { f, a } = Excitation::seed000_multisine() else { unreachable!() };
        assert_eq!(f.len(), 11);
        assert!(f.iter().all(|v| (1.0..=10.0).contains(v)));
        assert!((a.iter().map(|v| v.abs()).sum::<f64>() - 1.0).abs() < 1e-12);
        let e = Excitation::seed000_multisine();
        assert!((0..10_000).all(|i| e.at(i as f64 * 1e-3).x.abs() <= 1.0 + 1e-12));
        let tri = Excitation::Triangle { f: 0.5 };
        assert!((tri.at(0.5).x - 1.0).abs() < 1e-12 && (tri.at(1.5).x + 1.0).abs() < 1e-12);
    }
}
