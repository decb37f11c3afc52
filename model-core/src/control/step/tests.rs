#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use crate::control::ControlConfig;
use crate::models::algebraic::Algebraic;
use proptest::prelude::*;

const DT: f32 = 1e-4;

fn setup(mode: LoopMode) -> (ControlStep<Algebraic>, ValidatedConfig) {
    let m = Algebraic::new(20.0, -0.05, -10.0, 0.8, DT).unwrap();
    let step = ControlStep::new(m, RateParams::filtered(DT, 200.0).unwrap()).unwrap();
    let cfg = ControlConfig { mode, calib_samples: 10.0, ..ControlConfig::defaults(DT) };
    (step, cfg.validate().unwrap())
}

/// A step with a slow pass every 10 samples (1 kHz at 10 kHz), as the firmware runs it.
fn tick<M: Model>(
    step: &ControlStep<M>,
    cfg: &ValidatedConfig,
    s: &mut ControlState<M::State>,
    x: ControlInput,
) -> ControlOutput {
    if s.sup.since_slow >= 10 || !s.sup.slow_seen {
        step.slow(cfg, s, f32::NAN);
    }
    step.step(cfg, s, x)
}

fn all_finite(o: &ControlOutput) -> bool {
    [o.duty, o.b, o.current, o.torque_est, o.i_ref, o.v_cmd].iter().all(|v| v.is_finite())
        && (-1.0..=1.0).contains(&o.duty)
}

#[test]
fn calibrates_then_runs_and_drives_current_toward_its_reference() {
    let (step, cfg) = setup(LoopMode::Current);
    let mut s = step.state();
    for k in 0..11u16 {
        let o = tick(&step, &cfg, &mut s, ControlInput::new(2050 + k % 2, 2047, 24.0, 1.0));
        assert!(!o.pwm_enable, "bridge stays off while calibrating");
    }
    assert_eq!(s.mode, Mode::Running);
    assert!((s.hall_offset - 2050.5).abs() < 0.6, "{}", s.hall_offset);
    // A simple RL coil integrated here: the current loop pulls i toward 1 A.
    let (r, l) = (4.0f32, 0.02f32);
    let mut i = 0.0f32;
    for k in 0..2000u16 {
        let counts = (2047.0 + i / cfg.get().current_gain).round() as u16;
        let o = tick(&step, &cfg, &mut s, ControlInput::new(2050 + (i * 100.0) as u16 + k % 2, counts, 24.0, 1.0));
        assert!(o.pwm_enable && all_finite(&o), "{o:?}");
        i += DT * (o.duty * 24.0 - r * i) / l;
    }
    assert!((i - 1.0).abs() < 0.02, "current {i}");
}

#[test]
fn fault_latches_until_reset() {
    let (step, cfg) = setup(LoopMode::Torque);
    let mut s = step.state();
    for k in 0..12 {
        tick(&step, &cfg, &mut s, ControlInput::new(2048 + k % 2, 2048, 24.0, 2.0));
    }
    assert_eq!(s.mode, Mode::Running);
    for _ in 0..2 {
        let o = tick(&step, &cfg, &mut s, ControlInput::new(4095, 2048, 24.0, 2.0));
        assert!(o.pwm_enable, "one rail sample does not trip");
    }
    let o = tick(&step, &cfg, &mut s, ControlInput::new(4095, 2048, 24.0, 2.0));
    assert_eq!((o.pwm_enable, o.fault, o.mode), (false, FaultCode::HallOpen, Mode::Fault(FaultCode::HallOpen)));
    assert_eq!(s.mode, Mode::Fault(FaultCode::HallOpen));
    let o = tick(&step, &cfg, &mut s, ControlInput::new(2048, 2048, 24.0, 2.0));
    assert_eq!((o.pwm_enable, o.duty, o.fault), (false, 0.0, FaultCode::HallOpen));
    let o = tick(&step, &cfg, &mut s, ControlInput { reset: true, ..ControlInput::new(2048, 2048, 24.0, 0.0) });
    assert_eq!(o.mode, Mode::Init);
    // The default state, but for the sample log's stale entries (never read again).
    assert_eq!(ControlState { log: SampleLog::default(), ..s }, ControlState::default(), "reset is the default");
}

