//! Steim-1 and Steim-2 decompression (SEED manual v2.4, appendix B), strictly: every frame of
//! the data area is read (Steim-2 differences are bit fields of a 32-bit word, Steim-1
//! differences bytes or half-words in memory order), the first difference gives way to the forward integration constant
//! `X0`, and the last sample must equal the reverse integration constant `Xn`.

/// Byte order of the header fields or of the data words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum WordOrder {
    Big,
    Little,
}

/// Bytes of one Steim frame: sixteen 32-bit words, the first of them the nibble word.
const FRAME_BYTES: usize = 64;

/// Which Steim variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Steim {
    One,
    Two,
}

impl Steim {
    fn name(self) -> &'static str {
        match self {
            Steim::One => "Steim-1",
            Steim::Two => "Steim-2",
        }
    }
}

fn word(data: &[u8], at: usize, order: WordOrder) -> u32 {
    let b = [data[at], data[at + 1], data[at + 2], data[at + 3]];
    match order {
        WordOrder::Big => u32::from_be_bytes(b),
        WordOrder::Little => u32::from_le_bytes(b),
    }
}

/// The signed value of the low `bits` bits of `w >> shift`.
fn field(w: u32, shift: u32, bits: u32) -> i32 {
    let v = (w >> shift) & ((1u32 << bits) - 1);
    ((v << (32 - bits)) as i32) >> (32 - bits)
}

/// Pushes the `count` fields of `bits` bits of `w`, the first at the most significant end of
/// the lowest `count * bits` bits.
fn push_fields(w: u32, count: u32, bits: u32, out: &mut Vec<i32>) {
    for k in (0..count).rev() {
        out.push(field(w, k * bits, bits));
    }
}

