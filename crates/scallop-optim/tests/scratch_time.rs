#![allow(missing_docs, clippy::unwrap_used)]
use scallop_optim::study::*;
use scallop_optim::surface::*;
#[test]
fn time_it() {
    for name in ["choi", "rubio"] {
    let set = scallop_surface::builtin(name).unwrap();
    let t = std::time::Instant::now();
    let model = SurfaceModel::new(&set.patches()[0], SurfaceSettings::default()).unwrap();
    println!("{name} model {:?}", t.elapsed());
    for f in [Formulation::ThreeAxis, Formulation::ThreePlusTwo, Formulation::Heuristic] {
    for k in [2, 5, 10] {
        let t = std::time::Instant::now();
        let p = model.partition(k, &[1.0; 4], Fidelity::BlackBox).unwrap();
        let tp = t.elapsed();
        let d = model.initial_design(k, f, &p).unwrap();
        let t = std::time::Instant::now();
        let a = model.assess(&p, f, &d, Fidelity::BlackBox).unwrap();
        let ta = t.elapsed();
        let t = std::time::Instant::now();
        let p3 = model.partition(k, &[1.0; 4], Fidelity::S3).unwrap();
        let s3 = model.assess(&p3, f, &d, Fidelity::S3).unwrap();
        let t3 = t.elapsed();
        let t = std::time::Instant::now();
        let p4 = model.partition(k, &[1.0; 4], Fidelity::S4).unwrap();
        let s4 = model.assess(&p4, f, &d, Fidelity::S4).unwrap();
        let t4 = t.elapsed();
        println!("{name} {f:?} K={k} zones={} part {tp:?} bb {:.2} s ({ta:?}) h={:.3e} | S3 {:.2} ({t3:?}) | S4 {:.2} ({t4:?}) theta {:?}", p.partition_zone_count(), a.time_s, a.violation, s3.time_s, s4.time_s, d.theta.iter().map(|t| t.to_degrees().round()).collect::<Vec<_>>());
    }}}
}
