use super::*;
use crate::ident::fit::simulate::simulator_of;
use model_core::models::narx::Narx;
use model_core::Kin;

const H: usize = 4;

fn input(n: usize) -> Vec<Kin> {
    (0..n)
        .map(|i| {
            let t = i as f32 * 1e-3;
            Kin::new(0.4 + 0.3 * (9.0 * t).sin() + 0.2 * (23.0 * t).sin() + 0.05 * (71.0 * t).cos(), 0.0, 0.0, 0.0)
        })
        .collect()
}

fn random_theta(sh: Shape, rng: &mut StdRng) -> Vec<f64> {
    let mut th: Vec<f64> = (0..sh.n_free()).map(|_| rng.random_range(-0.6..0.6)).collect();
    th[0] = 0.7;
    th
}

/// The f32 core's output for free block `th` (normalisation `(0.4, 0.3)`, `(1.0, 2.0)`).
fn core(th: &[f64], kin: &[Kin]) -> Vec<f64> {
    let mut p = vec![0.4, 0.3, 1.0, 2.0];
    p.extend_from_slice(th);
    p.extend([-9.0, 11.0]);
    let mut out = vec![0.0; kin.len()];
    assert!(simulator_of::<Narx<H>>(1e-3).run(&p, kin, &mut out));
    out
}

fn twin(kin: &[Kin], y: &[f64]) -> Twin {
    Twin::new(Shape { h: H }, kin, y, (0.4, 0.3), (1.0, 2.0), (-9.0, 11.0))
}

#[test]
fn twin_runs_like_the_core() {
    let kin = input(3000);
    let mut rng = StdRng::seed_from_u64(3);
    let th = random_theta(Shape { h: H }, &mut rng);
    let y = core(&th, &kin);
    let rows: Vec<usize> = (0..kin.len()).collect();
    let r = twin(&kin, &y).run(&th, &rows, &[], None).unwrap();
    // Residuals against the core's own output: f32 rounding only.
    assert!(r.iter().all(|e| e.abs() < 1e-5), "{:?}", r.iter().fold(0.0f64, |m, e| m.max(e.abs())));
}

#[test]
fn jacobian_matches_finite_differences() {
    let kin = input(1500);
    let mut rng = StdRng::seed_from_u64(5);
    let sh = Shape { h: H };
    let th = random_theta(sh, &mut rng);
    let y = vec![0.0; kin.len()];
    // No clamp in reach: the output is differentiable everywhere.
    let tw = Twin::new(sh, &kin, &y, (0.4, 0.3), (1.0, 2.0), (-1e3, 1e3));
    let rows: Vec<usize> = (0..kin.len()).step_by(7).collect();
    let cols: Vec<usize> = (0..sh.n_free()).collect();
    let mut jac = DMatrix::zeros(rows.len(), cols.len());
    tw.run(&th, &rows, &cols, Some(&mut jac)).unwrap();
    for c in cols {
        // Central difference, the step well above the f32 rounding of the weights.
        let h = 1e-3;
        let mut plus = th.clone();
        plus[c] += h;
        let mut minus = th.clone();
        minus[c] -= h;
        let (rp, rm) = (tw.run(&plus, &rows, &[], None).unwrap(), tw.run(&minus, &rows, &[], None).unwrap());
        for (i, (a, b)) in rp.iter().zip(&rm).enumerate() {
            let fd = (a - b) / (2.0 * h);
            let an = jac[(i, c)];
            assert!((fd - an).abs() < 2e-3 * (1.0 + an.abs()), "column {c}, row {i}: {an} vs {fd}");
        }
    }
}

#[test]
fn slow_state_is_written_exactly() {
    // G on û(t) … û(t−4) (units 0..2), then the slow state: the network must run as
    // G(t) + s(t) with s(t) = a·s(t−1) + κ·G(t−1) + d from its steady start.
    let kin = input(4000);
    let sh = Shape { h: H };
    let mut rng = StdRng::seed_from_u64(9);
    let mut g = vec![0.0; sh.n_free()];
    for c in static_cols(sh, H / 2, 5) {
        g[c] = rng.random_range(-0.8..0.8);
    }
    // A measurement with a slow drift, so the least squares pick a slow state.
    let rows: Vec<usize> = (0..kin.len()).collect();
    let tw0 = twin(&kin, &vec![0.0; kin.len()]);
    let gv = outputs(&tw0, &g, kin.len()).unwrap();
    let mut s = 0.0;
    let y: Vec<f64> = gv
        .iter()
        .map(|gt| {
            let v = 1.0 + 2.0 * (gt + s);
            s = 0.999 * s - 0.0004 * gt;
            v
        })
        .collect();
    let tw = twin(&kin, &y);
    let th = with_slow_state(&tw, &g, H / 2, &rows, &[10.0, 1000.0, 3000.0]).unwrap();
    let a = th[0];
    assert!(a > 0.99, "a = {a}");
    let out = outputs(&tw, &th, kin.len()).unwrap();
    // s = ŷ − G must follow s(t) = a·s(t−1) + κ·G(t−1) + d with one constant d (κ from
    // the shifted copy's output weight −(a − κ)·aⱼ); up to the f32 rounding of the weights.
    let kappa = a + th[sh.a(H / 2)] / g[sh.a(0)];
    let d: Vec<f64> =
        (1..kin.len()).map(|t| out[t] - gv[t] - a * (out[t - 1] - gv[t - 1]) - kappa * gv[t - 1]).collect();
    assert!(d.iter().all(|v| (v - d[0]).abs() < 1e-6), "d varies: {:?}", (d[0], d.last()));
}

#[test]
fn learns_a_network_from_its_output() {
    // Data from a known 4-unit network; the training must reproduce it closely on a
    // stretch it was not trained on.
    let kin = input(6000);
    let mut rng = StdRng::seed_from_u64(11);
    let sh = Shape { h: H };
    let mut truth = random_theta(sh, &mut rng);
    truth[0] = 0.5;
    let y = core(&truth, &kin);
    let tw = twin(&kin, &y);
    let rows: Vec<usize> = (0..4500).collect();
    let held: Vec<usize> = (4500..6000).collect();
    let score = |th: &[f64], at: &[usize]| tw.cost(th, at);
    let net = train(&tw, &rows, &Effort::default(), 1, &score).unwrap();
    let var = {
        let m = held.iter().map(|&i| (y[i] - 1.0) / 2.0).sum::<f64>() / held.len() as f64;
        held.iter().map(|&i| ((y[i] - 1.0) / 2.0 - m).powi(2)).sum::<f64>() / held.len() as f64
    };
    let mse = tw.cost(&net.theta, &held);
    assert!(mse < 1e-3 * var, "held-out MSE {mse} against variance {var}");
}
