//! Offset clearing covers its region even where the offset kernel loses
//! rings: a tool-centre region of the fitting pocket (`scallop rough5 --part
//! fitting --baseline zlevel`, its z = 22 level) whose first erosion by the
//! stepover eroded to nothing at the next offset, leaving its inside uncut
//! under a rapid of the level below (docs/rough5.md, "Baselines").
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_contour::{Contour, Region, Vertex};
use scallop_rough::{ClearOptions, Direction, Pattern, Step, plan_offset};

fn fitting_level() -> Region {
    level(include_str!("data/fitting_level_22.txt"))
}

/// A region of one ring from its text: `x y bulge` per line, `#` comments.
fn level(text: &str) -> Region {
    let vertices: Vec<Vertex> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            Vertex { x: v[0], y: v[1], bulge: v[2] }
        })
        .collect();
    Region::with_holes(Contour::new(&vertices, true).unwrap(), Vec::new()).unwrap()
}

/// Every point of the region lies within the stepover of a pass (the offset
/// clearing's coverage: a point eroded away at the next level is within ae of
/// the ring it was eroded from), checked on a 1 mm grid.
#[test]
fn the_fitting_level_is_covered_by_its_passes() {
    let region = fitting_level();
    let steps = plan_offset(&region, &OPTIONS).unwrap();
    assert_covered(&region, &steps, &OPTIONS);
}

/// The fitting's 3-axis tool, stepover and tolerance.
const OPTIONS: ClearOptions = ClearOptions {
    tool_radius: 5.0,
    stepover: 4.5,
    direction: Direction::Climb,
    chord_tolerance: 0.005,
    pattern: Pattern::Offset,
};

/// Another level of the fitting, whose erosions the offset kernel returned
/// with folds (a ring running A -> D, D -> A and A -> D again): the passes
/// turn back nowhere, and the region is still covered.
#[test]
fn the_fitting_passes_do_not_run_back_over_themselves() {
    let region = level(include_str!("data/fitting_level_folds.txt"));
    let steps = plan_offset(&region, &OPTIONS).unwrap();
    let mut turns = Vec::new();
    for s in &steps {
        let Step::Cut(c) = s else { continue };
        let p = c.to_points(OPTIONS.chord_tolerance);
        let n = p.len();
        for i in 0..n {
            let (a, b, d) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
            let (u, w) = ([b[0] - a[0], b[1] - a[1]], [d[0] - b[0], d[1] - b[1]]);
            let cos = (u[0] * w[0] + u[1] * w[1]) / (u[0].hypot(u[1]) * w[0].hypot(w[1]));
            if cos < -0.999 {
                turns.push(b);
            }
        }
    }
    assert!(turns.is_empty(), "the passes turn back at {turns:?}");
    assert_covered(&region, &steps, &OPTIONS);
}

/// Every point of `region` on a 1 mm grid lies within the stepover of a pass
/// (plus 0.1 mm for the grid).
fn assert_covered(region: &Region, steps: &[Step], options: &ClearOptions) {
    let points: Vec<[f64; 2]> = steps
        .iter()
        .filter_map(|s| match s {
            Step::Cut(c) => Some(c.to_points(0.005)),
            Step::Link { .. } => None,
        })
        .flat_map(|ring| {
            (0..ring.len())
                .flat_map(|i| {
                    let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                    let n = ((b[0] - a[0]).hypot(b[1] - a[1]) / 0.05).ceil().max(1.0) as usize;
                    (0..n).map(move |j| {
                        let t = j as f64 / n as f64;
                        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let (lo, hi) = region.bounds().unwrap();
    let mut worst = (0.0_f64, [0.0, 0.0]);
    let mut y = lo[1];
    while y <= hi[1] {
        let mut x = lo[0];
        while x <= hi[0] {
            if region.contains([x, y]) {
                let d = points.iter().map(|p| (p[0] - x).hypot(p[1] - y)).fold(f64::INFINITY, f64::min);
                if d > worst.0 {
                    worst = (d, [x, y]);
                }
            }
            x += 1.0;
        }
        y += 1.0;
    }
    assert!(
        worst.0 <= options.stepover + 0.1,
        "({:.3}, {:.3}) is {:.3} mm from every pass",
        worst.1[0],
        worst.1[1],
        worst.0
    );
}
