use clap::Args;
use model_core::MODELS;
use serde_json::json;

#[derive(Args, Debug)]
pub struct ModelsArgs {
    /// Print one JSON object (`models: [{id, params, no_std, state_bytes}]`).
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: ModelsArgs) -> anyhow::Result<()> {
    if a.json {
        let models: Vec<_> = MODELS
            .iter()
            .map(|m| {
                json!({
                    "id": m.id, "params": m.params, "n_params": m.n_params,
                    "no_std": m.no_std, "state_bytes": m.state_bytes, "source": m.source,
                })
            })
            .collect();
        return super::print_json(&json!({ "models": models }));
    }
    super::emit(&table());
    Ok(())
}

/// The human-readable model table.
pub fn table() -> String {
    let mut s =
        format!("{:<19} {:>6} {:>11}  {:<52} {}\n", "model", "params", "state bytes", "source", "parameter names");
    for m in MODELS.iter() {
        let mut names = m.params.join(", ");
        if names.len() > 60 {
            names.truncate(57);
            names.push_str("...");
        }
        s += &format!("{:<19} {:>6} {:>11}  {:<52} {}\n", m.id, m.n_params, m.state_bytes, m.source, names);
    }
    s
}

/// The model table for a report: headers and one row per model, every parameter named.
pub fn rows() -> (Vec<String>, Vec<Vec<String>>) {
    let headers = ["model", "params", "state (B)", "source", "parameter names"].map(String::from).to_vec();
    let rows = MODELS
        .iter()
        .map(|m| {
            vec![
                m.id.to_owned(),
                m.n_params.to_string(),
                m.state_bytes.to_string(),
                m.source.to_owned(),
                m.params.join(", "),
            ]
        })
        .collect();
    (headers, rows)
}
