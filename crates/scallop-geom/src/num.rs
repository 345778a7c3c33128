//! Fast exact rounding helpers shared by the machine layer and the post-processor:
//! bit-identical to the standard library's `round` and `floor`.

/// `x.round()` (half away from zero, signed zero kept) without the library call for
/// |x| < 2^52, where truncation and the fraction are exact.
#[inline]
#[must_use]
pub fn round_fast(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss, reason = "|x| < 2^52, exact")]
        let t = x as i64 as f64;
        let f = x - t;
        let r = if f >= 0.5 {
            t + 1.0
        } else if f <= -0.5 {
            t - 1.0
        } else {
            t
        };
        r.copysign(x)
    } else {
        x.round()
    }
}

/// `x.floor()` (signed zero kept) without the library call for |x| < 2^52.
#[inline]
#[must_use]
pub fn floor_fast(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss, reason = "|x| < 2^52, exact")]
        let t = x as i64 as f64;
        let r = if t > x { t - 1.0 } else { t };
        r.copysign(x)
    } else {
        x.floor()
    }
}

#[cfg(test)]
mod tests {
    use super::{floor_fast, round_fast};

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
}
