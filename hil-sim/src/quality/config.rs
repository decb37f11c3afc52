//! The thresholds of the checks, relative to each channel's own scales (see
//! [`Scale`](super::scale::Scale)).

/// Thresholds; [`Default`] gives the documented values.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityConfig {
    /// Clipping band at each extreme, fraction of the span.
    pub clip_band: f64,
    /// Visits to the band closer than this many T½ form one episode.
    pub clip_merge: f64,
    /// An episode is clipping when the signal spends at least this many T½ in the band
    /// (a sine's peak spends 0.18 T½ within 2 % of the span of its top; the free peaks of
    /// the Dyke recordings up to 0.37 T½, their end-stop episode 2.1 T½),
    pub clip_dwell: f64,
    /// or stays within 3σ of the extreme for at least this many T½ and
    pub clip_flat: f64,
    /// at least this many samples;
    pub clip_flat_samples: usize,
    /// and in either case the episode's longest hump (its visits with the channel staying
    /// within twice the band of the extreme between them) is flat: a parabola fitted to it
    /// (first to last visit) falls from its top to its lower end at most this share of how
    /// deep into the band that top reaches. A free peak traces its own curve, which falls
    /// from its top back to the band's edge, whether it reaches the extreme or grazes the band; a slow
    /// peak (a swept sine's first cycles, a 1 Hz block among faster ones) stays in the band
    /// for many of the recording's median T½, and a block of fast peaks at full amplitude
    /// merges into one long episode of many humps.
    pub clip_curved: f64,
    /// Standstill: the input stays within this fraction of its span
    pub standstill_band: f64,
    /// for at least this long (s) and at least `standstill_half_periods` T½.
    pub standstill_min_s: f64,
    pub standstill_half_periods: f64,
    /// An input clipping or hold episode through which the output stays within this fraction
    /// of its span is the device at rest (a standstill), not a sensor fault.
    pub standstill_output_band: f64,
    /// Held value: at least this many bit-identical samples, and at least 3× the longest
    /// run the channel's own repeat rate makes likely by chance.
    pub hold_samples: usize,
    /// Spike: distance from the 7-sample median at least this many local scales
    /// (1.4826·median |Δx| over ±32 samples, at least σ),
    pub spike_ratio: f64,
    /// and at least this fraction of the span,
    pub spike_span: f64,
    /// and at most this many samples in a row.
    pub spike_samples: usize,
    /// Sampling: an interval outside (1 ± this)·nominal is non-uniform; 1.5× or more is
    /// a gap (a missing sample). 0.5: a stamp off by less than half an interval still
    /// names its own grid point (the Dyke files' 0.1 ms rounding is 0.3 of an interval).
    pub dt_tolerance: f64,
}

impl Default for QualityConfig {
    fn default() -> Self {
        Self {
            clip_band: 0.02,
            clip_merge: 1.0,
            clip_dwell: 1.0,
            clip_flat: 0.1,
            clip_flat_samples: 10,
            clip_curved: 0.5,
            standstill_band: 0.01,
            standstill_min_s: 0.5,
            standstill_half_periods: 4.0,
            standstill_output_band: 0.05,
            hold_samples: 10,
            spike_ratio: 20.0,
            spike_span: 0.02,
            spike_samples: 3,
            dt_tolerance: 0.5,
        }
    }
}
