#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]
use super::*;
use crate::control::page::RateSpec;
use crate::control::ControlConfig;

#[test]
fn commands_round_trip() {
    let all = [
        Command::SetTorque(6.25),
        Command::Enable(true),
        Command::Enable(false),
        Command::Reset,
        Command::GetStatus,
        Command::ConfigBegin { len: 2048 },
        Command::ConfigData { offset: 2040, len: 3, data: [1, 2, 3, 0, 0] },
        Command::ConfigCommit { crc: 0xDEAD_BEEF },
    ];
    for c in all {
        let mut f = [0u8; FRAME];
        let n = c.encode(&mut f);
        assert_eq!(Command::decode(&f[..n]), Ok(c), "{c:?}");
    }
    assert_eq!(Command::decode(&[0x55]), Err(Nack::Unknown));
    assert_eq!(Command::decode(&[]), Err(Nack::Malformed));
    assert_eq!(Command::decode(&[0x01, 0, 0]), Err(Nack::Malformed));
    assert_eq!(Command::decode(&[0x01, 0, 0, 0xC0, 0x7F]), Err(Nack::Malformed), "NaN reference");
    assert_eq!(Command::decode(&[0x02, 7]), Err(Nack::Malformed));
    assert_eq!(Command::decode(&[0x11, 0, 0]), Err(Nack::Malformed), "empty chunk");
}

#[test]
fn responses_round_trip() {
    for r in [Response::Ack(0x02), Response::Nack(0x12, Nack::InvalidPage)] {
        let mut f = [0u8; FRAME];
        let n = r.encode(&mut f);
        assert_eq!(Response::decode(&f[..n]), Some(r));
    }
    let mut f = [0u8; FRAME];
    let n = Response::Status { mode: 2, fault: 0, overruns: 3, torque_est: 7.5 }.encode(&mut f);
    assert_eq!(n, 8);
    let Some(Response::Status { mode, overruns, torque_est, .. }) = Response::decode(&f) else { panic!() };
    assert_eq!((mode, overruns), (2, 3));
    assert_eq!(torque_est, 7.5);
}

#[test]
fn a_page_over_the_wire() {
    let c = ControlConfig::defaults(5e-5).validate().unwrap();
    let img = ConfigImage::new("algebraic", &crate::models::algebraic::SEED000_AVERAGE, RateSpec::Backward, c).unwrap();
    let page = img.encode();
    let len = usize::from(u16::from_le_bytes([page[6], page[7]])) + 4;
    let mut a = PageAssembler::default();
    assert_eq!(a.data(0, &[1]), Err(Nack::Sequence));
    a.begin(len as u16).unwrap();
    for (k, chunk) in page[..len].chunks(CHUNK).enumerate() {
        let mut f = [0u8; FRAME];
        let mut d = [0u8; CHUNK];
        d[..chunk.len()].copy_from_slice(chunk);
        let n = Command::ConfigData { offset: (k * CHUNK) as u16, len: chunk.len() as u8, data: d }.encode(&mut f);
        match Command::decode(&f[..n]).unwrap() {
            Command::ConfigData { offset, len, data } => a.data(offset, &data[..usize::from(len)]).unwrap(),
            other => panic!("{other:?}"),
        }
    }
    assert_eq!(a.data(len as u16, &[0]), Err(Nack::Sequence), "beyond the announced length");
    let crc = !crate::control::config::crc32_update(!0, &page[..len]);
    let mut bad = a.clone();
    assert_eq!(bad.commit(crc ^ 1).unwrap_err(), Nack::TransferCrc);
    let (bytes, back) = a.commit(crc).unwrap();
    assert_eq!(back, img);
    assert_eq!(bytes[..], page[..]);
    assert_eq!(a.commit(crc).unwrap_err(), Nack::Sequence, "one commit per transfer");
}

#[test]
fn frames_round_trip_through_cobs_and_resync_after_garbage() {
    use super::frame::{encode, Deframer, FrameError, MAX_ENCODED};
    let payloads: [&[u8]; 4] = [&[0x04], &[0, 0, 0, 0], &[0x01, 0, 0, 0x80, 0x3f], &[0xff; 40]];
    let mut d = Deframer::default();
    for p in payloads {
        let mut out = [0u8; MAX_ENCODED];
        let n = encode(p, &mut out);
        assert!(n > p.len() + 4 && out[..n - 1].iter().all(|b| *b != 0) && out[n - 1] == 0);
        // Garbage first (ends in a delimiter): dropped, never returned as a payload.
        let mut got = None;
        for b in [0x13, 0x77, 0x00].iter().chain(&out[..n]) {
            if let Some(r) = d.push(*b) {
                got = Some(r.map(<[u8]>::to_vec));
            }
        }
        assert_eq!(got, Some(Ok(p.to_vec())));
        // One byte flipped: the frame fails its CRC (or its COBS) and is dropped.
        let mut bad = out;
        bad[1] ^= 0x5a;
        let last = bad[..n].iter().filter_map(|b| d.push(*b).map(|r| r.map(<[u8]>::to_vec))).last();
        assert!(matches!(last, Some(Err(FrameError::Crc | FrameError::Cobs | FrameError::Short))), "{last:?}");
    }
}

#[test]
fn telemetry_round_trips_and_counts_losses() {
    use super::telemetry::{lost_between, Telemetry};
    let t = Telemetry {
        t_us: 123_456,
        b: 0.4,
        current: 1.5,
        torque_est: 7.25,
        reference: 8.0,
        duty: -0.3,
        mode: 2,
        fault: 1,
        torque_true: f32::NAN,
    };
    let (seq, back) = Telemetry::decode(&t.encode(65_535)).expect("decodes");
    assert_eq!(seq, 65_535);
    assert_eq!((back.t_us, back.torque_est, back.fault), (t.t_us, t.torque_est, t.fault));
    assert!(back.torque_true.is_nan());
    assert_eq!(lost_between(65_535, 2), 2);
    assert_eq!(lost_between(4, 5), 0);
}

#[test]
fn the_device_refuses_a_commit_while_enabled_and_acks_telemetry() {
    use super::device::{Action, Device};
    let mut d = Device::default();
    assert_eq!(d.handle(&[0x02, 1]), (Action::Enable(true), Some(Response::Ack(0x02))));
    assert_eq!(d.handle(&[0x12, 0, 0, 0, 0]), (Action::None, Some(Response::Nack(0x12, Nack::Busy))));
    assert_eq!(d.handle(&[0x05, 2, 0]), (Action::None, Some(Response::Ack(0x05))));
    assert_eq!(
        [d.telemetry_due(), d.telemetry_due(), d.telemetry_due(), d.telemetry_due()],
        [false, true, false, true]
    );
    assert_eq!(d.handle(&[0x7f]), (Action::None, Some(Response::Nack(0x7f, Nack::Unknown))));
}

#[test]
fn the_page_crc_query_answers_the_running_page_from_boot() {
    use super::device::{Action, Device};
    let mut d = Device::with_active_crc(0xDEAD_BEEF);
    assert_eq!(d.handle(&[0x13]), (Action::None, Some(Response::PageCrc(0xDEAD_BEEF))));
    d.set_active_crc(0x1234_5678);
    assert_eq!(d.handle(&[0x13]), (Action::None, Some(Response::PageCrc(0x1234_5678))));
    assert_eq!(Device::default().handle(&[0x13]), (Action::None, Some(Response::PageCrc(0))));
}
