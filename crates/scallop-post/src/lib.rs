//! G-code output. A [`Dialect`] is data (decimals, axis words, feed conventions, header
//! and footer templates, line numbering, modal suppression, TCP and tilted-plane codes),
//! loadable from TOML, with built-ins for LinuxCNC, Fanuc, Siemens 840D, Heidenhain
//! (plain language and ISO) and grbl. Two writers:
//! - [`write_gcode`]: a 3-axis [`Toolpath`] (the demo path); [`write_fitted`]: a 3-axis
//!   path with `G2`/`G3` arcs ([`scallop_toolpath::fit_arcs`]) and the job's program,
//!   tool, spindle and 3+2 rotary positioning;
//! - [`write_program`]: a joint-space [`MachineProgram`](scallop_machine::program::MachineProgram)
//!   in joint space with inverse-time feeds, in TCP form, or in tilted work planes
//!   ([`OutputMode`]).
//!
//! [`replay`] reads our own output back into joint motion through the machine's forward
//! kinematics and [`check_replay`] checks it against the input CL path (spec K16).
//! Specification: `kinematics.md` 3.9-3.13; user documentation: `docs/post.md`.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_post::{Dialect, write_gcode};
//! use scallop_toolpath::{Move, MoveKind, Toolpath};
//! let mut path = Toolpath::new(1200.0);
//! path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 5.0)));
//! path.push(Move::new(MoveKind::Feed, Point3::new(10.0, 0.0, -0.0)));
//! let mut out = Vec::new();
//! write_gcode(&path, &Dialect::plain(), &["demo"], &mut out).unwrap();
//! let text = String::from_utf8(out).unwrap();
//! assert!(text.contains("G1 X10.000 Y0.000 Z0.000 F1200"));
//! ```
//!
//! # Invariants
//! - Never performs file I/O and never prints: text goes through `io::Write`.
//! - Output is deterministic: fixed decimals, `-0` written as `0`, modal words
//!   suppressed only by rule.
//! - Units in: mm, rad and mm/min; out: mm, deg, mm/min (1/min for G93, s for `FT`).
//!   G93 words are rounded down and `FT` times up, so no axis exceeds its velocity.
//! - Every numeric threshold lives in [`tol`].

use std::io::{self, Write};

use scallop_toolpath::{MoveKind, Toolpath};

pub mod dialect;
pub mod error;
pub mod reader;
pub mod three_axis;
pub mod tol;
pub mod writer;

pub use dialect::{ArcWords, Dialect, FeedByTime, LineNumbers, ModuloWords, Syntax, TcpCodes, TiltedPlane};
pub use error::PostError;
pub use reader::{ReplayedBlock, RoundTrip, check_replay, replay};
pub use three_axis::{NO_SPINDLE, ProgramInfo, Section, write_fitted, write_sections, write_toolpath};
pub use writer::{OutputMode, PostParams, cycle800_angles, program_text, write_program};

/// Formats `v` with `decimals` digits, writing negative zero as zero.
///
/// ```
/// assert_eq!(scallop_post::fmt_number(-0.0004, 3), "0.000");
/// assert_eq!(scallop_post::fmt_number(-1.25, 1), "-1.2");
/// ```
#[must_use]
pub fn fmt_number(v: f64, decimals: usize) -> String {
    let mut s = String::with_capacity(16);
    push_number(&mut s, v, decimals);
    s
}

/// Appends `v` with `decimals` digits to `out`, exactly as [`fmt_number`] formats it.
pub fn push_number(out: &mut String, v: f64, decimals: usize) {
    let mut bytes = [0u8; 32];
    match number_fast(&mut bytes, v, decimals) {
        // Only ASCII digits, '.' and '-' were written.
        Some(at) => out.push_str(std::str::from_utf8(&bytes[at..]).unwrap_or_default()),
        None => out.push_str(&fmt_number_exact(v, decimals)),
    }
}

/// [`push_number`] into a byte buffer (ASCII), for writers that build their text as bytes.
pub(crate) fn push_number_bytes(out: &mut Vec<u8>, v: f64, decimals: usize) {
    let mut bytes = [0u8; 32];
    match number_fast(&mut bytes, v, decimals) {
        Some(at) => out.extend_from_slice(&bytes[at..]),
        None => out.extend_from_slice(fmt_number_exact(v, decimals).as_bytes()),
    }
}

