//! The serial link task (LPUART1 on the board, a TCP socket on the virtual board): the
//! commands, each frame COBS-encoded with a CRC-32 (`model_core::protocol::frame`), and the
//! telemetry stream: the control interrupt's samples at the decimation the host asked
//! for, numbered by sample index (a gap is a lost frame), in SI units.

use embedded_io_async::{Read, Write};
use model_core::protocol::device::Device;
use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::{mode_code, Response, FRAME};

use super::links::{serve, watch_link};
use super::ports::{Clock, ControlPort, Events, FlashPages};
use super::time::with_timeout;
use super::App;

/// The link's baud rate, 8N1 (LPUART1 on the board; `hil-sim board --port /dev/ttyACM0`
/// opens the port at the same).
pub const BAUD: u32 = 921_600;

/// The longest the task sleeps on a silent link, µs (it drains the stream ring then).
pub const POLL_US: u64 = 500;

/// `r` as one encoded frame; its length in `out`.
fn frame_of(r: Response, out: &mut [u8; MAX_ENCODED]) -> usize {
    let mut f = [0u8; FRAME];
    let m = r.encode(&mut f);
    encode(f.get(..m).unwrap_or(&[]), out)
}

pub async fn run<C, F, P, E, R, W>(app: App<'_, C, F, P, E>, mut rx: R, mut tx: W) -> !
where
    C: Clock,
    F: FlashPages,
    P: ControlPort,
    E: Events,
    R: Read,
    W: Write,
{
    let mut device = Device::default();
    let mut deframer = Deframer::default();
    let mut buf = [0u8; 64];
    loop {
        let got = with_timeout(app.clock, POLL_US, rx.read(&mut buf)).await;
        watch_link(app, &mut device);
        let n = match got {
            Some(Ok(n)) => n,
            Some(Err(_)) | None => 0,
        };
        for &byte in buf.get(..n).unwrap_or(&[]) {
            let Some(Ok(payload)) = deframer.push(byte) else { continue };
            if let Some(r) = serve(app, &mut device, payload).await {
                let mut out = [0u8; MAX_ENCODED];
                let k = frame_of(r, &mut out);
                let _ = tx.write_all(out.get(..k).unwrap_or(&[])).await;
            }
        }
        let d = u32::from(device.decimation());
        app.ctl.set_stream_decimation(d);
        while let Some(s) = app.ctl.pop_stream() {
            let t = Telemetry {
                t_us: s.t_us,
                b: s.out.b,
                current: s.out.current,
                torque_est: s.out.torque_est,
                reference: s.reference,
                duty: s.out.duty,
                mode: mode_code(s.out.mode),
                fault: s.out.fault.code(),
                torque_true: s.torque_true,
            };
            let seq = (s.n / d.max(1)) as u16;
            let mut out = [0u8; MAX_ENCODED];
            let k = encode(&t.encode(seq), &mut out);
            let _ = tx.write_all(out.get(..k).unwrap_or(&[])).await;
        }
    }
}
