//! One channel of a compressor impeller: the open pocket between two twisted
//! blades over a revolved hub (a look-alike of the impeller of Jousselin 2020,
//! Ch. 1 section 3 and Ch. 4 section 2, whose CAD is not public).

use std::f64::consts::TAU;

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::{FaceTag, PartError, TestPart, build::Builder, check};

/// Parameters of [`impeller_channel`] (mm, radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpellerParams {
    /// Hub radius at the inlet and at the outlet.
    pub radii: [f64; 2],
    /// Hub height at the inlet and at the outlet.
    pub hub_z: [f64; 2],
    /// Blade height above the hub at the inlet and at the outlet.
    pub span: [f64; 2],
    /// Number of blades (the channel spans one pitch minus a blade).
    pub blades: usize,
    /// Blade thickness.
    pub thickness: f64,
    /// Angular wrap of the blades from inlet to outlet.
    pub wrap: f64,
    /// Twist: angular lean of the blade tip against its root.
    pub twist: f64,
    /// Sections along the channel, points across the hub and up a blade.
    pub samples: [usize; 3],
    /// Angle of blade a's root at the inlet (about +z from +x).
    pub phase: f64,
}

impl Default for ImpellerParams {
    fn default() -> Self {
        ImpellerParams {
            radii: [25.0, 75.0],
            hub_z: [40.0, 8.0],
            span: [28.0, 14.0],
            blades: 9,
            thickness: 3.0,
            wrap: 0.6,
            twist: 0.2,
            samples: [30, 10, 8],
            phase: -2.8,
        }
    }
}

