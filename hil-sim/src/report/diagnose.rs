//! The diagnosis as a report section: the findings table, the base residual over time
//! with the findings' windows shaded, the held-out loops before and after, and the error
//! per frequency band before and after.

use std::path::Path;

use crate::ident::diagnose::diagnosis::Diagnosis;
use crate::ident::diagnose::locate;
use crate::numerics::units::unit_of;
use crate::report::plot::{self, PlotError};
use crate::report::Report;

/// Add the diagnosis to `rep`, its plots written to `dir` as `<stem>_*.svg`.
pub fn section(rep: &mut Report, dir: &Path, stem: &str, d: &Diagnosis, names: (&str, &str)) -> Result<(), PlotError> {
    let p = &d.plot;
    let unit = |n: &str| unit_of(n).map(|u| format!(" ({u})")).unwrap_or_default();
    let (xl, yl) = (format!("{}{}", names.0, unit(names.0)), format!("{}{}", names.1, unit(names.1)));
    rep.paragraph(&format!(
        "Base model **{}** (fitted on the first {:.0} % with the channels as recorded), held-out R-RMSE {:.2} %, \
         R² {:.4}; with every finding's term: R-RMSE {:.2} %, R² {:.4}. Residual noise floor {:.4}{} RMS; {} s.",
        d.base_model,
        100.0 * (1.0 - d.heldout_fraction),
        100.0 * d.base_heldout.r_rmse,
        d.base_heldout.r2,
        100.0 * d.final_heldout.r_rmse,
        d.final_heldout.r2,
        d.locate.noise_rms,
        unit(names.1),
        format_args!("{:.1}", d.seconds)
    ));
    for n in &d.notes {
        rep.paragraph(&format!("Note: {n}."));
    }
    if d.findings.is_empty() {
        rep.paragraph("**No finding:** no candidate of the catalog lowers the held-out error by more than chance.");
    } else {
        let rows: Vec<Vec<String>> = d
            .findings
            .iter()
            .enumerate()
            .map(|(k, f)| {
                vec![
                    format!("{}", k + 1),
                    format!("`{}`", f.effect),
                    f.summary.clone(),
                    f.params
                        .iter()
                        .map(|(n, v)| match f.units.get(n).filter(|u| !u.is_empty()) {
                            Some(u) => format!("{n} = {v:.4e} {u}"),
                            None => format!("{n} = {v:.4e}"),
                        })
                        .collect::<Vec<_>>()
                        .join(", "),
                    f.windows.iter().map(|(a, b)| format!("{a:.2}–{b:.2}")).collect::<Vec<_>>().join(", "),
                    format!("{:.2} % → {:.2} %", 100.0 * f.heldout_before.r_rmse, 100.0 * f.heldout_after.r_rmse),
                    format!("{:.1}", f.evidence.test.t),
                ]
            })
            .collect();
        rep.table(&["#", "effect", "what", "fitted values", "windows (s)", "held-out R-RMSE", "t"], &rows);
    }
    let tested: Vec<Vec<String>> = d
        .candidates
        .iter()
        .map(|c| {
            vec![
                format!("{}", c.round),
                format!("`{}`", c.effect),
                match &c.value {
                    Some((n, v)) => format!("{} ({n} = {v:.4})", c.label),
                    None => c.label.clone(),
                },
                format!("{:.1}", c.bic_gain),
                format!("{:.2} % → {:.2} %", 100.0 * c.heldout_r_rmse_before, 100.0 * c.heldout_r_rmse_after),
                format!("{:.1}", c.test.t),
                if c.kept { "kept".into() } else { String::new() },
            ]
        })
        .collect();
    rep.paragraph("Every candidate tested, by round (kept: first by BIC gain that passes the held-out block test):");
    rep.table(&["round", "effect", "term", "BIC gain", "held-out R-RMSE", "t", ""], &tested);

    let residual: Vec<f64> = p.output.iter().zip(&p.before).map(|(y, m)| y - m).collect();
    let mut windows: Vec<(f64, f64)> = d.findings.iter().flat_map(|f| f.windows.iter().copied()).collect();
    if windows.is_empty() {
        windows = d.locate.windows.clone();
    }
    let file = format!("{stem}_residual.svg");
    plot::residual(
        dir.join(&file),
        &format!("{} residual (base model), windows shaded", d.base_model),
        &format!("residual{}", unit(names.1)),
        &p.time,
        &residual,
        &windows,
        p.time.get(p.train_end).copied(),
    )?;
    rep.image(&file, "Base model's residual over time; shaded: where the findings' terms bite (or, with no finding, where the residual concentrates).");
    let held = &p.heldout_rows;
    let pick = |v: &[f64]| -> Vec<f64> { held.iter().map(|&i| v[i]).collect() };
    let (x, y) = (pick(&p.input), pick(&p.output));
    for (tag, model, what) in [("before", &p.before, "base model"), ("after", &p.after, "with the findings' terms")] {
        let file = format!("{stem}_loop_{tag}.svg");
        plot::hysteresis_loop(dir.join(&file), &format!("held-out loop, {what}"), &xl, &yl, &x, &y, &pick(model))?;
        rep.image(&file, &format!("Held-out loop, {what}."));
    }
    let edges = locate::band_edges(p.fs);
    let band = |m: &[f64]| {
        let r: Vec<f64> = held.iter().map(|&i| p.output[i] - m[i]).collect();
        locate::spectrum(&r, p.fs, &edges)
    };
    let (b0, b1) = (band(&p.before), band(&p.after));
    let cats: Vec<String> = b0.iter().map(|b| format!("{:.1}–{:.0} Hz", b.lo_hz, b.hi_hz)).collect();
    let v0: Vec<f64> = b0.iter().map(|b| b.rms).collect();
    let v1: Vec<f64> = b1.iter().map(|b| b.rms).collect();
    let file = format!("{stem}_error_by_frequency.svg");
    plot::bars(
        dir.join(&file),
        "held-out error by frequency band",
        &format!("RMS error{}", unit(names.1)),
        &cats,
        &[("base model", v0), ("with findings", v1)],
    )?;
    rep.image(&file, "Held-out error per frequency band, before and after.");
    Ok(())
}
