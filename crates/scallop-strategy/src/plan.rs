//! Parallel-planes finishing: passes by drop-cutter in vertical planes, plane
//! spacing from the local effective radius and the measured scallop, links.

use rayon::prelude::*;
use scallop_analysis::fold_direction_angle;
use scallop_cutter::{ClPoint, Contact, Cutter, CutterShape, drop_cutter, drop_points};
use scallop_geom::{Point2, Point3, Tolerances, Vec2, Vec3};
use scallop_mesh::MeshIndex;
use scallop_toolpath::{Move, MoveKind, Toolpath, simplify_above};

use crate::geometry::{Frame, PartBoundary, contact_normal, on_flat_bottom, slots_by_original};
use crate::scallop::{Curve, Measure, pair_heights};
use crate::{Boundary, FinishingParams, Pattern, Plane, StrategyError, ZoneRegion, tol};

/// A straight XY line `origin + t dir` along which the cutter is dropped.
#[derive(Debug, Clone, Copy)]
struct Line {
    origin: Point2,
    dir: Vec2,
}

impl Line {
    fn at(&self, t: f64) -> Point2 {
        self.origin + self.dir * t
    }
}

/// A point of a pass at abscissa `t`: a cutter location, or (`lift`) a point
/// above the CL surface where the pass steps over a jump of it (see
/// [`Planner::lift`]); lifts are no samples of the surface.
#[derive(Debug, Clone, Copy)]
struct Sample {
    t: f64,
    cl: ClPoint,
    lift: bool,
}

impl Sample {
    fn new(t: f64, cl: ClPoint) -> Sample {
        Sample { t, cl, lift: false }
    }
}

/// Everything the planner needs, computed once.
pub(crate) struct Planner<'a> {
    index: &'a MeshIndex,
    cutter: &'a Cutter,
    shape: CutterShape,
    model: scallop_analysis::Cutter,
    params: &'a FinishingParams,
    pub(crate) frame: Frame,
    slots: Vec<u32>,
    part_boundary: PartBoundary,
    region: Option<&'a ZoneRegion>,
    measure: Measure<'a>,
    raw_measure: Measure<'a>,
    floor: f64,
    sample_tol: f64,
    /// A chord whose midpoint lies farther than this below the CL surface is
    /// split ([`tol::GOUGE_MIDPOINT_SHARE`] of `sample_tol`).
    gouge_tol: f64,
    simplify_tol: f64,
    /// The scallop height the spacing holds (`params.scallop_height`).
    sh: f64,
    boundary_tol: f64,
    min_step: f64,
    /// Shortest step of the gouge bisection (see [`tol::GOUGE_MIDPOINT_SHARE`]).
    gouge_step: f64,
    pub(crate) d_range: [f64; 2],
    pub(crate) feed_samples: Vec<f64>,
    pub(crate) drops: usize,
    /// While bridging a gap between two ranges (see [`Planner::bridge`]): the
    /// feed interval in which any contact with the part counts as inside.
    bridge_span: Option<[f64; 2]>,
    /// Where no spacing holds `sh`, keep the spacing rule's gap instead of
    /// failing (the stock simulation then tells rest material from scallop).
    pub(crate) tolerate_rest: bool,
}

/// One plane with its passes and the samples the spacing rule reads.
pub(crate) struct PlanePasses {
    pub(crate) plane: Plane,
    samples: Vec<ClPoint>,
    curves: Vec<Curve>,
    /// The largest height (mm) by which a merged chord rides above a point it
    /// replaced: the material under it adds to the scallop between the feed
    /// samples where the pair is measured.
    lift: f64,
}

