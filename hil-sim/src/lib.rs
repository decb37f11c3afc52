//! Host side of the MR clutch controller: recordings, replay through model-core,
//! accuracy checks of the fixed-step core.

pub mod reference;
