//! Seed 000's comparison protocol for any set of recordings: fit every model on each
//! identification recording (one per excitation frequency in the paper), average each
//! model's parameters over those fits, and validate the averaged set on other recordings
//! (the paper's multi-sine and swept sine).
//!
//! The three tables it yields are the analogues of seed 000 Table 1 (R-RMSE per
//! recording and model), Table 2 (parameters, fit time, replay time per sample, state
//! bytes) and Table 7 (validation R-RMSE and R²).

use serde::Serialize;

use crate::ident::fit::{fit, Dataset, DelayChoice, FitError, FitOptions, FitResult};
use crate::ident::own_runs::{self, OwnRunsCheck};
use crate::io::params_file::{ParamsFile, Values};
use crate::models::replay;
use crate::numerics::metrics::{metrics, Metrics};
use crate::progress::Progress;

/// A named dataset (the name is what the tables print, e.g. the file stem).
#[derive(Clone, Debug)]
pub struct Named {
    pub name: String,
    pub data: Dataset,
}

/// Table 1: one model fitted on one recording.
#[derive(Clone, Debug, Serialize)]
pub struct PerRecording {
    pub recording: String,
    pub model: String,
    pub heldout: Metrics,
    pub fit_seconds: f64,
}

/// Table 2: one model's averaged parameters and costs.
#[derive(Clone, Debug, Serialize)]
pub struct Averaged {
    pub model: String,
    pub params: Values,
    pub n_params: usize,
    pub state_bytes: usize,
    /// Mean fit time over the identification recordings.
    pub fit_seconds: f64,
    /// Mean f32 replay time per sample, nanoseconds.
    pub replay_ns_per_sample: f64,
    /// Whether the averaged set is valid: a parameter set of the model (averaging can leave
    /// the admissible region; then the model is not validated) that is not worse than the
    /// recordings' own fits by more than chance on the recordings it came from.
    pub valid: bool,
    /// The averaged set on its own recordings ([`crate::ident::own_runs`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub own_runs: Option<OwnRunsCheck>,
    /// Why the set is not valid, in words (`None` when it is).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_valid: Option<String>,
    #[serde(skip)]
    pub flat: Vec<f64>,
    #[serde(skip)]
    pub rate: crate::models::RateSpec,
}

/// Table 7: one averaged model on one validation recording (whole recording).
#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    pub recording: String,
    pub model: String,
    pub metrics: Metrics,
}

/// The whole comparison.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub fits: Vec<PerRecording>,
    pub averaged: Vec<Averaged>,
    pub validation: Vec<Validation>,
}

