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
//!   new page, never the defaults, never a hang; a damaged page with nothing else boots
//!   the defaults reported as damaged, the drive refused.
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
use model_core::control::{ConfigImage, ControlInput, ControlOutput, ControlStep};
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
    let text = std::fs::read_to_string(&trace).expect("trace");
    let (compared, driving, nonzero) = compare_trace(&text, |input, slow| {
        let out = step.step(&cfg, &mut st, input);
        if slow {
            step.slow(&cfg, &mut st, f32::NAN);
        }
        out
    });
    println!("compare values equal to model-core's ControlStep on {compared} samples ({driving} driving, {nonzero} non-zero)");
    assert!(compared >= 20_000, "only {compared} samples");
    assert!(nonzero > 15_000, "the loop hardly drove the bridge: {nonzero} non-zero compares");
}

/// Every traced period of `text` (`control`'s CSV) against `step` (the control step, and
/// the slow pass after it when the interrupt ran one): the compares and MOE the interrupt
/// wrote must be the ones the bridge sequencing gives for the step's output. Returns
/// (periods compared, periods driving, periods with non-zero compares).
fn compare_trace(text: &str, mut step: impl FnMut(ControlInput, bool) -> ControlOutput) -> (usize, usize, usize) {
    let mut bridge = Bridge::Off;
    let (mut moe, mut compared, mut driving, mut nonzero) = (false, 0usize, 0usize, 0usize);
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
            enable: enable != 0,
            reset: reset != 0,
            ..ControlInput::new(
                hall as u16,
                current as u16,
                supply_volts(supply as u16),
                f32::from_bits(reference as u32),
            )
        };
        let out = step(input, slow != 0);
        let (next, action) = bridge.next(out.pwm_enable && stalled == 0);
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
        compared += 1;
        driving += usize::from(moe);
        nonzero += usize::from(want != (0, 0));
    }
    (compared, driving, nonzero)
}

/// A Preisach page at its 10 kHz (issue 17: every clutch model on the board; its 10 KB
/// table is built in place in CCM SRAM).
fn preisach_page() -> ConfigImage {
    let d = default_image().expect("default image");
    let mut c = *d.control.get();
    c.dt = 1.0 / firmware::runner::control_hz_of("preisach").expect("a rate") as f32;
    let control = c.validate().expect("valid");
    ConfigImage::new("preisach", &[1.0, 2.0, 0.1, 0.05, 0.1, 1.0, -1.0, 1.0, 0.0], d.rate, control).expect("page")
}

#[test]
fn a_preisach_page_boots_from_its_slot_and_runs_as_the_runner_does() {
    let Some(f) = fil() else { return };
    let img = preisach_page();
    let mut flash = slots::slot_image(&img.encode(), 1).expect("fits a slot").to_vec();
    flash.extend([0xFF; slots::SLOT_BYTES]);
    let flash_path = f.scratch.join("flash-preisach.bin");
    std::fs::write(&flash_path, flash).expect("write");
    let trace = f.scratch.join("control-preisach.csv");
    run(&f, &["control", "6000", trace.to_str().expect("utf-8 path"), flash_path.to_str().expect("utf-8 path")]);

    let mut lp = firmware::runner::Loop::from_image(&img).expect("the runner builds the page");
    let cfg = img.control;
    let text = std::fs::read_to_string(&trace).expect("trace");
    let (compared, driving, nonzero) = compare_trace(&text, |input, slow| {
        let out = lp.step(&cfg, input);
        if slow {
            lp.slow(&cfg, f32::NAN);
        }
        out
    });
    println!(
        "preisach from slot A: {compared} periods equal to firmware::runner ({driving} driving, {nonzero} non-zero)"
    );
    assert!(compared >= 5_000, "only {compared} samples");
    assert!(nonzero > 1_000, "the loop hardly drove the bridge: {nonzero} non-zero compares");
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
    assert!(out.contains("2 passed, 0 failed"), "{out}");
}

/// One field of a register dump: `(value >> shift) & mask`.
fn field(regs: &serde_json::Value, name: &str, shift: u32, mask: u64) -> u64 {
    let v = regs[name].as_u64().unwrap_or_else(|| panic!("register {name} missing from the dump"));
    (v >> shift) & mask
}

