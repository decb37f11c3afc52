use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use hil_sim::closed_loop::{compare as loop_compare, identify, multisine_reference, Run, T_START};
use hil_sim::ident::dataset::{prepare, Dataset, Keeping, Prepared};
use hil_sim::ident::diagnose::Diagnosis;
use hil_sim::ident::fit::{FitOptions, FitResult};
use hil_sim::io::params_file::ParamsFile;
use hil_sim::io::recording::Channels;
use hil_sim::io::recording::Recording;
use hil_sim::models::replay::replay_recording;
use hil_sim::models::RateSpec;
use hil_sim::numerics::metrics::Metrics;
use hil_sim::report::fit::{error_bars, fit_plots, results_table, Labels};
use hil_sim::report::plot::{self, colour, Series, Style};
use hil_sim::report::Report;
use hil_sim::sim::plant::ClutchParams;
use serde_json::json;

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Folder the report is written to.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

/// Published parameter set shipped with the repository.
const SPENCER: &str = include_str!("../../params/spencer_dyke_1997.json");
/// The held-out split of the acceptance run (last 15 %).
const TRAIN: f64 = 0.85;

struct DykeFit {
    file: &'static str,
    path: PathBuf,
    rec: Recording,
    data: Dataset,
    results: Vec<FitResult>,
    warnings: Vec<String>,
}

fn dyke_channels() -> Channels {
    Channels { time: "t".into(), input: "D".into(), output: "F".into(), command: Some("Y".into()), set: Vec::new() }
}

fn fit_dyke(file: &'static str) -> anyhow::Result<DykeFit> {
    let path = hil_sim::io::bundled::data_file(file).map_err(anyhow::Error::msg)?;
    let Prepared { recording: rec, quality: q, data } =
        prepare(&path, &dyke_channels(), TRAIN, false, Keeping::Everything)?;
    let warnings: Vec<String> = q.warnings.iter().map(|w| w.message.clone()).collect();
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    let ids = super::fit::model_list("all")?;
    eprintln!("fitting {} models on {file}", ids.len());
    let results = super::fit::fit_all(&data, &ids, &FitOptions::default())?;
    Ok(DykeFit { file, path, rec, data, results, warnings })
}

fn loop_plots(rep: &mut Report, dir: &Path, lp: &Run, bl: &Run) -> anyhow::Result<()> {
    let k0 = lp.after(T_START + 1.0);
    let k1 = lp.after(T_START + 2.0);
    let t = &lp.t[k0..k1];
    plot::time_series(
        dir.join("loop_torque.svg"),
        "Closed loop on the simulated clutch, multi-sine torque reference (1–10 Hz)",
        "time (s)",
        "torque (N·m)",
        t,
        &[
            Series::new("reference", &lp.reference[k0..k1]).style(Style::of(colour::REFERENCE)),
            Series::new("estimate (Hall + model)", &lp.torque_est[k0..k1]).style(Style::of(colour::MODEL).width(1)),
            Series::new("true torque, closed loop", &lp.torque_true[k0..k1]).style(Style::of(colour::IMPROVED)),
            Series::new("true torque, open-loop baseline", &bl.torque_true[k0..k1]).style(Style::of(colour::BASELINE)),
        ],
    )?;
    rep.image(
        "loop_torque.svg",
        "reference, estimated and true torque; baseline: open-loop current through a static map",
    );
    plot::time_series(
        dir.join("loop_current.svg"),
        "Coil current",
        "time (s)",
        "current (A)",
        t,
        &[
            Series::new("closed loop", &lp.coil_current[k0..k1]).style(Style::of(colour::IMPROVED)),
            Series::new("open-loop baseline", &bl.coil_current[k0..k1]).style(Style::of(colour::BASELINE)),
        ],
    )?;
    rep.image("loop_current.svg", "coil current");
    plot::time_series(
        dir.join("loop_duty.svg"),
        "H-bridge duty",
        "time (s)",
        "duty (−1…1)",
        t,
        &[
            Series::new("closed loop", &lp.duty[k0..k1]).style(Style::of(colour::IMPROVED).width(1)),
            Series::new("open-loop baseline", &bl.duty[k0..k1]).style(Style::of(colour::BASELINE).width(1)),
        ],
    )?;
    rep.image("loop_duty.svg", "PWM duty of the bipolar H-bridge");
    Ok(())
}