/// Run the protocol. `progress` is called once per finished fit. The channels are taken as
/// recorded (no fitted delay, whatever `opts.delay` says): parameters are averaged across
/// recordings, and a per-recording alignment has no average that means anything.
pub fn compare(
    identify: &[Named],
    validate: &[Named],
    models: &[String],
    opts: &FitOptions,
    progress: &dyn Progress,
) -> Result<Comparison, FitError> {
    let opts = &FitOptions { delay: DelayChoice::Off, ..*opts };
    let mut fits = Vec::new();
    let mut averaged = Vec::new();
    progress.stage("comparing", (models.len() * identify.len()) as u64);
    for id in models {
        let mut results: Vec<FitResult> = Vec::with_capacity(identify.len());
        for rec in identify {
            let r = fit(id, &rec.data, opts)?;
            progress.message(&format!("{id} on {}", rec.name));
            progress.advance(1);
            fits.push(PerRecording {
                recording: rec.name.clone(),
                model: id.clone(),
                heldout: r.heldout,
                fit_seconds: r.fit_seconds,
            });
            results.push(r);
        }
        let Some(first) = results.first() else { continue };
        let n = results.len() as f64;
        let mut flat = vec![0.0; first.flat.len()];
        for r in &results {
            for (a, b) in flat.iter_mut().zip(&r.flat) {
                *a += b / n;
            }
        }
        let flat32: Vec<f32> = flat.iter().map(|v| *v as f32).collect();
        let admissible =
            crate::ident::fit::simulate::simulator(id, identify.first().map_or(1e-3, |r| r.data.dt) as f32)
                .is_some_and(|s| s.valid(&flat));
        let own = if admissible { on_own_runs(id, &flat32, first.rate_choice, identify, &results)? } else { None };
        let not_valid = if !admissible {
            Some("the averaged set is not a valid parameter set of the model".to_owned())
        } else {
            own.as_ref().filter(|c| c.worse).map(|c| {
                format!(
                    "on the held-out parts of its own recordings the averaged set scores RMSE {:.4} against {:.4} \
                     for their own fits ({:.1} standard errors, more than chance): the per-recording fits \
                     compensate each other and their average is not a model of the device",
                    c.averaged_rmse, c.own_rmse, c.z
                )
            })
        };
        let valid = not_valid.is_none();
        averaged.push(Averaged {
            model: id.clone(),
            params: ParamsFile::from_flat(id, None, &flat32).map_or(Values::Flat(flat.clone()), |f| f.params),
            n_params: first.n_params,
            state_bytes: first.state_bytes,
            fit_seconds: results.iter().map(|r| r.fit_seconds).sum::<f64>() / n,
            replay_ns_per_sample: results.iter().map(|r| r.replay_ns_per_sample).sum::<f64>() / n,
            valid,
            own_runs: own,
            not_valid,
            flat,
            rate: first.rate_choice,
        });
    }
    let mut validation = Vec::new();
    // An inadmissible set cannot run; a set worse on its own runs is still scored (and marked).
    for a in averaged.iter().filter(|a| a.valid || a.own_runs.is_some()) {
        for rec in validate {
            let d = &rec.data;
            let p32: Vec<f32> = a.flat.iter().map(|v| *v as f32).collect();
            let rep = replay(&a.model, &p32, d.dt as f32, a.rate, &d.samples())
                .map_err(|e| FitError::Replay { model: a.model.clone(), reason: e.to_string() })?;
            let y: Vec<f64> = rep.y.iter().map(|v| f64::from(*v)).collect();
            validation.push(Validation {
                recording: rec.name.clone(),
                model: a.model.clone(),
                metrics: metrics(&d.output, &y, None),
            });
        }
    }
    Ok(Comparison { fits, averaged, validation })
}

/// The averaged set `p` replayed on the identification recordings, against their own fits.
fn on_own_runs(
    id: &str,
    p: &[f32],
    rate: crate::models::RateSpec,
    identify: &[Named],
    fits: &[FitResult],
) -> Result<Option<OwnRunsCheck>, FitError> {
    let mut avg = Vec::with_capacity(identify.len());
    for rec in identify {
        let d = &rec.data;
        let rep = crate::models::replay::replay_runs(id, p, d.dt as f32, rate, &d.samples(), &d.run_starts())
            .map_err(|e| FitError::Replay { model: id.to_owned(), reason: e.to_string() })?;
        avg.push(rep.y.iter().map(|v| f64::from(*v)).collect::<Vec<f64>>());
    }
    let parts: Vec<own_runs::Part<'_>> = identify
        .iter()
        .zip(fits)
        .zip(&avg)
        .map(|((rec, f), a)| (rec.data.output.as_slice(), f.output.as_slice(), a.as_slice(), rec.data.heldout_rows()))
        .collect();
    Ok(own_runs::check(&parts))
}

impl Comparison {
    /// Table 1 as text: held-out R-RMSE (%) per identification recording (rows) and model.
    pub fn table_fits(&self) -> String {
        let models = self.models();
        let mut recs: Vec<&str> = Vec::new();
        for f in &self.fits {
            if !recs.contains(&f.recording.as_str()) {
                recs.push(&f.recording);
            }
        }
        let mut s = format!("{:<24}", "R-RMSE % (held-out)");
        for m in &models {
            s += &format!(" {m:>14}");
        }
        s.push('\n');
        for r in recs {
            s += &format!("{r:<24}");
            for m in &models {
                let v = self.fits.iter().find(|f| f.recording == r && &f.model == m).map(|f| 100.0 * f.heldout.r_rmse);
                s += &v.map_or(format!(" {:>14}", "-"), |v| format!(" {v:>14.2}"));
            }
            s.push('\n');
        }
        s
    }