#[test]
fn sensor_and_supply_faults_latch_with_the_bridge_off() {
    let (step, cfg) = setup(LoopMode::Torque);
    let off = |hall, supply| ControlInput { enable: false, ..ControlInput::new(hall, 2048, supply, 0.0) };
    for (x, code) in [(off(4095, 24.0), FaultCode::HallOpen), (off(2048, 3.0), FaultCode::SupplyLow)] {
        let mut s = step.state();
        for _ in 0..5 {
            let o = tick(&step, &cfg, &mut s, off(2048, 24.0));
            assert_eq!((o.mode, o.fault), (Mode::Disabled, FaultCode::None), "idle and well");
        }
        let confirm = cfg.get().confirm_samples as usize;
        for _ in 1..confirm {
            assert_eq!(tick(&step, &cfg, &mut s, x).fault, FaultCode::None, "confirmed over {confirm} samples");
        }
        let o = tick(&step, &cfg, &mut s, x);
        assert_eq!((o.mode, o.fault, o.pwm_enable), (Mode::Fault(code), code, false), "{x:?}");
        // Latched: the sensor back to normal, enable asked for, still the fault until reset.
        let o = tick(&step, &cfg, &mut s, ControlInput::new(2048, 2048, 24.0, 1.0));
        assert_eq!(o.fault, code, "latched");
    }
}

#[test]
fn the_loop_waits_for_a_slow_pass_and_trips_when_it_stalls() {
    let (step, cfg) = setup(LoopMode::Current);
    let mut s = step.state();
    for k in 0..50u16 {
        let o = step.step(&cfg, &mut s, ControlInput::new(2048 + k % 2, 2048, 24.0, 0.0));
        assert_eq!((o.mode, o.pwm_enable), (Mode::Init, false));
    }
    step.slow(&cfg, &mut s, f32::NAN);
    for k in 0..20u16 {
        step.step(&cfg, &mut s, ControlInput::new(2048 + k % 2, 2048, 24.0, 0.0));
    }
    assert_eq!(s.mode, Mode::Running);
    let timeout = cfg.coeffs().slow_timeout;
    let mut tripped = None;
    for k in 0..timeout {
        let o = step.step(&cfg, &mut s, ControlInput::new(2048 + (k % 2) as u16, 2048, 24.0, 0.0));
        if o.fault != FaultCode::None {
            tripped = Some((k, o));
            break;
        }
    }
    let (k, o) = tripped.unwrap();
    assert!(k + 70 >= timeout, "tripped early, after {k} samples");
    assert_eq!((o.fault, o.pwm_enable), (FaultCode::SupervisorStalled, false));
}

/// Each slow-developing check, now judged in the slow pass from the sample log, still
/// trips on a synthetic fault: with the code of the check, on the sample after the slow
/// pass that sees its count reached, within its count plus one slow period (10 samples
/// here) plus one sample. Without slow passes the per-sample step alone does not trip.
#[test]
fn slow_developing_checks_trip_through_the_slow_pass() {
    // (check, count, reference, fault input at sample k of the injection)
    type Case = (FaultCode, u32, f32, fn(u16) -> (u16, u16));
    let cases: [Case; 4] = [
        (FaultCode::HallStuck, 12, 0.0, |_| (2100, 2047)),
        (FaultCode::HallNoise, 4, 0.0, |k| (if k % 2 == 0 { 2100 } else { 2000 }, 2047)),
        // 1 A asked, no current flows: the current PI drives the full voltage.
        (FaultCode::CoilOpen, 10, 1.0, |k| (2048 + k % 3, 2047 + k % 2)),
        // 0.5 T with no current (band 0.05 T below).
        (FaultCode::BImplausible, 10, 0.0, |k| (2048 + 819 + k % 3, 2047)),
    ];
    for (code, count, reference, fault) in cases {
        let (step, _) = setup(LoopMode::Current);
        let cfg = ControlConfig { b_band: 0.05, calib_samples: 10.0, ..ControlConfig::defaults(DT) };
        let cfg = ControlConfig { mode: LoopMode::Current, ..cfg }.validate().unwrap();
        let mut s = step.state();
        for k in 0..30u16 {
            tick(&step, &cfg, &mut s, ControlInput::new(2048 + k % 3, 2047, 24.0, 0.0));
        }
        assert_eq!(s.mode, Mode::Running, "{code:?}");
        // Without a slow pass (it runs before every 10th sample), nothing trips.
        let mut quiet = s;
        for k in 0..50u16 {
            let (hall, current) = fault(k);
            let o = step.step(&cfg, &mut quiet, ControlInput::new(hall, current, 24.0, reference));
            assert_eq!(o.fault, FaultCode::None, "{code:?} tripped in the per-sample step");
        }
        let mut tripped = None;
        for k in 0..60u16 {
            let (hall, current) = fault(k);
            let slow_before = s.sup.since_slow >= 10;
            let o = tick(&step, &cfg, &mut s, ControlInput::new(hall, current, 24.0, reference));
            if o.fault != FaultCode::None {
                tripped = Some((u32::from(k) + 1, o, slow_before));
                break;
            }
        }
        assert!(tripped.is_some(), "{code:?} did not trip");
        let (n, o, slow_before) = tripped.unwrap();
        assert_eq!((o.fault, o.pwm_enable, o.mode), (code, false, Mode::Fault(code)));
        assert!(slow_before, "{code:?}: tripped on a sample without a slow pass before it");
        assert!(n >= count.min(4) && n <= count + 10 + 1, "{code:?} after {n} samples");
    }
}

