//! The mutation engine: coverage-blind, seeded, stacked byte-level mutations of corpus files.
//!
//! Each iteration draws its own random stream from `(seed, iteration)` ([`Dice::new`]), so any
//! iteration can be regenerated alone. An input is a corpus file with 1, 2, 4 or 8 mutations
//! applied in turn: bit flips, random bytes, inserted, deleted and duplicated ranges, chunks
//! spliced from another corpus file, truncation, numbers replaced by values that break number
//! handling (`nan`, `inf`, `-0`, `1e308`, subnormals, overflowing exponents, huge digit
//! strings), dictionary tokens of the formats, long lines, bytes that are not UTF-8, NUL, mixed
//! line ends, byte-order marks, and integers written over binary fields (lengths and offsets of
//! HDF5 metadata).

use tiltnoise_core::rng::Rng;

/// Largest input the engine produces (bytes): mutations that grow a file past it are cut.
const MAX_INPUT: usize = 1 << 20;

/// The random choices of one iteration.
pub struct Dice(Rng);

impl Dice {
    /// Stream `iteration` of run `seed`.
    pub fn new(seed: u64, iteration: u64) -> Dice {
        Dice(Rng::stream(seed, iteration))
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.0.uniform() * n as f64) as usize).min(n - 1)
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.0.uniform() < p
    }

    /// One of `items` (not empty).
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// A copy of one of `items` (not empty).
    pub fn choose<T: Copy>(&mut self, items: &[T]) -> T {
        *self.pick(items)
    }

    /// A length in `1..=max`, small ones far more likely (log-uniform).
    pub fn len_up_to(&mut self, max: usize) -> usize {
        let bits = (usize::BITS - max.max(1).leading_zeros()) as usize;
        let cap = 1usize << self.below(bits + 1);
        (1 + self.below(cap)).min(max.max(1))
    }

    /// A random byte.
    pub fn byte(&mut self) -> u8 {
        self.below(256) as u8
    }
}

/// Values that break number parsing and arithmetic.
const NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "-nan",
    "inf",
    "-inf",
    "+Infinity",
    "-0",
    "-0.0",
    "0",
    "0.0",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "1e-320",
    "4.9e-324",
    "2.2250738585072014e-308",
    "1e-400",
    "1.5e-2147483649",
    "1.5e2147483647",
    "1e-2147483648",
    "0.1e99999999999",
    "9223372036854775807",
    "18446744073709551616",
    "4294967296",
    "2147483648",
    "65536",
    "-1",
    "1",
    "2",
    "1e",
    "e5",
    ".",
    "-",
    "+",
    "0x10",
    "1_000",
    "1,5",
    "١",
    "1e+",
    "--1",
    ".e1",
];

/// Tokens of the input formats (CSV metadata, headers, units, axis maps, TOML) and characters
/// that matter to tokenizers.
const TOKENS: &[&[u8]] = &[
    b",",
    b"\"",
    b"\"\"",
    b"#",
    b"# units: ",
    b"# axes: ",
    b"# start_time: ",
    b"# description: ",
    b"rad",
    b"rad/s",
    b"rad/sqrt(Hz)",
    b"rad^2/Hz",
    b"m",
    b"time_s",
    b"freq_hz",
    b"theta_t",
    b"eta_t",
    b"phi_t",
    b"E",
    b"N",
    b"Z",
    b"LJE",
    b"X",
    b"phi_a",
    b"mode",
    b"frequency_hz",
    b"sigma_hz",
    b"=",
    b"=-",
    b"=+",
    b":",
    b"2018-01-23T09:31:42Z",
    b"2020-02-29 23:59:60.5+14:00",
    b"[",
    b"]",
    b"[[",
    b"{",
    b"}",
    b"'",
    b"\"\"\"",
    b"[uncertainty]",
    b"rel_sigma = ",
    b"distribution = \"uniform\"",
    b"length.h_m",
    b".",
    b"\t",
    b" ",
    b"\n",
    b"\r\n",
    b"\r",
    b"\0",
    "\u{feff}".as_bytes(),
    "é".as_bytes(),
    "€".as_bytes(),
    "𝄞".as_bytes(),
    "√".as_bytes(),
    "²".as_bytes(),
    "\u{2028}".as_bytes(),
    "\u{85}".as_bytes(),
    b"\xff",
    b"\xfe\xff",
    b"\xc3",
    b"\xc0\x80",
    b"\xed\xa0\x80",
    b"\xf4\x90\x80\x80",
    b"\xe2\x82",
];

