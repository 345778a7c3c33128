//! Drop-cutter: the lowest tool-tip z at (x, y) where the cutter touches the
//! mesh and penetrates nothing.
//!
//! The result is the maximum, over every triangle within the cutter's disk,
//! of three contact candidates (after OpenCAMLib's design, re-derived here):
//! - [`vertex`]: a corner at horizontal distance rho <= R gives `z - h(rho)`;
//! - [`facet`]: the cutter's support point towards the triangle's plane, when it
//!   lies inside the triangle (exact predicate; the boundary is covered by the
//!   edge and vertex cases, so the interior test may be strict or closed);
//! - [`edge`]: the maximum of `z(x) - h(sqrt(x^2 + d^2))` along the edge, a
//!   concave function, solved per shape in closed form or by a safeguarded
//!   Newton iteration on a monotone function (bull-nose).
//!
//! Pruning: a contact on a triangle is never higher than the triangle's highest
//! corner, so a triangle (or a subtree of the index) whose highest z does not
//! exceed the best height found so far is skipped. Skipping cannot change the
//! maximum, so the indexed result equals [`drop_cutter_brute_force`] exactly.

mod edge;
mod facet;
mod vertex;

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use scallop_geom::{Point2, Point3, Vec3};
use scallop_mesh::MeshIndex;

use crate::Cutter;
use crate::shape::Profile;

/// Which feature of the mesh the cutter rests on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// Nothing under the cutter: the tip sits on the floor height.
    Floor,
    /// A triangle corner.
    Vertex {
        /// Triangle number in the source mesh.
        triangle: usize,
        /// Contact point on the mesh.
        point: Point3,
    },
    /// A triangle edge.
    Edge {
        /// Triangle number in the source mesh.
        triangle: usize,
        /// Contact point on the mesh.
        point: Point3,
    },
    /// The interior of a triangle.
    Facet {
        /// Triangle number in the source mesh.
        triangle: usize,
        /// Contact point on the mesh.
        point: Point3,
    },
}

/// A cutter location: the tool tip (lowest point of the cutter on its axis) and the contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClPoint {
    /// Tool tip (mm).
    pub tip: Point3,
    /// What the cutter touches.
    pub contact: Contact,
}

impl ClPoint {
    /// A point resting on the floor.
    #[must_use]
    pub fn floor(xy: Point2, floor: f64) -> ClPoint {
        ClPoint { tip: Point3::new(xy.x, xy.y, floor), contact: Contact::Floor }
    }
}

/// Raises `best` to the highest contact of `cutter` at `best.tip.xy` with one
/// triangle (`corners`, unit `normal` with z >= 0, number `triangle` for the
/// report). Only strictly higher candidates replace `best`.
pub fn drop_triangle(cutter: &Cutter, corners: &[Point3; 3], normal: &Vec3, triangle: usize, best: &mut ClPoint) {
    drop_triangle_profile(&Profile::new(cutter.shape()), corners, normal, triangle, best);
}

#[inline]
fn drop_triangle_profile(profile: &Profile, corners: &[Point3; 3], normal: &Vec3, triangle: usize, best: &mut ClPoint) {
    let c = Point2::new(best.tip.x, best.tip.y);
    vertex::drop_vertices(profile, corners, triangle, c, best);
    facet::drop_facet(profile, corners, normal, triangle, c, best);
    for k in 0..3 {
        let (a, b) = (&corners[k], &corners[(k + 1) % 3]);
        if a.z.max(b.z) > best.tip.z {
            edge::drop_edge(profile, a, b, triangle, c, best);
        }
    }
}

/// Drop-cutter at one point through the index. `floor` is the lowest tip
/// height returned (where nothing is under the cutter).
#[must_use]
pub fn drop_cutter(cutter: &Cutter, index: &MeshIndex, xy: Point2, floor: f64) -> ClPoint {
    drop_seeded(cutter, index, xy, floor, None).0
}

/// Drop-cutter that first tries the triangle in `seed` (typically the contact
/// of the neighbouring grid point): its contact is a valid lower bound that
/// lets the search prune from the start. Returns the slot of the contact.
fn drop_seeded(
    cutter: &Cutter,
    index: &MeshIndex,
    xy: Point2,
    floor: f64,
    seed: Option<usize>,
) -> (ClPoint, Option<usize>) {
    let profile = Profile::new(cutter.shape());
    let mut best = ClPoint::floor(xy, floor);
    let mut best_slot = None;
    if let Some(slot) = seed {
        drop_triangle_profile(&profile, index.corners(slot), index.normal(slot), index.original_index(slot), &mut best);
        if !matches!(best.contact, Contact::Floor) {
            best_slot = Some(slot);
        }
    }
    let mut bound = best.tip.z;
    index.visit_disk(
        xy,
        cutter.radius(),
        |d2| profile.height(d2.sqrt()),
        &mut bound,
        |slot, bound| {
            let before = best.tip.z;
            drop_triangle_profile(
                &profile,
                index.corners(slot),
                index.normal(slot),
                index.original_index(slot),
                &mut best,
            );
            if best.tip.z > before {
                best_slot = Some(slot);
            }
            *bound = best.tip.z;
        },
    );
    (best, best_slot)
}

/// The test oracle: every triangle, no index, no pruning.
#[must_use]
pub fn drop_cutter_brute_force(cutter: &Cutter, index: &MeshIndex, xy: Point2, floor: f64) -> ClPoint {
    let profile = Profile::new(cutter.shape());
    let mut best = ClPoint::floor(xy, floor);
    for slot in 0..index.len() {
        drop_triangle_profile(&profile, index.corners(slot), index.normal(slot), index.original_index(slot), &mut best);
    }
    best
}

/// Drop-cutter at many points, in parallel; the output is in input order and
/// does not depend on the number of threads.
#[must_use]
pub fn drop_points(cutter: &Cutter, index: &MeshIndex, points: &[Point2], floor: f64) -> Vec<ClPoint> {
    points.par_iter().with_min_len(256).map(|&p| drop_cutter(cutter, index, p, floor)).collect()
}

/// Drop-cutter on the grid `xs` x `ys`, row-major with x fastest, in parallel
/// over rows. `progress(rows_done)` is called after each row (from any thread).
#[must_use]
pub fn drop_grid(
    cutter: &Cutter,
    index: &MeshIndex,
    xs: &[f64],
    ys: &[f64],
    floor: f64,
    progress: &(dyn Fn(usize) + Sync),
) -> Vec<ClPoint> {
    let done = AtomicUsize::new(0);
    let rows: Vec<Vec<ClPoint>> = ys
        .par_iter()
        .map(|&y| {
            let mut seed = None;
            let row: Vec<ClPoint> = xs
                .iter()
                .map(|&x| {
                    let (cl, slot) = drop_seeded(cutter, index, Point2::new(x, y), floor, seed);
                    seed = slot;
                    cl
                })
                .collect();
            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
            row
        })
        .collect();
    rows.into_iter().flatten().collect()
}
