//! Auxiliary channels the diagnosis must not use: a channel named as the truth (`*_true`,
//! `true_*`, as simulated recordings carry it) or one that is (nearly) a copy of the output
//! explains the output trivially, and a finding "the torque depends on `torque_true`"
//! says nothing about the clutch.

use serde::Serialize;

use crate::numerics::stats::mean;

/// |correlation| with the output at or above which a channel counts as a copy of it.
pub const COPY_CORRELATION: f64 = 0.99;

/// An auxiliary channel left out, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Dropped {
    pub name: String,
    pub reason: String,
}

/// Whether `name` says the channel is the concealed truth.
fn named_as_truth(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    n.ends_with("_true") || n.starts_with("true_") || n == "truth" || n.ends_with("_truth")
}

/// Pearson correlation of two equally long series (0 when either is constant).
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let (ma, mb) = (mean(a), mean(b));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (dx, dy) = (x - ma, y - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

/// Split `aux` into the channels the diagnosis may use and those it must not; the
/// command channel (`command`) is always kept.
pub fn screen(
    aux: Vec<(String, Vec<f64>)>,
    output: &[f64],
    command: Option<&str>,
) -> (Vec<(String, Vec<f64>)>, Vec<Dropped>) {
    let mut kept = Vec::new();
    let mut dropped = Vec::new();
    for (name, values) in aux {
        if Some(name.as_str()) == command {
            kept.push((name, values));
            continue;
        }
        let r = correlation(&values, output);
        let reason = if named_as_truth(&name) {
            Some("its name marks it as the simulated truth".to_owned())
        } else if r.abs() >= COPY_CORRELATION {
            Some(format!("it is nearly a copy of the output (correlation {r:.4})"))
        } else {
            None
        };
        match reason {
            Some(reason) => dropped.push(Dropped { name, reason }),
            None => kept.push((name, values)),
        }
    }
    (kept, dropped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truth_and_copies_are_dropped_the_rest_kept() {
        let y: Vec<f64> = (0..200).map(|k| (f64::from(k) * 0.1).sin()).collect();
        let temp: Vec<f64> = (0..200).map(|k| 20.0 + f64::from(k) * 0.01).collect();
        let aux = vec![
            ("torque_true".to_owned(), temp.clone()),
            ("torque2".to_owned(), y.iter().map(|v| 2.0 * v + 1.0).collect()),
            ("temperature".to_owned(), temp.clone()),
            ("Y".to_owned(), y.clone()),
        ];
        let (kept, dropped) = screen(aux, &y, Some("Y"));
        let names: Vec<&str> = kept.iter().map(|k| k.0.as_str()).collect();
        assert_eq!(names, ["temperature", "Y"]);
        assert_eq!(dropped.iter().map(|d| d.name.as_str()).collect::<Vec<_>>(), ["torque_true", "torque2"]);
        assert!(dropped[1].reason.contains("copy"));
    }
}
