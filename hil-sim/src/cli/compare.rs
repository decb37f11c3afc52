use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use hil_sim::ident::compare::{compare, Named};
use hil_sim::ident::dataset::{prepare, Keeping};
use hil_sim::ident::fit::FitOptions;
use hil_sim::ident::runs::{from_manifest, RunSpec};
use hil_sim::io::manifest::Role;
use hil_sim::io::recording::Channels;
use serde_json::json;

use super::ChannelArgs;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Identification recordings (one per excitation frequency in seed 000's protocol).
    #[arg(long = "fit", required_unless_present = "dataset", num_args = 1..)]
    pub fit: Vec<PathBuf>,
    /// A dataset manifest instead: its `train` runs are the identification recordings, its
    /// `validate` runs the validation ones (each with its own channels and constants).
    #[arg(long, value_name = "TOML", conflicts_with_all = ["fit", "validate"])]
    pub dataset: Option<PathBuf>,
    /// Let the manifest's runs name files outside its folder (absolute paths, `..`).
    #[arg(long, requires = "dataset")]
    pub allow_outside: bool,
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

fn load(path: &std::path::Path, ch: &Channels, a: &CompareArgs, train: f64) -> anyhow::Result<Named> {
    let p = super::file_arg(path)?;
    let prepared = prepare(&p, ch, train, a.ch.keep_flagged, Keeping::DatasetOnly)?;
    for w in &prepared.quality.warnings {
        eprintln!("warning: {}", w.message);
    }
    let name = p.file_stem().map_or_else(|| p.display().to_string(), |s| s.to_string_lossy().into_owned());
    Ok(Named { name, data: prepared.data })
}

pub fn run(a: CompareArgs) -> anyhow::Result<()> {
    let models = super::fit::model_list(&a.model)?;
    let ch = a.ch.channels();
    let runs: Vec<RunSpec> = match &a.dataset {
        Some(m) => {
            let paths = match a.allow_outside {
                true => hil_sim::io::manifest::RunPaths::Anywhere,
                false => hil_sim::io::manifest::RunPaths::InsideFolder,
            };
            from_manifest(&super::file_arg(m)?, &ch, paths)?
        }
        None => {
            let run = |p: &PathBuf, role| RunSpec { path: p.clone(), channels: ch.clone(), role };
            a.fit.iter().map(|p| run(p, Role::Train)).chain(a.validate.iter().map(|p| run(p, Role::Validate))).collect()
        }
    };
    if !runs.iter().any(|r| r.role == Role::Train) {
        bail!("--fit: name at least one identification recording");
    }
    // Validation recordings are replayed whole; the split is irrelevant there.
    let load_role = |role: Role, train: f64| -> anyhow::Result<Vec<Named>> {
        runs.iter().filter(|r| r.role == role).map(|r| load(&r.path, &r.channels, &a, train)).collect()
    };
    let ident = load_role(Role::Train, a.train)?;
    let val = load_role(Role::Validate, 0.5)?;
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
