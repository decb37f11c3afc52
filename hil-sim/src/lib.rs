//! Host side of the MR clutch controller: recordings, replay through model-core,
//! accuracy checks of the fixed-step core.

pub mod accuracy;
pub mod alignment;
pub mod budget;
pub mod closed_loop;
pub mod compare;
pub mod data;
pub mod dispatch;
pub mod excitation;
pub mod export;
pub mod fit;
pub mod fit_report;
pub mod ident;
pub mod metrics;
pub mod params_file;
pub mod plant;
pub mod plot;
pub mod progress;
pub mod quality;
pub mod rate_offline;
pub mod recording;
pub mod reference;
pub mod replay;
pub mod report;
pub mod scenario;
pub mod sim;
