use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, ValueEnum};
use hil_sim::closed_loop::{
    bandwidth, compare, fault_run, frequency_response, identify, multisine_reference, Injection, Run, T_START,
};
use hil_sim::numerics::metrics::metrics;
use hil_sim::sim::plant::ClutchParams;
use hil_sim::sim::scenario::Scenario;
use serde_json::{json, Value};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LoopScenario {
    /// Torque reference: seed 000 eq. 21 multi-sine mapped to 2–10 N·m, 20 s.
    Multisine,
    /// Torque steps 2 → 8 → 4 → 10 → 0 → 6 N·m, 0.25 s each.
    Steps,
    /// Stepped sines 2–500 Hz, ±1 N·m around 6 N·m: the −3 dB bandwidth.
    Sweep,
    /// 90 s at 60 rad/s slip, 7 ± 2 N·m at 1 Hz: error drift as the fluid heats.
    Heating,
    /// Each fault injected alone at 0.3 s into a multi-sine run.
    Faults,
}

#[derive(Args, Debug)]
pub struct LoopArgs {
    #[arg(long, value_enum)]
    pub scenario: LoopScenario,
    /// TOML scenario file whose `[clutch]` replaces the reference clutch.
    #[arg(long)]
    pub clutch: Option<PathBuf>,
    /// Folder for CSV files of the runs (`t,reference,torque_est,torque,i,i_ref,duty,…`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Control-step rate, Hz.
    #[arg(long, default_value_t = 10_000.0)]
    pub control_hz: f64,
    /// Duration of the multisine run, s.
    #[arg(long, default_value_t = 20.0)]
    pub duration: f64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long)]
    pub json: bool,
}

