//! Who may drive the clutch, and whether a command is still the one its host meant: the
//! board's session (one controlling host at a time, ended by release or by silence) and
//! the guard every driving command carries (session, sequence number, deadline).
//!
//! The rules, each the reason of one refusal:
//! - a guarded command names the session the board holds, or it is [`Nack::NoSession`];
//! - its sequence number is ahead of the last one run in that session (within half the
//!   12-bit space), or it is [`Nack::Stale`]: a duplicate, a frame overtaken by a later
//!   one, a retry of a command that already ran;
//! - its deadline, in ms of the board's clock (16 bits, compared modulo 2^16), has not
//!   passed and lies at most [`MAX_LEAD_MS`] ahead, or it is [`Nack::Expired`].
//!
//! A host that gives up on a command once its deadline has passed on its own estimate of
//! the board's clock therefore knows it did not run. The estimate comes from the board's
//! clock in every ack and nack: it lags the board by the reply's latency, which only
//! moves the host's deadlines earlier. A session whose holder has sent nothing guarded
//! for [`IDLE_MS`] ends (the drive is released with it), so a host that died does not
//! lock the others out.

use super::Nack;

/// A session whose holder sent nothing guarded for this long ends, ms.
pub const IDLE_MS: u64 = 1_000;
/// A deadline further ahead than this is refused, ms: no host means a command to wait
/// that long, so such a deadline is a clock gone wrong.
pub const MAX_LEAD_MS: u16 = 2_000;
/// Sequence numbers are 12 bits; "ahead" is within half of them.
const SEQ_MASK: u16 = 0x0FFF;
const SEQ_AHEAD: u16 = 0x0800;

/// What a guarded command carries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Guard {
    /// Session, 4 bits (the board's count of claims).
    pub session: u8,
    /// Sequence number in the session, 12 bits.
    pub seq: u16,
    /// Deadline: the board's clock in ms, modulo 2^16.
    pub deadline_ms: u16,
}

impl Guard {
    /// The 16-bit tag: session in the top 4 bits, sequence number below.
    pub const fn tag(&self) -> u16 {
        ((self.session as u16 & 0xF) << 12) | (self.seq & SEQ_MASK)
    }

    /// A guard from its tag and deadline.
    pub const fn from_tag(tag: u16, deadline_ms: u16) -> Self {
        Self { session: (tag >> 12) as u8, seq: tag & SEQ_MASK, deadline_ms }
    }

    /// The guard of the command after this one, with its own deadline.
    pub const fn next(&self, deadline_ms: u16) -> Self {
        Self { session: self.session, seq: (self.seq + 1) & SEQ_MASK, deadline_ms }
    }
}

/// The session held now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Held {
    session: u8,
    /// The claim's nonce (a repeated claim of the same host gets the same session back).
    nonce: u16,
    /// Sequence number of the last command run (the claim's reply names the one after).
    last_seq: u16,
    /// When its holder was last heard, ms.
    heard_ms: u64,
}

/// Sessions of the board (shared by its links: one controlling host across all of them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sessions {
    held: Option<Held>,
    /// Claims granted so far (the next session number is its low 4 bits).
    claims: u8,
}

/// What ending a session means for the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ended {
    /// Nothing ended.
    No,
    /// The session ended: release the drive.
    Yes,
}

/// The board's clock as a deadline compares it.
pub const fn clock16(now_ms: u64) -> u16 {
    now_ms as u16
}

impl Sessions {
    /// No session held, no claim granted yet.
    pub const fn new() -> Self {
        Self { held: None, claims: 0 }
    }

    /// A claim with the host's `nonce` at `now_ms`: the guard of its first command (the
    /// reply's tag) or [`Nack::Held`]. A claim repeated with the same nonce (its reply was
    /// lost) gets the same session back, the sequence where it stands.
    pub fn claim(&mut self, nonce: u16, now_ms: u64) -> Result<u16, Nack> {
        self.expire(now_ms);
        match self.held {
            Some(h) if h.nonce == nonce => {
                let g = Guard { session: h.session, seq: (h.last_seq + 1) & SEQ_MASK, deadline_ms: 0 };
                Ok(g.tag())
            }
            Some(_) => Err(Nack::Held),
            None => {
                self.claims = self.claims.wrapping_add(1);
                let session = self.claims & 0xF;
                // The first command is sequence 1; 0 was "run" by the claim.
                self.held = Some(Held { session, nonce, last_seq: 0, heard_ms: now_ms });
                Ok(Guard { session, seq: 1, deadline_ms: 0 }.tag())
            }
        }
    }

