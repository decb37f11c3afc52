//! The f64 twin of the core's NARX evaluator: the weights rounded to f32 and the inputs
//! normalised in f32, as the core stores and computes them, with the exact forward-mode
//! sensitivities `∂ŷ(t)/∂θ` along the recursion (and through the steady start).

use model_core::Kin;
use nalgebra::DMatrix;

/// Clamp of the normalised inputs (as the core's `U_LIM`).
pub(super) const U_LIM: f32 = 1.0e6;

/// Index map of the free block for `h` hidden units: `lin[7], hid_w[7·h], hid_b[h],
/// out_a[h], offset`, the values that follow `u_mean, u_scale, y_mean, y_scale` in the
/// core's flat vector.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub h: usize,
}

impl Shape {
    pub fn n_free(self) -> usize {
        9 * self.h + 8
    }
    pub(super) fn w(self, j: usize, k: usize) -> usize {
        7 + 7 * j + k
    }
    pub(super) fn b(self, j: usize) -> usize {
        7 + 7 * self.h + j
    }
    pub(super) fn a(self, j: usize) -> usize {
        7 + 8 * self.h + j
    }
    pub(super) fn c(self) -> usize {
        7 + 9 * self.h
    }
}

pub(super) fn sigmoid(s: f64) -> f64 {
    1.0 / (1.0 + (-s).exp())
}

/// The recording in the core's normalised units.
pub struct Twin {
    pub shape: Shape,
    /// `û(t)` for every sample.
    pub(super) un: Vec<f64>,
    /// Measured output, normalised.
    pub(super) yn: Vec<f64>,
    /// Output clamp, normalised.
    pub(super) lo: f64,
    pub(super) hi: f64,
}

/// One evaluation of eq. 18–19 at regressors `r` (normalised): the unit activations into
/// `act`; returns the unclamped output and `∂f/∂ŷ(t−1)`.
pub(super) fn eval(sh: Shape, th: &[f64], r: &[f64; 7], act: &mut [f64]) -> (f64, f64) {
    let (lin, w, b, a, c) = blocks(sh, th);
    let act = &mut act[..sh.h];
    let mut y = c;
    let mut dfdy = lin[0];
    for (l, rk) in lin.iter().zip(r) {
        y += l * rk;
    }
    // The units' sums, then their sigmoids, then the output's sums (each in the order of one
    // unit after the other, as before): the units' independent chains are not serialised
    // behind each unit's `exp`.
    for ((wj, bj), s) in w.chunks_exact(7).zip(b).zip(act.iter_mut()) {
        let mut acc = *bj;
        for (wk, rk) in wj.iter().zip(r) {
            acc += wk * rk;
        }
        *s = acc;
    }
    for s in act.iter_mut() {
        *s = sigmoid(*s);
    }
    for ((aj, &sg), wj) in a.iter().zip(act.iter()).zip(w.chunks_exact(7)) {
        y += aj * sg;
        dfdy += aj * sg * (1.0 - sg) * wj[0];
    }
    (y, dfdy)
}

/// The free block `th` split as [`Shape`] lays it out: `lin[7], hid_w[7·h], hid_b[h],
/// out_a[h], offset` (one slice split instead of an index check per weight).
fn blocks(sh: Shape, th: &[f64]) -> (&[f64; 7], &[f64], &[f64], &[f64], f64) {
    let h = sh.h;
    let (lin, rest) = th.split_at(7);
    let (w, rest) = rest.split_at(7 * h);
    let (b, rest) = rest.split_at(h);
    let (a, rest) = rest.split_at(h);
    let lin: &[f64; 7] = lin.try_into().unwrap_or(&[0.0; 7]);
    (lin, w, b, a, rest[0])
}

/// `∂f/∂θ` at regressors `r` (activations from [`eval`]), into `g`.
pub(super) fn direct(sh: Shape, th: &[f64], r: &[f64; 7], act: &[f64], g: &mut [f64]) {
    let h = sh.h;
    let (_, _, _, a, _) = blocks(sh, th);
    let (g_lin, rest) = g.split_at_mut(7);
    let (g_w, rest) = rest.split_at_mut(7 * h);
    let (g_b, rest) = rest.split_at_mut(h);
    let (g_a, rest) = rest.split_at_mut(h);
    g_lin.copy_from_slice(r);
    for ((((gwj, gbj), gaj), aj), &sg) in g_w.chunks_exact_mut(7).zip(g_b).zip(g_a).zip(a).zip(&act[..h]) {
        let ad = aj * sg * (1.0 - sg);
        for (gk, rk) in gwj.iter_mut().zip(r) {
            *gk = ad * rk;
        }
        *gbj = ad;
        *gaj = sg;
    }
    rest[0] = 1.0;
}

