//! The tool's body (flutes above the corner, shank, holder) against the
//! flank faces of the finished part: a placed tool whose body comes closer
//! to a flank than its radius would gouge the flank or collide with it.
//!
//! The body is a stack of solids of revolution of radius at most `rho` over
//! heights `[h0, h1]` above the tip. Points of the axis are sampled every
//! `delta` mm and each must be at least `rho + delta / 2` from the flank
//! mesh: the distance to a mesh is 1-Lipschitz and every axis point is within
//! `delta / 2` of a sample, so the check is conservative. The lower end of the
//! tool (below the corner height) lies inside the ball of radius R around the
//! axis point at the corner height, which the flute check covers.

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{MeshQuery, TriMesh};

use crate::tol;

/// The flank check of one tool.
#[derive(Debug, Clone)]
pub struct BodyCheck {
    query: MeshQuery,
    /// (h0, h1, radius) above the tip.
    pieces: Vec<(f64, f64, f64)>,
    /// Highest z of the flanks: samples whose ball is above it are skipped.
    top: f64,
    delta: f64,
    /// A mesh the shank and holder (not the flutes) must clear too, and its
    /// highest z ([`BodyCheck::with_stock`]).
    upper: Option<(MeshQuery, f64)>,
}

impl BodyCheck {
    /// The check of `cutter`'s body against `flanks`, keeping `clearance`
    /// (mm) between the flutes and the flanks.
    #[must_use]
    pub fn new(flanks: &TriMesh, cutter: &Cutter, clearance: f64) -> BodyCheck {
        let corner = match *cutter.shape() {
            CutterShape::Ball { radius } => radius,
            CutterShape::Bull { corner, .. } => corner,
            _ => 0.0,
        };
        let flutes = cutter.flute_length();
        let mut pieces = vec![(corner.min(flutes), flutes, cutter.radius() + clearance)];
        let shank_top = flutes + cutter.shank_length();
        pieces.push((flutes, shank_top, cutter.shank_radius()));
        let mut h = shank_top;
        for s in cutter.holder() {
            pieces.push((h, h + s.length, s.bottom_radius.max(s.top_radius)));
            h += s.length;
        }
        BodyCheck {
            query: MeshQuery::new(flanks),
            pieces,
            top: flanks.bounds().max.z,
            delta: tol::BODY_STEP,
            upper: None,
        }
    }

    /// This check with the shank and holder also kept their radius from
    /// `stock` (the surface of stock the flutes never cut: a blank beyond
    /// the pocket, where the neighbouring channels of an impeller stay full).
    #[must_use]
    pub fn with_stock(mut self, stock: &TriMesh) -> BodyCheck {
        let top = stock.bounds().max.z;
        self.upper = Some((MeshQuery::new(stock), top));
        self
    }

    /// The flank or stock point closest to the sample `p` of piece `piece`
    /// within `within`, when `p`'s ball of that radius reaches below their
    /// tops; `Err(())` when it is above both.
    fn nearest(&self, piece: usize, p: &Point3, within: f64) -> Result<Option<scallop_mesh::ClosestPoint>, ()> {
        let flank = (p.z - within <= self.top).then(|| self.query.closest_within(p, within)).flatten();
        let stock = match &self.upper {
            Some((q, top)) if piece > 0 && p.z - within <= *top => q.closest_within(p, within),
            _ => None,
        };
        let above = p.z - within > self.top && self.upper.as_ref().is_none_or(|u| piece == 0 || p.z - within > u.1);
        if above {
            return Err(());
        }
        Ok(match (flank, stock) {
            (Some(a), Some(b)) => Some(if b.distance < a.distance { b } else { a }),
            (a, b) => a.or(b),
        })
    }

    /// The deepest intrusion of the tool with its tip at `tip` and unit axis
    /// `axis` into the distance it must keep from the flanks: how much closer
    /// than needed its worst axis sample is (mm, positive), and the unit
    /// direction from the flank point closest to that sample to the sample
    /// (the flank normal N_f seen from the tool, Jousselin 2020, Ch. 3 §3,
    /// step 3, for a tool on the open side of the flank; zero when the sample
    /// is on the flank); `None` exactly when
    /// [`BodyCheck::collides`] is false.
    #[must_use]
    pub fn intrusion(&self, tip: &Point3, axis: &Vec3) -> Option<(f64, Vec3)> {
        let mut worst: Option<(f64, Vec3)> = None;
        for (piece, &(h0, h1, rho)) in self.pieces.iter().enumerate() {
            let n = ((h1 - h0) / self.delta).ceil().max(1.0) as usize;
            let need = rho + 0.5 * self.delta;
            for k in 0..=n {
                let h = h0 + (h1 - h0) * (k as f64 / n as f64);
                let p = tip + axis * h;
                let Ok(found) = self.nearest(piece, &p, need) else {
                    if axis.z > 0.0 {
                        break;
                    }
                    continue;
                };
                let Some(c) = found else { continue };
                let deficit = need - c.distance;
                if worst.is_none_or(|w| deficit > w.0) {
                    // A sample on the flank has no direction: zero.
                    let away = p - c.point;
                    let len = away.norm();
                    worst = Some((deficit, if len > 0.0 { away / len } else { Vec3::zeros() }));
                }
            }
        }
        worst
    }

    /// Whether the tool with its tip at `tip` and unit axis `axis` comes
    /// closer to the flanks than its radius (plus the clearance on the flutes).
    #[must_use]
    pub fn collides(&self, tip: &Point3, axis: &Vec3) -> bool {
        for (piece, &(h0, h1, rho)) in self.pieces.iter().enumerate() {
            let n = ((h1 - h0) / self.delta).ceil().max(1.0) as usize;
            let need = rho + 0.5 * self.delta;
            for k in 0..=n {
                let h = h0 + (h1 - h0) * (k as f64 / n as f64);
                let p = tip + axis * h;
                match self.nearest(piece, &p, need) {
                    Err(()) if axis.z > 0.0 => break,
                    Ok(Some(_)) => return true,
                    _ => {}
                }
            }
        }
        false
    }
}
