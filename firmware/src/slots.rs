//! Two configuration pages, A and B, so that a commit interrupted at any flash operation
//! (a reset, a power cut, the watchdog) leaves the previous page intact.
//!
//! A slot is one 2 KiB flash page: the configuration image
//! ([`model_core::control::ConfigImage`], at most [`IMAGE_BYTES`]) and, in its last
//! double-word, the commit record: a sequence number and its complement. A commit erases
//! the slot that is *not* running, programs the image, then programs the record with the
//! running sequence + 1 as the very last operation. A slot counts only when its record
//! is whole (or erased: a page flashed by a probe without the protocol, such as the
//! single page of earlier firmware at slot B's address, counts as sequence 0), its image
//! decodes and validates, and no double-word of it read back with an uncorrectable ECC
//! error; of two such slots the newer sequence (wrapping) boots, A on a tie.

use model_core::control::page::PAGE_BYTES;

/// Bytes of a slot (one flash page).
pub const SLOT_BYTES: usize = PAGE_BYTES;
/// Bytes the image may use: everything but the commit record.
pub const IMAGE_BYTES: usize = SLOT_BYTES - 8;

/// The two slots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Slot {
    A,
    B,
}

impl Slot {
    pub const fn other(self) -> Self {
        match self {
            Self::A => Self::B,
            Self::B => Self::A,
        }
    }
}

/// The commit record for sequence `seq`: `seq` then `!seq`, little-endian.
pub fn record(seq: u32) -> [u8; 8] {
    let mut r = [0u8; 8];
    r[..4].copy_from_slice(&seq.to_le_bytes());
    r[4..].copy_from_slice(&(!seq).to_le_bytes());
    r
}

/// What the commit record of a slot says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Record {
    /// Whole, with this sequence.
    Committed(u32),
    /// Erased: a page written without the A/B protocol (`hil-sim export` + a probe); it
    /// counts as sequence 0, the oldest, if its image is valid.
    Absent,
    /// Neither: a commit cut while writing its record.
    Broken,
}

/// The commit record at the end of `slot`.
pub fn record_of(slot: &[u8; SLOT_BYTES]) -> Record {
    match (sequence(slot), slot.get(IMAGE_BYTES..).is_some_and(is_blank)) {
        (Some(seq), _) => Record::Committed(seq),
        (None, true) => Record::Absent,
        (None, false) => Record::Broken,
    }
}

/// The sequence of a whole commit record at the end of `slot`, if any.
pub fn sequence(slot: &[u8; SLOT_BYTES]) -> Option<u32> {
    let w = |at: usize| slot.get(at..at + 4).and_then(|b| b.try_into().ok()).map(u32::from_le_bytes);
    let (seq, inv) = (w(IMAGE_BYTES)?, w(IMAGE_BYTES + 4)?);
    (seq == !inv).then_some(seq)
}

/// Whether every byte is erased (0xFF).
pub fn is_blank(bytes: &[u8]) -> bool {
    bytes.iter().all(|b| *b == 0xFF)
}

/// What reading one slot found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum SlotState {
    /// Erased: never written, or a commit that did not get past its erase.
    Blank,
    /// Committed and valid, with its sequence.
    Valid(u32),
    /// Something is there but it cannot be used (half-written, bad CRC, ECC error,
    /// refused settings): the reason for the log.
    Unusable(&'static str),
}

/// Which slot boots, from what was found in A and B.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Boot {
    /// This slot, with its sequence.
    Slot(Slot, u32),
    /// Both slots blank: a new board, the compiled-in configuration.
    Blank,
    /// Nothing usable but something was written: the compiled-in configuration, reported
    /// as a fault (never silently).
    Damaged,
}

/// `b` is newer than `a` (wrapping sequence numbers).
pub const fn newer(a: u32, b: u32) -> bool {
    (b.wrapping_sub(a) as i32) > 0
}

