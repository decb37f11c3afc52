//! What a diagnosis returns: the findings (which physics, how big, where, the held-out
//! error before and after), every candidate tested, where the base residual concentrates
//! and what the report plots.

use std::collections::BTreeMap;

use serde::Serialize;

use super::acting::Acting;
use super::candidates::AuxChannel;
use super::lag_or_delay::Mixture;
use super::locate::{Condition, Locate};
use super::replicate::Replication;
use super::significance::Test;
use crate::numerics::metrics::Metrics;

/// One piece of missing physics, in the contract's shape.
#[derive(Clone, Debug, Serialize)]
pub struct Finding {
    pub effect: String,
    pub summary: String,
    /// Where the gain concentrates, seconds.
    pub windows: Vec<(f64, f64)>,
    /// Fitted values of the term (units in the names or in `units`).
    pub params: BTreeMap<String, f64>,
    /// Units of `params` entries whose name does not carry one.
    pub units: BTreeMap<String, String>,
    pub heldout_before: Metrics,
    pub heldout_after: Metrics,
    /// Operating conditions where the gain concentrates, strongest first.
    #[serde(rename = "where")]
    pub conditions: Vec<Condition>,
    /// The candidate as tested (label, channel, test outcome, size).
    pub evidence: Evidence,
    /// When the evidence is weak, the candidate that does nearly as well (effect and term).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub runner_up: Option<String>,
}

/// How a candidate fared.
#[derive(Clone, Debug, Serialize)]
pub struct Evidence {
    pub label: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub channel: Option<String>,
    pub test: Test,
    /// The reversed split, when the held-out tail alone did not settle it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replication: Option<Replication>,
    /// The lag and the delay given together, when that told them apart.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_or_delay: Option<Mixture>,
    /// The split where it acts, when the tail barely excited it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acting: Option<Acting>,
    /// RMS of what the term changes in the prediction, output units, and as a share of the
    /// output's span.
    pub term_rms: f64,
    pub term_share_of_span: f64,
    /// Training-part information criterion gain (positive: better).
    pub bic_gain: f64,
}

/// A candidate tested in one round.
#[derive(Clone, Debug, Serialize)]
pub struct Tested {
    pub round: usize,
    pub effect: String,
    pub label: String,
    /// The candidate's grid value (`tau_s`, `delay_s`, …) where it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<(String, f64)>,
    pub bic_gain: f64,
    pub heldout_r_rmse_before: f64,
    pub heldout_r_rmse_after: f64,
    pub test: Test,
    /// RMS of what the term changes in the prediction, in units of the residual's noise
    /// floor (below [`super::significance::MIN_TERM_OF_NOISE`] the recording does not resolve it).
    pub change_of_noise: f64,
    /// What the term changes in the held-out tail's prediction over what it changes in the
    /// training part's (RMS ratio; below [`super::acting::QUIET_TAIL`] the tail barely
    /// excites it).
    pub tail_share: f64,
    pub kept: bool,
    /// Why its fitted values are physically impossible (then it is never kept).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub impossible: Option<String>,
    /// Read as an effect an earlier round named ([`super::physical::reading`]: a loop
    /// narrowing after a saturation): then it is never kept.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub named_before: bool,
    /// The reversed split, when it was given one ([`super::replicate`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replication: Option<Replication>,
    /// A field lag and a delay of the torque given together, when the two came within
    /// [`super::replicate::NEAR`] of each other ([`super::lag_or_delay`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_or_delay: Option<Mixture>,
    /// The split where it acts, when the tail barely excited it ([`super::acting`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acting: Option<Acting>,
    /// A field lag against the input smoothed without its phase, when it was to be kept
    /// ([`super::zero_phase`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub zero_phase: Option<super::zero_phase::Control>,
    /// Another field lag of the round was no better than its zero-phase control, and every
    /// field lag of the round was left out with it.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub barred: bool,
}

/// The whole diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub base_model: String,
    pub heldout_fraction: f64,
    pub findings: Vec<Finding>,
    /// The base model as fitted, held-out part.
    pub base_heldout: Metrics,
    /// The base model as the first round's candidates were judged against it, held-out part:
    /// refitted from the fit until it stalls (further when a candidate's refit found better
    /// base parameters), with its play operators and its level term when it has them.
    pub reference_heldout: Metrics,
    /// The model the diagnosis ends with (the reference with every finding's term), held-out
    /// part; the reference's when nothing was found.
    pub final_heldout: Metrics,
    /// Base models tried by `auto`, with their held-out R-RMSE.
    pub bases_tried: Vec<(String, f64)>,
    /// Every base `auto` gave a first round ([`super::contenders`]), with what it found there.
    pub contenders: Vec<super::contenders::Contender>,
    pub locate: Locate,
    pub channels: Vec<AuxChannel>,
    pub candidates: Vec<Tested>,
    /// What the diagnosis could not do, in words: a base model `auto` could not fit and why,
    /// a round stopped because the base model's Jacobian could not be taken.
    pub notes: Vec<String>,
    /// Units of the input and the output channel (empty when the names are not known ones).
    pub units: (String, String),
    pub seconds: f64,
    #[serde(skip)]
    pub plot: PlotData,
}

impl Diagnosis {
    /// The reference's held-out metrics when they read otherwise than the fit's at two
    /// decimals of a per cent; `None` when the header needs one figure only.
    pub fn reference_apart(&self) -> Option<&Metrics> {
        let pct = |m: &Metrics| format!("{:.2}", 100.0 * m.r_rmse);
        (pct(&self.reference_heldout) != pct(&self.base_heldout)).then_some(&self.reference_heldout)
    }
}

/// What the report draws.
#[derive(Clone, Debug, Default)]
pub struct PlotData {
    pub time: Vec<f64>,
    pub input: Vec<f64>,
    pub output: Vec<f64>,
    /// The base model as fitted and the final model.
    pub before: Vec<f64>,
    pub after: Vec<f64>,
    pub train_end: usize,
    pub heldout_rows: Vec<usize>,
    pub fs: f64,
}
