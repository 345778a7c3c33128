//! Small numeric routines shared across the workspace: fast exact rounding
//! (bit-identical to the standard library's `round` and `floor`, for the machine
//! layer and the post-processor), the one golden-section search and the one
//! check of settings that must be finite and positive.

/// `x.round()` (half away from zero, signed zero kept) without the library call for
/// |x| < 2^52, where truncation and the fraction are exact.
#[inline]
#[must_use]
pub fn round_fast(x: f64) -> f64 {
    let Some(t) = truncated(x) else { return x.round() };
    let f = x - t;
    let r = if f >= 0.5 {
        t + 1.0
    } else if f <= -0.5 {
        t - 1.0
    } else {
        t
    };
    r.copysign(x)
}

/// `x.floor()` (signed zero kept) without the library call for |x| < 2^52.
#[inline]
#[must_use]
pub fn floor_fast(x: f64) -> f64 {
    let Some(t) = truncated(x) else { return x.floor() };
    let r = if t > x { t - 1.0 } else { t };
    r.copysign(x)
}

/// `x` truncated toward zero, for |x| < 2^52 (where the cast and the fraction
/// `x - t` are exact); `None` beyond.
#[inline]
fn truncated(x: f64) -> Option<f64> {
    if x.abs() < 4_503_599_627_370_496.0 {
        #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss, reason = "|x| < 2^52, exact")]
        let t = x as i64 as f64;
        Some(t)
    } else {
        None
    }
}

/// The first setting of `settings` (name, value) that is not a finite number
/// greater than zero: the check of lengths, steps and rates before any work.
///
/// ```
/// use scallop_geom::num::first_not_positive;
/// assert_eq!(first_not_positive(&[("step", 0.5), ("feed", 0.0), ("depth", f64::NAN)]), Some(("feed", 0.0)));
/// assert_eq!(first_not_positive(&[("step", 0.5)]), None);
/// ```
#[must_use]
pub fn first_not_positive<N: Copy>(settings: &[(N, f64)]) -> Option<(N, f64)> {
    settings.iter().copied().find(|&(_, v)| !(v.is_finite() && v > 0.0))
}

/// `1 / phi = (sqrt(5) - 1) / 2`, the golden section's shrink factor.
const INV_PHI: f64 = 0.618_033_988_749_894_9;

/// The end of a golden-section search: its last bracket and the two inner samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GoldenBracket {
    /// Low end of the bracket.
    pub lo: f64,
    /// High end of the bracket.
    pub hi: f64,
    /// The inner samples `(x, f(x))`, the lower `x` first.
    pub inner: [(f64, f64); 2],
}

/// Golden-section search on `[lo, hi]` (Kiefer 1953; Press et al., *Numerical
/// Recipes*, 3rd ed., 2007, section 10.2): at most `iterations` steps, stopping
/// early once the bracket is at most `stop` wide. Each step keeps the lower part
/// `[lo, x2]` when `keep_low(f(x1), f(x2))`, else the upper part `[x1, hi]`:
/// `f1 <= f2` closes in on a minimum of a unimodal `f`, `f1 > f2` on a maximum
/// (the comparison also fixes which part a tie keeps).
///
/// ```
/// use scallop_geom::num::golden_section;
/// let end = golden_section(|x: f64| (x - 0.3).powi(2), (0.0, 1.0), 60, None, |f1, f2| f1 <= f2);
/// assert!((end.inner[0].0 - 0.3).abs() < 1e-6 && end.lo <= 0.3 && 0.3 <= end.hi);
/// ```
pub fn golden_section(
    f: impl Fn(f64) -> f64,
    (mut lo, mut hi): (f64, f64),
    iterations: usize,
    stop: Option<f64>,
    keep_low: impl Fn(f64, f64) -> bool,
) -> GoldenBracket {
    let (mut x1, mut x2) = (hi - INV_PHI * (hi - lo), lo + INV_PHI * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..iterations {
        if stop.is_some_and(|width| hi - lo <= width) {
            break;
        }
        if keep_low(f1, f2) {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - INV_PHI * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + INV_PHI * (hi - lo);
            f2 = f(x2);
        }
    }
    GoldenBracket { lo, hi, inner: [(x1, f1), (x2, f2)] }
}

#[cfg(test)]
mod tests {
    use super::{floor_fast, golden_section, round_fast};

    #[test]
    fn equal_the_library_bit_for_bit() {
        for &x in &[
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.499_999_999_999_999_6,
            -7.5,
            1e15 + 0.5,
            4.6e15,
            -4.6e15,
            1e300,
            f64::NAN,
        ] {
            assert_eq!(round_fast(x).to_bits(), x.round().to_bits(), "round {x:e}");
            assert_eq!(floor_fast(x).to_bits(), x.floor().to_bits(), "floor {x:e}");
        }
    }

    #[test]
    fn golden_section_brackets_the_minimum_and_the_maximum() {
        // The shrink factor is (sqrt(5) - 1) / 2 to the last bit.
        assert_eq!(super::INV_PHI.to_bits(), ((5f64.sqrt() - 1.0) / 2.0).to_bits());
        for &c in &[0.0, 0.1, 0.5, 0.77, 1.0] {
            let min = golden_section(|x: f64| (x - c).abs(), (0.0, 1.0), 80, None, |f1, f2| f1 <= f2);
            let max = golden_section(|x: f64| -(x - c).abs(), (0.0, 1.0), 80, None, |f1, f2| f1 > f2);
            for end in [min, max] {
                assert!(end.lo <= c + 1e-12 && c <= end.hi + 1e-12, "{c}: {end:?}");
                assert!(end.hi - end.lo < 1e-12, "{end:?}");
            }
        }
        // The stop width ends the search early.
        let end = golden_section(|x: f64| x * x, (-1.0, 1.0), 80, Some(0.1), |f1, f2| f1 <= f2);
        assert!(end.hi - end.lo <= 0.1 && end.hi - end.lo > 0.1 * 0.6);
    }
}