/// Integers written over binary fields, little-endian in 1, 2, 4 or 8 bytes.
const INTEGERS: &[u64] = &[
    0,
    1,
    2,
    7,
    8,
    16,
    0x7f,
    0x80,
    0xff,
    0x100,
    0x7fff,
    0x8000,
    0xffff,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0000,
    0x7fff_ffff_ffff_ffff,
    0x8000_0000_0000_0000,
    u64::MAX,
];

/// A mutated copy of one of `corpus` (not empty), spliced with others.
pub fn mutate(dice: &mut Dice, corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut data = dice.pick(corpus).clone();
    let rounds = 1 << dice.below(4);
    for _ in 0..rounds {
        mutate_once(dice, &mut data, corpus);
        data.truncate(MAX_INPUT);
    }
    data
}

/// A position in `0..=len`.
fn position(dice: &mut Dice, data: &[u8]) -> usize {
    dice.below(data.len() + 1)
}

/// A range `start..end` inside `data` (empty only when `data` is).
fn range(dice: &mut Dice, data: &[u8]) -> std::ops::Range<usize> {
    if data.is_empty() {
        return 0..0;
    }
    let start = dice.below(data.len());
    start..start + dice.len_up_to(data.len() - start)
}

/// The number (digits, sign, point, exponent) at or after a random position, if any.
fn number_at(dice: &mut Dice, data: &[u8]) -> Option<std::ops::Range<usize>> {
    let from = position(dice, data);
    let is_num = |b: &u8| b.is_ascii_digit() || b"+-.eE".contains(b);
    let start = from + data[from..].iter().position(u8::is_ascii_digit)?;
    let start = data[..start]
        .iter()
        .rposition(|b| !is_num(b))
        .map_or(0, |p| p + 1);
    let end = start + data[start..].iter().take_while(|b| is_num(b)).count();
    Some(start..end)
}

/// Mixed line ends: one `\n` made `\r\n`, `\r`, `\n\r` or removed, or every one changed.
fn line_ends(dice: &mut Dice, data: &mut Vec<u8>) {
    let ends: [&[u8]; 4] = [b"\r\n", b"\r", b"\n\r", b""];
    let with = *dice.pick(&ends);
    let newlines: Vec<usize> = (0..data.len()).filter(|&i| data[i] == b'\n').collect();
    if newlines.is_empty() {
        return;
    }
    let chosen: Vec<usize> = if dice.chance(0.2) {
        newlines
    } else {
        vec![*dice.pick(&newlines)]
    };
    for &i in chosen.iter().rev() {
        data.splice(i..=i, with.iter().copied());
    }
}

