//! A board's session again, through the bench `hil-sim loop` runs: the journal a virtual
//! board writes (`K ref V`, `K enable 0|1`, `K reset`, `K page CRC`: what it
//! applied from sample K on) replayed sample by sample on [`rig`](super::rig) with the
//! firmware's own controller (`firmware::runner::Loop`, built by the configuration store's
//! `runnable`, the function the board commits with): the compiled-in configuration until
//! the journal's `page` event, then the page given. Same plant seed, same scenario, same
//! core: the same f32 numbers as the board's telemetry.

use firmware::application::store::runnable;
use firmware::runner::Loop;
use model_core::control::{ConfigImage, PageError, ValidatedConfig};
use thiserror::Error;

use super::rig::{Command, Rig};
use super::Schedule;
use crate::sim::plant::ClutchParams;

/// What the board applied from one sample on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Applied {
    /// Torque reference, N·m.
    Reference(f32),
    Enable(bool),
    /// A latched fault cleared (this sample only).
    Reset,
    /// A committed page (its CRC) swapped in before this sample.
    Page(u32),
}

/// One journal line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    /// Sample index.
    pub k: usize,
    pub applied: Applied,
}

#[derive(Debug, Error)]
pub enum ReplayError {
    #[error("journal line {line}: `{text}`: expected `K ref V`, `K enable 0|1`, `K reset` or `K page CRC`")]
    Line { line: usize, text: String },
    #[error("journal line {line}: sample {k} comes before sample {before}")]
    Order { line: usize, k: usize, before: usize },
    #[error("the journal swaps in page {journal:#010x} at sample {k}, the parameters give page {given:#010x}")]
    OtherPage { k: usize, journal: u32, given: u32 },
    #[error("the page is refused: {0}")]
    Page(#[from] PageError),
}

/// Parse a journal.
pub fn parse_journal(text: &str) -> Result<Vec<Event>, ReplayError> {
    let mut out: Vec<Event> = Vec::new();
    for (i, l) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let bad = || ReplayError::Line { line: i + 1, text: l.to_owned() };
        let w: Vec<&str> = l.split_whitespace().collect();
        let k: usize = w.first().and_then(|k| k.parse().ok()).ok_or_else(bad)?;
        let applied = match (w.get(1).copied(), w.get(2).copied()) {
            (Some("ref"), Some(v)) => Applied::Reference(v.parse().map_err(|_| bad())?),
            (Some("enable"), Some("0")) => Applied::Enable(false),
            (Some("enable"), Some("1")) => Applied::Enable(true),
            (Some("reset"), None) => Applied::Reset,
            (Some("page"), Some(v)) => {
                Applied::Page(u32::from_str_radix(v.trim_start_matches("0x"), 16).map_err(|_| bad())?)
            }
            _ => return Err(bad()),
        };
        if let Some(before) = out.last().map(|e| e.k).filter(|b| *b > k) {
            return Err(ReplayError::Order { line: i + 1, k, before });
        }
        out.push(Event { k, applied });
    }
    Ok(out)
}

/// One replayed sample.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// s since the board started.
    pub t: f64,
    /// N·m, as applied.
    pub reference: f32,
    /// The controller's estimate, N·m (the board's telemetry `torque_est`).
    pub torque_est: f32,
    /// The plant's torque, N·m.
    pub torque_true: f64,
    pub enable: bool,
    /// Latched fault code.
    pub fault: u8,
}

/// Replay `events` for `duration` simulated seconds on the clutch `clutch` (noise seed
/// `seed`, `fault` scheduled), `page` swapped in at the journal's `page` event (at its own
/// control rate from then on, as the board's repetition counter does).
pub fn replay(
    clutch: &ClutchParams,
    seed: u64,
    fault: Option<Schedule>,
    events: &[Event],
    page: &ConfigImage,
    duration: f64,
) -> Result<Vec<Row>, ReplayError> {
    let boot = firmware::bringup::default_image()?;
    let (lp, mut cfg): (Loop, ValidatedConfig) = runnable(&boot)?;
    let mut lp = Box::new(lp);
    let mut rig = Rig::new(clutch, &cfg, seed, fault);
    let mut cmd = Command { reference: 0.0, enable: false, reset: false };
    let mut reference = 0.0f32;
    let mut out = Vec::new();
    let mut ev = events.iter().peekable();
    // Every sample that starts before `duration` (half a step of round-off allowed).
    while rig.time() + 0.5 * rig.dt() < duration {
        let k = rig.samples();
        cmd.reset = false;
        while let Some(e) = ev.next_if(|e| e.k <= k) {
            match e.applied {
                Applied::Reference(v) => reference = v,
                Applied::Enable(on) => cmd.enable = on,
                Applied::Reset => cmd.reset = true,
                Applied::Page(crc) if crc != page.crc() => {
                    return Err(ReplayError::OtherPage { k: e.k, journal: crc, given: page.crc() })
                }
                Applied::Page(_) => {
                    let (l, c) = runnable(page)?;
                    *lp = l;
                    cfg = c;
                    rig.set_dt(f64::from(cfg.get().dt));
                }
            }
        }
        cmd.reference = f64::from(reference);
        let s = rig.sample(lp.as_mut(), &mut cfg, cmd);
        out.push(Row {
            t: s.t,
            reference,
            torque_est: s.out.torque_est,
            torque_true: s.torque_true,
            enable: cmd.enable,
            fault: s.out.fault.code(),
        });
    }
    Ok(out)
}

/// The rows as CSV (`t,reference,torque_est,torque,enable,fault`; f32 columns printed so
/// they read back to the same bits).
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from("t,reference,torque_est,torque,enable,fault\n");
    for r in rows {
        s += &format!(
            "{},{},{},{},{},{}\n",
            r.t,
            r.reference,
            r.torque_est,
            r.torque_true as f32,
            u8::from(r.enable),
            r.fault
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_journal_parses_and_a_bad_line_is_named() {
        let ev = parse_journal("0 ref 1.5\n10 enable 1\n12 page 0x0000abcd\n20 reset\n30 enable 0\n").expect("journal");
        assert_eq!(ev[0], Event { k: 0, applied: Applied::Reference(1.5) });
        assert_eq!(ev[2].applied, Applied::Page(0xabcd));
        assert_eq!(ev.len(), 5);
        let e = parse_journal("0 ref 1\n5 enable 2\n").expect_err("bad enable");
        assert!(e.to_string().contains("line 2"), "{e}");
        assert!(matches!(parse_journal("9 reset\n3 reset\n"), Err(ReplayError::Order { line: 2, .. })));
    }

    #[test]
    fn a_journal_of_another_page_is_refused() {
        let page = firmware::bringup::default_image().expect("page");
        let ev = [Event { k: 2, applied: Applied::Page(page.crc() ^ 1) }];
        let r = replay(&ClutchParams::default(), 1, None, &ev, &page, 5.0 / 20_000.0);
        assert!(matches!(r, Err(ReplayError::OtherPage { k: 2, .. })), "{r:?}");
    }

    #[test]
    fn replay_applies_the_reference_from_its_sample_on() {
        let page = firmware::bringup::default_image().expect("page");
        let ev = parse_journal("3 ref 4.5\n").expect("journal");
        let rows = replay(&ClutchParams::default(), 1, None, &ev, &page, 6.0 / 20_000.0).expect("replay");
        let refs: Vec<f32> = rows.iter().map(|r| r.reference).collect();
        assert_eq!(refs, [0.0, 0.0, 0.0, 4.5, 4.5, 4.5]);
    }
}