    /// Table 2 as text.
    pub fn table_costs(&self) -> String {
        let mut s = format!(
            "{:<20} {:>8} {:>12} {:>12} {:>12} {:>8}\n",
            "model", "params", "fit s (mean)", "ns/sample", "state bytes", "valid"
        );
        for a in &self.averaged {
            s += &format!(
                "{:<20} {:>8} {:>12.3} {:>12.1} {:>12} {:>8}\n",
                a.model,
                a.n_params,
                a.fit_seconds,
                a.replay_ns_per_sample,
                a.state_bytes,
                if a.valid { "yes" } else { "no" }
            );
        }
        for a in self.averaged.iter() {
            if let Some(why) = &a.not_valid {
                s += &format!("{}: not valid: {why}\n", a.model);
            }
        }
        s
    }

    /// Table 7 as text: validation R-RMSE (%) and R² of the averaged sets.
    pub fn table_validation(&self) -> String {
        let mut s = format!("{:<20} {:<24} {:>10} {:>10} {:>12}\n", "model", "validation", "R-RMSE %", "R²", "RMSE");
        for v in &self.validation {
            s += &format!(
                "{:<20} {:<24} {:>10.2} {:>10.4} {:>12.4}\n",
                v.model,
                v.recording,
                100.0 * v.metrics.r_rmse,
                v.metrics.r2,
                v.metrics.rmse
            );
        }
        s
    }

    fn models(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for f in &self.fits {
            if !out.contains(&f.model) {
                out.push(f.model.clone());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::fit::simulate::{kinematics, simulator};
    use crate::io::recording::Channels;
    use crate::io::recording::{Column, Recording};
    use crate::models::RateSpec;
    use crate::sim::excitation::Excitation;
    use std::path::Path;

    /// A recording of a known Bouc–Wen clutch driven by a sine of `f` Hz.
    fn recording(f: f64, truth: &[f64]) -> Dataset {
        let dt = 1e-3;
        let n = (3.0 / f).max(2.0) as usize * 1000;
        let s = Excitation::Sine { f };
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let x: Vec<f64> = t.iter().map(|t| s.at(*t).x).collect();
        let samples: Vec<model_core::Sample> = x.iter().map(|v| model_core::Sample::new(*v as f32)).collect();
        let kin = kinematics(&samples, dt as f32, RateSpec::Backward).unwrap();
        let mut y = vec![0.0; n];
        assert!(simulator("bouc_wen", dt as f32).unwrap().run(truth, &kin, &mut y));
        let rec = Recording::from_columns(
            Path::new("synthetic.csv"),
            vec![
                Column { name: "t".into(), values: t },
                Column { name: "b".into(), values: x },
                Column { name: "torque".into(), values: y },
            ],
            vec![],
        );
        Dataset::new(&rec, &Channels::default(), 0.7, None).unwrap()
    }

    #[test]
    fn protocol_recovers_a_known_model_and_validates_it() {
        let truth = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
        let ident: Vec<Named> =
            [1.0, 3.0].iter().map(|f| Named { name: format!("sine {f} Hz"), data: recording(*f, &truth) }).collect();
        let val = vec![Named { name: "sine 2 Hz".into(), data: recording(2.0, &truth) }];
        let models = vec!["bouc_wen".to_owned(), "algebraic".to_owned()];
        // The truth was generated with backward differences: fit with the same estimator, and
        // let the solver converge on noiseless data.
        let opts = FitOptions {
            rate: Some(RateSpec::Backward),
            lm_iterations: 30,
            polish_iterations: 30,
            ..FitOptions::default()
        };
        struct Count(std::sync::atomic::AtomicU64);
        impl Progress for Count {
            fn advance(&self, n: u64) {
                self.0.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
            }
        }
        let calls = Count(std::sync::atomic::AtomicU64::new(0));
        let c = compare(&ident, &val, &models, &opts, &calls).unwrap();
        assert_eq!(calls.0.into_inner(), 4);
        assert_eq!(c.fits.len(), 4);
        assert_eq!(c.averaged.len(), 2);
        let bw = c.validation.iter().find(|v| v.model == "bouc_wen").unwrap();
        let alg = c.validation.iter().find(|v| v.model == "algebraic").unwrap();
        // The true model structure validates almost perfectly, and better than the algebraic one.
        assert!(bw.metrics.r_rmse < 0.01, "{:?}", bw.metrics);
        assert!(alg.metrics.r_rmse > bw.metrics.r_rmse);
        assert!(c.table_fits().contains("sine 3 Hz") && c.table_validation().contains("bouc_wen"));
    }
}
