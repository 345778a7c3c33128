//! The self-contained `report.html`: no network, no external file. The page
//! holds a hand-written WebGL viewer (`viewer.js`, inlined), the scene as
//! base64 typed arrays in a JSON block, the key figures and settings tables
//! and inline SVG plots.
//!
//! The page catches its own errors: `window.onerror`, unhandled rejections,
//! `console.error` and a `try`/`catch` around every draw write into
//! `<pre id="errors">`; after the first frame is drawn it sets
//! `document.body.dataset.drawn = "1"`, so a headless browser can check both
//! with `--dump-dom`.
//!
//! A toolpath longer than [`tol::MAX_DISPLAY_VERTICES`] is decimated for the
//! display (every k-th move plus every move where the kind changes; times and
//! the lowest feed of the skipped moves are kept); figures and plots use
//! every move.

use std::fmt::Write;

use scallop_toolpath::MoveKind;
use serde_json::{Value, json};

use crate::svg::{Series, bar_chart, escape, line_chart};
use crate::{DeviationMap, Figure, FigureValue, KIND_COLOURS, KIND_NAMES, ReportData, kind_index, tol};

/// The viewer's script.
const VIEWER_JS: &str = include_str!("viewer.js");
/// The page's style.
const STYLE: &str = include_str!("report.css");

/// Standard base64 (RFC 4648, with padding).
#[must_use]
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn b64_f32(values: impl Iterator<Item = f32>) -> String {
    base64(&values.flat_map(f32::to_le_bytes).collect::<Vec<u8>>())
}

/// Indices of the moves shown in 3D: all of them up to `max`; above, every
/// k-th move plus the moves on either side of a change of kind (when those
/// fit in half the budget), and the last move.
#[must_use]
pub fn display_indices(kinds: &[MoveKind], max: usize) -> Vec<usize> {
    let n = kinds.len();
    if n <= max || max < 2 {
        return (0..n).collect();
    }
    let boundary = |i: usize| (i > 0 && kinds[i] != kinds[i - 1]) || (i + 1 < n && kinds[i + 1] != kinds[i]);
    let boundaries = (0..n).filter(|&i| boundary(i)).count();
    let keep_boundaries = boundaries <= max / 2;
    let budget = if keep_boundaries { max - boundaries } else { max } - 1;
    let stride = n.div_ceil(budget.max(1));
    (0..n).filter(|&i| i % stride == 0 || i + 1 == n || (keep_boundaries && boundary(i))).collect()
}

/// The deviation map as the viewer's texture: the map reduced to at most
/// [`tol::MAX_DISPLAY_DEVIATION_CELLS`] cells, its first cell's centre
/// relative to the scene centre `c`, its range and the gouge tolerance. The
/// viewer colours each fragment of the part by the cell under it (so a large
/// facet shows every cell it covers), faces steeper than
/// [`tol::WALL_NORMAL_Z`] in the wall colour.
#[allow(clippy::cast_possible_truncation, reason = "f32 is the display precision")]
fn deviation_json(d: &DeviationMap, c: [f64; 2]) -> Value {
    let shown = d.reduced(tol::MAX_DISPLAY_DEVIATION_CELLS);
    let finite = || shown.values.iter().copied().filter(|v| v.is_finite());
    json!({
        "origin": [shown.origin[0] - c[0], shown.origin[1] - c[1]],
        "cell": shown.cell,
        "nx": shown.nx,
        "ny": shown.ny,
        "values": b64_f32(shown.values.iter().map(|&v| v as f32)),
        "min": finite().fold(0.0, f64::min),
        "max": finite().fold(0.0, f64::max),
        "gougeTolerance": d.gouge_tolerance,
        "wallNormalZ": tol::WALL_NORMAL_Z,
    })
}

