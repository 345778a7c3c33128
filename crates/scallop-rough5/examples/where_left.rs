//! Where a roughing program of the closed test pocket (or of the fitting
//! pocket, `--part fitting`) leaves its remaining volume V_r, and where its
//! machine time goes (docs/validation.md, "5-axis roughing: where the
//! remaining volume is").
//!
//! ```sh
//! scallop rough5 --part pocket --tilt guides -o out/guides
//! cargo run -p scallop-rough5 --profile fast --example where_left -- out/guides/toolpath.cl [left.csv]
//! scallop rough5 --part impeller -o out/impeller
//! cargo run -p scallop-rough5 --profile fast --example where_left -- out/impeller/toolpath.cl --part impeller
//! scallop rough5 --part fitting -o out/fitting
//! cargo run -p scallop-rough5 --profile fast --example where_left -- out/fitting/toolpath.cl --part fitting
//! ```
//!
//! With `--part impeller` the program is cut on the channel's turned blank
//! and every remaining sample is classed by its distance to the hub (4 mm
//! bands: the levels), to the blades and to the tip surface, and by where it
//! lies along the channel (tenths from the inlet to the outlet).
//!
//! The program (`toolpath.cl` of `scallop rough5`, the default tool and
//! cutting data of the command) is cut on the tri-dexel stock of the proof
//! (0.5 mm); every Z ray's material inside the volume to remove is sampled
//! every 0.05 mm and each sample is classed by its distance to the bottom and
//! to the flanks (the 0.5 mm allowance shell, the fillet where both are near,
//! near a flank, near the bottom, the interior), by the side of its nearest
//! flank point and by its height above the bottom. The time is the UCP 710's
//! time model block by block (the `scallop rough5` model), summed by move kind,
//! by tilt and by the length of the feed run the move belongs to, and run by
//! run between two rapids (time, time at the feed, length, heights, largest
//! tilt, azimuth travel). On the impeller it also gives the moves at the feed
//! that remove nothing (the out-of-material share), by kind and tilt.
//! `WHERE_LEFT_MOVES=FILE` writes every move's time, length, tip, tilt and
//! azimuth as CSV, `WHERE_LEFT_REMOVED=FILE` (impeller) the volume each move
//! removes.

#![allow(clippy::unwrap_used, clippy::print_stdout, clippy::cast_precision_loss, reason = "an analysis example")]

use std::collections::BTreeMap;

use rayon::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{Motion, ProgramOptions, records_of, to_program};
use scallop_machine::time::{path_time, rapid_time};
use scallop_machine::{Joints, Kinematics, Machine};
use scallop_mesh::MeshQuery;
use scallop_parts::{FaceTag, ImpellerParams, closed_pocket, fitting_pocket, impeller_channel};
use scallop_rough5::TorusTool;
use scallop_sim::{DexelOptions, DexelPart, DexelStock, ToolMove};
use scallop_toolpath::MoveKind;

const ALLOWANCE: f64 = 0.5;
const DZ: f64 = 0.05;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let part_name = match args.iter().position(|a| a == "--part") {
        Some(i) => {
            let name = args.remove(i + 1);
            args.remove(i);
            name
        }
        None => "pocket".to_string(),
    };
    let file = args.first().expect("give a toolpath.cl of `scallop rough5 --part pocket`");
    let text = std::fs::read_to_string(file).unwrap();
    let path = scallop_io::cl::read_cl(&text, 2400.0).unwrap();
    let tool = TorusTool::THESIS.cutter().unwrap();
    if part_name == "impeller" {
        let part = impeller_channel(&ImpellerParams::default()).unwrap();
        remaining_impeller(&path, &tool, &part, args.get(1));
    } else {
        let fitting = part_name == "fitting";
        let part = if fitting { fitting_pocket(&Default::default()) } else { closed_pocket(&Default::default()) };
        let part = part.unwrap();
        let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
        let flanks = part.faces(&[FaceTag::Flank]).unwrap();
        let side = if fitting { fitting_side } else { side };
        remaining(&path, &tool, &part, (&bottom, &flanks, side), args.get(1));
    }
    timing(&path);
}