/// 1. Identification of every model on the real Dyke recordings.
fn identification(rep: &mut Report, out: &Path, text: &mut String) -> anyhow::Result<Vec<DykeFit>> {
    let fits = vec![fit_dyke("dyke/ranran_50.csv")?, fit_dyke("dyke/ransim_u.csv")?];
    rep.heading("Identification on the real Dyke damper recordings");
    rep.paragraph(&format!(
        "Input D (cm), output F (N), command Y (V). Each model is fitted on the first {:.0} % (time-ordered) and \
         scored on the rest, with the f32 core the firmware runs. Samples flagged by the quality checks are left \
         out of the fit; the held-out metrics cover every held-out sample, and where some were flagged the \
         table also scores the unflagged ones.",
        100.0 * TRAIN
    ));
    for f in &fits {
        rep.heading_level(3, f.file);
        for w in &f.warnings {
            rep.paragraph(&format!("**Quality warning:** {}", hil_sim::report::relabel(w, &f.path)));
        }
        let labels = Labels { input: "D (cm)".into(), output: "F (N)".into() };
        results_table(rep, &f.results, &labels);
        let stem = f.file.trim_start_matches("dyke/").trim_end_matches(".csv").to_owned();
        error_bars(rep, out, &stem, &f.results)?;
        if let Some(best) = f.results.iter().min_by(|x, y| x.heldout.rmse.total_cmp(&y.heldout.rmse)) {
            rep.paragraph(&format!(
                "Best held-out: **{}**, fitted in {:.2} s. {}",
                best.model,
                best.fit_seconds,
                hil_sim::report::scores::heldout_note(&f.data, best, "F", "N")
            ));
            fit_plots(rep, out, &format!("{stem}_{}", best.model), &f.data, best, &labels)?;
        }
        *text += &format!("\n{} (fit on the first {:.0} %, scored on the rest)\n", f.file, 100.0 * TRAIN);
        *text += &super::fit::table(&f.results);
    }

    Ok(fits)
}

/// 2. The published Spencer set, replayed: the report's table and the JSON rows.
fn published_spencer(rep: &mut Report, fits: &[DykeFit]) -> anyhow::Result<Vec<serde_json::Value>> {
    let pf: ParamsFile = serde_json::from_str(SPENCER).context("bundled Spencer parameter file")?;
    let flat = pf.flat(Path::new("hil-sim/params/spencer_dyke_1997.json"))?;
    let mut rows = Vec::new();
    let mut replays = Vec::new();
    for f in fits {
        let r = replay_recording(f.rec.clone(), &dyke_channels(), &pf.model, &flat, RateSpec::Backward, (0.0, 0.0))?;
        let m = r.metrics;
        rows.push(vec![
            f.file.to_owned(),
            r.samples.to_string(),
            format!("{:.1}", m.rmse),
            format!("{:.4}", m.r2),
            format!("{:.2} %", 100.0 * m.r_rmse),
        ]);
        replays.push(json!({"recording": f.file, "metrics": m}));
    }
    rep.heading("Spencer et al. 1997's published set, replayed (whole recordings)");
    rep.table(&["recording", "samples", "RMSE (N)", "R²", "R-RMSE"], &rows);

    Ok(replays)
}

/// 3. The closed loop on the simulated clutch: tracking of the loop and of the baseline.
fn closed_loop(rep: &mut Report, out: &Path, text: &mut String) -> anyhow::Result<(Metrics, Metrics)> {
    eprintln!("closed loop on the simulated clutch (multi-sine reference)");
    let clutch = ClutchParams::default();
    let id = identify(&clutch, 10_000.0, 1).context("identifying the simulated clutch")?;
    let (lp, bl) = loop_compare(&id, &clutch, &multisine_reference(), T_START + 3.0, 0.0, 1)?;
    let (tl, tb) = (lp.tracking(T_START + 0.5), bl.tracking(T_START + 0.5));
    rep.heading("Closed loop on the simulated clutch (`hil-sim loop --scenario multisine`)");
    rep.paragraph(&format!(
        "Tracking R-RMSE of the true torque: closed loop (Hall + model estimate + PI) {:.2} %, open-loop baseline \
         {:.2} % ({:.1}× lower).",
        100.0 * tl.r_rmse,
        100.0 * tb.r_rmse,
        tb.r_rmse / tl.r_rmse.max(1e-12)
    ));
    loop_plots(rep, out, &lp, &bl)?;
    *text += &format!(
        "\nclosed loop, multi-sine: tracking R-RMSE {:.2} % vs open-loop baseline {:.2} %\n",
        100.0 * tl.r_rmse,
        100.0 * tb.r_rmse
    );

    Ok((tl, tb))
}

