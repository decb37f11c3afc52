//! Identification of the operator models of seed 004 (eq. 5–25).
//!
//! - Prandtl–Ishlinskii and Maxwell-slip are linear in their weights once the radii
//!   (breakaway deflections) are fixed: the weights come from one sign-constrained least
//!   squares ([`crate::numerics::nnls`], seed 004's bounds `p₀, pᵢ, kᵢ ≥ 0`), for a few radius
//!   spreads; the best on the training rows wins ([`closed_form`]).
//! - Preisach and GPI are linear in their output scale and offset (`y₀, s`; `p₀, δ₁` and
//!   an envelope shift) but not in the density or envelope shape. [`Projected`] wraps the
//!   core so that the global search and Levenberg–Marquardt see only the shape: every run
//!   solves the linear part in closed form (variable projection), and
//!   [`Projected::complete`] writes it back into the flat vector.
//!
//! All columns are computed with the core's own f32 operators ([`play`]), so the
//! closed-form fit is the fit of the code that runs on the board.

use model_core::models::prandtl_ishlinskii::play;
use model_core::Kin;

use super::simulate::Simulator;
use crate::models::search::Structure;
use crate::numerics::nnls;

/// Smallest and largest input over the first `end` samples.
pub fn x_range(kin: &[Kin], end: usize) -> (f64, f64) {
    kin.iter()
        .take(end.max(1))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), k| (lo.min(f64::from(k.x)), hi.max(f64::from(k.x))))
}

/// Fractions of the half span that the largest radius takes in the closed-form search.
const SPREADS: [f64; 4] = [0.35, 0.6, 0.85, 1.0];

/// Mean squared residual of `Σ θⱼ·colⱼ` against `y` on `rows`.
fn cost(cols: &[Vec<f64>], theta: &[f64], y: &[f64], rows: &[usize]) -> f64 {
    let mut s = 0.0;
    let mut n = 0usize;
    for &i in rows {
        let Some(yi) = y.get(i) else { continue };
        let m: f64 = cols.iter().zip(theta).map(|(c, t)| c.get(i).copied().unwrap_or(0.0) * t).sum();
        s += (m - yi) * (m - yi);
        n += 1;
    }
    if n == 0 {
        f64::INFINITY
    } else {
        s / n as f64
    }
}

/// Output of one play operator of radius `r` from `m0` over `kin`, as the core runs it.
fn play_column(kin: &[Kin], r: f32, m0: f32) -> Vec<f64> {
    let mut z = kin.first().map_or(m0, |k| play(k.x, r, m0));
    kin.iter()
        .map(|k| {
            z = play(k.x, r, z);
            f64::from(z)
        })
        .collect()
}

/// Spring deflection of one elasto-slide element with limit `lim`, as the core runs it.
fn slip_column(kin: &[Kin], lim: f32) -> Vec<f64> {
    let mut prev = kin.first().map_or(0.0, |k| k.x);
    let mut d = 0.0f32;
    kin.iter()
        .map(|k| {
            let dx = k.x - prev;
            prev = k.x;
            d = model_core::math::clamp(d + dx, -lim, lim);
            f64::from(d)
        })
        .collect()
}

