//! The catalog's candidate causes (shared/spec/physics-catalog.md), each as the term that
//! models it, with a one-dimensional grid for the value the term cannot fit linearly (a
//! time constant, a delay, a saturation level, an offset).
//!
//! Auxiliary channels are used only when the recording has them. Each is first classified
//! from its data and its name ([`classify`]):
//!
//! - a copy of the input's rate (|corr(a, ẋ)| ≥ 0.9, e.g. the Dyke files' `V`): not a cause;
//! - a channel the input explains (R² ≥ [`FOLLOWS_R2`] of `a` on `x`, `x²`, `ẋ` and
//!   `tanh(ẋ/ε)`, e.g. a coil current next to its field, with eddy lag and remanence):
//!   what it could add is a function of the input, which the input's own candidates test
//!   by name; not a cause;
//! - the input's acceleration (|corr(a, ẍ)| ≥ 0.6, e.g. the Dyke files' `A`): the `inertia`
//!   regressor, measured instead of differentiated twice;
//! - a temperature (name `temp…`, `theta`, `oil`): the `thermal_drift` state;
//! - a speed (name `speed`, `omega`, `rpm`, `slip`, `w`): `slip_speed`, and its derivative
//!   for `inertia` (the output rotor's inertia seen by the torque sensor);
//! - anything else that varies (a coil current, a command voltage): `aux_dependence`.

use serde::Serialize;

use super::{augment::Fitted, augment::Term, transform::Transform};
use crate::ident::fit::Dataset;
use crate::numerics::log_spaced;
use crate::numerics::stats::{mean, min_max, std};

/// What an auxiliary channel was taken to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// A copy of the input's rate: not used.
    InputRate,
    /// Explained by the input and its rate: not used.
    FollowsInput,
    InputAcceleration,
    Temperature,
    Speed,
    Auxiliary,
    /// Constant, mostly missing, or the model's own command: not used.
    Unused,
}

/// An auxiliary channel and its role.
#[derive(Clone, Debug, Serialize)]
pub struct AuxChannel {
    pub name: String,
    pub role: Role,
    #[serde(skip)]
    pub values: Vec<f64>,
}

/// One candidate: its catalog effect, a label naming the channel it uses, the grid of its
/// nonlinear value and how to build the piece at each grid value.
pub struct Candidate {
    pub effect: &'static str,
    pub label: String,
    /// Name and unit of the grid value in the finding's params (`tau_s`, …); `None` when the
    /// candidate has no grid.
    pub grid_name: Option<String>,
    pub grid: Vec<f64>,
    /// Builds the piece at a grid value.
    pub build: Box<dyn Fn(f64) -> Piece + Sync + Send>,
    /// The auxiliary channel it uses, if any.
    pub channel: Option<String>,
}

/// What a candidate adds: an input transform and/or terms.
#[derive(Clone, Debug)]
pub struct Piece {
    pub transform: Option<Transform>,
    pub terms: Vec<Term>,
}

