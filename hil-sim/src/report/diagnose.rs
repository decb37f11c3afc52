//! The diagnosis as a report section: the findings table (every value with its unit), the
//! base residual over time with the findings' windows shaded, the residual before and
//! after the findings' terms over the held-out stretch where they help most, and the error
//! per frequency band before and after (bands up to where the recording has content).

use std::path::Path;

use super::plot::{self, colour, PlotError, Series, Style};
use super::Report;
use crate::ident::diagnose::diagnosis::{Diagnosis, Finding, PlotData, Tested};
use crate::ident::diagnose::locate;
use crate::numerics::number::{num, with_unit};
use crate::numerics::units::unit_of;

/// Longest stretch the before/after residual plot shows, seconds.
const ZOOM_S: f64 = 0.5;
/// Length of the held-out loop shown, seconds.
const LOOP_S: f64 = 0.4;
/// Share of the measured output's power the frequency-band chart covers.
const BAND_POWER: f64 = 0.999;

/// Add the diagnosis to `rep`, its plots written to `dir` as `<stem>_*.svg`.
pub fn section(rep: &mut Report, dir: &Path, stem: &str, d: &Diagnosis, names: (&str, &str)) -> Result<(), PlotError> {
    let p = &d.plot;
    let out_unit = unit_of(names.1).unwrap_or("");
    let unit = |n: &str| unit_of(n).map(|u| format!(" ({u})")).unwrap_or_default();
    let yl = format!("{}{}", names.1, unit(names.1));
    let b = &d.base_heldout;
    // The fit alone and the reference the candidates were judged against, when they differ.
    let reference = d.reference_apart().map_or_else(String::new, |r| {
        format!(
            "; refitted until it stalls, the reference every candidate is judged against: R-RMSE {:.2} %, R² {:.4}",
            100.0 * r.r_rmse,
            r.r2
        )
    });
    rep.paragraph(&format!(
        "Base model **{}** (fitted on the first {:.0} % with the channels as recorded), held-out R-RMSE {:.2} %, \
         R² {:.4}{reference}; with every finding's term: R-RMSE {:.2} %, R² {:.4}. Residual noise floor {} (RMS); \
         diagnosed in {}.",
        d.base_model,
        100.0 * (1.0 - d.heldout_fraction),
        100.0 * b.r_rmse,
        b.r2,
        100.0 * d.final_heldout.r_rmse,
        d.final_heldout.r2,
        with_unit(d.locate.noise_rms, 4, out_unit),
        with_unit(d.seconds, 2, "s"),
    ));
    for n in &d.notes {
        rep.paragraph(&format!("Note: {n}."));
    }
    findings_table(rep, d);
    candidates_table(rep, d);

    let residual: Vec<f64> = p.output.iter().zip(&p.before).map(|(y, m)| y - m).collect();
    let mut windows: Vec<(f64, f64)> = d.findings.iter().flat_map(|f| f.windows.iter().copied()).collect();
    let shaded = if windows.is_empty() {
        windows = d.locate.windows.clone();
        "where the residual concentrates"
    } else {
        "where the findings bite"
    };
    let file = format!("{stem}_residual.svg");
    plot::residual_shaded(
        dir.join(&file),
        &format!("{} residual (base model) over the whole recording", d.base_model),
        &format!("residual{}", unit(names.1)),
        &p.time,
        &residual,
        (&windows, shaded),
        p.time.get(p.train_end).copied(),
    )?;
    rep.image(&file, &format!("Base model's residual over time; shaded: {shaded}."));
    if !d.findings.is_empty() {
        if let Some((a, b)) = best_stretch(p) {
            let file = format!("{stem}_residual_before_after.svg");
            let r = |m: &[f64]| -> Vec<f64> { (a..b).map(|i| p.output[i] - m[i]).collect() };
            let (r0, r1) = (r(&p.before), r(&p.after));
            plot::time_series(
                dir.join(&file),
                &format!("held-out residual before and after, {:.2}–{:.2} s", p.time[a], p.time[b - 1]),
                "time (s)",
                &format!("residual{}", unit(names.1)),
                &p.time[a..b],
                &[
                    Series::new("base model", &r0).style(Style::of(colour::BASELINE)),
                    Series::new("with the findings' terms", &r1).style(Style::of(colour::IMPROVED)),
                ],
            )?;
            rep.image(&file, "Residual on held-out data where the findings' terms lower it most.");
        }
    }
    let held = &p.heldout_rows;
    let pick = |v: &[f64]| -> Vec<f64> { held.iter().map(|&i| v[i]).collect() };
    let (x, y) = (pick(&p.input), pick(&p.output));
    let xl = format!("{}{}", names.0, unit(names.0));
    let file = format!("{stem}_loop.svg");
    let n = ((LOOP_S * p.fs) as usize).max(2);
    let last = |v: &[f64]| v[v.len().saturating_sub(n)..].to_vec();
    plot::hysteresis_loop(
        dir.join(&file),
        &format!("held-out loop (last {}), with the findings' terms", with_unit(LOOP_S, 2, "s")),
        &xl,
        &yl,
        &last(&x),
        &last(&y),
        &last(&pick(&p.after)),
    )?;
    rep.image(&file, "Held-out loop, measured (grey) and the model with the findings' terms.");
    band_chart(rep, dir, stem, p, &unit(names.1))
}

