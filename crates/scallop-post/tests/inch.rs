//! Inch programs (`Dialect::in_inches`, `G20`) read back by the independent
//! 3-axis reader of `scallop-io` (which scales `G20` words to mm) replay the
//! same path within the words' resolution (half a unit of the last inch
//! decimal, in mm), arcs included, in LinuxCNC, Fanuc and grbl.

use scallop_geom::Point3;
use scallop_io::gcode::{GcodeOptions, read_gcode_arcs};
use scallop_post::{Dialect, ProgramInfo, write_fitted};
use scallop_toolpath::{Move, MoveKind, Toolpath, fit_arcs};

/// A generated path: a rapid, a plunge, a zigzag of pseudo-random heights
/// (a linear congruential sequence), and a full circle in the XY plane (arcs).
fn path(seed: u64) -> Toolpath {
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        #[allow(clippy::cast_precision_loss, reason = "53 bits of a 64-bit state")]
        let r = (state >> 11) as f64 / (1u64 << 53) as f64;
        r
    };
    let mut p = Toolpath::new(1234.5);
    p.plunge_feed = 300.0;
    p.push(Move::new(MoveKind::Rapid, Point3::new(-3.0, 2.0, 30.0)));
    p.push(Move::new(MoveKind::Plunge, Point3::new(-3.0, 2.0, 5.0)));
    for i in 0..200 {
        let x = -3.0 + 0.37 * f64::from(i);
        let y = if i % 40 < 20 { 2.0 } else { 47.123_456 };
        p.push(Move::new(MoveKind::Feed, Point3::new(x, y, 5.0 * next() - 1.0)));
    }
    let c = Point3::new(40.0, 20.0, 2.5);
    for k in 0..=360 {
        let a = f64::from(k).to_radians();
        p.push(Move::new(MoveKind::Feed, Point3::new(c.x + 12.7 * a.cos(), c.y + 12.7 * a.sin(), c.z)));
    }
    p.push(Move::new(MoveKind::Retract, Point3::new(52.7, 20.0, 30.0)));
    p
}

#[test]
fn inch_programs_replay_the_same_path() {
    for dialect in ["linuxcnc", "fanuc", "grbl"] {
        let mm = Dialect::builtin(dialect).expect("shipped");
        let inch = mm.in_inches().expect("ISO dialect");
        assert!(inch.header.iter().any(|h| h.split_whitespace().any(|w| w == "G20")), "{dialect}");
        assert!(!inch.header.iter().any(|h| h.split_whitespace().any(|w| w == "G21")), "{dialect}");
        // Half a unit of the last decimal of the inch words, in mm, plus float rounding.
        let resolution = 0.5 * 10f64.powi(-i32::try_from(inch.decimals).expect("small")) * 25.4 + 1e-9;
        for seed in 1..4 {
            let original = path(seed);
            let fitted = fit_arcs(&original, 1e-3);
            assert!(fitted.segments.len() < original.moves().len(), "the circle became arcs");
            let mut text = Vec::new();
            write_fitted(&fitted, &inch, &ProgramInfo::anonymous(), &[], &mut text).expect("writes");
            let text = String::from_utf8(text).expect("UTF-8");
            let back = read_gcode_arcs(&text, &GcodeOptions::default()).expect("the reader takes the inch program");
            assert_eq!(back.moves().len(), fitted.segments.len(), "{dialect}");
            for (k, (m, s)) in back.moves().iter().zip(&fitted.segments).enumerate() {
                let d = (m.to - s.to()).abs().max();
                assert!(d <= resolution, "{dialect} move {k}: {:?} vs {:?} ({d} mm > {resolution} mm)", m.to, s.to());
                if let Some(arc) = back.arc(k) {
                    let scallop_toolpath::Segment::Arc(a) = s else { panic!("{dialect}: move {k} is no arc") };
                    let dc = (arc.center - a.center.xy()).abs().max();
                    assert!(dc <= 2.0 * resolution, "{dialect} arc {k}: centre off by {dc} mm");
                }
            }
            // Feeds are written in in/min: read back in mm/min within the feed words' resolution.
            let feed_res = 0.5 * 10f64.powi(-i32::try_from(inch.feed_decimals).expect("small")) * 25.4 + 1e-9;
            let feeds: Vec<f64> = (0..back.moves().len())
                .filter(|&k| back.moves()[k].kind == MoveKind::Feed)
                .map(|k| back.feed_of(k))
                .collect();
            assert!(feeds.iter().all(|f| (f - original.feed).abs() <= feed_res), "{dialect}: {feeds:?}");
        }
    }
}