/// Closed-form fit of `prandtl_ishlinskii` (`N` = `n_ops`) or `maxwell_slip` on the
/// training rows: the flat parameter vector and its training cost (mean squared residual,
/// output units). `None` for another model or data the solver cannot use.
pub fn closed_form(
    structure: Structure,
    n_ops: usize,
    kin: &[Kin],
    y: &[f64],
    rows: &[usize],
) -> Option<(Vec<f64>, f64)> {
    let end = rows.last().map_or(0, |r| r + 1).min(kin.len());
    let kin = kin.get(..end)?;
    let (lo, hi) = x_range(kin, end);
    let span = (hi - lo).max(1e-12);
    let mut best: Option<(Vec<f64>, f64)> = None;
    let mut consider = |p: Vec<f64>, c: f64| {
        if c.is_finite() && best.as_ref().is_none_or(|b| c < b.1) {
            best = Some((p, c));
        }
    };
    match structure {
        Structure::PlayOperators if n_ops >= 2 => {
            // Operators 1…N−1 with radii up to the spread; operator N with a radius beyond
            // the input range never moves from M₀ and carries the output offset (its weight
            // times M₀), so M₀ takes the sign of the offset.
            let big = lo.abs().max(hi.abs()) + 2.0 * span + 1.0;
            let hyster = n_ops - 1;
            // p₀ ≥ ε keeps the analytical inverse (which needs p₀ > 0) available for
            // feed-forward: the fit runs on y − ε·x with p₀ − ε ≥ 0.
            let ys: Vec<f64> = rows.iter().filter_map(|&i| y.get(i).copied()).collect();
            let y_spread =
                ys.iter().fold(f64::NEG_INFINITY, |a, v| a.max(*v)) - ys.iter().fold(f64::INFINITY, |a, v| a.min(*v));
            let eps = 1e-3 * y_spread.max(1e-12) / span;
            let y_eps: Vec<f64> = y
                .iter()
                .zip(kin.iter().chain(std::iter::repeat(&Kin::default())))
                .map(|(v, k)| v - eps * f64::from(k.x))
                .collect();
            for spread in SPREADS {
                let radii: Vec<f64> = (1..=hyster).map(|i| spread * 0.5 * span * i as f64 / hyster as f64).collect();
                for m0 in [big, -big] {
                    let mut cols = vec![kin.iter().map(|k| f64::from(k.x)).collect::<Vec<f64>>()];
                    for r in &radii {
                        cols.push(play_column(kin, *r as f32, m0 as f32));
                    }
                    cols.push(play_column(kin, (3.0 * big) as f32, m0 as f32));
                    let (g, b) = nnls::normal_equations(&cols, &y_eps, rows);
                    let theta = nnls::solve(&g, &b, &vec![true; cols.len()])?;
                    let c = cost(&cols, theta.as_slice(), &y_eps, rows);
                    // Flat order: p0, m0, r[N], p[N].
                    let mut p = vec![theta[0] + eps, m0];
                    p.extend(radii.iter().copied());
                    p.push(3.0 * big);
                    p.extend(theta.iter().skip(1).copied());
                    consider(p, c);
                }
            }
        }
        Structure::ElastoSlide if n_ops >= 1 => {
            for spread in SPREADS {
                let lims: Vec<f64> = (1..=n_ops).map(|i| spread * 0.5 * span * i as f64 / n_ops as f64).collect();
                let mut cols: Vec<Vec<f64>> = lims.iter().map(|l| slip_column(kin, *l as f32)).collect();
                cols.push(kin.iter().map(|k| f64::from(k.x)).collect());
                cols.push(vec![1.0; kin.len()]);
                let mut nonneg = vec![true; n_ops];
                nonneg.extend([false, false]);
                let (g, b) = nnls::normal_equations(&cols, y, rows);
                let theta = nnls::solve(&g, &b, &nonneg)?;
                let c = cost(&cols, theta.as_slice(), y, rows);
                // kᵢ > 0 in the core: an unused element gets a negligible stiffness.
                let tiny = 1e-9 * theta.iter().take(n_ops).fold(1e-9f64, |a, v| a.max(v.abs()));
                let k: Vec<f64> = theta.iter().take(n_ops).map(|v| v.max(tiny)).collect();
                // Flat order: w0, k[N], f[N] (= kᵢ·limᵢ), k0.
                let mut p = vec![theta[n_ops + 1]];
                p.extend(k.iter().copied());
                p.extend(k.iter().zip(&lims).map(|(k, l)| k * l));
                p.push(theta[n_ops]);
                consider(p, c);
            }
        }
        _ => return None,
    }
    best
}

/// What [`Projected`] solves in closed form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Linear {
    /// Preisach: offset `y₀` and scale `s` (flat 4, 5).
    Preisach,
    /// GPI: `p₀`, `δ₁ ≥ 0` and an offset written as a common shift of both envelopes
    /// (their additive coefficient: `b` of the polynomial, `c` of tanh) and of `M₀` (the
    /// play operators commute with it).
    Gpi,
}

/// Variable projection for the Preisach and GPI models: a [`Simulator`] over the shape
/// parameters whose output is the least-squares best over the linear ones on `rows`.
pub struct Projected<'a> {
    inner: &'a dyn Simulator,
    kind: Linear,
    y: &'a [f64],
    rows: &'a [usize],
}

/// Number of parameters [`Projected`] solves in closed form for model `id` (0: not projected).
pub fn projected_count(structure: Structure) -> usize {
    match structure {
        Structure::PreisachProjection => 2,
        Structure::GpiProjection => 3,
        _ => 0,
    }
}

impl<'a> Projected<'a> {
    /// `None` for a model without a projection.
    pub fn new(inner: &'a dyn Simulator, y: &'a [f64], rows: &'a [usize]) -> Option<Self> {
        let kind = match crate::models::host(inner.id())?.structure {
            Structure::PreisachProjection => Linear::Preisach,
            Structure::GpiProjection => Linear::Gpi,
            _ => return None,
        };
        Some(Self { inner, kind, y, rows })
    }

    /// The shape with unit linear part (flat vector of the model).
    fn unit(&self, p: &[f64]) -> Vec<f64> {
        let mut q = p.get(..self.inner.n_params()).unwrap_or(p).to_vec();
        match self.kind {
            Linear::Preisach => {
                set(&mut q, 4, 0.0);
                set(&mut q, 5, 1.0);
            }
            Linear::Gpi => {
                set(&mut q, 0, 0.0);
                set(&mut q, 2, 1.0);
                let at = gpi_shift_index(&q);
                set(&mut q, at, 0.0);
            }
        }
        q
    }