fn findings_table(rep: &mut Report, d: &Diagnosis) {
    if d.findings.is_empty() {
        rep.paragraph("**No finding:** no candidate of the catalog lowers the held-out error by more than chance.");
        return;
    }
    let rows: Vec<Vec<String>> = d
        .findings
        .iter()
        .enumerate()
        .map(|(k, f)| {
            vec![
                format!("{}", k + 1),
                format!("`{}`", f.effect),
                f.summary.clone(),
                f.params.iter().map(|(n, v)| format!("{n} = {}", value(f, n, *v))).collect::<Vec<_>>().join(", "),
                f.windows.iter().map(|(a, b)| format!("{a:.2}–{b:.2}")).collect::<Vec<_>>().join(", "),
                format!("{:.2} → {:.2}", 100.0 * f.heldout_before.r_rmse, 100.0 * f.heldout_after.r_rmse),
                format!("{:.1}", f.evidence.test.t),
            ]
        })
        .collect();
    rep.table(&["#", "effect", "what", "fitted values", "windows (s)", "held-out R-RMSE (%)", "t-statistic"], &rows);
}

fn candidates_table(rep: &mut Report, d: &Diagnosis) {
    let tested: Vec<Vec<String>> = d
        .candidates
        .iter()
        .map(|c| {
            vec![
                format!("{}", c.round),
                format!("`{}`", c.effect),
                match &c.value {
                    Some((n, v)) => format!("{} ({n} = {})", c.label, with_unit(*v, 4, grid_unit(d, n))),
                    None => c.label.clone(),
                },
                format!("{:.1}", c.bic_gain),
                format!("{:.2} → {:.2}", 100.0 * c.heldout_r_rmse_before, 100.0 * c.heldout_r_rmse_after),
                format!("{:.1}", c.test.t),
                c.acting
                    .map(|a| {
                        format!(
                            "tail sees {:.0} %; {:.2}–{:.2} s held out, interleaved: {:.0} % lower{}",
                            100.0 * a.tail_share,
                            a.from_s,
                            a.to_s,
                            100.0 * a.test.gain,
                            if a.passed { " (passed)" } else { "" }
                        )
                    })
                    .or_else(|| {
                        c.replication.map(|r| {
                            let p = if r.both.p_rank < 1e-4 {
                                "< 0.0001".to_owned()
                            } else {
                                format!("= {:.4}", r.both.p_rank)
                            };
                            format!(
                                "head {:.0} % lower; both p {p}{}",
                                100.0 * r.head.gain,
                                if r.passed { " (passed)" } else { "" }
                            )
                        })
                    })
                    .unwrap_or_default(),
                c.lag_or_delay
                    .map(|m| {
                        format!(
                            "least error at {:.0} % of the {} delay",
                            100.0 * m.best_share,
                            with_unit(1e3 * m.delay_s, 3, "ms")
                        )
                    })
                    .unwrap_or_default(),
                outcome(c),
            ]
        })
        .collect();
    rep.paragraph(&format!(
        "Every candidate tested, by round, by BIC gain (kept: of those that pass the held-out block test, the one with \
         the lowest held-out error; not possible: fitted values no physical cause has, never kept; a direction term \
         narrowing the loop as the input grows is read as a saturation). Reversed split: a \
         candidate the held-out tail left undecided, or close to another effect's, refitted with the first part of the \
         recording held out instead; its gain there and the signed-rank p \
         over the blocks of both held-out parts. When a round keeps nothing, a candidate the tail barely excites (it \
         changes the tail's prediction by less than {:.0} % of what it changes over the training part) is refitted \
         with the stretch where it acts most held out instead, in two interleaved halves: its share on the tail and \
         its gain on that stretch. Lag and delay together: a field lag and a delay of the torque close \
         on the held-out tail, the input given a share of the delay with the lag tuned on top; the share where the \
         training error is least names the effect (below half the lag, above it the delay):",
        100.0 * crate::ident::diagnose::acting::QUIET_TAIL
    ));
    let headers = [
        "round",
        "effect",
        "term",
        "BIC gain",
        "held-out R-RMSE (%)",
        "t-statistic",
        "second split",
        "lag and delay together",
        "kept or why not",
    ];
    rep.table(&headers, &tested);
}

