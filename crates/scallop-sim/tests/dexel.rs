//! The tri-dexel stock: agreement with the z-map for vertical tools, analytic
//! sections and volumes of tilted cuts, sphere invariance, undercuts, gouges
//! of a lowered 3+2 path, sub-stepped 5-axis moves, collisions and determinism.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape, HolderSegment};
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_sim::{
    DexelOptions, DexelPart, DexelStock, SimError, ToolMove, ToolPart, VerifyOptions, ZMap, simulate_dexel,
    verify_dexel,
};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

fn mv(kind: MoveKind, tip: Point3, axis: Vec3) -> ToolMove {
    ToolMove::new(kind, tip, axis)
}

/// Axis tilted by `tilt` from +Z towards the azimuth `phi`.
fn tilted(tilt: f64, phi: f64) -> Vec3 {
    Vec3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos())
}

/// A closed box mesh (12 triangles).
fn block(lo: Point3, hi: Point3) -> TriMesh {
    let c = |i: u8| {
        p(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let mut soup = Vec::new();
    for q in quads {
        soup.push([c(q[0]), c(q[1]), c(q[2])]);
        soup.push([c(q[0]), c(q[2]), c(q[3])]);
    }
    TriMesh::from_soup(&soup).unwrap().0
}

fn shapes() -> [CutterShape; 4] {
    [
        CutterShape::Flat { radius: 2.0 },
        CutterShape::Ball { radius: 2.0 },
        CutterShape::Bull { radius: 2.0, corner: 0.6 },
        CutterShape::Cone { radius: 2.0, half_angle: 0.7 },
    ]
}

/// A vertical tool cuts the same as the z-map: the top of each Z ray equals
/// the z-map cell height, bit for bit (the Z rays of a +Z axis use the
/// z-map's closed forms; the general sweep is checked against them in the
/// crate's unit tests).
#[test]
fn vertical_tools_match_the_zmap() {
    let stock = Aabb3 { min: p(0.0, 0.0, -4.0), max: p(12.0, 10.0, 0.0) };
    for shape in shapes() {
        // Flutes longer than the stock is deep: the z-map removes whole columns.
        let cutter = Cutter::new(shape, 10.0).unwrap();
        let mut path = Toolpath::new(1000.0);
        path.push(Move::new(MoveKind::Rapid, p(-3.0, 2.0, 5.0)));
        path.push(Move::new(MoveKind::Plunge, p(-3.0, 2.0, -1.0)));
        path.push(Move::new(MoveKind::Feed, p(15.0, 3.1, -2.2))); // descending diagonal
        path.push(Move::new(MoveKind::Feed, p(7.3, 8.4, -0.4))); // ascending
        path.push(Move::new(MoveKind::Feed, p(7.3, 8.4, -3.0))); // plunge
        path.push(Move::new(MoveKind::Feed, p(2.0, 6.0, -1.7)));
        path.push(Move::new(MoveKind::Retract, p(2.0, 6.0, 5.0)));
        let mut zmap = ZMap::new(stock, 0.2).unwrap();
        let zr = zmap.cut(&cutter, &path).unwrap();
        let mut dexels = DexelStock::new(stock, 0.2).unwrap();
        let dr = dexels.cut(&cutter, &ToolMove::from_toolpath(&path), &DexelOptions::default()).unwrap();
        dr.check().unwrap();
        let top = dexels.top_heights();
        assert_eq!(top.len(), zmap.heights().len());
        for (k, (a, b)) in top.iter().zip(zmap.heights()).enumerate() {
            // The Z rays of a vertical tool use the z-map's closed forms: the same bits.
            assert_eq!(a.to_bits(), b.to_bits(), "{shape:?} cell {k}: dexel {a} zmap {b}");
        }
        assert!((dr.removed_volume - zr.removed_volume).abs() <= 1e-6 * zr.removed_volume, "{shape:?}");
        // Below the top every Z ray is one solid interval (no undercut from a vertical tool).
        for j in 0..dexels.grid(2).1 {
            for i in 0..dexels.grid(2).0 {
                assert!(dexels.intervals(2, i, j).len() <= 1);
            }
        }
    }
}

/// A flat end mill tilted 30 degrees about X moving along X leaves a slot
/// whose section (away from the move's ends) is the tilted rectangle: width
/// 2R across the axis, the axis direction along its sides.
#[test]
fn tilted_flat_cuts_the_analytic_slot() {
    let (r, l) = (2.0, 8.0);
    let stock = Aabb3 { min: p(0.0, 0.0, -6.0), max: p(20.0, 12.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Flat { radius: r }, l).unwrap();
    let tilt = 30f64.to_radians();
    let a = tilted(tilt, -std::f64::consts::FRAC_PI_2); // (0, -sin, cos)
    let b = Vec3::new(0.0, tilt.cos(), tilt.sin()); // across the axis, in the YZ plane
    let tip = p(0.0, 7.0, -3.0);
    let path = [mv(MoveKind::Rapid, p(-8.0, tip.y, tip.z), a), mv(MoveKind::Feed, p(28.0, tip.y, tip.z), a)];
    let mut dexels = DexelStock::new(stock, 0.1).unwrap();
    let report =
        dexels.cut(&cutter, &path, &DexelOptions { check_collisions: false, ..DexelOptions::default() }).unwrap();
    assert_eq!(report.rapid_hits.len(), 0);
    // Inside the section: 0 <= (q - tip) . a <= L and |(q - tip) . b| <= R (q in the YZ plane).
    let inside = |y: f64, z: f64| {
        let q = Vec3::new(0.0, y - tip.y, z - tip.z);
        let h = q.dot(&a);
        (0.0..=l).contains(&h) && q.dot(&b).abs() <= r
    };
    // Y rays (u = z, v = x) at x = 10: removed exactly where the section is.
    let (nz, nx) = dexels.grid(1);
    let ix = nx / 2;
    for iz in 0..nz {
        let o = dexels.ray_origin(1, iz, ix);
        let z = o.z;
        // The section's y range at height z: four linear conditions.
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let dz = z - tip.z;
        for (coef, c0, lo_v, hi_v) in [(a.y, a.z * dz, 0.0, l), (b.y, b.z * dz, -r, r)] {
            // lo_v <= coef (y - tip.y) + c0 <= hi_v
            let (p0, p1) = ((lo_v - c0) / coef, (hi_v - c0) / coef);
            lo = lo.max(p0.min(p1));
            hi = hi.min(p0.max(p1));
        }
        let (lo, hi) = ((lo + tip.y).max(0.0), (hi + tip.y).min(12.0));
        let got = dexels.intervals(1, iz, ix);
        let mut want = Vec::new();
        if lo > 0.0 {
            want.push([0.0, lo.min(12.0)]);
        }
        if hi < 12.0 {
            want.push([hi.max(0.0), 12.0]);
        }
        if lo >= hi {
            want = vec![[0.0, 12.0]];
        }
        assert_eq!(got.len(), want.len(), "z {z}: {got:?} vs {want:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!((g[0] - w[0]).abs() < 1e-9 && (g[1] - w[1]).abs() < 1e-9, "z {z}: {got:?} vs {want:?}");
        }
    }
    // X rays (u = y, v = z): empty over the middle of the stock exactly when
    // their (y, z) lies in the section.
    let (ny, nz) = dexels.grid(0);
    for iz in 0..nz {
        for iy in 0..ny {
            let o = dexels.ray_origin(0, iy, iz);
            let iv = dexels.intervals(0, iy, iz);
            let middle_empty = !iv.iter().any(|s| s[0] < 12.0 && s[1] > 8.0);
            assert_eq!(middle_empty, inside(o.y, o.z), "X ray at y {} z {}: {iv:?}", o.y, o.z);
        }
    }
}

/// A ball cutter removes the same wherever its axis points, as long as only
/// the ball touches the stock: the sphere of centre `tip + R a` is the same.
#[test]
fn ball_is_invariant_under_tilt_examples() {
    ball_invariance(0.7, 2.1, (1.0, 2.0), (9.0, 7.0), 0.4);
}

fn ball_invariance(tilt: f64, phi: f64, from: (f64, f64), to: (f64, f64), depth: f64) {
    let rr = 2.0;
    let stock = Aabb3 { min: p(0.0, 0.0, -3.0), max: p(10.0, 9.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Ball { radius: rr }, 6.0).unwrap();
    // Centres at z = R - depth: the cylinder above the ball stays above
    // z = R - depth - R sin(tilt) >= 0 (the stock top) for tilts up to 45 deg.
    let cz = rr - depth;
    let run = |a: Vec3| {
        let tip = |x: f64, y: f64| p(x, y, cz) - rr * a;
        let path = [
            mv(MoveKind::Plunge, tip(from.0, from.1), a),
            mv(MoveKind::Feed, tip(to.0, to.1), a),
            mv(MoveKind::Feed, tip(to.0, from.1), a),
        ];
        let mut d = DexelStock::new(stock, 0.25).unwrap();
        d.cut(&cutter, &path, &DexelOptions { check_collisions: false, ..DexelOptions::default() }).unwrap();
        d
    };
    let (up, tilted_stock) = (run(Vec3::z()), run(tilted(tilt, phi)));
    for axis in 0..3 {
        let (nu, nv) = up.grid(axis);
        for iv in 0..nv {
            for iu in 0..nu {
                let (x, y) = (up.intervals(axis, iu, iv), tilted_stock.intervals(axis, iu, iv));
                assert_eq!(x.len(), y.len(), "axis {axis} ray ({iu}, {iv}): {x:?} vs {y:?}");
                for (s, t) in x.iter().zip(&y) {
                    assert!((s[0] - t[0]).abs() < 1e-7 && (s[1] - t[1]).abs() < 1e-7, "{x:?} vs {y:?}");
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]
    #[test]
    fn ball_is_invariant_under_tilt(
        tilt in 0.0f64..0.785,
        phi in 0.0f64..std::f64::consts::TAU,
        x0 in 0.0f64..10.0, y0 in 0.0f64..9.0, x1 in 0.0f64..10.0, y1 in 0.0f64..9.0,
        depth in 0.05f64..0.58,
    ) {
        ball_invariance(tilt, phi, (x0, y0), (x1, y1), depth);
    }
}

/// A horizontal tool reaching under an overhang leaves material above and
/// below the slot on the same vertical line: two intervals on a Z ray, which a
/// height field cannot hold.
#[test]
fn undercut_keeps_the_overhang() {
    let (r, l) = (1.5, 6.0);
    let stock = Aabb3 { min: p(0.0, 0.0, 0.0), max: p(10.0, 10.0, 10.0) };
    let cutter = Cutter::new(CutterShape::Flat { radius: r }, l).unwrap();
    // Axis +X: the tool comes from the +X side, its tip at x = 6.
    let a = Vec3::x();
    let path = [
        mv(MoveKind::Rapid, p(6.0, -5.0, 3.0), a),
        mv(MoveKind::Feed, p(6.0, 15.0, 3.0), a),
        mv(MoveKind::Rapid, p(20.0, 15.0, 3.0), a),
    ];
    let mut dexels = DexelStock::new(stock, 0.25).unwrap();
    let report =
        dexels.cut(&cutter, &path, &DexelOptions { check_collisions: false, ..DexelOptions::default() }).unwrap();
    report.check().unwrap();
    // Z rays with 6 < x (< 6 + L) through the slot: [0, 3 - r] and [3 + r, 10].
    let (nx, ny) = dexels.grid(2);
    let mut undercut_rays = 0;
    for j in 0..ny {
        for i in 0..nx {
            let o = dexels.ray_origin(2, i, j);
            let iv = dexels.intervals(2, i, j);
            if o.x > 6.0 {
                assert_eq!(iv.len(), 2, "ray at x {}: {iv:?}", o.x);
                assert!((iv[0][1] - (3.0 - r)).abs() < 1e-9 && (iv[1][0] - (3.0 + r)).abs() < 1e-9);
                assert_eq!(iv[1][1], 10.0);
                undercut_rays += 1;
            } else {
                assert_eq!(iv, vec![[0.0, 10.0]]);
            }
        }
    }
    assert!(undercut_rays > 0);
    // The removed volume is the slot: 2 r x 4 x 10 mm (the flat face at x = 6
    // sweeps a plane), measured on Z rays and on X rays alike.
    let slot = 2.0 * r * 4.0 * 10.0;
    let removed_z = dexels.initial_volume() - dexels.volume_along(2);
    let removed_x = dexels.initial_volume() - dexels.volume_along(0);
    assert!((removed_z - slot).abs() < 1e-9, "{removed_z}");
    assert!((removed_x - slot).abs() < 1e-9, "{removed_x}");
}

/// The volume of a straight flat move inside the stock is
/// `(2 R L + pi R^2) D` up to the grid's sampling of the footprint: cells
/// whose centre and area disagree lie within half a cell diagonal `rho` of
/// the footprint's edge, a band of area at most `2 rho P + pi rho^2` for a
/// convex footprint of perimeter `P`.
#[test]
fn straight_flat_move_removes_the_swept_volume() {
    let (r, len, depth) = (2.5, 11.0, 1.3);
    let stock = Aabb3 { min: p(0.0, 0.0, -5.0), max: p(20.0, 12.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Flat { radius: r }, 10.0).unwrap();
    for res in [0.4, 0.2, 0.1] {
        let mut dexels = DexelStock::new(stock, res).unwrap();
        let (x0, y0) = (4.3, 2.7);
        let path = [
            mv(MoveKind::Plunge, p(x0, y0, -depth), Vec3::z()),
            mv(MoveKind::Feed, p(x0 + len * 0.8, y0 + len * 0.6, -depth), Vec3::z()),
        ];
        let report = dexels.cut(&cutter, &path, &DexelOptions::default()).unwrap();
        let exact = (2.0 * r * len + std::f64::consts::PI * r * r) * depth;
        let [cx, cy, _] = dexels.cell_size();
        let rho = 0.5 * cx.hypot(cy);
        let perimeter = 2.0 * len + std::f64::consts::TAU * r;
        let bound = (2.0 * rho * perimeter + std::f64::consts::PI * rho * rho) * depth;
        assert!((report.removed_volume - exact).abs() <= bound, "res {res}: {} vs {exact}", report.removed_volume);
        // The X and Y rays measure the same solid; their cells straddle the
        // footprint's edge and the floor, half a cell of z at most over the footprint.
        for axis in 0..2 {
            let removed = dexels.initial_volume() - dexels.volume_along(axis);
            assert!((removed - exact).abs() <= bound + 0.5 * res * exact / depth, "axis {axis} res {res}: {removed}");
        }
    }
}

/// A 3+2 finishing path with a tilted ball over the top face of a block
/// leaves the theoretical scallop and no gouge; the same path with one pass
/// lowered by 0.05 mm is a gouge named at that pass.
#[test]
fn lowered_3_plus_2_pass_is_a_gouge_at_that_move() {
    let rr = 2.0;
    let part = DexelPart::new(&block(p(-1.0, -1.0, -4.0), p(11.0, 11.0, 0.0)));
    assert!(part.is_closed());
    let stock = Aabb3 { min: p(0.0, 0.0, -3.0), max: p(10.0, 10.0, 0.5) };
    let cutter = Cutter::new(CutterShape::Ball { radius: rr }, 8.0).unwrap();
    let a = tilted(20f64.to_radians(), 0.3);
    let step = 0.8;
    let passes = 15;
    let path = |lowered: Option<usize>| {
        let mut moves = vec![mv(MoveKind::Rapid, p(-4.0, -1.0, 8.0), a)];
        for k in 0..passes {
            let y = -1.0 + step * k as f64;
            let dz = if lowered == Some(k) { 0.05 } else { 0.0 };
            // Sphere centre R above the plane z = 0.
            let tip = |x: f64| p(x, y, rr - dz) - rr * a;
            let (x0, x1) = if k % 2 == 0 { (-4.0, 14.0) } else { (14.0, -4.0) };
            moves.push(mv(MoveKind::Plunge, tip(x0), a));
            moves.push(mv(MoveKind::Feed, tip(x1), a));
        }
        moves
    };
    let opts = VerifyOptions { gouge_tolerance: 0.001, ..VerifyOptions::default() };
    let sim = simulate_dexel(stock, 0.1, &cutter, &path(None), &part, &DexelOptions::default(), &opts).unwrap();
    // Scallop between passes 0.8 apart, measured on the Z rays (the plane is
    // horizontal: vertical = normal), within the grid's bound at the cusp.
    let theory = rr - (rr * rr - 0.25 * step * step).sqrt();
    let v = sim.verification;
    assert!(v.max_thickness <= theory + 1e-9, "{} vs {theory}", v.max_thickness);
    assert!(v.max_thickness >= theory - 0.21 * 0.0708, "{} vs {theory}", v.max_thickness);
    // The stock above the part everywhere: no negative deviation.
    assert!(v.min_deviation >= -1e-9);
    let lowered = 7;
    let err =
        simulate_dexel(stock, 0.1, &cutter, &path(Some(lowered)), &part, &DexelOptions::default(), &opts).unwrap_err();
    let SimError::DexelGouge { worst, .. } = err else { panic!("expected a gouge, got {err:?}") };
    // Move of the lowered feed: 1 rapid + 2 moves per pass (plunge, feed).
    let feed_index = 1 + 2 * lowered + 1;
    let depth = worst[0].depth;
    assert!((depth - 0.05).abs() < 0.005, "depth {depth}");
    // The plunges start and end beyond the block (x = -4 or 14): the feed cut it.
    assert!(worst.iter().all(|g| g.cut_by.is_some_and(|m| m.index as usize == feed_index)), "{worst:?}");
    assert!((worst[0].at.y - (-1.0 + step * lowered as f64)).abs() < rr);
}

/// Distance from `q` to a flat end mill (radius `r`, flutes `l`) with its tip at `tip` and axis `a`.
fn flat_distance(q: &Point3, tip: &Point3, a: &Vec3, r: f64, l: f64) -> f64 {
    let w = q - tip;
    let h = w.dot(a);
    let rho = (w - h * a).norm();
    let dh = (-h).max(h - l).max(0.0);
    (rho - r).max(0.0).hypot(dh)
}

/// Simultaneous 5-axis: a flat end mill turning by 57 degrees while it
/// moves. Every point where the simulated stock was cut back to (an interval
/// end inside the stock box) lies on the simulated swept solid, so within the
/// stated bound `l dtheta / 2 <= axis_tolerance` of the true swept solid: its
/// distance to the tool at the nearest of 20,000 true poses along the move is
/// at most the tolerance plus the sampling's own gap. The volumes at two
/// tolerances differ by at most the swept surface's area times the tolerances.
#[test]
fn five_axis_sub_steps_stay_within_the_bound() {
    let (r, l) = (2.0, 6.0);
    let stock = Aabb3 { min: p(0.0, 0.0, -4.0), max: p(16.0, 10.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Flat { radius: r }, l).unwrap();
    let (p0, p1) = (p(2.0, 5.0, -1.5), p(14.0, 5.0, -1.0));
    let (a0, a1) = (tilted(-0.4, 0.0), tilted(0.6, 0.0));
    let path = [mv(MoveKind::Plunge, p0, a0), mv(MoveKind::Feed, p1, a1)];
    let run = |tol: f64| {
        let mut d = DexelStock::new(stock, 0.25).unwrap();
        let rep = d
            .cut(&cutter, &path, &DexelOptions { axis_tolerance: tol, check_collisions: false, max_stick_out: None })
            .unwrap();
        (d, rep)
    };
    let tol = 0.02;
    let (coarse, rc) = run(tol);
    let (fine, rf) = run(0.0005);
    let theta = 1.0f64;
    let reach = l.hypot(r);
    assert_eq!(rc.sweeps, 1 + (theta / (2.0 * tol / reach)).ceil() as usize);
    assert!(rf.sweeps > rc.sweeps);
    // The true poses: tip on the segment, axis on the great circle (a turn about Y).
    let n = 20_000;
    let poses: Vec<(Point3, Vec3)> = (0..=n)
        .map(|i| {
            let t = f64::from(i) / f64::from(n);
            (p0 + t * (p1 - p0), tilted(-0.4 + t * theta, 0.0))
        })
        .collect();
    // Between two samples a tool point moves at most this far.
    let gap = ((p1 - p0).norm() + reach * theta) / f64::from(n);
    let mut checked = 0;
    for axis in 0..3 {
        let (nu, nv) = coarse.grid(axis);
        let (lo, hi) = (stock.min[axis], stock.max[axis]);
        for iv in 0..nv {
            for iu in 0..nu {
                for s in coarse.intervals(axis, iu, iv) {
                    for end in s {
                        if end <= lo || end >= hi {
                            continue;
                        }
                        let mut q = coarse.ray_origin(axis, iu, iv);
                        q[axis] = end;
                        let dist =
                            poses.iter().map(|(tip, a)| flat_distance(&q, tip, a, r, l)).fold(f64::INFINITY, f64::min);
                        assert!(dist <= tol + gap + 1e-9, "axis {axis} point {q:?}: {dist} from the true sweep");
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 1000, "{checked}");
    // Volumes: the swept surface's area, generously (side and ends of the tool over the move).
    let area = (2.0 * r + std::f64::consts::TAU * r) * (p1 - p0).norm() * 2.0 + std::f64::consts::TAU * r * l * 2.0;
    let dv = (coarse.volume() - fine.volume()).abs();
    assert!(dv <= area * (tol + 0.0005), "{dv}");
}

/// The shank of a tilted tool dragged through the stock is a collision, and
/// the message names the move.
#[test]
fn shank_in_the_stock_is_a_collision() {
    let stock = Aabb3 { min: p(0.0, 0.0, -10.0), max: p(20.0, 10.0, 0.0) };
    // Short flutes (3 mm), shank radius 3.
    let cutter = Cutter::new(CutterShape::Flat { radius: 2.0 }, 3.0).unwrap().with_shank(3.0, 20.0).unwrap();
    let a = tilted(0.5, 1.0);
    let path = [mv(MoveKind::Plunge, p(-5.0, 5.0, -6.0), a), mv(MoveKind::Feed, p(25.0, 5.0, -6.0), a)];
    let mut d = DexelStock::new(stock, 0.25).unwrap();
    let report = d.cut(&cutter, &path, &DexelOptions::default()).unwrap();
    let err = report.check().unwrap_err();
    assert!(matches!(&err, SimError::DexelCollision { collisions, .. } if collisions[0].id.index == 1), "{err}");
    assert!(err.to_string().contains("move 1 of operation 0"), "{err}");
    // Deep enough flutes: no collision.
    let long = Cutter::new(CutterShape::Flat { radius: 2.0 }, 12.0).unwrap();
    let mut d = DexelStock::new(stock, 0.25).unwrap();
    d.cut(&long, &path, &DexelOptions::default()).unwrap().check().unwrap();
    // A wide holder above a short shank, tilted towards +X: its rim dips to
    // z = -6 + 14 cos(0.5) - 20 sin(0.5) = -3.3 ahead of the tool, inside the stock.
    let holder = HolderSegment { length: 5.0, bottom_radius: 20.0, top_radius: 20.0 };
    let held = long.with_shank(2.0, 2.0).unwrap().with_holder(vec![holder]).unwrap();
    let a = tilted(0.5, 0.0);
    let path = [mv(MoveKind::Plunge, p(-5.0, 5.0, -6.0), a), mv(MoveKind::Feed, p(25.0, 5.0, -6.0), a)];
    let mut d = DexelStock::new(stock, 0.25).unwrap();
    let report = d.cut(&held, &path, &DexelOptions::default()).unwrap();
    assert!(
        report.collisions.iter().any(|c| c.part == ToolPart::Holder(0) && c.id.index == 1),
        "{:?}",
        report.collisions
    );
    assert!(report.collisions.iter().all(|c| c.part != ToolPart::Shank));
    let deepest = report.collisions.iter().map(|c| c.depth).fold(0.0, f64::max);
    assert!(deepest > 1.0, "{deepest}");
}

/// A tilted tool whose holder reaches over a post of the part standing
/// outside the stock box: a collision with the part (not the stock, which
/// the holder never reaches), named by move; none with a smaller holder.
#[test]
fn holder_on_a_part_feature_outside_the_stock_is_a_collision() {
    // The part: a base slab inside the stock and a post at x in [16, 20],
    // beyond the stock's end at x = 10.
    let mut soup = Vec::new();
    for mesh in [block(p(-1.0, -1.0, -5.0), p(11.0, 11.0, -2.0)), block(p(16.0, 3.0, -5.0), p(20.0, 7.0, 10.0))] {
        for t in mesh.triangles() {
            soup.push(t.map(|i| mesh.vertices()[i as usize]));
        }
    }
    let part = DexelPart::new(&TriMesh::from_soup(&soup).unwrap().0);
    assert!(part.is_closed());
    let stock = Aabb3 { min: p(0.0, 0.0, -5.0), max: p(10.0, 10.0, 0.0) };
    // Ball R 1, 6 mm of flutes, shank R 1 over 4 mm, holder R 6 over 10 mm
    // from 10 mm up the axis; tilted 30 degrees towards +X. At a tip x the
    // holder's lower rim reaches x + 5 + 6 cos 30 = x + 10.2 at z tip + 5.66.
    let holder = |r: f64, length: f64| HolderSegment { length, bottom_radius: r, top_radius: r };
    let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 6.0).unwrap().with_shank(1.0, 4.0).unwrap();
    let a = tilted(std::f64::consts::FRAC_PI_6, 0.0);
    let path = [
        mv(MoveKind::Rapid, p(2.0, 5.0, 3.0), a),
        mv(MoveKind::Plunge, p(2.0, 5.0, -1.5), a),
        mv(MoveKind::Feed, p(8.0, 5.0, -1.5), a),
        // Up at feed: a tilted tool rising along Z shaves rounding-sized
        // slivers off the walls it cut, which a retract would report.
        mv(MoveKind::Feed, p(8.0, 5.0, 3.0), a),
    ];
    let options = DexelOptions::default();
    let wide = ball.clone().with_holder(vec![holder(6.0, 10.0)]).unwrap();
    let mut d = DexelStock::new(stock, 0.25).unwrap();
    let report = d.cut(&wide, &path, &options).unwrap();
    // The stock alone is safe: the holder stays above it.
    report.check().unwrap();
    let hits = d.part_collisions(&part, &wide, &path, &options, report.operation).unwrap();
    let moves: Vec<u32> = hits.iter().map(|c| c.id.index).collect();
    assert_eq!(moves, vec![2, 3], "{hits:?}");
    for c in &hits {
        assert_eq!(c.part, ToolPart::Holder(0));
        // In the post, outside the stock box.
        assert!(c.at.x >= 16.0 - 0.25 && c.at.x <= 20.0 + 0.25 && c.at.z <= 10.0 + 0.25, "{c:?}");
        assert!(c.depth > 0.5, "{c:?}");
    }
    let err = simulate_dexel(stock, 0.25, &wide, &path, &part, &options, &VerifyOptions::default()).unwrap_err();
    assert!(matches!(&err, SimError::DexelPartCollision { collisions } if collisions.len() == 2), "{err}");
    assert!(err.to_string().contains("move 2 of operation 0") && err.to_string().contains("into the part"), "{err}");
    // A holder of radius 2 over 2 mm (its top rim at most at x = 8 + 7.73
    // < 16): safe, and the program verifies.
    let narrow = ball.with_holder(vec![holder(2.0, 2.0)]).unwrap();
    let d = DexelStock::new(stock, 0.25).unwrap();
    let hits = d.part_collisions(&part, &narrow, &path, &options, 0).unwrap();
    assert!(hits.is_empty(), "{hits:?}");
    simulate_dexel(stock, 0.25, &narrow, &path, &part, &options, &VerifyOptions::default()).unwrap();
}

/// The same cut on one and two threads gives identical rays and reports.
#[test]
fn one_and_two_threads_agree() {
    let stock = Aabb3 { min: p(0.0, 0.0, -4.0), max: p(12.0, 10.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Bull { radius: 1.5, corner: 0.5 }, 8.0).unwrap();
    let part = DexelPart::new(&block(p(-1.0, -1.0, -6.0), p(13.0, 11.0, -3.6)));
    let mut path = vec![mv(MoveKind::Rapid, p(-3.0, 0.0, 6.0), Vec3::z())];
    for k in 0..12 {
        let y = 0.9 * k as f64;
        let a = tilted(0.05 * k as f64, 0.7 * k as f64);
        path.push(mv(MoveKind::Plunge, p(-3.0, y, -2.0 + 0.1 * (k % 3) as f64), a));
        path.push(mv(MoveKind::Feed, p(15.0, y + 0.3, -2.4), tilted(0.05 * k as f64 + 0.1, 0.7 * k as f64)));
    }
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut d = DexelStock::new(stock, 0.15).unwrap();
            let r = d.cut(&cutter, &path, &DexelOptions::default()).unwrap();
            let v = verify_dexel(&d, &part, &VerifyOptions::default()).unwrap();
            let rays: Vec<Vec<[f64; 2]>> = (0..3)
                .flat_map(|axis| {
                    let (nu, nv) = d.grid(axis);
                    let d = &d;
                    (0..nv).flat_map(move |iv| (0..nu).map(move |iu| d.intervals(axis, iu, iv)))
                })
                .collect();
            (rays, r, v)
        })
    };
    let (a, b) = (run(1), run(2));
    assert!(a.0.iter().zip(&b.0).all(|(x, y)| x.len() == y.len()
        && x.iter().zip(y).all(|(s, t)| s[0].to_bits() == t[0].to_bits() && s[1].to_bits() == t[1].to_bits())));
    assert_eq!(a.1, b.1);
    assert_eq!(a.2, b.2);
}

/// Untouched rays hold no heap memory; bad input is an error naming the move.
#[test]
fn memory_and_errors() {
    let stock = Aabb3 { min: p(0.0, 0.0, -4.0), max: p(12.0, 10.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Ball { radius: 1.0 }, 5.0).unwrap();
    let mut d = DexelStock::new(stock, 0.5).unwrap();
    let path = [mv(MoveKind::Plunge, p(3.0, 3.0, -1.0), Vec3::z())];
    d.cut(&cutter, &path, &DexelOptions::default()).unwrap();
    assert!(d.is_untouched(2, 20, 15));
    assert!(!d.is_untouched(2, 6, 6));
    let bad = [mv(MoveKind::Feed, p(3.0, 3.0, -1.0), Vec3::zeros())];
    let e = d.cut(&cutter, &bad, &DexelOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::BadAxis { index: 0, .. }), "{e}");
    let flip = [mv(MoveKind::Feed, p(3.0, 3.0, -1.0), Vec3::z()), mv(MoveKind::Feed, p(3.0, 3.0, -1.0), -Vec3::z())];
    let e = d.cut(&cutter, &flip, &DexelOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::AxisTurn { index: 1, .. }), "{e}");
    assert!(DexelStock::new(stock, 0.0).is_err());
    let e = d.cut(&cutter, &path, &DexelOptions { axis_tolerance: -1.0, ..DexelOptions::default() }).unwrap_err();
    assert!(e.to_string().contains("axis tolerance"), "{e}");
}

/// Arcs (planar and helical) are cut as chords within `ARC_SAGITTA`: the
/// z-map cuts them exactly, and the two stocks agree up to that sagitta.
#[test]
fn arcs_match_the_zmap_up_to_the_sagitta() {
    use scallop_geom::Point2;
    use scallop_toolpath::ArcXY;
    let stock = Aabb3 { min: p(0.0, 0.0, -4.0), max: p(12.0, 12.0, 0.0) };
    let cutter = Cutter::new(CutterShape::Ball { radius: 1.5 }, 8.0).unwrap();
    let mut path = Toolpath::new(1000.0);
    path.push(Move::new(MoveKind::Rapid, p(9.0, 6.0, 3.0)));
    path.push(Move::new(MoveKind::Plunge, p(9.0, 6.0, -1.0)));
    // A planar half circle (G3) and a clockwise helical three-quarter turn (G2).
    path.push_arc(
        Move::new(MoveKind::Feed, p(3.0, 6.0, -1.0)),
        ArcXY { center: Point2::new(6.0, 6.0), sweep: std::f64::consts::PI },
    );
    path.push_arc(
        Move::new(MoveKind::Feed, p(6.0, 3.0, -2.0)),
        ArcXY { center: Point2::new(6.0, 6.0), sweep: -1.5 * std::f64::consts::PI },
    );
    let mut zmap = ZMap::new(stock, 0.1).unwrap();
    let zr = zmap.cut(&cutter, &path).unwrap();
    let mut dexels = DexelStock::new(stock, 0.1).unwrap();
    let moves = ToolMove::from_toolpath(&path);
    assert!(moves[2].arc.is_some());
    let dr = dexels.cut(&cutter, &moves, &DexelOptions::default()).unwrap();
    assert!(dr.sweeps > 100, "{}", dr.sweeps);
    // The footprint's edge is about 2 x 2 pi x 3 mm long, the cut up to 2 mm deep.
    let bound = 2.0 * std::f64::consts::TAU * 4.5 * 2.0 * scallop_sim::tol::ARC_SAGITTA;
    assert!((dr.removed_volume - zr.removed_volume).abs() <= bound, "{} vs {}", dr.removed_volume, zr.removed_volume);
    let top = dexels.top_heights();
    let same = top.iter().zip(zmap.heights()).filter(|(a, b)| (*a - *b).abs() <= 1e-3).count();
    assert!(same as f64 >= 0.999 * top.len() as f64, "{same} of {}", top.len());
}

/// A horizontal tool finishing the side wall of a block 0.1 mm too deep: the
/// X rays crossing the wall see the removed part, 0.1 mm along its normal,
/// and name the move along the wall.
#[test]
fn side_wall_gouge_is_found_by_the_x_rays() {
    let part = DexelPart::new(&block(p(0.0, 0.0, -10.0), p(10.0, 10.0, 0.0)));
    let stock = Aabb3 { min: p(-3.0, -3.0, -10.0), max: p(13.0, 13.0, 1.0) };
    let cutter = Cutter::new(CutterShape::Flat { radius: 1.5 }, 10.0).unwrap();
    // The spindle on the -X side: the flat face looks at the wall x = 0.
    let a = -Vec3::x();
    let run = |into: f64| {
        let path = [
            mv(MoveKind::Rapid, p(-8.0, -4.0, -5.0), a),
            mv(MoveKind::Feed, p(into, -4.0, -5.0), a),
            mv(MoveKind::Feed, p(into, 14.0, -5.0), a),
        ];
        let opts = VerifyOptions { gouge_tolerance: 0.01, ..VerifyOptions::default() };
        simulate_dexel(stock, 0.2, &cutter, &path, &part, &DexelOptions::default(), &opts)
    };
    // Exactly on the wall: no gouge, and the X rays through the slot hold
    // material from the wall on (none left before it).
    let sim = run(0.0).unwrap();
    let (ny, nz) = sim.stock.grid(0);
    let mut through = 0;
    for iz in 0..nz {
        for iy in 0..ny {
            let o = sim.stock.ray_origin(0, iy, iz);
            if (o.z + 5.0).abs() < 1.4 && (0.5..9.5).contains(&o.y) {
                let iv = sim.stock.intervals(0, iy, iz);
                assert!(iv[0][0].abs() < 1e-9, "ray at y {} z {}: {iv:?}", o.y, o.z);
                through += 1;
            }
        }
    }
    assert!(through > 100);
    let err = run(0.1).unwrap_err();
    let SimError::DexelGouge { worst, .. } = err else { panic!("expected a gouge, got {err:?}") };
    let g = worst[0];
    assert_eq!(g.axis, 0, "{g:?}");
    assert!((g.depth - 0.1).abs() < 1e-9, "{g:?}");
    assert!(g.at.x > 0.0 && g.at.x < 0.1 && (g.at.z + 5.0).abs() <= 1.5 && (0.0..=10.0).contains(&g.at.y));
    assert_eq!(g.cut_by.map(|m| m.index), Some(2));
}

/// Rays through the edges and vertices of a closed part's triangles cross
/// it consistently (symbolic perturbation): inside, one whole interval;
/// on its boundary, the whole interval or nothing, never half of it.
#[test]
fn rays_through_edges_and_vertices_of_a_closed_part() {
    let part = DexelPart::new(&block(p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0)));
    assert!(part.is_closed());
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for (cu, cv) in [(0.5, 0.5), (0.25, 0.75), (0.75, 0.25), (0.5, 0.25)] {
            // Interior: the diagonals of the faces' triangulation and plain points.
            let mut o = Point3::origin();
            o[u] = cu;
            o[v] = cv;
            let iv = part.intervals(&o, axis);
            assert_eq!(iv.len(), 1, "axis {axis} at ({cu}, {cv}): {iv:?}");
            assert_eq!((iv[0].0, iv[0].1), (0.0, 1.0));
            assert!((iv[0].2 - 1.0).abs() < 1e-12 && (iv[0].3 - 1.0).abs() < 1e-12);
        }
        for (cu, cv) in [(0.0, 0.0), (1.0, 1.0), (0.0, 0.5), (1.0, 0.5), (0.5, 0.0), (0.5, 1.0), (0.0, 1.0)] {
            let mut o = Point3::origin();
            o[u] = cu;
            o[v] = cv;
            let iv = part.intervals(&o, axis);
            assert!(iv.is_empty() || (iv.len() == 1 && (iv[0].0, iv[0].1) == (0.0, 1.0)), "axis {axis}: {iv:?}");
        }
    }
}

/// A stock started from a closed blank holds exactly the blank: its volume on
/// every ray family is the blank's, a slot through the box removes only the
/// part of the slot inside the blank, and a shank passing over the box but
/// outside the blank collides with nothing.
#[test]
fn a_blank_is_the_starting_stock() {
    let stock = Aabb3 { min: p(0.0, 0.0, -10.0), max: p(40.0, 20.0, 0.0) };
    // A step: the blank fills x < 20 to z = 0 and x >= 20 to z = -6 (cell-aligned at 0.25 mm).
    let low = block(p(20.0, 0.0, -10.0), p(40.0, 20.0, -6.0));
    let high = block(p(0.0, 0.0, -10.0), p(20.0, 20.0, 0.0));
    let mut soup: Vec<[Point3; 3]> = Vec::new();
    for m in [&low, &high] {
        soup.extend((0..m.triangles().len()).map(|t| m.triangle(t)));
    }
    let blank = TriMesh::from_soup(&soup).unwrap().0;
    let mut dexels = DexelStock::from_solid(stock, 0.25, &DexelPart::new(&blank)).unwrap();
    let expected = 20.0 * 20.0 * 10.0 + 20.0 * 20.0 * 4.0;
    for axis in 0..3 {
        assert!((dexels.volume_along(axis) - expected).abs() < 1e-6, "axis {axis}: {}", dexels.volume_along(axis));
    }
    assert!((dexels.initial_volume() - expected).abs() < 1e-6);
    // A flat D4 slot 1 mm deep along x at y = 10 from above the box: 4 x 1 x 40 inside the box, half
    // of it over the low side, where the blank stops at z = -6: only the high half is cut.
    let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0).unwrap();
    let path = [
        mv(MoveKind::Rapid, p(-3.0, 10.0, 5.0), Vec3::z()),
        mv(MoveKind::Plunge, p(-3.0, 10.0, -1.0), Vec3::z()),
        mv(MoveKind::Feed, p(43.0, 10.0, -1.0), Vec3::z()),
    ];
    let report = dexels.cut(&flat, &path, &DexelOptions::default()).unwrap();
    report.check().unwrap();
    assert!((report.removed_volume - 80.0).abs() < 1e-6, "{}", report.removed_volume);
    assert!((dexels.initial_volume() - dexels.volume() - 80.0).abs() < 1e-6);
    // Flutes 4 mm long under a shank of radius 3: a slot at z = -7 on the low side puts the shank
    // (above z = -3) inside the box but over the blank's top (z = -6): no collision from the blank,
    // one from the full box.
    let short = Cutter::new(CutterShape::Flat { radius: 2.0 }, 4.0).unwrap().with_shank(3.0, 20.0).unwrap();
    let low_slot = [
        mv(MoveKind::Rapid, p(30.0, -3.0, 5.0), Vec3::z()),
        mv(MoveKind::Plunge, p(30.0, -3.0, -7.0), Vec3::z()),
        mv(MoveKind::Feed, p(30.0, 23.0, -7.0), Vec3::z()),
    ];
    let options = DexelOptions::default();
    assert!(options.check_collisions);
    let mut from_blank = DexelStock::from_solid(stock, 0.25, &DexelPart::new(&blank)).unwrap();
    assert!(from_blank.cut(&short, &low_slot, &options).unwrap().collisions.is_empty());
    let mut full = DexelStock::new(stock, 0.25).unwrap();
    assert!(!full.cut(&short, &low_slot, &options).unwrap().collisions.is_empty());
    // An open surface is no blank.
    let open = TriMesh::from_soup(&soup[..soup.len() - 1]).unwrap().0;
    assert!(matches!(DexelStock::from_solid(stock, 0.25, &DexelPart::new(&open)), Err(SimError::OpenBlank)));
}

/// A bull nose R 3 r 1 with 10 mm of flutes, a shank R 3 out to `stick_out`
/// and a holder R 8 x 40 above it.
fn held(stick_out: f64) -> Cutter {
    Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 10.0)
        .unwrap()
        .with_shank(3.0, stick_out - 10.0)
        .unwrap()
        .with_holder(vec![HolderSegment { length: 40.0, bottom_radius: 8.0, top_radius: 8.0 }])
        .unwrap()
}

/// Whether the cut of `path` on a fresh stock with the tool at `stick_out`
/// finds no shank or holder collision (a re-proof at that length).
fn free_at(stock: &Aabb3, path: &[ToolMove], stick_out: f64) -> bool {
    let mut d = DexelStock::new(*stock, 0.5).unwrap();
    let options = DexelOptions { axis_tolerance: 0.02, ..DexelOptions::default() };
    d.cut(&held(stick_out), path, &options).unwrap().collisions.is_empty()
}

/// The smallest collision-free stick-out found in one cut
/// ([`DexelOptions::max_stick_out`]) is the one a bisection of re-proofs at
/// fixed lengths finds: a vertical plunge 15 mm into the block (the holder,
/// wider than the hole, must stay above the block's top: 15 mm), and random
/// programs of tilted 5-axis moves along the block's top, where the tilted
/// holder's rim reaches down into it.
#[test]
fn stick_out_search_agrees_with_reproofs() {
    let stock = Aabb3 { min: p(0.0, 0.0, 0.0), max: p(40.0, 40.0, 20.0) };
    let search = |path: &[ToolMove], max: f64| {
        let mut d = DexelStock::new(stock, 0.5).unwrap();
        let options = DexelOptions { axis_tolerance: 0.02, max_stick_out: Some(max), ..DexelOptions::default() };
        let report = d.cut(&held(max), path, &options).unwrap();
        (report.min_stick_out.unwrap(), report.collisions.is_empty())
    };
    // The plunge: the flutes reach 10 mm up from the tip at z 5, the holder
    // must start above z 20.
    let plunge =
        [mv(MoveKind::Rapid, p(20.0, 20.0, 30.0), Vec3::z()), mv(MoveKind::Feed, p(20.0, 20.0, 5.0), Vec3::z())];
    let (found, free) = search(&plunge, 30.0);
    assert!(free && !found.exceeded, "{found:?}");
    assert!(found.length >= 15.0 && found.length <= 15.0 + scallop_sim::tol::STICK_OUT_TOL, "{found:?}");
    assert_eq!(found.limit.unwrap().0.index, 1);
    // Shallow cuts: the flutes alone.
    let shallow =
        [mv(MoveKind::Rapid, p(20.0, 20.0, 30.0), Vec3::z()), mv(MoveKind::Feed, p(20.0, 20.0, 14.0), Vec3::z())];
    let (found, _) = search(&shallow, 30.0);
    assert_eq!((found.length, found.limit), (10.0, None));
    // Random tilted programs.
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut compared = 0;
    for case in 0..8 {
        let mut path = vec![mv(MoveKind::Rapid, p(20.0, 20.0, 40.0), Vec3::z())];
        // Tips at least 13 mm up and tilts of at most 0.5 rad: the flutes'
        // top (and the shank) stay above the block, the holder's rim (R 8)
        // dips into it for stick-outs up to about 12.3 mm.
        for _ in 0..4 {
            let tip = p(8.0 + 24.0 * unit(), 8.0 + 24.0 * unit(), 13.0 + 2.0 * unit());
            let axis = tilted(0.3 + 0.2 * unit(), std::f64::consts::TAU * unit());
            path.push(mv(MoveKind::Feed, tip, axis));
        }
        let max = 34.0;
        let (found, free) = search(&path, max);
        if case == 0 {
            // The same on one thread (the bands of rays are fixed).
            let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            assert_eq!(one.install(|| search(&path, max)), (found, free));
        }
        // The search ends at the largest length exactly when the cut collides there.
        assert_eq!(found.exceeded, !free, "case {case}: {found:?}");
        assert_eq!(free, free_at(&stock, &path, max), "case {case}");
        if found.exceeded {
            continue;
        }
        // A bisection of re-proofs between the flute length and the largest length.
        let (mut short, mut long) = (10.0 + 1e-3, max);
        if free_at(&stock, &path, short) {
            assert!(found.length <= short, "case {case}: {found:?}");
            continue;
        }
        while long - short > 1e-3 {
            let mid = 0.5 * (short + long);
            if free_at(&stock, &path, mid) { long = mid } else { short = mid }
        }
        let tol = scallop_sim::tol::STICK_OUT_TOL;
        assert!(found.length >= short - 1e-9 && found.length <= long + tol, "case {case}: {found:?} [{short}, {long}]");
        // Just shorter collides, the length found does not.
        assert!(
            !free_at(&stock, &path, found.length - tol - 1e-3) && free_at(&stock, &path, found.length),
            "case {case}"
        );
        compared += 1;
    }
    assert!(compared >= 5, "{compared}");
}