    /// Check `g` at `now_ms`; on success the command runs, its sequence number is the last
    /// one run and the holder was heard.
    pub fn admit(&mut self, g: Guard, now_ms: u64) -> Result<(), Nack> {
        if self.expire(now_ms) == Ended::Yes {
            return Err(Nack::NoSession);
        }
        let Some(h) = self.held.as_mut() else { return Err(Nack::NoSession) };
        if h.session != g.session & 0xF {
            return Err(Nack::NoSession);
        }
        let ahead = g.seq.wrapping_sub(h.last_seq) & SEQ_MASK;
        if ahead == 0 || ahead >= SEQ_AHEAD {
            return Err(Nack::Stale);
        }
        let lead = g.deadline_ms.wrapping_sub(clock16(now_ms));
        if lead > MAX_LEAD_MS {
            return Err(Nack::Expired);
        }
        h.last_seq = g.seq & SEQ_MASK;
        h.heard_ms = now_ms;
        Ok(())
    }

    /// End the session of `g` (a release it sent, already admitted).
    pub fn release(&mut self) -> Ended {
        match self.held.take() {
            Some(_) => Ended::Yes,
            None => Ended::No,
        }
    }

    /// End a session whose holder has been silent for [`IDLE_MS`]; called on every
    /// wake-up of a link task.
    pub fn expire(&mut self, now_ms: u64) -> Ended {
        match self.held {
            Some(h) if now_ms.saturating_sub(h.heard_ms) > IDLE_MS => {
                self.held = None;
                Ended::Yes
            }
            _ => Ended::No,
        }
    }

    /// A session is held.
    pub fn is_held(&self) -> bool {
        self.held.is_some()
    }

    /// Session `session` is the one held.
    pub fn holds(&self, session: u8) -> bool {
        self.held.is_some_and(|h| h.session == session & 0xF)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn claimed(now: u64) -> (Sessions, Guard) {
        let mut s = Sessions::default();
        let tag = s.claim(0x1234, now).unwrap();
        (s, Guard::from_tag(tag, clock16(now + 300)))
    }

    #[test]
    fn a_command_runs_once_in_order_and_before_its_deadline() {
        let (mut s, g) = claimed(10);
        assert_eq!(s.admit(g, 20), Ok(()));
        assert_eq!(s.admit(g, 21), Err(Nack::Stale), "the same command twice");
        let g2 = g.next(clock16(400));
        let g3 = g2.next(clock16(400));
        assert_eq!(s.admit(g3, 30), Ok(()), "a lost command is no reason to refuse the next");
        assert_eq!(s.admit(g2, 31), Err(Nack::Stale), "overtaken");
        let late = g3.next(clock16(100));
        assert_eq!(s.admit(late, 101), Err(Nack::Expired));
        let far = late.next(clock16(100 + 5_000));
        assert_eq!(s.admit(far, 100), Err(Nack::Expired), "a deadline no host would mean");
    }

    #[test]
    fn deadlines_compare_across_the_clock_wrap() {
        let now = 65_530;
        let (mut s, _) = claimed(now);
        let g = Guard { session: 1, seq: 1, deadline_ms: clock16(now + 100) };
        assert!(g.deadline_ms < 100, "wrapped");
        assert_eq!(s.admit(g, now + 5), Ok(()));
        assert_eq!(s.admit(g.next(clock16(now + 10)), now + 11), Err(Nack::Expired));
    }

    #[test]
    fn one_holder_at_a_time_until_release_or_silence() {
        let (mut s, g) = claimed(0);
        assert_eq!(s.claim(0x9999, 10), Err(Nack::Held), "another host");
        assert_eq!(s.claim(0x1234, 10), Ok(g.tag()), "the same host's repeated claim");
        let other = Guard { session: g.session.wrapping_add(1), ..g };
        assert_eq!(s.admit(other, 20), Err(Nack::NoSession));
        assert_eq!(s.admit(g, 20), Ok(()));
        assert_eq!(s.expire(20 + IDLE_MS), Ended::No);
        assert_eq!(s.expire(21 + IDLE_MS), Ended::Yes, "silent for longer than the idle time");
        assert_eq!(s.admit(g.next(clock16(1100)), 1030), Err(Nack::NoSession), "an ended session");
        let tag = s.claim(0x9999, 1040).unwrap();
        assert_ne!(Guard::from_tag(tag, 0).session, g.session, "a new session number");
        assert_eq!(s.release(), Ended::Yes);
        assert!(!s.is_held());
    }

    #[test]
    fn sequence_numbers_wrap_in_twelve_bits() {
        let mut g = Guard { session: 3, seq: 0x0FFF, deadline_ms: 0 };
        g = g.next(0);
        assert_eq!((g.session, g.seq), (3, 0));
        assert_eq!(Guard::from_tag(g.tag(), 7), Guard { deadline_ms: 7, ..g });
    }
}