    /// Linear coefficients for the unit-shape output `phi` over `kin`: Preisach
    /// `[y₀, s]`, GPI `[p₀, δ₁, offset]`.
    fn solve(&self, kin: &[Kin], phi: &[f64]) -> Option<Vec<f64>> {
        let rows: Vec<usize> = self.rows.iter().copied().filter(|&i| i < phi.len()).collect();
        match self.kind {
            Linear::Preisach => {
                let cols = [vec![1.0; phi.len()], phi.to_vec()];
                let (g, b) = nnls::normal_equations(&cols, self.y, &rows);
                Some(nnls::solve(&g, &b, &[false, false])?.iter().copied().collect())
            }
            Linear::Gpi => {
                let x: Vec<f64> = kin.iter().take(phi.len()).map(|k| f64::from(k.x)).collect();
                let cols = [x, phi.to_vec(), vec![1.0; phi.len()]];
                let (g, b) = nnls::normal_equations(&cols, self.y, &rows);
                Some(nnls::solve(&g, &b, &[false, true, false])?.iter().copied().collect())
            }
        }
    }

    /// The flat vector with the linear part solved on `kin` (delay entries of `p` kept).
    /// `None` when the shape is invalid or the linear part cannot be written back.
    pub fn complete(&self, p: &[f64], kin: &[Kin]) -> Option<Vec<f64>> {
        let q = self.unit(p);
        let mut phi = vec![0.0; kin.len()];
        if !self.inner.run(&q, kin, &mut phi) {
            return None;
        }
        let lin = self.solve(kin, &phi)?;
        let mut full = p.to_vec();
        full.get_mut(..q.len())?.copy_from_slice(&q);
        match self.kind {
            Linear::Preisach => {
                set(&mut full, 4, *lin.first()?);
                set(&mut full, 5, *lin.get(1)?);
            }
            Linear::Gpi => {
                let (p0, d1, off) = (*lin.first()?, *lin.get(1)?, *lin.get(2)?);
                // Σ exp(−δ₂·rᵢ) over the core's radii, for the offset as an envelope shift.
                let sum_w = gpi_weight_sum(&q)?;
                if !(d1 > 0.0 && sum_w > 0.0) {
                    return None;
                }
                let shift = off / (d1 * sum_w);
                let at = gpi_shift_index(&q);
                set(&mut full, 0, p0);
                set(&mut full, 2, d1);
                set(&mut full, 1, q.get(1)? + shift);
                set(&mut full, at, shift);
                set(&mut full, at + 3, q.get(at + 3)? + shift);
            }
        }
        Some(full)
    }
}

/// Flat index of the right envelope's additive coefficient (the left one's is 3 further):
/// `c_r` for tanh envelopes, `b_r` for the polynomial (Gaussian envelopes have none; their
/// offset is left at `b_r`, which is not additive, so the closed form does not apply).
fn gpi_shift_index(q: &[f64]) -> usize {
    if q.get(12).copied() == Some(1.0) {
        6
    } else {
        5
    }
}

fn set(v: &mut [f64], i: usize, x: f64) {
    if let Some(e) = v.get_mut(i) {
        *e = x;
    }
}

/// `Σ exp(−δ₂·rᵢ)` of the registered GPI model's radii for flat vector `q` (with δ₁ = 1),
/// as the core computes it.
fn gpi_weight_sum(q: &[f64]) -> Option<f64> {
    use model_core::Model;
    let mut p: Vec<f32> = q.iter().map(|v| *v as f32).collect();
    *p.get_mut(2)? = 1.0;
    let m = model_core::models::gpi::Registered::from_params(&p, 1e-3).ok()?;
    Some(m.weights().iter().map(|w| f64::from(*w)).sum())
}

impl Simulator for Projected<'_> {
    fn id(&self) -> &'static str {
        self.inner.id()
    }
    fn n_params(&self) -> usize {
        self.inner.n_params()
    }
    fn valid(&self, p: &[f64]) -> bool {
        self.inner.valid(&self.unit(p))
    }
    fn run(&self, p: &[f64], kin: &[Kin], out: &mut [f64]) -> bool {
        let q = self.unit(p);
        if !self.inner.run(&q, kin, out) {
            return false;
        }
        let n = kin.len().min(out.len());
        let Some(lin) = self.solve(kin, out.get(..n).unwrap_or(&[])) else { return false };
        match self.kind {
            Linear::Preisach => {
                let (a, b) = (lin.first().copied().unwrap_or(0.0), lin.get(1).copied().unwrap_or(0.0));
                out.iter_mut().for_each(|o| *o = a + b * *o);
            }
            Linear::Gpi => {
                let (p0, d1, off) = (
                    lin.first().copied().unwrap_or(0.0),
                    lin.get(1).copied().unwrap_or(0.0),
                    lin.get(2).copied().unwrap_or(0.0),
                );
                if d1 <= 0.0 {
                    return false;
                }
                for (o, k) in out.iter_mut().zip(kin) {
                    *o = p0 * f64::from(k.x) + d1 * *o + off;
                }
            }
        }
        out.iter().all(|v| v.is_finite())
    }
}

