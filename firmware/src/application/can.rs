//! The CAN command task (protocol in `model_core::protocol`: one command a frame to
//! `CAN_ID_CMD`, the reply from `CAN_ID_REPLY`). A drive enabled with no command on either
//! link for `COMMAND_TIMEOUT_MS` is released ([`crate::link`]).

use model_core::protocol::device::Device;
use model_core::protocol::{Response, FRAME};

use super::links::{serve, watch_link};
use super::ports::{CanFrame, CanPort, Clock, ControlPort, Event, Events, FlashPages};
use super::time::{after, with_timeout};
use super::App;
use crate::link::COMMAND_TIMEOUT_MS;

/// Commands to this identifier, replies from [`ID_REPLY`].
pub const ID_CMD: u16 = 0x120;
pub const ID_REPLY: u16 = 0x121;

/// The reply frame of `r`.
pub fn reply(r: Response) -> Option<CanFrame> {
    let mut buf = [0u8; FRAME];
    let n = r.encode(&mut buf);
    CanFrame::new(ID_REPLY, buf.get(..n)?)
}

pub async fn run<C, F, P, E, B>(app: App<'_, C, F, P, E>, mut can: B) -> !
where
    C: Clock,
    F: FlashPages,
    P: ControlPort,
    E: Events,
    B: CanPort,
{
    let mut device = Device::default();
    loop {
        let got = with_timeout(app.clock, COMMAND_TIMEOUT_MS * 1000 / 4, can.recv()).await;
        watch_link(app, &mut device);
        let frame = match got {
            None => continue,
            Some(Ok(f)) => f,
            Some(Err(_)) => {
                app.events.event(Event::Bus);
                after(app.clock, 1_000).await;
                continue;
            }
        };
        if frame.id != ID_CMD {
            continue;
        }
        if let Some(out) = serve(app, &mut device, frame.data()).await.and_then(reply) {
            can.send(&out).await;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::protocol::Command;

    #[test]
    fn a_reply_fits_one_classic_frame_from_the_reply_id() {
        let ack = Response::Ack { code: 7, tag: 0x1005, now_ms: 65_000 };
        let f = reply(ack).expect("a frame");
        assert_eq!(f.id, ID_REPLY);
        assert!(f.len as usize <= 8 && f.len > 0);
        assert_eq!(Response::decode(f.data()), Some(ack));
        assert!(Command::decode(&[]).is_err());
    }
}
