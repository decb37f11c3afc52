//! Files in and out: recordings (CSV, MAT), parameter files, the firmware's configuration
//! page and its physics check, and where the bundled laboratory data lives.

pub mod bundled;
pub mod config_page;
pub mod manifest;
pub mod output;
pub mod page_physics;
pub mod params_file;
pub mod rate;
pub mod recording;