/// 4. A diagnosis: the damper file through a model that ignores the command voltage.
fn diagnosis(rep: &mut Report, out: &Path, text: &mut String) -> anyhow::Result<Diagnosis> {
    eprintln!("diagnosing ranran_50.csv from bouc_wen without the command channel");
    let diag_rec = hil_sim::io::bundled::data_file("dyke/ranran_50.csv").map_err(anyhow::Error::msg)?;
    let diag_ch = hil_sim::io::recording::Channels {
        time: "t".into(),
        input: "D".into(),
        output: "F".into(),
        command: None,
        set: Vec::new(),
    };
    let diag_opts = hil_sim::ident::diagnose::DiagnoseOptions {
        model: Some(<model_core::models::bouc_wen::Registered as model_core::Model>::ID.into()),
        heldout: 0.3,
        rate: None,
        seed: 1,
        max_findings: 3,
        ..Default::default()
    };
    let (diag, _) = super::diagnose::run_diagnosis(&diag_rec, &diag_ch, false, &diag_opts)?;
    rep.heading("Diagnosis: what Bouc–Wen misses on ranran_50.csv (`hil-sim diagnose --model bouc_wen`)");
    rep.paragraph(
        "The classical Bouc–Wen model has no command input, so it cannot know that the damper's force follows the \
         command voltage Y. `diagnose` is given D and F only; Y and A are auxiliary channels it may use.",
    );
    hil_sim::report::diagnose::section(rep, out, "diagnose_ranran50", &diag, ("D", "F"))?;
    *text += &format!("\ndiagnosis of ranran_50.csv from bouc_wen (no --command):\n{}", super::diagnose::text(&diag));

    Ok(diag)
}

/// 5. The fixed-step core against f64 references (short runs), and the models' table.
fn accuracy(rep: &mut Report) -> anyhow::Result<(usize, f64)> {
    let acc = super::accuracy::rows(None, true, false)?;
    let worst = acc.iter().map(|r| r.r_rmse).fold(0.0, f64::max);
    rep.heading("Fixed-step f32 core vs f64 adaptive references");
    rep.paragraph(&format!(
        "{} runs, worst R-RMSE {:.4} % (bound 0.5 %). Full check: `cargo run --release -p hil-sim -- accuracy`.",
        acc.len(),
        100.0 * worst
    ));
    rep.heading("Models (model-core, no_std, f32, fixed step)");
    let (headers, rows) = super::models::rows();
    rep.table(&headers, &rows);
    Ok((acc.len(), worst))
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let mut rep = Report::new("hil-sim demo: the MR clutch/damper toolchain on the bundled data");
    let mut text = String::new();
    let fits = identification(&mut rep, &a.out, &mut text)?;
    let replays = published_spencer(&mut rep, &fits)?;
    let (tl, tb) = closed_loop(&mut rep, &a.out, &mut text)?;
    let diag = diagnosis(&mut rep, &a.out, &mut text)?;
    let (acc_runs, worst) = accuracy(&mut rep)?;
    let index = rep.write(&a.out).with_context(|| format!("writing the report to {}", a.out.display()))?;

    if a.json {
        let fits_json: Vec<_> =
            fits.iter().map(|f| json!({"recording": f.file, "warnings": f.warnings, "results": f.results})).collect();
        return super::print_json(&json!({
            "fits": fits_json,
            "published_spencer": replays,
            "loop": {"tracking": tl, "baseline": tb},
            "diagnosis": diag,
            "accuracy": {"runs": acc_runs, "worst_r_rmse": worst},
            "report": index,
        }));
    }
    super::emit(&text);
    super::emit(&format!("\nreport: {}\n", index.display()));
    Ok(())
}
