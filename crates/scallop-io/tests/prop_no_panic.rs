//! `read_mesh` returns `Ok` or `Err` on any input, never panics: random bytes,
//! and valid files of every format truncated or with bytes overwritten.
//! Any `Ok` is a valid mesh (finite, in-range), as `TriMesh` guarantees.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

mod common;

use common::*;
use proptest::prelude::*;
use scallop_io::{MeshFormat, Units, read_mesh};

const FORMATS: [MeshFormat; 4] = [MeshFormat::Stl, MeshFormat::Obj, MeshFormat::Ply, MeshFormat::ThreeMf];

fn check(bytes: &[u8], format: MeshFormat) {
    if let Ok(m) = read_mesh(bytes, format, Units::Millimetres) {
        let n = m.mesh.vertices().len();
        assert!(m.mesh.vertices().iter().all(|p| p.coords.iter().all(|c| c.is_finite())));
        assert!(m.mesh.triangles().iter().flatten().all(|&i| (i as usize) < n));
    }
    // The error message is always printable.
    if let Err(e) = read_mesh(bytes, format, Units::Inches) {
        assert!(!e.to_string().is_empty());
    }
}

fn seeds() -> Vec<(MeshFormat, Vec<u8>)> {
    let (v, t) = (&TETRA_VERTICES[..], &TETRA_TRIANGLES[..]);
    vec![
        (MeshFormat::Stl, stl_ascii(v, t)),
        (MeshFormat::Stl, stl_binary(v, t, b"solid x")),
        (MeshFormat::Obj, obj(v, t)),
        (MeshFormat::Ply, ply_ascii(v, t)),
        (MeshFormat::Ply, ply_binary(v, t, false)),
        (MeshFormat::Ply, ply_binary(v, t, true)),
        (MeshFormat::ThreeMf, threemf_tetra(None)),
        (MeshFormat::ThreeMf, zip(&[("3D/3dmodel.model", &threemf_model(None, &threemf_object(1, v, t), ""))], false)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        for format in FORMATS {
            check(&bytes, format);
        }
    }

    #[test]
    fn random_text_never_panics(text in "[ -~\n\t\r]{0,400}", prefix in prop::sample::select(vec![
        "solid ", "solid x\nfacet normal 0 0 1\nouter loop\nvertex ", "v 1 2 3\nf ",
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n",
        "ply\nformat binary_big_endian 1.0\nelement face 3\nproperty list uint int vertex_indices\nend_header\n",
    ])) {
        let bytes = format!("{prefix}{text}").into_bytes();
        for format in FORMATS {
            check(&bytes, format);
        }
    }

    #[test]
    fn damaged_valid_files_never_panic(
        seed in 0usize..8,
        cut in any::<prop::sample::Index>(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..6),
    ) {
        let (format, mut bytes) = seeds().swap_remove(seed);
        for (at, value) in edits {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        check(&bytes, format);
        bytes.truncate(cut.index(bytes.len() + 1));
        check(&bytes, format);
    }
}
