//! Limit curves C_n (Jousselin 2020, Ch. 2 §3.2.1, Fig. 2.28): the
//! intersection of a level mesh with the offset of the flanks at R + s_f,
//! chained into polylines by [`scallop_mesh::intersect_meshes`], closed loops
//! turned so that their inside is on their left about the level's normals.

use scallop_mesh::{TriMesh, intersect_meshes};

use crate::support::{Curve, Support};

/// The limit curves of one level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LimitCurves {
    /// Closed loops, inside on the left (several loops: several pockets).
    pub loops: Vec<Curve>,
    /// Open chains: the intersection reaches the level's boundary (an open
    /// pocket, to be closed by virtual flanks, Jousselin 2020, Ch. 4 §1.3.1).
    pub open: Vec<Curve>,
    /// Loops lying inside another loop (islands: outside the method's scope,
    /// reported, not processed).
    pub nested: usize,
    /// How many of [`LimitCurves::loops`] were made by closing the open
    /// chains along the level's edge (the virtual crossable flanks of an open
    /// pocket, Jousselin 2020, Ch. 4 §1.3.1; the chains stay in
    /// [`LimitCurves::open`]). Set by [`crate::build_guides`].
    pub closed_by_virtual_flanks: usize,
}

/// The limit curves where `flank_offset` (the pocket-side sheet of the flank
/// offset) meets `level`.
#[must_use]
pub fn limit_curves(level: &Support, flank_offset: &TriMesh) -> LimitCurves {
    let x = intersect_meshes(level.mesh(), flank_offset);
    let mut out = LimitCurves::default();
    for line in x.chains {
        if line.points.len() < 2 {
            continue;
        }
        let Ok(curve) = level.curve(line) else { continue };
        if curve.line.closed {
            out.loops.push(curve.inside_left());
        } else {
            out.open.push(curve);
        }
    }
    out.nested = nested_count(&out.loops);
    out
}

/// Loops with a point inside another loop (by the sign of the signed
/// distance to that loop alone).
fn nested_count(loops: &[Curve]) -> usize {
    let fields: Vec<crate::CurveField> =
        loops.iter().map(|l| crate::CurveField::new(std::slice::from_ref(l))).collect();
    loops
        .iter()
        .enumerate()
        .filter(|(i, l)| fields.iter().enumerate().any(|(j, f)| j != *i && f.signed(&l.line.points[0]) > 0.0))
        .count()
}
