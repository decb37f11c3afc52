//! Global search for models with local minima (Bouc–Wen family, LuGre, Dahl, trig): a
//! particle swarm (argmin's `ParticleSwarm`, costs evaluated in parallel) over the unit box
//! of the free parameters, seeded with the spec's starting point. It returns the best few
//! distinct points it saw, for Levenberg–Marquardt to polish with the papers' start and the
//! separable grid's best points ([`super::separable`]); [`global_fit`] restarts it until
//! two starts agree.

use std::sync::Mutex;

use argmin::core::{CostFunction, Error, Executor, PopulationState};
use argmin::solver::particleswarm::{Particle, ParticleSwarm};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

use super::objective::Objective;
use super::{lm, restarts, simulate, valid_or_err, FitError, FitOptions};
use crate::models::search::ModelSpec;

/// Size of the swarm search.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SwarmOptions {
    pub particles: usize,
    pub iterations: u64,
    pub seed: u64,
    /// How many distinct candidates to return.
    pub keep: usize,
}

impl SwarmOptions {
    /// The wider search a fit falls back to when the default finds no valid point.
    pub fn wide(seed: u64) -> Self {
        Self { particles: 48, iterations: 20, seed, keep: 3 }
    }
}

impl Default for SwarmOptions {
    fn default() -> Self {
        Self { particles: 16, iterations: 12, seed: 1, keep: 1 }
    }
}

/// One point of the search, as a full parameter vector.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub params: Vec<f64>,
    pub cost: f64,
}

struct Cost<'a, 'b> {
    obj: &'b Objective<'a>,
    /// Best distinct points seen so far (unit-box positions), best first.
    best: &'b Mutex<Vec<(f64, Vec<f64>)>>,
    keep: usize,
}

/// Two unit-box points closer than this (max-norm) count as the same basin.
const DISTINCT: f64 = 0.05;

impl Cost<'_, '_> {
    fn record(&self, cost: f64, unit: &[f64]) {
        if !cost.is_finite() {
            return;
        }
        let Ok(mut best) = self.best.lock() else { return };
        let near = |u: &Vec<f64>| u.iter().zip(unit).all(|(a, b)| (a - b).abs() < DISTINCT);
        if let Some(pos) = best.iter().position(|(_, u)| near(u)) {
            if best.get(pos).is_some_and(|(c, _)| cost < *c) {
                best.remove(pos);
            } else {
                return;
            }
        }
        let at = best.iter().position(|(c, _)| cost < *c).unwrap_or(best.len());
        if at < self.keep {
            best.insert(at, (cost, unit.to_vec()));
            best.truncate(self.keep);
        }
    }
}

impl CostFunction for Cost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, unit: &Vec<f64>) -> Result<f64, Error> {
        let c = self.obj.cost(&self.obj.from_unit(unit));
        self.record(c, unit);
        // The swarm compares costs; an invalid point is simply the worst.
        Ok(if c.is_finite() { c } else { f64::MAX })
    }
}

/// Search the box of `obj`'s free parameters. The spec's starting point is one of the
/// particles, so the result is never worse than the start.
pub fn search(obj: &Objective<'_>, opts: SwarmOptions) -> Result<Vec<Candidate>, Error> {
    let n = obj.free.len();
    let best = Mutex::new(Vec::new());
    let cost = Cost { obj, best: &best, keep: opts.keep.max(1) };
    if n == 0 {
        let p = obj.spec.start();
        return Ok(vec![Candidate { cost: obj.cost(&p), params: p }]);
    }
    let mut rng = StdRng::seed_from_u64(opts.seed);
    let mut points: Vec<Vec<f64>> = vec![obj.to_unit(&obj.spec.start())];
    while points.len() < opts.particles.max(2) {
        points.push((0..n).map(|_| rng.random::<f64>()).collect());
    }
    let costs: Vec<f64> = points.par_iter().map(|u| cost.cost(u).unwrap_or(f64::MAX)).collect();
    let population: Vec<Particle<Vec<f64>, f64>> = points
        .into_iter()
        .zip(costs)
        .map(|(u, c)| {
            let v: Vec<f64> = (0..n).map(|_| 0.1 * (rng.random::<f64>() - 0.5)).collect();
            Particle::new(u, c, v)
        })
        .collect();
    let solver = ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), population.len())
        .with_rng_generator(StdRng::seed_from_u64(opts.seed.wrapping_add(1)));
    Executor::new(cost, solver)
        .configure(|s: PopulationState<Particle<Vec<f64>, f64>, f64>| {
            s.population(population).max_iters(opts.iterations)
        })
        .run()?;
    let best = best.into_inner().map_err(|_| Error::msg("swarm bookkeeping poisoned"))?;
    Ok(best.into_iter().map(|(c, u)| Candidate { params: obj.from_unit(&u), cost: c }).collect())
}

/// Starts that are the same on every restart of the global search: the papers' start and
/// the best points of the separable grid ([`super::separable`]), polished once per fit.
pub(super) struct FixedStarts {
    starts: Vec<Vec<f64>>,
    polished: std::sync::OnceLock<Vec<lm::LocalFit>>,
}

/// Grid points of [`super::separable`] polished beside the swarm's.
const GRID_KEEP: usize = 2;

