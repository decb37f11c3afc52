use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use hil_sim::dispatch::RateChoice;
use hil_sim::params_file::ParamsFile;
use hil_sim::recording::Recording;
use hil_sim::replay::{replay_recording, Channels};
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

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    let pf: ParamsFile = serde_json::from_str(SPENCER).context("bundled Spencer parameter file")?;
    let flat = pf.flat(std::path::Path::new("hil-sim/params/spencer_dyke_1997.json"))?;
    let ch = Channels { time: "t".into(), input: "D".into(), output: "F".into(), command: Some("Y".into()) };
    let mut replays = Vec::new();
    for file in ["dyke/ranran_50.csv", "dyke/ransim_u.csv"] {
        let path = hil_sim::data::data_file(file).map_err(anyhow::Error::msg)?;
        let rec = Recording::read_csv(&path)?;
        let r = replay_recording(&rec, &ch, &pf.model, &flat, RateChoice::Backward)
            .with_context(|| format!("replaying {}", path.display()))?;
        replays.push((file, r));
    }
    // The fixed-step core against f64 adaptive references (shortened runs; the full check
    // is `hil-sim accuracy`).
    let acc = super::accuracy::rows(&super::accuracy::AccuracyArgs {
        model: None,
        quick: true,
        no_recording: false,
        json: false,
    })?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let mut md = String::from("# hil-sim demo\n\n## Models (model-core, no_std, f32, fixed step)\n\n```\n");
    md += &super::models::table();
    md += "```\n\n## Replay of the real Dyke recordings with Spencer et al. 1997's published parameters\n\n";
    md += "| recording | samples | RMSE (N) | R-RMSE | R² | GOF |\n|---|---|---|---|---|---|\n";
    for (f, r) in &replays {
        let m = &r.metrics;
        md += &format!(
            "| {f} | {} | {:.1} | {:.2} % | {:.4} | {:.4} |\n",
            r.samples,
            m.rmse,
            100.0 * m.r_rmse,
            m.r2,
            m.gof
        );
    }
    md += "\n## Fixed-step f32 core vs f64 adaptive reference (R-RMSE of the difference; bound 0.5 %)\n\n";
    md += "| model | runs | worst R-RMSE | worst case |\n|---|---|---|---|\n";
    let mut ids: Vec<&str> = acc.iter().map(|r| r.model.as_str()).collect();
    ids.dedup();
    for id in ids {
        let rows: Vec<_> = acc.iter().filter(|r| r.model == id).collect();
        if let Some(w) = rows.iter().max_by(|a, b| a.r_rmse.total_cmp(&b.r_rmse)) {
            md += &format!(
                "| {id} | {} | {:.4} % | {}, {} at {:.0} Hz |\n",
                rows.len(),
                100.0 * w.r_rmse,
                w.params,
                w.excitation,
                w.fs_hz
            );
        }
    }
    md += "\nFull check: `cargo run --release -p hil-sim -- accuracy`.\n";
    let report = a.out.join("README.md");
    std::fs::write(&report, &md).with_context(|| format!("writing {}", report.display()))?;
    if a.json {
        let reps: Vec<_> = replays
            .iter()
            .map(|(f, r)| json!({"recording": f, "model": r.model, "samples": r.samples, "metrics": r.metrics}))
            .collect();
        let worst = acc.iter().map(|r| r.r_rmse).fold(0.0, f64::max);
        return super::print_json(&json!({
            "models": model_core::MODELS.iter().map(|m| m.id).collect::<Vec<_>>(),
            "replays": reps, "report": report,
            "accuracy": {"runs": acc.len(), "worst_r_rmse": worst, "failures": acc.iter().filter(|r| !r.pass).count()},
        }));
    }
    super::emit(&md);
    eprintln!("report written to {}", report.display());
    Ok(())
}
