//! Thresholds of the mesh queries (each documented where it is decided).

/// Barycentric slack of the ray-triangle test ([`crate::ray_triangle`]): a
/// relative margin of a few thousand ulps so that a ray through a shared edge
/// or vertex hits at least one of the triangles around it despite rounding.
pub const RAY_EDGE_SLACK: f64 = 1e-12;