#[test]
fn corrupted_config_trips_at_the_next_slow_pass() {
    // Current mode at 0 A: nothing else can trip while the coil is not simulated.
    let (step, mut cfg) = setup(LoopMode::Current);
    let mut s = step.state();
    let input = |k: u16| ControlInput::new(2048 + k % 3, 2048 + k % 2, 24.0, 0.0);
    for k in 0..20 {
        tick(&step, &cfg, &mut s, input(k));
    }
    assert_eq!(s.mode, Mode::Running);
    cfg.inject_bit_flip(700);
    let first = (0..30u16).map(|k| tick(&step, &cfg, &mut s, input(k))).position(|o| o.fault == FaultCode::ConfigCrc);
    assert!(first.is_some_and(|k| k <= 10), "{first:?}");
    assert!(!tick(&step, &cfg, &mut s, input(0)).pwm_enable);
}

#[test]
fn dt_mismatch_is_a_fault() {
    let (step, _) = setup(LoopMode::Torque);
    let cfg = ControlConfig { dt: 2e-4, ..ControlConfig::defaults(2e-4) }.validate().unwrap();
    let mut s = step.state();
    let o = tick(&step, &cfg, &mut s, ControlInput::new(2048, 2048, 24.0, 2.0));
    assert_eq!(o.fault, FaultCode::ConfigMismatch);
}

/// A sample and, when `Some`, a slow pass with that temperature before it.
fn any_input() -> impl Strategy<Value = (ControlInput, Option<f32>)> {
    let f = prop_oneof![any::<f32>(), Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY), -30.0f32..30.0];
    (any::<u16>(), any::<u16>(), f.clone(), f.clone(), f, any::<[bool; 4]>()).prop_map(
        |(hall, current, supply_v, reference, temperature, [overrun, enable, reset, slow])| {
            let x = ControlInput {
                hall: hall % 4096,
                current: current % 4096,
                supply_v,
                reference,
                overrun,
                enable: enable || hall % 7 != 0,
                reset: reset && hall % 5 == 0,
            };
            (x, (slow && current % 3 == 0).then_some(temperature))
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn never_panics_and_never_emits_nan(
        inputs in proptest::collection::vec(any_input(), 1..400),
        mode in prop_oneof![Just(LoopMode::Torque), Just(LoopMode::OpenLoopTorque), Just(LoopMode::Current)],
        temp_coeff in -0.01f32..0.01,
    ) {
        let (step, _) = setup(mode);
        let cfg = ControlConfig { mode, temp_coeff, calib_samples: 5.0, calib_max_spread: 4095.0,
            calib_max_offset_error: 4095.0, demag_samples: 5.0, ..ControlConfig::defaults(DT) }
            .validate().unwrap();
        let mut s = step.state();
        for (x, slow) in inputs {
            if let Some(theta) = slow {
                step.slow(&cfg, &mut s, theta);
            }
            let o = step.step(&cfg, &mut s, x);
            prop_assert!(all_finite(&o), "{:?} -> {:?}", x, o);
            if !o.pwm_enable {
                prop_assert_eq!(o.duty, 0.0);
            }
            if let Mode::Fault(_) = o.mode {
                prop_assert!(!o.pwm_enable);
            }
        }
    }
}