impl<'a> Planner<'a> {
    pub(crate) fn new(
        index: &'a MeshIndex,
        cutter: &'a Cutter,
        params: &'a FinishingParams,
        tol_: &Tolerances,
        region: Option<&'a ZoneRegion>,
    ) -> Result<Planner<'a>, StrategyError> {
        params.validate()?;
        if !(tol_.path.is_finite() && tol_.path >= tol::MIN_PATH_TOLERANCE) {
            return Err(StrategyError::BadParameter {
                name: "tolerances.path",
                value: tol_.path,
                fix: "give a chordal tolerance of at least 1e-4 mm (e.g. 0.01)",
            });
        }
        let shape = *cutter.shape();
        let sh = params.scallop_height;
        let (model, bound, what) = spacing_model(&shape);
        if sh >= bound {
            return Err(StrategyError::ScallopTooLarge { scallop_height: sh, what, radius: bound });
        }
        let frame = Frame::new(params.direction);
        // Cutter locations with a contact lie within R of the part.
        let reach = match params.boundary {
            Boundary::ContactInside => cutter.radius(),
        };
        let (mut t_range, mut d_range) = ([f64::INFINITY, f64::NEG_INFINITY], [f64::INFINITY, f64::NEG_INFINITY]);
        for slot in 0..index.len() {
            if region.is_some_and(|r| !r.contains_triangle(index.original_index(slot))) {
                continue;
            }
            for p in index.corners(slot) {
                let (t, d) = (frame.t(p), frame.d(p));
                t_range = [t_range[0].min(t), t_range[1].max(t)];
                d_range = [d_range[0].min(d), d_range[1].max(d)];
            }
        }
        if t_range[0] > t_range[1] {
            return Err(StrategyError::EmptyRegion { direction_deg: params.direction.to_degrees() });
        }
        t_range = [t_range[0] - reach, t_range[1] + reach];
        d_range = [d_range[0] - reach, d_range[1] + reach];
        let span = t_range[1] - t_range[0];
        let steps = (span / params.max_step).ceil().max(1.0);
        // The work, bounded before it is spent: the fewest passes (flat-surface spacing)
        // times the forward samples of each.
        let width = d_range[1] - d_range[0];
        let passes = (width / model.max_step_over(sh).min(2.0 * cutter.radius())).ceil().max(1.0);
        let estimate = passes * (steps + 1.0);
        if !(steps <= tol::MAX_PASS_SAMPLES && estimate <= tol::MAX_PLAN_SAMPLES) {
            return Err(StrategyError::TooMuchWork {
                passes,
                samples: steps + 1.0,
                estimate,
                span,
                max_step: params.max_step,
                budget: tol::MAX_PLAN_SAMPLES,
            });
        }
        // INVARIANT: span / max_step is finite and positive, so steps fits a usize.
        let n = steps as usize;
        let feed_samples = (0..=n).map(|k| t_range[0] + span * (k as f64 / steps)).collect();
        let bounds = index.bounds();
        let end_margin = zone_end_margin(cutter, region);
        let gouge_tol = tol::GOUGE_MIDPOINT_SHARE * tol::SAMPLING_SHARE * tol_.path;
        let min_step = params.max_step * tol::MIN_STEP_FRACTION;
        let simplify_tol = (tol::PASS_SIMPLIFY_SHARE * tol_.path).min(tol::MERGE_SCALLOP_SHARE * sh);
        Ok(Planner {
            index,
            cutter,
            shape,
            model,
            params,
            frame,
            slots: slots_by_original(index),
            part_boundary: PartBoundary::new(index),
            region,
            measure: Measure { end_margin, ..Measure::new(index, cutter, params.direction, sh) },
            raw_measure: Measure { refine: false, end_margin, ..Measure::new(index, cutter, params.direction, sh) },
            floor: bounds.min.z - bounds.diagonal() - 1.0,
            sample_tol: tol::SAMPLING_SHARE * tol_.path,
            gouge_tol,
            simplify_tol,
            sh,
            boundary_tol: tol::BOUNDARY_SHARE * tol_.path,
            min_step,
            gouge_step: (gouge_tol * gouge_tol / (2.0 * cutter.radius())).min(min_step),
            d_range,
            feed_samples,
            drops: 0,
            bridge_span: None,
            tolerate_rest: false,
        })
    }

    /// Indices of the points kept by merging nearly collinear ones: one-sided
    /// (`simplify_above`), a kept chord never passes below a removed point and
    /// lies at most `PASS_SIMPLIFY_SHARE * path` above it (vertically: a pass or a
    /// link runs along one XY line). The merged chord is then never below the
    /// sampled polyline, which keeps the sampling's bound below the CL surface.
    fn merge(&self, points: &[Point3]) -> Vec<usize> {
        simplify_above(points, self.simplify_tol)
    }

    /// The points to insert before `b` where the chord from `a` to `b`, a step
    /// of at most `gouge_step`, still lies below the CL surface at `mid` by more
    /// than `gouge_tol`: the CL surface jumps there (a wall, the foot of a
    /// steep arc). The pass climbs vertically at `a` to the highest of the three
    /// cutter locations, moves level to above `b` and descends vertically to it;
    /// over a step this short the CL surface varies by at most `gouge_tol`
    /// outside its jumps (a circular arc of radius up to the cutter radius `R`
    /// rises by `sqrt(2 R step)` at most).
    fn lift(a: &Point3, mid: &Point3, b: &Point3) -> [Option<Point3>; 2] {
        let top = a.z.max(mid.z).max(b.z);
        [(top > a.z).then(|| Point3::new(a.x, a.y, top)), (top > b.z).then(|| Point3::new(b.x, b.y, top))]
    }

    fn drop_at(&mut self, xy: Point2) -> ClPoint {
        self.drops += 1;
        drop_cutter(self.cutter, self.index, xy, self.floor)
    }

    fn is_inside(&self, cl: &ClPoint, _scratch: &mut Vec<u32>) -> bool {
        if let Some([t0, t1]) = self.bridge_span {
            let t = self.frame.t(&cl.tip);
            // Any contact with the part (its open boundary too), within the
            // span, and within the zone when planning one.
            return !matches!(cl.contact, Contact::Floor)
                && t >= t0
                && t <= t1
                && self.region.is_none_or(|r| r.contains_contact(self.index, &self.slots, cl));
        }
        match self.params.boundary {
            Boundary::ContactInside => {
                self.part_boundary.is_interior_contact(self.index, &self.slots, cl)
                    && self.region.is_none_or(|r| r.contains_contact(self.index, &self.slots, cl))
            }
        }
    }

    /// The last inside sample between an inside sample and an outside abscissa.
    fn bisect(&mut self, line: &Line, mut inside: Sample, mut outside: f64, scratch: &mut Vec<u32>) -> Sample {
        while (outside - inside.t).abs() > self.boundary_tol {
            let t = 0.5 * (inside.t + outside);
            let cl = self.drop_at(line.at(t));
            if self.is_inside(&cl, scratch) {
                inside = Sample::new(t, cl);
            } else {
                outside = t;
            }
        }
        inside
    }

    /// Appends the samples after `a` up to `b` (both inside), bisecting a step
    /// while the CL midpoint is farther than the sampling tolerance from the
    /// chord, or the CL surface lies above the chord by more than `gouge_tol`
    /// at its middle or quarter points (down to `gouge_step`, then a
    /// [`Planner::lift`]); `None` marks a gap where a point left the region.
    /// `known` is the CL point at the middle when already dropped.
    fn refine(
        &mut self,
        line: &Line,
        a: Sample,
        b: Sample,
        known: Option<Sample>,
        out: &mut Vec<Option<Sample>>,
        scratch: &mut Vec<u32>,
    ) {
        let length = b.t - a.t;
        if length <= self.gouge_step {
            out.push(Some(b));
            return;
        }
        let t = 0.5 * (a.t + b.t);
        let mid = known.unwrap_or_else(|| Sample::new(t, self.drop_at(line.at(t))));
        if !self.is_inside(&mid.cl, scratch) {
            let end = self.bisect(line, a, mid.t, scratch);
            if end.t > a.t {
                self.refine(line, a, end, None, out, scratch);
            }
            out.push(None);
            let start = self.bisect(line, b, mid.t, scratch);
            out.push(Some(start));
            if b.t > start.t {
                self.refine(line, start, b, None, out, scratch);
            }
            return;
        }
        let (chordal, below) = self.split_tests(&mid.cl.tip, &a.cl.tip, &b.cl.tip, length);
        if chordal || below {
            self.refine(line, a, mid, None, out, scratch);
            self.refine(line, mid, b, None, out, scratch);
            return;
        }
        if length > self.min_step {
            // The quarter points: a CL surface with an inflection inside the
            // step can cross the chord at its middle and still rise above it.
            let quarters = [0.75 * a.t + 0.25 * b.t, 0.25 * a.t + 0.75 * b.t];
            let [q1, q3] = quarters.map(|t| Sample::new(t, self.drop_at(line.at(t))));
            let rises = |q: &Sample, f: f64| q.cl.tip.z - (a.cl.tip.z + f * (b.cl.tip.z - a.cl.tip.z)) > self.gouge_tol;
            if rises(&q1, 0.25) || rises(&q3, 0.75) {
                self.refine(line, a, mid, Some(q1), out, scratch);
                self.refine(line, mid, b, Some(q3), out, scratch);
                return;
            }
        }
        if gouge_depth(&mid.cl.tip, &a.cl.tip, &b.cl.tip) > self.gouge_tol {
            for (end, p) in [a, b].iter().zip(Self::lift(&a.cl.tip, &mid.cl.tip, &b.cl.tip)) {
                if let Some(p) = p {
                    out.push(Some(Sample { t: end.t, cl: ClPoint { tip: p, contact: end.cl.contact }, lift: true }));
                }
            }
        }
        out.push(Some(b));
    }

    /// Whether a step of `length` from `a` to `b` with the CL point `mid` at
    /// its middle is split: (chordal) the midpoint is farther than the sampling
    /// tolerance from the chord and the step longer than `min_step`; (below)
    /// the chord passes more than `gouge_tol` below the midpoint and the step is
    /// longer than `gouge_step` (on a part of the CL surface concave over the
    /// step, the chord then lies at most `2 gouge_tol = sample_tol` below it
    /// anywhere: the deepest point is at most twice the midpoint's depth).
    fn split_tests(&self, mid: &Point3, a: &Point3, b: &Point3, length: f64) -> (bool, bool) {
        let chordal = length > self.min_step && vertical_gap(mid, a, b) > self.sample_tol;
        let below = length > self.gouge_step && gouge_depth(mid, a, b) > self.gouge_tol;
        (chordal, below)
    }

    /// Like [`Planner::refine`] for links: every point must have a contact
    /// (on the CL surface); `None` when one has not.
    fn refine_link(
        &mut self,
        line: &Line,
        a: Sample,
        b: Sample,
        known: Option<Sample>,
        out: &mut Vec<Point3>,
    ) -> Option<()> {
        let length = b.t - a.t;
        if length > self.gouge_step {
            let t = 0.5 * (a.t + b.t);
            let mid = known.unwrap_or_else(|| Sample::new(t, self.drop_at(line.at(t))));
            if matches!(mid.cl.contact, Contact::Floor) {
                return None;
            }
            let (chordal, below) = self.split_tests(&mid.cl.tip, &a.cl.tip, &b.cl.tip, length);
            if chordal || below {
                self.refine_link(line, a, mid, None, out)?;
                return self.refine_link(line, mid, b, None, out);
            }
            if length > self.min_step {
                let quarters = [0.75 * a.t + 0.25 * b.t, 0.25 * a.t + 0.75 * b.t];
                let [q1, q3] = quarters.map(|t| Sample::new(t, self.drop_at(line.at(t))));
                let rises =
                    |q: &Sample, f: f64| q.cl.tip.z - (a.cl.tip.z + f * (b.cl.tip.z - a.cl.tip.z)) > self.gouge_tol;
                if rises(&q1, 0.25) || rises(&q3, 0.75) {
                    self.refine_link(line, a, mid, Some(q1), out)?;
                    return self.refine_link(line, mid, b, Some(q3), out);
                }
            }
            if gouge_depth(&mid.cl.tip, &a.cl.tip, &b.cl.tip) > self.gouge_tol {
                out.extend(Self::lift(&a.cl.tip, &mid.cl.tip, &b.cl.tip).into_iter().flatten());
            }
        }
        out.push(b.cl.tip);
        Some(())
    }

    /// Samples the line on `ts` (in parallel), then refines: runs of inside samples.
    fn runs(&mut self, line: &Line, ts: &[f64]) -> Vec<Vec<Sample>> {
        let xys: Vec<Point2> = ts.iter().map(|&t| line.at(t)).collect();
        let cls = drop_points(self.cutter, self.index, &xys, self.floor);
        self.drops += cls.len();
        let mut scratch = Vec::new();
        let inside: Vec<bool> = cls.iter().map(|cl| self.is_inside(cl, &mut scratch)).collect();
        let mut marks: Vec<Option<Sample>> = Vec::new();
        let mut last: Option<Sample> = None;
        for (k, (&t, cl)) in ts.iter().zip(&cls).enumerate() {
            let s = Sample::new(t, *cl);
            match (inside[k], last) {
                (true, None) => {
                    let start = if k > 0 { self.bisect(line, s, ts[k - 1], &mut scratch) } else { s };
                    marks.push(Some(start));
                    if s.t > start.t {
                        self.refine(line, start, s, None, &mut marks, &mut scratch);
                    }
                    last = Some(s);
                }
                (true, Some(prev)) => {
                    self.refine(line, prev, s, None, &mut marks, &mut scratch);
                    last = Some(s);
                }
                (false, Some(prev)) => {
                    let end = self.bisect(line, prev, t, &mut scratch);
                    if end.t > prev.t {
                        self.refine(line, prev, end, None, &mut marks, &mut scratch);
                    }
                    marks.push(None);
                    last = None;
                }
                (false, None) => {}
            }
        }
        let mut runs = Vec::new();
        let mut current = Vec::new();
        for m in marks {
            match m {
                Some(s) => current.push(s),
                None => {
                    if current.len() >= 2 {
                        runs.push(std::mem::take(&mut current));
                    }
                    current.clear();
                }
            }
        }
        if current.len() >= 2 {
            runs.push(current);
        }
        runs
    }

    /// The passes of the plane at offset `d`.
    pub(crate) fn plane(&mut self, d: f64) -> PlanePasses {
        let line = Line { origin: self.frame.xy(0.0, d), dir: self.frame.f };
        let ts = self.feed_samples.clone();
        let runs = self.runs(&line, &ts);
        let mut passes = Vec::with_capacity(runs.len());
        let mut samples = Vec::new();
        let mut lift = 0.0_f64;
        for run in runs {
            let points: Vec<Point3> = run.iter().map(|s| s.cl.tip).collect();
            let kept = self.merge(&points);
            lift = lift.max(merge_lift(&points, &kept));
            passes.push(kept.iter().map(|&i| points[i]).collect::<Vec<_>>());
            samples.extend(run.iter().filter(|s| !s.lift).map(|s| s.cl));
        }
        let curves = passes.iter().map(|p: &Vec<Point3>| Curve::new(&self.frame, p)).collect();
        PlanePasses { plane: Plane { offset: d, passes }, samples, curves, lift }
    }

    /// NEXT_SPACING (finishing.md 6.4): the smallest horizontal plane spacing
    /// over the samples of the plane, `sod_i |c_i . m|`, with the place.
    fn spacing(&self, plane: &PlanePasses) -> Option<(f64, Point2)> {
        let sh = self.sh;
        let m = Vec3::new(self.frame.m.x, self.frame.m.y, 0.0);
        let mut best: Option<(f64, Point2)> = None;
        for cl in &plane.samples {
            let n = contact_normal(&self.shape, self.index, &self.slots, cl);
            if self.rides_sharp_edge(cl, &n) {
                continue;
            }
            let delta = spacing_at(&self.shape, &self.model, sh, &n, self.params.direction, &m);
            if best.is_none_or(|(b, _)| delta < b) {
                best = Some((delta, Point2::new(cl.tip.x, cl.tip.y)));
            }
        }
        best
    }

    /// Whether the cutter at `cl` rolls over a sharp convex edge or vertex of
    /// the mesh: an edge or vertex contact whose cutter normal `n` leans more
    /// than [`tol::SHARP_EDGE_DEG`] from the contacted facet's normal. There
    /// the part has no surface between passes to leave a scallop on (every
    /// pass touches the same edge), so the contact does not set the spacing;
    /// the measured scallop still checks the pair. A flat bottom resting on
    /// the edge or vertex has the normal +Z whatever triangle owns the feature
    /// (the top corner of a vertical wall: the wall's normal would otherwise
    /// set a spacing near zero, [`on_flat_bottom`]).
    fn rides_sharp_edge(&self, cl: &ClPoint, n: &Vec3) -> bool {
        let triangle = match cl.contact {
            Contact::Vertex { triangle, .. } | Contact::Edge { triangle, .. } => triangle,
            Contact::Floor | Contact::Facet { .. } => return false,
        };
        let n = if on_flat_bottom(&self.shape, cl) { Vec3::z() } else { *n };
        self.slots
            .get(triangle)
            .is_some_and(|&slot| self.index.normal(slot as usize).dot(&n) < tol::SHARP_EDGE_DEG.to_radians().cos())
    }

    /// Largest measured scallop between two planes at the feed samples.
    fn measured(&self, a: &PlanePasses, b: &PlanePasses, refine: bool) -> (f64, Point2) {
        let measure = if refine { &self.measure } else { &self.raw_measure };
        let chunks: Vec<(f64, Point2)> = self
            .feed_samples
            .par_chunks(16)
            .map(|ts| {
                let hs = pair_heights(measure, &a.curves, &b.curves, ts);
                hs.into_iter()
                    .fold((0.0, Point2::origin()), |acc, c| if c.height > acc.0 { (c.height, c.at) } else { acc })
            })
            .collect();
        let (h, at) = chunks.into_iter().fold((0.0, Point2::origin()), |acc, h| if h.0 > acc.0 { h } else { acc });
        (h + a.lift.max(b.lift), at)
    }

    /// Per feed sample, the largest measured scallop between two planes
    /// (0 where none, or where `skip` is set: rest) with its place, and the
    /// merged chords' lift of the pair (added to every sample's height).
    fn measured_samples(
        &self,
        a: &PlanePasses,
        b: &PlanePasses,
        refine: bool,
        skip: &[bool],
    ) -> (Vec<(f64, Point2)>, f64) {
        let measure = if refine { &self.measure } else { &self.raw_measure };
        let heights = self
            .feed_samples
            .par_chunks(16)
            .zip(skip.par_chunks(16))
            .flat_map_iter(|(ts, skip)| {
                ts.iter()
                    .zip(skip)
                    .map(|(t, &skip)| {
                        let cusps = if skip {
                            Vec::new()
                        } else {
                            pair_heights(measure, &a.curves, &b.curves, std::slice::from_ref(t))
                        };
                        cusps
                            .into_iter()
                            .fold((0.0, Point2::origin()), |m, c| if c.height > m.0 { (c.height, c.at) } else { m })
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        (heights, a.lift.max(b.lift))
    }

    /// The next plane after the last one at `d`: from `next` at `gap`, the gap
    /// shrinks until the measured scallop holds `sh` at every feed sample
    /// that is not rest material. With rest tolerated, a sample is rest when
    /// its residual at any try exceeds [`tol::REST_RESIDUAL_FACTOR`] `sh`, or
    /// does not fall as the gap shrinks ([`is_rest`]: the foot of a wall, a
    /// corner: no spacing removes it); near rest the gap is
    /// at most `rest_gap`, and a gap shrunk for samples found rest later goes
    /// back up to it (at most the first gap). The other samples of the pair still hold `sh`: a
    /// rest place on one section does not leave the rest of the pair to the
    /// spacing rule, whose model of a plane is optimistic on convex or
    /// faceted surface, most for a bull-nose whose contact lies far from its
    /// axis (docs/validation.md, issue 15, "Rest on one section").
    /// `current` is the plane at `d`. Returns whether it holds, the gap and
    /// the plane there.
    ///
    /// # Errors
    /// [`StrategyError::Unreachable`] when the gap falls under
    /// [`tol::MIN_SPACING`] without rest tolerated.
    fn hold(
        &mut self,
        current: &PlanePasses,
        d: f64,
        gap: f64,
        next: PlanePasses,
        rest_gap: f64,
    ) -> Result<(bool, f64, PlanePasses), StrategyError> {
        let (sh, tolerate_rest, samples) = (self.sh, self.tolerate_rest, self.feed_samples.len());
        let mut probe = PlaneProbe { planner: self, current, d, next };
        let outcome = search_gap(sh, tolerate_rest, samples, gap, rest_gap, &mut probe);
        let next = probe.next;
        match outcome {
            GapSearch::Held(gap) => Ok((true, gap, next)),
            GapSearch::Empty(gap) | GapSearch::NotHeld(gap) => Ok((false, gap, next)),
            GapSearch::Unreachable(gap, place) => Err(self.unreachable(gap, place)),
        }
    }

    fn unreachable(&self, spacing: f64, at: Point2) -> StrategyError {
        StrategyError::Unreachable { x: at.x, y: at.y, spacing, scallop_height: self.params.scallop_height }
    }

    /// The offset between `empty` (a plane without passes) and `full` (with
    /// passes) where passes begin, to the boundary tolerance; returns the plane
    /// on the `full` side.
    fn edge(&mut self, mut empty: f64, full: PlanePasses) -> PlanePasses {
        let mut full = full;
        while (full.plane.offset - empty).abs() > self.boundary_tol {
            let mid = self.plane(0.5 * (empty + full.plane.offset));
            if mid.plane.passes.is_empty() {
                empty = mid.plane.offset;
            } else {
                full = mid;
            }
        }
        full
    }

    /// The plane sweep (finishing.md 6.5 with half-spacing margins, see the crate
    /// docs): ranges of offsets with passes are found by scanning at `max_step`;
    /// in each, the first plane lies half its spacing inside the first edge, each
    /// next plane one spacing further (shrunk until the measured scallop holds),
    /// and the last within half its spacing of the far edge.
    pub(crate) fn sweep(&mut self) -> Result<Vec<PlanePasses>, StrategyError> {
        let sh = self.sh;
        let [d_lo, d_hi] = self.d_range;
        let cap = self.model.max_step_over(sh).min(2.0 * self.cutter.radius());
        let mut planes: Vec<PlanePasses> = Vec::new();
        let mut empty = d_lo;
        'ranges: loop {
            // Scan for the next plane with passes.
            let mut probe = empty;
            let found = loop {
                probe += self.params.max_step;
                if probe > d_hi {
                    break None;
                }
                let p = self.plane(probe);
                if !p.plane.passes.is_empty() {
                    break Some(p);
                }
                empty = probe;
            };
            let Some(found) = found else { break 'ranges };
            let edge = self.edge(empty, found);
            let edge_offset = edge.plane.offset;
            // First plane: half its own spacing inside the edge (fixed point).
            let mut delta = cap;
            let mut first = edge;
            for _ in 0..tol::FIRST_PLANE_ITERATIONS {
                let candidate = self.plane(edge_offset + 0.5 * delta);
                if candidate.plane.passes.is_empty() {
                    break;
                }
                let spacing = self.spacing(&candidate).map_or(delta, |(s, _)| s);
                first = candidate;
                if spacing >= delta {
                    break;
                }
                delta = spacing.max(tol::MIN_SPACING);
            }
            if let Some(previous) = planes.pop() {
                // The planes between two ranges have no passes: the cutter would
                // ride on the part's open boundary there. Bridge the gap when
                // the surface between the ranges is left above sh.
                let bridged = self.bridge(previous, &first)?;
                planes.extend(bridged);
            }
            planes.push(first);
            loop {
                // INVARIANT: a plane was pushed above.
                let current = planes.last().expect("a plane of this range");
                let d = current.plane.offset;
                let (spacing, at) = self.spacing(current).unwrap_or((delta, self.frame.xy(0.0, d)));
                let spacing = match spacing {
                    s if s >= tol::MIN_SPACING => s,
                    _ if self.tolerate_rest => tol::REST_SPACING_SHARE * cap,
                    s => return Err(self.unreachable(s, at)),
                };
                // With rest tolerated, a residual many times sh at the rule's
                // spacing is rest material between the passes (the foot of a
                // wall that the waterline levels finish, a corner), not a
                // scallop: creeping on at tiny spacings would multiply the
                // planes, so near rest the next plane goes at most a share of
                // the largest step-over away (the other sections of the pair
                // still hold sh, see `hold`) and the simulation reports what
                // is left.
                let rest_gap = (tol::REST_SPACING_SHARE * cap).min(spacing);
                delta = spacing;
                let mut gap = spacing;
                let mut next = self.plane(d + gap);
                if next.plane.passes.is_empty() {
                    let here = self.plane(d);
                    let far = self.edge(d + gap, here);
                    let end = far.plane.offset;
                    if end - d <= 0.5 * spacing + self.boundary_tol {
                        empty = d + gap;
                        continue 'ranges;
                    }
                    gap = end - 0.5 * spacing - d;
                    next = self.plane(d + gap);
                    if next.plane.passes.is_empty() {
                        empty = d + gap;
                        continue 'ranges;
                    }
                }
                // INVARIANT: as above.
                let current = planes.last().expect("a plane of this range");
                let (accepted, held_gap, held) = self.hold(current, d, gap, next, rest_gap)?;
                (gap, next) = (held_gap, held);
                if !accepted {
                    if !self.tolerate_rest {
                        return Err(self.unreachable(gap, at));
                    }
                    // At the rule's own gap (a residual called rest on the
                    // first try) `next` is that plane already.
                    if rest_gap.to_bits() != gap.to_bits() {
                        next = self.plane(d + rest_gap);
                    }
                    if next.plane.passes.is_empty() {
                        empty = d + rest_gap;
                        continue 'ranges;
                    }
                }
                planes.push(next);
            }
        }
        if planes.is_empty() {
            return Err(StrategyError::EmptyRegion { direction_deg: self.params.direction.to_degrees() });
        }
        Ok(planes)
    }

    /// `planes` (in increasing offset, as [`Self::sweep`] gives them) with a
    /// plane at each offset of `extra` that has passes and is not already
    /// within the boundary tolerance of one (see [`crate::Refinement`]).
    pub(crate) fn with_planes(&mut self, mut planes: Vec<PlanePasses>, extra: &[f64]) -> Vec<PlanePasses> {
        for &d in extra {
            if !d.is_finite() || planes.iter().any(|p| (p.plane.offset - d).abs() <= self.boundary_tol) {
                continue;
            }
            let plane = self.plane(d);
            if plane.plane.passes.is_empty() {
                continue;
            }
            let at = planes.partition_point(|p| p.plane.offset < d);
            planes.insert(at, plane);
        }
        planes
    }

    /// The planes from `previous` (the last plane of a range, returned first)
    /// up to the first plane `next` of the following range (excluded) such that
    /// every pair of neighbours holds `sh` by the refined measure. Between two
    /// ranges no cutter location has an interior contact (the cutter rides on
    /// the part's open boundary), yet the surface between the ranges' passes may
    /// stand above `sh` (a raised edge that only the boundary-riding cutter
    /// reaches). The bridge planes accept any contact with the part (in the zone,
    /// when planning one), within the
    /// feed span of the two neighbours' passes widened by the cutter radius: the
    /// cutter only lowers material there (every CL point is a drop-cutter
    /// point, so no gouge) and the final verification covers the new pairs.
    ///
    /// # Errors
    /// [`StrategyError::Unreachable`] when no spacing above
    /// [`tol::MIN_SPACING`] holds `sh` between bridge planes.
    fn bridge(&mut self, previous: PlanePasses, next: &PlanePasses) -> Result<Vec<PlanePasses>, StrategyError> {
        let sh = self.sh;
        let (h, _) = self.measured(&previous, next, true);
        if h <= sh {
            return Ok(vec![previous]);
        }
        let radius = self.cutter.radius();
        let (mut t0, mut t1) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in previous.plane.passes.iter().chain(&next.plane.passes).flatten() {
            let t = self.frame.t(p);
            t0 = t0.min(t);
            t1 = t1.max(t);
        }
        self.bridge_span = Some([t0 - radius, t1 + radius]);
        let result = self.bridge_planes(previous, next);
        self.bridge_span = None;
        result
    }

    fn bridge_planes(&mut self, previous: PlanePasses, next: &PlanePasses) -> Result<Vec<PlanePasses>, StrategyError> {
        let sh = self.sh;
        let end = next.plane.offset;
        let mut out = vec![previous];
        loop {
            // INVARIANT: `out` starts with `previous`.
            let current = out.last().expect("the previous plane");
            let d = current.plane.offset;
            let (h, at) = self.measured(current, next, true);
            if h <= sh {
                return Ok(out);
            }
            let (spacing, _) = self.spacing(current).unwrap_or((end - d, at));
            let mut gap = spacing.min(end - d).max(tol::MIN_SPACING);
            let mut accepted = None;
            for retry in 0..tol::MAX_SPACING_RETRIES {
                let candidate = self.plane(d + gap);
                // INVARIANT: as above.
                let current = out.last().expect("the previous plane");
                let (h, place) = if candidate.plane.passes.is_empty() {
                    (f64::INFINITY, at)
                } else {
                    self.measured(current, &candidate, true)
                };
                if h <= sh {
                    accepted = Some(candidate);
                    break;
                }
                let ratio = if h.is_finite() { (sh / h).sqrt() * tol::SPACING_SAFETY } else { 0.5 };
                gap *= if retry == 0 { ratio } else { ratio.min(tol::SPACING_MIN_SHRINK) };
                if gap < tol::MIN_SPACING {
                    if self.tolerate_rest {
                        return Ok(out);
                    }
                    return Err(self.unreachable(gap, place));
                }
            }
            let Some(candidate) = accepted else {
                if self.tolerate_rest {
                    return Ok(out);
                }
                return Err(self.unreachable(gap, at));
            };
            out.push(candidate);
        }
    }

    /// CL points of a straight link from `a` to `b` on the CL surface (every
    /// drop-cutter point has a contact), or `None` when the cutter would touch
    /// nothing somewhere along it.
    fn link(&mut self, a: &Point3, b: &Point3) -> Option<Vec<Point3>> {
        let v = Vec2::new(b.x - a.x, b.y - a.y);
        let len = v.norm();
        if len <= self.min_step {
            return Some(vec![*b]);
        }
        let line = Line { origin: Point2::new(a.x, a.y), dir: v / len };
        let steps = (len / self.params.max_step).ceil().max(1.0);
        // INVARIANT: finite positive.
        let n = steps as usize;
        let ts: Vec<f64> = (0..=n).map(|k| len * (k as f64 / steps)).collect();
        let xys: Vec<Point2> = ts.iter().map(|&t| line.at(t)).collect();
        let cls = drop_points(self.cutter, self.index, &xys, self.floor);
        self.drops += cls.len();
        if cls.iter().any(|cl| matches!(cl.contact, Contact::Floor)) {
            return None;
        }
        let mut points = vec![cls[0].tip];
        for k in 1..=n {
            let (p, q) = (Sample::new(ts[k - 1], cls[k - 1]), Sample::new(ts[k], cls[k]));
            self.refine_link(&line, p, q, None, &mut points)?;
        }
        // The ends are the pass ends (same drop, same point); keep them exact.
        if let Some(first) = points.first_mut() {
            *first = *a;
        }
        if let Some(last) = points.last_mut() {
            *last = *b;
        }
        let kept = self.merge(&points);
        Some(kept.iter().skip(1).map(|&i| points[i]).collect())
    }

    /// Orders the passes (zigzag or one-way) and joins them into a toolpath.
    pub(crate) fn toolpath(&mut self, planes: &[PlanePasses]) -> (Toolpath, usize, usize) {
        let params = self.params;
        let mut path = Toolpath::new(params.machine.feed * 60.0);
        path.plunge_feed = params.plunge_feed * 60.0;
        let clear = self.index.bounds().max.z + params.clearance;
        let mut ordered: Vec<Vec<Point3>> = Vec::new();
        let mut parity = false;
        for plane in planes.iter().filter(|p| !p.plane.passes.is_empty()) {
            let mut passes = plane.plane.passes.clone();
            if parity && params.pattern == Pattern::Zigzag {
                passes.reverse();
                for p in &mut passes {
                    p.reverse();
                }
            }
            ordered.extend(passes);
            parity = !parity;
        }
        let (mut links, mut retracts) = (0, 0);
        for (i, pass) in ordered.iter().enumerate() {
            let (Some(start), Some(end)) = (pass.first(), pass.last()) else { continue };
            if i == 0 {
                path.push(Move::new(MoveKind::Rapid, Point3::new(start.x, start.y, clear)));
                path.push(Move::new(MoveKind::Plunge, *start));
            }
            for p in &pass[1..] {
                path.push(Move::new(MoveKind::Feed, *p));
            }
            let Some(next) = ordered.get(i + 1).and_then(|p| p.first()) else {
                path.push(Move::new(MoveKind::Retract, Point3::new(end.x, end.y, clear)));
                continue;
            };
            let link = if params.pattern == Pattern::Zigzag { self.link(end, next) } else { None };
            if let Some(points) = link {
                links += 1;
                for p in points {
                    path.push(Move::new(MoveKind::Link, p));
                }
            } else {
                retracts += 1;
                path.push(Move::new(MoveKind::Retract, Point3::new(end.x, end.y, clear)));
                path.push(Move::new(MoveKind::Rapid, Point3::new(next.x, next.y, clear)));
                path.push(Move::new(MoveKind::Plunge, *next));
            }
        }
        (path, links, retracts)
    }
}

/// Sections this close to a pass end are not measured (see `Measure::end_margin`):
/// the cutter radius in zone planning, where passes end inside the part; 0 otherwise.
/// What the gap search of [`Planner::hold`] asks of the planes: the plane at
/// a gap from the last one, and the measured scallops between the two.
trait GapProbe {
    /// Puts the next plane at `gap`; false when it has no passes.
    fn move_to(&mut self, gap: f64) -> bool;
    /// Per feed sample, the scallop between the last plane and the next (0
    /// where `rest` is set), and the pair's lift ([`Planner::measured_samples`]).
    fn measure(&mut self, refine: bool, rest: &[bool]) -> (Vec<(f64, Point2)>, f64);
}

/// The planes of one sweep step, as the gap search sees them.
struct PlaneProbe<'p, 'a> {
    planner: &'p mut Planner<'a>,
    current: &'p PlanePasses,
    d: f64,
    next: PlanePasses,
}

impl GapProbe for PlaneProbe<'_, '_> {
    fn move_to(&mut self, gap: f64) -> bool {
        self.next = self.planner.plane(self.d + gap);
        !self.next.plane.passes.is_empty()
    }

    fn measure(&mut self, refine: bool, rest: &[bool]) -> (Vec<(f64, Point2)>, f64) {
        self.planner.measured_samples(self.current, &self.next, refine, rest)
    }
}

/// How the gap search of [`Planner::hold`] ended, with the last gap.
#[derive(Debug, Clone, Copy, PartialEq)]
enum GapSearch {
    /// The scallop holds `sh` at every sample that is not rest.
    Held(f64),
    /// The plane at the gap has no passes.
    Empty(f64),
    /// Out of tries, or under [`tol::MIN_SPACING`] with rest tolerated.
    NotHeld(f64),
    /// Under [`tol::MIN_SPACING`] without rest tolerated, at this place.
    Unreachable(f64, Point2),
}

/// The gap search of [`Planner::hold`] (see there), on `samples` feed
/// samples from the gap `gap`, the probe's plane being already at it.
fn search_gap(
    sh: f64,
    tolerate_rest: bool,
    samples: usize,
    mut gap: f64,
    rest_gap: f64,
    probe: &mut impl GapProbe,
) -> GapSearch {
    let mut rest = vec![false; samples];
    let mut last_try: Option<(f64, Vec<(f64, Point2)>)> = None;
    let widest = gap.min(rest_gap);
    for retry in 0..tol::MAX_SPACING_RETRIES {
        let (heights, lift) = probe.measure(retry >= tol::RAW_RETRIES, &rest);
        let mut found_rest = false;
        if tolerate_rest {
            for (i, &(h, _)) in heights.iter().enumerate() {
                let before = last_try.as_ref().map(|(g, hp)| (*g, hp[i].0));
                if !rest[i] && is_rest(h, lift, sh, gap, before) {
                    rest[i] = true;
                    found_rest = true;
                }
            }
        }
        // Near rest the planes keep at most the rest gap; a gap shrunk
        // for sections now found to be rest goes back up to it.
        if found_rest && gap.to_bits() != widest.to_bits() {
            gap = widest;
            if !probe.move_to(gap) {
                return GapSearch::Empty(gap);
            }
            last_try = None;
            continue;
        }
        let (h, place) = heights
            .iter()
            .zip(&rest)
            .filter(|&(_, &r)| !r)
            .fold((0.0, Point2::origin()), |m, (&(h, at), _)| if h > m.0 { (h, at) } else { m });
        let h = h + lift;
        if h <= sh {
            return GapSearch::Held(gap);
        }
        // Scallop ~ gap^2; after a first exact-ratio try, shrink by at
        // least SPACING_MIN_SHRINK per retry (curvature, rest material).
        let ratio = if h.is_finite() { (sh / h).sqrt() * tol::SPACING_SAFETY } else { 0.5 };
        let first = last_try.is_none();
        last_try = Some((gap, heights));
        gap *= if first { ratio } else { ratio.min(tol::SPACING_MIN_SHRINK) };
        if gap < tol::MIN_SPACING {
            if tolerate_rest {
                break;
            }
            return GapSearch::Unreachable(gap, place);
        }
        probe.move_to(gap);
    }
    GapSearch::NotHeld(gap)
}

pub(crate) fn zone_end_margin(cutter: &Cutter, region: Option<&ZoneRegion>) -> f64 {
    region.map_or(0.0, |_| cutter.radius())
}

/// Whether a section's residual `h` (mm, plus the pair's chord `lift`)
/// measured at `gap` is rest material rather than a scallop, with rest
/// tolerated; `before` is the gap and residual of the previous try (the gap
/// only shrinks from the spacing rule's). A scallop grows with the square of
/// the gap, so a residual above [`tol::REST_RESIDUAL_FACTOR`] `sh` at any try
/// is rest; so is one that does not fall as the gap shrinks: one that grows
/// (it held, or was lower, at the wider gap: its cusp lies on other material
/// than between the passes), or keeps more than half its height when the gap
/// is more than halved (a scallop would fall to a quarter). Without the
/// first two a section could shrink the gap until the passes nearly
/// coincided (docs/validation.md, "idler_riser regressions traced").
fn is_rest(h: f64, lift: f64, sh: f64, gap: f64, before: Option<(f64, f64)>) -> bool {
    if h + lift <= sh {
        return false;
    }
    let not_falling = before.is_some_and(|(g, hp)| h > hp || (gap < 0.5 * g && hp + lift > sh && h > 0.5 * hp));
    h > tol::REST_RESIDUAL_FACTOR * sh || not_falling
}

/// Vertical distance of the CL point `mid`, dropped at the XY midpoint of `a`
/// and `b`, from their chord. Gouges are heights (the stock simulation measures
/// stock below part vertically), and on a steep pass the vertical gap is the
/// perpendicular distance divided by the cosine of the slope.
/// The largest vertical height of a kept chord above a point it replaced
/// (`kept` from [`simplify_above`] on `points`).
fn merge_lift(points: &[Point3], kept: &[usize]) -> f64 {
    let mut lift = 0.0_f64;
    for w in kept.windows(2) {
        let (a, b) = (&points[w[0]], &points[w[1]]);
        let ab = b - a;
        let len2 = ab.xy().norm_squared();
        for p in &points[w[0] + 1..w[1]] {
            let t = if len2 > 0.0 { ((p - a).xy().dot(&ab.xy()) / len2).clamp(0.0, 1.0) } else { 0.0 };
            lift = lift.max(a.z + ab.z * t - p.z);
        }
    }
    lift
}

fn vertical_gap(mid: &Point3, a: &Point3, b: &Point3) -> f64 {
    (mid.z - 0.5 * (a.z + b.z)).abs()
}

/// How far the CL point `mid`, dropped at the XY midpoint of `a` and `b`, lies
/// above their chord (negative: below it). A straight move between two exact
/// cutter locations gouges only where the CL surface rises above it: on convex
/// crests and at the top of steep descents.
fn gouge_depth(mid: &Point3, a: &Point3, b: &Point3) -> f64 {
    mid.z - 0.5 * (a.z + b.z)
}

/// The start spacing of a cone (V) cutter of half angle `alpha` across a
/// plane of slope `slope` for a scallop `sh`: the ridge between two grooves
/// is a triangle on the surface whose base angles are `90° - alpha -+ slope`,
/// so its base is `sh (tan(alpha + slope) + tan(alpha - slope))`. Where the
/// uphill flank is flatter than the surface (`alpha + slope >= 90°`) the rim
/// cuts, as with a flat end: `sh / sin(slope)`. The measured scallop corrects
/// either start.
fn cone_step(sh: f64, slope: f64, alpha: f64) -> f64 {
    if alpha + slope < std::f64::consts::FRAC_PI_2 - 1e-9 {
        sh * ((alpha + slope).tan() + (alpha - slope).tan())
    } else {
        sh / slope.sin().max(1e-9)
    }
}

/// The horizontal plane spacing the rule gives at a contact of unit normal `n`
/// for passes in `direction` (rad from +X; `m` the unit horizontal normal of the
/// planes): the step-over `sod` of the cutter's model at the contact's slope and
/// feed angle, with the sharp-rim and V rules of the flat end and the cone,
/// projected to the planes' normal (finishing.md 6.4).
fn spacing_at(
    shape: &CutterShape,
    model: &scallop_analysis::Cutter,
    sh: f64,
    n: &Vec3,
    direction: f64,
    m: &Vec3,
) -> f64 {
    let slope = n.z.abs().min(1.0).acos();
    let horizontal = n.x.hypot(n.y);
    let alpha = if horizontal < tol::HORIZONTAL_XY { 0.0 } else { fold_direction_angle(n.y.atan2(n.x) - direction) };
    let mut sod = model.step_over(sh, slope, alpha);
    if let CutterShape::Flat { radius } = *shape {
        // A sharp rim leaves a saw tooth, not a circle: start from sh / sin s
        // (the measured scallop corrects it); never more than the diameter.
        let sin_s = slope.sin();
        if sin_s > 0.0 {
            sod = sod.max(sh / sin_s);
        }
        sod = sod.min(2.0 * radius);
    }
    if let CutterShape::Cone { radius, half_angle } = *shape {
        // The V's ridge lies in the section across the feed, whose slope is
        // atan(tan s |sin alpha|) (0 when feeding down the slope).
        let across = (slope.tan() * alpha.sin().abs()).atan();
        sod = cone_step(sh, if across.is_nan() { slope } else { across }, half_angle).min(2.0 * radius);
    }
    let tau = m.cross(n);
    let cross = if tau.norm() > 0.0 { n.cross(&(tau / tau.norm())) } else { Vec3::zeros() };
    let factor = if cross.norm() > 0.0 { (cross / cross.norm()).dot(m).abs() } else { 0.0 };
    sod * factor
}

/// The spacing model of a cutter: the step-over rule's cutter, and the radius
/// the scallop height must stay below (with its name).
fn spacing_model(shape: &CutterShape) -> (scallop_analysis::Cutter, f64, &'static str) {
    match *shape {
        CutterShape::Ball { radius } => (scallop_analysis::Cutter::Ball { radius }, radius, "radius"),
        CutterShape::Bull { radius, corner } => {
            (scallop_analysis::Cutter::Toroidal { radius, corner }, corner, "corner radius")
        }
        // A flat end is the torus with r = 0 in Eq. 1.5 (R / sin s along the slope);
        // a cone is planned from the sharp-tip rule, the torus only caps the step.
        CutterShape::Flat { radius } | CutterShape::Cone { radius, .. } => {
            (scallop_analysis::Cutter::Toroidal { radius, corner: 0.0 }, radius, "radius")
        }
    }
}

/// The start spacing of parallel planes at a surface point of unit normal
/// `normal` (mm, horizontal, across planes in `direction` rad from +X), by the
/// planner's own rule before any scallop is measured: the cheap estimate of
/// a plan (`scallop run --plan-only`). `f64::INFINITY` where the planes run
/// along the normal's horizontal part (no spacing limit there).
#[must_use]
pub fn rule_spacing(shape: &CutterShape, scallop_height: f64, normal: &Vec3, direction: f64) -> f64 {
    let (model, _, _) = spacing_model(shape);
    let m = Vec3::new(-direction.sin(), direction.cos(), 0.0);
    let delta = spacing_at(shape, &model, scallop_height, normal, direction, &m);
    let cap = model.max_step_over(scallop_height).min(2.0 * shape.radius());
    if delta > 0.0 { delta.min(cap) } else { cap }
}

#[cfg(test)]
mod cone_tests {
    use super::cone_step;

    /// On a flat floor the ridge between two V grooves `w` apart is `w / (2 tan alpha)` high.
    #[test]
    fn cone_step_on_a_floor_is_twice_sh_tan_alpha() {
        for deg in [15.0_f64, 30.0, 45.0, 60.0] {
            let a = deg.to_radians();
            let w = cone_step(0.05, 0.0, a);
            assert!((w / (2.0 * a.tan()) - 0.05).abs() < 1e-12, "{deg}: {w}");
        }
        // Symmetric in the slope's sign, and growing with the slope below the rim limit.
        let a = 45f64.to_radians();
        assert!((cone_step(0.05, 0.2, a) - cone_step(0.05, -0.2, a)).abs() < 1e-12);
        assert!(cone_step(0.05, 0.3, a) > cone_step(0.05, 0.1, a));
    }
}

#[cfg(test)]
mod sharp_edge_tests {
    use scallop_cutter::{ClPoint, Contact, Cutter, CutterShape};
    use scallop_geom::{Point3, Tolerances};
    use scallop_mesh::{MeshIndex, TriMesh};

    use super::Planner;
    use crate::geometry::contact_normal;

    /// A block 20 x 20 x 10 mm with vertical walls.
    fn block() -> TriMesh {
        let c = |i: usize| {
            let pick = |bit: usize, hi: f64| if i & bit == 0 { 0.0 } else { hi };
            Point3::new(pick(1, 20.0), pick(2, 20.0), pick(4, 10.0))
        };
        let mut soup = Vec::new();
        for [a, b, cc, d] in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
            soup.push([c(a), c(b), c(cc)]);
            soup.push([c(a), c(cc), c(d)]);
        }
        TriMesh::from_soup(&soup).expect("block").0
    }

    /// A bull-nose whose flat bottom rests on the block's top corner touches a
    /// horizontal surface, whichever triangle owns the corner: a vertical
    /// wall's normal there would set a spacing near zero (issue 15,
    /// octagonal_pocket), so the contact counts as a sharp edge exactly when
    /// the owner is a wall; a contact on the torus keeps the torus normal.
    #[test]
    fn a_flat_bottom_on_the_top_corner_of_a_wall_rides_a_sharp_edge() {
        let params = crate::steep::tests::test_params();
        let mesh = block();
        let index = MeshIndex::build(&mesh);
        let corner = Point3::new(0.0, 0.0, 10.0);
        let (mut walls, mut tops) = (0, 0);
        for shape in [CutterShape::Bull { radius: 8.0, corner: 3.0 }, CutterShape::Ball { radius: 5.0 }] {
            let cutter = Cutter::new(shape, 30.0).expect("cutter");
            let planner =
                Planner::new(&index, &cutter, &params, &Tolerances { path: 0.01, gouge: 0.0 }, None).expect("planner");
            for slot in 0..index.len() {
                let triangle = index.original_index(slot);
                if !mesh.triangle(triangle).contains(&corner) {
                    continue;
                }
                // The tip 3.6 mm inside the corner over the top face, at its height.
                let cl =
                    ClPoint { tip: Point3::new(2.0, 3.0, 10.0), contact: Contact::Vertex { triangle, point: corner } };
                let n = contact_normal(&shape, &index, &planner.slots, &cl);
                let wall = index.normal(slot).z.abs() < 1e-12;
                let sharp = planner.rides_sharp_edge(&cl, &n);
                if matches!(shape, CutterShape::Bull { .. }) {
                    assert_eq!(sharp, wall, "triangle {triangle}: normal {n:?}");
                    walls += usize::from(wall);
                    tops += usize::from(!wall);
                } else {
                    // The ball's own normal at this tip points from its centre.
                    let expect = (Point3::new(2.0, 3.0, 15.0) - corner).normalize();
                    assert!((n - expect).norm() < 1e-12);
                }
            }
        }
        assert!(walls > 0 && tops > 0, "the corner is shared by walls ({walls}) and the top ({tops})");
    }
}

#[cfg(test)]
mod rest_tests {
    use scallop_geom::Point2;

    use super::{GapProbe, GapSearch, is_rest, search_gap};
    use crate::tol;

    const SH: f64 = 0.01;

    /// A section that held at the wider gap and shows a residual many times
    /// sh once the gap shrank (its cusp moved onto other material) is rest:
    /// shrinking on for it left planes a few um apart (idler_riser with the
    /// bull-nose, docs/validation.md, "idler_riser regressions traced").
    #[test]
    fn a_residual_that_grows_as_the_gap_shrinks_is_rest() {
        assert!(is_rest(0.3 * tol::REST_RESIDUAL_FACTOR * SH, 0.0, SH, 0.06, Some((0.23, 0.8 * SH))));
        // Just over sh and growing a little while the gap shrank by 10 %.
        assert!(is_rest(1.2 * SH, 0.0, SH, 0.9 * 0.2, Some((0.2, 1.1 * SH))));
    }

    /// The residual factor holds at every try, not only at the spacing rule's
    /// gap: the gap only shrinks from it, so a scallop could only be lower.
    #[test]
    fn a_residual_many_times_sh_is_rest_at_any_try() {
        let h = 1.25 * tol::REST_RESIDUAL_FACTOR * SH;
        // Falling, but the gap shrank by less than half: not stalled.
        assert!(is_rest(h, 0.0, SH, 0.15, Some((0.2, 1.5 * tol::REST_RESIDUAL_FACTOR * SH))));
        assert!(is_rest(h, 0.0, SH, 0.2, None));
    }

    /// A scallop falls with the square of the gap: never rest, at any gap,
    /// from a first residual under the factor; nor a residual that holds sh.
    #[test]
    fn a_scallop_falling_with_the_square_of_the_gap_is_not_rest() {
        let (g0, h0) = (0.4, 0.9 * tol::REST_RESIDUAL_FACTOR * SH);
        assert!(!is_rest(h0, 0.0, SH, g0, None));
        let mut before = (g0, h0);
        for shrink in [0.9, 0.5, 0.3, 0.1] {
            let gap = before.0 * shrink;
            let h = before.1 * shrink * shrink;
            assert!(!is_rest(h, 0.0, SH, gap, Some(before)), "{gap} {h}");
            before = (gap, h);
        }
        assert!(!is_rest(0.5 * SH, 0.0, SH, 0.1, Some((0.2, 0.1 * SH))));
    }

    /// Planes as functions of the gap: sample i's scallop is `scallop[i](gap)`.
    struct Planes {
        gap: f64,
        scallop: Vec<fn(f64) -> f64>,
        /// Gaps from which the plane has no passes.
        empty_from: f64,
        moves: Vec<f64>,
    }

    impl GapProbe for Planes {
        fn move_to(&mut self, gap: f64) -> bool {
            self.gap = gap;
            self.moves.push(gap);
            gap < self.empty_from
        }

        fn measure(&mut self, _refine: bool, rest: &[bool]) -> (Vec<(f64, Point2)>, f64) {
            let at = Point2::origin();
            (self.scallop.iter().zip(rest).map(|(f, &r)| (if r { 0.0 } else { f(self.gap) }, at)).collect(), 0.0)
        }
    }

    /// A scallop that holds sh at gaps up to 0.35 mm (falling with the gap's square).
    fn scallop(gap: f64) -> f64 {
        SH * (gap / 0.35).powi(2)
    }

    /// A residual of 5 sh at 0.4 mm that grows as the gap shrinks: rest found late.
    fn growing(gap: f64) -> f64 {
        5.0 * SH * 0.4 / gap
    }

    /// A section found to be rest only after the gap shrank for it: the gap
    /// goes back up to the rest gap, where the other sections hold sh, instead
    /// of staying at the shrunk gap (planes crept a few um apart on
    /// idler_riser, docs/validation.md, "idler_riser regressions traced").
    #[test]
    fn a_gap_shrunk_for_rest_found_late_goes_back_up_to_the_rest_gap() {
        let mut planes =
            Planes { gap: 0.4, scallop: vec![scallop, growing], empty_from: f64::INFINITY, moves: Vec::new() };
        let outcome = search_gap(SH, true, 2, 0.4, 0.3, &mut planes);
        assert_eq!(outcome, GapSearch::Held(0.3), "moves {:?}", planes.moves);
        // It shrank first (the growth shows only on the second try).
        assert!(planes.moves[0] < 0.3, "moves {:?}", planes.moves);
        // Without rest tolerated the same planes are refused, at the growing section.
        let mut planes =
            Planes { gap: 0.4, scallop: vec![scallop, growing], empty_from: f64::INFINITY, moves: Vec::new() };
        assert!(matches!(search_gap(SH, false, 2, 0.4, 0.3, &mut planes), GapSearch::Unreachable(..)));
        // Where the plane at the rest gap has no passes, the search says so.
        let mut planes = Planes { gap: 0.4, scallop: vec![scallop, growing], empty_from: 0.25, moves: Vec::new() };
        assert_eq!(search_gap(SH, true, 2, 0.4, 0.3, &mut planes), GapSearch::Empty(0.3));
    }

    /// Sections that are all scallops: the gap shrinks until they hold, as
    /// without rest, and never goes back up.
    #[test]
    fn scallops_alone_shrink_the_gap_until_they_hold() {
        let mut planes =
            Planes { gap: 0.5, scallop: vec![scallop, scallop], empty_from: f64::INFINITY, moves: Vec::new() };
        let GapSearch::Held(gap) = search_gap(SH, true, 2, 0.5, 0.45, &mut planes) else {
            panic!("{:?}", planes.moves)
        };
        assert!(gap <= 0.35 && gap > 0.3, "gap {gap}");
        assert!(planes.moves.windows(2).all(|w| w[1] < w[0]), "moves {:?}", planes.moves);
    }
}