/// The scene block of the page (JSON).
#[allow(clippy::cast_possible_truncation, reason = "f32 is the display precision")]
fn scene_json(data: &ReportData) -> Value {
    let Some(bounds) = data.bounds() else { return json!(null) };
    let c = scallop_geom::Point3::from((bounds.min.coords + bounds.max.coords) * 0.5);
    let radius = (0.5 * (bounds.max - bounds.min).norm()).max(1e-6);
    let rel = |p: &scallop_geom::Point3| [(p.x - c.x) as f32, (p.y - c.y) as f32, (p.z - c.z) as f32];
    let part = data.part.as_ref().map(|mesh| {
        json!({
            "positions": b64_f32(mesh.vertices().iter().flat_map(rel)),
            "indices": base64(&mesh.triangles().iter().flatten().flat_map(|i| i.to_le_bytes()).collect::<Vec<u8>>()),
            "triangles": mesh.triangles().len(),
        })
    });
    let deviation = data.deviation.as_ref().filter(|_| data.part.is_some()).map(|d| deviation_json(d, [c.x, c.y]));
    let path = data.toolpath.as_ref().map(|path| {
        let moves = path.moves();
        let kinds: Vec<MoveKind> = moves.iter().map(|m| m.kind).collect();
        let keep = display_indices(&kinds, tol::MAX_DISPLAY_VERTICES);
        let durations = data.move_durations();
        let mut cumulative = Vec::with_capacity(moves.len());
        let mut t = 0.0f64;
        for d in &durations {
            t += d;
            cumulative.push(t);
        }
        let times = b64_f32(keep.iter().map(|&i| cumulative[i] as f32));
        let achieved = data.timing.as_ref().filter(|t| t.achieved.len() == moves.len()).map(|t| &t.achieved);
        let feeds = achieved.map(|a| {
            // The lowest feed of the moves merged into each shown vertex.
            let mut prev = 0usize;
            b64_f32(keep.iter().map(|&i| {
                let lo = a[(prev + 1).min(i)..=i].iter().copied().fold(f64::INFINITY, f64::min);
                prev = i;
                if lo.is_finite() { lo as f32 } else { a[i] as f32 }
            }))
        });
        let max_feed = achieved.map_or(path.feed, |a| {
            a.iter()
                .zip(&kinds)
                .filter(|(_, k)| matches!(k, MoveKind::Feed | MoveKind::Link))
                .map(|(v, _)| *v)
                .fold(path.feed, f64::max)
        });
        let zones = data
            .zones
            .as_ref()
            .filter(|z| z.of_move.len() == moves.len())
            .map(|z| base64(&keep.iter().flat_map(|&i| z.of_move[i].to_le_bytes()).collect::<Vec<u8>>()));
        let engagement = data.engagement.as_ref().filter(|e| e.len() == moves.len()).map(|e| {
            // The highest ratio of the moves merged into each shown vertex; -1: not measured.
            let mut prev = 0usize;
            b64_f32(keep.iter().map(|&i| {
                let hi = e[(prev + 1).min(i)..=i].iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
                prev = i;
                if hi.is_finite() { hi as f32 } else { -1.0 }
            }))
        });
        json!({
            "positions": b64_f32(keep.iter().flat_map(|&i| rel(&moves[i].to))),
            "kinds": base64(&keep.iter().map(|&i| kind_index(kinds[i])).collect::<Vec<u8>>()),
            "times": times,
            "feeds": feeds,
            "zones": zones,
            "engagement": engagement,
            "moves": moves.len(),
            "shown": keep.len(),
            "totalTime": t,
            "maxFeed": max_feed,
        })
    });
    let stock = data.stock.as_ref().map(|s| json!({"min": rel(&s.min), "max": rel(&s.max)}));
    json!({
        "centre": [c.x, c.y, c.z],
        "radius": radius,
        "part": part,
        "stock": stock,
        "path": path,
        "deviation": deviation,
        "zoneNames": data.zones.as_ref().map(|z| z.names.clone()),
        "zoneLabel": data.zones.as_ref().map(|z| z.label.clone()),
        "kindNames": KIND_NAMES,
        "kindColours": KIND_COLOURS,
    })
}

fn table(out: &mut String, id: &str, caption: &str, rows: &[Figure]) {
    if rows.is_empty() {
        return;
    }
    let _ = write!(out, "<table id=\"{id}\"><caption>{}</caption>", escape(caption));
    for f in rows {
        let value = match &f.value {
            FigureValue::Number { value, .. } => format!(" data-value=\"{value}\""),
            FigureValue::Text(_) => String::new(),
        };
        let _ = write!(out, "<tr><th>{}</th><td{value}>{}</td></tr>", escape(&f.label), escape(&f.shown()));
    }
    out.push_str("</table>");
}

