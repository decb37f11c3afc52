//! f64 reference of the modified Bouc–Wen model with voltage dependence and η filter
//! (Spencer et al. 1997; seed 001 eq. 3–7, seed 002 eq. 1–7), written from the equations,
//! independently of model-core's discretisation. State `[y, z, u]`:
//!
//! ```text
//! ẏ = (α·z + c0·ẋ + k0·(x − y)) / (c0 + c1)                                (eq. 5)
//! ż = −γ·|ẋ − ẏ|·z·|z|ⁿ⁻¹ − β·(ẋ − ẏ)·|z|ⁿ + A·(ẋ − ẏ)                    (eq. 4)
//! u̇ = −η·(u − max(v, 0))                                                  (eq. 7)
//! α = αa + αb·u,  c1 = c1a + c1b·u,  c0 = c0a + c0b·u                       (eq. 6)
//! F = c1·ẏ + k1·(x − x0)                                                   (eq. 3)
//! ```
//!
//! The command `v` is the input's `u`; a negative command is 0 V (unipolar driver — the
//! same model definition as model-core's `spencer`). Initial state: `y = x`, `z = 0`,
//! `u = max(v, 0)` at the first instant (at rest, filter settled).

use crate::models::reference::{Case, Command, Input, InputScale, Reference};

/// The 14 parameters in model-core's `PARAM_NAMES` order:
/// c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, A, n, eta.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spencer {
    pub c0a: f64,
    pub c0b: f64,
    pub k0: f64,
    pub c1a: f64,
    pub c1b: f64,
    pub k1: f64,
    pub x0: f64,
    pub alpha_a: f64,
    pub alpha_b: f64,
    pub gamma: f64,
    pub beta: f64,
    pub a: f64,
    pub n: f64,
    pub eta: f64,
}

/// Spencer et al. (1997) for the prototype damper of `shared/data/dyke` (x in cm, F in N,
/// v in V): model-core's [`model_core::models::spencer::DYKE_1997_FLAT`] as published.
pub fn dyke_1997() -> Spencer {
    let [c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, a, n, eta] =
        model_core::models::spencer::DYKE_1997_FLAT.map(crate::models::search::published);
    Spencer { c0a, c0b, k0, c1a, c1b, k1, x0, alpha_a, alpha_b, gamma, beta, a, n, eta }
}

impl Spencer {
    /// Flat vector in model-core's parameter order.
    pub fn flat(&self) -> Vec<f32> {
        [
            self.c0a,
            self.c0b,
            self.k0,
            self.c1a,
            self.c1b,
            self.k1,
            self.x0,
            self.alpha_a,
            self.alpha_b,
            self.gamma,
            self.beta,
            self.a,
            self.n,
            self.eta,
        ]
        .iter()
        .map(|&v| v as f32)
        .collect()
    }

    /// `(α, c0, c1)` at filtered command `u` (eq. 6).
    fn coefficients(&self, u: f64) -> (f64, f64, f64) {
        (self.alpha_a + self.alpha_b * u, self.c0a + self.c0b * u, self.c1a + self.c1b * u)
    }

    /// ẏ of eq. 5.
    fn ydot(&self, y: f64, z: f64, u: f64, input: &Input) -> f64 {
        let (alpha, c0, c1) = self.coefficients(u);
        (alpha * z + c0 * input.dx + self.k0 * (input.x - y)) / (c0 + c1)
    }
}

impl Reference for Spencer {
    fn dim(&self) -> usize {
        3
    }

    fn init(&self, first: &Input) -> Vec<f64> {
        vec![first.x, 0.0, first.u.max(0.0)]
    }

    fn rhs(&self, s: &[f64], input: &Input, ds: &mut [f64]) {
        if let ([y, z, u], [dy, dz, du]) = (s, ds) {
            let yd = self.ydot(*y, *z, *u, input);
            let wd = input.dx - yd;
            let az = z.abs();
            *dy = yd;
            *dz = -self.gamma * wd.abs() * z * az.powf(self.n - 1.0) - self.beta * wd * az.powf(self.n) + self.a * wd;
            *du = -self.eta * (u - input.u.max(0.0));
        }
    }