/// Whether the steady loop of a fitted asymmetric Bouc–Wen set crosses itself over the
/// training range at the training data's typical rate (seed 004's warning on eq. 30:
/// a high GOF with a non-physical loop). `flat` is the model's flat vector.
pub fn abw_crossing(flat: &[f64], dt: f32, kin: &[Kin], rows: &[usize]) -> Option<bool> {
    use model_core::models::bouc_wen_asym::BoucWenAsym;
    use model_core::Model;
    let p: Vec<f32> = flat.iter().map(|v| *v as f32).collect();
    let m = BoucWenAsym::from_params(&p, dt).ok()?;
    let end = rows.last().map_or(0, |r| r + 1).min(kin.len());
    let (lo, hi) = x_range(kin, end);
    let rates: Vec<f64> = rows.iter().filter_map(|&i| kin.get(i)).map(|k| f64::from(k.dx).abs()).collect();
    let rate = rates.iter().sum::<f64>() / rates.len().max(1) as f64;
    Some(m.crossing_risk(lo as f32, hi as f32, rate as f32))
}

/// The asymmetric Bouc–Wen set's non-physical crossing loop (seed 004 §6.2), if it has one.
pub fn abw_warning(
    params: &[f64],
    dt: f32,
    kin: &[model_core::Kin],
    delays: (f64, f64),
    starts: &[usize],
    rows: &[usize],
) -> Option<String> {
    let mut shifted = Vec::new();
    crate::models::alignment::shift_kin_runs(kin, delays.0, delays.1, starts, &mut shifted);
    (abw_crossing(params, dt, &shifted, rows) == Some(true)).then(|| {
        let eq = if params.get(11).copied() == Some(1.0) { "eq. 30" } else { "eq. 31" };
        format!(
            "bouc_wen_asym ({eq}): the fitted loop crosses itself over the training range at the data's mean \
             rate, a non-physical artefact (seed 004 §6.2); do not use this set for control"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::fit::simulate::simulator;

    fn triangle(n: usize) -> Vec<Kin> {
        (0..n)
            .map(|i| {
                let ph = (i % 2000) as f32 / 2000.0;
                let x = if ph < 0.5 { 4.0 * ph } else { 4.0 * (1.0 - ph) } * (1.0 + 0.3 * (i / 2000) as f32 % 2.0);
                Kin::new(x, 0.0, 0.0, 0.0)
            })
            .collect()
    }

    /// The closed form reproduces a Maxwell-slip and a PI loop that its radii can represent.
    #[test]
    fn closed_form_reproduces_operator_loops() {
        let kin = triangle(12_000);
        let rows: Vec<usize> = (0..kin.len()).collect();
        for id in ["maxwell_slip", "prandtl_ishlinskii"] {
            let sim = simulator(id, 1e-3).unwrap();
            let structure = crate::models::host(id).unwrap().structure;
            let truth: Vec<f64> = if id == "maxwell_slip" {
                // kᵢ > 0 in the core: the unused elements get a negligible stiffness.
                let k = [2.0, 1e-6, 1.0, 1e-6, 1e-6, 3.0, 1e-6, 1e-6, 1e-6, 1e-6];
                let mut p = vec![0.5];
                p.extend(k);
                p.extend(k.iter().enumerate().map(|(i, k)| k * 0.1 * (i + 1) as f64));
                p.push(0.7);
                p
            } else {
                let mut p = vec![1.5, 0.0];
                p.extend((0..10).map(|i| 0.1 * i as f64));
                p.extend([0.0, 2.0, 0.0, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0]);
                p
            };
            let mut y = vec![0.0; kin.len()];
            assert!(sim.run(&truth, &kin, &mut y), "{id}");
            let (p, cost) = closed_form(structure, 10, &kin, &y, &rows).unwrap();
            let mut out = vec![0.0; kin.len()];
            assert!(sim.run(&p, &kin, &mut out), "{id}: {p:?}");
            let var = y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64;
            let mse = y.iter().zip(&out).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / y.len() as f64;
            assert!(mse < 1e-3 * var && cost < 1e-3 * var, "{id}: mse {mse}, cost {cost}, var {var}");
        }
        assert!(closed_form(Structure::Generic, 10, &kin, &[0.0; 10], &rows).is_none());
    }
}
