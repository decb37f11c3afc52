//! Simulation: the MR clutch plant, the scenarios that drive it, the papers' excitation
//! signals, and recordings with a concealed effect.

pub mod accuracy;
pub mod bench;
pub mod concealed;
pub mod excitation;
pub mod plant;
pub mod scenario;