/// The remaining volume of a program of the impeller channel, cut on its
/// turned blank: by distance to the hub (4 mm bands), the class of
/// [`class`] with the tip surface as a third face, and the tenth of the
/// channel (by radius, 25 mm at the inlet to 75 mm at the outlet).
fn remaining_impeller(
    path: &scallop_toolpath::Toolpath,
    tool: &Cutter,
    part: &scallop_parts::TestPart,
    csv: Option<&String>,
) {
    let blank = DexelPart::new(part.blank.as_ref().unwrap());
    let mut dexels = DexelStock::from_solid(part.stock, 0.5, &blank).unwrap();
    let moves = ToolMove::from_toolpath(path);
    let options = DexelOptions { axis_tolerance: 0.05, check_collisions: true, max_stick_out: None };
    let report = dexels.cut_with_progress(tool, &moves, &options, &|_, _| {}).unwrap();
    // An unsafe program is still measured: its collisions are listed first.
    if report.check().is_err() {
        println!(
            "NOT SAFE: {} rapid hits, {} shank or holder collisions",
            report.rapid_hits.len(),
            report.collisions.len()
        );
        for c in report.collisions.iter().take(5) {
            println!("  {:?} {:?} at ({:.2}, {:.2}) depth {:.3}", c.id, c.part, c.at.x, c.at.y, c.depth);
        }
    }
    air_by_kind(path, &report.removed_by_move);
    let volume = DexelPart::new(&part.mesh);
    let face = |t| MeshQuery::new(&part.faces(&[t]).unwrap());
    let (qb, qf, qt) = (face(FaceTag::Bottom), face(FaceTag::Flank), face(FaceTag::Top));
    let (nu, nv) = dexels.grid(2);
    let cell = dexels.cell_size();
    let area = cell[0] * cell[1];
    let (lo, hi) = (part.stock.min.z, part.stock.max.z);
    type Row = (BTreeMap<(String, i64, i64), f64>, f64, Vec<[f64; 6]>);
    let rows: Vec<Row> = (0..nv)
        .into_par_iter()
        .map(|iv| {
            let mut acc = BTreeMap::new();
            let mut total = 0.0;
            let mut samples = Vec::new();
            for iu in 0..nu {
                let o = dexels.ray_origin(2, iu, iv);
                let pocket: Vec<[f64; 2]> = volume
                    .intervals(&o, 2)
                    .iter()
                    .map(|s| [s.0.max(lo), s.1.min(hi)])
                    .filter(|s| s[1] > s[0])
                    .collect();
                total += pocket.iter().map(|s| s[1] - s[0]).sum::<f64>() * area;
                for m in dexels.intervals(2, iu, iv) {
                    for s in &pocket {
                        let (a, b) = (m[0].max(s[0]), m[1].min(s[1]));
                        if b <= a {
                            continue;
                        }
                        let n = ((b - a) / DZ).ceil().max(1.0) as usize;
                        let w = (b - a) / n as f64 * area;
                        for k in 0..n {
                            let p = Point3::new(o.x, o.y, a + (k as f64 + 0.5) * (b - a) / n as f64);
                            let d = |q: &MeshQuery| (q.closest_point(&p).point - p).norm();
                            let (d_b, d_f, d_t) = (d(&qb), d(&qf), d(&qt));
                            let c = if d_t <= 3.0 && d_b > ALLOWANCE + 1e-3 && d_f > 3.0 {
                                "under the tip surface (within 3 mm)"
                            } else {
                                class(d_b, d_f)
                            };
                            let tenth = ((p.x.hypot(p.y) - 25.0) / 5.0).floor().clamp(-1.0, 10.0) as i64;
                            *acc.entry((c.to_string(), (d_b / 4.0).floor() as i64, tenth)).or_insert(0.0) += w;
                            samples.push([p.x, p.y, p.z, w, d_b, d_f]);
                        }
                    }
                }
            }
            (acc, total, samples)
        })
        .collect();
    let total: f64 = rows.iter().map(|r| r.1).sum();
    if let Some(csv) = csv {
        let mut text = String::from("x,y,z,mm3,hub_distance,flank_distance\n");
        for r in rows.iter().flat_map(|r| &r.2) {
            text.push_str(&format!("{},{},{:.3},{:.5},{:.3},{:.3}\n", r[0], r[1], r[2], r[3], r[4], r[5]));
        }
        std::fs::write(csv, text).unwrap();
    }
    let mut all: BTreeMap<(String, i64, i64), f64> = BTreeMap::new();
    for (m, _, _) in rows {
        for (k, v) in m {
            *all.entry(k).or_insert(0.0) += v;
        }
    }
    print_left(&all, total);
    let by = |f: &dyn Fn(&(String, i64, i64)) -> String, title: &str| print_by(&all, total, f, title, 50);
    by(&|k| k.0.clone(), "by class");
    by(&|k| format!("{:>2}: {:>2}-{:>2} mm from the hub", k.1, 4 * k.1, 4 * k.1 + 4), "by distance to the hub");
    by(&|k| format!("{:>2}: r {:>2}-{:>2} mm", k.2, 25 + 5 * k.2, 30 + 5 * k.2), "by tenth of the channel (radius)");
    by(
        &|k| if k.0.starts_with("allowance") { k.0.clone() } else { format!("{:>2} band | {}", k.1, k.0) },
        "by band and class (beyond the allowance)",
    );
    by(
        &|k| if k.0.starts_with("allowance") { k.0.clone() } else { format!("{:>2} tenth | {:>2} band", k.2, k.1) },
        "by tenth and band (beyond the allowance)",
    );
}

