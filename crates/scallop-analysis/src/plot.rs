//! Hand-written SVG plot of the `(mu, s)` decision plane (finishing.md 10, Fig. 2.4).

use crate::advisor::{AnalysisReport, Recommendation};
use crate::plane::critical_slope;
use crate::tol;

const WIDTH: f64 = 680.0;
const HEIGHT: f64 = 460.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 30.0;
const TOP: f64 = 50.0;
const BOTTOM: f64 = 60.0;
const BALL_FILL: &str = "#dbe9f6";
const TOROIDAL_FILL: &str = "#fde5cc";

/// An SVG image (a `String`, UTF-8) of the `(mu, s)` plane for the report's size
/// `chi~`, tools, machine and scallop height: the critical curve `s_c(mu)`, the two
/// decision regions (above the curve: ball along the principal direction; below:
/// toroidal along the steepest slope), and the part's point `(mu~, s~)`, labelled.
/// `mu` runs from 1 to `max(5, ceil(1.15 mu~))`, `s` from 0 to 90 degrees.
/// Deterministic (fixed decimals); never touches files.
///
/// ```
/// use scallop_analysis::{analyze, plot_svg, sample_patch, MachineLimits, ToolOptions};
/// let set = scallop_surface::builtin("choi").unwrap();
/// let samples = sample_patch(&set.patches()[0], &Default::default()).unwrap();
/// let report = analyze(&samples, &ToolOptions::default(), &MachineLimits::default(), 0.01).unwrap();
/// let svg = plot_svg(&report);
/// assert!(svg.starts_with("<svg") && svg.contains("s_c(μ)") && svg.trim_end().ends_with("</svg>"));
/// ```
#[must_use]
pub fn plot_svg(report: &AnalysisReport) -> String {
    let mu_max = (1.15 * report.shape_factor).ceil().max(5.0);
    let (plot_w, plot_h) = (WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM);
    let x = |mu: f64| LEFT + (mu.clamp(1.0, mu_max) - 1.0) / (mu_max - 1.0) * plot_w;
    let y = |deg: f64| TOP + (1.0 - deg.clamp(0.0, 90.0) / 90.0) * plot_h;
    let curve: Vec<(f64, f64)> = (0..tol::PLOT_CURVE_POINTS)
        .map(|k| {
            let mu = 1.0 + (mu_max - 1.0) * k as f64 / (tol::PLOT_CURVE_POINTS - 1) as f64;
            let s_c = critical_slope(mu, report.size_mm2, &report.tools, report.scallop_height_mm, &report.machine);
            (x(mu), y(s_c.to_degrees()))
        })
        .collect();
    let path: String = curve.iter().map(|(px, py)| format!("{px:.2},{py:.2}")).collect::<Vec<_>>().join(" ");

    let mut svg = String::new();
    let mut line = |text: String| {
        svg.push_str(&text);
        svg.push('\n');
    };
    line(format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    ));
    line(format!(r#"<rect x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#));
    line(format!(
        r#"<text x="{:.2}" y="22" text-anchor="middle" font-size="15">Tool choice: critical slope s_c(μ) for χ = {:.0} mm², sh = {} mm</text>"#,
        WIDTH / 2.0,
        report.size_mm2,
        report.scallop_height_mm
    ));
    // Regions: above the curve (ball) and below it (toroidal).
    let (x0, x1, y_top, y_bottom) = (x(1.0), x(mu_max), y(90.0), y(0.0));
    line(format!(
        r#"<polygon points="{x0:.2},{y_top:.2} {path} {x1:.2},{y_top:.2}" fill="{BALL_FILL}" stroke="none"/>"#
    ));
    line(format!(
        r#"<polygon points="{x0:.2},{y_bottom:.2} {path} {x1:.2},{y_bottom:.2}" fill="{TOROIDAL_FILL}" stroke="none"/>"#
    ));
    // Grid and ticks.
    let mu_step = if mu_max <= 10.0 { 1.0 } else { (mu_max / 10.0).ceil() };
    let mut mu = 1.0;
    while mu <= mu_max + 0.5 * mu_step {
        let px = x(mu);
        line(format!(
            r##"<line x1="{px:.2}" y1="{y_top:.2}" x2="{px:.2}" y2="{y_bottom:.2}" stroke="#bbbbbb" stroke-width="0.5"/>"##
        ));
        line(format!(r#"<text x="{px:.2}" y="{:.2}" text-anchor="middle">{mu}</text>"#, y_bottom + 18.0));
        mu += mu_step;
    }
    for deg in (0..=90).step_by(15) {
        let py = y(f64::from(deg));
        line(format!(
            r##"<line x1="{x0:.2}" y1="{py:.2}" x2="{x1:.2}" y2="{py:.2}" stroke="#bbbbbb" stroke-width="0.5"/>"##
        ));
        line(format!(r#"<text x="{:.2}" y="{:.2}" text-anchor="end">{deg}°</text>"#, x0 - 8.0, py + 4.0));
    }
    line(format!(
        r#"<rect x="{x0:.2}" y="{y_top:.2}" width="{plot_w:.2}" height="{plot_h:.2}" fill="none" stroke="black"/>"#
    ));
    line(format!(
        r#"<text x="{:.2}" y="{:.2}" text-anchor="middle">shape factor μ = w/h</text>"#,
        LEFT + plot_w / 2.0,
        HEIGHT - 15.0
    ));
    line(format!(
        r#"<text x="18" y="{:.2}" text-anchor="middle" transform="rotate(-90 18 {:.2})">slope s (degrees)</text>"#,
        TOP + plot_h / 2.0,
        TOP + plot_h / 2.0
    ));
    // Critical curve and region labels.
    line(format!(r#"<polyline points="{path}" fill="none" stroke="black" stroke-width="2"/>"#));
    if let Some(&(end_x, end_y)) = curve.last() {
        line(format!(r#"<text x="{:.2}" y="{:.2}" text-anchor="end">s_c(μ)</text>"#, end_x - 6.0, end_y - 8.0));
    }
    line(format!(
        r##"<text x="{:.2}" y="{:.2}" text-anchor="end" fill="#1f4e79">ball along the principal direction (s &gt; s_c)</text>"##,
        x1 - 8.0,
        y_top + 18.0
    ));
    line(format!(
        r##"<text x="{:.2}" y="{:.2}" text-anchor="end" fill="#8a4500">toroidal along the steepest slope (s &lt; s_c)</text>"##,
        x1 - 8.0,
        y_bottom - 10.0
    ));
    // The part: its point, the critical slope at its mu, and a label.
    let (mu_part, s_part) = (report.shape_factor, report.slope_deg);
    let (px, py, pc) = (x(mu_part), y(s_part), y(report.critical_slope_deg));
    line(format!(
        r##"<line x1="{px:.2}" y1="{py:.2}" x2="{px:.2}" y2="{pc:.2}" stroke="#c00000" stroke-width="1.5" stroke-dasharray="4 3"/>"##
    ));
    line(format!(r##"<circle cx="{px:.2}" cy="{py:.2}" r="5" fill="#c00000" stroke="black"/>"##));
    let verdict = match report.recommendation {
        Recommendation::BallAlongPrincipal => "ball along principal direction",
        Recommendation::ToroidalAlongSlope => "toroidal along steepest slope",
    };
    let (anchor, dx) = if px > LEFT + 0.45 * plot_w { ("end", -10.0) } else { ("start", 10.0) };
    let label_y = if py < y_top + 50.0 { py + 18.0 } else { py - 24.0 };
    line(format!(
        r##"<text x="{:.2}" y="{label_y:.2}" text-anchor="{anchor}" font-weight="bold" fill="#c00000">part: μ = {mu_part:.3}, s = {s_part:.2}°</text>"##,
        px + dx
    ));
    line(format!(
        r##"<text x="{:.2}" y="{:.2}" text-anchor="{anchor}" fill="#c00000">s_c(μ) = {:.2}° → {verdict}</text>"##,
        px + dx,
        label_y + 15.0,
        report.critical_slope_deg
    ));
    svg.push_str("</svg>\n");
    svg
}
