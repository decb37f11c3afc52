//! The controller a configuration page describes, for every model that maps the field to
//! torque: one variant per model, built once from a validated page (`from_image`), then
//! stepped by the control interrupt (and by `hil-sim virtual-board` on the host) without
//! a failure path. The damper models (command-dependent force laws in x) are not built in.
//! `preisach`'s control step (its 50 × 50 weight table, 10 KB) is built in place in a static
//! slot the [`Loop`] owns ([`PreisachSlot`]), so neither the commit and boot paths nor the
//! control interrupt's swap copy it. Each model runs at its own control rate
//! ([`control_hz_of`], [`Loop::control_hz`]). The physics check of a page's model
//! ([`model_core::control::physics`]) runs on the estimator a [`Loop`] holds
//! ([`Loop::sweep`]), so every built-in model has it and Preisach's table is not copied.

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};
use model_core::control::physics::Sweep;
use model_core::control::{ConfigImage, ControlInput, ControlOutput, ControlState, ControlStep, PageError};
use model_core::control::{ControlConfig, PhysicsFault, ValidatedConfig};

use model_core::models::{
    algebraic, bouc_wen, bouc_wen_asym, dahl, gpi, hammerstein_wiener, lugre, maxwell_slip, narx, prandtl_ishlinskii,
    preisach, tanh,
};
use model_core::rate::RateParams;
use model_core::{Estimator, Model};

use crate::bringup::{rate_of_dt, CONTROL_RATES, CORE_HZ};

/// Calls `$callback!` with `Variant(control rate, Hz) => model type [where its control step
/// is kept]` for every model the firmware runs: the one place the rate of each model is set (issue 17). Each is the
/// fastest rate of [`CONTROL_RATES`] at which the model's control interrupt fits
/// ([`fits`]) by the worst cycles `hil-sim budget` measures (`control_step_<id>` plus
/// `supervisor_slow_<id>`, figures of 2026-11-24 in the comments); `hil-sim budget --check`
/// fails when one no longer fits at its rate.
macro_rules! clutch_models {
    ($callback:ident) => {
        $callback! {
            Algebraic(20_000) => algebraic::Registered [ControlStep<algebraic::Registered>],            // 520 + 4867 cycles
            BoucWen(20_000) => bouc_wen::Registered [ControlStep<bouc_wen::Registered>],               // 1221 + 6640
            LuGre(20_000) => lugre::Registered [ControlStep<lugre::Registered>],                    // 878 + 5836
            Tanh(20_000) => tanh::Registered [ControlStep<tanh::Registered>],                      // 611 + 5130
            Dahl(20_000) => dahl::Registered [ControlStep<dahl::Registered>],                      // 1358 + 5940
            HammersteinWiener(5_000) => hammerstein_wiener::Registered [ControlStep<hammerstein_wiener::Registered>], // 6738 + 17339
            // The first running sample seeds the NARX state by a 32-step bisection of its
            // fixed point (~33 network evaluations): 56508 + 9704.
            Narx(1_000) => narx::Registered [ControlStep<narx::Registered>],
            PrandtlIshlinskii(20_000) => prandtl_ishlinskii::Registered [ControlStep<prandtl_ishlinskii::Registered>], // 1720 + 6624
            Gpi(10_000) => gpi::Registered [ControlStep<gpi::Registered>],                        // 1977 + 7224
            MaxwellSlip(20_000) => maxwell_slip::Registered [ControlStep<maxwell_slip::Registered>],       // 882 + 5575
            BoucWenAsym(20_000) => bouc_wen_asym::Registered [ControlStep<bouc_wen_asym::Registered>],      // 975 + 6069
            // Built in place in a static slot (its 50 × 50 table, 10 KB): 1957 + 9028.
            Preisach(10_000) => preisach::Registered [PreisachSlot],
        }
    };
}

/// The rate of the slow supervisor pass, Hz (the firmware's `supervisor` task asks for it;
/// it runs in the control interrupt's tail).
pub const SLOW_HZ: u32 = 1_000;
/// The share of the core the control interrupt may take, percent: the worst control step
/// at the model's rate plus the worst slow pass at [`SLOW_HZ`] (amortised).
pub const CPU_SHARE_PERCENT: u64 = 50;

