//! Units of well-known channel names: the MR clutch contract's (`t`, `b`, `torque`, the
//! current `i`, …) and the Dyke damper files' (`D` cm, `F` N, `V` cm/s, `Y` V; see
//! shared/data/dyke/README.md). Used for axis labels and for levels in messages.

/// The unit of channel `name` (e.g. `"N·m"` for `torque`), `None` when the name is not a
/// well-known one.
pub fn unit_of(name: &str) -> Option<&'static str> {
    Some(match name {
        "t" | "time" => "s",
        "b" | "B" => "T",
        "torque" | "T" | "torque_true" => "N·m",
        "F" => "N",
        "D" => "cm",
        "V" => "cm/s",
        "Y" => "V",
        "i" | "i_ref" => "A",
        "speed" => "rad/s",
        "temperature" => "°C",
        _ => return None,
    })
}

/// `" <unit>"` to append to a level in a message (`"3.2 N·m"`), empty for an unknown name.
pub fn unit_suffix(name: &str) -> String {
    unit_of(name).map(|u| format!(" {u}")).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_and_unknown_names() {
        assert_eq!(unit_of("torque"), Some("N·m"));
        assert_eq!(unit_of("D"), Some("cm"));
        assert_eq!(unit_of("t"), Some("s"));
        assert_eq!(unit_of("x"), None);
        assert_eq!(unit_suffix("F"), " N");
        assert_eq!(unit_suffix("x"), "");
    }
}