    fn output(&self, s: &[f64], input: &Input) -> f64 {
        match s {
            [y, z, u] => {
                let (_, _, c1) = self.coefficients(*u);
                c1 * self.ydot(*y, *z, *u, input) + self.k1 * (input.x - self.x0)
            }
            _ => f64::NAN,
        }
    }
}

/// Spencer's published set at 0, 1 and 2.25 V (displacement ±1 cm), and on the Dyke
/// recording (its own command `Y`).
pub fn cases() -> Vec<Case> {
    [0.0, 1.0, 2.25]
        .iter()
        .enumerate()
        .map(|(i, &volt)| Case {
            model: <model_core::models::spencer::Registered as model_core::Model>::ID,
            label: format!("Spencer et al. 1997, Dyke damper (shared/data/dyke/README.md), x in cm, F in N, {volt} V"),
            params: dyke_1997().flat(),
            reference: Box::new(dyke_1997()),
            scale: InputScale { amplitude: 1.0, offset: 0.0 },
            command: Command::Constant(volt),
            // The recording carries its own command; checking it once is enough.
            on_dyke_recording: i == 0,
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use model_core::models::spencer::Spencer as Core;
    use model_core::{Kin, Model};

    /// `shared/data/dyke/ranran_50.csv`, found by walking up from the crate (the repository
    /// may be a worktree one level deeper than `/work/main`).
    pub(crate) fn dyke_csv() -> std::path::PathBuf {
        let mut dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        loop {
            let c = dir.join("shared/data/dyke/ranran_50.csv");
            if c.exists() {
                return c;
            }
            assert!(dir.pop(), "shared/data/dyke/ranran_50.csv not found above {}", env!("CARGO_MANIFEST_DIR"));
        }
    }

    /// `(D [cm], Y [V], fs [Hz])` of the first `secs` seconds of ranran_50.csv. Header
    /// `"t","A","D","Y","fs","V","F",`, trailing commas, `fs` on the first row only.
    pub(crate) fn read_dyke(secs: f64) -> (Vec<f64>, Vec<f64>, f64) {
        let text = std::fs::read_to_string(dyke_csv()).expect("read ranran_50.csv");
        let (mut d, mut y, mut fs) = (Vec::new(), Vec::new(), f64::NAN);
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            if f.len() < 7 || f[0].trim().is_empty() {
                continue;
            }
            let t: f64 = f[0].parse().expect("t");
            if let Ok(v) = f[4].parse::<f64>() {
                fs = v;
            }
            if t >= secs {
                break;
            }
            d.push(f[2].parse().expect("D"));
            y.push(f[3].parse().expect("Y"));
        }
        assert!(fs > 0.0 && d.len() > 100);
        (d, y, fs)
    }

    /// Fine fixed-step RK4 (`sub` steps per sample) of any reference driven by `inp(t)`;
    /// the output at sample i uses `inp(i·dt)` (with `out_dx[i]` for ẋ).
    pub(crate) fn integrate(
        r: &dyn Reference,
        dt: f64,
        n: usize,
        inp: &dyn Fn(f64) -> Input,
        out_dx: &[f64],
        sub: usize,
    ) -> Vec<f64> {
        let dim = r.dim();
        let mut s = r.init(&inp(0.0));
        let h = dt / sub as f64;
        let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; dim], vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]);
        let mut tmp = vec![0.0; dim];
        let mut out = Vec::with_capacity(n);
        for (i, &dx_i) in out_dx.iter().enumerate().take(n) {
            if i > 0 {
                for j in 0..sub {
                    let t = (i - 1) as f64 * dt + j as f64 * h;
                    r.rhs(&s, &inp(t), &mut k1);
                    for q in 0..dim {
                        tmp[q] = s[q] + 0.5 * h * k1[q];
                    }
                    r.rhs(&tmp, &inp(t + 0.5 * h), &mut k2);
                    for q in 0..dim {
                        tmp[q] = s[q] + 0.5 * h * k2[q];
                    }
                    r.rhs(&tmp, &inp(t + 0.5 * h), &mut k3);
                    for q in 0..dim {
                        tmp[q] = s[q] + h * k3[q];
                    }
                    r.rhs(&tmp, &inp(t + h), &mut k4);
                    for q in 0..dim {
                        s[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q]);
                    }
                }
            }
            let at = Input { dx: dx_i, ..inp(i as f64 * dt) };
            out.push(r.output(&s, &at));
        }
        out
    }

    /// Piecewise-linear input through samples (slope of the segment ending at a sample on
    /// the sample itself, i.e. the backward difference), command interpolated too.
    pub(crate) fn pwl<'a>(dt: f64, x: &'a [f64], u: &'a [f64]) -> impl Fn(f64) -> Input + 'a {
        move |t: f64| {
            let last = x.len() - 1;
            let k = ((t / dt).floor() as usize).min(last - 1);
            let tau = t - k as f64 * dt;
            let (k, tau) = if tau <= 1e-9 * dt && k > 0 { (k - 1, dt) } else { (k, tau) };
            let dx = (x[k + 1] - x[k]) / dt;
            Input { x: x[k] + dx * tau, dx, ddx: 0.0, u: u[k] + (u[k + 1] - u[k]) * tau / dt }
        }
    }

    /// The f32 core stepped once per sample.
    pub(crate) fn run_core<M: Model>(m: &M, x: &[f64], dx: &[f64], u: &[f64]) -> Vec<f64> {
        let first = Kin::new(x[0] as f32, dx[0] as f32, 0.0, u[0] as f32);
        let mut s = m.initial_state(&first);
        x.iter()
            .zip(dx)
            .zip(u)
            .map(|((&x, &dx), &u)| f64::from(m.step(&mut s, &Kin::new(x as f32, dx as f32, 0.0, u as f32))))
            .collect()
    }

    /// R-RMSE of the difference (seed 000 eq. 20): RMS(a − b) / RMS(b − mean b).
    pub(crate) fn r_rmse(a: &[f64], b: &[f64]) -> f64 {
        let n = b.len() as f64;
        let mean = b.iter().sum::<f64>() / n;
        let num: f64 = a.iter().zip(b).map(|(a, b)| (a - b) * (a - b)).sum();
        let den: f64 = b.iter().map(|b| (b - mean) * (b - mean)).sum();
        (num / den).sqrt()
    }

    /// The f32 core (one step per sample) against this reference (RK4, 200 sub-steps).
    #[test]
    fn core_matches_reference() {
        let r = dyke_1997();
        // (a) 9 Hz, 1 cm sine at 500 Hz and 3 kHz; the core gets exact x, ẋ per sample
        // (the harness's synthetic protocol) and, separately, a piecewise-linear input with
        // backward-difference rates.
        for &fs in &[500.0, 3000.0] {
            for &volt in &[0.0, 1.0, 2.25] {
                let dt = 1.0 / fs;
                let n = (1.5 * fs) as usize;
                let w = 2.0 * std::f64::consts::PI * 9.0;
                let sine = |t: f64| Input { x: (w * t).sin(), dx: w * (w * t).cos(), ddx: 0.0, u: volt };
                let x: Vec<f64> = (0..n).map(|i| sine(i as f64 * dt).x).collect();
                let dx: Vec<f64> = (0..n).map(|i| sine(i as f64 * dt).dx).collect();
                let u = vec![volt; n];
                let core = Core::from_params(&r.flat(), dt as f32).expect("published set");
                let e_exact = r_rmse(&run_core(&core, &x, &dx, &u), &integrate(&r, dt, n, &sine, &dx, 200));
                let bdx: Vec<f64> = (0..n).map(|i| if i == 0 { 0.0 } else { (x[i] - x[i - 1]) / dt }).collect();
                let e_pwl = r_rmse(&run_core(&core, &x, &bdx, &u), &integrate(&r, dt, n, &pwl(dt, &x, &u), &bdx, 200));
                println!(
                    "spencer 9 Hz 1 cm sine, {volt} V at {fs} Hz: R-RMSE {:.4} % (exact ẋ), {:.4} % (piecewise linear)",
                    100.0 * e_exact,
                    100.0 * e_pwl
                );
                assert!(e_exact <= 0.005 && e_pwl <= 0.005);
            }
        }
        // Multi-sine (seed 000 eq. 21: 11 components, 1–10 Hz, peak ≤ 1 cm) and swept sine
        // (eq. 22: 0.1 → 5 Hz over 10 s, 1 cm), exact x and ẋ per sample.
        let comps: Vec<(f64, f64, f64)> = (0..11)
            .map(|i| {
                let i = i as f64;
                (1.0 / (1.0 + 0.15 * i), 2.0 * std::f64::consts::PI * (1.0 + 0.9 * i), 0.7 * i * i)
            })
            .collect();
        let norm: f64 = comps.iter().map(|c| c.0).sum();
        let (f0, f1, tt) = (0.1, 5.0, 10.0);
        for &fs in &[500.0, 3000.0] {
            for &volt in &[0.0, 2.25] {
                let dt = 1.0 / fs;
                let core = Core::from_params(&r.flat(), dt as f32).expect("published set");
                let multi = |t: f64| {
                    let (x, dx) = comps.iter().fold((0.0, 0.0), |(x, dx), &(a, w, p)| {
                        (x + a / norm * (w * t + p).sin(), dx + a / norm * w * (w * t + p).cos())
                    });
                    Input { x, dx, ddx: 0.0, u: volt }
                };
                let swept = |t: f64| {
                    let ph = 2.0 * std::f64::consts::PI * (f0 * t + (f1 - f0) / (2.0 * tt) * t * t);
                    let w = 2.0 * std::f64::consts::PI * (f0 + (f1 - f0) / tt * t);
                    Input { x: ph.sin(), dx: w * ph.cos(), ddx: 0.0, u: volt }
                };
                for (name, secs, inp) in
                    [("multi-sine", 3.0, &multi as &dyn Fn(f64) -> Input), ("swept-sine", tt, &swept)]
                {
                    let n = (secs * fs) as usize;
                    let x: Vec<f64> = (0..n).map(|i| inp(i as f64 * dt).x).collect();
                    let dx: Vec<f64> = (0..n).map(|i| inp(i as f64 * dt).dx).collect();
                    let u = vec![volt; n];
                    let e = r_rmse(&run_core(&core, &x, &dx, &u), &integrate(&r, dt, n, inp, &dx, 100));
                    println!("spencer {name}, {volt} V at {fs} Hz: R-RMSE {:.4} %", 100.0 * e);
                    assert!(e <= 0.005, "{name} {volt} V {fs} Hz: {e}");
                }
            }
        }
        // (b) The first 5 s of ranran_50.csv at its native rate, command Y.
        let (x, u, fs) = read_dyke(5.0);
        let dt = 1.0 / fs;
        let n = x.len();
        let bdx: Vec<f64> = (0..n).map(|i| if i == 0 { 0.0 } else { (x[i] - x[i - 1]) / dt }).collect();
        let core = Core::from_params(&r.flat(), dt as f32).expect("published set");
        let out = run_core(&core, &x, &bdx, &u);
        let reference = integrate(&r, dt, n, &pwl(dt, &x, &u), &bdx, 200);
        let e = r_rmse(&out, &reference);
        let max = out.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let rms = (reference.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        println!(
            "spencer on ranran_50.csv (first 5 s, {n} samples at {fs} Hz, command Y): R-RMSE {:.4} %, max |diff| {max:.2} N (RMS force {rms:.0} N)",
            100.0 * e
        );
        assert!(e <= 0.005, "{e}");
    }
}