fn corr(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 3 {
        return 0.0;
    }
    let (ma, mb) = (a[..n].iter().sum::<f64>() / n as f64, b[..n].iter().sum::<f64>() / n as f64);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a[..n].iter().zip(&b[..n]) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

fn centred(v: &[f64]) -> Vec<f64> {
    let m = mean(v);
    v.iter().map(|a| a - m).collect()
}

/// The local excitation frequency relative to its mean, less 1: `f_loc/f̄ − 1`, with
/// `2π·f_loc` the RMS rate over the RMS level about the local mean, each a causal
/// first-order average over `window_s` (the fluid's damping can follow the excitation only
/// from what it has seen). 0 where the input rests. `2π·f_loc` is held below `cap` (rad/s),
/// the rate's band: at the first samples of a record starting in motion the level's power is
/// ~0 and the rate's is not, and the unbounded ratio (~10¹⁴⁶ on a bench recording) set `f̄`.
fn local_frequency(x: &[f64], dx: &[f64], dt: f64, window_s: f64, cap: f64) -> Vec<f64> {
    let average = |v: &[f64]| lowpass(v, window_s, dt);
    let level = average(x);
    let dev: Vec<f64> = x.iter().zip(&level).map(|(x, m)| (x - m) * (x - m)).collect();
    let (p_x, p_dx) = (average(&dev), average(&dx.iter().map(|d| d * d).collect::<Vec<f64>>()));
    let f: Vec<f64> =
        p_x.iter().zip(&p_dx).map(|(px, pd)| if *px > 0.0 { (pd / px).sqrt().min(cap) } else { 0.0 }).collect();
    let mean_f = mean(&f);
    if !(mean_f > 0.0 && mean_f.is_finite()) {
        return vec![0.0; x.len()];
    }
    f.iter().map(|v| if v.is_finite() { v / mean_f - 1.0 } else { 0.0 }).collect()
}

/// Averaging times (s) of the local excitation frequency a frequency-dependent damping is
/// tried with: from a tenth of a second to a few seconds (log grid, refined by the refit).
const FREQUENCY_WINDOWS_S: (f64, f64, usize) = (0.1, 3.0, 8);

/// The damping that grows with the local excitation frequency, `c·(f_loc/f̄ − 1)·ẋ`, its
/// averaging time the grid value.
fn frequency_damping(s: &InputStats) -> Candidate {
    let (x, dx, dt) = (s.x.clone(), s.dx.clone(), s.dt);
    let cap = 2.0 * std::f64::consts::PI * s.rate_band_hz;
    let (lo, hi, n) = FREQUENCY_WINDOWS_S;
    Candidate {
        effect: "rate_dependence",
        label: "damping growing with the excitation frequency".into(),
        grid_name: Some("window_s".into()),
        grid: log_spaced(lo, hi, n),
        build: Box::new(move |w| {
            let term = local_frequency(&x, &dx, dt, w, cap).iter().zip(&dx).map(|(f, d)| f * d).collect();
            Piece { transform: None, terms: vec![Term::additive("c_freq", term)] }
        }),
        channel: None,
    }
}

/// A causal first-order low-pass with time constant `tau_s` (0: unchanged).
fn lowpass(v: &[f64], tau_s: f64, dt: f64) -> Vec<f64> {
    Transform::Lag { tau_s }.apply(v, dt)
}

/// The input's rate and acceleration: the given ones, else the zero-phase offline ones.
pub fn rates(data: &Dataset) -> (Vec<f64>, Vec<f64>) {
    data.rates.clone().unwrap_or_else(|| crate::numerics::derivative::rates(&data.input, data.dt))
}

/// Correlation of `v` with the input's acceleration `ddx` beyond what the input `x` itself
/// explains (partial correlation given `x`). A channel that mostly follows the input (a
/// coil current next to its field) correlates with `ẍ` under a band-limited input only
/// through `x` (for a narrow band `ẍ ≈ −ω²x`); a measured acceleration keeps its correlation
/// once `x` is taken out. Falls back to the plain correlation when `ẍ` is `x` up to a
/// factor (a pure sine).
fn acceleration_corr(v: &[f64], x: &[f64], ddx: &[f64]) -> f64 {
    let (r_vd, r_vx, r_dx) = (corr(v, ddx), corr(v, x), corr(ddx, x));
    let den = ((1.0 - r_vx * r_vx) * (1.0 - r_dx * r_dx)).sqrt();
    if 1.0 - r_dx * r_dx < 1e-4 || den <= 1e-12 {
        r_vd
    } else {
        (r_vd - r_vx * r_dx) / den
    }
}

/// Classify the recording's auxiliary channels `aux` (name, values).
pub fn classify(data: &Dataset, aux: Vec<(String, Vec<f64>)>, command: Option<&str>) -> Vec<AuxChannel> {
    let (dx, ddx) = rates(data);
    aux.into_iter()
        .map(|(name, values)| {
            let finite = values.iter().filter(|v| v.is_finite()).count();
            let lower = name.to_lowercase();
            let role = if command == Some(name.as_str())
                || finite + finite / 50 < values.len()
                || std(&values) <= 1e-12 * mean(&values).abs().max(1e-300)
            {
                Role::Unused
            } else if corr(&values, &dx).abs() >= 0.9 {
                Role::InputRate
            } else if acceleration_corr(&values, &data.input, &ddx).abs() >= 0.6 {
                Role::InputAcceleration
            } else if explained_by_input(&values, &data.input, &dx) >= FOLLOWS_R2 {
                Role::FollowsInput
            } else if ["temp", "theta", "oil", "therm"].iter().any(|k| lower.contains(k)) {
                Role::Temperature
            } else if ["speed", "omega", "rpm", "slip"].iter().any(|k| lower.contains(k)) || lower == "w" {
                Role::Speed
            } else {
                Role::Auxiliary
            };
            // Non-finite entries (a channel logged on the first row only) are not used.
            let values = if role == Role::Unused { values } else { fill(values) };
            AuxChannel { name, role, values }
        })
        .collect()
}

/// Share of a channel's variance the input must explain for it to be taken as following
/// the input.
pub const FOLLOWS_R2: f64 = 0.98;

/// R² of `v` regressed on the input `x`, `x²`, its rate `dx` and `tanh(dx/ε)` (ε a tenth of
/// the rate's spread); 0 when the fit fails or `v` has non-finite entries.
fn explained_by_input(v: &[f64], x: &[f64], dx: &[f64]) -> f64 {
    if v.iter().any(|a| !a.is_finite()) {
        return 0.0;
    }
    let eps = 0.1 * std(dx).max(1e-300);
    let rows: Vec<[f64; 5]> = x.iter().zip(dx).map(|(x, d)| [1.0, *x, x * x, *d, (d / eps).tanh()]).collect();
    let Some(th) = crate::numerics::lstsq::fit_rows(&rows, v) else { return 0.0 };
    let res: Vec<f64> =
        rows.iter().zip(v).map(|(r, a)| a - r.iter().zip(&th).map(|(r, t)| r * t).sum::<f64>()).collect();
    let (sr, sv) = (std(&res), std(v));
    if sv > 0.0 {
        1.0 - (sr / sv).powi(2)
    } else {
        0.0
    }
}

/// Replace non-finite entries by the previous finite value.
fn fill(mut v: Vec<f64>) -> Vec<f64> {
    let mut last = v.iter().copied().find(|a| a.is_finite()).unwrap_or(0.0);
    for a in &mut v {
        if a.is_finite() {
            last = *a;
        } else {
            *a = last;
        }
    }
    v
}

/// The input's statistics the candidates' grids and terms are built from.
struct InputStats {
    dt: f64,
    x: Vec<f64>,
    dx: Vec<f64>,
    ddx: Vec<f64>,
    /// Largest |x|, the span of x and its mean.
    x_max: f64,
    x_span: f64,
    x_mean: f64,
    /// Standard deviation of the rate.
    dx_std: f64,
    /// The band the rate carries (Hz): where it was smoothed, else the estimator's top.
    rate_band_hz: f64,
}

impl InputStats {
    fn of(data: &Dataset, rate_band_hz: f64) -> Self {
        let x = data.input.clone();
        let (dx, ddx) = rates(data);
        let x_max = x.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        let x_span = {
            let (lo, hi) = min_max(&x);
            (hi - lo).max(1e-300)
        };
        let x_mean = mean(&x);
        let dx_std = std(&dx).max(1e-300);
        Self { dt: data.dt, x, dx, ddx, x_max, x_span, x_mean, dx_std, rate_band_hz }
    }
}

/// A candidate with one term and no grid.
fn additive(
    effect: &'static str,
    label: String,
    name: &'static str,
    v: Vec<f64>,
    channel: Option<String>,
) -> Candidate {
    Candidate {
        effect,
        label,
        grid_name: None,
        grid: vec![0.0],
        build: Box::new(move |_| Piece { transform: None, terms: vec![Term::additive(name, v.clone())] }),
        channel,
    }
}

/// Every candidate for this recording; `input_is_field`: the input is a magnetic field
/// (unit T), which has no mass, so `m·ẍ` of it is no inertia (a clutch's inertia shows
/// through a speed channel). `rate_band_hz`: where the input's rate was smoothed.
pub fn all(data: &Dataset, aux: &[AuxChannel], input_is_field: bool, rate_band_hz: f64) -> Vec<Candidate> {
    let s = InputStats::of(data, rate_band_hz);
    let mut out = input_transforms(&s);
    out.push(yield_saturation(data));
    out.extend(
        kinematic_terms(&s, aux)
            .into_iter()
            .filter(|c| !(input_is_field && c.effect == "inertia" && c.channel.is_none())),
    );
    out.extend(thermal(data, &s, aux));
    for c in aux.iter().filter(|a| a.role == Role::Speed) {
        out.extend(speed(&s, c));
    }
    for a in aux.iter().filter(|a| a.role == Role::Auxiliary) {
        out.push(auxiliary(&s, a));
    }
    out
}

/// Longest field lag tried (s): eddy currents in thick discs, or a coil's L/R behind a current input, reach 0.1–0.2 s.
const LAG_MAX_S: f64 = 0.3;
/// Phase (a first-order and a two-pole lag, 1 sample to [`LAG_MAX_S`], and a pure delay, ±30 ms, refitted to [`DELAY_BOX`] times it) and amplitude (a
/// saturating map and a zero offset): transforms of the input the base model is fed.
fn input_transforms(s: &InputStats) -> Vec<Candidate> {
    let dt = s.dt;
    let fs = 1.0 / dt;
    // ±30 ms (at least 4 samples), in at most 40 steps each way.
    let reach = (0.03 * fs).round().max(4.0);
    let stride = (reach / 40.0).ceil();
    let max_delay = (reach / stride).round();
    let delays: Vec<f64> =
        (-(max_delay as i64)..=max_delay as i64).filter(|k| *k != 0).map(|k| k as f64 * stride * dt).collect();
    let levels = log_spaced(0.6 * s.x_max, 6.0 * s.x_max, 10);
    let offsets: Vec<f64> = (-8..=8).filter(|k| *k != 0).map(|k| f64::from(k) * 0.01 * s.x_span).collect();
    vec![
        transform(
            "field_lag",
            "first-order lag of the input",
            "tau_s",
            log_spaced(dt, LAG_MAX_S.max(4.0 * dt), 20),
            |tau| Transform::Lag { tau_s: tau },
        ),
        transform(
            "field_lag",
            "two-pole lag of the input",
            "tau_s",
            log_spaced(2.0 * dt, LAG_MAX_S.max(8.0 * dt), 20),
            |tau| Transform::Lag2 { tau_s: tau },
        ),
        transform("transport_delay", "time shift between input and output", "delay_s", delays, |d| Transform::Delay {
            delay_s: d,
        }),
        transform("saturation", "saturating map of the input", "b_sat", levels.clone(), |b| Transform::Saturate {
            b_sat: b,
        }),
        transform("saturation", "saturating map of the input with a sharp knee", "b_sat", levels, |b| {
            Transform::SaturateKnee { b_sat: b }
        }),
        transform("sensor_offset", "zero offset of the input", "b_0", offsets, |b| Transform::Offset { b_0: b }),
    ]
}

/// Saturation on the output side: the fluid's yield stress levelling off at high field, so
/// the torque above its floor is compressed, `T_lo + u/√(1 + (u/T_s)²)` of the model's
/// `u = T − T_lo`, whatever the field did (the steel saturating is the input's map above).
/// `T_s` from 0.3 to 10 output spans; the term's coefficient is ≈ 1 for exactly that map.
fn yield_saturation(data: &Dataset) -> Candidate {
    let (lo, hi) = min_max(&data.output);
    let span = (hi - lo).max(1e-300);
    Candidate {
        effect: "saturation",
        label: "saturating torque at high level (yield stress)".into(),
        grid_name: Some("t_sat".into()),
        grid: log_spaced(0.3 * span, 10.0 * span, 12),
        build: Box::new(|t| Piece { transform: None, terms: vec![Term::output_saturation("k_sat", t)] }),
        channel: None,
    }
}

/// A candidate that feeds the base model the input through `make(g)`, `g` on `grid`.
fn transform(
    effect: &'static str,
    label: &str,
    grid_name: &str,
    grid: Vec<f64>,
    make: fn(f64) -> Transform,
) -> Candidate {
    Candidate {
        effect,
        label: label.into(),
        grid_name: Some(grid_name.into()),
        grid,
        build: Box::new(move |g| Piece { transform: Some(make(g)), terms: vec![] }),
        channel: None,
    }
}

/// Names of the direction terms' coefficients, `δ·(x − x̄)·sgn(ẋ)` and `δ₂·(x − x̄)²·sgn(ẋ)`
/// ([`super::physical`] judges their signs by these names).
pub const DIRECTION_TERM: &str = "delta";
pub const DIRECTION_SQUARED_TERM: &str = "delta2";
/// Name of the loading-branch term's coefficient, `δ_l·(x − x_min)·(1 + sgn(ẋ))/2`.
pub const LOADING_TERM: &str = "delta_loading";

/// Rate dependence in three shapes (`c·|ẋ|ẋ`, `c·ẋ³`, and a damping that grows with the
/// local excitation frequency, `c·(f_loc/f̄ − 1)·ẋ`: the catalog's α(f), beyond the linear
/// `c·ẋ` a base already has), direction in two shapes (`δ·(x − x̄)·sgn(ẋ)` and
/// `δ₂·(x − x̄)²·sgn(ẋ)`, the sign smoothed over 5 % of the rate's spread) and gated
/// (`δ_l·(x − x_min)·(1 + sgn(ẋ))/2`: the loading branch alone lifted, the catalog's
/// sigmoid-gated variant) and inertia (`m·ẍ`, from a measured acceleration when there is one).
fn kinematic_terms(s: &InputStats, aux: &[AuxChannel]) -> Vec<Candidate> {
    let rate_term: Vec<f64> = s.dx.iter().map(|v| v.abs() * v).collect();
    let cubed: Vec<f64> = s.dx.iter().map(|v| v * v * v).collect();
    let direction: Vec<f64> = s.dx.iter().map(|d| (d / (0.05 * s.dx_std)).tanh()).collect();
    let asym: Vec<f64> = s.x.iter().zip(&direction).map(|(x, d)| (x - s.x_mean) * d).collect();
    let asym2: Vec<f64> = s.x.iter().zip(&direction).map(|(x, d)| (x - s.x_mean).powi(2) * d).collect();
    let x_min = min_max(&s.x).0;
    let loading: Vec<f64> = s.x.iter().zip(&direction).map(|(x, d)| (x - x_min) * 0.5 * (1.0 + d)).collect();
    let acc = aux.iter().find(|a| a.role == Role::InputAcceleration);
    let (acc_values, acc_label, acc_channel) = match acc {
        Some(a) => {
            (centred(&a.values), format!("inertial term m·{} (measured acceleration)", a.name), Some(a.name.clone()))
        }
        None => (s.ddx.clone(), "inertial term m·ẍ of the input".into(), None),
    };
    vec![
        additive("rate_dependence", "term in |rate|·rate".into(), "c_rate", rate_term, None),
        additive("rate_dependence", "term in rate³".into(), "c_rate3", cubed, None),
        frequency_damping(s),
        additive("asymmetry", "loading/unloading difference growing with the input".into(), DIRECTION_TERM, asym, None),
        additive(
            "asymmetry",
            "loading/unloading difference growing with the input squared".into(),
            DIRECTION_SQUARED_TERM,
            asym2,
            None,
        ),
        additive("asymmetry", "loading branch lifted with the input".into(), LOADING_TERM, loading, None),
        additive("inertia", acc_label, "m", acc_values, acc_channel),
    ]
}

/// Thermal drift: a temperature channel scales the model (and shifts its offset); without
/// one, the dissipated energy does.
fn thermal(data: &Dataset, s: &InputStats, aux: &[AuxChannel]) -> Vec<Candidate> {
    let temps: Vec<&AuxChannel> = aux.iter().filter(|a| a.role == Role::Temperature).collect();
    let drift = |label: String, (kappa, offset): (&'static str, &'static str), v: Vec<f64>, channel| Candidate {
        effect: "thermal_drift",
        label,
        grid_name: None,
        grid: vec![0.0],
        build: Box::new(move |_| Piece {
            transform: None,
            terms: vec![Term::scaling(kappa, v.clone()), Term::additive(offset, v.clone())],
        }),
        channel,
    };
    if temps.is_empty() {
        let energy = {
            let mut e = 0.0;
            let p: Vec<f64> = data.output.iter().zip(&s.dx).map(|(y, d)| (y * d).abs()).collect();
            let mut v: Vec<f64> = p
                .iter()
                .map(|p| {
                    e += p * s.dt;
                    e
                })
                .collect();
            let last = v.last().copied().unwrap_or(1.0).max(1e-300);
            v.iter_mut().for_each(|a| *a /= last);
            centred(&v)
        };
        return vec![drift("drift with the dissipated energy".into(), ("kappa_energy", "offset_energy"), energy, None)];
    }
    temps
        .into_iter()
        .map(|t| {
            let label = format!("drift with the channel {} (a temperature)", t.name);
            drift(label, ("kappa_per_unit", "offset_per_unit"), centred(&t.values), Some(t.name.clone()))
        })
        .collect()
}

/// A speed channel: a viscous term in it (alone and times the input) and the inertia of
/// what it measures (`J·dω/dt`, the speed smoothed over 20 samples without delay).
fn speed(s: &InputStats, c: &AuxChannel) -> Vec<Candidate> {
    let dt = s.dt;
    let v = centred(&c.values);
    let vb: Vec<f64> = v.iter().zip(&s.x).map(|(v, x)| v * x / s.x_max).collect();
    let tau = 20.0 * dt / (2.0 * std::f64::consts::PI);
    let smooth = crate::models::alignment::shift(&lowpass(&c.values, tau, dt), tau / dt);
    let acc = crate::numerics::derivative::gradient(&smooth, dt);
    vec![
        Candidate {
            effect: "slip_speed",
            label: format!("viscous term in the channel {} (a speed)", c.name),
            grid_name: None,
            grid: vec![0.0],
            build: Box::new(move |_| Piece {
                transform: None,
                terms: vec![Term::additive("c_omega", v.clone()), Term::additive("c_omega_field", vb.clone())],
            }),
            channel: Some(c.name.clone()),
        },
        additive("inertia", format!("inertial term J·d{}/dt", c.name), "j", acc, Some(c.name.clone())),
    ]
}

/// Any other varying channel: the model's parameters scaled by it, through a first-order
/// lag whose time constant is the grid (0: none).
fn auxiliary(s: &InputStats, a: &AuxChannel) -> Candidate {
    let dt = s.dt;
    let raw = a.values.clone();
    let dx = s.dx.clone();
    let xc: Vec<f64> = s.x.iter().map(|v| v - s.x_mean).collect();
    let mut grid = vec![0.0];
    grid.extend(log_spaced(dt, (0.05f64).max(4.0 * dt), 10));
    Candidate {
        effect: "aux_dependence",
        label: format!("parameters scaled by {}", a.name),
        grid_name: Some("lag_s".into()),
        grid,
        build: Box::new(move |tau| {
            let u = centred(&lowpass(&raw, tau, dt));
            let udx: Vec<f64> = u.iter().zip(&dx).map(|(u, d)| u * d).collect();
            let ux: Vec<f64> = u.iter().zip(&xc).map(|(u, x)| u * x).collect();
            Piece {
                transform: None,
                terms: vec![
                    Term::scaling("alpha", u.clone()),
                    Term::additive("offset", u),
                    Term::additive("c_rate", udx),
                    Term::additive("k_input", ux),
                ],
            }
        }),
        channel: Some(a.name.clone()),
    }
}

/// How far past its grid's ends (±30 ms) a delay is refitted: one near them settles inside
/// the box, and only one running on past it is pinned at the edge ([`super::physical`]).
pub const DELAY_BOX: f64 = 1.5;

impl Candidate {
    /// The box its value is refitted in: its grid's ends, a delay's [`DELAY_BOX`] times them.
    pub fn bounds(&self) -> (f64, f64) {
        let k = if self.effect == "transport_delay" { DELAY_BOX } else { 1.0 };
        let lo = self.grid.iter().copied().fold(f64::INFINITY, f64::min);
        (k * lo, k * self.grid.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    }

    /// The transforms and terms of `current` with this candidate's piece at value `g` added.
    pub fn on_top(&self, current: &Fitted, g: f64) -> (Vec<Transform>, Vec<Term>) {
        let piece = (self.build)(g);
        let mut transforms = current.transforms.clone();
        transforms.extend(piece.transform);
        let mut terms = current.terms.clone();
        terms.extend(piece.terms);
        (transforms, terms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-tone input, its exact acceleration, a coil-current-like channel (the input plus
    /// a lead term) and a measured acceleration (the exact one plus noise).
    fn signals() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let (w1, w2, tau) = (std::f64::consts::TAU * 5.0, std::f64::consts::TAU * 7.0, 0.002);
        let t: Vec<f64> = (0..20_000).map(|k| k as f64 * 5e-4).collect();
        let x: Vec<f64> = t.iter().map(|t| (w1 * t).sin() + 0.5 * (w2 * t).sin()).collect();
        let dx: Vec<f64> = t.iter().map(|t| w1 * (w1 * t).cos() + 0.5 * w2 * (w2 * t).cos()).collect();
        let ddx: Vec<f64> = t.iter().map(|t| -w1 * w1 * (w1 * t).sin() - 0.5 * w2 * w2 * (w2 * t).sin()).collect();
        let current: Vec<f64> = x.iter().zip(&dx).map(|(x, d)| 0.3 + x + tau * d).collect();
        let accel: Vec<f64> = ddx
            .iter()
            .enumerate()
            .map(|(k, a)| a + 200.0 * ((k as f64 * 12.9898).sin() * 43758.5453).fract())
            .collect();
        (x, ddx, current, accel)
    }

    #[test]
    fn a_channel_following_the_input_is_not_its_acceleration() {
        let (x, ddx, current, accel) = signals();
        // Under a narrow band the plain correlation cannot tell them apart ...
        assert!(corr(&current, &ddx).abs() > 0.6, "{}", corr(&current, &ddx));
        assert!(corr(&accel, &ddx).abs() > 0.6);
        // ... the correlation beyond the input can.
        assert!(acceleration_corr(&current, &x, &ddx).abs() < 0.3, "{}", acceleration_corr(&current, &x, &ddx));
        assert!(acceleration_corr(&accel, &x, &ddx).abs() > 0.6, "{}", acceleration_corr(&accel, &x, &ddx));
    }

    /// A record starting in motion (a sine from phase 0, 4 Hz then 8 Hz): its first samples,
    /// held below the rate's band, leave the mean, and so the two halves, where they are.
    #[test]
    fn a_record_starting_at_full_rate_keeps_its_local_frequencies() {
        let dt = 5e-4;
        let (mut x, mut dx, mut phase) = (Vec::new(), Vec::new(), 0.0f64);
        for k in 0..16_000 {
            let w = std::f64::consts::TAU * if k < 8_000 { 4.0 } else { 8.0 };
            x.push(phase.sin());
            dx.push(w * phase.cos());
            phase += w * dt;
        }
        let f = local_frequency(&x, &dx, dt, 0.5, std::f64::consts::TAU * 60.0);
        let avg = |a: usize, b: usize| f[a..b].iter().sum::<f64>() / (b - a) as f64;
        let (slow, fast) = (avg(3_000, 8_000), avg(11_000, 16_000));
        // f̄ ≈ 6 Hz: 4/6 − 1 and 8/6 − 1, whatever the first samples were.
        assert!((slow + 1.0 / 3.0).abs() < 0.1 && (fast - 1.0 / 3.0).abs() < 0.1, "{slow} {fast}");
    }
}
