//! The contact check shared by the waterline tests: every loop vertex and
//! every chord's midpoint lies on the cutter's contact surface at z, so that a
//! cutter moving along a chord never cuts into the part. The oracle is the
//! brute-force drop-cutter `d(x, y)`; the cutter at tip height z cuts into the
//! part exactly where `d > z`.

use scallop_cutter::{Contact, Cutter, CutterShape, drop_cutter_brute_force};
use scallop_geom::{Point2, Point3, Vec2};
use scallop_mesh::MeshIndex;
use scallop_waterline::Loop;

/// Directions tried around a point when looking for the other side.
const RING: u32 = 32;

/// Points tried along the chord's normal when looking for the other side.
const LINE_STEPS: u32 = 64;

/// Height slack for the brute force against the indexed drop-cutter, relative
/// to the part's size.
const HEIGHT_SLACK: f64 = 1e-10;

/// Relative rounding at which the brute-force and the indexed drop-cutter may
/// disagree about a contact exactly on the cutter's rim (horizontal distance R).
const RIM_ROUNDING: f64 = 1e-12;

/// Checks, with the brute-force drop-cutter:
/// - every vertex is safe (`d <= z`) and within `vertex_reach` of a point
///   where the cutter cuts (`d > z`): it is on the contour;
/// - every chord's midpoint is on the contact surface: if it cuts (`d > z`),
///   a point within `chord_reach` does not (the chord enters the part by at
///   most `chord_reach` horizontally); if it is safe, a point within
///   `off_reach` cuts (the chord stays near the contour: material left, never
///   a gouge, so a looser bound).
///
/// Only the midpoint is checked here; [`check_chord_points`] checks the
/// quarter points of long chords, which the kernel's refinement checks too.
///
/// Returns the first violation found, described.
pub fn check_on_contact(
    cutter: &Cutter,
    index: &MeshIndex,
    loops: &[Loop],
    z: f64,
    vertex_reach: f64,
    chord_reach: f64,
    off_reach: f64,
) -> Result<(), String> {
    let o = Oracle::new(cutter, index, z);
    for (a, c) in chords(loops) {
        let dv = o.height(a).0;
        if !o.safe_at(a) {
            return Err(format!("vertex {a:?} cuts into the part: d = {dv}, z = {z}"));
        }
        let chord = c - a;
        let len = chord.norm();
        let left = if len > 0.0 { Vec2::new(-chord.y, chord.x) / len } else { Vec2::new(0.0, 0.0) };
        if !o.side_near(a, left, vertex_reach, true) {
            return Err(format!("vertex {a:?} is farther than {vertex_reach} from the contour (d = {dv}, z = {z})"));
        }
        if len == 0.0 {
            continue;
        }
        let mid = a + chord * 0.5;
        let dm = o.height(mid).0;
        let cuts = !o.safe_at(mid);
        let hint = if cuts { -left } else { left };
        let reach = if cuts { chord_reach } else { off_reach };
        if !o.side_near(mid, hint, reach, !cuts) {
            let what = if cuts { "cuts into the part" } else { "is off the contour" };
            return Err(format!(
                "midpoint {mid:?} of chord {a:?} -> {c:?} {what} by more than {reach} (d = {dm}, z = {z})"
            ));
        }
    }
    Ok(())
}

/// Checks, with the brute-force drop-cutter, that at the points `fractions`
/// along every chord longer than `min_length` a cutter never cuts into the
/// part by more than `chord_reach` horizontally: where it cuts (`d > z`), a
/// point within `chord_reach` outwards does not.
#[allow(dead_code, reason = "not every test crate checks long chords")]
pub fn check_chord_points(
    cutter: &Cutter,
    index: &MeshIndex,
    loops: &[Loop],
    z: f64,
    (fractions, min_length): (&[f64], f64),
    chord_reach: f64,
) -> Result<(), String> {
    let o = Oracle::new(cutter, index, z);
    for (a, c) in chords(loops) {
        let chord = c - a;
        let len = chord.norm();
        if len <= min_length {
            continue;
        }
        let left = Vec2::new(-chord.y, chord.x) / len;
        for &t in fractions {
            let q = a + chord * t;
            if !o.safe_at(q) && !o.side_near(q, -left, chord_reach, false) {
                return Err(format!(
                    "point {t} of chord {a:?} -> {c:?} (length {len}) cuts into the part by more than \
                         {chord_reach} (d = {}, z = {z})",
                    o.height(q).0
                ));
            }
        }
    }
    Ok(())
}

