//! CRC-32 (IEEE 802.3: reflected, polynomial 0xEDB88320, pre- and post-inverted) of the
//! settings' byte encoding, nibble-table form (16 words of table, 2 lookups a byte).

/// CRC-32 over the little-endian bytes of `words`.
pub fn crc_words(words: &[f32]) -> u32 {
    !words.iter().fold(!0u32, |c, w| crc32_update(c, &w.to_le_bytes()))
}

/// Nibble table of CRC-32 (reflected 0xEDB88320). Built at compile time: an index out
/// of bounds here would be a compile error, not a panic.
#[allow(clippy::indexing_slicing)]
const NIBBLE: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 4 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// Update a running (pre-inverted) CRC-32 with `bytes`.
#[inline]
pub fn crc32_update(mut crc: u32, bytes: &[u8]) -> u32 {
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..2 {
            crc = (crc >> 4) ^ NIBBLE.get((crc & 0xF) as usize).copied().unwrap_or(0);
        }
    }
    crc
}