fn fmt_number_exact(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') { s[1..].to_string() } else { s }
}

/// `fmt_number` by integer arithmetic, byte for byte equal to the exact formatting
/// (`format!("{v:.decimals$}")` with `-0` cleaned) where it answers: away from rounding
/// ties by more than the product's rounding error, and for magnitudes where the scaled
/// value is an exact integer range. `None` sends the caller to the
/// exact formatter. The text is written at the end of `bytes`, from the returned index.
fn number_fast(bytes: &mut [u8; 32], v: f64, decimals: usize) -> Option<usize> {
    scaled_key(v, decimals).map(|key| write_key(bytes, key, decimals))
}

/// The number `fmt_number(v, decimals)` writes, as a signed integer in units of the last
/// digit (`-0` is `0`), where the integer fast path answers (see [`number_fast`]): two
/// values format to the same text exactly when their keys are equal, so modal words are
/// compared without formatting.
#[inline]
pub(crate) fn scaled_key(v: f64, decimals: usize) -> Option<i64> {
    const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];
    let &scale = POW10.get(decimals)?;
    let x = v.abs() * scale;
    // |x| < 1e9: the product's error is below 2.3e-7, far from the 1e-6 tie margin.
    if x.is_nan() || x >= 1e9 {
        return None;
    }
    // 0 <= x < 1e9: truncation is the floor, and both conversions are exact.
    #[allow(clippy::cast_possible_truncation, reason = "0 <= x < 1e9")]
    let floor = x as i64;
    #[allow(clippy::cast_precision_loss, reason = "below 1e9, exact")]
    let frac = x - floor as f64;
    if (frac - 0.5).abs() < tol::FAST_FORMAT_TIE_MARGIN {
        return None;
    }
    let n = floor + i64::from(frac > 0.5);
    Some(if v < 0.0 { -n } else { n })
}

pub(crate) use scallop_geom::num::{floor_fast, round_fast};

/// Appends a prefix (the last `prefix_len` bytes of `prefix`: a space, a word letter, a
/// `+`) and the number of a [`scaled_key`] with `decimals` digits: the hot path of every
/// motion block. For 3 and 4 decimals and fewer than 8 digits, [`push_token_dec`]; other
/// cases go through [`push_key`].
#[inline(always)]
pub(crate) fn push_token_key(out: &mut Vec<u8>, prefix: [u8; 4], prefix_len: usize, key: i64, decimals: usize) {
    if key.unsigned_abs() < 100_000_000 && prefix_len <= 4 {
        match decimals {
            3 => return push_token_dec::<3>(out, prefix, prefix_len, key),
            4 => return push_token_dec::<4>(out, prefix, prefix_len, key),
            _ => {}
        }
    }
    out.extend_from_slice(&prefix[4 - prefix_len.min(4)..]);
    push_key(out, key, decimals);
}

/// [`push_token_key`] for `D` decimals (3 or 4) and `|key| < 1e8`: the eight digits of
/// `|key|` (leading zeros included) are computed at once in the lanes of a `u64` (two
/// 4-digit lanes, then four 2-digit lanes, then eight 1-digit lanes, by multiplications
/// that divide every lane by 100 and 10 without carries between lanes), the point is
/// inserted, the integer part's leading zeros are skipped, and the token (at most 16
/// bytes with its prefix and sign) is appended with one fixed-length copy.
#[inline(always)]
fn push_token_dec<const D: usize>(out: &mut Vec<u8>, prefix: [u8; 4], prefix_len: usize, key: i64) {
    let n = key.unsigned_abs();
    let merged = (n / 10_000) | ((n % 10_000) << 32);
    let hundreds = ((merged * 10_486) >> 20) & 0x0000_007f_0000_007f;
    let merged = hundreds | ((merged - 100 * hundreds) << 16);
    let tens = ((merged * 103) >> 10) & 0x000f_000f_000f_000f;
    let merged = tens | ((merged - 10 * tens) << 8);
    let digits = (merged + 0x3030_3030_3030_3030).to_le_bytes();
    let int = n / if D == 3 { 1_000 } else { 10_000 };
    let int_len =
        1 + usize::from(int >= 10) + usize::from(int >= 100) + usize::from(int >= 1_000) + usize::from(int >= 10_000);
    let mut buf = [0u8; 40];
    buf[16..24].copy_from_slice(&digits);
    buf[24 - D] = b'.';
    buf[25 - D..25].copy_from_slice(&digits[8 - D..]);
    let mut start = 24 - D - int_len;
    if key < 0 {
        start -= 1;
        buf[start] = b'-';
    }
    buf[start - 4..start].copy_from_slice(&prefix);
    start -= prefix_len;
    let len = out.len() + 25 - start;
    out.extend_from_slice(&buf[start..start + 16]);
    out.truncate(len);
}

