//! Criterion benchmark of the engagement measure on the in-process stock
//! (`stock_engagement`), as a roughing job runs it: a 120 x 100 mm stock on a
//! 0.1 mm z-map (1,200,000 cells), a 6 mm flat end mill 2 mm deep along
//! passes 1.2 mm apart (0.2 D) across its middle third, cut as moves of 0.4 mm
//! (the adaptive planner's lines are that short), 3,000 moves in all. The
//! measure cuts the stock one move at a time, so its cost per move must not
//! grow with the stock's size. Run: `cargo bench -p scallop-sim --bench engagement`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point3};
use scallop_sim::{EngagementOptions, ZMap, engagement_angle, stock_engagement};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn passes() -> Toolpath {
    let mut t = Toolpath::new(5000.0);
    let step = 0.4;
    let (x0, x1) = (40.0, 80.0);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small count")]
    let n = ((x1 - x0) / step) as usize;
    for row in 0..30 {
        let y = 20.0 + 1.2 * f64::from(row);
        t.push(Move::new(MoveKind::Rapid, Point3::new(x0 - 4.0, y, 5.0)));
        t.push(Move::new(MoveKind::Plunge, Point3::new(x0 - 4.0, y, -2.0)));
        for i in 0..=n {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let x = x0 + step * i as f64;
            t.push(Move::new(MoveKind::Feed, Point3::new(x, y, -2.0)));
        }
        t.push(Move::new(MoveKind::Retract, Point3::new(x1, y, 5.0)));
    }
    t
}

fn bench(c: &mut Criterion) {
    let stock = ZMap::new(Aabb3 { min: Point3::new(0.0, 0.0, -10.0), max: Point3::new(120.0, 100.0, 0.0) }, 0.1)
        .expect("stock");
    let flat = Cutter::new(CutterShape::Flat { radius: 3.0 }, 20.0).expect("valid cutter");
    let path = passes();
    let target = engagement_angle(1.2, 3.0);
    let options = EngagementOptions::default();
    let mut group = c.benchmark_group("stock_engagement_120x100_0.1");
    group.sample_size(10);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        group.bench_function(format!("{threads}_thread"), |b| {
            b.iter(|| pool.install(|| stock_engagement(&stock, &flat, &path, target, &options).expect("measured")));
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