/// Every chord of the closed loops: each point and the next, the last
/// closing on the first.
fn chords(loops: &[Loop]) -> impl Iterator<Item = (Point2, Point2)> + '_ {
    loops.iter().flat_map(|l| {
        let n = l.points.len();
        (0..n).map(move |i| (l.points[i], l.points[(i + 1) % n]))
    })
}

/// The brute-force drop-cutter at one level.
struct Oracle<'a> {
    cutter: &'a Cutter,
    index: &'a MeshIndex,
    z: f64,
    floor: f64,
    slack: f64,
}

impl<'a> Oracle<'a> {
    fn new(cutter: &'a Cutter, index: &'a MeshIndex, z: f64) -> Oracle<'a> {
        let b = index.bounds();
        let slack = HEIGHT_SLACK * (1.0 + b.max.z.abs().max(b.min.z.abs()));
        Oracle { cutter, index, z, floor: b.min.z - 100.0, slack }
    }

    /// The brute-force height at q, and whether its contact is on the
    /// cutter's rim (where rounding may decide either way).
    fn height(&self, q: Point2) -> (f64, bool) {
        let cl = drop_cutter_brute_force(self.cutter, self.index, q, self.floor);
        let rim = match cl.contact {
            Contact::Floor => false,
            Contact::Vertex { point, .. } | Contact::Edge { point, .. } | Contact::Facet { point, .. } => {
                (point.x - q.x).hypot(point.y - q.y) >= self.cutter.radius() * (1.0 - RIM_ROUNDING)
            }
        };
        (cl.tip.z, rim)
    }

    fn cuts_at(&self, q: Point2) -> bool {
        self.height(q).0 > self.z
    }

    fn safe_at(&self, q: Point2) -> bool {
        let (h, rim) = self.height(q);
        h <= self.z + self.slack || rim
    }

    /// Is some point within r of q on the given side? Searched along the
    /// hinted direction in fine steps (a thin channel of the other side is
    /// found), then on a ring of radius r.
    fn side_near(&self, q: Point2, hint: Vec2, r: f64, want_cut: bool) -> bool {
        let on = |p: Point2| if want_cut { self.cuts_at(p) } else { self.safe_at(p) };
        (1..=LINE_STEPS).any(|k| on(q + hint * (r * f64::from(k) / f64::from(LINE_STEPS))))
            || (0..RING).any(|a| {
                let t = std::f64::consts::TAU * f64::from(a) / f64::from(RING);
                on(Point2::new(q.x + r * t.cos(), q.y + r * t.sin()))
            })
    }
}

/// The cutter of shape `kind` (flat, ball, bull-nose with corner 0.4 R, cone
/// of half-angle 0.6 rad, cycling) and `radius`.
pub fn shape_of(kind: u8, radius: f64) -> CutterShape {
    match kind % 4 {
        0 => CutterShape::Flat { radius },
        1 => CutterShape::Ball { radius },
        2 => CutterShape::Bull { radius, corner: 0.4 * radius },
        _ => CutterShape::Cone { radius, half_angle: 0.6 },
    }
}

/// The point (x, y, z) rotated by `angle` about the z axis.
#[allow(dead_code)] // not every test file builds boxes
pub fn rotated(angle: f64, x: f64, y: f64, z: f64) -> Point3 {
    let (s, c) = angle.sin_cos();
    Point3::new(c * x - s * y, s * x + c * y, z)
}

/// The top and four walls of the box [x0, x1] x [0, b] x [0, h], rotated.
#[allow(dead_code)] // not every test file builds boxes
pub fn box_soup(angle: f64, x0: f64, x1: f64, b: f64, h: f64) -> Vec<[Point3; 3]> {
    let p = |x, y, z| rotated(angle, x, y, z);
    let (t0, t1, t2, t3) = (p(x0, 0., h), p(x1, 0., h), p(x1, b, h), p(x0, b, h));
    let (b0, b1, b2, b3) = (p(x0, 0., 0.), p(x1, 0., 0.), p(x1, b, 0.), p(x0, b, 0.));
    vec![
        [t0, t1, t2],
        [t0, t2, t3],
        [b0, b1, t1],
        [b0, t1, t0],
        [b1, b2, t2],
        [b1, t2, t1],
        [b2, b3, t3],
        [b2, t3, t2],
        [b3, b0, t0],
        [b3, t0, t3],
    ]
}
