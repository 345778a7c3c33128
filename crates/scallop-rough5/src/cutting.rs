//! Cutting data of the roughing tool (Jousselin 2020, Ch. 2 §4 and Ch. 3
//! §2.3: FRAISA recommendations for aluminium in slotting conditions).

use crate::Rough5Error;

/// Teeth, feed per tooth and spindle speed; the feed follows from them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuttingData {
    /// Number of teeth z.
    pub teeth: u32,
    /// Feed per tooth f_z (mm).
    pub feed_per_tooth: f64,
    /// Spindle speed N (1/min).
    pub spindle: f64,
}

impl CuttingData {
    /// The thesis's cutting data: 2 teeth, f_z 0.08 mm, N 15 000 1/min.
    pub const THESIS: CuttingData = CuttingData { teeth: 2, feed_per_tooth: 0.08, spindle: 15_000.0 };

    /// The feed V_f = z f_z N (mm/min).
    ///
    /// ```
    /// let f = scallop_rough5::CuttingData::THESIS.feed().unwrap();
    /// assert!((f - 2400.0).abs() < 1e-9);
    /// ```
    ///
    /// # Errors
    /// [`Rough5Error::BadSetting`] when a value is not finite and positive.
    pub fn feed(&self) -> Result<f64, Rough5Error> {
        for (name, value) in
            [("teeth", f64::from(self.teeth)), ("feed_per_tooth", self.feed_per_tooth), ("spindle", self.spindle)]
        {
            if !(value.is_finite() && value > 0.0) {
                return Err(Rough5Error::BadSetting { name, value });
            }
        }
        Ok(f64::from(self.teeth) * self.feed_per_tooth * self.spindle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spec 12.1 item 1: V_f = z f_z N = 2 x 0.08 x 15 000 = 2 400 mm/min.
    #[test]
    fn feed_of_the_thesis_cutting_data_is_2400() {
        let f = CuttingData::THESIS.feed().unwrap();
        assert!((f - 2400.0).abs() <= 1e-6 * 2400.0, "{f}");
    }

    #[test]
    fn feed_is_linear_in_each_factor_and_refuses_bad_data() {
        let base = CuttingData::THESIS;
        let f0 = base.feed().unwrap();
        let double = |c: CuttingData| c.feed().unwrap() / f0;
        assert!((double(CuttingData { teeth: 4, ..base }) - 2.0).abs() < 1e-12);
        assert!((double(CuttingData { feed_per_tooth: 0.16, ..base }) - 2.0).abs() < 1e-12);
        assert!((double(CuttingData { spindle: 30_000.0, ..base }) - 2.0).abs() < 1e-12);
        assert!(CuttingData { teeth: 0, ..base }.feed().is_err());
        assert!(CuttingData { spindle: f64::NAN, ..base }.feed().is_err());
        assert!(CuttingData { feed_per_tooth: -0.1, ..base }.feed().is_err());
    }
}
