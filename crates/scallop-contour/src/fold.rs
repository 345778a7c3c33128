//! Redundant folds of a closed ring: a stretch of the ring that runs along a
//! line, turns back along it and runs forward over the same stretch again.
//!
//! The offset kernel (`cavalier_contours`) now and then returns such a ring
//! where an erosion reaches a branch of the region's medial axis: the ring
//! runs A -> D, back D -> A and A -> D again before going on (docs/roughing.md,
//! "Offset rings without folds"). As a pass, the tool stops twice and
//! reverses over ground it has just cut. The stretch is removed only when
//! what it covers is covered by the rest of the ring: the run before the turn
//! starts at or behind the farthest point the turn goes back to, and the run
//! after it comes forward to the turning point again. Every removed point then
//! lies within the fold width of the ring that is kept.

use crate::Vertex;

/// The ring `vertices` (closed) with its redundant folds removed: every
/// stretch that turns back along the line it came on, within `width` (mm) of
/// that line, over ground the ring covers before and after it. The kept ring
/// passes within `width` of every removed point.
pub(crate) fn unfold(vertices: &[Vertex], width: f64) -> Vec<Vertex> {
    let mut v = vertices.to_vec();
    // Each removal drops at least one vertex: at most n rounds.
    while v.len() > 3 {
        let Some((i, remove, bulge)) = (0..v.len()).find_map(|i| redundant_fold(&v, i, width).map(|(r, b)| (i, r, b)))
        else {
            break;
        };
        let n = v.len();
        v[i].bulge = bulge;
        let gone: Vec<usize> = (1..=remove).map(|k| (i + k) % n).collect();
        v = v.iter().enumerate().filter(|(k, _)| !gone.contains(k)).map(|(_, x)| *x).collect();
    }
    v
}

/// A segment's sagitta (mm): the largest distance of its arc from its chord.
fn sagitta(a: &Vertex, b: &Vertex) -> f64 {
    a.bulge.abs() * 0.5 * (b.x - a.x).hypot(b.y - a.y)
}

/// The fold turning back at vertex `i`, if it is redundant: how many vertices
/// after `i` to remove, and the bulge of the segment that then leaves `i`.
fn redundant_fold(v: &[Vertex], i: usize, width: f64) -> Option<(usize, f64)> {
    let n = v.len();
    let at = |k: usize| &v[k % n];
    let (a, b) = (at(i + n - 1), at(i));
    let len = (b.x - a.x).hypot(b.y - a.y);
    if len <= crate::tol::POS_EQUAL {
        return None;
    }
    let u = [(b.x - a.x) / len, (b.y - a.y) / len];
    // Position along the line through b (t) and distance from it.
    let t = |p: &Vertex| (p.x - b.x) * u[0] + (p.y - b.y) * u[1];
    let off = |p: &Vertex| ((p.x - b.x) * u[1] - (p.y - b.y) * u[0]).abs();
    // On the line and straight: the segment from `k` to `k + 1`.
    let straight = |k: usize| sagitta(at(k), at(k + 1)) <= width && off(at(k)) <= width && off(at(k + 1)) <= width;
    if !straight(i + n - 1) || !straight(i) || t(at(i + 1)) >= -width {
        return None; // no turn back along the line at b
    }
    // The run that came to b: back to its start s.
    let mut s = i + n - 1;
    for _ in 0..n {
        let prev = s + n - 1;
        if prev % n == i || !straight(prev) || t(at(prev)) > t(at(s)) {
            break;
        }
        s = prev;
    }
    // The run back from b to its farthest point m.
    let mut m = i + 1;
    while m < i + n - 1 && straight(m) && t(at(m + 1)) <= t(at(m)) {
        m += 1;
    }
    if t(at(s)) > t(at(m)) + width {
        return None; // the turn goes back over ground the ring has not covered
    }
    // The run forward again from m to the first vertex f at b's place or beyond.
    let mut f = m;
    while t(at(f)) < -width {
        if f + 1 >= i + n || !straight(f) || t(at(f + 1)) < t(at(f)) {
            return None; // the ring leaves the line before it is back at b
        }
        f += 1;
    }
    if f - i + 2 >= n {
        return None; // the whole ring is one line: nothing would be left
    }
    let fv = at(f);
    if (fv.x - b.x).hypot(fv.y - b.y) <= width {
        // f is b again: b goes on as f did.
        Some((f - i, fv.bulge))
    } else {
        // f is ahead of b (m is behind it by more than the width: f > i + 1).
        Some((f - i - 1, 0.0)).filter(|&(remove, _)| remove > 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(points: &[[f64; 2]]) -> Vec<Vertex> {
        points.iter().map(|p| Vertex { x: p[0], y: p[1], bulge: 0.0 }).collect()
    }

    fn xy(v: &[Vertex]) -> Vec<[f64; 2]> {
        v.iter().map(|p| [p.x, p.y]).collect()
    }

    #[test]
    fn a_stretch_run_three_times_is_run_once() {
        // A square whose bottom edge runs 0 -> 4, back to 1, forward to 4 again.
        let folded =
            ring(&[[0.0, 0.0], [2.0, 0.0], [4.0, 0.0], [1.0, 0.0], [3.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
        assert_eq!(xy(&unfold(&folded, 1e-3)), vec![[0.0, 0.0], [2.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
    }

    #[test]
    fn a_fold_forward_past_the_turn_ends_there() {
        // Out to 3, back to 1, forward past 3 to 4: the path runs 0 -> 3 -> 4.
        let folded = ring(&[[0.0, 0.0], [3.0, 0.0], [1.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
        assert_eq!(xy(&unfold(&folded, 1e-3)), vec![[0.0, 0.0], [3.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
    }

    #[test]
    fn a_spur_into_new_ground_is_kept() {
        // A spur from the square's corner out to (6, 0) and back: the ring
        // leaves the line where the spur starts, so without the way back it
        // would cut across (a slot exactly as wide as the tool keeps its pass).
        let spur = ring(&[[0.0, 0.0], [4.0, 0.0], [6.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
        assert_eq!(xy(&unfold(&spur, 1e-3)), xy(&spur));
        // A turn back past where the run along the line began is kept too.
        let back =
            ring(&[[0.0, 4.0], [0.0, 0.0], [2.0, 0.0], [4.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [4.0, 0.0], [4.0, 4.0]]);
        assert_eq!(xy(&unfold(&back, 1e-3)), xy(&back));
    }

    #[test]
    fn a_fold_off_the_line_by_more_than_the_width_is_kept() {
        let wide = ring(&[[0.0, 0.0], [4.0, 0.0], [1.0, 0.01], [4.0, 0.02], [4.0, 4.0], [0.0, 4.0]]);
        assert_eq!(xy(&unfold(&wide, 1e-3)), xy(&wide));
    }
}