/// Appends the number of a [`scaled_key`] with `decimals` digits.
#[inline]
pub(crate) fn push_key(out: &mut Vec<u8>, key: i64, decimals: usize) {
    // A key is below 1e9 + 1 in magnitude: at most 10 digits, the point and the sign, so
    // the number ends at byte 32 and starts at byte 20 or later. A fixed-length copy of
    // 16 bytes (inlined, no memcpy call) followed by a truncation appends exactly it.
    let mut bytes = [0u8; 48];
    let mut head = [0u8; 32];
    let at = write_key(&mut head, key, decimals);
    if at < 20 {
        out.extend_from_slice(&head[at..]);
        return;
    }
    bytes[..32].copy_from_slice(&head);
    let len = out.len() + 32 - at;
    out.extend_from_slice(&bytes[at..at + 16]);
    out.truncate(len);
}

/// Writes the number of a [`scaled_key`] with `decimals` digits at the end of `bytes`;
/// returns the index of its first byte.
pub(crate) fn write_key(bytes: &mut [u8; 32], key: i64, decimals: usize) -> usize {
    const POW10_U64: [u64; 10] =
        [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000, 100_000_000, 1_000_000_000];
    const DIGIT_PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
        2021222324252627282930313233343536373839\
        4041424344454647484950515253545556575859\
        6061626364656667686970717273747576777879\
        8081828384858687888990919293949596979899";
    let n = key.unsigned_abs();
    // Written right to left into a stack buffer: at least decimals + 1 digits (leading
    // zeros), the point, the sign; then appended in one copy. Constant divisors (no
    // hardware division) for the usual decimals.
    let (mut n, mut f) = match decimals {
        0 => (n, 0),
        1 => (n / 10, n % 10),
        2 => (n / 100, n % 100),
        3 => (n / 1_000, n % 1_000),
        4 => (n / 10_000, n % 10_000),
        _ => (n / POW10_U64[decimals], n % POW10_U64[decimals]),
    };
    let mut at = bytes.len();
    let mut k = 0;
    if decimals > 0 {
        // The fraction digits, two at a time, then the point.
        while k + 2 <= decimals {
            let pair = (f % 100) as usize;
            f /= 100;
            at -= 2;
            bytes[at..at + 2].copy_from_slice(&DIGIT_PAIRS[2 * pair..2 * pair + 2]);
            k += 2;
        }
        if k < decimals {
            at -= 1;
            bytes[at] = b'0' + (f % 10) as u8;
        }
        at -= 1;
        bytes[at] = b'.';
    }
    // The integer digits (at least one), two at a time.
    while n >= 100 {
        let pair = (n % 100) as usize;
        n /= 100;
        at -= 2;
        bytes[at..at + 2].copy_from_slice(&DIGIT_PAIRS[2 * pair..2 * pair + 2]);
    }
    if n >= 10 {
        at -= 2;
        bytes[at..at + 2].copy_from_slice(&DIGIT_PAIRS[2 * n as usize..2 * n as usize + 2]);
    } else {
        at -= 1;
        bytes[at] = b'0' + n as u8;
    }
    if key < 0 {
        at -= 1;
        bytes[at] = b'-';
    }
    at
}