/// The plots of the page (SVG strings).
#[must_use]
pub fn plots(data: &ReportData) -> Vec<String> {
    let mut out = Vec::new();
    if let (Some(path), Some(t)) = (&data.toolpath, &data.timing)
        && t.achieved.len() == path.moves().len()
        && t.commanded.len() == path.moves().len()
    {
        let (mut s, mut commanded, mut achieved) = (0.0f64, Vec::new(), Vec::new());
        for (k, w) in path.moves().windows(2).enumerate() {
            if matches!(w[1].kind, MoveKind::Feed | MoveKind::Link) {
                s += (w[1].to - w[0].to).norm();
                commanded.push([s, t.commanded[k + 1]]);
                achieved.push([s, t.achieved[k + 1]]);
            }
        }
        out.push(line_chart(
            &format!("Feed along the cutting path, {}", t.model),
            "cutting path length (mm)",
            "feed (mm/min)",
            &[
                Series { name: "commanded".into(), points: commanded, steps: true },
                Series { name: "achieved (peak per move)".into(), points: achieved, steps: true },
            ],
        ));
    }
    if let Some(h) = &data.histogram {
        let n = h.counts.len();
        let labels: Vec<String> = (0..n)
            .map(|k| {
                #[allow(clippy::cast_precision_loss, reason = "bin counts far below 2^52")]
                let edge = h.bin_width * k as f64;
                if h.last_is_overflow && k + 1 == n { format!("> {edge:.4}") } else { format!("{edge:.4}") }
            })
            .collect();
        #[allow(clippy::cast_precision_loss, reason = "sample counts far below 2^52")]
        let values: Vec<f64> = h.counts.iter().map(|&c| c as f64).collect();
        out.push(bar_chart(&h.title, &format!("lower bin edge ({})", h.unit), "samples", &labels, &values));
    }
    if let Some(z) = &data.zones
        && !z.times_s.is_empty()
    {
        let title = format!("Machining time per {}", z.label);
        out.push(bar_chart(&title, &z.label, "time (s)", &z.names, &z.times_s));
    }
    for c in &data.convergence {
        let series: Vec<Series> =
            c.curves.iter().map(|k| Series { name: k.name.clone(), points: k.points.clone(), steps: false }).collect();
        out.push(line_chart(&c.title, &c.x_label, &c.y_label, &series));
    }
    out
}

/// The whole page.
#[must_use]
pub fn report_html(data: &ReportData) -> String {
    let mut out = String::new();
    let title = escape(&data.title);
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>{title}</title><style>{STYLE}</style></head>\n<body>\
         <header><h1>{title}</h1><p class=\"cmd\">{}</p></header>\
         <pre id=\"errors\"></pre>",
        escape(&data.command)
    );
    out.push_str(
        "<section id=\"view\"><div id=\"toolbar\">\
         <button id=\"fit\" title=\"fit the scene into the view\">fit</button>\
         <label>colour <select id=\"colour\"></select></label>\
         <label><input type=\"checkbox\" id=\"showPart\" checked> part</label>\
         <label><input type=\"checkbox\" id=\"showStock\" checked> stock</label>\
         <label><input type=\"checkbox\" id=\"showPath\" checked> toolpath</label>\
         <label><input type=\"checkbox\" id=\"showRapids\" checked> rapids</label>\
         <label><input type=\"checkbox\" id=\"section\"> section</label>\
         <select id=\"sectionAxis\"><option>x</option><option>y</option><option selected>z</option></select>\
         <input type=\"range\" id=\"sectionPos\" min=\"0\" max=\"1000\" value=\"500\">\
         </div><canvas id=\"gl\"></canvas><div id=\"legend\"></div>\
         <div id=\"player\"><button id=\"play\">play</button>\
         <input type=\"range\" id=\"time\" min=\"0\" max=\"1000\" value=\"1000\"><span id=\"timeLabel\"></span></div>\
         <p class=\"hint\">drag: orbit · right-drag or shift-drag: pan · wheel: zoom</p><p id=\"pathNote\"></p></section>",
    );
    out.push_str("<section class=\"tables\">");
    table(&mut out, "figures", "Key figures", &data.figures);
    table(&mut out, "settings", "Job settings", &data.settings);
    out.push_str("</section><section class=\"plots\">");
    for p in plots(data) {
        let _ = write!(out, "<figure>{p}</figure>");
    }
    out.push_str("</section>");
    // `</` cannot appear inside a script block: escape it in the JSON.
    let scene = scene_json(data).to_string().replace("</", "<\\/");
    let _ = write!(
        out,
        "<script type=\"application/json\" id=\"scene-data\">{scene}</script>\n<script>\n{VIEWER_JS}\n</script>\n</body></html>\n"
    );
    out
}
