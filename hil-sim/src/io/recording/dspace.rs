//! dSPACE ControlDesk recordings: one struct variable holding the time in `X` and the
//! signals in the struct array `Y`, each `Y(k)` with its `Name` and `Data` (the layout
//! the clutch paper's dSPACE rig writes). `X` is either the time vector itself or, as
//! ControlDesk writes it, a struct whose `Data` is.
//!
//! Each signal becomes a variable named after the last part of its `Name` (ControlDesk
//! names signals by their model path, `Model Root/Plant/"torque"`); the time is the
//! channel `X`.

use super::mat::{Kind, Variable};

/// The struct's fields as signals, or `None` when it is not a ControlDesk recording.
pub(super) fn signals(fields: &[String], elements: &[Vec<Variable>]) -> Option<Vec<Variable>> {
    let first = elements.first()?;
    let field = |name: &str| fields.iter().position(|f| f == name).and_then(|i| first.get(i));
    let (x, y) = (field("X")?, field("Y")?);
    let mut out = Vec::new();
    let time = match &x.kind {
        Kind::Numeric(_) => x,
        Kind::Struct { fields, elements } => data(fields, elements.first()?)?,
        _ => return None,
    };
    out.push(Variable { name: "X".into(), dims: time.dims.clone(), kind: clone_numeric(&time.kind)? });
    let Kind::Struct { fields, elements } = &y.kind else { return None };
    for (k, e) in elements.iter().enumerate() {
        let Some(d) = data(fields, e) else { continue };
        let name = fields
            .iter()
            .position(|f| f == "Name")
            .and_then(|i| e.get(i))
            .and_then(|v| match &v.kind {
                Kind::Text(t) => Some(signal_name(t)),
                _ => None,
            })
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| format!("Y{}", k + 1));
        out.push(Variable { name, dims: d.dims.clone(), kind: clone_numeric(&d.kind)? });
    }
    Some(out)
}

/// The `Data` field of one struct element.
fn data<'a>(fields: &[String], element: &'a [Variable]) -> Option<&'a Variable> {
    fields.iter().position(|f| f == "Data").and_then(|i| element.get(i))
}

fn clone_numeric(k: &Kind) -> Option<Kind> {
    match k {
        Kind::Numeric(v) => Some(Kind::Numeric(v.clone())),
        _ => None,
    }
}

/// `Model Root/Plant/"torque"` → `torque`.
fn signal_name(full: &str) -> String {
    full.rsplit('/').next().unwrap_or(full).trim().trim_matches('"').trim().to_owned()
}

#[cfg(test)]
mod tests {
    #[test]
    fn signal_names_drop_the_model_path() {
        assert_eq!(super::signal_name("Model Root/Plant/\"torque\""), "torque");
        assert_eq!(super::signal_name("speed"), "speed");
    }
}
