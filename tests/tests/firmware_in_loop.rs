//! Firmware in the loop without a board: the shipping ELF
//! (`target/thumbv7em-none-eabihf/release/firmware`) runs on an instruction-level
//! Cortex-M4F (Unicorn, GPL-2, test-only) with the STM32G474 registers it touches modelled
//! from RM0440 (`tests/fil/g474.py`; scenarios in `tests/fil/run.py`).
//!
//! - 1 s of control at 20 kHz from reset in closed loop on a coil model: every compare
//!   value the interrupt wrote equals model-core's `ControlStep` on the host for the same
//!   inputs (same configuration, same f32 code).
//! - A panic, a HardFault, an NMI, a stuck control interrupt and a watchdog stall each end
//!   with MOE cleared within one PWM period (the stall: within the watchdog time).
//! - A configuration commit cut by a reset at every flash operation boots the old or the
//!   new page, never the defaults, never a hang.
//!
//! Needs the firmware built for the target and `scripts/setup` (the Python venv with
//! Unicorn under the target folder). Without them the tests say so and pass, unless
//! `MRC_FIL=required` (set by `.ci/run`, which builds the firmware first).

use std::path::{Path, PathBuf};
use std::process::Command;

use firmware::bridge::{compares, Action, Bridge};
use firmware::bringup::{default_image, supply_volts, PWM_COUNTS};
use firmware::slots;
use model_core::control::page::PAGE_BYTES;
use model_core::control::{ConfigImage, ControlInput, ControlStep};
use model_core::models::algebraic::Algebraic;

struct Fil {
    python: PathBuf,
    elf: PathBuf,
    objdump: PathBuf,
    scratch: PathBuf,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace").to_path_buf()
}

fn objdump() -> Option<PathBuf> {
    let out = Command::new(std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into()))
        .args(["--print", "sysroot"])
        .output()
        .ok()?;
    let sysroot = PathBuf::from(String::from_utf8(out.stdout).ok()?.trim());
    std::fs::read_dir(sysroot.join("lib/rustlib"))
        .ok()?
        .filter_map(|e| e.ok())
        .map(|e| e.path().join("bin/llvm-objdump"))
        .find(|p| p.exists())
}

/// The harness's pieces, or `None` (with the reason printed) when they are missing and
/// not required.
fn fil() -> Option<Fil> {
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root().join("target"), PathBuf::from);
    let target = if target.is_absolute() { target } else { root().join(target) };
    let f = Fil {
        python: target.join("fil-venv/bin/python"),
        elf: target.join("thumbv7em-none-eabihf/release/firmware"),
        objdump: objdump().unwrap_or_else(|| "llvm-objdump".into()),
        scratch: target.join("fil"),
    };
    let missing: Vec<String> =
        [&f.python, &f.elf].iter().filter(|p| !p.exists()).map(|p| p.display().to_string()).collect();
    if missing.is_empty() {
        std::fs::create_dir_all(&f.scratch).expect("scratch folder");
        return Some(f);
    }
    let why = format!(
        "firmware in the loop needs {} (cargo build --release -p firmware --target \
         thumbv7em-none-eabihf; scripts/setup)",
        missing.join(", ")
    );
    assert!(std::env::var("MRC_FIL").as_deref() != Ok("required"), "{why}");
    eprintln!("skipped: {why}");
    None
}

fn run(f: &Fil, args: &[&str]) -> String {
    let out = Command::new(&f.python)
        .arg(root().join("tests/fil/run.py"))
        .arg(&f.elf)
        .args(args)
        .env("OBJDUMP", &f.objdump)
        .output()
        .expect("run the harness");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    print!("{text}");
    eprint!("{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "harness {args:?} failed");
    text
}

#[test]
fn one_second_of_control_matches_model_core() {
    let Some(f) = fil() else { return };
    let trace = f.scratch.join("control.csv");
    run(&f, &["control", "20200", trace.to_str().expect("utf-8 path")]);

    let img = default_image().expect("default image");
    let cfg = img.control;
    let rate = img.rate.build(cfg.get().dt).expect("rate");
    let step = ControlStep::new(img.model::<Algebraic>().expect("model"), rate).expect("step");
    let mut st = step.state();
    let mut bridge = Bridge::Off;
    let (mut moe, mut compared, mut driving, mut nonzero) = (false, 0usize, 0usize, 0usize);
    let text = std::fs::read_to_string(&trace).expect("trace");
    for (line, row) in text.lines().skip(1).enumerate() {
        let v: Vec<u64> = row.split(',').map(|x| x.parse().expect("number")).collect();
        let &[ran, hall, current, supply, enable, reference, reset, stalled, slow, ccr1, ccr2, moe_seen] = v.as_slice()
        else {
            panic!("trace line {}: {} fields", line + 2, v.len());
        };
        if ran == 0 {
            continue;
        }
        let input = ControlInput {
            overrun: stalled != 0,
            enable: enable != 0 && stalled == 0,
            reset: reset != 0,
            ..ControlInput::new(
                hall as u16,
                current as u16,
                supply_volts(supply as u16),
                f32::from_bits(reference as u32),
            )
        };
        let out = step.step(&cfg, &mut st, input);
        let (next, action) = bridge.next(out.pwm_enable);
        bridge = next;
        let want = match action {
            Action::Off => (0, 0),
            Action::Arm | Action::Drive => compares(out.compare, PWM_COUNTS),
        };
        moe = match action {
            Action::Off => false,
            Action::Drive => true,
            Action::Arm => moe,
        };
        assert_eq!((ccr1 as u32, ccr2 as u32), want, "trace line {}: compares (mode {:?})", line + 2, out.mode);
        assert_eq!(moe_seen != 0, moe, "trace line {}: MOE", line + 2);
        if slow != 0 {
            step.slow(&cfg, &mut st, f32::NAN);
        }
        compared += 1;
        driving += usize::from(moe);
        nonzero += usize::from(want != (0, 0));
    }
    println!("compare values equal to model-core's ControlStep on {compared} samples ({driving} driving, {nonzero} non-zero)");
    assert!(compared >= 20_000, "only {compared} samples");
    assert!(nonzero > 15_000, "the loop hardly drove the bridge: {nonzero} non-zero compares");
}

#[test]
fn every_fault_path_clears_moe() {
    let Some(f) = fil() else { return };
    let out = run(&f, &["faults"]);
    assert!(out.contains("5 passed, 0 failed"), "{out}");
}

/// A page the firmware accepts, distinct from the compiled-in one.
fn page(gain: f32) -> [u8; PAGE_BYTES] {
    let d = default_image().expect("default image");
    ConfigImage::new("algebraic", &[gain, -0.05, -10.0, 0.8], d.rate, d.control).expect("page").encode()
}

#[test]
fn a_commit_cut_at_every_flash_operation_boots_old_or_new() {
    let Some(f) = fil() else { return };
    let old = slots::slot_image(&page(18.0), 1).expect("fits a slot");
    let mut flash = old.to_vec();
    flash.extend([0xFF; slots::SLOT_BYTES]);
    let flash_path = f.scratch.join("flash.bin");
    let page_path = f.scratch.join("page.bin");
    std::fs::write(&flash_path, flash).expect("write");
    let new = page(22.0);
    let used = new.len() - new.iter().rev().take_while(|b| **b == 0xFF).count();
    std::fs::write(&page_path, &new[..used.max(64)]).expect("write");
    let out = run(&f, &["powercut", flash_path.to_str().expect("utf-8"), page_path.to_str().expect("utf-8")]);
    assert!(out.contains("1 passed, 0 failed"), "{out}");
}
