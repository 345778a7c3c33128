//! Every numeric threshold and constant of the report writers.

/// Above this many toolpath vertices the 3D display is decimated (every k-th
/// move, always keeping the moves where the kind changes); the figures and
/// plots always use the full toolpath. 200 000 vertices keep a 10^6-move
/// report far below 50 MB and draw smoothly in software WebGL.
pub const MAX_DISPLAY_VERTICES: usize = 200_000;

/// Points of a line plot: longer series are reduced to the minimum and the
/// maximum of this many buckets (dips stay visible).
pub const MAX_PLOT_BUCKETS: usize = 1_000;

/// Rapid rate for nominal times when no time model is given (mm/min).
pub const NOMINAL_RAPID_RATE: f64 = 10_000.0;

/// Margin around the fitted view of a render (share of the image side).
pub const RENDER_MARGIN: f64 = 0.05;

/// Ambient share of the Lambert shading of a render (the rest is diffuse).
pub const AMBIENT: f64 = 0.25;

/// Scale of the GLB scene: glTF is in metres, scallop in millimetres.
pub const GLB_SCALE: f64 = 0.001;

/// Above this many cells the deviation map is reduced for the 3D display
/// (square blocks of cells become one texel: the deepest gouge of the block
/// when it has one, else the most material left). 512 x 512 cells embed as
/// 1.4 MB of base64 and are about as fine as the screen on a fitted view.
pub const MAX_DISPLAY_DEVIATION_CELLS: usize = 512 * 512;

/// The viewer shows faces whose normal's Z component is below this (slopes
/// over about 84 degrees) in the wall colour: a height map seen from above
/// does not measure them (every point of a vertical face would take the
/// deviation of the surface above or beside it).
pub const WALL_NORMAL_Z: f64 = 0.1;
