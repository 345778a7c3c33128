//! Cutting data of the roughing tool (Jousselin 2020, Ch. 2 §4 and Ch. 3
//! §2.3: FRAISA recommendations for aluminium in slotting conditions).

use scallop_cutter::{Cutter, CutterError, CutterShape, HolderSegment};

use crate::Rough5Error;

/// A torus end mill in a cylindrical holder: the tool of `scallop rough5`
/// and of its tests and examples (spec 9 of the thesis's pocket: the FRAISA
/// torus R 5 r 1.5 in a slender collet chuck 27 mm across and 192 mm long).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusTool {
    /// Torus radius R (mm).
    pub radius: f64,
    /// Corner radius r (mm).
    pub corner: f64,
    /// Flute length (mm).
    pub flutes: f64,
    /// Stick-out from the holder (mm): the flutes, then a shank of radius R.
    pub stick_out: f64,
    /// Holder diameter (mm).
    pub holder_diameter: f64,
    /// Holder length (mm).
    pub holder_length: f64,
}

impl TorusTool {
    /// The thesis's tool: R 5, r 1.5, 30 mm of flutes (not given in the
    /// thesis: they keep the shank above the 35 mm block), 41 mm out of a
    /// holder 27 mm across and 192 mm long.
    pub const THESIS: TorusTool = TorusTool {
        radius: 5.0,
        corner: 1.5,
        flutes: 30.0,
        stick_out: 41.0,
        holder_diameter: 27.0,
        holder_length: 192.0,
    };

    /// The cutter: the torus with its flutes, a shank of radius R up to the
    /// stick-out, and the holder.
    ///
    /// ```
    /// let tool = scallop_rough5::TorusTool::THESIS.cutter().unwrap();
    /// assert!((tool.radius() - 5.0).abs() < 1e-12);
    /// ```
    ///
    /// # Errors
    /// The cutter's error when a length is not positive or the stick-out is
    /// shorter than the flutes.
    pub fn cutter(&self) -> Result<Cutter, CutterError> {
        let holder = HolderSegment {
            length: self.holder_length,
            bottom_radius: self.holder_diameter / 2.0,
            top_radius: self.holder_diameter / 2.0,
        };
        Cutter::new(CutterShape::Bull { radius: self.radius, corner: self.corner }, self.flutes)?
            .with_shank(self.radius, self.stick_out - self.flutes)?
            .with_holder(vec![holder])
    }
}

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
