//! Where a pocket program's cycle time goes (bench/freecad, docs/benchmarks.md):
//! the simulator's engagement per move and scallop's look-ahead jerk-limited
//! model per move, summed by kind of move.
//!
//! ```sh
//! cargo run -p scallop-rough --profile fast --example cycle_breakdown -- POCKET.json PROGRAM.nc [D] [STEPOVER] [FEED]
//! ```
//!
//! Kinds: cutting (a feed move at cutting depth with a sample at 2 degrees
//! or more), link (a feed move at cutting depth that cuts nothing, as the
//! evaluator counts links), entry (the helix or plunge down to the depth),
//! rapid (rapids and retracts). Per kind: length, length over the rate, the
//! model's time, and the excess (the time lost to speed changes: junction
//! slow-downs and stops). The cutting and link excess is also split by the
//! deflection at the move's start.

use scallop_analysis::MachineLimits;
use scallop_geom::Point2;
use scallop_io::gcode::{GcodeOptions, read_gcode};
use scallop_sim::{EngagementOptions, Pocket, engagement_angle, pocket_engagement};
use scallop_strategy::{Boundary, FinishingParams, Pattern, lookahead_profile};
use scallop_toolpath::MoveKind;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: cycle_breakdown POCKET.json PROGRAM.nc [D] [STEPOVER] [FEED]".into());
    }
    let num = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (d, stepover, feed) = (num(3, 6.0), num(4, 0.2), num(5, 5000.0));
    let pocket: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&args[1])?)?;
    let rings: Vec<Vec<Point2>> = pocket["rings"]
        .as_array()
        .ok_or("no rings")?
        .iter()
        .map(|r| {
            r.as_array()
                .map(|pts| {
                    pts.iter()
                        .map(|p| Point2::new(p[0].as_f64().unwrap_or(0.0), p[1].as_f64().unwrap_or(0.0)))
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let pocket = Pocket::new(rings)?;
    let path = read_gcode(&std::fs::read_to_string(&args[2])?, &GcodeOptions::default())?;
    let r = d / 2.0;
    let target = engagement_angle(stepover * d, r);
    let options = EngagementOptions { gouge_tolerance: 0.1, ..EngagementOptions::default() };
    let report = pocket_engagement(&pocket, r, &path, target, &options)?;
    let machine = MachineLimits { feed: feed / 60.0, ..MachineLimits::default() };
    let params = FinishingParams {
        direction: 0.0,
        pattern: Pattern::Zigzag,
        scallop_height: 0.01,
        boundary: Boundary::ContactInside,
        max_step: 1.0,
        clearance: 1.0,
        machine,
        plunge_feed: feed / 60.0,
        rapid_rate: 10_000.0 / 60.0,
        sharp_corner: 0.5,
        blend_tolerance: 0.01,
    };
    let profile = lookahead_profile(&path, &params);
    let moves = path.moves();
    let zmin = moves.iter().map(|m| m.to.z).fold(f64::INFINITY, f64::min);
    // kind: 0 cutting, 1 link, 2 entry, 3 rapid
    let names = ["cutting", "link", "entry/plunge", "rapid/retract"];
    let mut sums = [[0.0f64; 4]; 4]; // length, plain, model, count
    let bins = [0.0, 2.0, 5.0, 10.0, 20.0, 45.0, 90.0, 181.0];
    let mut by_turn = vec![[0.0f64; 3]; bins.len() - 1]; // count, excess cutting, excess link
    let mut slow = [0.0f64; 2];
    let mut prev_dir: Option<scallop_geom::Vec3> = None;
    // SCALLOP_MOVES=FILE: one line per move (index, kind, x, y, length, entry, exit, peak, duration).
    let mut dump = std::env::var("SCALLOP_MOVES").ok().map(|_| String::from("k,kind,x,y,len,entry,exit,peak,t,phi\n"));
    for k in 1..moves.len() {
        let v = moves[k].to - moves[k - 1].to;
        let len = v.norm();
        let deep = moves[k].to.z <= zmin + 1e-6 && moves[k - 1].to.z <= zmin + 1e-6;
        let kind = match moves[k].kind {
            MoveKind::Rapid | MoveKind::Retract => 3,
            _ if !deep => 2,
            _ if report.move_phi.get(k).copied().unwrap_or(0.0) >= 2f64.to_radians() => 0,
            _ => 1,
        };
        let rate = if kind == 3 { 10_000.0 / 60.0 } else { feed / 60.0 };
        let t = profile[k].duration;
        if let Some(d) = dump.as_mut() {
            let f = &profile[k];
            d.push_str(&format!(
                "{k},{kind},{:.4},{:.4},{len:.4},{:.2},{:.2},{:.2},{t:.5},{:.1}\n",
                moves[k].to.x,
                moves[k].to.y,
                f.entry,
                f.exit,
                f.peak,
                report.move_phi.get(k).copied().unwrap_or(0.0).to_degrees()
            ));
        }
        sums[kind][0] += len;
        sums[kind][1] += len / rate;
        sums[kind][2] += t;
        sums[kind][3] += 1.0;
        if len > 1e-9 {
            let dir = v / len;
            if kind < 2 {
                let turn = prev_dir.map_or(180.0, |p| p.dot(&dir).clamp(-1.0, 1.0).acos().to_degrees());
                let b = bins.windows(2).position(|w| turn >= w[0] && turn < w[1]).unwrap_or(bins.len() - 2);
                by_turn[b][0] += 1.0;
                by_turn[b][1 + kind] += t - len / rate;
                if profile[k].peak < 0.5 * rate {
                    slow[0] += t;
                    slow[1] += len;
                }
            }
            prev_dir = Some(dir);
        }
    }
    if let (Ok(file), Some(d)) = (std::env::var("SCALLOP_MOVES"), dump) {
        std::fs::write(file, d)?;
    }
    let total: f64 = sums.iter().map(|s| s[2]).sum();
    println!("{}: total {total:.1} s (model), {} moves", args[2], moves.len());
    println!("{:<14} {:>9} {:>8} {:>8} {:>8} {:>7}", "kind", "length", "plain s", "model s", "excess", "moves");
    for (i, s) in sums.iter().enumerate() {
        println!("{:<14} {:>9.0} {:>8.1} {:>8.1} {:>8.1} {:>7.0}", names[i], s[0], s[1], s[2], s[2] - s[1], s[3]);
    }
    println!("excess by deflection at the move's start (deg): count, cutting s, link s");
    for (b, row) in by_turn.iter().enumerate() {
        println!("  [{:>3}, {:>3}) {:>7.0} {:>8.1} {:>8.1}", bins[b], bins[b + 1], row[0], row[1], row[2]);
    }
    println!("moves with peak under half the feed: {:.1} s over {:.0} mm", slow[0], slow[1]);
    Ok(())
}