/// The candidates table's last cell: kept, or why its fitted values rule it out.
fn outcome(c: &Tested) -> String {
    match (&c.impossible, c.kept) {
        (_, true) => "kept".into(),
        (Some(why), false) => format!("not possible: {why}"),
        (None, false) if c.named_before => format!("not kept: read as {}, named in an earlier round", c.effect),
        (None, false) => match c.zero_phase.filter(|z| !z.passed) {
            Some(z) => format!(
                "not kept: no better than the input smoothed without a lag's phase (τ = {:.3} ms): held-out RMSE {:.1} % {} than it, {:.0} % lower needed",
                1e3 * z.tau_s,
                100.0 * z.test.gain.abs(),
                if z.test.gain < 0.0 { "higher" } else { "lower" },
                100.0 * crate::ident::diagnose::significance::MIN_GAIN
            ),
            None if c.barred => {
                "not kept: another field lag of the round was no better than the input smoothed without its phase".into()
            }
            None => String::new(),
        },
    }
}

/// A finding's value with its unit: from the finding's `units`, else from the name's suffix.
fn value(f: &Finding, name: &str, v: f64) -> String {
    match f.units.get(name) {
        Some(u) => with_unit(v, 4, u),
        None => with_unit(v, 4, suffix_unit(name)),
    }
}

/// The unit of a candidate's grid value: as its finding would give it, else the name's suffix.
fn grid_unit<'a>(d: &'a Diagnosis, name: &str) -> &'a str {
    crate::ident::diagnose::describe::grid_unit(name, (&d.units.0, &d.units.1)).unwrap_or_else(|| suffix_unit(name))
}

/// The unit a parameter name carries in its suffix (`tau_s` → s), or `""`.
fn suffix_unit(name: &str) -> &'static str {
    match name.rsplit_once('_').map(|(_, s)| s) {
        Some("s") => "s",
        Some("ms") => "ms",
        Some("hz") => "Hz",
        Some("t") => "T",
        _ => "",
    }
}

/// The held-out stretch of at most [`ZOOM_S`] where the findings' terms lower the squared
/// residual most, as a sample range.
fn best_stretch(p: &PlotData) -> Option<(usize, usize)> {
    let start = *p.heldout_rows.first()?;
    let end = p.heldout_rows.last()? + 1;
    let w = ((ZOOM_S * p.fs) as usize).clamp(2, end.saturating_sub(start).max(2));
    let gain = |i: usize| (p.output[i] - p.before[i]).powi(2) - (p.output[i] - p.after[i]).powi(2);
    if end < start + w {
        return None;
    }
    let mut sum: f64 = (start..start + w).map(gain).sum();
    let (mut best, mut at) = (sum, start);
    for i in start + w..end {
        sum += gain(i) - gain(i - w);
        if sum > best {
            (best, at) = (sum, i + 1 - w);
        }
    }
    Some((at, at + w))
}

