//! What the control interrupt hands the tasks: the decimated snapshot for the log and the
//! ring of samples for the serial link's telemetry stream.

use model_core::control::{ControlOutput, FaultCode, Mode};

/// One decimated sample for the log (the step's raw output; formatting in the log).
#[derive(Clone, Copy, Debug, Default)]
pub struct Snapshot {
    pub out: ControlOutput,
    /// Torque reference, N·m.
    pub reference: f32,
    /// Bridge supply, V.
    pub supply_v: f32,
    /// Core cycles the step took.
    pub cycles: u32,
}

impl Snapshot {
    pub const EMPTY: Self = Self { out: EMPTY_OUTPUT, reference: 0.0, supply_v: 0.0, cycles: 0 };
}

/// One control sample for the serial link's telemetry stream (raw step output; the serial
/// task numbers and encodes it).
#[derive(Clone, Copy, Debug, Default)]
pub struct StreamSample {
    /// Sample index since start-up (the stream's sequence numbers).
    pub n: u32,
    /// Its time since start-up, µs (wraps after 71 min): the control periods summed, so it
    /// stays right across a page swapped in at another control rate.
    pub t_us: u32,
    pub out: ControlOutput,
    /// Torque reference, N·m.
    pub reference: f32,
    /// The clutch's true torque, N·m, where it is known (a simulated clutch); NaN on the
    /// board.
    pub torque_true: f32,
}

/// Samples waiting for the serial task; a full ring drops the newest (the host sees the
/// gap in the sequence numbers).
pub struct StreamRing {
    buf: [StreamSample; STREAM_RING],
    head: usize,
    len: usize,
}

/// Ring length, samples (0.8 ms at 20 kHz with every sample streamed; the serial task
/// drains it every 0.5 ms).
pub const STREAM_RING: usize = 16;

impl Default for StreamRing {
    fn default() -> Self {
        Self::new()
    }
}

impl StreamRing {
    pub const fn new() -> Self {
        let empty = StreamSample { n: 0, t_us: 0, out: EMPTY_OUTPUT, reference: 0.0, torque_true: f32::NAN };
        Self { buf: [empty; STREAM_RING], head: 0, len: 0 }
    }

    /// Queue `s` (dropped when the ring is full).
    #[inline(always)]
    pub fn push(&mut self, s: StreamSample) {
        if self.len < STREAM_RING {
            if let Some(slot) = self.buf.get_mut((self.head + self.len) % STREAM_RING) {
                *slot = s;
                self.len += 1;
            }
        }
    }

    /// The oldest sample.
    pub fn pop(&mut self) -> Option<StreamSample> {
        if self.len == 0 {
            return None;
        }
        let s = self.buf.get(self.head).copied();
        self.head = (self.head + 1) % STREAM_RING;
        self.len -= 1;
        s
    }
}

/// A step output before the first step.
pub const EMPTY_OUTPUT: ControlOutput = ControlOutput {
    duty: 0.0,
    compare: 0,
    pwm_enable: false,
    b: 0.0,
    current: 0.0,
    torque_est: 0.0,
    i_ref: 0.0,
    v_cmd: 0.0,
    mode: Mode::Init,
    fault: FaultCode::None,
    flags: 0,
};

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: u32) -> StreamSample {
        StreamSample { n, ..Default::default() }
    }

    #[test]
    fn the_ring_keeps_the_oldest_and_drops_the_newest_when_full() {
        let mut r = StreamRing::new();
        for n in 0..(STREAM_RING as u32 + 3) {
            r.push(sample(n));
        }
        let got: Vec<u32> = core::iter::from_fn(|| r.pop()).map(|s| s.n).collect();
        assert_eq!(got, (0..STREAM_RING as u32).collect::<Vec<_>>());
        r.push(sample(99));
        assert_eq!(r.pop().map(|s| s.n), Some(99), "room again once drained");
    }
}