/// The class of a remaining sample.
/// Prints the volume to remove, the volume left in `all` and V_r.
/// The moves at the feed that remove nothing (the out-of-material share
/// L_HM), by kind and tilt: length in the air over all.
fn air_by_kind(path: &scallop_toolpath::Toolpath, removed: &[f64]) {
    let moves = path.moves();
    let mut by: BTreeMap<String, [f64; 2]> = BTreeMap::new();
    for (i, m) in moves.iter().enumerate().skip(1) {
        if matches!(m.kind, MoveKind::Rapid | MoveKind::Retract) {
            continue;
        }
        let tilted = path.axis(i).angle(&Vec3::z()).to_degrees() > 0.1;
        let key = format!("{:?} | {}", m.kind, if tilted { "tilted" } else { "axis Z" });
        let len = (m.to - moves[i - 1].to).norm();
        let e = by.entry(key).or_insert([0.0; 2]);
        e[1] += len;
        if removed.get(i).is_none_or(|&v| v <= 0.0) {
            e[0] += len;
        }
    }
    if let Ok(out) = std::env::var("WHERE_LEFT_REMOVED") {
        let csv: String = removed.iter().enumerate().map(|(i, v)| format!("{i},{v:.4}\n")).collect();
        std::fs::write(out, format!("i,removed\n{csv}")).unwrap();
    }
    let (air, all) = by.values().fold((0.0, 0.0), |a, v| (a.0 + v[0], a.1 + v[1]));
    println!("moves at the feed in the air: {air:.0} of {all:.0} mm ({:.1} %)", 100.0 * air / all.max(1e-9));
    for (k, v) in &by {
        println!("  {k:<30} {:>7.0} of {:>7.0} mm in the air", v[0], v[1]);
    }
    println!();
}

fn print_left<K>(all: &BTreeMap<K, f64>, total: f64) {
    let left: f64 = all.values().sum();
    println!("volume to remove {total:.0} mm3, left {left:.0} mm3, V_r {:.2} %", 100.0 * left / total);
}

/// Prints the volume left in `all` grouped by the label `f` gives each key,
/// under `title`, labels `width` wide.
fn print_by<K>(all: &BTreeMap<K, f64>, total: f64, f: &dyn Fn(&K) -> String, title: &str, width: usize) {
    let mut m: BTreeMap<String, f64> = BTreeMap::new();
    for (k, v) in all {
        *m.entry(f(k)).or_insert(0.0) += v;
    }
    println!("\n{title}:");
    for (k, v) in m {
        println!("  {k:<width$} {v:>8.0} mm3  {:>6.2} %", 100.0 * v / total);
    }
}

