//! Regular sample axes `MIN:MAX:STEP`.

/// Largest number of points of a whole grid (one f64 triple each in memory).
pub const MAX_GRID_POINTS: usize = 500_000_000;

/// Largest number of samples along one axis; larger requests are mistakes.
pub const MAX_AXIS_SAMPLES: usize = 100_000_000;

/// Why a grid axis is unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GridError {
    /// Not three numbers separated by colons.
    #[error("'{0}' is not MIN:MAX:STEP (three numbers separated by colons, e.g. 0:100:0.5)")]
    Syntax(String),
    /// A non-finite number, a step <= 0 or MAX < MIN.
    #[error("'{0}': need finite numbers with MIN <= MAX and STEP > 0")]
    Values(String),
    /// Far too many samples.
    #[error("'{spec}' gives {count} samples, more than the limit of {MAX_AXIS_SAMPLES}; use a larger STEP")]
    TooMany {
        /// The axis as given.
        spec: String,
        /// Samples it would give.
        count: f64,
    },
}

/// Samples `min + i * step` for `i = 0..=round((max - min) / step)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridAxis {
    /// First sample.
    pub min: f64,
    /// Nominal last sample.
    pub max: f64,
    /// Spacing (> 0).
    pub step: f64,
}

impl GridAxis {
    /// Parses `MIN:MAX:STEP`.
    ///
    /// # Errors
    /// [`GridError`] naming the text.
    ///
    /// ```
    /// use scallop_engine::GridAxis;
    /// let a = GridAxis::parse("0:1:0.25").unwrap();
    /// assert_eq!(a.values(), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
    /// assert!(GridAxis::parse("0:1:-1").is_err());
    /// assert!(GridAxis::parse("0:1").is_err());
    /// ```
    pub fn parse(spec: &str) -> Result<GridAxis, GridError> {
        let parts: Vec<&str> = spec.split(':').collect();
        let [a, b, c] = parts.as_slice() else { return Err(GridError::Syntax(spec.to_string())) };
        let num = |t: &str| t.trim().parse::<f64>().map_err(|_| GridError::Syntax(spec.to_string()));
        let (min, max, step) = (num(a)?, num(b)?, num(c)?);
        if !(min.is_finite() && max.is_finite() && step.is_finite() && step > 0.0 && max >= min) {
            return Err(GridError::Values(spec.to_string()));
        }
        let count = ((max - min) / step).round() + 1.0;
        #[allow(clippy::cast_precision_loss)]
        if count.is_nan() || count > MAX_AXIS_SAMPLES as f64 {
            return Err(GridError::TooMany { spec: spec.to_string(), count });
        }
        Ok(GridAxis { min, max, step })
    }

    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        // INVARIANT: parse() bounded the count by MAX_AXIS_SAMPLES.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let n = ((self.max - self.min) / self.step).round() as usize + 1;
        n
    }

    /// Always false: an axis has at least one sample.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The sample values.
    #[must_use]
    pub fn values(&self) -> Vec<f64> {
        #[allow(clippy::cast_precision_loss)]
        (0..self.len()).map(|i| self.min + i as f64 * self.step).collect()
    }
}