/// The bring-up configuration as the shipping ELF leaves it after boot (RM0440 fields).
#[test]
fn bring_up_registers_after_boot() {
    let Some(f) = fil() else { return };
    let out = run(&f, &["board"]);
    let regs: serde_json::Value = serde_json::from_str(out.lines().last().expect("dump")).expect("JSON");
    let r = |name: &str, shift: u32, mask: u64| field(&regs, name, shift, mask);
    // Clocks: HSE on, PLL from HSE /6 ×85, P /8 for the ADC, R /2 for SYSCLK.
    assert_eq!(r("rcc_cr", 16, 1), 1, "HSEON");
    assert_eq!(r("rcc_pllcfgr", 0, 3), 3, "PLLSRC = HSE");
    assert_eq!(r("rcc_pllcfgr", 4, 0xF) + 1, 6, "PLLM");
    assert_eq!(r("rcc_pllcfgr", 8, 0x7F), 85, "PLLN");
    assert_eq!((r("rcc_pllcfgr", 16, 1), r("rcc_pllcfgr", 27, 0x1F)), (1, 8), "PLLP enabled, /8");
    assert_eq!(r("rcc_ccipr", 28, 3), 1, "ADC12SEL = PLL P (not disabled)");
    assert_eq!(r("rcc_ccipr", 24, 3), 0, "FDCANSEL = HSE");
    // ADC: Hall and current 12.5 cycles, the supply (channel 12) 47.5; TIM1_TRGO2 rising.
    assert_eq!((r("adc1_smpr1", 3, 7), r("adc1_smpr1", 6, 7)), (2, 2), "SMP1, SMP2 = 12.5 cycles");
    assert_eq!(r("adc1_smpr2", 6, 7), 4, "SMP12 = 47.5 cycles");
    assert_eq!((r("adc1_jsqr", 2, 0x1F), r("adc1_jsqr", 7, 3)), (8, 1), "JEXTSEL TIM1_TRGO2, rising");
    // TIM1: update as TRGO2 once per period, the deadline monitor's interrupt, dead time,
    // break from COMP1 active high, BDTR locked.
    assert_eq!(r("tim1_cr2", 20, 0xF), 2, "MMS2 = update");
    assert_eq!(r("tim1_rcr", 0, 0xFFFF), 1, "repetition counter");
    assert_eq!(r("tim1_dier", 0, 1), 1, "UIE (deadline monitor)");
    assert_eq!(r("tim1_arr", 0, 0xFFFF) + 1, u64::from(PWM_COUNTS));
    assert_eq!(r("tim1_bdtr", 0, 0xFF), 85, "DTG");
    assert_eq!((r("tim1_bdtr", 12, 1), r("tim1_bdtr", 13, 1)), (1, 1), "BKE, BKP active high");
    assert_eq!(r("tim1_bdtr", 8, 3), 1, "LOCK level 1");
    assert_eq!(r("tim1_af1", 1, 1), 1, "BKCMP1E: COMP1 into the break");
    assert_eq!(r("syscfg_cfgr2", 0, 0xF), 0xF, "lockup, SRAM parity, PVD, flash ECC to the break");
    // COMP1: enabled, inverting input DAC3 CH1, locked; DAC3 at the configured threshold.
    assert_eq!((r("comp1_csr", 0, 1), r("comp1_csr", 4, 7), r("comp1_csr", 31, 1)), (1, 4, 1), "COMP1");
    let cfg = default_image().expect("default image").control;
    let threshold = firmware::bringup::over_current_counts(cfg.get()).expect("threshold");
    assert_eq!(r("dac3_dhr12r1", 0, 0xFFF), u64::from(threshold), "DAC3 threshold from over_current");
    assert_eq!((r("dac3_cr", 0, 1), r("dac3_mcr", 0, 7)), (1, 3), "DAC3 on, internal connection");
    // Watchdog frozen under the debugger; 50 ms from LSI 32 kHz.
    assert_eq!(r("dbgmcu_apb1fzr1", 12, 1), 1, "DBG_IWDG_STOP");
    let wd_ms = (4u64 << r("iwdg_pr", 0, 7)) * (r("iwdg_rlr", 0, 0xFFF) + 1) / 32;
    assert_eq!(wd_ms, 50, "IWDG timeout, ms");
    // FDCAN: timing from the crystal, one filter for the command identifier into FIFO 0,
    // everything else rejected.
    let t = firmware::can_timing::nominal(24_000_000, 1_000_000).expect("timing");
    assert_eq!(r("fdcan_nbtp", 16, 0x1FF) + 1, u64::from(t.prescaler), "NBRP");
    assert_eq!(r("fdcan_nbtp", 8, 0xFF) + 1, u64::from(t.seg1), "NTSEG1");
    assert_eq!(r("fdcan_nbtp", 0, 0x7F) + 1, u64::from(t.seg2), "NTSEG2");
    assert_eq!(r("fdcan_nbtp", 25, 0x7F) + 1, u64::from(t.sjw), "NSJW");
    assert_eq!((r("fdcan_rxgfc", 4, 3) >> 1, r("fdcan_rxgfc", 2, 3) >> 1), (1, 1), "non-matching rejected");
    let flt = (r("fdcan_flssa0", 30, 3), r("fdcan_flssa0", 27, 7), r("fdcan_flssa0", 16, 0x7FF));
    assert_eq!(flt, (1, 1, 0x120), "filter 0: command id into FIFO 0");
    // The reset flags read and cleared.
    assert_eq!(r("rcc_csr", 25, 0x7F), 0, "RMVF");
    // Priorities: deadline monitor > control > CAN > time driver (lower value wins).
    let prio = |irq: &str| regs["prio"][irq].as_u64().unwrap_or(0);
    assert!(prio("25") < prio("18"), "TIM1_UP above ADC1_2");
    assert!(prio("18") < prio("21") && prio("18") < prio("22"), "ADC1_2 above FDCAN");
    assert!(prio("21") < prio("24"), "FDCAN above the time driver (TIM15)");
    println!("bring-up registers: clocks, ADC, TIM1 break/lock, COMP1/DAC3, IWDG, FDCAN, priorities as configured");
}
