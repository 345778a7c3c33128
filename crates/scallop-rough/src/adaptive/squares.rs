//! What a probe of the walk's engagement reads ([`probe`]), and a cache per
//! square of the grid (the four cell centres a bilinear sample reads) of
//! that answer where it is the same everywhere in the square
//! ([`Squares`]): most of the front half's probes lie deep in the cut or
//! deep in the material, where the cache answers with one byte instead of
//! two or three bilinear samples (docs/benchmarks.md, "Adaptive clearing:
//! planning time, sixteenth session").
//!
//! Exact: a bilinear sample is a convex combination of its square's four
//! values, computed with non-negative weights in a few roundings, so it
//! lies within a few units in the last place of their range (all four of
//! one sign): a square whose four values are all more than [`MARGIN`] on
//! one side of a threshold answers every comparison of a sample in it
//! with that threshold alike. The cache holds only such answers, and a
//! square is forgotten whenever one of its values changes in a way that
//! could change its answer ([`Squares::lowered`], [`Squares::changed`]).

use std::cell::Cell;

use crate::grid::Grid;

/// Not known yet: classify the square.
const UNKNOWN: u8 = 0;
/// No probe in the square counts.
pub(super) const NOTHING: u8 = 1;
/// Every probe in the square counts, in the engagement and its core.
pub(super) const CORE: u8 = 2;
/// Every probe in the square counts in the engagement, none in its core
/// (the strip along the walls).
pub(super) const RIM: u8 = 3;
/// The probes in the square answer differently: read them ([`probe`]).
pub(super) const MIXED: u8 = 4;

/// How far (mm) all four values of a square must lie past a threshold for
/// the cache to answer for it, far above the rounding of a bilinear
/// sample of values of a few millimetres (about 1e-15 mm; the same as
/// `Grid::quiet`'s).
const MARGIN: f64 = 1e-9;

/// The fields a probe reads (rows of `nx`) and its thresholds: material is
/// farther than `r` from every swept centre, within `r` of the region
/// (`reach`) and not outside the level's material (`open` positive), or
/// touched beyond it (`touch`: the material's signed distance and the
/// distance from the region raised outside it); the core is within `strip`
/// of the region.
#[derive(Clone, Copy)]
pub(super) struct Fields<'a> {
    pub swept: &'a [f64],
    pub reach: &'a [f64],
    pub open: Option<&'a [f64]>,
    pub touch: Option<(&'a [f64], &'a [f64])>,
    pub nx: usize,
    pub r: f64,
    pub strip: f64,
}

/// What a probe at the location `at` ([`Grid::locate`]) reads: whether it
/// counts in the engagement and whether in its core.
#[inline]
pub(super) fn probe(f: &Fields<'_>, at: (usize, f64, f64)) -> (bool, bool) {
    let nx = f.nx;
    if Grid::interpolate(f.swept, nx, at) <= f.r {
        return (false, false);
    }
    let reach = Grid::interpolate(f.reach, nx, at);
    // The level's material; the material touched beyond it counts in the
    // engagement only.
    let inside = reach < f.r && !f.open.is_some_and(|o| Grid::interpolate(o, nx, at) > 0.0);
    let counted = inside
        || f.touch
            .is_some_and(|(t, near)| Grid::interpolate(near, nx, at) < f.r && Grid::interpolate(t, nx, at) <= 0.0);
    (counted, counted && inside && reach < f.strip)
}

/// The answer of every probe in each square where it is one, learnt on the
/// first probe in the square ([`Squares::get`]).
pub(super) struct Squares {
    state: Vec<Cell<u8>>,
    nx: usize,
}

impl Squares {
    /// Nothing known, for a grid of `len` cells in rows of `nx`.
    pub fn new(len: usize, nx: usize) -> Squares {
        Squares { state: vec![Cell::new(UNKNOWN); len], nx }
    }

    /// The answer ([`NOTHING`], [`CORE`], [`RIM`] or [`MIXED`]) of the
    /// square whose lower-left centre is cell `k` (as [`Grid::locate`]
    /// gives it), classified when not known.
    #[inline]
    pub fn get(&self, k: usize, f: &Fields<'_>) -> u8 {
        let c = &self.state[k];
        let s = c.get();
        if s != UNKNOWN {
            return s;
        }
        let s = classify(k, f);
        c.set(s);
        s
    }

    /// Cell `k` of the swept field went down from `old`, at threshold `r`:
    /// only a square with all four values over `r` (and the margin) can
    /// change its answer then.
    #[inline]
    pub fn lowered(&self, k: usize, old: f64, r: f64) {
        if old > r + MARGIN {
            self.changed(k);
        }
    }

    /// Cell `k` of the swept field changed: the squares it is a corner of
    /// are forgotten.
    #[inline]
    pub fn changed(&self, k: usize) {
        for i in [k, k.wrapping_sub(1), k.wrapping_sub(self.nx), k.wrapping_sub(self.nx + 1)] {
            if let Some(c) = self.state.get(i) {
                c.set(UNKNOWN);
            }
        }
    }

