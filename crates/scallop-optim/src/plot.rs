//! SVG pictures of a study: convergence curves and the zones of a plan. Pure
//! functions returning text; the caller writes the files.

use std::fmt::Write as _;

use crate::study::{PlanReport, Study};

const WIDTH: f64 = 640.0;
const HEIGHT: f64 = 480.0;
const MARGIN: f64 = 60.0;

/// A distinct colour for index `i` (golden-ratio hues).
fn colour(i: usize) -> String {
    #[allow(clippy::cast_precision_loss)]
    let hue = (i as f64 * 137.507_764).rem_euclid(360.0);
    format!("hsl({hue:.1},65%,{}%)", if i.is_multiple_of(2) { 50 } else { 38 })
}

/// The best time against the budget spent, one step line per `K`
/// (`convergence.svg`).
///
/// ```
/// # use scallop_optim::study::*;
/// # use scallop_optim::{HistoryPoint, StopReason};
/// # let plan = PlanReport { time_s: 9.0, transition_time_s: 0.0, violation: 0.0, grid: [1, 1], labels: vec![0], cell_xy: vec![[0.0, 0.0]], zones: vec![] };
/// # let r = KResult { k: 2, f0: 10.0, f_best: 9.0, eta: 0.1, evaluations: 5, surrogate_evaluations: 0, spent: 5.0,
/// #   stop: StopReason::Budget, wall_time_s: None, black_box_times: None, start: Design::zeros(2), best: Design::zeros(2), plan,
/// #   history: vec![HistoryPoint { spent: 1.0, best: 10.0 }, HistoryPoint { spent: 5.0, best: 9.0 }] };
/// # let study = Study { settings: StudySettings::thesis(Formulation::ThreeAxis), results: vec![r], best: 0, mean_eta: 0.1 };
/// let svg = scallop_optim::convergence_svg(&study);
/// assert!(svg.starts_with("<svg") && svg.contains("K = 2"));
/// ```
#[must_use]
pub fn convergence_svg(study: &Study) -> String {
    let points = study.results.iter().flat_map(|r| r.history.iter());
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut spent_max: f64 = 1.0;
    for p in points {
        if p.best.is_finite() {
            lo = lo.min(p.best);
            hi = hi.max(p.best);
        }
        spent_max = spent_max.max(p.spent);
    }
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    if hi - lo < 1e-9 * hi.abs().max(1.0) {
        hi = lo + 1.0;
    }
    let pad = 0.05 * (hi - lo);
    let (lo, hi) = (lo - pad, hi + pad);
    let x = |s: f64| MARGIN + (s / spent_max) * (WIDTH - 2.0 * MARGIN);
    let y = |v: f64| HEIGHT - MARGIN - (v - lo) / (hi - lo) * (HEIGHT - 2.0 * MARGIN);
    let mut svg = String::new();
    let _ = write!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{}\" y=\"24\" text-anchor=\"middle\" font-size=\"14\">Best predicted machining time vs black-box-equivalent evaluations ({:?})</text>\n",
        WIDTH / 2.0,
        study.settings.formulation
    );
    let (x0, x1, y0, y1) = (MARGIN, WIDTH - MARGIN, HEIGHT - MARGIN, MARGIN);
    let _ = writeln!(svg, "<path d=\"M{x0},{y1} L{x0},{y0} L{x1},{y0}\" fill=\"none\" stroke=\"black\"/>");
    for i in 0..=4 {
        let f = f64::from(i) / 4.0;
        let (v, s) = (lo + f * (hi - lo), f * spent_max);
        let _ = writeln!(svg, "<text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{v:.1}</text>", x0 - 6.0, y(v) + 4.0);
        let _ = writeln!(svg, "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">{s:.0}</text>", x(s), y0 + 18.0);
    }
    let _ = writeln!(
        svg,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">evaluations</text>\n<text x=\"16\" y=\"{}\" transform=\"rotate(-90 16 {})\" text-anchor=\"middle\">time (s)</text>",
        WIDTH / 2.0,
        HEIGHT - 16.0,
        HEIGHT / 2.0,
        HEIGHT / 2.0
    );
    for (i, r) in study.results.iter().enumerate() {
        let mut d = String::new();
        let mut last: Option<f64> = None;
        for p in r.history.iter().filter(|p| p.best.is_finite()) {
            match last {
                None => {
                    let _ = write!(d, "M{:.1},{:.1}", x(p.spent), y(p.best));
                }
                Some(prev) => {
                    let _ = write!(d, " L{:.1},{:.1} L{:.1},{:.1}", x(p.spent), y(prev), x(p.spent), y(p.best));
                }
            }
            last = Some(p.best);
        }
        let c = colour(i);
        let _ = writeln!(svg, "<path d=\"{d}\" fill=\"none\" stroke=\"{c}\" stroke-width=\"1.5\"/>");
        #[allow(clippy::cast_precision_loss)]
        let ly = MARGIN + 16.0 * i as f64;
        let _ = writeln!(
            svg,
            "<line x1=\"{}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"{c}\" stroke-width=\"2\"/><text x=\"{}\" y=\"{}\">K = {}: {:.1} s</text>",
            x1 - 120.0,
            x1 - 100.0,
            x1 - 95.0,
            ly + 4.0,
            r.k,
            r.f_best
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// The zones of a plan seen from above (XY): one square per clustering cell
/// at its surface point, one colour per zone, an arrow per zone along its
/// feed direction (`zones.svg`). In 3+2 the directions are in each zone's
/// rotated frame, so the arrows are indicative only.
///
/// ```
/// # use scallop_optim::study::*;
/// let plan = PlanReport { time_s: 9.0, transition_time_s: 0.0, violation: 0.0, grid: [2, 1],
///     labels: vec![0, 1], cell_xy: vec![[0.0, 0.0], [1.0, 0.0]], zones: vec![] };
/// let svg = scallop_optim::zones_svg(&plan, "test");
/// assert_eq!(svg.matches("<rect").count(), 3); // background + 2 cells
/// ```
#[must_use]
pub fn zones_svg(plan: &PlanReport, title: &str) -> String {
    let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &plan.cell_xy {
        for i in 0..2 {
            min[i] = min[i].min(p[i]);
            max[i] = max[i].max(p[i]);
        }
    }
    if !min[0].is_finite() {
        (min, max) = ([0.0; 2], [1.0; 2]);
    }
    let span = (max[0] - min[0]).max(max[1] - min[1]).max(1e-9);
    let scale = (HEIGHT - 2.0 * MARGIN) / span;
    let px = |x: f64| MARGIN + (x - min[0]) * scale;
    let py = |y: f64| HEIGHT - MARGIN - (y - min[1]) * scale;
    #[allow(clippy::cast_precision_loss)]
    let cell = (span / (plan.grid[0].max(plan.grid[1]).max(1) as f64) * scale * 1.6).max(1.0);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{MARGIN}\" y=\"22\" font-size=\"14\">{title}: {} zones, {:.1} s</text>\n\
         <text x=\"{MARGIN}\" y=\"40\" font-size=\"11\">top view (X right, Y up); arrows: feed direction of each zone</text>",
        plan.zones.len(),
        plan.time_s
    );
    for (p, &l) in plan.cell_xy.iter().zip(&plan.labels) {
        let _ = writeln!(
            svg,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{cell:.1}\" height=\"{cell:.1}\" fill=\"{}\"/>",
            px(p[0]) - cell / 2.0,
            py(p[1]) - cell / 2.0,
            colour(l as usize)
        );
    }
    let arrow = 0.08 * span * scale;
    for z in &plan.zones {
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
        for (p, &l) in plan.cell_xy.iter().zip(&plan.labels) {
            if l as usize == z.zone {
                sx += p[0];
                sy += p[1];
                n += 1.0;
            }
        }
        if n == 0.0 {
            continue;
        }
        let (cx, cy) = (px(sx / n), py(sy / n));
        let (s, c) = z.theta_deg.to_radians().sin_cos();
        let (dx, dy) = (c * arrow, -s * arrow);
        let _ = writeln!(
            svg,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\" stroke-width=\"2\"/>\
             <circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"black\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\">{}</text>",
            cx - dx,
            cy - dy,
            cx + dx,
            cy + dy,
            cx + dx,
            cy + dy,
            cx + 4.0,
            cy - 4.0,
            z.zone
        );
    }
    svg.push_str("</svg>\n");
    svg
}
