//! Bisection on the exact drop-cutter, and the adaptive splitting of chords.

use std::cell::Cell;

use rayon::prelude::*;
use scallop_cutter::{BoxDrop, Contact, Cutter};
use scallop_geom::{Point2, Vec2};
use scallop_mesh::MeshIndex;

use crate::{Loop, tol};

/// The side test at one height: is the cutter with its tip at `z` cutting
/// into the part at (x, y)?
pub(crate) struct Probe<'a> {
    pub(crate) cutter: &'a Cutter,
    pub(crate) index: &'a MeshIndex,
    pub(crate) z: f64,
    /// Width of the final bisection bracket.
    pub(crate) tolerance: f64,
    /// The grid step.
    pub(crate) step: f64,
}

impl<'a> Probe<'a> {
    /// Tip height of the exact drop-cutter at `p` minus z, floored at
    /// `-step` (a floor only prunes the search; it never changes the sign, so
    /// `height(p) > 0` is exactly "the cutter at z cuts into the part at p").
    #[cfg(test)]
    pub(crate) fn height(&self, p: Point2) -> f64 {
        scallop_cutter::drop_cutter(self.cutter, self.index, p, self.z - self.step).tip.z - self.z
    }

    /// The probe restricted to points of the box `[lo, hi]`: the triangles
    /// within the cutter's reach of the box, sorted by decreasing bound over
    /// the box ([`BoxDrop`]), so that each evaluation scans a short list
    /// instead of searching the index.
    pub(crate) fn local(&'a self, lo: Point2, hi: Point2) -> Local<'a> {
        Local {
            probe: self,
            drop: BoxDrop::new(self.cutter, self.index, lo, hi),
            seed: Cell::new(None),
            slope: Cell::new(f64::NAN),
            seed_features: Cell::new(ALL_FEATURES),
            contact: Cell::new(Contact::Floor),
        }
    }
}

/// A [`Probe`] with the candidate triangles of one box (a chord's, a grid
/// edge's or a cell's neighbourhood). Heights equal the exact drop-cutter's up
/// to rounding (the same contacts, each mesh corner and edge tested once, from
/// the triangle that owns it, maximised over every triangle that can raise the
/// result); points outside the box fall back to the index.
pub(crate) struct Local<'a> {
    pub(crate) probe: &'a Probe<'a>,
    drop: BoxDrop<'a>,
    /// The contact triangle of the last evaluation: tried first at the next
    /// (a valid lower bound that prunes the scan early; the height is the same).
    seed: Cell<Option<usize>>,
    /// The slope (height per unit length, along the probe line) of the last
    /// Newton start of [`Local::contour_near`]: predicts whether the contour
    /// lies within the accepted distance of the next midpoint where the seed's
    /// contact there gives no slope (`NaN`: unknown).
    slope: Cell<f64>,
    /// The corners and edges of the seed that held its contact at the last
    /// evaluation ([`BoxDrop::contact_features`]).
    seed_features: Cell<u8>,
    /// The contact of the last [`Local::height_slot`] evaluation.
    contact: Cell<Contact>,
}