/// Decodes `n` samples from the Steim data area `data` (a whole number of frames is used;
/// trailing bytes short of a frame are ignored, as libmseed does). Errors say what is wrong,
/// for the caller to place in the file.
pub(crate) fn decode(
    data: &[u8],
    n: usize,
    order: WordOrder,
    kind: Steim,
) -> Result<Vec<i32>, String> {
    let frames = data.len() / FRAME_BYTES;
    if n == 0 {
        return Ok(Vec::new());
    }
    if frames == 0 {
        return Err(format!(
            "{} data area of {} bytes holds no 64-byte frame for {n} samples",
            kind.name(),
            data.len()
        ));
    }
    let x0 = word(data, 4, order) as i32;
    let xn = word(data, 8, order) as i32;
    // The differences, in order; at most 7 per word, 15 words per frame.
    let mut diffs: Vec<i32> = Vec::with_capacity(n + 7);
    'frames: for f in 0..frames {
        let base = f * FRAME_BYTES;
        let nibbles = word(data, base, order);
        let first = if f == 0 { 3 } else { 1 };
        for w in first..16 {
            if diffs.len() >= n {
                break 'frames;
            }
            let value = word(data, base + 4 * w, order);
            let nibble = (nibbles >> (30 - 2 * w as u32)) & 3;
            let dnib = value >> 30;
            match (kind, nibble, dnib) {
                (_, 0, _) => {}
                // Steim-1 packs bytes and half-words in memory order (SEED manual, appendix
                // B), so their order within a little-endian word is reversed.
                (Steim::One, 1, _) => {
                    let at = base + 4 * w;
                    diffs.extend(data[at..at + 4].iter().map(|&b| i32::from(b as i8)));
                }
                (Steim::One, 2, _) => {
                    let at = base + 4 * w;
                    for h in [at, at + 2] {
                        let x = [data[h], data[h + 1]];
                        diffs.push(i32::from(match order {
                            WordOrder::Big => i16::from_be_bytes(x),
                            WordOrder::Little => i16::from_le_bytes(x),
                        }));
                    }
                }
                (Steim::One, 3, _) => diffs.push(value as i32),
                (Steim::Two, 1, _) => push_fields(value, 4, 8, &mut diffs),
                (Steim::Two, 2, 1) => push_fields(value, 1, 30, &mut diffs),
                (Steim::Two, 2, 2) => push_fields(value, 2, 15, &mut diffs),
                (Steim::Two, 2, 3) => push_fields(value, 3, 10, &mut diffs),
                (Steim::Two, 3, 0) => push_fields(value, 5, 6, &mut diffs),
                (Steim::Two, 3, 1) => push_fields(value, 6, 5, &mut diffs),
                (Steim::Two, 3, 2) => push_fields(value, 7, 4, &mut diffs),
                (_, nibble, dnib) => {
                    return Err(format!(
                        "{} frame {f}, word {w}: nibble {nibble} with dnib {dnib} is not a \
                         valid Steim-2 packing",
                        kind.name()
                    ))
                }
            }
        }
    }
    if diffs.len() < n {
        return Err(format!(
            "{} data area ({frames} frames) holds {} differences, fewer than the {n} samples \
             the header announces",
            kind.name(),
            diffs.len()
        ));
    }
    let mut out = Vec::with_capacity(n);
    out.push(x0);
    let mut last = x0;
    for &d in &diffs[1..n] {
        last = last.wrapping_add(d);
        out.push(last);
    }
    if last != xn {
        return Err(format!(
            "{} last sample {last} differs from the reverse integration constant Xn = {xn}: \
             the compressed data are damaged",
            kind.name()
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One frame, big-endian, from its 16 words.
    fn frame(words: [u32; 16]) -> Vec<u8> {
        words.iter().flat_map(|w| w.to_be_bytes()).collect()
    }

    #[test]
    fn steim1_bytes_and_halves() {
        // Samples 5, 6, 4, 104, -96: differences (ignored first) 1, -2, 100, -200.
        // Word 3: four 8-bit differences [0, 1, -2, 100]; word 4: one 32-bit -200.
        let nib = (1u32 << (30 - 6)) | (3u32 << (30 - 8));
        let mut w = [0u32; 16];
        w[0] = nib;
        w[1] = 5;
        w[2] = (-96i32) as u32;
        w[3] = u32::from_be_bytes([0, 1, (-2i8) as u8, 100]);
        w[4] = (-200i32) as u32;
        let got = decode(&frame(w), 5, WordOrder::Big, Steim::One).unwrap();
        assert_eq!(got, vec![5, 6, 4, 104, -96]);
        // A wrong Xn is refused.
        w[2] = 7;
        let e = decode(&frame(w), 5, WordOrder::Big, Steim::One).unwrap_err();
        assert!(e.contains("reverse integration constant"), "{e}");
    }

    #[test]
    fn steim2_packings() {
        // Differences: one 30-bit, then seven 4-bit.
        let mut w = [0u32; 16];
        w[0] = (2u32 << (30 - 6)) | (3u32 << (30 - 8));
        w[1] = 10; // X0
        w[3] = (1u32 << 30) | 0x3FFF_FFFF; // one 30-bit field: -1 (ignored: first difference)
        let sevens: [i32; 7] = [1, -1, 7, -8, 0, 2, -3];
        let mut v = 2u32 << 30;
        for (k, d) in sevens.iter().enumerate() {
            v |= ((*d as u32) & 0xF) << (4 * (6 - k));
        }
        w[4] = v;
        let mut want = vec![10];
        for d in sevens {
            want.push(want.last().unwrap() + d);
        }
        w[2] = *want.last().unwrap() as u32;
        let got = decode(&frame(w), 8, WordOrder::Big, Steim::Two).unwrap();
        assert_eq!(got, want);
        // dnib 0 under nibble 2 is not a packing.
        w[4] = 0;
        w[0] = 2u32 << (30 - 8);
        assert!(decode(&frame(w), 2, WordOrder::Big, Steim::Two).is_err());
    }

    #[test]
    fn too_few_differences() {
        let mut w = [0u32; 16];
        w[0] = 1u32 << (30 - 6);
        let e = decode(&frame(w), 10, WordOrder::Big, Steim::One).unwrap_err();
        assert!(e.contains("fewer than the 10 samples"), "{e}");
        assert!(decode(&[0u8; 10], 1, WordOrder::Big, Steim::One).is_err());
    }
}
