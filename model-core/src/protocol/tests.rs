#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]
use super::*;
use crate::control::page::RateSpec;
use crate::control::ControlConfig;

fn g(seq: u16) -> Guard {
    Guard { session: 5, seq, deadline_ms: 300 }
}

#[test]
fn commands_round_trip() {
    let all = [
        Command::SetTorque { guard: g(1), reference: 6.25, ack: false },
        Command::SetTorque { guard: g(2), reference: -8_000.0, ack: true },
        Command::Enable { guard: g(3), on: true },
        Command::Enable { guard: g(4), on: false },
        Command::Reset { guard: g(4095) },
        Command::GetStatus,
        Command::Claim { nonce: 0xBEEF },
        Command::Release { guard: g(7) },
        Command::Heartbeat { guard: g(8) },
        Command::ConfigBegin { guard: g(9), len: 2048 },
        Command::ConfigData { offset: 2040, len: 3, data: [1, 2, 3, 0, 0] },
        Command::ConfigCommit { crc: 0xDEAD_BEEF },
        Command::ConfigQuery,
        Command::Limits,
    ];
    for c in all {
        let mut f = [0u8; FRAME];
        let n = c.encode(&mut f);
        assert!(n > 0 && n <= FRAME, "{c:?} fits a classic CAN frame");
        assert_eq!(Command::decode(&f[..n]), Ok(c), "{c:?}");
    }
    assert_eq!(Command::decode(&[0x55]), Err(Nack::Unknown));
    assert_eq!(Command::decode(&[]), Err(Nack::Malformed));
    assert_eq!(Command::decode(&[0x01, 0, 0]), Err(Nack::Malformed));
    assert_eq!(Command::decode(&[0x02, 0x01, 0x50, 0, 0, 7]), Err(Nack::Malformed));
    assert_eq!(Command::decode(&[0x02, 1]), Err(Nack::Malformed), "enable without its guard");
    assert_eq!(Command::decode(&[0x11, 0, 0]), Err(Nack::Malformed), "empty chunk");
}

#[test]
fn a_reference_no_frame_carries_is_not_encoded() {
    let mut f = [0u8; FRAME];
    for v in [1e38, f32::NAN, f32::INFINITY, REFERENCE_MAX * 1.01] {
        assert_eq!(Command::SetTorque { guard: g(1), reference: v, ack: true }.encode(&mut f), 0, "{v}");
        assert_eq!(quantise_reference(v), None);
    }
    assert_eq!(quantise_reference(5.0004), Some(5.0));
    assert_eq!(quantise_reference(-0.0016), Some(-0.002));
}

