//! Pictures without dependencies: an RGB raster, a 5x7 digit font for labels,
//! and a PNG encoder: rows filtered with "Sub" and compressed by a small
//! deflate (greedy LZ77 over a hash chain, one block of fixed Huffman codes):
//! byte-for-byte deterministic, and pictures with large plain areas shrink
//! twenty-fold or more against stored blocks. The one PNG encoder of the workspace: the
//! renderer and the CLI's plots use it.

/// An RGB image.
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major RGB bytes.
    pub pixels: Vec<u8>,
}

impl Image {
    /// A blank image of one colour.
    #[must_use]
    pub fn new(width: usize, height: usize, rgb: [u8; 3]) -> Image {
        Image { width, height, pixels: rgb.repeat(width * height) }
    }

    /// Sets a pixel (ignored outside).
    pub fn set(&mut self, x: usize, y: usize, rgb: [u8; 3]) {
        if x < self.width && y < self.height {
            let k = 3 * (y * self.width + x);
            self.pixels[k..k + 3].copy_from_slice(&rgb);
        }
    }

    /// Fills a rectangle.
    pub fn fill(&mut self, x0: usize, y0: usize, w: usize, h: usize, rgb: [u8; 3]) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.set(x, y, rgb);
            }
        }
    }

    /// Writes `text` (digits, `.`, `-`, `+`, space, `m`, `e`) at (x, y), `scale` pixels per font pixel.
    pub fn text(&mut self, x: usize, y: usize, text: &str, scale: usize, rgb: [u8; 3]) {
        for (k, ch) in text.chars().enumerate() {
            let glyph = glyph(ch);
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0b10000 >> col) != 0 {
                        self.fill(x + (k * 6 + col) * scale, y + row * scale, scale, scale, rgb);
                    }
                }
            }
        }
    }

    /// The colour of a pixel (`None` outside).
    #[must_use]
    pub fn get(&self, x: usize, y: usize) -> Option<[u8; 3]> {
        (x < self.width && y < self.height).then(|| {
            let k = 3 * (y * self.width + x);
            [self.pixels[k], self.pixels[k + 1], self.pixels[k + 2]]
        })
    }

    /// The PNG file.
    #[must_use]
    pub fn to_png(&self) -> Vec<u8> {
        let mut raw = Vec::with_capacity((3 * self.width + 1) * self.height);
        for row in self.pixels.chunks(3 * self.width) {
            raw.push(1); // filter: Sub (difference to the pixel on the left)
            raw.extend(row.iter().enumerate().map(|(k, &b)| if k < 3 { b } else { b.wrapping_sub(row[k - 3]) }));
        }
        let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = Vec::new();
        ihdr.extend_from_slice(&u32::try_from(self.width).unwrap_or(u32::MAX).to_be_bytes());
        ihdr.extend_from_slice(&u32::try_from(self.height).unwrap_or(u32::MAX).to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8-bit RGB
        chunk(&mut out, b"IHDR", &ihdr);
        chunk(&mut out, b"IDAT", &zlib(&raw));
        chunk(&mut out, b"IEND", &[]);
        out
    }
}

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&u32::try_from(data.len()).unwrap_or(u32::MAX).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// Bits written least significant first, as deflate wants.
struct Bits {
    out: Vec<u8>,
    acc: u64,
    n: u32,
}