fn mutate_once(dice: &mut Dice, data: &mut Vec<u8>, corpus: &[Vec<u8>]) {
    match dice.below(16) {
        // Flip a bit.
        0 if !data.is_empty() => {
            let i = dice.below(data.len());
            data[i] ^= 1 << dice.below(8);
        }
        // Overwrite bytes with random ones.
        1 => {
            for i in range(dice, data) {
                data[i] = dice.byte();
            }
        }
        // Insert random bytes.
        2 => {
            let at = position(dice, data);
            let n = dice.len_up_to(16);
            let bytes: Vec<u8> = (0..n).map(|_| dice.byte()).collect();
            data.splice(at..at, bytes);
        }
        // Delete a range.
        3 => {
            let r = range(dice, data);
            data.drain(r);
        }
        // Duplicate a range elsewhere, possibly many times.
        4 => {
            let r = range(dice, data);
            let chunk = data[r].to_vec();
            let most = if dice.chance(0.1) { 4096 } else { 4 };
            let times = dice.len_up_to(most).min(MAX_INPUT / chunk.len().max(1));
            let at = position(dice, data);
            data.splice(at..at, chunk.repeat(times));
        }
        // Splice a chunk of another corpus file: inserted, written over, or as the tail.
        5 => {
            let other = dice.pick(corpus);
            let chunk = other[range(dice, other)].to_vec();
            let at = position(dice, data);
            match dice.below(3) {
                0 => {
                    data.splice(at..at, chunk);
                }
                1 => {
                    let end = (at + chunk.len()).min(data.len());
                    data.splice(at..end, chunk);
                }
                _ => {
                    data.truncate(at);
                    data.extend_from_slice(&other[dice.below(other.len() + 1)..]);
                }
            }
        }
        // Truncate.
        6 => {
            let at = position(dice, data);
            data.truncate(at);
        }
        // Replace a number with an interesting value (or insert one).
        7 | 8 => {
            let value = dice.pick(NUMBERS).as_bytes().to_vec();
            match number_at(dice, data) {
                Some(r) => {
                    data.splice(r, value);
                }
                None => {
                    let at = position(dice, data);
                    data.splice(at..at, value);
                }
            }
        }
        // Replace a number with a huge digit string.
        9 => {
            let digits = dice.len_up_to(5000);
            let mut value: Vec<u8> = match dice.below(3) {
                0 => b"1".to_vec(),
                1 => b"0.".to_vec(),
                _ => b"9.".to_vec(),
            };
            value.extend(std::iter::repeat_n(b'0' + dice.below(10) as u8, digits));
            if dice.chance(0.5) {
                let tails: [&[u8]; 4] = [b"1", b"e-300", b"e300", b"e-5"];
                value.extend_from_slice(dice.choose(&tails));
            }
            let r = number_at(dice, data).unwrap_or(0..0);
            data.splice(r, value);
        }
        // Insert a token of the formats.
        10 | 11 => {
            let token = *dice.pick(TOKENS);
            let at = if dice.chance(0.5) {
                line_start(dice, data)
            } else {
                position(dice, data)
            };
            data.splice(at..at, token.iter().copied());
        }
        // A long line: one byte or token repeated, across the readers' 64 KiB buffers.
        12 => {
            let token: &[u8] = if dice.chance(0.5) {
                dice.choose(TOKENS)
            } else {
                b"x"
            };
            let n = if dice.chance(0.5) {
                (1 << 16) - 2 + dice.below(5)
            } else {
                dice.len_up_to(1 << 17)
            };
            let bytes: Vec<u8> = token.iter().copied().cycle().take(n).collect();
            let at = position(dice, data);
            data.splice(at..at, bytes);
        }
        // Mixed line ends.
        13 => line_ends(dice, data),
        // A byte-order mark, at the start or anywhere.
        14 => {
            let at = if dice.chance(0.5) {
                0
            } else {
                position(dice, data)
            };
            data.splice(at..at, "\u{feff}".bytes());
        }
        // Write an integer over a binary field.
        _ => {
            let width = 1 << dice.below(4);
            if data.len() >= width {
                let at = dice.below(data.len() - width + 1);
                let mut v = *dice.pick(INTEGERS);
                if dice.chance(0.3) {
                    v = v.wrapping_sub(1 + dice.below(2) as u64);
                }
                data[at..at + width].copy_from_slice(&v.to_le_bytes()[..width]);
            }
        }
    }
}

/// The start of a random line of `data` (0 if it has none).
fn line_start(dice: &mut Dice, data: &[u8]) -> usize {
    let at = position(dice, data);
    data[..at]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1)
}