impl FixedStarts {
    /// The papers' start of `sp` and, for a model with affine parameters and `grid`, the
    /// grid's best points on the window `win`.
    pub(super) fn new(sp: &ModelSpec, win: &Objective<'_>, grid: bool) -> Self {
        let mut starts = vec![sp.start()];
        let affine = crate::models::host(sp.id).filter(|_| grid).map_or(&[][..], |h| h.affine);
        starts.extend(super::separable::starts(win, affine, GRID_KEEP).into_iter().map(|c| c.params));
        Self { starts, polished: std::sync::OnceLock::new() }
    }
}

/// The global phase of [`Strategy::Global`]: swarm on the window, then every candidate and
/// the fixed starts polished there (the fixed ones once per fit, [`FixedStarts`], for all
/// the starts of [`super::restarts::until_agree`]). Returns the candidate with the lowest cost
/// on the whole training part (`None` when none is valid), the evaluations spent, and whether
/// the swarm found any valid point on the window.
pub(super) fn global_search(
    id: &str,
    (win, full): (&Objective<'_>, &Objective<'_>),
    opts: &FitOptions,
    swarm: SwarmOptions,
    fixed: &FixedStarts,
) -> Result<(Option<lm::LocalFit>, usize, bool), FitError> {
    let mut cands = search(win, swarm).map_err(|e| FitError::Swarm { model: id.to_owned(), reason: e.to_string() })?;
    let found = !cands.is_empty();
    // The papers' starting values are always polished too: they are often in the
    // right basin already (Spencer's published set on the Dyke files is), and the
    // swarm offers the alternatives.
    cands.retain(|c| !fixed.starts.contains(&c.params));
    // Polish every candidate on the window (in parallel), rank them by their cost on
    // the whole training part (one run each: the window alone does not tell
    // near-equal basins apart), then finish the best on the whole training part.
    let polish = |p: &[f64]| {
        let r = lm::minimize(win, p, opts.polish_iterations);
        lm::LocalFit { cost: full.cost(&r.params), evaluations: r.evaluations + 1, ..r }
    };
    let mut polished: Vec<lm::LocalFit> = cands.par_iter().map(|c| polish(&c.params)).collect();
    let swarm_evals = polished.iter().map(|r| r.evaluations).sum::<usize>();
    let mut fixed_evals = 0;
    let done = fixed.polished.get_or_init(|| {
        let r: Vec<lm::LocalFit> = fixed.starts.par_iter().map(|p| polish(p)).collect();
        fixed_evals = r.iter().map(|r| r.evaluations).sum();
        r
    });
    polished.extend(done.iter().cloned());
    let evals = swarm.particles * (swarm.iterations as usize + 1) + swarm_evals + fixed_evals;
    let best = polished.into_iter().filter(|r| r.cost.is_finite()).min_by(|a, b| a.cost.total_cmp(&b.cost));
    Ok((best, evals, found))
}

/// [`Strategy::Global`]: restarts of the global search (swarm on a window, then LM on it)
/// until two agree, then LM on the whole training part.
#[allow(clippy::too_many_arguments)]
pub(super) fn global_fit(
    id: &str,
    sp: &ModelSpec,
    sim: &dyn simulate::Simulator,
    (kin, y, rows): (&[model_core::Kin], &[f64], &[usize]),
    y_scale: f64,
    opts: &FitOptions,
    notes: &restarts::Notes,
    full: &Objective<'_>,
) -> Result<(Vec<f64>, usize), FitError> {
    let window_rows: Vec<usize> = rows.iter().copied().filter(|&i| i < opts.swarm_window).collect();
    let window_rows = if window_rows.len() < 20 { rows.to_vec() } else { window_rows };
    let win = Objective::new(sim, sp, kin, y, &window_rows, y_scale);
    let fixed = FixedStarts::new(sp, &win, opts.separable);
    let mut evals = 0;
    let mut failure = None;
    let best = restarts::until_agree(
        &format!("the {id} global search"),
        opts.swarm.seed,
        restarts::MAX_STARTS,
        notes,
        |seed| {
            let swarm = SwarmOptions { seed, ..opts.swarm };
            let search = |swarm| global_search(id, (&win, full), opts, swarm, &fixed);
            let r = search(swarm).and_then(|first| match first {
                (Some(best), e, _) => Ok((Some(best), e)),
                // A box where the small swarm found nothing valid (a start that is not a
                // published set, a narrow valid region) gets a wider search before giving
                // up; not one where it did and the polished points are not valid on the
                // whole training part (the wider swarm searches the same window: GPI on
                // `ranran_50.csv` ran it seven times for nothing valid).
                (None, e, true) => Ok((None, e)),
                (None, e, false) => search(SwarmOptions::wide(seed)).map(|(b, more, _)| (b, e + more)),
            });
            match r {
                Ok((b, e)) => {
                    evals += e;
                    b.map(|b| {
                        let c = b.cost;
                        (b, c)
                    })
                }
                Err(e) => {
                    failure = failure.take().or(Some(e));
                    None
                }
            }
        },
    );
    let Some(best) = best else {
        return Err(failure.unwrap_or_else(|| FitError::NoValidSet { model: id.to_owned() }));
    };
    let r = lm::minimize_reduced(full, &best.params, opts.lm_iterations);
    evals += r.evaluations;
    valid_or_err(id, sim, r.params, evals)
}
