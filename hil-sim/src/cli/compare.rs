use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use hil_sim::ident::compare::{compare, Named};
use hil_sim::ident::dataset::prepare;
use hil_sim::ident::fit::FitOptions;
use serde_json::json;

use super::ChannelArgs;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Identification recordings (one per excitation frequency in seed 000's protocol).
    #[arg(long = "fit", required = true, num_args = 1..)]
    pub fit: Vec<PathBuf>,
    /// Validation recordings (seed 000: multi-sine and swept sine), replayed whole with the
    /// averaged parameters.
    #[arg(long = "validate", num_args = 1..)]
    pub validate: Vec<PathBuf>,
    /// Model id, comma-separated list, or `all`.
    #[arg(long, default_value = "all")]
    pub model: String,
    /// Fraction of each identification recording used for fitting.
    #[arg(long, default_value_t = 0.7)]
    pub train: f64,
    #[command(flatten)]
    pub ch: ChannelArgs,
    #[arg(long)]
    pub json: bool,
}

fn load(path: &std::path::Path, a: &CompareArgs, train: f64) -> anyhow::Result<Named> {
    let p = super::file_arg(path)?;
    let prepared = prepare(&p, &a.ch.channels(), train, a.ch.keep_flagged)?;
    for w in &prepared.quality.warnings {
        eprintln!("warning: {}", w.message);
    }
    let name = p.file_stem().map_or_else(|| p.display().to_string(), |s| s.to_string_lossy().into_owned());
    Ok(Named { name, data: prepared.data })
}

pub fn run(a: CompareArgs) -> anyhow::Result<()> {
    let models = super::fit::model_list(&a.model)?;
    if a.fit.is_empty() {
        bail!("--fit: name at least one identification recording");
    }
    let ident = a.fit.iter().map(|p| load(p, &a, a.train)).collect::<anyhow::Result<Vec<_>>>()?;
    // Validation recordings are replayed whole; the split is irrelevant there.
    let val = a.validate.iter().map(|p| load(p, &a, 0.5)).collect::<anyhow::Result<Vec<_>>>()?;
    let opts = FitOptions { rate: a.ch.rate()?, ..Default::default() };
    let bar = super::progress::Bar::new((models.len() * ident.len()) as u64, "comparing");
    let c = compare(&ident, &val, &models, &opts, &bar)?;
    bar.finish();
    if a.json {
        return super::print_json(&json!(c));
    }
    super::emit("Table 1 analogue: held-out R-RMSE per identification recording\n");
    super::emit(&c.table_fits());
    super::emit("\nTable 2 analogue: averaged parameter sets\n");
    super::emit(&c.table_costs());
    if !c.validation.is_empty() {
        super::emit("\nTable 7 analogue: validation of the averaged sets\n");
        super::emit(&c.table_validation());
    }
    Ok(())
}