/// Whether a control interrupt fits at `control_hz` on the [`CORE_HZ`] core, from the
/// worst cycles of its step and of its slow pass:
/// - deadline: step + slow pass (the interrupt that runs both) within one control period;
/// - share: `step · control_hz + slow · SLOW_HZ` at most [`CPU_SHARE_PERCENT`] of the core.
pub fn fits(step_cycles: u64, slow_cycles: u64, control_hz: u32) -> bool {
    let (hz, core) = (u64::from(control_hz), u64::from(CORE_HZ));
    control_hz > 0
        && step_cycles + slow_cycles <= core / hz
        && 100 * (step_cycles * hz + slow_cycles * u64::from(SLOW_HZ)) <= CPU_SHARE_PERCENT * core
}

/// The fastest rate of [`CONTROL_RATES`] at which those cycles [`fits`].
pub fn fastest_fitting(step_cycles: u64, slow_cycles: u64) -> Option<u32> {
    CONTROL_RATES.iter().copied().find(|&hz| fits(step_cycles, slow_cycles, hz))
}

/// Where a controller keeps its control step: by value in the [`Loop`], or (Preisach) in a
/// static slot the [`Loop`] owns.
pub trait Store<M: Model>: Sized {
    /// The control step of a page (model parameters by `from_params` at its time step).
    fn build(img: &ConfigImage) -> Result<Self, PageError>;
    fn get(&self) -> &ControlStep<M>;
}

impl<M: Model> Store<M> for ControlStep<M> {
    fn build(img: &ConfigImage) -> Result<Self, PageError> {
        let rate = img.rate.build(img.control.get().dt).map_err(PageError::Invalid)?;
        ControlStep::new(img.model::<M>()?, rate).map_err(PageError::Invalid)
    }

    #[inline(always)]
    fn get(&self) -> &ControlStep<M> {
        self
    }
}

type PreisachStep = ControlStep<preisach::Registered>;

/// How many Preisach controllers can exist at once: on the board the running one and one
/// built for a commit (or at start-up one per configuration slot); on the host (virtual
/// boards, tests in parallel threads) more.
#[cfg(target_os = "none")]
pub const PREISACH_SLOTS: usize = 2;
#[cfg(not(target_os = "none"))]
pub const PREISACH_SLOTS: usize = 16;

/// Static storage of one Preisach control step (its 50 × 50 weight table, 10 KB, is built
/// here in place and never moved: building it by value copied it several times over the
/// stack of the commit and boot paths, and swapping it into the control interrupt would
/// copy it there). On the board the steps live in CCM SRAM (`.ccmram` in `memory.x`, not
/// zeroed at start-up: a slot's step is written whole before its first use), the flags in
/// the main SRAM.
struct Slot {
    taken: AtomicBool,
    /// `step` holds a value (written once, at the slot's first use).
    ready: AtomicBool,
}

#[allow(clippy::declare_interior_mutable_const)]
const FREE_SLOT: Slot = Slot { taken: AtomicBool::new(false), ready: AtomicBool::new(false) };
static SLOTS: [Slot; PREISACH_SLOTS] = [FREE_SLOT; PREISACH_SLOTS];

/// The steps of [`SLOTS`], same index.
struct Steps([UnsafeCell<MaybeUninit<PreisachStep>>; PREISACH_SLOTS]);

// SAFETY: step `i` is reached only through the one `PreisachSlot` that took `SLOTS[i]` (a
// compare-exchange of `taken` from false to true, released when it drops), so there is
// never more than one owner; shared access (`get`) needs `&PreisachSlot`, building
// (`get_mut`) `&mut PreisachSlot`, as for a value the `Loop` held itself.
unsafe impl Sync for Steps {}

#[allow(clippy::declare_interior_mutable_const)]
const NO_STEP: UnsafeCell<MaybeUninit<PreisachStep>> = UnsafeCell::new(MaybeUninit::uninit());
#[cfg_attr(target_os = "none", link_section = ".ccmram")]
static STEPS: Steps = Steps([NO_STEP; PREISACH_SLOTS]);

