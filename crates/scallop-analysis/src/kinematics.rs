//! Jerk-limited stop-to-stop machining time (finishing.md chapter 7).
//!
//! Units: mm and s throughout (feed mm/s, acceleration mm/s^2, jerk mm/s^3). Every
//! formula of chapter 7 is dimensionally homogeneous, so evaluating it in mm and s
//! gives the same seconds as the specification's SI evaluation.

use serde::{Deserialize, Serialize};

use crate::error::AnalysisError;

/// Which stop-to-stop time model to use (finishing.md 7.1, 7.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KinematicModel {
    /// Full jerk-limited S-curve with four cases (7.2) [DECISION, default]. Equals
    /// [`KinematicModel::Thesis`] whenever `V J <= A^2` (always with the defaults).
    #[default]
    SCurve,
    /// The thesis's three cases selected by the argmin of `t_A`, `t_V`, `t_l` (7.1)
    /// \[COMPAT\]; wrong when `A` is reached but `V` is not (`V J > A^2`, short moves).
    Thesis,
}

/// Machine kinematics: nominal feed `V`, maximum acceleration `A`, maximum jerk `J`.
///
/// [`Default`] is the specification's default machine (finishing.md 13):
/// `V = 5 m/min = 83.333 mm/s`, `A = 6 m/s^2 = 6000 mm/s^2`,
/// `J = 40 m/s^3 = 40000 mm/s^3`, full S-curve model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MachineLimits {
    /// Nominal (programmed) feed rate `V` (mm/s).
    pub feed: f64,
    /// Maximum acceleration `A_max` (mm/s^2).
    pub acceleration: f64,
    /// Maximum jerk `J_max` (mm/s^3).
    pub jerk: f64,
    /// Stop-to-stop time model.
    pub model: KinematicModel,
}

impl Default for MachineLimits {
    fn default() -> Self {
        MachineLimits { feed: 5000.0 / 60.0, acceleration: 6000.0, jerk: 40_000.0, model: KinematicModel::SCurve }
    }
}

impl MachineLimits {
    /// Limits given in the thesis's units: feed in m/min, acceleration in m/s^2,
    /// jerk in m/s^3 (full S-curve model).
    ///
    /// ```
    /// use scallop_analysis::MachineLimits;
    /// assert_eq!(MachineLimits::from_thesis_units(5.0, 6.0, 40.0), MachineLimits::default());
    /// ```
    #[must_use]
    pub fn from_thesis_units(feed_m_per_min: f64, acceleration_m_s2: f64, jerk_m_s3: f64) -> MachineLimits {
        MachineLimits {
            feed: feed_m_per_min * 1000.0 / 60.0,
            acceleration: acceleration_m_s2 * 1000.0,
            jerk: jerk_m_s3 * 1000.0,
            model: KinematicModel::SCurve,
        }
    }