fn write_csv(dir: &Option<PathBuf>, name: &str, r: &Run) -> anyhow::Result<()> {
    if let Some(d) = dir {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
        let p = d.join(name);
        std::fs::write(&p, r.csv()).with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(())
}

fn rise_time(r: &Run, t0: f64, t1: f64) -> Option<f64> {
    let (k0, k1) = (r.after(t0), r.after(t1));
    let (from, to) = (*r.reference.get(k0.checked_sub(1)?)?, *r.reference.get(k0)?);
    let y0 = r.torque_true.get(k0.checked_sub(1)?)?;
    let span = to - from;
    let lvl = |f: f64| y0 + f * (to - y0);
    let cross =
        |f: f64| (k0..k1).find(|&k| if span > 0.0 { r.torque_true[k] >= lvl(f) } else { r.torque_true[k] <= lvl(f) });
    Some((cross(0.9)? as f64 - cross(0.1)? as f64) * (r.t[1] - r.t[0]))
}

pub fn run_cmd(a: LoopArgs) -> anyhow::Result<()> {
    let clutch = match &a.clutch {
        Some(p) => {
            Scenario::parse(p, &std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?)?.clutch
        }
        None => ClutchParams::default(),
    };
    let pb = super::progress(3, "identify");
    let id = identify(&clutch, a.control_hz, a.seed).context("identifying the simulated clutch")?;
    pb.inc(1);
    let from = T_START + 0.5;
    let mut extra = json!({});
    let mut faults = Vec::new();
    let mut text = String::new();
    let (lp, bl) = match a.scenario {
        LoopScenario::Multisine => {
            pb.set_message("multisine");
            compare(&id, &clutch, &multisine_reference(), T_START + a.duration, 0.0, a.seed)?
        }
        LoopScenario::Steps => {
            pb.set_message("steps");
            let levels = [2.0, 8.0, 4.0, 10.0, 0.0, 6.0];
            let steps = move |t: f64| levels[((t / 0.25) as usize).min(levels.len() - 1)];
            let (lp, bl) = compare(&id, &clutch, &steps, T_START + 1.5, 0.0, a.seed)?;
            let rises: Vec<Value> = (1..4)
                .map(|j| {
                    let t0 = T_START + 0.25 * j as f64;
                    json!({"at_s": t0 - T_START, "loop_rise_ms": rise_time(&lp, t0, t0 + 0.25).map(|v| v * 1e3),
                           "baseline_rise_ms": rise_time(&bl, t0, t0 + 0.25).map(|v| v * 1e3)})
                })
                .collect();
            extra = json!({"rise_10_90": rises});
            (lp, bl)
        }
        LoopScenario::Sweep => {
            pb.set_message("sweep");
            let step = id.loop_step(u32::MAX)?;
            let fl = frequency_response(&clutch, &step, id.loop_config(0.0)?, 6.0, 1.0, a.seed);
            let fb = frequency_response(&clutch, &step, id.baseline_config()?, 6.0, 1.0, a.seed);
            let (bw_l, bw_b) = (bandwidth(&fl), bandwidth(&fb));
            text += &format!(
                "  -3 dB bandwidth of the true torque: loop {} Hz, baseline {} Hz\n",
                bw_l.map_or("> 500".into(), |v| format!("{v:.0}")),
                bw_b.map_or("> 500".into(), |v| format!("{v:.0}"))
            );
            for (p, q) in fl.iter().zip(&fb) {
                text += &format!("    {:>5.0} Hz  loop {:.3}  baseline {:.3}\n", p.f_hz, p.gain, q.gain);
            }
            extra = json!({"bandwidth_hz": {"loop": bw_l, "baseline": bw_b}, "response": {"loop": fl, "baseline": fb}});
            // Tracking of a 5 Hz ±1 N·m sine for the metrics fields.
            let sine = |t: f64| 6.0 + (2.0 * std::f64::consts::PI * 5.0 * t).sin();
            compare(&id, &clutch, &sine, T_START + 2.0, 0.0, a.seed)?
        }
        LoopScenario::Heating => {
            pb.set_message("heating");
            let mut hot = clutch.clone();
            hot.motor.speed = vec![[0.0, 60.0]];
            let sine = |t: f64| 7.0 + 2.0 * (2.0 * std::f64::consts::PI * t).sin();
            let dur = T_START + 90.0;
            let (lp, bl) = compare(&id, &hot, &sine, dur, 0.0, a.seed)?;
            // Compensated: the fluid datasheet's yield slope (−0.3 %/K) as the estimate's coefficient.
            let (lc, _) = compare(&id, &hot, &sine, dur, -0.003, a.seed)?;
            write_csv(&a.out, "heating_loop_temp_comp.csv", &lc)?;
            let mut rows = Vec::new();
            text += "  window    θ (°C)   mean error (N·m) / R-RMSE: loop | loop+temp comp | baseline\n";
            for w in 0..9 {
                let (t0, t1) = (T_START + 10.0 * w as f64, T_START + 10.0 * (w + 1) as f64);
                let stats = |r: &Run| {
                    let (k0, k1) = (r.after(t0.max(from)), r.after(t1));
                    let e: f64 = (k0..k1).map(|k| r.torque_true[k] - r.reference[k]).sum::<f64>() / (k1 - k0) as f64;
                    (e, metrics(&r.reference[k0..k1], &r.torque_true[k0..k1], None).r_rmse, k0, k1)
                };
                let (el, rl, k0, k1) = stats(&lp);
                let (ec, rc, _, _) = stats(&lc);
                let (eb, rb, _, _) = stats(&bl);
                let theta = lp.temperature[k0..k1].iter().sum::<f64>() / (k1 - k0) as f64;
                text += &format!(
                    "  {:>2}-{:<3}s  {:6.1}   {:+.3} / {:5.2} % | {:+.3} / {:5.2} % | {:+.3} / {:5.2} %\n",
                    10 * w,
                    10 * (w + 1),
                    theta,
                    el,
                    100.0 * rl,
                    ec,
                    100.0 * rc,
                    eb,
                    100.0 * rb
                );
                rows.push(json!({"t0_s": 10 * w, "t1_s": 10 * (w + 1), "temperature_c": theta,
                    "loop": {"mean_error": el, "r_rmse": rl},
                    "loop_temp_comp": {"mean_error": ec, "r_rmse": rc},
                    "baseline": {"mean_error": eb, "r_rmse": rb}}));
            }
            extra = json!({"heating": rows, "tracking_temp_comp": lc.tracking(from)});
            (lp, bl)
        }
        LoopScenario::Faults => {
            pb.set_message("faults");
            text += "  fault          detected  detect_ms  safe_state  code\n";
            for inj in Injection::ALL {
                let (f, r) = fault_run(&id, &clutch, inj, a.seed)?;
                write_csv(&a.out, &format!("fault_{}.csv", inj.name()), &r)?;
                text += &format!(
                    "  {:<14} {:<9} {:>9} {:<11} {} ({})\n",
                    f.fault,
                    f.detected,
                    f.detect_ms.map_or("-".into(), |v| format!("{v:.2}")),
                    f.safe_state,
                    f.code,
                    f.code_name
                );
                faults.push(f);
            }
            let ms = multisine_reference();
            compare(&id, &clutch, &ms, T_START + 3.0, 0.0, a.seed)?
        }
    };
    pb.inc(1);
    let name = format!("{:?}", a.scenario).to_lowercase();
    write_csv(&a.out, &format!("{name}_loop.csv"), &lp)?;
    write_csv(&a.out, &format!("{name}_baseline.csv"), &bl)?;
    let (tm, bm) = (lp.tracking(from), bl.tracking(from));
    let improvement = bm.r_rmse / tm.r_rmse;
    pb.finish_and_clear();
    if a.json {
        let mut v = json!({
            "scenario": name, "control_hz": a.control_hz,
            "identified": id,
            "tracking": tm, "baseline": bm, "improvement_r_rmse": improvement,
            "faults": faults,
        });
        if let (Some(o), Some(e)) = (v.as_object_mut(), extra.as_object()) {
            o.extend(e.clone());
        }
        return super::print_json(&v);
    }
    super::emit(&format!(
        "loop --scenario {name} at {} Hz (algebraic model fitted on the simulated clutch: R-RMSE {:.2} %)\n",
        a.control_hz,
        100.0 * id.algebraic_fit_r_rmse
    ));
    super::emit(&format!(
        "  true torque vs reference: loop R-RMSE {:.2} % (R² {:.4}), baseline R-RMSE {:.2} % (R² {:.4}), {:.1}× lower\n",
        100.0 * tm.r_rmse,
        tm.r2,
        100.0 * bm.r_rmse,
        bm.r2,
        improvement
    ));
    super::emit(&text);
    if let Some(d) = &a.out {
        super::emit(&format!("  CSV written to {}\n", Path::new(d).display()));
    }
    Ok(())
}