impl Local<'_> {
    /// [`Probe::height`] through the candidate list.
    fn height(&self, p: Point2) -> f64 {
        self.height_slot(p).0
    }

    /// [`Local::height`] and the slot of the triangle that gives it (`None` on
    /// the floor).
    pub(crate) fn height_slot(&self, p: Point2) -> (f64, Option<usize>) {
        let probe = self.probe;
        let (cl, slot) = self.drop.drop(p, probe.z - probe.step, self.seed.get());
        if let Some(s) = slot {
            self.seed.set(slot);
            self.seed_features.set(self.drop.contact_features(s, &cl.contact));
        }
        self.contact.set(cl.contact);
        (cl.tip.z - probe.z, slot)
    }

    /// The side of `p` as [`Local::height_slot`] gives it, the search pruned
    /// at z instead of at the floor: where the cutter at z cuts (> 0) the same
    /// height and contact triangle (every contact above z is computed as
    /// there), else 0 and `None` (no contact above z), which leaves the seed
    /// as it was. For the checks that need only the side of an outside point
    /// (its height only feeds secant guesses when it is inside). Cheaper where
    /// the contact triangle at the last point does not hold the cutter near z
    /// here (its height jumps at its rim, as along a wall's top edge).
    fn side_slot(&self, p: Point2) -> (f64, Option<usize>) {
        let probe = self.probe;
        let (cl, slot) = self.drop.drop(p, probe.z, self.seed.get());
        if let Some(s) = slot {
            self.seed.set(slot);
            self.seed_features.set(self.drop.contact_features(s, &cl.contact));
        }
        ((cl.tip.z - probe.z).max(0.0), slot)
    }

    /// Tip height of the drop-cutter on the one triangle in `slot` at `p`,
    /// minus z, floored as [`Probe::height`]: the full height is the maximum of
    /// these over all triangles. The set where it is > 0 is convex (the cutter
    /// and the triangle are convex), so it meets a segment in one interval.
    fn triangle_height(&self, slot: usize, p: Point2) -> f64 {
        let probe = self.probe;
        self.drop.drop_one(slot, p, probe.z - probe.step).tip.z - probe.z
    }

    /// [`Local::feature_height`] and the contact that gives it.
    fn triangle_contact(&self, slot: usize, features: u8, p: Point2) -> (f64, Contact) {
        let probe = self.probe;
        let cl = self.drop.drop_one_features(slot, features, p, probe.z - probe.step);
        (cl.tip.z - probe.z, cl.contact)
    }

    /// [`Local::triangle_height`] on the facet and the corners and edges in
    /// `features` only: at most the triangle's height, so a point where it is
    /// > 0 is inside as well (and the triangle lifts the cutter there).
    fn feature_height(&self, slot: usize, features: u8, p: Point2) -> f64 {
        let probe = self.probe;
        self.drop.drop_one_features(slot, features, p, probe.z - probe.step).tip.z - probe.z
    }

    /// `triangle_height(slot, p) > 0`, with the search pruned at z.
    fn lifts(&self, slot: usize, p: Point2) -> bool {
        self.drop.lifts(slot, p, self.probe.z)
    }

    /// Shrinks the bracket from `inside` (height `h_in > 0`) to `outside`
    /// (height `h_out <= 0`) to the tolerance and returns its outside end.
    ///
    /// Every step keeps a true bracket (each new point is classified by the
    /// exact drop-cutter). Where the height is smooth, the secant guess
    /// `t = h_in / (h_in - h_out)` lands within the tolerance of the contour and
    /// two probes half a tolerance either side of it close the bracket; where it
    /// is not (vertical walls, creases), a step that did not halve the bracket
    /// is followed by [`BISECTIONS_AFTER_SECANT`] bisections before the secant
    /// is tried again (a crease is one point: the bracket soon lies on one
    /// smooth piece), so the worst case is about twice plain bisection.
    ///
    /// With `slot_in`, the contact triangle at `inside`, the crossing is first
    /// looked for by [`Local::walk_bracket`] (a few full evaluations where the
    /// height has creases between triangles).
    pub(crate) fn bisect_heights(
        &self,
        inside: Point2,
        h_in: f64,
        slot_in: Option<usize>,
        outside: Point2,
        h_out: f64,
    ) -> Point2 {
        slot_in
            .and_then(|slot| self.walk_bracket(inside, slot, outside))
            .unwrap_or_else(|| self.bracket(inside, h_in, outside, h_out))
            .1
    }

    /// The first crossing from `inside` (contact triangle `slot`) towards
    /// `outside` (the cutter at z cuts at the first, not at the second) as a
    /// bracket (inside, outside) no wider than the tolerance, found triangle by
    /// triangle: the interval where the current triangle lifts the cutter above
    /// z ends within the segment (convexity; that triangle alone is below the
    /// full height at `outside`); its end is bracketed on that one triangle
    /// (a smooth height: secant steps, a few cheap evaluations), and one full
    /// evaluation at the outer end of that bracket either ends the walk
    /// (outside: its inner end is inside, lifted by the triangle) or names the
    /// next triangle. `None` after [`MAX_WALK_STEPS`] triangles or on a step
    /// that does not advance (rounding): the caller brackets on the full
    /// drop-cutter instead.
    fn walk_bracket(&self, inside: Point2, slot: usize, outside: Point2) -> Option<(Point2, Point2)> {
        self.walk_bracket_from(inside, slot, None, outside)
    }

    /// [`Local::walk_bracket`] with the height `h_inside` of the triangle in
    /// `slot` at `inside`, when known.
    fn walk_bracket_from(
        &self,
        inside: Point2,
        slot: usize,
        h_inside: Option<f64>,
        outside: Point2,
    ) -> Option<(Point2, Point2)> {
        let (mut at, mut slot, mut known) = (inside, slot, h_inside);
        for _ in 0..MAX_WALK_STEPS {
            let h_at = known.take().unwrap_or_else(|| self.triangle_height(slot, at));
            let h_end = self.triangle_height(slot, outside);
            if !(h_at > 0.0 && h_end <= 0.0) {
                return None;
            }
            // The triangle's height jumps where its part above the cutter's
            // profile leaves the cutter's reach: start from there.
            let guess = self.drop.rim_exit(slot, self.probe.z, at, outside);
            let height = |p| self.triangle_height(slot, p);
            let (tin, tout) = self.bracket_with(&height, at, h_at, outside, h_end, guess);
            let (h, next) = self.side_slot(tout);
            if h <= 0.0 {
                return (tin != tout).then_some((tin, tout));
            }
            match next {
                Some(next) if tout != at => (at, slot) = (tout, next),
                _ => return None,
            }
        }
        None
    }

    /// As [`Local::bisect_heights`] without a contact triangle, returning both
    /// ends of the final bracket (inside, outside).
    fn bracket(&self, inside: Point2, h_in: f64, outside: Point2, h_out: f64) -> (Point2, Point2) {
        self.bracket_with(&|p| self.height(p), inside, h_in, outside, h_out, None)
    }

    /// The bracket of [`Local::bracket`] on the height function `height`.
    /// `guess` (a parameter from `inside` to `outside`, as
    /// [`BoxDrop::rim_exit`](scallop_cutter::BoxDrop::rim_exit)) replaces the
    /// first secant guess: probed half a tolerance either side, as a secant
    /// guess, a right one closes the bracket at once, even where the height
    /// jumps (where secant steps find nothing and only bisection shrinks the
    /// bracket); a wrong one moves one end, as a poor secant step does.
    fn bracket_with(
        &self,
        height: &dyn Fn(Point2) -> f64,
        mut inside: Point2,
        mut h_in: f64,
        mut outside: Point2,
        mut h_out: f64,
        mut guess: Option<f64>,
    ) -> (Point2, Point2) {
        let mut bisections = 0;
        loop {
            let width = (outside - inside).norm();
            if width <= self.probe.tolerance {
                return (inside, outside);
            }
            let secant = h_in - h_out;
            let first = guess.take().filter(|t| (0.0..=1.0).contains(t));
            let use_secant = first.is_some() || (bisections == 0 && secant.is_finite() && secant > 0.0);
            let (a, b) = (inside, outside);
            let steps: [Option<f64>; 2] = if use_secant {
                let t = first.unwrap_or(h_in / secant).clamp(0.0, 1.0);
                let half = SECANT_PROBE * self.probe.tolerance / width;
                [Some((t - half).max(0.0)), Some((t + half).min(1.0))]
            } else {
                [Some(0.5), None]
            };
            for s in steps.into_iter().flatten() {
                let p = a + (b - a) * s;
                if p == inside || p == outside {
                    continue;
                }
                let h = height(p);
                if h > 0.0 {
                    (inside, h_in) = (p, h);
                } else {
                    (outside, h_out) = (p, h);
                    break;
                }
            }
            let after = (outside - inside).norm();
            if after >= width {
                // Down to adjacent floats (or a guess on an end): stop on the outside.
                return (inside, outside);
            }
            // A secant step that did not halve the bracket: the height is not
            // smooth here (a wall, a crease): bisection steps until the bracket
            // may lie on one smooth piece, then the secant again.
            if use_secant && after > 0.5 * width {
                bisections = BISECTIONS_AFTER_SECANT;
            } else if !use_secant {
                bisections = bisections.saturating_sub(1);
            }
        }
    }

    /// Where the contour crosses the line through `mid` along `normal` (unit,
    /// pointing inside): [`Near::Within`] if it does within `accept` of `mid`
    /// (one probe); otherwise, from an inside midpoint, the end of the walk of
    /// [`Local::walk_bracket`] from `mid` to `reach` (the first crossing along
    /// the line: every point before it is lifted by one of the walked
    /// triangles); else (an outside midpoint, or a walk that gives up) probes
    /// at growing distances up to `reach` and
    /// refines the first change of side found between two probes;
    /// [`Near::Missing`] if none. Each next distance is the secant estimate of
    /// the contour from the last two probes, a little beyond (where the height
    /// is smooth the next probe crosses the contour), kept between
    /// [`PROBE_GROWTH`] and [`PROBE_GROWTH_MAX`] times the last distance.
    ///
    /// A step between two inside probes is checked whole (the secant may jump
    /// over a band of outside to another inside region): the contact triangle
    /// of either end lifting the cutter above z at the other end certifies the
    /// step (convexity, see [`Local::triangle_height`]); otherwise the step is
    /// walked as a grid edge ([`Local::gaps`]) and its first gap is the
    /// contour. A gap of any width above the crossing tolerance is found, so
    /// the contour found from an inside midpoint is the nearest one along the
    /// line up to that tolerance. Between two outside probes an inside sliver
    /// is not looked for (the midpoint is safe there).
    ///
    /// The first probe pair needs one full evaluation where a single triangle
    /// settles the other side (the full height is the maximum over the
    /// triangles, so one triangle lifting the cutter above z proves inside):
    /// the last contact triangle at `mid` before the full evaluation at the
    /// first outside probe; the midpoint's contact triangle at the first
    /// inside probe. Where that last contact triangle lifts the cutter at
    /// `mid`, it also stands for the midpoint's contact triangle (no full
    /// evaluation at `mid`). The crossing found is the same as with full
    /// evaluations, up to the crossing tolerance.
    ///
    /// Before the probes, [`Local::newton_near`] tries the secant root of
    /// that triangle's own height along the line (docs/waterline.md, step 6,
    /// "Newton start"): one full evaluation where it lands within the
    /// crossing tolerance, as it does along most of a loop.
    pub(crate) fn contour_near(&self, mid: Point2, normal: Vec2, accept: f64, reach: f64) -> Near {
        let mut first: Option<(f64, Option<usize>)> = None;
        let mut at_mid: Option<(f64, Option<usize>)> = None;
        let mut features = ALL_FEATURES;
        let mut contact = Contact::Floor;
        // The slope of the seed's height at the midpoint, once computed.
        let mut gradient: Option<Option<[f64; 2]>> = None;
        if let Some(seed) = self.seed.get() {
            // The seed's last contact features first (the contact moves little
            // from one midpoint to the next), the whole triangle if they do not lift.
            let last = self.seed_features.get();
            let (mut h_seed, mut seed_contact) = self.triangle_contact(seed, last, mid);
            if h_seed <= 0.0 && last != ALL_FEATURES {
                (h_seed, seed_contact) = self.triangle_contact(seed, ALL_FEATURES, mid);
            }
            if h_seed > 0.0 {
                contact = seed_contact;
                gradient = Some(self.drop.contact_gradient(&seed_contact, mid));
                // Where the seed's fall along the line puts the contour within
                // `accept`, the full evaluation that accepts the chord comes
                // first (elsewhere the seed's own height there decides, below).
                // The fall is the slope of the seed's height at the midpoint,
                // from its contact (a Newton step: where the height is concave
                // along the line, as around a convex inside, it overestimates
                // the distance); where the contact leaves the cutter's radius
                // first (the seed's height jumps there, as along a wall's top
                // edge held by the rim), that distance. The last Newton
                // start's slope where the contact gives none (axis, rim).
                let near = match gradient.flatten() {
                    Some(g) => {
                        let fall = g[0] * normal.x + g[1] * normal.y;
                        let rim = rim_distance(&seed_contact, mid, -normal, self.probe.cutter.radius());
                        h_seed <= fall * accept || rim <= accept
                    }
                    None => h_seed <= self.slope.get() * accept,
                };
                if near {
                    let (h, slot) = self.side_slot(mid - normal * accept);
                    if h <= 0.0 {
                        return Near::Within; // inside at the midpoint, outside within `accept`
                    }
                    first = Some((h, slot));
                }
                // The corners and edges that hold the contact, for the heights below.
                features = self.drop.contact_features(seed, &seed_contact);
                // The seed lifts the cutter at the midpoint: it stands for the
                // contact triangle there (any triangle lifting the cutter at an
                // inside point serves the gap checks and the walk), and its
                // height, at most the full one, for the secant guess.
                at_mid = Some((h_seed, Some(seed)));
            }
        }
        let (h_mid, slot_mid) = at_mid.unwrap_or_else(|| {
            let (h, slot) = self.height_slot(mid);
            contact = self.contact.get();
            (h, slot)
        });
        let mid_in = h_mid > 0.0;
        let towards = if mid_in { -normal } else { normal };
        if let Some(slot) = slot_mid {
            // The features of the seed's contact where the seed stands for the
            // contact triangle, else the whole triangle.
            let features = if at_mid.is_some() { features } else { ALL_FEATURES };
            // The slope of that height along the line, from its contact, and
            // how far along the line the contact stays within the cutter's
            // radius (past it the height jumps: no Newton step beyond).
            let slope =
                gradient.filter(|_| at_mid.is_some()).unwrap_or_else(|| self.drop.contact_gradient(&contact, mid));
            let slope = slope.map(|g| {
                (g[0] * towards.x + g[1] * towards.y, rim_distance(&contact, mid, towards, self.probe.cutter.radius()))
            });
            let start = (h_mid, slot, features, slope);
            match self.newton_near(mid, towards, mid_in, start, accept, reach, &mut first) {
                Start::Settled(near) => return near,
                Start::Open => {}
            }
        }
        // From an inside midpoint, the first crossing along the line is the end
        // of the walk over the triangles that lift the cutter from the midpoint
        // on (the probes below find the same one, with more full evaluations).
        if mid_in
            && let Some(slot) = slot_mid
            && let Some((_, out)) = self.walk_bracket_from(mid, slot, at_mid.map(|(h, _)| h), mid + towards * reach)
        {
            return if (out - mid).norm() <= accept { Near::Within } else { Near::Found(out) };
        }
        let (mut last, mut h_last, mut r_last, mut slot_last) = (mid, h_mid, 0.0, slot_mid);
        let mut r = accept;
        loop {
            let p = mid + towards * r;
            // The first probe (taken on the first pass) may be known already: the same point.
            let (h, slot) = match first.take().filter(|_| mid_in) {
                Some(known) => known,
                None => self.height_slot(p),
            };
            if (h > 0.0) != mid_in {
                if r <= accept {
                    return Near::Within;
                }
                return Near::Found(if mid_in {
                    self.bisect_heights(last, h_last, slot_last, p, h)
                } else {
                    self.bisect_heights(p, h, slot, last, h_last)
                });
            }
            if mid_in && let Some(gap) = self.first_gap(last, slot_last, p, h, slot) {
                return if r <= accept { Near::Within } else { Near::Found(gap) };
            }
            if r >= reach {
                return Near::Missing;
            }
            // Secant root of the height along the line, from the last two probes.
            let slope = (h - h_last) / (r - r_last);
            let root = r - h / slope;
            let guess = if root.is_finite() && root > r { SECANT_OVERSHOOT * root } else { 0.0 };
            (last, h_last, r_last, slot_last) = (p, h, r, slot);
            r = guess.clamp(PROBE_GROWTH * r, PROBE_GROWTH_MAX * r).min(reach);
        }
    }
}