    /// Checks that `V`, `A` and `J` are finite and positive.
    ///
    /// ```
    /// let mut m = scallop_analysis::MachineLimits::default();
    /// assert!(m.validate().is_ok());
    /// m.jerk = 0.0;
    /// assert!(m.validate().is_err());
    /// ```
    ///
    /// # Errors
    /// [`AnalysisError::BadMachine`] naming the first bad value.
    pub fn validate(&self) -> Result<(), AnalysisError> {
        for (what, value) in [("feed", self.feed), ("acceleration", self.acceleration), ("jerk", self.jerk)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(AnalysisError::BadMachine { what, value });
            }
        }
        Ok(())
    }

    /// `t_A = A / J`: time to reach the maximum acceleration (s).
    ///
    /// ```
    /// assert!((scallop_analysis::MachineLimits::default().time_to_acceleration() - 0.15).abs() < 1e-15);
    /// ```
    #[must_use]
    pub fn time_to_acceleration(&self) -> f64 {
        self.acceleration / self.jerk
    }

    /// `t_V = sqrt(V / J)`: time to reach the feed without reaching `A` (s).
    ///
    /// ```
    /// let t = scallop_analysis::MachineLimits::default().time_to_feed();
    /// assert!((t - 0.045_643_546).abs() < 1e-9);
    /// ```
    #[must_use]
    pub fn time_to_feed(&self) -> f64 {
        (self.feed / self.jerk).sqrt()
    }

    /// `t_l = cbrt(l / J)`: time to cover the half-length `l` (mm) when neither `V`
    /// nor `A` is reached (s).
    ///
    /// ```
    /// let m = scallop_analysis::MachineLimits::default();
    /// assert!((m.time_for_half_length(40.0) - 0.1).abs() < 1e-15);
    /// ```
    #[must_use]
    pub fn time_for_half_length(&self, half_length: f64) -> f64 {
        (half_length / self.jerk).cbrt()
    }

    /// The full segment length `2 sqrt(V^3 / J)` (mm) above which a stop-to-stop
    /// move reaches the feed when `A` is never reached (7.3: 7.607 mm by default).
    ///
    /// ```
    /// let l = scallop_analysis::MachineLimits::default().critical_segment_length();
    /// assert!((l - 7.607).abs() < 1e-3);
    /// ```
    #[must_use]
    pub fn critical_segment_length(&self) -> f64 {
        2.0 * (self.feed.powi(3) / self.jerk).sqrt()
    }

    /// Time (s) of one stop-to-stop linear move of length `length` (mm) with the
    /// configured [`KinematicModel`]; 0 for `length <= 0`.
    ///
    /// ```
    /// let m = scallop_analysis::MachineLimits::default();
    /// // Long pass (case 2): L/V + 2 sqrt(V/J).
    /// assert!((m.segment_time(28.0) - (28.0 / m.feed + 2.0 * m.time_to_feed())).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn segment_time(&self, length: f64) -> f64 {
        if length.is_nan() || length <= 0.0 {
            return 0.0;
        }
        match self.model {
            KinematicModel::SCurve => self.s_curve_time(length),
            KinematicModel::Thesis => self.thesis_time(length),
        }
    }

    /// Eqs. 1.13-1.15 with the thesis's case selection (7.1).
    fn thesis_time(&self, length: f64) -> f64 {
        let (v, a, j) = (self.feed, self.acceleration, self.jerk);
        let l = 0.5 * length;
        let (t_a, t_v, t_l) = (self.time_to_acceleration(), self.time_to_feed(), self.time_for_half_length(l));
        if t_a < t_v && t_a < t_l {
            2.0 * l / v + a / j + v / a // case 1 (1.13)
        } else if t_v <= t_l {
            2.0 * l / v + 2.0 * t_v // case 2 (1.14)
        } else {
            4.0 * t_l // case 3 (1.15)
        }
    }

    /// SEGMENT_TIME of 7.2: all four cases, continuous at every boundary.
    fn s_curve_time(&self, length: f64) -> f64 {
        let (v, a, j) = (self.feed, self.acceleration, self.jerk);
        let l = 0.5 * length;
        if v * j <= a * a {
            // A is never reached.
            return if l >= (v.powi(3) / j).sqrt() { 2.0 * l / v + 2.0 * (v / j).sqrt() } else { 4.0 * (l / j).cbrt() };
        }
        let l_a = a.powi(3) / (j * j); // half-length that just reaches A
        let l_va = v * (v / a + a / j) / 2.0; // half-length that just reaches V
        if l >= l_va {
            2.0 * l / v + a / j + v / a // case 1
        } else if l >= l_a {
            // case 4: A reached, V not; peak speed v_p solves l = v_p (v_p/A + A/J) / 2.
            let v_peak = (-a * a / j + (a.powi(4) / (j * j) + 8.0 * l * a).sqrt()) / 2.0;
            2.0 * (v_peak / a + a / j)
        } else {
            4.0 * (l / j).cbrt() // case 3
        }
    }
}