impl Bits {
    fn put(&mut self, value: u32, bits: u32) {
        self.acc |= u64::from(value) << self.n;
        self.n += bits;
        while self.n >= 8 {
            self.out.push((self.acc & 0xff) as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    /// A Huffman code: sent most significant bit first.
    fn code(&mut self, code: u32, bits: u32) {
        self.put(code.reverse_bits() >> (32 - bits), bits);
    }

    /// A literal or length symbol of the fixed Huffman code (RFC 1951, 3.2.6).
    fn symbol(&mut self, s: u32) {
        match s {
            0..=143 => self.code(0x30 + s, 8),
            144..=255 => self.code(0x190 + s - 144, 9),
            256..=279 => self.code(s - 256, 7),
            _ => self.code(0xc0 + s - 280, 8),
        }
    }
}

/// Match lengths: base of each length code 257.. and its extra bits.
const LENGTH_BASE: [u32; 29] =
    [3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258];
const LENGTH_EXTRA: [u32; 29] = [0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0];
/// Distances: base of each distance code and its extra bits.
const DIST_BASE: [u32; 30] = [
    1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145,
    8193, 12289, 16385, 24577,
];
const DIST_EXTRA: [u32; 30] =
    [0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13];
/// Deflate's window (bytes).
const WINDOW: usize = 32_768;
/// Longest match.
const MAX_MATCH: usize = 258;
/// Candidates tried per position (speed against size).
const MAX_CHAIN: usize = 32;

/// zlib stream of `data`: one final deflate block with fixed Huffman codes.
fn zlib(data: &[u8]) -> Vec<u8> {
    let mut bits = Bits { out: vec![0x78, 0x01], acc: 0, n: 0 };
    bits.put(1, 1); // final block
    bits.put(1, 2); // fixed Huffman codes
    const HASH: usize = 1 << 15;
    let mut head = vec![usize::MAX; HASH];
    let mut prev = vec![usize::MAX; WINDOW];
    let hash = |k: usize| {
        ((usize::from(data[k]) << 10) ^ (usize::from(data[k + 1]) << 5) ^ usize::from(data[k + 2])) & (HASH - 1)
    };
    let insert = |k: usize, head: &mut Vec<usize>, prev: &mut Vec<usize>| {
        if k + 2 < data.len() {
            let h = hash(k);
            prev[k % WINDOW] = head[h];
            head[h] = k;
        }
    };
    let mut k = 0;
    while k < data.len() {
        let (mut best_len, mut best_dist) = (0usize, 0usize);
        if k + 2 < data.len() {
            let mut cand = head[hash(k)];
            let limit = (data.len() - k).min(MAX_MATCH);
            for _ in 0..MAX_CHAIN {
                if cand == usize::MAX || k - cand > WINDOW - 1 || cand >= k {
                    break;
                }
                let len = data[cand..].iter().zip(&data[k..k + limit]).take_while(|(a, b)| a == b).count();
                if len > best_len {
                    (best_len, best_dist) = (len, k - cand);
                    if len == limit {
                        break;
                    }
                }
                let next = prev[cand % WINDOW];
                if next == usize::MAX || next >= cand {
                    break;
                }
                cand = next;
            }
        }
        if best_len >= 3 {
            #[allow(clippy::cast_possible_truncation, reason = "lengths <= 258, distances < 32768")]
            let (len, dist) = (best_len as u32, best_dist as u32);
            let lc = LENGTH_BASE.iter().rposition(|&b| b <= len).unwrap_or(0);
            bits.symbol(257 + lc as u32);
            bits.put(len - LENGTH_BASE[lc], LENGTH_EXTRA[lc]);
            let dc = DIST_BASE.iter().rposition(|&b| b <= dist).unwrap_or(0);
            bits.code(dc as u32, 5);
            bits.put(dist - DIST_BASE[dc], DIST_EXTRA[dc]);
            for j in k..k + best_len {
                insert(j, &mut head, &mut prev);
            }
            k += best_len;
        } else {
            bits.symbol(u32::from(data[k]));
            insert(k, &mut head, &mut prev);
            k += 1;
        }
    }
    bits.symbol(256); // end of block
    bits.put(0, 7); // flush to a byte boundary
    let mut out = bits.out;
    let (mut a, mut b) = (1u32, 0u32);
    for &byte in data {
        a = (a + u32::from(byte)) % 65_521;
        b = (b + a) % 65_521;
    }
    out.extend_from_slice(&((b << 16) | a).to_be_bytes());
    out
}

fn crc32(data: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &byte in data {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

fn glyph(ch: char) -> [u8; 7] {
    match ch {
        '0' => [0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e],
        '1' => [0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e],
        '2' => [0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f],
        '3' => [0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e],
        '4' => [0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02],
        '5' => [0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e],
        '6' => [0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e],
        '7' => [0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e],
        '9' => [0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c],
        '.' => [0, 0, 0, 0, 0, 0x0c, 0x0c],
        '-' => [0, 0, 0, 0x1f, 0, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1f, 0x04, 0x04, 0],
        'm' => [0, 0, 0x1a, 0x15, 0x15, 0x11, 0x11],
        'e' => [0, 0, 0x0e, 0x11, 0x1f, 0x10, 0x0e],
        _ => [0; 7],
    }
}

/// A perceptually ordered colour ramp (blue, cyan, green, yellow, red) for t in [0, 1].
#[must_use]
pub fn ramp(t: f64) -> [u8; 3] {
    let stops: [[f64; 3]; 5] =
        [[40.0, 60.0, 200.0], [0.0, 190.0, 220.0], [40.0, 190.0, 60.0], [240.0, 220.0, 30.0], [220.0, 50.0, 40.0]];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 } * 4.0;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let k = (t.floor() as usize).min(3);
    let f = t - k as f64;
    let mix = |c: usize| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let v = (stops[k][c] + (stops[k + 1][c] - stops[k][c]) * f).round() as u8;
        v
    };
    [mix(0), mix(1), mix(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inflates a zlib stream of fixed-Huffman blocks (the test's own decoder, RFC 1951).
    fn inflate(z: &[u8]) -> Vec<u8> {
        let data = &z[2..z.len() - 4];
        let mut pos = 0usize; // bit position
        let mut bit = || {
            let b = (data[pos / 8] >> (pos % 8)) & 1;
            pos += 1;
            u32::from(b)
        };
        let mut out: Vec<u8> = Vec::new();
        loop {
            let last = bit();
            let kind = bit() | (bit() << 1);
            assert_eq!(kind, 1, "fixed Huffman block");
            loop {
                // Read a fixed-Huffman literal/length symbol, MSB first.
                let mut code = 0u32;
                for _ in 0..7 {
                    code = (code << 1) | bit();
                }
                let sym = if code <= 0x17 {
                    code + 256
                } else {
                    code = (code << 1) | bit();
                    if (0x30..=0xbf).contains(&code) {
                        code - 0x30
                    } else if (0xc0..=0xc7).contains(&code) {
                        code - 0xc0 + 280
                    } else {
                        code = (code << 1) | bit();
                        code - 0x190 + 144
                    }
                };
                let read = |n: u32, bit: &mut dyn FnMut() -> u32| (0..n).fold(0u32, |v, i| v | (bit() << i));
                match sym {
                    0..=255 => out.push(sym as u8),
                    256 => break,
                    _ => {
                        let lc = (sym - 257) as usize;
                        let len = LENGTH_BASE[lc] + read(LENGTH_EXTRA[lc], &mut bit);
                        let mut dc = 0u32;
                        for _ in 0..5 {
                            dc = (dc << 1) | bit();
                        }
                        let dist = DIST_BASE[dc as usize] + read(DIST_EXTRA[dc as usize], &mut bit);
                        for _ in 0..len {
                            out.push(out[out.len() - dist as usize]);
                        }
                    }
                }
            }
            if last == 1 {
                return out;
            }
        }
    }

    #[test]
    fn crc_and_adler_match_known_values() {
        assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
        let z = zlib(b"Wikipedia");
        assert_eq!(&z[z.len() - 4..], &0x11e6_0398u32.to_be_bytes());
    }

    #[test]
    fn deflate_round_trips() {
        let mut noise = 12_345u32;
        let cases: Vec<Vec<u8>> = vec![
            Vec::new(),
            b"a".to_vec(),
            b"abcabcabcabcabcabcabcabcabcabcabcabcabc".to_vec(),
            vec![7u8; 100_000],
            (0..70_000u32)
                .map(|k| {
                    noise = noise.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                    if k % 5 == 0 { (noise >> 16) as u8 } else { (k % 251) as u8 }
                })
                .collect(),
        ];
        for data in cases {
            let z = zlib(&data);
            assert_eq!(inflate(&z), data, "{} bytes", data.len());
        }
        assert!(zlib(&[0u8; 100_000]).len() < 2_000);
    }

    #[test]
    fn png_is_deterministic_and_well_formed() {
        let mut img = Image::new(70_000 / 3, 3, [1, 2, 3]);
        img.text(0, 0, "0.025 mm", 1, [255, 255, 255]);
        let a = img.to_png();
        assert_eq!(a, img.to_png());
        assert_eq!(&a[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&a[a.len() - 8..a.len() - 4], b"IEND");
    }
}