/// A band edge in Hz with no trailing zeros (`0.5`, `10`, `1500`).
fn hz(v: f64) -> String {
    let s = num(v, 3);
    if s.contains('.') && !s.contains('×') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// Held-out error per frequency band, before and after, over the bands that hold
/// [`BAND_POWER`] of the measured output's power (no bands above a lab filter's cut-off).
fn band_chart(rep: &mut Report, dir: &Path, stem: &str, p: &PlotData, unit: &str) -> Result<(), PlotError> {
    let held = &p.heldout_rows;
    let edges = locate::band_edges(p.fs);
    let band = |m: Option<&[f64]>| {
        let r: Vec<f64> = held.iter().map(|&i| p.output[i] - m.map_or(0.0, |m| m[i])).collect();
        locate::spectrum(&r, p.fs, &edges)
    };
    let measured = band(None);
    let total: f64 = measured.iter().map(|b| b.rms * b.rms).sum();
    let mut acc = 0.0;
    let keep = measured
        .iter()
        .position(|b| {
            acc += b.rms * b.rms;
            acc >= BAND_POWER * total
        })
        .map_or(measured.len(), |k| (k + 2).min(measured.len()));
    let (b0, b1) = (band(Some(&p.before)), band(Some(&p.after)));
    let cats: Vec<String> = b0.iter().take(keep).map(|b| format!("{}–{} Hz", hz(b.lo_hz), hz(b.hi_hz))).collect();
    let v0: Vec<f64> = b0.iter().take(keep).map(|b| b.rms).collect();
    let v1: Vec<f64> = b1.iter().take(keep).map(|b| b.rms).collect();
    let file = format!("{stem}_error_by_frequency.svg");
    plot::bars_coloured(
        dir.join(&file),
        "held-out error by frequency band",
        &format!("RMS error{unit}"),
        &cats,
        &[("base model", &v0, Some(colour::BASELINE)), ("with the findings' terms", &v1, Some(colour::IMPROVED))],
    )?;
    rep.image(
        &file,
        &format!(
            "Held-out error per frequency band, before and after (bands holding {:.1} % of the measured output's power).",
            100.0 * BAND_POWER
        ),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::diagnose::significance::Test;

    #[test]
    fn a_candidate_ruled_out_by_its_values_says_why_in_the_table() {
        let test = Test { t: 7.0, gain: 0.34, blocks_better: 10, blocks: 10, p_rank: 0.001, significant: true };
        let mut c = Tested {
            round: 1,
            effect: "asymmetry".into(),
            label: "loading/unloading difference growing with the input".into(),
            value: None,
            bic_gain: 21_000.0,
            heldout_r_rmse_before: 0.0355,
            heldout_r_rmse_after: 0.0235,
            test,
            change_of_noise: 13.5,
            tail_share: 1.0,
            kept: false,
            impossible: Some("a loop narrowing as the input grows (delta = -1.2)".into()),
            named_before: false,
            replication: None,
            lag_or_delay: None,
            acting: None,
            zero_phase: None,
            barred: false,
        };
        assert_eq!(outcome(&c), "not possible: a loop narrowing as the input grows (delta = -1.2)");
        c.impossible = None;
        assert_eq!(outcome(&c), "");
        c.zero_phase = Some(crate::ident::diagnose::zero_phase::Control {
            tau_s: 0.0021,
            test: Test { t: 1.2, gain: 0.012, blocks_better: 6, blocks: 10, p_rank: 0.2, significant: false },
            passed: false,
        });
        assert_eq!(
            outcome(&c),
            "not kept: no better than the input smoothed without a lag's phase (τ = 2.100 ms): held-out RMSE 1.2 % lower than it, 3 % lower needed"
        );
        c.zero_phase = None;
        c.barred = true;
        assert_eq!(
            outcome(&c),
            "not kept: another field lag of the round was no better than the input smoothed without its phase"
        );
        c.barred = false;
        c.named_before = true;
        c.effect = "saturation".into();
        assert_eq!(outcome(&c), "not kept: read as saturation, named in an earlier round");
        c.named_before = false;
        c.kept = true;
        assert_eq!(outcome(&c), "kept");
    }
}