/// A placeholder step (all zero) a slot starts from.
const ZERO_STEP: PreisachStep =
    ControlStep { est: Estimator { model: preisach::Registered::ZEROED, rate: RateParams::Backward { inv_dt: 0.0 } } };

/// A Preisach control step in one of the static slots, owned by the [`Loop`] that holds it
/// (the slot is free again when it drops).
pub struct PreisachSlot {
    slot: &'static Slot,
    step: &'static UnsafeCell<MaybeUninit<PreisachStep>>,
}

impl PreisachSlot {
    /// A free slot, now taken (`None`: all [`PREISACH_SLOTS`] are in use).
    fn take() -> Option<Self> {
        let (slot, step) = SLOTS
            .iter()
            .zip(STEPS.0.iter())
            .find(|(s, _)| s.taken.compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed).is_ok())?;
        if !slot.ready.load(Ordering::Relaxed) {
            // SAFETY: this is the slot's only owner (see `Steps`); nothing refers to the step.
            unsafe { (*step.get()).write(ZERO_STEP) };
            slot.ready.store(true, Ordering::Relaxed);
        }
        Some(Self { slot, step })
    }

    fn get_mut(&mut self) -> &mut PreisachStep {
        // SAFETY: this is the slot's only owner (see `Steps`), borrowed mutably; `take`
        // wrote the step before handing the slot out.
        unsafe { (*self.step.get()).assume_init_mut() }
    }
}

// SAFETY: the one owner of its step (see `Steps`): moving it to another thread or to the
// control interrupt moves that ownership, as for a value the `Loop` held itself.
unsafe impl Send for PreisachSlot {}

impl Drop for PreisachSlot {
    fn drop(&mut self) {
        self.slot.taken.store(false, Ordering::Release);
    }
}

impl Store<preisach::Registered> for PreisachSlot {
    /// Built in place ([`Preisach::rebuild_from_params`](model_core::models::preisach::Preisach::rebuild_from_params)):
    /// no copy of the table on the stack.
    fn build(img: &ConfigImage) -> Result<Self, PageError> {
        if img.model_id() != <preisach::Registered as Model>::ID {
            return Err(PageError::WrongModel);
        }
        let dt = img.control.get().dt;
        let rate = img.rate.build(dt).map_err(PageError::Invalid)?;
        let mut slot = Self::take().ok_or(PageError::Malformed("every Preisach slot is in use"))?;
        let step = slot.get_mut();
        // `rebuild_from_params` checks the time step as `Estimator::new` does.
        step.est.model.rebuild_from_params(img.params(), dt).map_err(PageError::Invalid)?;
        step.est.rate = rate;
        Ok(slot)
    }

    #[inline(always)]
    fn get(&self) -> &PreisachStep {
        // SAFETY: this is the slot's only owner (see `Steps`), borrowed shared; `take` wrote
        // the step before handing the slot out.
        unsafe { (*self.step.get()).assume_init_ref() }
    }
}

