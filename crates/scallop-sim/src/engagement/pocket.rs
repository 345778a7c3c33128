//! [`Pocket`]: a 2D region (an outer ring, the pocket wall, and islands) whose
//! inside is the material of a 2.5D pocket.

use scallop_geom::{Aabb2, Point2};

use crate::SimError;

/// A pocket: closed rings of points (mm), the first the outer boundary (the
/// wall), the others islands. Inside is decided by the even-odd rule over all
/// rings, so the orientation of the rings does not matter.
#[derive(Debug, Clone, PartialEq)]
pub struct Pocket {
    rings: Vec<Vec<Point2>>,
}

/// The distance from `p` to the segment `a b`.
pub(crate) fn segment_distance(p: Point2, a: Point2, b: Point2) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&d) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + d * t)).norm()
}

impl Pocket {
    /// A pocket from its rings; a ring's closing point (equal to its first) is
    /// dropped.
    ///
    /// # Errors
    /// [`SimError::BadPocket`] when there is no ring, a ring has fewer than 3
    /// distinct points or a coordinate is not finite.
    pub fn new(rings: Vec<Vec<Point2>>) -> Result<Pocket, SimError> {
        if rings.is_empty() {
            return Err(SimError::BadPocket { ring: 0, why: "no ring: give the outer boundary first, then islands" });
        }
        let mut out = Vec::with_capacity(rings.len());
        for (k, mut ring) in rings.into_iter().enumerate() {
            if ring.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
                return Err(SimError::BadPocket { ring: k, why: "a coordinate is not a finite number" });
            }
            ring.dedup();
            if ring.len() > 1 && ring.first() == ring.last() {
                ring.pop();
            }
            if ring.len() < 3 {
                return Err(SimError::BadPocket { ring: k, why: "fewer than 3 distinct points" });
            }
            out.push(ring);
        }
        Ok(Pocket { rings: out })
    }

    /// The rings, outer boundary first (without closing points).
    #[must_use]
    pub fn rings(&self) -> &[Vec<Point2>] {
        &self.rings
    }

    /// The box of the outer ring and the islands.
    #[must_use]
    pub fn bounds(&self) -> Aabb2 {
        let mut min = self.rings[0][0];
        let mut max = min;
        for p in self.rings.iter().flatten() {
            min = Point2::new(min.x.min(p.x), min.y.min(p.y));
            max = Point2::new(max.x.max(p.x), max.y.max(p.y));
        }
        Aabb2 { min, max }
    }

    fn edges(&self) -> impl Iterator<Item = (Point2, Point2)> + '_ {
        self.rings.iter().flat_map(|ring| ring.iter().zip(ring.iter().cycle().skip(1)).map(|(a, b)| (*a, *b)))
    }

    /// The x where the rings cross the horizontal line at `y` (half-open
    /// rule on the edges' y ranges, so a vertex is counted once), unsorted.
    pub(crate) fn crossings(&self, y: f64) -> Vec<f64> {
        self.edges()
            .filter(|(a, b)| (a.y <= y) != (b.y <= y))
            .map(|(a, b)| a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y))
            .collect()
    }

    /// Whether `p` lies inside (even-odd rule).
    #[must_use]
    pub fn contains(&self, p: Point2) -> bool {
        self.crossings(p.y).iter().filter(|&&x| x > p.x).count() % 2 == 1
    }

    /// The distance from `p` to the nearest wall (outer ring or island).
    #[must_use]
    pub fn wall_distance(&self, p: Point2) -> f64 {
        self.edges().map(|(a, b)| segment_distance(p, a, b)).fold(f64::INFINITY, f64::min)
    }

    /// How deep a disc of `radius` centred at `p` reaches beyond the walls
    /// (mm; negative: the clearance left).
    #[must_use]
    pub fn penetration(&self, p: Point2, radius: f64) -> f64 {
        let d = self.wall_distance(p);
        if self.contains(p) { radius - d } else { radius + d }
    }
}
