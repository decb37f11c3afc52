#![allow(clippy::unwrap_used)]
use super::*;
use crate::models::algebraic::Algebraic;

fn est() -> Estimator<Algebraic> {
    let dt = 0.01;
    Estimator::new(Algebraic::new(2.0, 0.5, 1.0, 0.0, dt).unwrap(), RateParams::backward(dt).unwrap()).unwrap()
}

#[test]
fn non_finite_input_holds_the_last_output_and_keeps_state() {
    let e = est();
    let mut s = e.state();
    let a = e.step(&mut s, Sample::new(1.0));
    assert!(a.flags.ok());
    let before = s;
    for bad in [
        Sample::new(f32::NAN),
        Sample::new(f32::INFINITY),
        Sample::new(1.0).with_command(f32::NAN),
        Sample::new(1.0).with_rate(f32::NEG_INFINITY),
    ] {
        let o = e.step(&mut s, bad);
        assert_eq!(o.y, a.y);
        assert!(o.flags.contains(Flags::NON_FINITE_INPUT));
        assert_eq!(s.rate, before.rate);
    }
    assert_eq!(s.rejected, 4);
    // The next good sample continues from the state before the bad ones.
    let o = e.step(&mut s, Sample::new(1.1));
    assert!(o.flags.ok());
    let want = 2.0 * 1.1 + 0.5 * (0.1 / 0.01) + 1.1f32.powi(4);
    assert!((o.y - want).abs() < 1e-3, "{} vs {want}", o.y);
}

#[test]
fn overflow_rolls_back() {
    let e = est();
    let mut s = e.state();
    let a = e.step(&mut s, Sample::new(1.0));
    let saved = s;
    // |B|·B³ overflows f32 at 1e30.
    let o = e.step(&mut s, Sample::new(1e30));
    assert!(o.flags.contains(Flags::OVERFLOW));
    assert_eq!(o.y, a.y);
    assert_eq!(s.rate, saved.rate);
    assert!(o.y.is_finite());
}

#[test]
fn measured_rate_overrides_the_estimate() {
    let e = est();
    let mut s = e.state();
    e.step(&mut s, Sample::new(0.0));
    let o = e.step(&mut s, Sample::new(0.0).with_rate(4.0));
    assert!((o.y - 0.5 * 4.0).abs() < 1e-6);
}

#[test]
fn rejected_samples_leave_a_stateful_model_untouched() {
    use crate::models::lugre::LuGre;
    let dt = 1e-3;
    let e = Estimator::new(LuGre::new(5.0, 6.0, 0.01, -0.1, 4.0, 5.0, dt).unwrap(), RateParams::backward(dt).unwrap())
        .unwrap();
    let mut s = e.state();
    for k in 0..50 {
        e.step(&mut s, Sample::new(0.02 * k as f32));
    }
    let before = s;
    assert_ne!(before.model, Default::default(), "the test needs a non-trivial state");
    let o = e.step(&mut s, Sample::new(f32::NAN));
    assert!(o.flags.contains(Flags::NON_FINITE_INPUT));
    let o = e.step(&mut s, Sample::new(3e38));
    assert!(o.flags.contains(Flags::OVERFLOW), "{o:?}");
    assert_eq!((s.model, s.rate, s.last), (before.model, before.rate, before.last));
}
