#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
use super::*;
use crate::control::RateSpec;
use crate::models::algebraic::{Algebraic, SEED000_AVERAGE};
use crate::models::dahl::Dahl;
use crate::{Kin, ParamError};

/// The firmware's 20 kHz control period and its default settings (b_max 0.8 T,
/// torque_max 15 N·m, b_per_amp 0.2 T/A).
const DT: f32 = 5e-5;

fn page(id: &str, params: &[f32]) -> ConfigImage {
    let control = ControlConfig::defaults(DT).validate().unwrap();
    ConfigImage::new(id, params, RateSpec::Filtered { fc: 150.0 }, control).unwrap()
}

fn verdict<M: Model>(img: &ConfigImage) -> Result<(), PhysicsFault> {
    check(&page_estimator::<M>(img).unwrap(), img.control.get())
}

fn algebraic(params: [f32; 4]) -> Result<(), PhysicsFault> {
    verdict::<Algebraic>(&page("algebraic", &params))
}

#[test]
fn a_published_clutch_set_passes_in_chunks_as_at_once() {
    let img = page("algebraic", &SEED000_AVERAGE);
    let est = page_estimator::<Algebraic>(&img).unwrap();
    let mut sweep = Sweep::new(&est, img.control.get());
    assert_eq!(sweep.steps(), 20_001, "0.5 s each way at 20 kHz");
    let mut chunks = 0;
    let v = loop {
        chunks += 1;
        if let Some(v) = sweep.advance(32) {
            break v;
        }
    };
    assert_eq!(v, Ok(()));
    assert_eq!(chunks, 20_001usize.div_ceil(32));
    assert_eq!(sweep.advance(32), Some(Ok(())), "the verdict stays");
    assert_eq!(check(&est, img.control.get()), Ok(()));
}

#[test]
fn the_firmware_default_and_a_fitted_set_that_turns_over_pass() {
    // The compiled-in page's set (peak at 0.79 T).
    assert_eq!(algebraic([20.0, -0.05, -10.0, 0.8]), Ok(()));
    // `simulate --scenario sine_1hz` + `fit --model algebraic`: fitted up to 0.6 T, it peaks
    // at 15.2 N·m at 0.62 T and falls to 12.2 N·m at 0.8 T, a fifth of its span.
    assert_eq!(algebraic([30.839, -0.0277, -32.338, 0.8139]), Ok(()));
}

#[test]
fn the_stiffness_with_the_wrong_sign_is_refused_as_decreasing() {
    let [k, c, alpha, t0] = SEED000_AVERAGE;
    match algebraic([-k, c, alpha, t0]) {
        Err(PhysicsFault::Decreasing { high, low, span }) => {
            // From T₀ at zero field down to about −k·b_max + α·b_max⁴ + T₀ near b_max (the
            // rate term c·Ḃ, with the rate estimator's lag, moves the lowest reading a
            // little before the top).
            assert_eq!(high.b, 0.0);
            assert!((high.torque - t0).abs() < 1e-3, "{high:?}");
            let want = -k * 0.8 + alpha * 0.8f32.powi(4) + t0;
            assert!((low.b - 0.8).abs() < 5e-3 && (low.torque - want).abs() < 0.05, "{low:?} vs {want}");
            assert!((span - (high.torque - low.torque)).abs() < 1e-4, "{span}");
        }
        other => panic!("{other:?}"),
    }
    // The fitted set flipped also exceeds the rating (−37 N·m at 0.8 T); it is reported as
    // falling with the field, the more specific reason.
    assert!(matches!(algebraic([-30.839, -0.0277, -32.338, 0.8139]), Err(PhysicsFault::Decreasing { .. })));
}

#[test]
fn a_set_scaled_a_thousandfold_is_refused_as_exceeding_the_rating() {
    let scaled = SEED000_AVERAGE.map(|p| 1000.0 * p);
    match algebraic(scaled) {
        Err(PhysicsFault::ExceedsRating { at, limit }) => {
            assert_eq!(limit, RATING_MARGIN * 15.0);
            // The largest estimate is about the static one at b_max (the rate term c·Ḃ,
            // c < 0, adds a little as the field turns down).
            let [k, _, alpha, t0] = scaled;
            let want = k * 0.8 + alpha * 0.8f32.powi(4) + t0;
            assert!((at.b - 0.8).abs() < 5e-3 && (at.torque - want).abs() < 0.01 * want, "{at:?} vs {want}");
        }
        other => panic!("{other:?}"),
    }
}

