//! What the bottom level of the impeller channel leaves along its limit
//! pass, and what a tool of the root rest pass could cut of it
//! (docs/rough5.md, "Impeller hub and roots").
//!
//! ```sh
//! scallop rough5 --part impeller --tilt guides -o out/imp
//! cargo run -p scallop-rough5 --profile fast --example root_reach -- out/imp/toolpath.cl FIRST
//! ```
//!
//! FIRST is the number of the first move of the bottom level in
//! `toolpath.cl` (the moves from it on are the tools that cut the bottom).
//! Every sixth pair of the bottom's limit pass (synchronised every 1 mm):
//! its radius, the cells of its cross-section (every 0.5 mm across the pass
//! along the hub from 3 mm behind the pair, 0.75 to 3.75 mm over the hub)
//! that no tool covered, up to the flank (`#`: within the 0.5 mm allowance
//! of a blade; the digit: open cells of the column), and for each tilt from
//! the hub's normal across the pass (degrees, positive towards the flank) the
//! move across the pass nearest the flank at which the whole tool keeps the
//! allowance from the blades, then the open cells that tool covers.
#![allow(clippy::unwrap_used, clippy::print_stdout, clippy::cast_precision_loss, reason = "an analysis example")]
use scallop_geom::{Point3, Vec3};
use scallop_guides::GuideSettings;
use scallop_mesh::MeshQuery;
use scallop_parts::{FaceTag, ImpellerParams, impeller_channel};
use scallop_rough5::rest::inside;
use scallop_rough5::{
    BodyCheck, Feature, LevelOptions, Placement, Placer, TiltMode, TorusTool, level_passes_with, synchronise,
};

fn main() {
    let cl = std::env::args().nth(1).unwrap();
    let from: usize = std::env::args().nth(2).unwrap().parse().unwrap();
    let part = impeller_channel(&ImpellerParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let g =
        GuideSettings { tool_radius: 5.0, flank_allowance: 0.5, axial_step: 4.0, radial_step: 4.5, voxel: 1.0, depth };
    let all = LevelOptions { centre_offsets: true, pair_by_rank: true, open_bottom: true };
    let levels = level_passes_with(&bottom, &flanks, &g, TiltMode::Guides, &all).unwrap();
    let cutter = TorusTool::THESIS.cutter().unwrap();
    let tool = (5.0, 1.5, 30.0);
    let text = std::fs::read_to_string(cl).unwrap();
    let mut cut = Vec::new();
    for (i, line) in text.lines().skip(1).enumerate() {
        if i < from {
            continue;
        }
        let f: Vec<&str> = line.split(',').collect();
        if f[0] != "feed" {
            continue;
        }
        let v: Vec<f64> = f[1..].iter().map(|x| x.parse().unwrap()).collect();
        let tip = Point3::new(v[0], v[1], v[2]);
        let axis = Vec3::new(v[3], v[4], v[5]);
        cut.push(Placement {
            tip,
            axis,
            cl: tip,
            contact: tip,
            normal: axis,
            feature: Feature::Facet,
            triangle: 0,
            drop: 0.0,
        });
    }
    let l0 = &levels[0];
    let (path, tilt) = l0.passes.last().unwrap();
    let pairs = synchronise(path, tilt.as_ref(), &path.line.points[0], 1.0);
    let placer = Placer::new(l0.support.mesh(), &cutter, 0.5).unwrap();
    let rest = BodyCheck::new(&flanks, &cutter, 0.5);
    let q = MeshQuery::new(&flanks);
    for (i, s) in pairs.iter().enumerate().step_by(6) {
        let c = q.closest_point(&s.path);
        let d = c.point - s.path;
        let f = Vec3::new(d.x, d.y, 0.0).normalize();
        let along = (f - s.normal * f.dot(&s.normal)).normalize();
        // The cross-section, column by column up to the first cell within the allowance of a blade.
        let mut prof = String::new();
        let mut open = 0;
        let mut blocked = false;
        for xi in 0..=34 {
            let x = -3.0 + 0.5 * f64::from(xi);
            let mut col = 0;
            for hi in 0..=6 {
                let h = 0.75 + 0.5 * f64::from(hi);
                let p = s.path + along * x + s.normal * h;
                let dist = q.closest_point(&p).distance;
                if dist < 0.5 || blocked {
                    col += 100;
                    blocked = true;
                    continue;
                }
                if !cut.iter().any(|t| inside(t, tool, &p)) {
                    col += 1;
                    open += 1;
                }
            }
            prof += &if col >= 100 { "#".to_string() } else { format!("{}", col % 100) };
        }
        let mut line = format!("{i:4} r {:5.1} open {open:3} {prof} |", s.path.x.hypot(s.path.y));
        for deg in [-60.0f64, -50.0, -40.0, -30.0, -20.0, -10.0, 0.0, 10.0] {
            let a = deg.to_radians();
            let axis = s.normal * a.cos() + along * a.sin();
            let mut best = None;
            for j in 0..=36 {
                let dd = -3.0 + f64::from(j) * 0.25;
                if let Some(p) = placer.place(&(s.path + along * dd), &axis) {
                    if !rest.collides(&p.tip, &p.axis) {
                        let cov = (0..=34)
                            .flat_map(|xi| (0..=6).map(move |hi| (xi, hi)))
                            .filter(|&(xi, hi)| {
                                let pp = s.path
                                    + along * (-3.0 + 0.5 * f64::from(xi))
                                    + s.normal * (0.75 + 0.5 * f64::from(hi));
                                inside(&p, tool, &pp) && !cut.iter().any(|t| inside(t, tool, &pp))
                            })
                            .count();
                        best = Some((dd, cov));
                    } else if best.is_some() {
                        break;
                    }
                }
            }
            match best {
                Some((dd, r)) => line += &format!(" {deg:+.0}:{dd:.1}/{r}"),
                None => line += &format!(" {deg:+.0}:-"),
            }
        }
        println!("{line}");
    }
}
