//! The telemetry stream: the control interrupt's signals, decimated, in SI units, with a
//! sequence number so a receiver counts the frames it lost. Frame `0x90` (little-endian):
//! u16 sequence, u32 time (µs since start-up, wraps), f32 B (T), f32 coil current (A),
//! f32 torque estimate (N·m), f32 reference (N·m, A in current mode), f32 duty (−1..1),
//! u8 mode, u8 fault code, f32 true torque (N·m; NaN on a board, the plant's on the virtual
//! board).

/// The frame's command byte.
pub const CODE: u8 = 0x90;
/// Its length in bytes.
pub const LEN: usize = 1 + 2 + 4 + 5 * 4 + 2 + 4;

/// One telemetry sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Telemetry {
    pub t_us: u32,
    pub b: f32,
    pub current: f32,
    pub torque_est: f32,
    pub reference: f32,
    pub duty: f32,
    pub mode: u8,
    pub fault: u8,
    pub torque_true: f32,
}

impl Telemetry {
    /// The frame with sequence number `seq`.
    pub fn encode(&self, seq: u16) -> [u8; LEN] {
        let mut out = [0u8; LEN];
        let parts: [&[u8]; 10] = [
            &[CODE],
            &seq.to_le_bytes(),
            &self.t_us.to_le_bytes(),
            &self.b.to_le_bytes(),
            &self.current.to_le_bytes(),
            &self.torque_est.to_le_bytes(),
            &self.reference.to_le_bytes(),
            &self.duty.to_le_bytes(),
            &[self.mode, self.fault],
            &self.torque_true.to_le_bytes(),
        ];
        for (o, i) in out.iter_mut().zip(parts.iter().flat_map(|p| p.iter())) {
            *o = *i;
        }
        out
    }

    /// A frame back into its sequence number and sample (`None` if it is not one).
    pub fn decode(frame: &[u8]) -> Option<(u16, Self)> {
        let f: &[u8; LEN] = frame.try_into().ok()?;
        if f[0] != CODE {
            return None;
        }
        let w = |i: usize| -> Option<[u8; 4]> { f.get(i..i + 4)?.try_into().ok() };
        let fl = |i: usize| w(i).map(f32::from_le_bytes);
        Some((
            u16::from_le_bytes([f[1], f[2]]),
            Self {
                t_us: u32::from_le_bytes(w(3)?),
                b: fl(7)?,
                current: fl(11)?,
                torque_est: fl(15)?,
                reference: fl(19)?,
                duty: fl(23)?,
                mode: f[27],
                fault: f[28],
                torque_true: fl(29)?,
            },
        ))
    }
}

/// Frames lost between two sequence numbers (`prev` then `next`; wraps at 2^16).
pub const fn lost_between(prev: u16, next: u16) -> u16 {
    next.wrapping_sub(prev).wrapping_sub(1)
}
