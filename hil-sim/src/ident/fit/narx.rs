//! Training of the data-driven models of seed 000 (NARX, eq. 18–19; Hammerstein–Wiener,
//! eq. 15–17) on the host, in simulation mode: the network runs on its own past output,
//! as on the board, and Levenberg–Marquardt (the `levenberg-marquardt` crate) minimises
//! that simulation error.
//!
//! - NARX: the registered size ([`model_core::models::narx::Registered`], 8 sigmoid units,
//!   86 values) is trained directly by [`super::narx_net`] (exact Jacobian through the
//!   recursion, a static start with and without a slow state in the output feedback,
//!   selection on a validation block of the training part).
//! - Hammerstein–Wiener (LM through the f32 core, [`super::lm`]): a small network (3 + 3 sigmoid units, 32 values) is trained and
//!   written into the registered size with the remaining units at zero weight (they add
//!   exactly nothing), so the fit costs seconds, not the minutes 95 free weights would.
//!   Start: both static nets the identity plus small random units, the linear block a pure
//!   one-sample delay, and the output net's linear part the least-squares line.

use model_core::models::hammerstein_wiener::HammersteinWiener;
use model_core::Kin;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::lm;
use super::objective::Objective;
use super::simulate::simulator_of;
use crate::models::search::{ModelSpec, ParamSpec, Spacing, Strategy, Structure};
use crate::models::RateSpec;

/// Hidden units of the Hammerstein–Wiener networks that are trained (input, output side).
pub const HW_TRAINED: (usize, usize) = (3, 3);
type SmallHw = HammersteinWiener<3, 3>;

/// Largest number of training rows the residual vector (and the Jacobian) has: longer
/// training parts are subsampled evenly (the network still runs over every sample).
const MAX_ROWS: usize = 6000;

/// How a training run went.
#[derive(Clone, Debug)]
pub struct Trained {
    /// Flat vector of the registered model.
    pub params: Vec<f64>,
    pub evaluations: usize,
    /// Mean squared scaled residual the choice was made on: the (subsampled) training rows
    /// (Hammerstein–Wiener), the validation block of the training part (NARX).
    pub cost: f64,
}

fn ps(name: &'static str, lo: f64, hi: f64, start: f64) -> ParamSpec {
    ParamSpec { name, lo, hi, start: start.clamp(lo, hi), spacing: Spacing::Linear, fixed: false }
}
fn fixed(name: &'static str, v: f64) -> ParamSpec {
    ParamSpec { name, lo: v, hi: v, start: v, spacing: Spacing::Linear, fixed: true }
}

/// Mean and standard deviation (floored at 1e-12: a scale to divide by).
fn mean_std(v: &[f64]) -> (f64, f64) {
    let (m, s) = crate::numerics::stats::mean_std(v);
    (m, s.max(1e-12))
}

fn subsample(rows: &[usize]) -> Vec<usize> {
    let step = rows.len().div_ceil(MAX_ROWS).max(1);
    rows.iter().step_by(step).copied().collect()
}