impl ImpellerParams {
    fn validate(&self) -> Result<(), PartError> {
        check("radii[0]", self.radii[0], 1.0, 1e4, "a positive inlet radius")?;
        check("radii[1]", self.radii[1], self.radii[0] + 1.0, 1e4, "an outlet radius beyond the inlet")?;
        for (name, v) in [("hub_z[0]", self.hub_z[0]), ("hub_z[1]", self.hub_z[1])] {
            check(name, v, 0.0, 1e4, "a hub height of 0 to 10 m")?;
        }
        for (name, v) in [("span[0]", self.span[0]), ("span[1]", self.span[1])] {
            check(name, v, 1.0, 1e4, "a blade height of 1 mm to 10 m")?;
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let blades = self.blades as f64;
        check("blades", blades, 2.0, 100.0, "2 to 100 blades")?;
        let pitch = self.radii[0] * TAU / blades;
        check("thickness", self.thickness, 0.1, 0.8 * pitch, "a blade thinner than 80 % of the inlet pitch")?;
        check("wrap", self.wrap, -2.0, 2.0, "a wrap within +-2 rad")?;
        check("twist", self.twist, -0.5, 0.5, "a twist within +-0.5 rad")?;
        check("phase", self.phase, -TAU, TAU, "an angle within +-2 pi")?;
        for (k, &n) in self.samples.iter().enumerate() {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            check(["samples[0]", "samples[1]", "samples[2]"][k], n as f64, 2.0, 1000.0, "2 to 1000 samples")?;
        }
        Ok(())
    }

    /// Point of the channel's cross-section at `u` along the channel (0 inlet,
    /// 1 outlet), `w` across (0 on blade a, 1 on blade b) and `t` up the blades
    /// (0 hub, 1 tip).
    fn point(&self, u: f64, w: f64, t: f64) -> Point3 {
        let r = self.radii[0] + u * (self.radii[1] - self.radii[0]);
        let hub = self.hub_z[1] + (self.hub_z[0] - self.hub_z[1]) * (1.0 - u) * (1.0 - u);
        let span = self.span[0] + u * (self.span[1] - self.span[0]);
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let width = TAU / self.blades as f64 - self.thickness / r;
        let theta = self.phase + self.wrap * u * u + self.twist * t * (1.0 - 0.5 * u) + w * width;
        Point3::new(r * theta.cos(), r * theta.sin(), hub + t * span)
    }

    /// Height of the blade tips at `u` along the channel (the same across it).
    fn tip_z(&self, u: f64) -> f64 {
        let hub = self.hub_z[1] + (self.hub_z[0] - self.hub_z[1]) * (1.0 - u) * (1.0 - u);
        hub + self.span[0] + u * (self.span[1] - self.span[0])
    }

    /// The closed cross-section at `u`: across the hub, up blade b, back across
    /// the tip, down blade a; with the tag of the segment starting at each point.
    fn section(&self, u: f64) -> (Vec<Point3>, Vec<FaceTag>) {
        let [_, nw, nt] = self.samples;
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let (fw, ft) = (nw as f64, nt as f64);
        let mut pts = Vec::new();
        let mut tags = Vec::new();
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        for i in 0..nw {
            pts.push(self.point(u, i as f64 / fw, 0.0));
            tags.push(FaceTag::Bottom);
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        for i in 0..nt {
            pts.push(self.point(u, 1.0, i as f64 / ft));
            tags.push(FaceTag::Flank);
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        for i in 0..nw {
            pts.push(self.point(u, 1.0 - i as f64 / fw, 1.0));
            tags.push(FaceTag::Top);
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        for i in 0..nt {
            pts.push(self.point(u, 0.0, 1.0 - i as f64 / ft));
            tags.push(FaceTag::Flank);
        }
        (pts, tags)
    }
}

/// The channel between two blades: cross-sections lofted from the inlet to
/// the outlet, the hub tagged bottom, the blades flank, the tip surface top,
/// and the inlet and outlet sections (pieces of the cylinders at the inlet
/// and outlet radii) top too: the volume to remove is a closed solid, but its
/// bottom and flanks are an open pocket, open at the inlet and the outlet
/// (the planners close it by virtual surfaces). The stock is the box around the whole
/// impeller, 2 mm over the blades; the blank inside it ([`TestPart::blank`])
/// is turned to the envelope of the blade tips.
///
/// # Errors
/// [`PartError::BadParameter`] naming the parameter and its range.
pub fn impeller_channel(params: &ImpellerParams) -> Result<TestPart, PartError> {
    params.validate()?;
    let mut b = Builder::default();
    let n = params.samples[0];
    let mut sections = Vec::new();
    let mut tags = Vec::new();
    for k in 0..=n {
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let (pts, t) = params.section(k as f64 / n as f64);
        sections.push(b.ring(pts));
        tags = t;
    }
    for w in sections.windows(2) {
        b.band(&w[0], &w[1], true, |i| tags[i]);
    }
    // The inlet and outlet sections close the volume to remove (crossable, so
    // tagged top: the planners build their virtual flanks from the bottom and
    // the flanks alone), outward as the bands are: the hub faces down when
    // they are outward, and the whole mesh is flipped below when they are not.
    let outward = b.first_normal(FaceTag::Bottom).is_some_and(|n| n.z < 0.0);
    let sign = if outward { 1.0 } else { -1.0 };
    b.section_cap(&sections[0], |w, t| params.point(0.0, w, t), params.samples, -sign);
    b.section_cap(&sections[n], |w, t| params.point(1.0, w, t), params.samples, sign);
    let mut part = b.finish(Aabb3 { min: Point3::origin(), max: Point3::origin() })?;
    // Sections run counter-clockwise about the outflow: flip if the hub faces up.
    let hub = part.tags.iter().position(|&t| t == FaceTag::Bottom).unwrap_or(0);
    let [p, q, r] = part.mesh.triangle(hub);
    if (q - p).cross(&(r - p)).dot(&Vec3::z()) > 0.0 {
        let flipped: Vec<[usize; 3]> =
            part.mesh.triangles().iter().map(|t| [t[0] as usize, t[2] as usize, t[1] as usize]).collect();
        part.mesh = scallop_mesh::TriMesh::from_indexed(part.mesh.vertices(), &flipped)?.0;
    }
    let rmax = params.radii[1] + BLANK_MARGIN;
    let zmax = part.mesh.bounds().max.z + BLANK_MARGIN;
    part.stock = Aabb3 { min: Point3::new(-rmax, -rmax, 0.0), max: Point3::new(rmax, rmax, zmax) };
    part.blank = Some(turned_blank(params, zmax)?);
    Ok(part)
}

/// Room of the stock box over the blade tips and beyond the outlet (mm).
const BLANK_MARGIN: f64 = 2.0;

/// Segments of the blank's revolution (its chords lie within 0.003 mm of the
/// true surface at the outlet radius).
const BLANK_SEGMENTS: usize = 360;

/// The turned blank: the revolution about z of the blade tips' profile (at
/// most `top`) down to z = 0, and inside the inlet radius the nose at the
/// hub's inlet height (the impeller is turned to the envelope of its blade
/// tips and its nose before the channels are roughed, so nothing stands above
/// the channels' tops). Its outer radius is that of the outlet section's
/// deepest chords (across the hub and up the twisted blades) and its nose's radius that of the inlet beyond the blank's own
/// chords, so that no sliver between two tessellations lies outside the
/// channel at its open ends: a tool leaving the channel there cuts air, not a
/// gouge.
fn turned_blank(params: &ImpellerParams, top: f64) -> Result<scallop_mesh::TriMesh, PartError> {
    let [r0, r1] = params.radii;
    let u_of = |r: f64| (r - r0) / (r1 - r0);
    // The outlet section's triangles span at most one step across the hub
    // and one step of the twist up the blades; their chords dip to r1 times
    // the cosine of half that angle.
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let span = (TAU / params.blades as f64 - params.thickness / r1) / params.samples[1] as f64
        + (0.5 * params.twist).abs() / params.samples[2] as f64;
    let outer = r1 * (0.5 * span).cos();
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let nose = r0 / (std::f64::consts::PI / BLANK_SEGMENTS as f64).cos();
    let n = params.samples[0];
    // The profile (r, z) counter-clockwise in the half-plane r > 0, without its two points on the axis.
    let mut profile = vec![(outer, 0.0), (outer, params.tip_z(u_of(outer)).min(top))];
    for k in 1..n {
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let u = 1.0 - k as f64 / n as f64;
        let r = r0 + u * (r1 - r0);
        if r > nose && r < outer {
            profile.push((r, params.tip_z(u).min(top)));
        }
    }
    profile.push((nose, params.tip_z(u_of(nose)).min(top)));
    profile.push((nose, params.hub_z[0]));
    let mut b = Builder::default();
    let rings: Vec<Vec<usize>> = profile
        .iter()
        .map(|&(r, z)| {
            b.ring((0..BLANK_SEGMENTS).map(|i| {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let a = TAU * i as f64 / BLANK_SEGMENTS as f64;
                Point3::new(r * a.cos(), r * a.sin(), z)
            }))
        })
        .collect();
    b.fan(Point3::origin(), &rings[0], FaceTag::Top, &-Vec3::z());
    for (w, seg) in rings.windows(2).zip(profile.windows(2)) {
        // Outward normal of a counter-clockwise profile segment: (dz, -dr).
        let (dr, dz) = (seg[1].0 - seg[0].0, seg[1].1 - seg[0].1);
        b.band_towards(&w[0], &w[1], FaceTag::Top, |c| {
            let radial = Vec3::new(c.x, c.y, 0.0).normalize();
            dz * radial - dr * Vec3::z()
        });
    }
    let last = rings.last().map_or(&[][..], |r| &r[..]);
    b.fan(Point3::new(0.0, 0.0, params.hub_z[0]), last, FaceTag::Top, &Vec3::z());
    Ok(b.finish(Aabb3 { min: Point3::origin(), max: Point3::origin() })?.mesh)
}
