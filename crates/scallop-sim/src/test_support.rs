//! What the unit tests share: pseudo-random numbers (Knuth's MMIX linear
//! congruential generator, the same sequence on every platform) and one cutter
//! of every shape.

use scallop_cutter::CutterShape;

/// A seeded generator state.
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    /// 53 random bits in [0, 1).
    pub(crate) fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A number in [-1, 1).
    pub(crate) fn signed(&mut self) -> f64 {
        self.unit() * 2.0 - 1.0
    }
}

/// One cutter of every shape: flat, ball, bull-nose and cone of radius `radius`.
pub(crate) fn shapes(radius: f64, corner: f64, half_angle: f64) -> [CutterShape; 4] {
    [
        CutterShape::Flat { radius },
        CutterShape::Ball { radius },
        CutterShape::Bull { radius, corner },
        CutterShape::Cone { radius, half_angle },
    ]
}
