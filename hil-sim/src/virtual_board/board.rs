//! The virtual board's control interrupt: one rig sample (`closed_loop::rig`, the bench
//! `hil-sim loop` steps) with what the application's tasks left in [`SimControl`], a
//! committed page swapped in while the bridge is off, the stream fed, and a journal of
//! what was applied at which sample.

use std::io::Write;

use firmware::application::{Snapshot, StreamSample};
use firmware::runner::Loop;
use model_core::control::ValidatedConfig;

use super::ports::SimControl;
use crate::closed_loop::rig::{Command, Rig, Sampled};
use crate::closed_loop::Schedule;
use crate::sim::plant::ClutchParams;

/// Where the virtual board writes what it applied and when (sample index first): `ref V`,
/// `enable 0|1`, `reset`, `page CRC` (a committed page swapped in before that sample). With
/// the scenario this reproduces the run exactly.
pub type Journal = Option<Box<dyn Write + Send>>;

/// The plant and the control loop: what survives a watchdog reset is the plant (the
/// clutch keeps turning); the controller is rebuilt from flash at every boot.
pub struct VirtualBoard {
    rig: Rig,
    lp: Box<Loop>,
    cfg: ValidatedConfig,
    /// The command applied to the previous sample (the journal logs changes).
    cmd: Command,
    last: Option<Sampled>,
    journal: Journal,
}

impl VirtualBoard {
    /// The clutch `clutch` (noise seed `seed`, `fault` scheduled) run by controller `lp`.
    pub fn new(
        clutch: &ClutchParams,
        seed: u64,
        fault: Option<Schedule>,
        journal: Journal,
        lp: Loop,
        cfg: ValidatedConfig,
    ) -> Self {
        Self {
            rig: Rig::new(clutch, &cfg, seed, fault),
            lp: Box::new(lp),
            cfg,
            cmd: Command { reference: 0.0, enable: false, reset: false },
            last: None,
            journal,
        }
    }

    /// After a reset: the controller of the new boot, the bridge off.
    pub fn reboot(&mut self, lp: Loop, cfg: ValidatedConfig) {
        *self.lp = lp;
        self.cfg = cfg;
        self.rig.set_dt(f64::from(cfg.get().dt));
    }

    /// The configuration that runs and its control rate (the limits the links answer).
    pub fn running(&self) -> (ValidatedConfig, u32) {
        (self.cfg, self.lp.control_hz())
    }

    /// Samples run.
    pub fn samples(&self) -> usize {
        self.rig.samples()
    }

    /// Simulated time of the next sample, µs.
    pub fn time_us(&self) -> u64 {
        (self.rig.time() * 1e6).round() as u64
    }

    fn log(&mut self, what: std::fmt::Arguments) {
        let k = self.rig.samples();
        if let Some(j) = self.journal.as_mut() {
            let _ = writeln!(j, "{k} {what}");
            let _ = j.flush();
        }
    }

    /// One control sample with the tasks' state in `ctl`.
    pub fn sample(&mut self, ctl: &SimControl) {
        // A committed page is swapped in only while the bridge is off.
        if !self.last.is_some_and(|s| s.applied.1) {
            let pending = ctl.pending.borrow_mut().take();
            if let Some(p) = pending {
                let (lp, cfg, crc) = *p;
                *self.lp = lp;
                self.cfg = cfg;
                // Its control rate from this sample on (the board's repetition counter).
                self.rig.set_dt(f64::from(cfg.get().dt));
                self.log(format_args!("page {crc:#010x}"));
            }
        }
        let reset = ctl.reset.replace(false);
        if reset {
            ctl.stalled.set(false);
            self.log(format_args!("reset"));
        }
        let reference = ctl.reference.get();
        let enable = ctl.enable.get();
        if f64::from(reference) != self.cmd.reference {
            self.log(format_args!("ref {reference}"));
        }
        if enable != self.cmd.enable {
            self.log(format_args!("enable {}", u8::from(enable)));
        }
        self.cmd = Command { reference: f64::from(reference), enable, reset };
        // The slow pass runs at 1 kHz inside the rig, on the grid `loop` uses; the
        // supervisor task's request is taken here as the interrupt takes it.
        ctl.slow_due.set(false);
        let k = self.rig.samples() as u32;
        let s = self.rig.sample(self.lp.as_mut(), &mut self.cfg, self.cmd);
        self.last = Some(s);
        ctl.samples.set(ctl.samples.get().wrapping_add(1));
        ctl.last.set(Snapshot { out: s.out, reference, supply_v: f32::NAN, cycles: 0 });
        let d = ctl.decimation.get();
        if d != 0 && k.is_multiple_of(d) {
            let t_us = (s.t * 1e6).round() as u64 as u32;
            ctl.stream.borrow_mut().push(StreamSample {
                n: k,
                t_us,
                out: s.out,
                reference,
                torque_true: s.torque_true as f32,
            });
        }
    }
}
