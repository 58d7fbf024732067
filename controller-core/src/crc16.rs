//! The frames' CRC: CRC-16/IBM-SDLC (also called CRC-16/X-25, the HDLC frame check
//! sequence: polynomial 0x1021 reflected, initial value 0xFFFF, final XOR 0xFFFF), four
//! bytes per step ("slice-by-4") on a microcontroller; hosts first take 16-byte blocks.
//!
//! Frames are short (≤ 60 bytes) and every tick checks every neighbour's frames, so the
//! CRC is the largest part of the wire cost on target. The `crc` crate's byte-wise table
//! costs about 6.8 instructions per byte on the Cortex-M4 and its slice-by-16 variant
//! (8 KiB of tables) only 13 % less on such short inputs; this slice-by-4 loop (2 KiB of
//! tables, built at compile time) takes one 32-bit load and four table look-ups per four
//! bytes. The reflected (LSB-first) variant needs no byte swap of the little-endian load,
//! one instruction less per word than CRC-16/IBM-3740 with the same polynomial.
//! `tests/wire.rs` checks it against the `crc` crate on random inputs of every length,
//! and the unit tests below both paths against the bitwise definition.

/// Polynomial x¹⁶ + x¹² + x⁵ + 1, reflected (LSB first: 0x1021 bit-reversed).
const POLY: u16 = 0x8408;
/// Initial register value.
const INIT: u16 = 0xFFFF;
/// Final XOR.
const XOR_OUT: u16 = 0xFFFF;

/// Tables of the slice-by-N steps: 4 (2 KiB of flash) on a microcontroller; 16 (8 KiB)
/// elsewhere, where a 16-byte step shortens the chain of dependent look-ups that bounds a
/// CRC's latency (host simulation: one CRC per frame sent).
const SLICE: usize = if cfg!(target_os = "none") { 4 } else { 16 };

/// `TABLES[k][b]`: the (reflected) register after feeding byte `b` followed by `k` zero
/// bytes into a zero register.
static TABLES: [[u16; 256]; SLICE] = build_tables();

// Evaluated at compile time only (`static` initialiser): an out-of-bounds index would be
// a build error, never a run-time panic.
#[allow(clippy::indexing_slicing)]
const fn build_tables() -> [[u16; 256]; SLICE] {
    let mut t = [[0u16; 256]; SLICE];
    let mut b = 0;
    while b < 256 {
        let mut crc = b as u16;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ POLY
            } else {
                crc >> 1
            };
            bit += 1;
        }
        t[0][b] = crc;
        b += 1;
    }
    let mut k = 1;
    while k < SLICE {
        let mut b = 0;
        while b < 256 {
            let prev = t[k - 1][b];
            t[k][b] = (prev >> 8) ^ t[0][(prev & 0xFF) as usize];
            b += 1;
        }
        k += 1;
    }
    t
}

/// Table look-up with a byte index: always in bounds (256 entries).
#[inline(always)]
fn look(table: &[u16; 256], index: u32) -> u32 {
    // `index as u8` keeps the low byte: the look-up cannot be out of bounds, and the
    // compiler emits no check.
    #[allow(clippy::indexing_slicing)]
    u32::from(table[usize::from(index as u8)])
}

/// Four bytes `x` (little-endian) looked up in the tables `4k … 4k+3`: the register
/// after them followed by `4k` zero bytes.
#[inline(always)]
fn word_at(k: usize, x: u32) -> u32 {
    match TABLES.as_chunks::<4>().0.get(k) {
        Some([t0, t1, t2, t3]) => {
            look(t3, x) ^ look(t2, x >> 8) ^ look(t1, x >> 16) ^ look(t0, x >> 24)
        }
        // Never: `k` is a constant below SLICE / 4 wherever this is inlined.
        None => 0,
    }
}

/// Four bytes into the register (slice-by-4): the register's two bytes meet the first two.
#[inline(always)]
fn word(crc: u32, w: &[u8; 4]) -> u32 {
    word_at(0, u32::from_le_bytes(*w) ^ crc)
}

/// Sixteen bytes into the register (slice-by-16): four independent word look-ups, of
/// which only the first depends on the register.
#[cfg(not(target_os = "none"))]
#[inline(always)]
fn block16(crc: u32, b: &[u8; 16]) -> u32 {
    let [w0, w1, w2, w3] = b.as_chunks::<4>().0 else {
        return crc;
    };
    let le = |w: &[u8; 4]| u32::from_le_bytes(*w);
    word_at(3, le(w0) ^ crc) ^ word_at(2, le(w1)) ^ word_at(1, le(w2)) ^ word_at(0, le(w3))
}

/// CRC-16/IBM-SDLC of `data`. (One out-of-line copy.)
#[inline(never)]
pub fn checksum(data: &[u8]) -> u16 {
    let crc = u32::from(INIT);
    #[cfg(not(target_os = "none"))]
    let (crc, data) = {
        let (blocks, rest) = data.as_chunks::<16>();
        (blocks.iter().fold(crc, block16), rest)
    };
    (short(crc, data) as u16) ^ XOR_OUT
}

/// The register after `data` with the four tables of slice-by-4: eight bytes per
/// iteration, then at most one word, one half-word and one byte, so that a short frame
/// (12–58 bytes, always of even length) pays little set-up on the Cortex-M4. (All of
/// [`checksum`] there; the rest after the 16-byte blocks elsewhere.)
#[inline(always)]
fn short(mut crc: u32, data: &[u8]) -> u32 {
    let (pairs, rest) = data.as_chunks::<8>();
    for p in pairs {
        let [ref a @ .., _, _, _, _] = *p;
        let [_, _, _, _, ref b @ ..] = *p;
        crc = word(word(crc, a), b);
    }
    let rest = match rest.split_first_chunk::<4>() {
        Some((w, rest)) => {
            crc = word(crc, w);
            rest
        }
        None => rest,
    };
    let [t0, t1, ..] = &TABLES;
    let rest = match rest.split_first_chunk::<2>() {
        Some((h, rest)) => {
            // Two bytes meet the register's two bytes.
            let x = u32::from(u16::from_le_bytes(*h)) ^ crc;
            crc = look(t1, x) ^ look(t0, x >> 8);
            rest
        }
        None => rest,
    };
    if let Some(&b) = rest.first() {
        crc = (crc >> 8) ^ look(t0, crc ^ u32::from(b));
    }
    crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_value() {
        // The catalogue's check value of CRC-16/IBM-SDLC for "123456789".
        assert_eq!(checksum(b"123456789"), 0x906E);
        assert_eq!(checksum(b""), 0x0000);
    }

    /// Bit by bit, from the definition: the reference for every path of `checksum`
    /// (eight-byte blocks, the word, the half-word and the byte after them).
    fn bitwise(data: &[u8]) -> u16 {
        let mut crc = INIT;
        for &b in data {
            crc ^= u16::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ POLY
                } else {
                    crc >> 1
                };
            }
        }
        crc ^ XOR_OUT
    }

    #[test]
    fn every_length_and_offset_matches_the_bitwise_definition() {
        let bytes: [u8; 80] = core::array::from_fn(|i| (i as u8).wrapping_mul(151) ^ 0x5A);
        for start in 0..4 {
            for end in start..bytes.len() {
                let data = &bytes[start..end];
                assert_eq!(checksum(data), bitwise(data), "bytes {start}..{end}");
                // The microcontroller's path alone (no 16-byte blocks).
                let short = (short(u32::from(INIT), data) as u16) ^ XOR_OUT;
                assert_eq!(short, bitwise(data), "slice-by-4, bytes {start}..{end}");
            }
        }
    }
}
