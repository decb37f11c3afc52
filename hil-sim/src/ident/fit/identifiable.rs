//! What the data cannot determine, said aloud (issue 16): a command-dependent term when the
//! command never changes over the training data, and a delay that ends at the edge of its
//! search range. Each is warned about by name and held at a sensible value (the model's
//! no-command form, a delay of zero) instead of being fitted into noise.

use super::Dataset;
use crate::models::alignment::MAX_DELAY_SAMPLES;
use crate::models::search::Scales;

/// The command's value when it is the same on every training sample (`None` without a
/// command channel or when it changes).
pub fn constant_command(data: &Dataset) -> Option<f64> {
    let u = data.command.as_ref()?;
    let rows = data.train_rows();
    let first = u.get(*rows.first()?)?;
    rows.iter().all(|&i| u.get(i) == Some(first)).then_some(*first)
}

/// The parameters of model `id` that the fit frees only when there is a command to drive
/// them (held at the model's no-command values otherwise).
pub fn command_terms(id: &str, scales: &Scales) -> Vec<&'static str> {
    let Some(host) = crate::models::host(id) else { return Vec::new() };
    let (Some(with), Some(without)) = (host.spec(scales, None), host.spec(&Scales { u: None, ..*scales }, None)) else {
        return Vec::new();
    };
    let held = without.free();
    with.free().into_iter().filter(|j| !held.contains(j)).filter_map(|j| with.params.get(j).map(|p| p.name)).collect()
}

/// The warning for a constant command, naming the held terms.
pub fn constant_command_warning(value: f64, terms: &[&str]) -> String {
    let held = if terms.is_empty() {
        String::new()
    } else {
        format!(
            "{} cannot be identified from one command level and are held at the model's no-command values; ",
            terms.join(", ")
        )
    };
    format!("the command never changes over the training data (always {value}): {held}no command delay is fitted")
}

/// The warning for model `id` on `data` when its command is the constant `value` (`None`: it changes).
pub fn constant_command_note(id: &str, data: &Dataset, value: Option<f64>) -> Option<String> {
    value.map(|v| constant_command_warning(v, &command_terms(id, &data.scales())))
}

/// Whether a delay of `d` samples sits at the edge of the search range.
pub fn at_edge(d: f64) -> bool {
    d.abs() >= MAX_DELAY_SAMPLES - 0.25
}

/// The warning for delays at the edge (`which`: "input", "command"), held at zero.
pub fn edge_warning(which: &[(&str, f64)], dt: f64) -> String {
    let list: Vec<String> =
        which.iter().map(|(name, d)| format!("the {name} delay ({:+.2} ms, {d:+.1} samples)", 1e3 * d * dt)).collect();
    format!(
        "{} ended at the edge of its search range (±{MAX_DELAY_SAMPLES} samples): the data do not determine it, so it \
         is held at 0 and the model refitted",
        list.join(" and ")
    )
}
