//! The controller a configuration page describes, for every model that maps the field to
//! torque: one variant per model, built once from a validated page (`from_image`), then
//! stepped by the control interrupt (and by `hil-sim virtual-board` on the host) without
//! a failure path. The damper models (command-dependent force laws in x) are not built in,
//! and neither is `preisach`: its 50 × 50 weight table (10 KB) is built by value through
//! `from_params` → `ControlStep::new` → the enum, several copies deep on the stack, which
//! the commit and boot paths cannot afford next to 55 KB of static RAM (it needs an in-place
//! constructor in model-core first).

use model_core::control::ValidatedConfig;
use model_core::control::{ConfigImage, ControlInput, ControlOutput, ControlState, ControlStep, PageError};
use model_core::models::{
    algebraic, bouc_wen, bouc_wen_asym, dahl, gpi, hammerstein_wiener, lugre, maxwell_slip, narx, prandtl_ishlinskii,
    tanh,
};
use model_core::Model;

/// Calls `$callback!` with `Variant => model type` for every model the firmware runs.
macro_rules! clutch_models {
    ($callback:ident) => {
        $callback! {
            Algebraic => algebraic::Registered,
            BoucWen => bouc_wen::Registered,
            LuGre => lugre::Registered,
            Tanh => tanh::Registered,
            Dahl => dahl::Registered,
            HammersteinWiener => hammerstein_wiener::Registered,
            Narx => narx::Registered,
            PrandtlIshlinskii => prandtl_ishlinskii::Registered,
            Gpi => gpi::Registered,
            MaxwellSlip => maxwell_slip::Registered,
            BoucWenAsym => bouc_wen_asym::Registered,
        }
    };
}

fn make<M: Model>(img: &ConfigImage) -> Result<(ControlStep<M>, ControlState<M::State>), PageError> {
    let rate = img.rate.build(img.control.get().dt).map_err(PageError::Invalid)?;
    let step = ControlStep::new(img.model::<M>()?, rate).map_err(PageError::Invalid)?;
    let state = step.state();
    Ok((step, state))
}

macro_rules! define_loop {
    ($($v:ident => $m:ty),* $(,)?) => {
        /// The model ids the firmware is built with (`Model::ID`, as `export` checks them).
        pub const MODELS: [&str; [$(stringify!($v)),*].len()] = [$(<$m as Model>::ID),*];

        /// The running controller: the control step of one model and its state.
        #[allow(clippy::large_enum_variant)]
        pub enum Loop {
            $($v(ControlStep<$m>, ControlState<<$m as Model>::State>),)*
        }

        impl Loop {
            /// The controller a page describes, validated (model parameters by
            /// `from_params` at the page's time step); `WrongModel` for a model not built in.
            pub fn from_image(img: &ConfigImage) -> Result<Self, PageError> {
                let id = img.model_id();
                $(if id == <$m as Model>::ID {
                    return make::<$m>(img).map(|(s, st)| Self::$v(s, st));
                })*
                Err(PageError::WrongModel)
            }

            /// The model id.
            pub fn model_id(&self) -> &'static str {
                match self {
                    $(Self::$v(..) => <$m as Model>::ID,)*
                }
            }

            /// The slow supervisor pass (temperature in °C, NaN when unknown).
            pub fn slow(&mut self, cfg: &ValidatedConfig, temperature: f32) {
                match self {
                    $(Self::$v(s, st) => s.slow(cfg, st, temperature),)*
                }
            }

            /// One control step.
            #[inline(always)]
            pub fn step(&mut self, cfg: &ValidatedConfig, x: ControlInput) -> ControlOutput {
                match self {
                    $(Self::$v(s, st) => s.step(cfg, st, x),)*
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