macro_rules! define_loop {
    ($($v:ident($hz:literal) => $m:ty [$store:ty]),* $(,)?) => {
        /// The model ids the firmware is built with (`Model::ID`, as `export` checks them).
        pub const MODELS: [&str; [$(stringify!($v)),*].len()] = [$(<$m as Model>::ID),*];

        /// The control rate (Hz) the firmware runs model `id` at (`None`: not built in).
        /// The page's time step must be its inverse (`hil-sim export` writes it so).
        pub fn control_hz_of(id: &str) -> Option<u32> {
            $(if id == <$m as Model>::ID {
                return Some($hz);
            })*
            None
        }

        /// The running controller: the control step of one model and its state.
        #[allow(clippy::large_enum_variant)]
        pub enum Loop {
            $($v($store, ControlState<<$m as Model>::State>),)*
        }

        impl Loop {
            /// The controller a page describes, validated (model parameters by
            /// `from_params` at the page's time step); `WrongModel` for a model not built in.
            pub fn from_image(img: &ConfigImage) -> Result<Self, PageError> {
                let id = img.model_id();
                if control_hz_of(id).is_some() && control_hz_of(id) != rate_of_dt(img.control.get().dt) {
                    return Err(PageError::Malformed("dt is not the model's control period"));
                }
                $(if id == <$m as Model>::ID {
                    return <$store as Store<$m>>::build(img).map(|s| Self::$v(s, ControlState::default()));
                })*
                Err(PageError::WrongModel)
            }

            /// The model id.
            pub fn model_id(&self) -> &'static str {
                match self {
                    $(Self::$v(..) => <$m as Model>::ID,)*
                }
            }

            /// The control rate this controller runs at, Hz ([`control_hz_of`] its model):
            /// the control interrupt's rate (TIM1's repetition counter) and the inverse of
            /// the page's time step.
            pub fn control_hz(&self) -> u32 {
                match self {
                    $(Self::$v(..) => $hz,)*
                }
            }

            /// The slow supervisor pass (temperature in °C, NaN when unknown).
            pub fn slow(&mut self, cfg: &ValidatedConfig, temperature: f32) {
                match self {
                    $(Self::$v(s, st) => Store::<$m>::get(s).slow(cfg, st, temperature),)*
                }
            }

            /// One control step.
            #[inline(always)]
            pub fn step(&mut self, cfg: &ValidatedConfig, x: ControlInput) -> ControlOutput {
                match self {
                    $(Self::$v(s, st) => Store::<$m>::get(s).step(cfg, st, x),)*
                }
            }

            /// The physics check of this controller's estimator (its model, rate
            /// estimator and time step) over the field range and against the rating of
            /// `control` (the page's settings), to advance in chunks.
            pub fn sweep(&self, control: &ControlConfig) -> LoopSweep<'_> {
                match self {
                    $(Self::$v(s, _) => LoopSweep::$v(Sweep::new(&Store::<$m>::get(s).est, control)),)*
                }
            }
        }

        /// A physics check in progress on a [`Loop`]'s estimator ([`Loop::sweep`]).
        pub enum LoopSweep<'a> {
            $($v(Sweep<'a, $m>),)*
        }

        impl LoopSweep<'_> {
            /// At most `max_steps` samples of the sweep: `None` while it goes on, then the
            /// verdict ([`Sweep::advance`]).
            pub fn advance(&mut self, max_steps: u32) -> Option<Result<(), PhysicsFault>> {
                match self {
                    $(Self::$v(s) => s.advance(max_steps),)*
                }
            }
        }
    };
}
clutch_models!(define_loop);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_has_a_menu_rate_and_the_share_rule_picks_it() {
        for id in MODELS {
            let hz = control_hz_of(id).expect("a rate");
            assert!(CONTROL_RATES.contains(&hz), "{id}: {hz} Hz off the menu");
        }
        assert_eq!(control_hz_of("spencer"), None);
        // The figures in `clutch_models!`'s comments give its rates.
        assert_eq!(fastest_fitting(520, 4867), control_hz_of("algebraic"));
        assert_eq!(fastest_fitting(1720, 6624), control_hz_of("prandtl_ishlinskii"));
        assert_eq!(fastest_fitting(1977, 7224), control_hz_of("gpi"));
        assert_eq!(fastest_fitting(6738, 17339), control_hz_of("hammerstein_wiener"));
        assert_eq!(fastest_fitting(56508, 9704), control_hz_of("narx"));
        // Deadline: step + slow pass beyond one 20 kHz period (8500 cycles).
        assert!(fits(1000, 7500, 20_000) && !fits(1000, 7501, 20_000));
        // Share: 56508 cycles at 2 kHz are 66 % of the core with the slow pass.
        assert!(!fits(56508, 9704, 2_000) && fits(56508, 9704, 1_000));
        assert_eq!(fastest_fitting(200_000, 0), None);
    }

    #[test]
    fn a_page_at_another_rate_than_its_models_is_refused() {
        let img = crate::bringup::default_image().expect("image");
        assert_eq!(Loop::from_image(&img).map(|l| l.control_hz()).ok(), Some(20_000));
        let mut c = *img.control.get();
        c.dt = 1.0 / 10_000.0;
        let control = c.validate().expect("valid");
        let other = ConfigImage::new(img.model_id(), img.params(), img.rate, control).expect("page");
        assert!(matches!(Loop::from_image(&other), Err(PageError::Malformed(_))));
    }

    fn preisach_page(hz: f32) -> ConfigImage {
        let img = crate::bringup::default_image().expect("image");
        let mut c = *img.control.get();
        c.dt = 1.0 / hz;
        let control = c.validate().expect("valid");
        let p = [1.0, 2.0, 0.1, 0.05, 0.1, 1.0, -1.0, 1.0, 0.0];
        ConfigImage::new("preisach", &p, img.rate, control).expect("page")
    }

    /// Held by the tests that take Preisach slots: one of them fills every slot.
    static SLOT_TESTS: std::sync::Mutex<()> = std::sync::Mutex::new(());

    #[test]
    fn preisach_runs_from_a_static_slot_as_built_by_value() {
        let _one = SLOT_TESTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let img = preisach_page(10_000.0);
        assert!(matches!(Loop::from_image(&preisach_page(20_000.0)), Err(PageError::Malformed(_))));
        let mut lp = Loop::from_image(&img).expect("preisach loop");
        assert_eq!((lp.model_id(), lp.control_hz()), ("preisach", 10_000));
        assert!(core::mem::size_of::<Loop>() < 2048, "the table is not in the Loop");
        let by_value = <ControlStep<preisach::Registered> as Store<_>>::build(&img).expect("by value");
        let mut st = by_value.state();
        let cfg = img.control;
        for k in 0..400u16 {
            let x = ControlInput::new(2048 + k % 7, 2047 + k % 5, 24.0, 2.0);
            if k % 10 == 0 {
                lp.slow(&cfg, f32::NAN);
                by_value.slow(&cfg, &mut st, f32::NAN);
            }
            assert_eq!(lp.step(&cfg, x), by_value.step(&cfg, &mut st, x), "sample {k}");
        }
        // The slots are taken and given back (one test: no other one holds slots meanwhile).
        drop(lp);
        let mut held: Vec<Loop> = core::iter::from_fn(|| Loop::from_image(&img).ok()).collect();
        assert!(!held.is_empty() && held.len() <= PREISACH_SLOTS);
        assert!(matches!(Loop::from_image(&img), Err(PageError::Malformed(_))));
        held.pop();
        assert!(Loop::from_image(&img).is_ok(), "a dropped Loop frees its slot");
    }

    /// A [`LoopSweep`] to its verdict.
    fn swept(lp: &Loop, img: &ConfigImage) -> Result<(), PhysicsFault> {
        let mut sweep = lp.sweep(img.control.get());
        loop {
            if let Some(v) = sweep.advance(1000) {
                return v;
            }
        }
    }

    #[test]
    fn the_physics_sweep_runs_on_the_loops_estimator_as_on_one_built_by_value() {
        let _one = SLOT_TESTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        use model_core::control::physics::{check, page_estimator};
        let img = crate::bringup::default_image().expect("image");
        let lp = Loop::from_image(&img).expect("loop");
        let by_value = page_estimator::<algebraic::Registered>(&img).expect("estimator");
        assert_eq!(swept(&lp, &img), check(&by_value, img.control.get()));
        assert_eq!(swept(&lp, &img), Ok(()));
        // Preisach's from its static slot (its table not copied).
        let img = preisach_page(10_000.0);
        let lp = Loop::from_image(&img).expect("preisach loop");
        let by_value = page_estimator::<preisach::Registered>(&img).expect("estimator");
        assert_eq!(swept(&lp, &img), check(&by_value, img.control.get()));
        // The test page's 1275 relays sum to about 300 N·m at b_max: beyond the rating.
        assert!(matches!(swept(&lp, &img), Err(PhysicsFault::ExceedsRating { .. })));
    }

    #[test]
    fn every_listed_model_is_registered_and_the_default_page_runs() {
        for id in MODELS {
            assert!(model_core::registry::find(id).is_some(), "{id}");
        }
        let img = crate::bringup::default_image().expect("image");
        let lp = Loop::from_image(&img).expect("loop");
        assert_eq!(lp.model_id(), img.model_id());
        println!(
            "Loop {} B, ConfigImage {} B, Device {} B",
            core::mem::size_of::<Loop>(),
            core::mem::size_of::<ConfigImage>(),
            core::mem::size_of::<model_core::protocol::device::Device>()
        );
    }
}