impl Twin {
    pub fn new(
        shape: Shape,
        kin: &[Kin],
        y: &[f64],
        (xm, xs): (f64, f64),
        (ym, ys): (f64, f64),
        clamp: (f64, f64),
    ) -> Self {
        // The inputs exactly as the core normalises them (f32), and the constants as it stores them.
        let f = |v: f64| f64::from(v as f32);
        let (xm32, xs32) = (xm as f32, xs as f32);
        let un = kin.iter().map(|k| f64::from(((k.x - xm32) / xs32).clamp(-U_LIM, U_LIM))).collect();
        let (ym, ys) = (f(ym), f(ys));
        let yn = y.iter().map(|v| (v - ym) / ys).collect();
        Self { shape, un, yn, lo: (f(clamp.0) - ym) / ys, hi: (f(clamp.1) - ym) / ys }
    }

    pub(super) fn u(&self, t: isize) -> f64 {
        let i = t.max(0) as usize;
        self.un.get(i).or(self.un.last()).copied().unwrap_or(0.0)
    }

    pub(super) fn regressors(&self, t: usize, y_prev: f64) -> [f64; 7] {
        let t = t as isize;
        [y_prev, self.u(t), self.u(t - 1), self.u(t - 2), self.u(t - 3), self.u(t - 4), self.u(t - 5)]
    }

    /// Residuals (model − measurement, normalised) at `rows` (ascending, distinct), running
    /// the network on its own output from the steady start; with `jac`, also their Jacobian
    /// with respect to the entries `cols` of the free block (a clamped output has none).
    /// `None` when the output is not finite.
    pub fn run(
        &self,
        th: &[f64],
        rows: &[usize],
        cols: &[usize],
        mut jac: Option<&mut DMatrix<f64>>,
    ) -> Option<Vec<f64>> {
        let sh = self.shape;
        let n = sh.n_free();
        if th.len() != n {
            return None;
        }
        // The weights as the core stores them (f32): a slow state integrates their rounding.
        let rounded: Vec<f64> = th.iter().map(|v| f64::from(*v as f32)).collect();
        let th = rounded.as_slice();
        let end = rows.last().map_or(0, |r| r + 1).min(self.un.len());
        let mut act = vec![0.0; sh.h];
        let mut g = vec![0.0; n];
        let mut sens = vec![0.0; if jac.is_some() { n } else { 0 }];
        // Steady start: the fixed point of the clamped map at the first input (bisection,
        // as the core's `initial_state`).
        let (mut lo, mut hi) = (self.lo, self.hi);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let (v, _) = eval(sh, th, &self.regressors(0, mid), &mut act);
            if v.clamp(self.lo, self.hi) > mid {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r0 = self.regressors(0, 0.5 * (lo + hi));
        let (v0, dfdy0) = eval(sh, th, &r0, &mut act);
        let mut y_prev = v0.clamp(self.lo, self.hi);
        if jac.is_some() && v0 == y_prev && (1.0 - dfdy0).abs() > 1e-9 {
            direct(sh, th, &r0, &act, &mut g);
            let k = 1.0 / (1.0 - dfdy0);
            for (s, gi) in sens.iter_mut().zip(&g) {
                *s = gi * k;
            }
        }
        let mut out = Vec::with_capacity(rows.len());
        let mut next = rows.iter().peekable();
        for t in 0..end {
            let r = self.regressors(t, y_prev);
            let (v, dfdy) = eval(sh, th, &r, &mut act);
            let y = v.clamp(self.lo, self.hi);
            if !y.is_finite() {
                return None;
            }
            if jac.is_some() {
                if v == y {
                    direct(sh, th, &r, &act, &mut g);
                    for (s, gi) in sens.iter_mut().zip(&g) {
                        *s = gi + dfdy * *s;
                    }
                } else {
                    sens.iter_mut().for_each(|s| *s = 0.0);
                }
            }
            if next.peek() == Some(&&t) {
                next.next();
                let row = out.len();
                out.push(y - self.yn.get(t).copied().unwrap_or(0.0));
                if let Some(j) = jac.as_deref_mut() {
                    for (c, &i) in cols.iter().enumerate() {
                        j[(row, c)] = sens.get(i).copied().unwrap_or(0.0);
                    }
                }
            }
            y_prev = y;
        }
        Some(out)
    }

    /// Mean squared residual at `rows`.
    pub fn cost(&self, th: &[f64], rows: &[usize]) -> f64 {
        match self.run(th, rows, &[], None) {
            Some(r) if !r.is_empty() => r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64,
            _ => f64::INFINITY,
        }
    }
}
