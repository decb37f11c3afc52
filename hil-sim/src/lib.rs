//! Host side of the MR clutch controller: read recordings, replay them through model-core,
//! identify and diagnose models, simulate the clutch, run the firmware's control step in
//! closed loop, and measure the firmware's budgets.
//!
//! One room per responsibility: [`io`] (files in and out), [`quality`] (data-quality
//! checks), [`models`] (what each model needs on the host, one file per model), [`ident`]
//! (fit, compare, diagnose), [`sim`] (the clutch simulator, scenarios, excitations,
//! concealed-effect recordings), [`closed_loop`], [`budget`], [`report`] (plots and the
//! HTML report), [`numerics`] (least squares, statistics, derivatives, metrics). The CLI
//! (`src/cli/`, binary only) parses flags, calls one function here and prints.

pub mod budget;
pub mod closed_loop;
pub mod ident;
pub mod io;
pub mod link;
pub mod models;
pub mod numerics;
pub mod progress;
pub mod quality;
pub mod report;
pub mod sim;
pub mod virtual_board;
