//! Simulation: recordings made from the models.

pub mod concealed;