/// Train model `id` (`narx` or `hammerstein_wiener`) on `rows` of `kin` → `y`.
/// Hammerstein–Wiener: `iterations` Levenberg–Marquardt iterations (Jacobians) on the first
/// `window` samples, then a few more on the first three windows (every Jacobian runs the
/// network once per free weight over its stretch, so this bounds the cost on long
/// recordings). NARX: the budget of [`super::narx_net::Effort::default`] (its Jacobian costs
/// one pass, not one per weight). `None` for another model or when no valid network was found.
#[allow(clippy::too_many_arguments)]
pub fn train(
    structure: Structure,
    kin: &[Kin],
    y: &[f64],
    rows: &[usize],
    dt: f32,
    rate: RateSpec,
    iterations: usize,
    window: usize,
    seed: u64,
) -> Option<Trained> {
    let xs: Vec<f64> = rows.iter().filter_map(|&i| kin.get(i)).map(|k| f64::from(k.x)).collect();
    let ys: Vec<f64> = rows.iter().filter_map(|&i| y.get(i).copied()).collect();
    let (xm, xsd) = mean_std(&xs);
    let (ym, ysd) = mean_std(&ys);
    let (ylo, yhi) = ys.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    let (xlo, xhi) = xs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    let mut rng = StdRng::seed_from_u64(seed);
    let sub = subsample(rows);
    let (spec, sim) = match structure {
        Structure::Narx => return train_narx(kin, y, rows, dt, (xm, xsd), (ym, ysd), (ylo, yhi), seed),
        Structure::HammersteinWiener => {
            let (nh, nw) = HW_TRAINED;
            // Output net's line: y ≈ w_lin·x + w_d.
            let slope = {
                let cov: f64 =
                    rows.iter().filter_map(|&i| Some((f64::from(kin.get(i)?.x) - xm) * (y.get(i)? - ym))).sum::<f64>()
                        / rows.len().max(1) as f64;
                cov / (xsd * xsd)
            };
            let yb = ym.abs() + 10.0 * ysd;
            let xb = 20.0 * (1.0 + xm.abs() / xsd);
            let mut p = Vec::new();
            let mut net = |p: &mut Vec<ParamSpec>, n: usize, a_scale: f64, names: [&'static str; 3]| {
                for _ in 0..n {
                    p.push(ps(names[0], -5.0 * a_scale, 5.0 * a_scale, a_scale * rng.random_range(-0.1..0.1)));
                }
                let ws: Vec<f64> = (0..n)
                    .map(|_| rng.random_range(0.5..2.0) / xsd * if rng.random::<bool>() { 1.0 } else { -1.0 })
                    .collect();
                for w in &ws {
                    p.push(ps(names[1], -20.0 / xsd, 20.0 / xsd, *w));
                }
                for w in &ws {
                    p.push(ps(names[2], -xb, xb, -w * xm + rng.random_range(-1.0..1.0)));
                }
            };
            net(&mut p, nh, xsd, ["h_a", "h_w", "h_b"]);
            p.push(ps("h_lin", -5.0, 5.0, 1.0));
            p.push(ps("h_d", -5.0 * xsd - xm.abs(), 5.0 * xsd + xm.abs(), 0.0));
            p.push(ps("lin_b", -3.0, 3.0, 1.0));
            p.push(ps("lin_b", -3.0, 3.0, 0.0));
            p.push(ps("lin_b", -3.0, 3.0, 0.0));
            for _ in 0..5 {
                p.push(ps("lin_f", -2.0, 2.0, 0.0));
            }
            net(&mut p, nw, ysd, ["w_a", "w_w", "w_b"]);
            p.push(ps("w_lin", -20.0 * ysd / xsd, 20.0 * ysd / xsd, slope));
            p.push(ps("w_d", -yb, yb, ym - slope * xm));
            let span = (xhi - xlo).max(1e-9);
            p.push(fixed("v_min", xlo - 2.0 * span));
            p.push(fixed("v_max", xhi + 2.0 * span));
            (p, simulator_of::<SmallHw>(dt))
        }
        _ => return None,
    };
    let sp = ModelSpec { id: sim.id(), params: spec, strategy: Strategy::Network, structure: Structure::Generic, rate };
    let start = sp.start();
    let win_rows: Vec<usize> = rows.iter().copied().filter(|&i| i < window).collect();
    let win_rows = if win_rows.len() < 200 { sub.clone() } else { subsample(&win_rows) };
    let win = Objective::new(sim.as_ref(), &sp, kin, y, &win_rows, ysd);
    if !win.cost(&start).is_finite() {
        return None;
    }
    let a = lm::minimize_reduced(&win, &start, iterations);
    let long: Vec<usize> = rows.iter().copied().filter(|&i| i < 3 * window).collect();
    let long = if long.len() < 200 { sub.clone() } else { subsample(&long) };
    let full = Objective::new(sim.as_ref(), &sp, kin, y, &long, ysd);
    let b = lm::minimize_reduced(&full, &a.params, (iterations / 4).max(1));
    // The start (a linear FIR / identity network) is itself a valid model: keep it when the
    // trained network does not beat it over the whole training part (a recursion trained on
    // the first stretch can still drift away later on: `ransim_u.csv` did).
    let whole = Objective::new(sim.as_ref(), &sp, kin, y, &sub, ysd);
    let (trained_cost, start_cost) = (whole.cost(&b.params), whole.cost(&start));
    let (best, cost) = if trained_cost <= start_cost { (b.params, trained_cost) } else { (start, start_cost) };
    let params = if structure == Structure::HammersteinWiener { embed_hw(&best)? } else { best };
    Some(Trained { params, evaluations: a.evaluations + b.evaluations + 1, cost })
}

