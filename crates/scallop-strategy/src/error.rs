//! Why planning failed. Every variant names the parameter or place and the fix.

/// Errors of [`crate::plan_finishing`] and [`crate::verify_scallop`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StrategyError {
    /// The waterline kernel failed on a level of steep-and-shallow finishing.
    #[error("waterline levels of the steep walls: {0}")]
    Waterline(String),
    /// Steep-and-shallow finishing would need too many waterline levels.
    #[error(
        "the steep walls would need more than {max} waterline levels ({levels} so far, {dz} mm apart); use a larger scallop height or a larger cutter (job keys: finishing.scallop_height, cutter.diameter)"
    )]
    TooManyLevels {
        /// Levels planned when the limit was hit.
        levels: usize,
        /// Their spacing (mm).
        dz: f64,
        /// The limit.
        max: usize,
    },
    /// A parameter that must be a finite number in a range.
    #[error("parameter `{name}` = {value:?} is invalid: {fix}")]
    BadParameter {
        /// Parameter name (as in [`crate::FinishingParams`] or [`scallop_geom::Tolerances`]).
        name: &'static str,
        /// The value given.
        value: f64,
        /// What to do instead.
        fix: &'static str,
    },
    /// The plan would need more work than the budget allows, estimated before planning:
    /// forward samples (drop-cutter queries) per pass times the fewest passes the
    /// scallop height allows. Fix: a larger `max_step`, scallop height or cutter, or a
    /// smaller part.
    #[error(
        "the plan needs at least {passes:.0} passes x {samples:.0} forward samples = {estimate:.3e} drop-cutter queries \
         (part {span:.1} mm along the feed, max_step {max_step:?} mm), over the budget of {budget:.0e}; \
         use a larger max_step or scallop height"
    )]
    TooMuchWork {
        /// Lower bound of the passes (the width over the flat-surface spacing).
        passes: f64,
        /// Forward samples per pass (`span / max_step`).
        samples: f64,
        /// Their product.
        estimate: f64,
        /// Extent of the part along the feed plus the cutter (mm).
        span: f64,
        /// The step asked for (mm).
        max_step: f64,
        /// The budget, [`crate::tol::MAX_PLAN_SAMPLES`].
        budget: f64,
    },
    /// The scallop height is not smaller than the cutter's radius (or corner radius).
    #[error(
        "parameter `scallop_height` = {scallop_height} mm is not smaller than the cutter's {what} {radius} mm; \
         use a scallop height well below it (typically 0.001 to 0.1 mm)"
    )]
    ScallopTooLarge {
        /// The scallop height asked for (mm).
        scallop_height: f64,
        /// Which radius bounds it.
        what: &'static str,
        /// That radius (mm).
        radius: f64,
    },
    /// The cutter shape has no finishing model.
    #[error(
        "cutter shape `{shape}` is not supported by parallel-planes finishing; use a ball, flat or bull-nose cutter"
    )]
    Unsupported {
        /// The shape name.
        shape: &'static str,
    },
    /// No plane crosses the region: nothing to machine.
    #[error(
        "the region to machine is empty for feed direction {direction_deg} deg (no cutter location over the part); \
         check the part, the `boundary` rule and `max_step` (smaller than the part)"
    )]
    EmptyRegion {
        /// Feed direction (degrees).
        direction_deg: f64,
    },
    /// The scallop height cannot be met: the plane spacing would fall below the minimum.
    #[error(
        "the cutter cannot reach the surface within scallop height {scallop_height} mm near ({x:.3}, {y:.3}) mm: \
         the plane spacing would be {spacing} mm; use a ball or bull-nose cutter, another `direction`, \
         or a larger `scallop_height`"
    )]
    Unreachable {
        /// Place (mm).
        x: f64,
        /// Place (mm).
        y: f64,
        /// The spacing that would be needed (mm).
        spacing: f64,
        /// The scallop height asked for (mm).
        scallop_height: f64,
    },
    /// Verification found a pass pair whose scallop exceeds the limit.
    #[error(
        "scallop {height} mm between planes {plane} and {next} near ({x:.3}, {y:.3}) mm exceeds {limit} mm; \
         this is a planner bug or a toolpath edited after planning"
    )]
    ScallopExceeded {
        /// Index of the first plane of the pair.
        plane: usize,
        /// Index of the second plane.
        next: usize,
        /// Place of the worst cusp (mm).
        x: f64,
        /// Place of the worst cusp (mm).
        y: f64,
        /// Measured height (mm).
        height: f64,
        /// The limit `sh` (mm).
        limit: f64,
    },
    /// Cell labels that do not fill their grid, or a zoning prepared for another network.
    #[error(
        "the cell labels ({cells_u} x {cells_v} cells, {found} labels) do not fit: give one label per cell \
         (index a * cells_v + b, labels below u32::MAX) and build the Zoning from the network it is used with"
    )]
    BadLabels {
        /// Cells along u.
        cells_u: usize,
        /// Cells along v.
        cells_v: usize,
        /// Labels given.
        found: usize,
    },
    /// A zone with no cell in the labelling, or no pass.
    #[error(
        "zone {zone} has no pass: no cell carries this label, or the zone is too small for the network; \
         check the zone number against Zoning::zones or use a finer machining mesh"
    )]
    EmptyZone {
        /// The zone's label.
        zone: u32,
    },
}
