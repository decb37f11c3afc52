//! `can:IFACE`: the board's CAN commands behind the byte stream the link client speaks.
//! On CAN every command is one classic frame to `firmware::application::can::ID_CMD`
//! (its payload exactly the bytes `model_core::protocol::Command` encodes, no COBS, no
//! CRC-32: the bus has its own CRC) and every reply one frame from `ID_REPLY`; the firmware's
//! CAN task (`firmware::application::can`) decodes exactly that. [`CanCodec`] turns the
//! client's COBS frames into CAN payloads and the board's replies back into COBS frames.
//! The CAN task streams no telemetry: `record` needs the serial link.

use std::collections::VecDeque;

use firmware::application::can::{ID_CMD, ID_REPLY};
use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::FRAME;

/// The byte stream ⇄ CAN frames translation.
#[derive(Default)]
pub struct CanCodec {
    deframer: Deframer,
    /// Encoded replies waiting for the client.
    inbound: VecDeque<u8>,
}

impl CanCodec {
    /// Bytes the client wrote → the payloads of the CAN frames to send to [`ID_CMD`]
    /// (a frame failing its CRC, or longer than a CAN frame, is dropped as the board would).
    pub fn outgoing(&mut self, bytes: &[u8]) -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        for &b in bytes {
            if let Some(Ok(p)) = self.deframer.push(b) {
                if p.len() <= FRAME {
                    out.push(p.to_vec());
                }
            }
        }
        out
    }

    /// A frame received on the bus: a reply from [`ID_REPLY`] is queued for the client as
    /// an encoded frame; anything else is ignored. Whether it was taken.
    pub fn incoming(&mut self, id: u16, data: &[u8]) -> bool {
        if id != ID_REPLY || data.len() > FRAME {
            return false;
        }
        let mut e = [0u8; MAX_ENCODED];
        let n = encode(data, &mut e);
        self.inbound.extend(&e[..n]);
        true
    }

    /// Encoded replies into `buf`; the bytes copied.
    pub fn read(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len().min(self.inbound.len());
        for (d, s) in buf.iter_mut().zip(self.inbound.drain(..n)) {
            *d = s;
        }
        n
    }

    pub fn has_inbound(&self) -> bool {
        !self.inbound.is_empty()
    }
}

#[cfg(target_os = "linux")]
mod socket {
    use std::io::{self, ErrorKind, Read, Write};
    use std::time::Duration;

    use socketcan::{CanFrame, CanSocket, EmbeddedFrame, Id, Socket, StandardId};

    use super::{CanCodec, ID_CMD};

    /// A SocketCAN raw socket as the client's byte stream.
    pub struct CanStream {
        socket: CanSocket,
        codec: CanCodec,
        /// How long one read waits for a reply frame.
        poll: Duration,
    }

    impl CanStream {
        pub fn open(iface: &str, poll: Duration) -> io::Result<Self> {
            Ok(Self { socket: CanSocket::open(iface)?, codec: CanCodec::default(), poll })
        }
    }

    impl Read for CanStream {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if !self.codec.has_inbound() {
                let f = self.socket.read_frame_timeout(self.poll)?;
                if let Id::Standard(id) = f.id() {
                    self.codec.incoming(id.as_raw(), f.data());
                }
            }
            match self.codec.read(buf) {
                0 => Err(io::Error::new(ErrorKind::TimedOut, "no reply frame")),
                n => Ok(n),
            }
        }
    }

    impl Write for CanStream {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            let id = StandardId::new(ID_CMD).ok_or_else(|| io::Error::other("CAN identifier"))?;
            for p in self.codec.outgoing(buf) {
                let f = CanFrame::new(id, &p).ok_or_else(|| io::Error::other("CAN frame"))?;
                self.socket.write_frame(&f)?;
            }
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }
}

#[cfg(target_os = "linux")]
pub use socket::CanStream;

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::application::can::reply;
    use model_core::protocol::frame::Deframer;
    use model_core::protocol::{Command, Response};

    fn framed(payload: &[u8]) -> Vec<u8> {
        let mut e = [0u8; MAX_ENCODED];
        let n = encode(payload, &mut e);
        e[..n].to_vec()
    }

    #[test]
    fn a_client_frame_goes_out_as_the_command_bytes_the_firmware_decodes() {
        let mut c = CanCodec::default();
        let mut cmd = [0u8; FRAME];
        let guard = model_core::protocol::Guard { session: 2, seq: 9, deadline_ms: 1234 };
        let set = Command::SetTorque { guard, reference: 6.5, ack: true };
        let n = set.encode(&mut cmd);
        let mut bytes = framed(&cmd[..n]);
        bytes.extend(framed(&[0xEE; 12])); // too long for CAN: dropped
        let mut damaged = framed(&cmd[..n]);
        damaged[1] ^= 0x40;
        bytes.extend(damaged);
        let out = c.outgoing(&bytes);
        assert_eq!(out, vec![cmd[..n].to_vec()]);
        assert_eq!(Command::decode(&out[0]), Ok(set), "a guarded command fits one classic frame");
    }

    #[test]
    fn the_firmware_reply_comes_back_as_a_client_frame() {
        let mut c = CanCodec::default();
        let ack = Response::Ack { code: 3, tag: 0x2009, now_ms: 1200 };
        let f = reply(ack).expect("reply frame");
        assert!(!c.incoming(ID_CMD, f.data()), "a frame from another id is not a reply");
        assert!(c.incoming(f.id, f.data()));
        let mut buf = [0u8; 64];
        let n = c.read(&mut buf);
        let mut d = Deframer::default();
        let mut got = Vec::new();
        for b in &buf[..n] {
            if let Some(p) = d.push(*b) {
                got.push(p.expect("CRC ok").to_vec());
            }
        }
        assert_eq!(got.len(), 1);
        assert_eq!(Response::decode(&got[0]), Some(ack));
        assert!(!c.has_inbound());
    }
}