/// Writes `path` as G-code. `comments` go into the header (one line each).
///
/// # Errors
/// Any error of `out`.
pub fn write_gcode(path: &Toolpath, dialect: &Dialect, comments: &[&str], out: &mut impl Write) -> io::Result<()> {
    let (open, close) = (&dialect.comment.0, &dialect.comment.1);
    writeln!(out, "{open}scallop, dialect: {}{close}", dialect.name)?;
    for c in comments {
        let clean: String = c.chars().map(|ch| if ch == '(' || ch == ')' { '_' } else { ch }).collect();
        writeln!(out, "{open}{clean}{close}")?;
    }
    for h in &dialect.header {
        writeln!(out, "{h}")?;
    }
    let d = dialect.decimals;
    let mut last_feed: Option<f64> = None;
    for m in path.moves() {
        let (x, y, z) = (fmt_number(m.to.x, d), fmt_number(m.to.y, d), fmt_number(m.to.z, d));
        match m.kind {
            MoveKind::Rapid | MoveKind::Retract => {
                writeln!(out, "G0 X{x} Y{y} Z{z}")?;
            }
            kind => {
                let feed = if kind == MoveKind::Plunge { path.plunge_feed } else { path.feed };
                if last_feed.is_some_and(|f| f.to_bits() == feed.to_bits()) {
                    writeln!(out, "G1 X{x} Y{y} Z{z}")?;
                } else {
                    writeln!(out, "G1 X{x} Y{y} Z{z} F{}", fmt_number(feed, 0))?;
                    last_feed = Some(feed);
                }
                continue;
            }
        }
        last_feed = None;
    }
    for f in &dialect.footer {
        writeln!(out, "{f}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{floor_fast, fmt_number, push_key, push_token_key, round_fast, scaled_key};

    #[test]
    fn keys_format_as_the_exact_formatter_and_the_fast_roundings_equal_the_library() {
        let mut rng = scallop_geom::rng::SplitMix64::new(0x2545_f491_4f6c_dd1d);
        for _ in 0..100_000 {
            let magnitude = 10f64.powi(i32::try_from(rng.next_u64() % 16).unwrap_or(0) - 6);
            let v = (rng.unit() - 0.5) * 2.0 * magnitude;
            for d in [0, 1, 3, 4, 6, 9] {
                if let Some(key) = scaled_key(v, d) {
                    let exact = fmt_number(v, d);
                    let mut out = b"X".to_vec();
                    push_key(&mut out, key, d);
                    assert_eq!(out[1..], *exact.as_bytes(), "{v:e} at {d}");
                    out.clear();
                    push_token_key(&mut out, [0, b' ', b'X', b'+'], 3, key, d);
                    assert_eq!(out, format!(" X+{exact}").into_bytes(), "{v:e} at {d}");
                    out.clear();
                    push_token_key(&mut out, [b'a', b'b', b'c', b'Y'], 1, key, d);
                    assert_eq!(out, format!("Y{exact}").into_bytes(), "{v:e} at {d}");
                }
            }
            for x in
                [v, v * 1e3, v + 0.5, -v - 0.5, v.trunc() + 0.5, v.trunc() - 0.5, -0.0, 0.0, 4.6e15, -4.6e15, f64::NAN]
            {
                assert_eq!(round_fast(x).to_bits(), x.round().to_bits(), "round {x:e}");
                assert_eq!(floor_fast(x).to_bits(), x.floor().to_bits(), "floor {x:e}");
            }
        }
    }

    fn exact(v: f64, decimals: usize) -> String {
        let s = format!("{v:.decimals$}");
        if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') { s[1..].to_string() } else { s }
    }

    #[test]
    fn the_fast_path_equals_the_exact_formatter() {
        // A deterministic sweep of magnitudes, signs, ties and near-ties.
        let mut rng = scallop_geom::rng::SplitMix64::new(0x9e37_79b9_7f4a_7c15);
        for _ in 0..200_000 {
            let bits = rng.next_u64();
            let magnitude = 10f64.powi(i32::try_from(bits % 14).unwrap_or(0) - 6);
            let v = (rng.unit() - 0.5) * 2.0 * magnitude;
            for d in [0, 1, 3, 4, 6] {
                assert_eq!(fmt_number(v, d), exact(v, d), "{v:e} at {d}");
            }
        }
        for v in [0.5, 1.5, 2.5, -2.5, 0.125, -0.125, 1.0005, 123.45, -0.0, 0.0, 1e12, -7.00005, 999_999.999_95] {
            for d in [0, 1, 2, 3, 4] {
                assert_eq!(fmt_number(v, d), exact(v, d), "{v} at {d}");
            }
        }
    }
}