    /// Every square forgotten (the swept field replaced).
    pub fn reset(&mut self) {
        for c in &mut self.state {
            *c.get_mut() = UNKNOWN;
        }
    }
}

/// The answer of square `k` from its four values of each field (see the
/// module documentation).
#[inline(never)]
fn classify(k: usize, f: &Fields<'_>) -> u8 {
    let corners = [k, k + 1, k + f.nx, k + f.nx + 1];
    let all = |v: &[f64], p: &dyn Fn(f64) -> bool| corners.iter().all(|&i| p(v[i]));
    let (r, m) = (f.r, MARGIN);
    if all(f.swept, &|x| x <= r - m) {
        return NOTHING;
    }
    let out = all(f.reach, &|x| x >= r + m) || f.open.is_some_and(|o| all(o, &|x| x > m));
    if out && f.touch.is_none() {
        return NOTHING;
    }
    let inside = all(f.reach, &|x| x < r - m) && f.open.is_none_or(|o| all(o, &|x| x <= -m));
    if !(inside && all(f.swept, &|x| x > r + m)) {
        return MIXED;
    }
    if all(f.reach, &|x| x < f.strip - m) {
        CORE
    } else if all(f.reach, &|x| x >= f.strip + m) {
        RIM
    } else {
        MIXED
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::BIG;
    use proptest::prelude::*;

    proptest! {
        /// The cache answers as the probe itself does, everywhere and all
        /// along a walk that stamps the swept field, undoes stamps and
        /// replaces it: fields as the planner's (a distance from the
        /// region, the level's material's signed distance, touched material
        /// beyond it), each probe's answer taken from the cache where it
        /// has one and checked against [`probe`] at random points.
        #[test]
        fn squares_answer_as_the_probes_do(
            wall in (0.5..3.5f64, -0.6..0.6f64), open_at in (0.0..4.0f64, -1.0..1.0f64),
            with_open in any::<bool>(), with_touch in any::<bool>(),
            turns in proptest::collection::vec(-0.8..0.8f64, 1..40), undo_at in 0usize..40,
            points in proptest::collection::vec((0.0..4.0f64, 0.0..4.0f64), 200..400),
            r in 0.4..1.0f64,
        ) {
            let g = Grid::new([0.0, 0.0], [4.0, 4.0], 1.0, 0.07).expect("grid");
            let n = g.len();
            // The region: right of a slanted wall.
            let reach: Vec<f64> = (0..n).map(|k| {
                let c = g.centre(k);
                let d = wall.0 + wall.1 * (c[1] - 2.0) - c[0];
                if d > 0.0 { if d < r + 0.2 { d } else { BIG } } else { 0.0 }
            }).collect();
            let open: Vec<f64> = (0..n).map(|k| { let c = g.centre(k); c[1] - open_at.0 + open_at.1 * c[0] }).collect();
            let touch_field: Vec<f64> = (0..n).map(|k| g.centre(k)[1] - open_at.0 - 0.5).collect();
            let near: Vec<f64> = reach.iter().map(|v| v.min(2.0 * r)).collect();
            let strip = r - 0.05;
            let mut swept = vec![BIG; n];
            let mut squares = Squares::new(n, g.nx);
            let check = |swept: &[f64], squares: &Squares, pts: &[(f64, f64)]| -> Result<(), TestCaseError> {
                let f = Fields {
                    swept, reach: &reach,
                    open: with_open.then_some(&open[..]),
                    touch: (with_open && with_touch).then_some((&touch_field[..], &near[..])),
                    nx: g.nx, r, strip,
                };
                for &(x, y) in pts {
                    let Some(at) = g.locate([x, y]) else { continue };
                    let want = probe(&f, at);
                    let got = match squares.get(at.0, &f) {
                        NOTHING => (false, false),
                        CORE => (true, true),
                        RIM => (true, false),
                        _ => probe(&f, at),
                    };
                    prop_assert_eq!(got, want, "at ({}, {})", x, y);
                }
                Ok(())
            };
            check(&swept, &squares, &points)?;
            let (mut p, mut heading) = ([2.0, 2.0], 0.3f64);
            let mut undo: Vec<(usize, f64)> = Vec::new();
            for (i, t) in turns.iter().enumerate() {
                heading += t;
                let q = [p[0] + 0.3 * heading.cos(), p[1] + 0.3 * heading.sin()];
                let floor = g.settled(r - 0.01);
                g.stamp_segment_with(&mut swept, p, q, r + 2.0 * g.h, floor, |k, old| {
                    undo.push((k, old));
                    squares.lowered(k, old, r);
                });
                p = q;
                check(&swept, &squares, &points[..points.len() / 4])?;
                if i == undo_at {
                    while let Some((k, v)) = undo.pop() {
                        swept[k] = v;
                        squares.changed(k);
                    }
                    check(&swept, &squares, &points)?;
                }
            }
            check(&swept, &squares, &points)?;
            swept = vec![BIG; n];
            squares.reset();
            check(&swept, &squares, &points)?;
        }
    }
}
