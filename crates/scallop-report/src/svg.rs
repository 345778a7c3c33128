//! Inline SVG plots: line charts (feed along the path, convergence curves)
//! and bar charts (scallop histogram, per-zone times). Text is escaped;
//! numbers have fixed decimals, so the output is deterministic.

use std::fmt::Write;

use crate::tol;

/// Plot width and height (SVG user units).
const W: f64 = 640.0;
const H: f64 = 300.0;
/// Margins: left, right, top, bottom.
const M: [f64; 4] = [64.0, 16.0, 30.0, 44.0];

/// Colours of successive series.
const SERIES: [&str; 6] = ["#888888", "#1f5fc8", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"];

/// One series of a line chart.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend.
    pub name: String,
    /// Points (x, y), x increasing.
    pub points: Vec<[f64; 2]>,
    /// Draw as steps (hold y until the next x).
    pub steps: bool,
}

/// Escapes text for HTML and SVG.
#[must_use]
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A "nice" tick step for a span (1, 2 or 5 times a power of ten).
fn tick_step(span: f64) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    p * if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    }
}

fn decimals(step: f64) -> usize {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small non-negative count")]
    let d = (-step.log10().floor()).max(0.0) as usize;
    d.min(9)
}

/// Reduces a series to the minimum and maximum of [`tol::MAX_PLOT_BUCKETS`] buckets of x.
#[must_use]
pub fn reduce(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = points.len();
    if n <= 2 * tol::MAX_PLOT_BUCKETS {
        return points.to_vec();
    }
    let mut out = Vec::with_capacity(2 * tol::MAX_PLOT_BUCKETS + 2);
    let per = n.div_ceil(tol::MAX_PLOT_BUCKETS);
    for bucket in points.chunks(per) {
        let (mut lo, mut hi) = (0usize, 0usize);
        for (k, p) in bucket.iter().enumerate() {
            if p[1] < bucket[lo][1] {
                lo = k;
            }
            if p[1] > bucket[hi][1] {
                hi = k;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(bucket[a]);
        if b != a {
            out.push(bucket[b]);
        }
    }
    out
}

fn frame(out: &mut String, title: &str, x_label: &str, y_label: &str, xr: Option<[f64; 2]>, yr: [f64; 2]) {
    let _ = write!(
        out,
        "<svg viewBox=\"0 0 {W} {H}\" class=\"plot\" role=\"img\">\
         <title>{t}</title><text x=\"{cx}\" y=\"18\" text-anchor=\"middle\" class=\"pt\">{t}</text>",
        t = escape(title),
        cx = W / 2.0
    );
    let (x0, x1, y0, y1) = (M[0], W - M[1], M[2], H - M[3]);
    let _ = write!(out, "<rect x=\"{x0}\" y=\"{y0}\" width=\"{}\" height=\"{}\" class=\"pf\"/>", x1 - x0, y1 - y0);
    let axes: Vec<(usize, [f64; 2])> = xr.map(|r| (0, r)).into_iter().chain([(1, yr)]).collect();
    for (axis, range) in axes {
        let step = tick_step(range[1] - range[0]);
        let d = decimals(step);
        let mut v = (range[0] / step).ceil() * step;
        let mut guard = 0;
        while v <= range[1] + 1e-9 * step && guard < 50 {
            let label = format!("{:.*}", d, v + 0.0);
            if axis == 0 {
                let x = x0 + (v - range[0]) / (range[1] - range[0]) * (x1 - x0);
                let _ = write!(
                    out,
                    "<line x1=\"{x:.1}\" y1=\"{y0}\" x2=\"{x:.1}\" y2=\"{y1}\" class=\"pg\"/>\
                     <text x=\"{x:.1}\" y=\"{ty}\" text-anchor=\"middle\">{label}</text>",
                    ty = y1 + 16.0
                );
            } else {
                let y = y1 - (v - range[0]) / (range[1] - range[0]) * (y1 - y0);
                let _ = write!(
                    out,
                    "<line x1=\"{x0}\" y1=\"{y:.1}\" x2=\"{x1}\" y2=\"{y:.1}\" class=\"pg\"/>\
                     <text x=\"{tx}\" y=\"{ty:.1}\" text-anchor=\"end\">{label}</text>",
                    tx = x0 - 6.0,
                    ty = y + 4.0
                );
            }
            v += step;
            guard += 1;
        }
    }
    let _ = write!(
        out,
        "<text x=\"{cx}\" y=\"{by}\" text-anchor=\"middle\">{xl}</text>\
         <text transform=\"translate(14 {cy}) rotate(-90)\" text-anchor=\"middle\">{yl}</text>",
        cx = 0.5 * (x0 + x1),
        by = H - 6.0,
        xl = escape(x_label),
        cy = 0.5 * (y0 + y1),
        yl = escape(y_label)
    );
}

fn range(values: impl Iterator<Item = f64>, from_zero: bool) -> [f64; 2] {
    let (mut lo, mut hi) = (if from_zero { 0.0 } else { f64::INFINITY }, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return [0.0, 1.0];
    }
    if hi - lo <= 0.0 {
        return [lo - 0.5, hi + 0.5];
    }
    [lo, hi + 0.05 * (hi - lo)]
}

/// A line chart of `series` (each reduced by [`reduce`]).
#[must_use]
pub fn line_chart(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> String {
    let reduced: Vec<Vec<[f64; 2]>> = series.iter().map(|s| reduce(&s.points)).collect();
    let xr = range(reduced.iter().flatten().map(|p| p[0]), false);
    let xr = [xr[0], xr[1].max(xr[0])];
    let yr = range(reduced.iter().flatten().map(|p| p[1]), true);
    let mut out = String::new();
    frame(&mut out, title, x_label, y_label, Some(xr), yr);
    let (x0, x1, y0, y1) = (M[0], W - M[1], M[2], H - M[3]);
    let sx = |x: f64| x0 + (x - xr[0]) / (xr[1] - xr[0]) * (x1 - x0);
    let sy = |y: f64| y1 - (y - yr[0]) / (yr[1] - yr[0]) * (y1 - y0);
    for (k, (s, pts)) in series.iter().zip(&reduced).enumerate() {
        let colour = SERIES[k % SERIES.len()];
        let mut d = String::new();
        let mut last_y: Option<f64> = None;
        for p in pts.iter().filter(|p| p[0].is_finite() && p[1].is_finite()) {
            let (x, y) = (sx(p[0]), sy(p[1]));
            match last_y {
                None => {
                    let _ = write!(d, "M{x:.1} {y:.1}");
                }
                Some(ly) if s.steps => {
                    let _ = write!(d, "L{x:.1} {ly:.1}L{x:.1} {y:.1}");
                }
                Some(_) => {
                    let _ = write!(d, "L{x:.1} {y:.1}");
                }
            }
            last_y = Some(y);
        }
        let _ = write!(out, "<path d=\"{d}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.2\"/>");
    }
    let names: Vec<&str> = series.iter().map(|s| s.name.as_str()).collect();
    for item in legend(&names) {
        let colour = SERIES[item.index % SERIES.len()];
        let _ = write!(
            out,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"12\" height=\"3\" fill=\"{colour}\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\">{}</text>",
            item.x,
            item.y - 5.0,
            item.x + 16.0,
            item.y,
            escape(&item.text)
        );
    }
    out.push_str("</svg>");
    out
}

/// Width of one character of the plots' 11-unit font, a generous average
/// (sans-serif glyphs average about 0.55 em).
const CHAR_WIDTH: f64 = 6.6;
/// Height of one legend row.
const LEGEND_ROW: f64 = 14.0;

/// One legend entry: the series, its text (shortened to fit) and the baseline
/// of its text; the colour swatch is drawn at `x`.
#[derive(Debug, Clone, PartialEq)]
struct LegendItem {
    index: usize,
    text: String,
    x: f64,
    y: f64,
}

/// The legend of a line chart inside its frame, in the top right corner:
/// rows of [`LEGEND_ROW`] while they fit the frame's height, then more
/// columns to the left; names shortened (with `…`) so that the columns fit
/// the frame's width.
fn legend(names: &[&str]) -> Vec<LegendItem> {
    let (x0, x1, y0, y1) = (M[0], W - M[1], M[2], H - M[3]);
    if names.is_empty() {
        return Vec::new();
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a few rows")]
    let rows = (((y1 - y0 - 8.0) / LEGEND_ROW).floor().max(1.0) as usize).min(names.len());
    let columns = names.len().div_ceil(rows);
    let longest = names.iter().map(|n| n.chars().count()).max().unwrap_or(0);
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let (columns_f, longest_f) = (columns as f64, longest as f64);
    // Each column: swatch 12, gap 4, text, gap 8; at most the frame's width less 8.
    let room = (x1 - x0 - 8.0) / columns_f;
    let column = (24.0 + CHAR_WIDTH * longest_f).min(room);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a few characters")]
    let chars = ((column - 24.0) / CHAR_WIDTH).floor().max(1.0) as usize;
    let left = x1 - 4.0 - columns_f * column;
    names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let text = if name.chars().count() > chars {
                name.chars().take(chars.saturating_sub(1)).chain(['…']).collect()
            } else {
                (*name).to_string()
            };
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let (col, row) = ((k / rows) as f64, (k % rows) as f64);
            LegendItem { index: k, text, x: left + col * column + 4.0, y: y0 + 15.0 + LEGEND_ROW * row }
        })
        .collect()
}

/// A bar chart: one bar per label.
#[must_use]
pub fn bar_chart(title: &str, x_label: &str, y_label: &str, labels: &[String], values: &[f64]) -> String {
    let n = labels.len().min(values.len()).max(1);
    let yr = range(values.iter().copied(), true);
    let mut out = String::new();
    #[allow(clippy::cast_precision_loss, reason = "bar counts far below 2^52")]
    let nf = n as f64;
    frame(&mut out, title, x_label, y_label, None, yr);
    let (x0, x1, y0, y1) = (M[0], W - M[1], M[2], H - M[3]);
    let bw = (x1 - x0) / nf;
    let label_every = n.div_ceil(12).max(1);
    for (k, (label, v)) in labels.iter().zip(values).enumerate() {
        #[allow(clippy::cast_precision_loss, reason = "bar counts far below 2^52")]
        let x = x0 + bw * k as f64;
        let h = ((v - yr[0]) / (yr[1] - yr[0]) * (y1 - y0)).max(0.0);
        let _ = write!(
            out,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{h:.1}\" fill=\"#1f5fc8\"><title>{}: {v}</title></rect>",
            x + 0.1 * bw,
            y1 - h,
            0.8 * bw,
            escape(label)
        );
        if k % label_every == 0 {
            let _ = write!(
                out,
                "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\" class=\"pl\">{}</text>",
                x + 0.5 * bw,
                y1 + 28.0,
                escape(label)
            );
        }
    }
    out.push_str("</svg>");
    out
}

#[cfg(test)]
mod tests {
    use super::{CHAR_WIDTH, H, LEGEND_ROW, M, W, legend};

    /// Every legend entry (swatch and text at the generous glyph width) stays
    /// inside the plot frame, for short, long and many series names, and no two
    /// entries overlap.
    #[test]
    fn legends_stay_inside_their_frames() {
        let (x0, x1, y0, y1) = (M[0], W - M[1], M[2], H - M[3]);
        let long = "a series name much longer than any legend column could ever hold in a plot";
        for (count, name) in [(1, "K = 2"), (3, long), (9, "K = 10"), (40, "zone 12 (3+2)"), (64, long)] {
            let names: Vec<String> = (0..count).map(|k| format!("{name} {k}")).collect();
            let refs: Vec<&str> = names.iter().map(String::as_str).collect();
            let items = legend(&refs);
            assert_eq!(items.len(), count);
            for it in &items {
                #[allow(clippy::cast_precision_loss, reason = "short texts")]
                let right = it.x + 16.0 + CHAR_WIDTH * it.text.chars().count() as f64;
                assert!(it.x >= x0 && right <= x1, "{count} x {name:?}: {it:?} ends at {right}");
                assert!(it.y - LEGEND_ROW >= y0 && it.y <= y1, "{count}: {it:?}");
            }
            for (a, b) in items.iter().zip(items.iter().skip(1)) {
                assert!(a.x != b.x || (a.y - b.y).abs() >= LEGEND_ROW, "{a:?} {b:?}");
            }
        }
    }
}