fn class(d_b: f64, d_f: f64) -> &'static str {
    let near = ALLOWANCE + 1e-3;
    if d_b <= near || d_f <= near {
        "allowance shell (<= 0.5 mm)"
    } else if d_b <= 3.0 && d_f <= 3.0 {
        "fillet (bottom and flank within 3 mm)"
    } else if d_f <= 1.5 {
        "flank, 0.5-1.5 mm"
    } else if d_f <= 3.0 {
        "flank, 1.5-3 mm"
    } else if d_b <= 1.5 {
        "bottom, 0.5-1.5 mm"
    } else if d_b <= 3.0 {
        "bottom, 1.5-3 mm"
    } else {
        "interior (> 3 mm from both)"
    }
}

/// The side of the pocket a flank point is on.
fn side(p: &Point3) -> &'static str {
    // The bottom outline is 12 mm inside the block; corners of radius 8.
    let (dx, dy) = (p.x - 50.0, p.y - 50.0);
    let (ax, ay) = (dx.abs(), dy.abs());
    if ax > 28.0 && ay > 28.0 {
        return "corner";
    }
    if ax - 28.0 > ay - 28.0 {
        if dx > 0.0 { "+x (undercut 10 deg)" } else { "-x (draft 8 deg)" }
    } else if dy > 0.0 {
        "+y (draft 5 deg)"
    } else {
        "-y (undercut 12 deg)"
    }
}

/// The side of the fitting pocket (`FittingParams::default()`: outline 10 mm
/// inside the 140 x 100 mm block, 4 mm ribs at x 50 from -y and x 90 from +y,
/// reaching 48 mm) a flank point is on.
fn fitting_side(p: &Point3) -> &'static str {
    let rib = |x: f64| (p.x - x).abs() < 6.0;
    if rib(50.0) && p.y < 62.0 {
        return "rib x 50 (from -y)";
    }
    if rib(90.0) && p.y > 38.0 {
        return "rib x 90 (from +y)";
    }
    let (dx, dy) = (p.x - 70.0, p.y - 50.0);
    if dx.abs() > 55.0 && dy.abs() > 35.0 {
        "corner"
    } else if dx.abs() - 60.0 > dy.abs() - 40.0 {
        if dx > 0.0 { "+x" } else { "-x" }
    } else if dy > 0.0 {
        "+y"
    } else {
        "-y"
    }
}

type Side = fn(&Point3) -> &'static str;

