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
