//! Offset levels of the closed test pocket's bottom by the voxel field
//! (docs/benchmarks.md, "Offset levels by voxel field"): two levels at
//! a_p = 4 mm, voxels of 0.5 and 0.25 mm. Prints the deviation of each level
//! from the exact offset, max |d(v, S_0) - d| over its vertices.
//! `RAYON_NUM_THREADS=2 cargo bench -p scallop-field --bench levels`

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_field::{LevelOptions, Side, Surface, offset_levels};
use scallop_parts::{FaceTag, PocketParams, closed_pocket};

const LEVELS: [f64; 2] = [4.0, 8.0];

fn levels(c: &mut Criterion) {
    let part = closed_pocket(&PocketParams::default()).expect("default pocket");
    let bottom = part.faces(&[FaceTag::Bottom]).expect("bottom faces");
    let surface = Surface::new(&bottom);
    let mut group = c.benchmark_group("pocket_levels");
    group.sample_size(10);
    for voxel in [0.5, 0.25] {
        // The volume to remove lies behind the bottom's outward normals.
        let options = LevelOptions { voxel, side: Side::Against, ..LevelOptions::default() };
        let out = offset_levels(&surface, &LEVELS, &options).expect("levels");
        for (level, d) in out.iter().zip(LEVELS) {
            let dev = level
                .vertices()
                .iter()
                .map(|v| (surface.closest(v, f64::INFINITY).map_or(f64::INFINITY, |c| c.dist2.sqrt()) - d).abs())
                .fold(0.0, f64::max);
            eprintln!(
                "voxel {voxel} mm, level d = {d} mm: {} triangles, max |dist - d| = {dev:.4} mm ({:.3} h)",
                level.triangles().len(),
                dev / voxel
            );
        }
        group.bench_function(format!("voxel_{voxel}mm"), |b| b.iter(|| offset_levels(&surface, &LEVELS, &options)));
    }
    group.finish();
}

criterion_group!(benches, levels);
criterion_main!(benches);