impl Local<'_> {
    /// The Newton start of [`Local::contour_near`] on the triangle in `slot`
    /// (lifting the cutter at `mid` if `mid_in`, else the contact triangle
    /// there, below z; `h_mid` the height at `mid`): that triangle's own height
    /// at `accept` along `towards` (one triangle evaluation) either settles
    /// the accepted distance or, with the height at `mid`, gives the secant
    /// root r of the triangle's height along the line (where the contour
    /// follows one triangle, as along most of a loop, its first Newton step:
    /// within the crossing tolerance of the contour once the chord's midpoint
    /// deviation is small). Two points half a crossing tolerance either side
    /// of r close the bracket: the one on the midpoint's side classified by
    /// the triangle (from an inside midpoint, the triangle lifting the cutter
    /// at both ends of the stretch proves it inside throughout, convexity as
    /// in [`Local::triangle_height`]), the other by the exact drop-cutter. The
    /// same crossing as the probes of [`Local::contour_near`] find, up to the
    /// crossing tolerance, with one exact evaluation instead of several.
    /// [`Start::Open`] where the guess misses (the caller's general search
    /// follows); `first` records the exact evaluation at `accept`, if made.
    #[allow(clippy::too_many_arguments)]
    fn newton_near(
        &self,
        mid: Point2,
        towards: Vec2,
        mid_in: bool,
        (h_mid, slot, features, slope): (f64, usize, u8, Option<(f64, f64)>),
        accept: f64,
        reach: f64,
        first: &mut Option<(f64, Option<usize>)>,
    ) -> Start {
        // The triangle's height on the features that hold its contact at the
        // midpoint: smooth where the contour follows one feature.
        let height = |p: Point2| self.feature_height(slot, features, p);
        // Where the contact's slope along the line puts the root well past
        // `accept`, the Newton step from the midpoint alone: the crossing then
        // lies beyond `near` (the bracket below checks it), whose height is not
        // needed. The stretch from the midpoint up to the bracket is then the
        // one the convexity argument covers.
        let newton = slope.and_then(|(g, rim)| {
            let root = -h_mid / g;
            // From inside, where the contact leaves the cutter's radius before
            // its height falls to z, the height jumps there (a wall's top edge
            // held by the rim): the rim is the guess. From outside, only a
            // root well inside it.
            let root = if mid_in {
                root.min(rim)
            } else if root < RIM_SHARE * rim {
                root
            } else {
                return None;
            };
            (root.is_finite() && root > NEWTON_SKIP * accept).then_some((root, g))
        });
        let (mut root, near, h_near, r_near) = if let Some((root, g)) = newton {
            self.slope.set(g.abs());
            (root, mid, h_mid, 0.0)
        } else {
            let near = mid + towards * accept;
            let h_near = height(near);
            // The triangle's height falls (from inside) or rises (from outside) towards the contour.
            let fall = h_mid - h_near;
            self.slope.set(fall.abs() / accept);
            if mid_in && h_near <= 0.0 {
                if first.is_none() {
                    let (h, next) = self.side_slot(near);
                    if h <= 0.0 {
                        return Start::Settled(Near::Within); // inside at the midpoint, outside within `accept`
                    }
                    *first = Some((h, next));
                }
                return Start::Open; // another triangle lifts the cutter within `accept`
            }
            if !mid_in && h_near > 0.0 {
                return Start::Settled(Near::Within); // outside at the midpoint, inside within `accept`
            }
            if !(if mid_in { fall > 0.0 } else { fall < 0.0 }) {
                return Start::Open;
            }
            (accept + h_near * accept / fall, near, h_near, accept)
        };
        let half = SECANT_PROBE * self.probe.tolerance;
        let at = |r: f64| mid + towards * r;
        let settle =
            |out: Point2| Start::Settled(if (out - mid).norm() <= accept { Near::Within } else { Near::Found(out) });
        if mid_in {
            if !(root.is_finite() && root + half <= reach) {
                return Start::Open;
            }
            let (lo, hi) = (at(root - half), at(root + half));
            let h_lo = height(lo);
            // The triangle's crossing: just past `lo`, or (the guess went past
            // it, as where the height is concave) between `near` and `lo`.
            let (inner, outer) = if h_lo > 0.0 {
                (lo, hi)
            } else {
                // Where the triangle leaves the cutter's reach its height jumps:
                // the guess of [`Local::walk_bracket_from`] first.
                let guess = self.drop.rim_exit(slot, self.probe.z, near, lo);
                self.bracket_with(&height, near, h_near, lo, h_lo, guess)
            };
            let (h, next) = self.side_slot(outer);
            if h <= 0.0 {
                return if inner == outer { Start::Open } else { settle(outer) };
            }
            // Inside at `outer` too: the walk goes on from there.
            match next.and_then(|next| self.walk_bracket_from(outer, next, None, at(reach))) {
                Some((_, out)) => settle(out),
                None => Start::Open,
            }
        } else {
            // Secant steps on the triangle's height until it lifts the cutter
            // past the guess (from below where the height is concave).
            let (mut r_last, mut h_last) = (r_near, h_near);
            for _ in 0..MAX_NEWTON_STEPS {
                if !(root.is_finite() && root > r_last && root + half <= reach) {
                    return Start::Open;
                }
                let h_hi = height(at(root + half));
                if h_hi > 0.0 {
                    let lo = at(root - half);
                    let (h, slot_lo) = self.side_slot(lo);
                    if h <= 0.0 {
                        return settle(lo);
                    }
                    // Another triangle lifts the cutter nearer: the first change
                    // of side between the midpoint and `lo`.
                    return settle(self.bisect_heights(lo, h, slot_lo, mid, h_mid));
                }
                let r = root + half;
                let rise = h_hi - h_last;
                if rise.is_nan() || rise <= 0.0 {
                    return Start::Open;
                }
                root = r - h_hi * (r - r_last) / rise;
                (r_last, h_last) = (r, h_hi);
            }
            Start::Open
        }
    }

    /// The contour crossings on the segment from `a` to `b`, both inside (the
    /// cutter at z cuts there), in order from `a`: the ends of the gaps
    /// (outside intervals) between them, each an outside point within the
    /// crossing tolerance of an inside one. `slot_a` is the triangle that
    /// gives the height at `a`.
    ///
    /// A cover walk: the triangle that lifts the cutter above z at the current
    /// point does so on one interval of the segment (convexity, see
    /// [`Local::triangle_height`]); its end is bisected on that triangle alone,
    /// and the full drop-cutter there either finds the next triangle (no gap)
    /// or starts a gap, whose far end is bisected on the full drop-cutter. A
    /// gap of any width above the crossing tolerance is found, however far it
    /// is from the grid samples (the fibres of OpenCAMLib's push-cutter find
    /// the same intervals); an inside sliver within a gap is not looked for.
    pub(crate) fn gaps(&self, a: Point2, slot_a: usize, b: Point2, h_b: f64) -> Vec<Point2> {
        let mut out = Vec::new();
        let (mut at, mut slot) = (a, slot_a);
        for _ in 0..MAX_COVER_STEPS {
            if self.lifts(slot, b) {
                break; // this triangle covers the rest of the segment
            }
            let end = self.triangle_end(slot, at, b);
            let (h, next) = self.height_slot(end);
            if h > 0.0 {
                match next {
                    Some(next) if end != at => (at, slot) = (end, next),
                    _ => break,
                }
                continue;
            }
            // A gap starts at `end`: its far end, towards the inside end `b`.
            let (inside, outside) = self.bracket(b, h_b, end, h);
            out.push(end);
            out.push(outside);
            let (h_in, next) = self.side_slot(inside);
            match next {
                Some(next) if h_in > 0.0 && inside != at => (at, slot) = (inside, next),
                _ => break,
            }
        }
        out
    }

    /// The start of the first gap (an outside point within the crossing
    /// tolerance of an inside one) on the segment from `a` to `b`, both inside
    /// with contact triangles `slot_a` and `slot_b`; `None` if the segment is
    /// inside throughout (up to gaps under the crossing tolerance). One
    /// triangle evaluation when a contact triangle covers the segment, else
    /// the cover walk of [`Local::gaps`].
    fn first_gap(
        &self,
        a: Point2,
        slot_a: Option<usize>,
        b: Point2,
        h_b: f64,
        slot_b: Option<usize>,
    ) -> Option<Point2> {
        if slot_a.is_some_and(|s| self.lifts(s, b)) || slot_b.is_some_and(|s| self.lifts(s, a)) {
            return None;
        }
        // An inside point always has a contact triangle (the floor is below z).
        slot_a.and_then(|s| self.gaps(a, s, b, h_b).first().copied())
    }

    /// The first point from `inside` towards `outside` (the triangle in `slot`
    /// lifting the cutter above z at the first, not at the second) where that
    /// triangle no longer does, within the crossing tolerance: bisection on the
    /// one triangle.
    fn triangle_end(&self, slot: usize, mut inside: Point2, mut outside: Point2) -> Point2 {
        let probe = self.probe;
        while (outside - inside).norm() > probe.tolerance {
            let mid = Point2::new(0.5 * (inside.x + outside.x), 0.5 * (inside.y + outside.y));
            if mid == inside || mid == outside {
                break;
            }
            if self.lifts(slot, mid) {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        outside
    }
}

/// The Newton start of [`Local::newton_near`] skips the triangle's height at
/// the accepted distance where the contact's slope puts the root beyond this
/// many accepted distances.
const NEWTON_SKIP: f64 = 2.0;

/// From an outside midpoint, the Newton start from the contact's slope is kept
/// only where its root lies within this share of the rim distance
/// ([`rim_distance`]).
const RIM_SHARE: f64 = 0.5;

/// How far from `p` along `u` (unit) the point of `contact` stays within
/// `radius` of the cutter's axis in XY (0 on the floor, or already past it).
fn rim_distance(contact: &Contact, p: Point2, u: Vec2, radius: f64) -> f64 {
    let q = match contact {
        Contact::Vertex { point, .. } | Contact::Edge { point, .. } | Contact::Facet { point, .. } => point,
        Contact::Floor => return 0.0,
    };
    let (dx, dy) = (p.x - q.x, p.y - q.y);
    let b = dx * u.x + dy * u.y;
    let c = dx * dx + dy * dy - radius * radius;
    let disc = b * b - c;
    if c >= 0.0 || disc < 0.0 { 0.0 } else { -b + disc.sqrt() }
}

/// Most triangles [`Local::walk_bracket`] steps through before the plain
/// bracket takes over.
const MAX_WALK_STEPS: usize = 8;

/// Every corner and edge of a triangle (bits as `MeshIndex::owned_features`).
const ALL_FEATURES: u8 = 0b11_1111;

/// Most secant steps of the Newton start from an outside midpoint
/// ([`Local::newton_near`]) before the general search takes over.
const MAX_NEWTON_STEPS: usize = 4;

/// Bisection steps after a secant step that failed to halve the bracket,
/// before the secant is tried again.
const BISECTIONS_AFTER_SECANT: u32 = 2;

/// Most triangles a cover walk along one grid edge steps through before it
/// gives up (the walk usually takes one to three).
const MAX_COVER_STEPS: usize = 256;

/// The outcome of [`Local::newton_near`].
enum Start {
    /// The answer of [`Local::contour_near`].
    Settled(Near),
    /// No answer: the general search follows.
    Open,
}

/// What [`Local::contour_near`] found.
pub(crate) enum Near {
    /// The contour is within the accepted distance.
    Within,
    /// The contour point found (farther).
    Found(Point2),
    /// No change of side within reach.
    Missing,
}

/// Margin of a chord's candidate box, in reaches (chord length or grid step).
pub(crate) const CHORD_MARGIN: f64 = 1.5;

/// Least growth of the probe distance from one probe to the next.
const PROBE_GROWTH: f64 = 2.0;

/// Most growth of the probe distance from one probe to the next (bounds how
/// far a secant guess may jump past a thin feature).
const PROBE_GROWTH_MAX: f64 = 16.0;

/// How far past the secant estimate of the contour the next normal probe goes,
/// as a factor of the estimated distance: the probe lands just across.
const SECANT_OVERSHOOT: f64 = 1.25;

/// Probe offset either side of a secant guess, in crossing tolerances: just
/// under a half, so that two probes that straddle the contour close the bracket.
const SECANT_PROBE: f64 = 0.45;

/// Points strictly between `a` and `b` that bring every chord within
/// `chord_tolerance` of the contour at its midpoint, and a chord longer than
/// `long` at its quarter points too (as far as the probe along the chord's
/// normal finds the contour), in order from `a` to `b`.
pub(crate) fn refine_chord(
    local: &Local<'_>,
    (a, b): (Point2, Point2),
    chord_tolerance: f64,
    long: f64,
    depth: u32,
    out: &mut Vec<Point2>,
) {
    let probe = local.probe;
    let d = b - a;
    let length = d.norm();
    if depth >= tol::MAX_REFINE_DEPTH || length <= tol::MIN_CHORD_PER_CROSSING * probe.tolerance {
        return;
    }
    let normal = Vec2::new(-d.y, d.x) / length; // left of a -> b: the inside
    let at = |t: f64| Point2::new(a.x + t * d.x, a.y + t * d.y);
    // Within a grid cell the contour may bulge up to about a cell away from the
    // chord joining its two crossings (a ridge along the diagonal): reach that far.
    let reach = length.max(probe.step);
    let on = match local.contour_near(at(0.5), normal, chord_tolerance, reach) {
        Near::Found(on) => on,
        // Within at the midpoint: a long chord is checked at its quarters.
        Near::Within if length > long => {
            let quarter = |t: f64| match local.contour_near(at(t), normal, chord_tolerance, reach) {
                Near::Found(on) => Some(on),
                Near::Within | Near::Missing => None,
            };
            let Some(on) = quarter(0.25).or_else(|| quarter(0.75)) else { return };
            on
        }
        Near::Within | Near::Missing => return,
    };
    if on == a || on == b {
        return;
    }
    refine_chord(local, (a, on), chord_tolerance, long, depth + 1, out);
    out.push(on);
    refine_chord(local, (on, b), chord_tolerance, long, depth + 1, out);
}

/// The length past which [`refine_chord`] checks a chord's quarter points
/// ([`tol::LONG_CHORD_SHARE`]).
pub(crate) fn long_chord(probe: &Probe<'_>, chord_tolerance: f64) -> f64 {
    tol::LONG_CHORD_SHARE * (8.0 * probe.cutter.radius() * chord_tolerance).sqrt()
}

/// Runs `[start, end)` of consecutive chords that share one candidate list:
/// at most [`CHORDS_PER_GROUP`] chords whose ends stay within a box of
/// [`GROUP_SPAN`] grid steps (one index query instead of one per chord; the
/// heights are the same).
fn chord_groups(chords: &[(Point2, Point2)], step: f64) -> Vec<(usize, usize)> {
    let span = GROUP_SPAN * step;
    let mut groups = Vec::new();
    let mut start = 0;
    while start < chords.len() {
        let (mut lo, mut hi) = (chords[start].0, chords[start].0);
        let mut end = start;
        while end < chords.len() && end - start < CHORDS_PER_GROUP {
            let (a, b) = chords[end];
            let nlo = Point2::new(lo.x.min(a.x).min(b.x), lo.y.min(a.y).min(b.y));
            let nhi = Point2::new(hi.x.max(a.x).max(b.x), hi.y.max(a.y).max(b.y));
            // Negated so that a NaN coordinate ends the group.
            if end > start && !(nhi.x - nlo.x <= span && nhi.y - nlo.y <= span) {
                break;
            }
            (lo, hi, end) = (nlo, nhi, end + 1);
        }
        groups.push((start, end));
        start = end;
    }
    groups
}

/// Most chords sharing one candidate list.
const CHORDS_PER_GROUP: usize = 16;

/// Largest extent of a group of chords, in grid steps.
const GROUP_SPAN: f64 = 8.0;

/// Closed loops from the grid chains, every chord refined (in parallel over
/// chords; the result does not depend on the number of threads).
pub(crate) fn refine_loops(probe: &Probe<'_>, chains: &[Vec<Point2>], chord_tolerance: f64, z: f64) -> Vec<Loop> {
    let chords: Vec<(Point2, Point2)> =
        chains.iter().flat_map(|c| (0..c.len()).map(move |i| (c[i], c[(i + 1) % c.len()]))).collect();
    let groups = chord_groups(&chords, probe.step);
    let long = long_chord(probe, chord_tolerance);
    let inserted: Vec<Vec<Point2>> = groups
        .par_iter()
        .map(|&(start, end)| {
            let group = &chords[start..end];
            // Probes stay within about one reach (the longest chord or a grid step) of the chords.
            let longest = group.iter().map(|(a, b)| (*a - *b).norm()).fold(probe.step, f64::max);
            let margin = CHORD_MARGIN * longest;
            let (mut lo, mut hi) = (group[0].0, group[0].0);
            for p in group.iter().flat_map(|(a, b)| [a, b]) {
                (lo, hi) = (Point2::new(lo.x.min(p.x), lo.y.min(p.y)), Point2::new(hi.x.max(p.x), hi.y.max(p.y)));
            }
            let local =
                probe.local(Point2::new(lo.x - margin, lo.y - margin), Point2::new(hi.x + margin, hi.y + margin));
            group
                .iter()
                .map(|&(a, b)| {
                    let mut out = Vec::new();
                    refine_chord(&local, (a, b), chord_tolerance, long, 0, &mut out);
                    out
                })
                .collect::<Vec<_>>()
        })
        .flatten()
        .collect();
    let mut loops = Vec::with_capacity(chains.len());
    let mut at = 0;
    for chain in chains {
        let mut points = Vec::with_capacity(chain.len());
        for (p, extra) in chain.iter().zip(&inserted[at..at + chain.len()]) {
            points.push(*p);
            points.extend_from_slice(extra);
        }
        at += chain.len();
        loops.push(Loop { z, points });
    }
    loops
}

#[cfg(test)]
mod tests {
    use scallop_cutter::{Cutter, CutterShape};
    use scallop_geom::{Point2, Point3};
    use scallop_mesh::{MeshIndex, TriMesh};

    use super::Probe;

    /// The side-only evaluation (pruned at z) gives the full one's side, and
    /// where the cutter cuts the same height and contact triangle, bit for
    /// bit: on a terrain with cliffs, every shape, levels through it, points
    /// inside the box and out.
    #[test]
    fn side_slot_gives_the_side_and_the_inside_heights() {
        let index = cliff_terrain();
        let (mut inside, mut outside) = (0, 0);
        for shape in [
            CutterShape::Flat { radius: 1.5 },
            CutterShape::Ball { radius: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 0.5 },
            CutterShape::Cone { radius: 2.0, half_angle: 0.5 },
        ] {
            let cutter = Cutter::new(shape, 30.0).expect("cutter");
            for z in [0.9, 2.35, 3.3, 5.6] {
                let probe = Probe { cutter: &cutter, index: &index, z, tolerance: 1e-7, step: 0.5 };
                for k in 0..400 {
                    let p = Point2::new(2.0 + (k % 20) as f64 * 0.41, 3.0 + (k / 20) as f64 * 0.33);
                    let (full, side) = (
                        probe.local(Point2::new(4.0, 5.0), Point2::new(9.0, 8.0)),
                        probe.local(Point2::new(4.0, 5.0), Point2::new(9.0, 8.0)),
                    );
                    let ((h, slot), (s, side_slot)) = (full.height_slot(p), side.side_slot(p));
                    assert_eq!(h > 0.0, s > 0.0, "{shape:?} z {z} at {p:?}: {h} vs {s}");
                    if h > 0.0 {
                        assert_eq!((h.to_bits(), slot), (s.to_bits(), side_slot), "{shape:?} z {z} at {p:?}");
                        inside += 1;
                    } else {
                        assert_eq!((s, side_slot), (0.0, None), "{shape:?} z {z} at {p:?}");
                        outside += 1;
                    }
                }
            }
        }
        assert!(inside > 500 && outside > 500, "both sides seen ({inside} inside, {outside} outside)");
    }

    /// A 6 x 6 grid of 3 mm squares whose corner heights step by 0.7 mm
    /// with 4 mm cliffs on every fifth diagonal, indexed.
    fn cliff_terrain() -> MeshIndex {
        let height =
            |i: usize, j: usize| ((i * 7 + j * 13) % 11) as f64 * 0.7 + if (i + j) % 5 == 0 { 4.0 } else { 0.0 };
        let at = |i: usize, j: usize| Point3::new(i as f64 * 3.0, j as f64 * 3.0, height(i, j));
        let mut soup = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                soup.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                soup.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        MeshIndex::build(&TriMesh::from_soup(&soup).expect("terrain").0)
    }

    /// The candidate list gives the index's heights (up to rounding), inside its box and out.
    #[test]
    fn local_heights_equal_the_index_heights() {
        let index = cliff_terrain();
        for shape in [
            CutterShape::Flat { radius: 1.5 },
            CutterShape::Ball { radius: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 0.5 },
            CutterShape::Cone { radius: 2.0, half_angle: 0.5 },
        ] {
            let cutter = Cutter::new(shape, 30.0).expect("cutter");
            let probe = Probe { cutter: &cutter, index: &index, z: 3.3, tolerance: 1e-7, step: 0.5 };
            let local = probe.local(Point2::new(4.0, 5.0), Point2::new(9.0, 8.0));
            for k in 0..400 {
                let p = Point2::new(2.0 + (k % 20) as f64 * 0.41, 3.0 + (k / 20) as f64 * 0.33);
                // Equal up to rounding: a shared edge is evaluated from its owning
                // triangle only (the index from both, in opposite directions); the
                // rounding level of coordinates up to 30 mm (the terrain is 18 mm wide).
                let (a, b) = (local.height(p), probe.height(p));
                assert!((a - b).abs() <= scallop_geom::tol::REL_ROUNDING * 30.0, "{shape:?} at {p:?}: {a} vs {b}");
            }
        }
    }
}
