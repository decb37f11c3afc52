//! Integration tests across the crates live in `tests/tests/`.

pub mod board;
pub mod peer;