fn remaining(
    path: &scallop_toolpath::Toolpath,
    tool: &Cutter,
    part: &scallop_parts::TestPart,
    (bottom, flanks, side): (&scallop_mesh::TriMesh, &scallop_mesh::TriMesh, Side),
    csv: Option<&String>,
) {
    let mut dexels = DexelStock::new(part.stock, 0.5).unwrap();
    let moves = ToolMove::from_toolpath(path);
    let options = DexelOptions { axis_tolerance: 0.05, check_collisions: true, max_stick_out: None };
    let report = dexels.cut_with_progress(tool, &moves, &options, &|_, _| {}).unwrap();
    report.check().unwrap();
    let volume = DexelPart::new(&part.mesh);
    let (qb, qf) = (MeshQuery::new(bottom), MeshQuery::new(flanks));
    let (nu, nv) = dexels.grid(2);
    let cell = dexels.cell_size();
    let area = cell[0] * cell[1];
    let (lo, hi) = (part.stock.min.z, part.stock.max.z);
    // (class, side, height band) -> volume; and the volume to remove.
    // Per ray: (x, y, thickness left beyond the allowance shell, lowest and highest such z).
    type Row = (BTreeMap<(String, String, i64), f64>, f64, Vec<[f64; 5]>, Vec<[f64; 4]>);
    let rows: Vec<Row> = (0..nv)
        .into_par_iter()
        .map(|iv| {
            let mut acc = BTreeMap::new();
            let mut total = 0.0;
            let mut rays = Vec::new();
            let mut samples = Vec::new();
            for iu in 0..nu {
                let mut ray = [0.0, 0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY];
                let o = dexels.ray_origin(2, iu, iv);
                let pocket: Vec<[f64; 2]> = volume
                    .intervals(&o, 2)
                    .iter()
                    .map(|s| [s.0.max(lo), s.1.min(hi)])
                    .filter(|s| s[1] > s[0])
                    .collect();
                total += pocket.iter().map(|s| s[1] - s[0]).sum::<f64>() * area;
                for m in dexels.intervals(2, iu, iv) {
                    for s in &pocket {
                        let (a, b) = (m[0].max(s[0]), m[1].min(s[1]));
                        if b <= a {
                            continue;
                        }
                        let n = ((b - a) / DZ).ceil().max(1.0) as usize;
                        let w = (b - a) / n as f64 * area;
                        for k in 0..n {
                            let z = a + (k as f64 + 0.5) * (b - a) / n as f64;
                            let p = Point3::new(o.x, o.y, z);
                            let cb = qb.closest_point(&p);
                            let cf = qf.closest_point(&p);
                            let (d_b, d_f) = ((cb.point - p).norm(), (cf.point - p).norm());
                            let c = class(d_b, d_f);
                            let sd = if d_f < d_b + 3.0 { side(&cf.point) } else { "bottom, away from the flanks" };
                            let band = ((p.z - cb.point.z) / 4.0).floor() as i64;
                            *acc.entry((c.to_string(), sd.to_string(), band)).or_insert(0.0) += w;
                            if !c.starts_with("allowance") {
                                samples.push([o.x, o.y, z, w]);
                                ray[2] += w / area;
                                ray[3] = ray[3].min(z);
                                ray[4] = ray[4].max(z);
                            }
                        }
                    }
                }
                if ray[2] > 0.0 {
                    ray[0] = o.x;
                    ray[1] = o.y;
                    rays.push(ray);
                }
            }
            (acc, total, rays, samples)
        })
        .collect();
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let mut all: BTreeMap<(String, String, i64), f64> = BTreeMap::new();
    if let Some(csv) = csv {
        let mut text = String::from("x,y,left_mm,z_lo,z_hi\n");
        for r in rows.iter().flat_map(|r| &r.2) {
            text.push_str(&format!("{},{},{:.3},{:.3},{:.3}\n", r[0], r[1], r[2], r[3], r[4]));
        }
        std::fs::write(csv, text).unwrap();
        let mut text = String::from("x,y,z,mm3\n");
        for r in rows.iter().flat_map(|r| &r.3) {
            text.push_str(&format!("{},{},{:.3},{:.5}\n", r[0], r[1], r[2], r[3]));
        }
        std::fs::write(format!("{csv}.samples"), text).unwrap();
    }
    for (m, _, _, _) in rows {
        for (k, v) in m {
            *all.entry(k).or_insert(0.0) += v;
        }
    }
    print_left(&all, total);
    let by = |f: &dyn Fn(&(String, String, i64)) -> String, title: &str| print_by(&all, total, f, title, 45);
    by(&|k| k.0.clone(), "by class");
    by(&|k| k.1.clone(), "by side (nearest flank point; bottom when the flanks are 3 mm farther)");
    by(&|k| format!("{:>2}: {:>2}-{:>2} mm above the bottom", k.2, 4 * k.2, 4 * k.2 + 4), "by height band");
    by(&|k| format!("{} | {}", k.0, k.1), "by class and side");
    by(
        &|k| if k.0.starts_with("allowance") { k.0.clone() } else { format!("{:>2} band | {}", k.2, k.0) },
        "by band and class (beyond the allowance)",
    );
}