/// A stand-in model whose output is NaN above a field: what a set that overflows inside a
/// model (∞ − ∞, 0·∞) gives.
#[derive(Clone, Copy, Debug)]
struct NanAbove(f32);

impl Model for NanAbove {
    type State = ();
    const ID: &'static str = "nan_above";
    const PARAM_NAMES: &'static [&'static str] = &["b"];
    const N_PARAMS: usize = 1;
    fn from_params(v: &[f32], _dt: f32) -> Result<Self, ParamError> {
        Ok(Self(v.first().copied().unwrap_or(0.0)))
    }
    fn write_params(&self, out: &mut [f32]) -> usize {
        crate::model::write_flat(&[self.0], out)
    }
    fn dt(&self) -> f32 {
        DT
    }
    fn step(&self, _: &mut (), k: &Kin) -> f32 {
        if k.x > self.0 {
            f32::NAN
        } else {
            20.0 * k.x
        }
    }
}

#[test]
fn a_nan_producing_set_is_refused_as_non_finite() {
    let img = page("nan_above", &[0.5]);
    match verdict::<NanAbove>(&img) {
        Err(PhysicsFault::NonFinite { b }) => assert!(b > 0.5 && b < 0.5001, "{b}"),
        other => panic!("{other:?}"),
    }
    // An algebraic set whose rate term overflows f32 on the sweep (|c·Ḃ| > 3.4e38).
    match algebraic([1.0, f32::MAX, 0.0, 0.0]) {
        Err(PhysicsFault::NonFinite { b }) => assert!(b > 0.0 && b < 0.8, "{b}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_flat_set_is_refused_as_not_rising() {
    match algebraic([0.5, 0.0, 0.0, 2.0]) {
        Err(PhysicsFault::NotRising { at_zero, at_max, needed }) => {
            assert_eq!((at_zero.b, at_zero.torque), (0.0, 2.0));
            assert!((at_max.b - 0.8).abs() < 1e-6 && (at_max.torque - 2.4).abs() < 1e-4, "{at_max:?}");
            assert_eq!(needed, MIN_RISE_SHARE * 15.0);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_damper_set_run_on_the_field_is_refused_as_exceeding_the_rating() {
    // `hil-sim fit ranran_50.csv --input D --output F --model dahl`: displacement (cm) to
    // force (N) of the Dyke damper, in `Dahl::PARAM_NAMES` order. On a field of 0-0.8 T its
    // Dahl variable saturates within 0.03 T and the estimate is ±600-700 N.
    let p = [17.189, 0.0, 598.33, 0.0, 0.0, 113.04, 99.977, 190.0];
    match verdict::<Dahl>(&page("dahl", &p)) {
        Err(PhysicsFault::ExceedsRating { at, limit }) => {
            assert!(at.torque.abs() > 600.0 && limit == 30.0, "{at:?}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_sweep_is_bounded_for_any_time_step() {
    let control = ControlConfig::defaults(DT);
    for (dt, half) in [(5e-5, 10_000), (1e-3, 500), (1e-7, MAX_HALF_STEPS), (10.0, MIN_HALF_STEPS)] {
        let est = Estimator::new(
            Algebraic::from_params(&SEED000_AVERAGE, dt).unwrap(),
            crate::rate::RateParams::backward(dt).unwrap(),
        )
        .unwrap();
        assert_eq!(Sweep::new(&est, &control).steps(), 2 * half + 1, "dt {dt}");
    }
    // The profile: zero at both ends, b_max at the top, never negative.
    let plan = Plan::new(DT, &control);
    assert_eq!(plan.field(0), 0.0);
    assert_eq!(plan.field(plan.half), 0.8);
    assert_eq!(plan.field(2 * plan.half), 0.0);
    assert!((0..=2 * plan.half).all(|k| plan.field(k) >= 0.0 && plan.field(k) <= 0.8));
    // Rising then falling, symmetric about the top.
    assert!((1..=plan.half).all(|k| plan.field(k) >= plan.field(k - 1)));
    assert!((1..=plan.half).all(|k| plan.field(plan.half + k) == plan.field(plan.half - k)));
}
