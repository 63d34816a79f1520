//! A self-contained PNG encoder: signature, IHDR, IDAT (a zlib stream), IEND.
//!
//! The pixel rows are filtered (per row, the PNG filter — None, Sub, Up, Average, Paeth — with
//! the smallest sum of absolute residuals) and compressed with DEFLATE (RFC 1951) in one block of
//! fixed Huffman codes, with a greedy LZ77 matcher over a 32 KiB window (hash chains of bounded
//! depth). Rendered pictures are mostly flat areas, which the filters turn into runs of zeros and
//! the matcher into a few long back-references. The zlib wrapper (RFC 1950) carries an Adler-32
//! and every chunk a CRC-32, both computed here.

/// CRC-32 (ISO-HDLC: reflected polynomial 0xEDB88320, initial and final XOR 0xFFFFFFFF), as PNG
/// chunks use it. O(len).
///
/// ```
/// assert_eq!(topomech::render::png::crc32(b"123456789"), 0xCBF4_3926);
/// ```
pub fn crc32(bytes: &[u8]) -> u32 {
    !crc32_update(0xFFFF_FFFF, bytes)
}

const CRC_TABLE: [u32; 256] = crc_table();

const fn crc_table() -> [u32; 256] {
    let mut table = [0u32; 256];
    let mut n = 0;
    while n < 256 {
        let mut c = n as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
            k += 1;
        }
        table[n] = c;
        n += 1;
    }
    table
}

fn crc32_update(mut crc: u32, bytes: &[u8]) -> u32 {
    for &b in bytes {
        crc = CRC_TABLE[((crc ^ b as u32) & 0xFF) as usize] ^ (crc >> 8);
    }
    crc
}

/// Adler-32 (RFC 1950): two sums modulo 65521, `b << 16 | a`. O(len).
///
/// ```
/// assert_eq!(topomech::render::png::adler32(b"Wikipedia"), 0x11E6_0398);
/// ```
pub fn adler32(bytes: &[u8]) -> u32 {
    const MOD: u32 = 65_521;
    // 5552 is the largest block after which b cannot overflow a u32 (RFC 1950's NMAX).
    let (mut a, mut b) = (1u32, 0u32);
    for block in bytes.chunks(5552) {
        for &x in block {
            a += x as u32;
            b += a;
        }
        a %= MOD;
        b %= MOD;
    }
    (b << 16) | a
}

/// The zlib stream (RFC 1950) of `data`: header 0x78 0x01, one fixed-Huffman DEFLATE block,
/// Adler-32 of `data`. Any inflater returns `data` exactly. O(len · chain depth).
///
/// # Examples
///
/// ```
/// use topomech::render::png::{adler32, zlib_compress};
///
/// let data = vec![7u8; 10_000];
/// let z = zlib_compress(&data);
/// assert_eq!(&z[..2], &[0x78, 0x01]);
/// assert_eq!(&z[z.len() - 4..], &adler32(&data).to_be_bytes()[..]);
/// assert!(z.len() < 100); // one long run: a few back-references
/// ```
pub fn zlib_compress(data: &[u8]) -> Vec<u8> {
    let mut w = BitWriter { out: vec![0x78, 0x01], acc: 0, n: 0 };
    w.bits(1, 1); // BFINAL
    w.bits(1, 2); // BTYPE = 01, fixed Huffman codes
    lz77(data, &mut w);
    w.literal_length(256);
    let mut out = w.finish();
    out.extend_from_slice(&adler32(data).to_be_bytes());
    out
}

/// Encodes 8-bit RGB pixels, `rgb.len() == 3 · width · height`, rows top to bottom, as a PNG file.
/// The caller checks the sizes (see `Image::encode_png`). O(pixels).
pub(crate) fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    let mut out = vec![0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // depth 8, RGB, deflate, adaptive filters, no interlace
    chunk(&mut out, b"IHDR", &ihdr);
    // Several IDAT chunks of at most 1 MiB each: a chunk length must stay below 2³¹.
    for part in zlib_compress(&filter_rows(width as usize, rgb)).chunks(IDAT_MAX) {
        chunk(&mut out, b"IDAT", part);
    }
    chunk(&mut out, b"IEND", &[]);
    out
}

const IDAT_MAX: usize = 1 << 20;

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    out.extend_from_slice(&(!crc32_update(crc32_update(0xFFFF_FFFF, kind), data)).to_be_bytes());
}

/// Each row prefixed by its filter type byte and replaced by its residuals.
fn filter_rows(width: usize, rgb: &[u8]) -> Vec<u8> {
    const BPP: usize = 3;
    let stride = BPP * width;
    let zero = vec![0u8; stride];
    let mut out = Vec::with_capacity(rgb.len() + rgb.len() / stride.max(1));
    let mut candidate = vec![0u8; stride];
    let mut best = vec![0u8; stride];
    for (r, row) in rgb.chunks_exact(stride).enumerate() {
        let up = if r == 0 { &zero[..] } else { &rgb[(r - 1) * stride..r * stride] };
        let mut best_kind = 0u8;
        let mut best_cost = u64::MAX;
        for kind in 0..5u8 {
            for i in 0..stride {
                let a = if i >= BPP { row[i - BPP] } else { 0 };
                let c = if i >= BPP { up[i - BPP] } else { 0 };
                let b = up[i];
                let predicted = match kind {
                    0 => 0,
                    1 => a,
                    2 => b,
                    3 => ((a as u16 + b as u16) / 2) as u8,
                    _ => paeth(a, b, c),
                };
                candidate[i] = row[i].wrapping_sub(predicted);
            }
            let cost = candidate.iter().map(|&x| (x as i8).unsigned_abs() as u64).sum();
            if cost < best_cost {
                best_cost = cost;
                best_kind = kind;
                std::mem::swap(&mut best, &mut candidate);
            }
        }
        out.push(best_kind);
        out.extend_from_slice(&best);
    }
    out
}