fn timing(path: &scallop_toolpath::Toolpath) {
    let machine = Machine::builtin("ucp710").unwrap();
    let kin = Kinematics::new(&machine, 233.0);
    let records = records_of(path);
    let program = to_program(&kin, &records, None, &ProgramOptions::default()).unwrap();
    let blocks: Vec<_> = program.blocks.iter().map(|b| (b.motion, b.joints, b.feed, b.cl_index)).collect();
    // Time of every block.
    let mut time = vec![0.0; blocks.len()];
    // And its time at the programmed feed (its equivalent length over the feed).
    let mut at_feed = vec![0.0; blocks.len()];
    let mut k = 1;
    while k < blocks.len() {
        if blocks[k].0 == Motion::Rapid {
            time[k] = rapid_time(&machine, &blocks[k - 1].1, &blocks[k].1);
            k += 1;
            continue;
        }
        let start = k - 1;
        while k < blocks.len() && blocks[k].0 != Motion::Rapid {
            k += 1;
        }
        let joints: Vec<Joints> = blocks[start..k].iter().map(|b| b.1).collect();
        let feeds: Vec<f64> = blocks[start + 1..k].iter().map(|b| b.2).collect();
        let r = path_time(&kin, &joints, &feeds).unwrap();
        for (j, b) in r.blocks.iter().enumerate() {
            time[start + 1 + j] = b.time;
            at_feed[start + 1 + j] = b.length / (feeds[j] / 60.0);
        }
    }
    // Runs of feeds: the length of the run each feed move is in.
    let moves = path.moves();
    let mut run_len = vec![0.0; moves.len()];
    let mut i = 1;
    while i < moves.len() {
        if moves[i].kind != MoveKind::Feed {
            i += 1;
            continue;
        }
        let s = i;
        let mut len = 0.0;
        while i < moves.len() && moves[i].kind == MoveKind::Feed {
            len += (moves[i].to - moves[i - 1].to).norm();
            i += 1;
        }
        for r in &mut run_len[s..i] {
            *r = len;
        }
    }
    let mut by: BTreeMap<String, [f64; 3]> = BTreeMap::new();
    let mut by_z: BTreeMap<i64, [f64; 3]> = BTreeMap::new();
    for ((b, t), floor) in blocks.iter().zip(&time).zip(&at_feed) {
        let i = b.3;
        let m = &moves[i];
        let axis: Vec3 = path.axis(i);
        let tilted = axis.angle(&Vec3::z()).to_degrees() > 0.1;
        let kind = match m.kind {
            MoveKind::Feed if run_len[i] < 150.0 => "feed, run < 150 mm",
            MoveKind::Feed if run_len[i] < 300.0 => "feed, run 150-300 mm",
            MoveKind::Feed => "feed, run >= 300 mm",
            MoveKind::Link => "link (incl. retract at feed)",
            MoveKind::Plunge => "plunge",
            MoveKind::Rapid | MoveKind::Retract => "rapid / retract",
        };
        let key = format!("{kind} | {}", if tilted { "tilted" } else { "axis Z" });
        let e = by.entry(key).or_insert([0.0; 3]);
        e[0] += t;
        e[2] += floor;
        let ez = by_z.entry((m.to.z / 4.0).floor() as i64).or_insert([0.0; 3]);
        ez[0] += t;
        ez[2] += floor;
    }
    // Lengths per CL move.
    for (i, m) in moves.iter().enumerate().skip(1) {
        let axis = path.axis(i);
        let tilted = axis.angle(&Vec3::z()).to_degrees() > 0.1;
        let kind = match m.kind {
            MoveKind::Feed if run_len[i] < 150.0 => "feed, run < 150 mm",
            MoveKind::Feed if run_len[i] < 300.0 => "feed, run 150-300 mm",
            MoveKind::Feed => "feed, run >= 300 mm",
            MoveKind::Link => "link (incl. retract at feed)",
            MoveKind::Plunge => "plunge",
            MoveKind::Rapid | MoveKind::Retract => "rapid / retract",
        };
        let key = format!("{kind} | {}", if tilted { "tilted" } else { "axis Z" });
        by.entry(key).or_insert([0.0; 3])[1] += (m.to - moves[i - 1].to).norm();
    }
    // Every run of feeds with its neighbouring plunges and links (between two
    // rapids or retracts): its time, length, time at the feed, heights and tilt.
    let mut run_time = vec![[0.0; 2]; moves.len()];
    for ((b, t), floor) in blocks.iter().zip(&time).zip(&at_feed) {
        run_time[b.3][0] += t;
        run_time[b.3][1] += floor;
    }
    let mut spans: Vec<(usize, usize, [f64; 7])> = Vec::new();
    let mut i = 1;
    while i < moves.len() {
        if matches!(moves[i].kind, MoveKind::Rapid | MoveKind::Retract) {
            i += 1;
            continue;
        }
        let s = i;
        // time, at feed, length, z min, z max, max tilt, azimuth travel (deg)
        let mut v = [0.0, 0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY, 0.0, 0.0];
        while i < moves.len() && !matches!(moves[i].kind, MoveKind::Rapid | MoveKind::Retract) {
            let axis = path.axis(i);
            let before = path.axis(i - 1);
            v[0] += run_time[i][0];
            v[1] += run_time[i][1];
            v[2] += (moves[i].to - moves[i - 1].to).norm();
            v[3] = v[3].min(moves[i].to.z);
            v[4] = v[4].max(moves[i].to.z);
            v[5] = f64::max(v[5], axis.angle(&Vec3::z()).to_degrees());
            if axis.angle(&Vec3::z()) > 1e-3 && before.angle(&Vec3::z()) > 1e-3 {
                let d = (axis.y.atan2(axis.x) - before.y.atan2(before.x)).to_degrees().rem_euclid(360.0);
                v[6] += d.min(360.0 - d);
            }
            i += 1;
        }
        spans.push((s, i, v));
    }
    if let Ok(out) = std::env::var("WHERE_LEFT_MOVES") {
        let mut csv = String::from("i,kind,time,at_feed,length,x,y,z,tilt,azimuth\n");
        for (i, m) in moves.iter().enumerate().skip(1) {
            let a = path.axis(i);
            csv += &format!(
                "{i},{:?},{:.5},{:.5},{:.4},{:.3},{:.3},{:.3},{:.3},{:.3}\n",
                m.kind,
                run_time[i][0],
                run_time[i][1],
                (m.to - moves[i - 1].to).norm(),
                m.to.x,
                m.to.y,
                m.to.z,
                a.angle(&Vec3::z()).to_degrees(),
                a.y.atan2(a.x).to_degrees()
            );
        }
        std::fs::write(out, csv).unwrap();
    }
    println!("\nruns between rapids (feeds, links, plunges), by time:");
    println!(
        "  {:>6} {:>6} {:>8} {:>8} {:>8} {:>11} {:>8} {:>9}",
        "from", "to", "time (s)", "at feed", "length", "z", "tilt", "azimuth"
    );
    let mut by_time: Vec<_> = spans.iter().collect();
    by_time.sort_by(|a, b| b.2[0].total_cmp(&a.2[0]));
    for (s, e, v) in by_time {
        println!(
            "  {s:>6} {e:>6} {:>8.1} {:>8.1} {:>5.0} mm {:>5.1}-{:<5.1} {:>6.1} deg {:>5.0} deg",
            v[0], v[1], v[2], v[3], v[4], v[5], v[6]
        );
    }
    let total: f64 = time.iter().sum();
    println!("\nmachine time {total:.1} s (UCP 710 model)");
    println!("  {:<45} {:>9} {:>10} {:>12}", "moves", "time (s)", "length", "at feed (s)");
    for (k, v) in &by {
        println!("  {k:<45} {:>9.1} {:>8.0} mm {:>12.1}", v[0], v[1], v[2]);
    }
    println!("\nby tip height (4 mm bands of z):");
    for (k, v) in &by_z {
        println!("  z {:>3}-{:>3} mm {:>9.1} s (at feed {:>7.1} s)", 4 * k, 4 * k + 4, v[0], v[2]);
    }
}
