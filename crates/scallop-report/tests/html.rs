//! The HTML report: self-contained, carries its scene, stays small for a
//! 10^6-move toolpath, and its figures are the job's numbers.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, Part, run_finishing};
use scallop_geom::Point3;
use scallop_mesh::TriMesh;
use scallop_report::html::{base64, display_indices, report_html};
use scallop_report::{DeviationMap, Figure, PathTiming, ReportData, Zones, tol};
use scallop_toolpath::{Move, MoveKind, Toolpath};
use serde_json::Value;

/// The JSON scene block of a page.
fn scene(page: &str) -> Value {
    let start = page.find("<script type=\"application/json\" id=\"scene-data\">").unwrap();
    let body = &page[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</script>").unwrap();
    serde_json::from_str(&body[open..close]).unwrap()
}

fn decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => u32::from(c - b'A'),
        b'a'..=b'z' => u32::from(c - b'a') + 26,
        b'0'..=b'9' => u32::from(c - b'0') + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::new();
    for chunk in text.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let n = chunk.iter().filter(|&&c| c != b'=').fold(0u32, |n, &c| (n << 6) | value(c)) << (6 * pad);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// Table cells with a full value: label -> value.
fn table_values(page: &str) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    let mut rest = page;
    while let Some(k) = rest.find("<tr><th>") {
        rest = &rest[k + 8..];
        let label = rest[..rest.find("</th>").unwrap()].to_string();
        let cell = &rest[rest.find("<td").unwrap()..];
        if let Some(v) = cell.strip_prefix("<td data-value=\"") {
            out.push((label, v[..v.find('"').unwrap()].parse().unwrap()));
        }
    }
    out
}

fn raster(moves: usize) -> Toolpath {
    let mut path = Toolpath::new(3000.0);
    path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 20.0)));
    path.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 1.0)));
    let row = 500;
    for k in 2..moves {
        let (r, c) = ((k - 2) / row, (k - 2) % row);
        let x = if r % 2 == 0 { c as f64 * 0.1 } else { (row - 1 - c) as f64 * 0.1 };
        let kind = if c == 0 { MoveKind::Link } else { MoveKind::Feed };
        path.push(Move::new(kind, Point3::new(x, r as f64 * 0.05, 1.0 + 0.3 * (x * 0.2).sin())));
    }
    path
}

#[test]
fn base64_matches_rfc_4648() {
    for (plain, coded) in [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foobar", "Zm9vYmFy")] {
        assert_eq!(base64(plain.as_bytes()), coded);
        assert_eq!(decode(coded), plain.as_bytes());
    }
}

#[test]
fn the_page_is_self_contained_and_carries_its_scene() {
    let p = |x, y, z| Point3::new(x, y, z);
    let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(10., 0., 0.), p(0., 10., 1.)]]).unwrap();
    let mut data = ReportData::new("a <small> & \"quoted\" job");
    data.part = Some(mesh.clone());
    data.toolpath = Some(raster(2000));
    data.zones = Some(Zones {
        label: "zone".into(),
        of_move: vec![1; 2000],
        names: vec!["flat".into(), "steep".into()],
        times_s: vec![2.0, 3.0],
    });
    data.figures = vec![Figure::count("moves", 2000), Figure::text("script", "</script><script>alert(1)</script>")];
    let page = report_html(&data);
    for bad in ["http://", "https://", " src=", " href=", "<link", "@import", "url(", "<iframe", "<img"] {
        assert!(!page.contains(bad), "the page refers outside itself: {bad}");
    }
    assert_eq!(page.matches("<script").count(), 2, "only the scene block and the viewer");
    assert!(page.contains("id=\"errors\"") && page.contains("document.body.dataset.drawn"));
    assert!(page.contains("a &lt;small&gt; &amp; &quot;quoted&quot; job"));
    let s = scene(&page);
    let positions = decode(s["part"]["positions"].as_str().unwrap());
    assert_eq!(positions.len(), 4 * 3 * mesh.vertices().len());
    let path = &s["path"];
    assert_eq!(path["moves"], 2000);
    assert_eq!(path["shown"], 2000);
    assert_eq!(decode(path["positions"].as_str().unwrap()).len(), 4 * 3 * 2000);
    assert_eq!(decode(path["kinds"].as_str().unwrap()).len(), 2000);
    assert_eq!(decode(path["zones"].as_str().unwrap()).len(), 2 * 2000);
    // Positions are relative to the centre of the bounds, within the radius.
    let r = s["radius"].as_f64().unwrap() as f32;
    for c in positions.chunks(12) {
        let v: Vec<f32> = c.chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
        assert!((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() <= r * 1.0001);
    }
    assert!(page.contains("Machining time per zone"));
}

