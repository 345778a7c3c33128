//! Built-in test surfaces of the finishing specification (finishing.md section 14).

use scallop_geom::Point3;

use crate::patch::Patch;
use crate::set::SurfaceSet;

/// Names accepted by [`builtin`].
pub const BUILTIN_NAMES: [&str; 2] = ["choi", "rubio"];

/// A built-in test surface set by name (one patch of the same name):
///
/// - `"rubio"`: the Rubio surface, Bezier degree 2 x 2, 3 x 3 control points
///   (finishing.md 14.2, thesis Table 2.2);
/// - `"choi"`: the Choi surface, Bezier degree 3 x 3, 4 x 4 control points
///   (finishing.md 14.3, thesis Table 2.4).
///
/// Both use the spec's table-reading rule: `P_ij`, `i` (table row) is the u index,
/// `j` (table column) the v index.
///
/// ```
/// let choi = scallop_surface::builtin("choi").unwrap();
/// assert_eq!(choi.patches()[0].degree(), [3, 3]);
/// assert!(scallop_surface::builtin("teapot").is_none());
/// ```
#[must_use]
pub fn builtin(name: &str) -> Option<SurfaceSet> {
    let patch = match name {
        "rubio" => bezier(name, &RUBIO),
        "choi" => bezier(name, &CHOI),
        _ => return None,
    };
    SurfaceSet::new(vec![patch?]).ok()
}

fn bezier<const N: usize>(name: &str, table: &[[[f64; 3]; N]; N]) -> Option<Patch> {
    let control: Vec<Vec<Point3>> =
        table.iter().map(|row| row.iter().map(|&[x, y, z]| Point3::new(x, y, z)).collect()).collect();
    Patch::bezier(name, [N - 1, N - 1], &control, None).ok()
}

/// finishing.md 14.2: `RUBIO[i][j] = P_ij` (mm).
const RUBIO: [[[f64; 3]; 3]; 3] = [
    [[0.0, -15.32, -12.85], [0.0, -6.42, 7.66], [0.0, 15.32, 12.85]],
    [[40.0, -18.53, -9.02], [40.0, -9.64, 11.49], [40.0, 12.10, 16.68]],
    [[80.0, -28.17, 2.46], [80.0, -22.49, 26.81], [80.0, 2.46, 28.17]],
];

/// finishing.md 14.3: `CHOI[i][j] = P_ij` (mm).
const CHOI: [[[f64; 3]; 4]; 4] = [
    [[7.92, 0.0, 37.26], [6.33, 20.4, 29.81], [6.33, 40.8, 29.81], [7.92, 61.2, 37.26]],
    [[23.72, 0.0, 26.11], [22.14, 20.4, 18.66], [22.14, 40.8, 18.66], [23.72, 61.2, 26.11]],
    [[42.70, 0.0, 29.87], [41.12, 20.4, 22.42], [41.12, 40.8, 22.42], [42.70, 61.2, 29.87]],
    [[56.02, 0.0, 19.25], [54.44, 20.4, 11.79], [54.44, 40.8, 11.79], [56.02, 61.2, 19.25]],
];