/// Write a trained `HammersteinWiener<3, 3>` vector into the registered size, the extra
/// units with zero output weight.
fn embed_hw(small: &[f64]) -> Option<Vec<f64>> {
    use model_core::models::hammerstein_wiener::Registered as Hw;
    use model_core::Model;
    let (nh, nw) = HW_TRAINED;
    let big_h = (Hw::N_PARAMS - 14 - 3 * registered_nw()) / 3;
    let big_w = registered_nw();
    let mut out = Vec::with_capacity(Hw::N_PARAMS);
    let mut it = small.iter().copied();
    let block = |out: &mut Vec<f64>, n: usize, big: usize, it: &mut dyn Iterator<Item = f64>| {
        for _ in 0..n {
            out.push(it.next().unwrap_or(0.0));
        }
        out.extend(std::iter::repeat_n(0.0, big - n));
    };
    for _ in 0..3 {
        block(&mut out, nh, big_h, &mut it);
    }
    // h_lin, h_d, lin_b[3], lin_f[5]
    for _ in 0..10 {
        out.push(it.next()?);
    }
    for _ in 0..3 {
        block(&mut out, nw, big_w, &mut it);
    }
    for _ in 0..4 {
        out.push(it.next()?);
    }
    (out.len() == Hw::N_PARAMS).then_some(out)
}

/// Output-side units of the registered Hammerstein–Wiener model.
fn registered_nw() -> usize {
    use model_core::models::hammerstein_wiener::Registered as Hw;
    use model_core::Model;
    Hw::PARAM_NAMES
        .get(7)
        .and_then(|n| n.split_once('[').and_then(|(_, r)| r.trim_end_matches(']').parse().ok()))
        .unwrap_or(0)
}

/// NARX at the registered size, trained by [`super::narx_net`]; the output clamp is the
/// training range widened by a quarter of its span on each side.
#[allow(clippy::too_many_arguments)]
fn train_narx(
    kin: &[Kin],
    y: &[f64],
    rows: &[usize],
    dt: f32,
    (xm, xsd): (f64, f64),
    (ym, ysd): (f64, f64),
    (ylo, yhi): (f64, f64),
    seed: u64,
) -> Option<Trained> {
    use super::narx_net::{Effort, Shape, Twin};
    use model_core::models::narx::Registered as Nx;
    use model_core::Model;
    let h = (Nx::N_PARAMS - 14) / 9;
    let margin = 0.25 * (yhi - ylo).max(1e-9);
    let clamp = (ylo - margin, yhi + margin);
    let twin = Twin::new(Shape { h }, kin, y, (xm, xsd), (ym, ysd), clamp);
    // The free block is the core's flat vector between the normalisation and the clamp.
    let flat = |th: &[f64]| -> Vec<f64> {
        let mut p = vec![xm, xsd, ym, ysd];
        p.extend_from_slice(th);
        p.extend([clamp.0, clamp.1]);
        p
    };
    let sim = simulator_of::<Nx>(dt);
    let score = |th: &[f64], at: &[usize]| -> f64 {
        let end = at.last().map_or(0, |r| r + 1).min(kin.len());
        let mut out = vec![0.0; end];
        if at.is_empty() || !sim.run(&flat(th), &kin[..end], &mut out) {
            return f64::INFINITY;
        }
        at.iter().map(|&i| ((out[i] - y.get(i).copied().unwrap_or(0.0)) / ysd).powi(2)).sum::<f64>() / at.len() as f64
    };
    let net = super::narx_net::train(&twin, rows, &Effort::default(), seed, &score)?;
    let params = flat(&net.theta);
    (params.len() == Nx::N_PARAMS).then_some(Trained { params, evaluations: net.runs, cost: net.validation })
}
