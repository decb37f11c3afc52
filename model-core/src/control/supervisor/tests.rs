use super::*;
use crate::control::ControlConfig;

#[derive(Clone, Copy)]
struct Obs {
    hall: u16,
    b: f32,
    i: f32,
    supply_v: f32,
    v_applied: f32,
    model_bad: bool,
    overrun: bool,
}

fn ok_obs(k: u16) -> Obs {
    Obs { hall: 2048 + k % 3, b: 0.1, i: 0.5, supply_v: 24.0, v_applied: 2.0, model_bad: false, overrun: false }
}

fn check(k: &Coeffs, s: &mut SupState, o: &Obs) -> FaultCode {
    let f = Fast { hall: o.hall, i: o.i, supply_v: o.supply_v, overrun: o.overrun, model_bad: o.model_bad };
    if confirm(k, s, fast_any(k, &f)) {
        return fast_code(k, &f);
    }
    if running(k, s, o.hall, o.b, o.i, o.v_applied) {
        running_code(k, s)
    } else {
        FaultCode::None
    }
}

fn run(cfg: &ControlConfig, f: impl Fn(u16) -> Obs) -> (FaultCode, u16) {
    let k = Coeffs::new(cfg);
    let mut s = SupState::default();
    prime(&mut s, 2047);
    for k0 in 0..50u16 {
        assert_eq!(check(&k, &mut s, &ok_obs(k0)), FaultCode::None);
    }
    for k0 in 0..100u16 {
        let c = check(&k, &mut s, &f(k0));
        if c != FaultCode::None {
            return (c, k0 + 1);
        }
    }
    (FaultCode::None, 0)
}

#[test]
fn each_check_trips_alone_and_healthy_does_not() {
    let cfg = ControlConfig::defaults(1e-4);
    assert_eq!(run(&cfg, ok_obs).0, FaultCode::None);
    assert_eq!(run(&cfg, |k| Obs { hall: 4095, ..ok_obs(k) }), (FaultCode::HallOpen, 3));
    assert_eq!(run(&cfg, |k| Obs { hall: 4079, ..ok_obs(k) }), (FaultCode::HallOpen, 3));
    assert_eq!(run(&cfg, |k| Obs { hall: 0, ..ok_obs(k) }), (FaultCode::HallShort, 3));
    assert_eq!(run(&cfg, |k| Obs { hall: 16, ..ok_obs(k) }), (FaultCode::HallShort, 3));
    assert_eq!(run(&cfg, |k| Obs { hall: 4078 - k % 2, ..ok_obs(k) }).0, FaultCode::None);
    assert_eq!(run(&cfg, |k| Obs { hall: 17 + k % 2, ..ok_obs(k) }).0, FaultCode::None);
    assert_eq!(run(&cfg, |k| Obs { hall: 2100, ..ok_obs(k) }), (FaultCode::HallStuck, 13));
    // 0.02 T per sample at 1.25/2048 T per count: 32.8 counts.
    let noisy = |k: u16| Obs { hall: if k.is_multiple_of(2) { 2100 } else { 2000 }, ..ok_obs(k) };
    // The first jump has no earlier one to reverse: the third reversal is the 4th sample.
    assert_eq!(run(&cfg, noisy), (FaultCode::HallNoise, 4));
    // A one-way collapse of the field (coil opened) is not noise.
    let collapse = |k: u16| Obs { hall: 2048 - 60 * k.min(2) + k % 3, ..ok_obs(k) };
    assert_eq!(run(&cfg, collapse).0, FaultCode::None);
    // Jumps just within the slew limit, reversing every sample, are not noise.
    let wobble = |k: u16| Obs { hall: if k.is_multiple_of(2) { 2080 } else { 2048 }, ..ok_obs(k) };
    assert_eq!(run(&cfg, wobble).0, FaultCode::None);
    let rattle = |k: u16| Obs { hall: if k.is_multiple_of(2) { 2081 } else { 2048 }, ..ok_obs(k) };
    assert_eq!(run(&cfg, rattle).0, FaultCode::HallNoise);
    assert_eq!(run(&cfg, |k| Obs { i: 0.0, v_applied: 10.0, ..ok_obs(k) }), (FaultCode::CoilOpen, 10));
    assert_eq!(run(&cfg, |k| Obs { i: 9.0, ..ok_obs(k) }), (FaultCode::OverCurrent, 3));
    assert_eq!(run(&cfg, |k| Obs { i: -9.0, ..ok_obs(k) }), (FaultCode::OverCurrent, 3));
    assert_eq!(run(&cfg, |k| Obs { supply_v: 12.0, ..ok_obs(k) }), (FaultCode::SupplyLow, 3));
    assert_eq!(run(&cfg, |k| Obs { supply_v: f32::NAN, ..ok_obs(k) }), (FaultCode::SupplyLow, 3));
    assert_eq!(run(&cfg, |k| Obs { supply_v: 40.0, ..ok_obs(k) }), (FaultCode::SupplyHigh, 3));
    assert_eq!(run(&cfg, |k| Obs { supply_v: f32::INFINITY, ..ok_obs(k) }), (FaultCode::SupplyHigh, 3));
    assert_eq!(run(&cfg, |k| Obs { overrun: true, ..ok_obs(k) }), (FaultCode::Overrun, 3));
    assert_eq!(run(&cfg, |k| Obs { model_bad: true, ..ok_obs(k) }), (FaultCode::ModelNonFinite, 3));
    // Conditions that alternate still trip (one counter for all): the code is the
    // priority of the sample that confirms.
    let alt =
        |k: u16| if k.is_multiple_of(2) { Obs { overrun: true, ..ok_obs(k) } } else { Obs { i: 9.0, ..ok_obs(k) } };
    assert_eq!(run(&cfg, alt), (FaultCode::Overrun, 3));
    // One bad sample in between resets the count.
    let gap = |k: u16| if k % 3 == 2 { ok_obs(k) } else { Obs { i: 9.0, ..ok_obs(k) } };
    assert_eq!(run(&cfg, gap).0, FaultCode::None);
    let banded = ControlConfig { b_band: 0.05, ..cfg };
    assert_eq!(run(&banded, |k| Obs { b: 0.5, ..ok_obs(k) }), (FaultCode::BImplausible, 10));
    assert_eq!(run(&banded, |k| Obs { i: 2.0, ..ok_obs(k) }), (FaultCode::BImplausible, 10));
    // Disabled checks never trip.
    let off = ControlConfig { stuck_samples: 0.0, ..cfg };
    assert_eq!(run(&off, |k| Obs { hall: 2100, ..ok_obs(k) }).0, FaultCode::None);
}