#[test]
fn responses_round_trip() {
    for r in [
        Response::Ack { code: 0x02, tag: 0x5001, now_ms: 65_535 },
        Response::Nack { code: 0x12, why: Nack::InvalidPage, tag: 0, now_ms: 7 },
        Response::Session { nonce: 1, tag: 0x3001, now_ms: 9 },
        Response::Limits { reference_max: 30.0, control_hz: 20_000 },
        Response::PageCrc(0xFEED_F00D),
    ] {
        let mut f = [0u8; FRAME];
        let n = r.encode(&mut f);
        assert_eq!(Response::decode(&f[..n]), Some(r));
    }
    for why in Nack::ALL {
        assert_eq!(Nack::from_code(why as u8), Some(why));
    }
    assert_eq!(Response::decode(&[0x83, 0x02, 200, 0, 0, 0, 0]), None, "an unknown reason is no other reason");
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

fn frame(c: Command) -> ([u8; FRAME], usize) {
    let mut f = [0u8; FRAME];
    let n = c.encode(&mut f);
    (f, n)
}

fn handle(d: &mut device::Device, s: &mut Sessions, c: Command, now: u64) -> device::Handled {
    let (f, n) = frame(c);
    d.handle(&f[..n], now, s)
}

/// A claimed session's first guard, with a deadline 300 ms after `now`.
fn claim(d: &mut device::Device, s: &mut Sessions, now: u64) -> Guard {
    match handle(d, s, Command::Claim { nonce: 42 }, now).reply {
        Some(Response::Session { tag, nonce: 42, .. }) => Guard::from_tag(tag, session::clock16(now + 300)),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_device_refuses_a_commit_while_enabled_and_acks_telemetry() {
    use super::device::{Action, Device};
    let (mut d, mut s) = (Device::default(), Sessions::default());
    let g1 = claim(&mut d, &mut s, 0);
    let h = handle(&mut d, &mut s, Command::Enable { guard: g1, on: true }, 1);
    assert!(matches!(h.action, Action::Enable { on: true, .. }) && h.heard && h.reply.is_none());
    let g2 = g1.next(300);
    assert!(handle(&mut d, &mut s, Command::ConfigBegin { guard: g2, len: 8 }, 2).reply.is_some());
    let h = handle(&mut d, &mut s, Command::ConfigCommit { crc: 0 }, 3);
    assert!(matches!(h.reply, Some(Response::Nack { why: Nack::Busy, .. })), "{h:?}");
    let h = handle(&mut d, &mut s, Command::Telemetry { decimation: 2 }, 4);
    assert!(matches!(h.reply, Some(Response::Ack { code: 0x05, .. })));
    assert_eq!(
        [d.telemetry_due(), d.telemetry_due(), d.telemetry_due(), d.telemetry_due()],
        [false, true, false, true]
    );
    let h = d.handle(&[0x7f], 5, &mut s);
    assert!(matches!(h.reply, Some(Response::Nack { code: 0x7f, why: Nack::Unknown, .. })));
}

#[test]
fn a_driving_command_without_the_session_late_or_twice_does_not_run() {
    use super::device::{Action, Device};
    let (mut d, mut s) = (Device::default(), Sessions::default());
    let none = Guard { session: 1, seq: 1, deadline_ms: 100 };
    let h = handle(&mut d, &mut s, Command::Enable { guard: none, on: true }, 0);
    assert!(matches!(h.reply, Some(Response::Nack { why: Nack::NoSession, .. })) && h.action == Action::None);
    let g = claim(&mut d, &mut s, 10);
    let set = |guard| Command::SetTorque { guard, reference: 40.0, ack: true };
    let h = handle(&mut d, &mut s, set(g), 400);
    assert!(matches!(h.reply, Some(Response::Nack { why: Nack::Expired, .. })) && h.action == Action::None, "{h:?}");
    let g2 = g.next(session::clock16(700));
    assert!(matches!(handle(&mut d, &mut s, set(g2), 500).action, Action::Reference { value: 40.0, .. }));
    let h = handle(&mut d, &mut s, set(g2), 501);
    assert!(matches!(h.reply, Some(Response::Nack { why: Nack::Stale, .. })), "a duplicate: {h:?}");
    let mut other = Device::default();
    assert!(matches!(
        handle(&mut other, &mut s, Command::Claim { nonce: 7 }, 502).reply,
        Some(Response::Nack { why: Nack::Held, .. })
    ));
}

#[test]
fn a_commit_belongs_to_the_session_that_began_the_transfer() {
    use super::device::Device;
    let (mut d, mut s) = (Device::default(), Sessions::default());
    let g = claim(&mut d, &mut s, 0);
    assert!(matches!(
        handle(&mut d, &mut s, Command::ConfigBegin { guard: g, len: 8 }, 1).reply,
        Some(Response::Ack { .. })
    ));
    let _ = s.expire(5_000);
    let h = handle(&mut d, &mut s, Command::ConfigCommit { crc: 0 }, 5_001);
    assert!(matches!(h.reply, Some(Response::Nack { why: Nack::NoSession, .. })), "{h:?}");
}

#[test]
fn the_page_crc_query_answers_the_running_page_from_boot() {
    use super::device::Device;
    let mut s = Sessions::default();
    let mut d = Device::with_active_crc(0xDEAD_BEEF);
    assert_eq!(d.handle(&[0x13], 0, &mut s).reply, Some(Response::PageCrc(0xDEAD_BEEF)));
    d.set_active_crc(0x1234_5678);
    assert_eq!(d.handle(&[0x13], 0, &mut s).reply, Some(Response::PageCrc(0x1234_5678)));
    assert_eq!(Device::default().handle(&[0x13], 0, &mut s).reply, Some(Response::PageCrc(0)));
}