#[test]
fn a_million_moves_make_a_page_under_50_mb_with_numbers_from_every_move() {
    let n = 1_000_000;
    let path = raster(n);
    let mut data = ReportData::new("a long toolpath");
    data.toolpath = Some(path.clone());
    let durations = data.move_durations();
    data.timing = Some(PathTiming {
        model: "nominal".into(),
        durations: durations.clone(),
        commanded: vec![3000.0; n],
        achieved: (0..n).map(|k| 1000.0 + (k % 7) as f64 * 100.0).collect(),
    });
    data.figures = vec![Figure::count("moves", n), Figure::number("time", durations.iter().sum(), 1, "s")];
    data.toolpath = Some(path);
    let page = report_html(&data);
    assert!(page.len() < 50_000_000, "{} bytes", page.len());
    let s = scene(&page);
    let shown = s["path"]["shown"].as_u64().unwrap() as usize;
    assert!(shown <= tol::MAX_DISPLAY_VERTICES && shown > tol::MAX_DISPLAY_VERTICES / 2, "{shown}");
    assert_eq!(s["path"]["moves"].as_u64().unwrap() as usize, n);
    // The total time is that of every move, not of the shown ones.
    let total = s["path"]["totalTime"].as_f64().unwrap();
    assert!((total - durations.iter().sum::<f64>()).abs() <= 1e-9 * total);
    let values = table_values(&page);
    assert!(values.iter().any(|(l, v)| l == "moves" && v.to_bits() == (n as f64).to_bits()));
}

/// A tilted plane finished with a ball: quick, and a real finishing job.
fn small_job() -> FinishJob {
    let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    let p = |x: f64, y: f64| Point3::new(x * c, y, x * s);
    let (mesh, _) =
        TriMesh::from_soup(&[[p(0., 0.), p(30., 0.), p(0., 20.)], [p(30., 0.), p(30., 20.), p(0., 20.)]]).unwrap();
    let mut job = FinishJob::choi_demo();
    job.part = Part::Mesh(mesh);
    job.part_name = "tilted plane".into();
    job.cutter = Cutter::new(CutterShape::Ball { radius: 3.0 }, 20.0).unwrap();
    job.scallop_height = 0.02;
    job.max_step = 1.0;
    job.sim_resolution = 0.25;
    job
}

#[test]
fn the_figures_table_holds_the_reports_numbers() {
    let job = small_job();
    let out = run_finishing(&job).unwrap();
    let data = ReportData::from_finishing(&job, &out, 1.25, "test");
    data.check().unwrap();
    let page = report_html(&data);
    let values = table_values(&page);
    let get = |label: &str| values.iter().find(|(l, _)| l == label).map(|(_, v)| *v).unwrap();
    let p = &out.report.plan;
    assert_eq!(
        get("machining time, stop-to-stop model (a)").to_bits(),
        (p.machining_time_s).to_bits(),
        "machining time, stop-to-stop model (a)"
    );
    assert_eq!(
        get("machining time, look-ahead model (b)").to_bits(),
        (p.machining_time_lookahead_s).to_bits(),
        "machining time, look-ahead model (b)"
    );
    assert_eq!(get("total time (a)").to_bits(), (p.total_time_s).to_bits(), "total time (a)");
    assert_eq!(
        get("path length (passes + links)").to_bits(),
        (p.path_length_mm).to_bits(),
        "path length (passes + links)"
    );
    assert_eq!(get("passes").to_bits(), (p.passes as f64).to_bits(), "passes");
    assert_eq!(get("max scallop (measured)").to_bits(), (p.max_scallop_mm).to_bits(), "max scallop (measured)");
    assert_eq!(
        get("simulated: deepest deviation").to_bits(),
        (out.report.sim_min_deviation_mm).to_bits(),
        "simulated: deepest deviation"
    );
    assert_eq!(get("scallop height").to_bits(), (job.scallop_height).to_bits(), "scallop height");
    assert_eq!(get("planning time").to_bits(), 1.25f64.to_bits(), "planning time");
    // The look-ahead profile sums to the reported look-ahead time (cutting moves).
    let t = data.timing.as_ref().unwrap();
    let cutting: f64 = out
        .toolpath
        .moves()
        .iter()
        .zip(&t.durations)
        .filter(|(m, _)| matches!(m.kind, MoveKind::Feed | MoveKind::Link))
        .map(|(_, d)| d)
        .sum();
    assert!((cutting - p.machining_time_lookahead_s).abs() <= 1e-9 * cutting);
    // Plots: feed along the path and the scallop histogram; deviation colouring.
    assert!(page.contains("Feed along the cutting path") && page.contains("Measured scallop heights"));
    let s = scene(&page);
    assert!(s["deviation"]["values"].is_string() && s["path"]["feeds"].is_string());
    assert!(s["deviation"]["max"].as_f64().unwrap() >= 0.0);
    // The viewer's texture is the simulated map itself (small enough not to be reduced).
    let d = data.deviation.as_ref().unwrap();
    assert!(d.nx * d.ny <= tol::MAX_DISPLAY_DEVIATION_CELLS);
    assert_eq!((s["deviation"]["nx"].as_u64(), s["deviation"]["ny"].as_u64()), (Some(d.nx as u64), Some(d.ny as u64)));
}