fn paeth(a: u8, b: u8, c: u8) -> u8 {
    let p = a as i16 + b as i16 - c as i16;
    let (pa, pb, pc) = ((p - a as i16).abs(), (p - b as i16).abs(), (p - c as i16).abs());
    if pa <= pb && pa <= pc {
        a
    } else if pb <= pc {
        b
    } else {
        c
    }
}

/// Bits are packed from the least significant bit of each byte (RFC 1951 §3.1.1).
struct BitWriter {
    out: Vec<u8>,
    acc: u64,
    n: u32,
}

impl BitWriter {
    /// Writes the low `count` bits of `value`, least significant first.
    fn bits(&mut self, value: u32, count: u32) {
        debug_assert!(count <= 32 && (count == 32 || value >> count == 0));
        self.acc |= (value as u64) << self.n;
        self.n += count;
        while self.n >= 8 {
            self.out.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    /// Writes a Huffman code of `len` bits, most significant bit first.
    fn code(&mut self, code: u32, len: u32) {
        self.bits(code.reverse_bits() >> (32 - len), len);
    }

    /// The fixed code of literal/length symbol `s` (RFC 1951 §3.2.6).
    fn literal_length(&mut self, s: u32) {
        match s {
            0..=143 => self.code(0x30 + s, 8),
            144..=255 => self.code(0x190 + s - 144, 9),
            256..=279 => self.code(s - 256, 7),
            _ => self.code(0xC0 + s - 280, 8),
        }
    }

    fn matched(&mut self, length: usize, distance: usize) {
        let i = LENGTH_BASE.partition_point(|&b| b as usize <= length) - 1;
        self.literal_length(257 + i as u32);
        self.bits((length - LENGTH_BASE[i] as usize) as u32, LENGTH_EXTRA[i] as u32);
        let j = DIST_BASE.partition_point(|&b| b as usize <= distance) - 1;
        self.code(j as u32, 5);
        self.bits((distance - DIST_BASE[j] as usize) as u32, DIST_EXTRA[j] as u32);
    }

    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.out.push(self.acc as u8);
        }
        self.out
    }
}

const LENGTH_BASE: [u16; 29] =
    [3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258];
const LENGTH_EXTRA: [u8; 29] = [0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0];
const DIST_BASE: [u16; 30] = [
    1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145,
    8193, 12289, 16385, 24577,
];
const DIST_EXTRA: [u8; 30] =
    [0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13];

const WINDOW: usize = 32_768;
const MIN_MATCH: usize = 3;
const MAX_MATCH: usize = 258;
const MAX_CHAIN: usize = 24;
const NONE: u32 = u32::MAX;

/// Greedy LZ77: at each position, the longest match among the last `MAX_CHAIN` positions with the
/// same 3-byte hash inside the window, else a literal.
fn lz77(data: &[u8], w: &mut BitWriter) {
    let mut head = vec![NONE; 1 << 15];
    let mut prev = vec![NONE; WINDOW];
    // Multiplicative hash of the next three bytes, 15 bits.
    let hash = |i: usize| {
        let key = (data[i] as u32) << 16 | (data[i + 1] as u32) << 8 | data[i + 2] as u32;
        (key.wrapping_mul(0x9E37_79B1) >> 17) as usize
    };
    let insert = |i: usize, head: &mut Vec<u32>, prev: &mut Vec<u32>| {
        if i + MIN_MATCH <= data.len() {
            let h = hash(i);
            prev[i % WINDOW] = head[h];
            head[h] = i as u32;
        }
    };
    let mut i = 0;
    while i < data.len() {
        let (len, dist) = longest_match(data, i, &head, &prev, i + MIN_MATCH <= data.len(), hash);
        if len >= MIN_MATCH {
            w.matched(len, dist);
            for k in i..i + len {
                insert(k, &mut head, &mut prev);
            }
            i += len;
        } else {
            w.literal_length(data[i] as u32);
            insert(i, &mut head, &mut prev);
            i += 1;
        }
    }
}

fn longest_match(
    data: &[u8],
    i: usize,
    head: &[u32],
    prev: &[u32],
    hashable: bool,
    hash: impl Fn(usize) -> usize,
) -> (usize, usize) {
    if !hashable {
        return (0, 0);
    }
    let limit = MAX_MATCH.min(data.len() - i);
    let (mut best_len, mut best_dist) = (0, 0);
    let mut j = head[hash(i)];
    for _ in 0..MAX_CHAIN {
        if j == NONE || (j as usize) >= i || i - j as usize > WINDOW {
            break;
        }
        let jj = j as usize;
        let len = data[jj..jj + limit].iter().zip(&data[i..i + limit]).take_while(|(a, b)| a == b).count();
        if len > best_len {
            best_len = len;
            best_dist = i - jj;
            if len == limit {
                break;
            }
        }
        let next = prev[jj % WINDOW];
        // An overwritten slot points forward (to a newer position): the chain ended.
        if next != NONE && next >= j {
            break;
        }
        j = next;
    }
    (best_len, best_dist)
}