/// The slot to boot.
pub fn choose(a: SlotState, b: SlotState) -> Boot {
    match (a, b) {
        (SlotState::Valid(sa), SlotState::Valid(sb)) => {
            if newer(sa, sb) {
                Boot::Slot(Slot::B, sb)
            } else {
                Boot::Slot(Slot::A, sa)
            }
        }
        (SlotState::Valid(s), _) => Boot::Slot(Slot::A, s),
        (_, SlotState::Valid(s)) => Boot::Slot(Slot::B, s),
        (SlotState::Blank, SlotState::Blank) => Boot::Blank,
        _ => Boot::Damaged,
    }
}

/// Where the next commit goes and with which sequence: the slot not running (A on a board
/// running defaults).
pub const fn commit_target(running: Option<(Slot, u32)>) -> (Slot, u32) {
    match running {
        Some((slot, seq)) => (slot.other(), seq.wrapping_add(1)),
        None => (Slot::A, 1),
    }
}

/// The slot image for an encoded page: `None` when the image reaches into the record.
pub fn slot_image(page: &[u8; PAGE_BYTES], seq: u32) -> Option<[u8; SLOT_BYTES]> {
    if !is_blank(page.get(IMAGE_BYTES..)?) {
        return None;
    }
    let mut out = *page;
    out.get_mut(IMAGE_BYTES..)?.copy_from_slice(&record(seq));
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_round_trips_and_half_records_do_not_count() {
        let mut s = [0xFFu8; SLOT_BYTES];
        assert_eq!(sequence(&s), None, "erased record");
        s[IMAGE_BYTES..].copy_from_slice(&record(7));
        assert_eq!(sequence(&s), Some(7));
        s[IMAGE_BYTES + 4] = 0xFF; // the complement not fully programmed
        assert_eq!(sequence(&s), None);
        let mut z = [0xFFu8; SLOT_BYTES];
        z[IMAGE_BYTES..].copy_from_slice(&[0u8; 8]);
        assert_eq!(sequence(&z), None, "all zeros is not a record");
    }

    #[test]
    fn newest_valid_slot_boots() {
        use SlotState::*;
        assert_eq!(choose(Valid(3), Valid(4)), Boot::Slot(Slot::B, 4));
        assert_eq!(choose(Valid(5), Valid(4)), Boot::Slot(Slot::A, 5));
        assert_eq!(choose(Valid(u32::MAX), Valid(0)), Boot::Slot(Slot::B, 0), "wraps");
        assert_eq!(choose(Unusable("crc"), Valid(9)), Boot::Slot(Slot::B, 9));
        assert_eq!(choose(Valid(2), Blank), Boot::Slot(Slot::A, 2));
        assert_eq!(choose(Blank, Blank), Boot::Blank);
        assert_eq!(choose(Unusable("ecc"), Blank), Boot::Damaged);
        assert_eq!(choose(Blank, Unusable("half-written")), Boot::Damaged);
    }

    #[test]
    fn commits_alternate_and_never_touch_the_running_slot() {
        assert_eq!(commit_target(None), (Slot::A, 1));
        let mut running = None;
        for _ in 0..5 {
            let (slot, seq) = commit_target(running);
            if let Some((r, rs)) = running {
                assert_ne!(slot, r);
                assert!(newer(rs, seq));
            }
            running = Some((slot, seq));
        }
    }

    #[test]
    fn a_page_without_record_is_the_oldest() {
        let mut s = [0xFFu8; SLOT_BYTES];
        s[..4].fill(7);
        assert_eq!(record_of(&s), Record::Absent);
        s[IMAGE_BYTES..].copy_from_slice(&record(2));
        assert_eq!(record_of(&s), Record::Committed(2));
        s[IMAGE_BYTES + 6] = 0;
        assert_eq!(record_of(&s), Record::Broken);
        assert_eq!(choose(SlotState::Valid(0), SlotState::Valid(1)), Boot::Slot(Slot::B, 1));
    }

    #[test]
    fn an_image_reaching_the_record_is_refused() {
        let mut page = [0xFFu8; PAGE_BYTES];
        page[..10].fill(1);
        let img = slot_image(&page, 3).expect("fits");
        assert_eq!(sequence(&img), Some(3));
        page[IMAGE_BYTES] = 0;
        assert!(slot_image(&page, 3).is_none());
    }
}