proptest! {
    /// Decimation keeps the ends, stays within budget, keeps order, and keeps
    /// every change of kind while those fit in half the budget.
    #[test]
    fn decimation_keeps_ends_order_and_kind_changes(
        kinds in proptest::collection::vec(0u8..3, 2..3000), max in 10usize..400
    ) {
        let kinds: Vec<MoveKind> =
            kinds.iter().map(|k| [MoveKind::Feed, MoveKind::Link, MoveKind::Rapid][usize::from(*k)]).collect();
        let keep = display_indices(&kinds, max);
        prop_assert!(keep.len() <= max);
        prop_assert_eq!(keep[0], 0);
        prop_assert_eq!(*keep.last().unwrap(), kinds.len() - 1);
        prop_assert!(keep.windows(2).all(|w| w[0] < w[1]));
        let changes: Vec<usize> = (1..kinds.len()).filter(|&i| kinds[i] != kinds[i - 1]).collect();
        if 2 * changes.len() <= max / 2 {
            for i in changes {
                prop_assert!(keep.binary_search(&i).is_ok() && keep.binary_search(&(i - 1)).is_ok());
            }
        }
    }
}

proptest! {
    /// The display reduction of a deviation map fits the budget, and every
    /// cell of the map finds its block by position (`at`): a cell over the
    /// part lies in a block over the part, a gouge in a block at least as deep,
    /// a cell's material left in a block with at least as much (or a gouge).
    #[test]
    fn reduced_deviation_keeps_gouges_and_the_most_material_left(
        nx in 1usize..60, ny in 1usize..60, max_cells in 1usize..400,
        seed in proptest::collection::vec((0u8..4, -1.0f64..1.0), 3600),
        origin in (-50.0f64..50.0, -50.0f64..50.0), cell in (0.05f64..2.0, 0.05f64..2.0),
    ) {
        let values: Vec<f64> = seed[..nx * ny]
            .iter()
            .map(|&(kind, v)| match kind { 0 => f64::NAN, 1 => -0.1 - v.abs(), _ => v.abs() })
            .collect();
        let map = DeviationMap {
            origin: [origin.0, origin.1], cell: [cell.0, cell.1], nx, ny, values, gouge_tolerance: 0.05,
        };
        let shown = map.reduced(max_cells);
        prop_assert!(shown.nx * shown.ny <= max_cells);
        for j in 0..ny {
            for i in 0..nx {
                let v = map.values[j * nx + i];
                let (x, y) = (origin.0 + i as f64 * cell.0, origin.1 + j as f64 * cell.1);
                let block = shown.at(x, y);
                if v.is_nan() {
                    continue;
                }
                let b = block.expect("a cell over the part lies in a block over the part");
                if v < -map.gouge_tolerance {
                    prop_assert!(b <= v, "gouge {v} in a block of {b}");
                } else {
                    prop_assert!(b >= v || b < -map.gouge_tolerance, "material {v} in a block of {b}");
                }
            }
        }
    }
}
