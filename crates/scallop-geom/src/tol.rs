//! Every numeric threshold of scallop. No other module of the workspace
//! compares floats against a literal; they take a named value from here. The
//! thresholds of one crate are in the module named after it (`strategy` for
//! `scallop-strategy`), which that crate re-exports as its own `tol`; the 2D
//! contour crate, which depends on no scallop crate, keeps its own.

/// User-facing machining tolerances in mm; part of every job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Maximum deviation of emitted motion from the ideal CL surface (chordal error).
    pub path: f64,
    /// Maximum allowed penetration into the part; normally 0.
    pub gouge: f64,
}

impl Tolerances {
    /// Share of `path` given to the tessellation of parametric surfaces before a
    /// drop-cutter (the rest goes to path sampling and simplification).
    pub const TESSELLATION_SHARE: f64 = 0.25;

    /// The chordal tolerance budgeted for tessellating surfaces.
    #[must_use]
    pub fn tessellation(&self) -> f64 {
        self.path * Self::TESSELLATION_SHARE
    }
}

/// Relative rounding scale: `Eps` is this times the largest |coordinate|.
pub const REL_ROUNDING: f64 = 1e-12;

/// Relative weld distance for mesh vertices: this times the model's bounding-box diagonal.
pub const REL_WELD: f64 = 1e-9;

/// A mesh vertex farther than this many times the size of the box holding the bulk
/// of the vertices (5 % to 95 % quantiles per axis) from that box is an outlier, an
/// error: one corrupt vertex would otherwise set the weld distance and the bounds.
pub const OUTLIER_FACTOR: f64 = 1e4;

/// Relative tolerance under which a drop-cutter result counts as touching the
/// mesh in tests and verification (times the model scale).
pub const REL_CONTACT: f64 = 1e-9;

/// Relative slack added to upper bounds in branch-and-bound searches (times the
/// model's largest |coordinate|), far above rounding error and far below any
/// geometric feature: pruning stays conservative.
pub const REL_PRUNE_SLACK: f64 = 1e-9;

/// Relative convergence of parameter iterations (times the parameter's range).
/// Used where the result is the maximum of a smooth concave function, whose
/// value errs by O(parameter error^2): 1e-10 of a 10 mm range moves a height by
/// far less than 1e-12 mm.
pub const PARAMETER_CONVERGENCE: f64 = 1e-10;

/// Numeric epsilon derived from the largest |coordinate| of a model: rounding
/// error grows with coordinate magnitude, not with part size. Never user-facing.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Eps(pub f64);

impl Eps {
    /// Epsilon for a model whose largest |coordinate| is `max_abs_coord`.
    ///
    /// ```
    /// let e = scallop_geom::Eps::for_scale(100.0);
    /// assert!(e.0 > 0.0 && e.0 < 1e-6);
    /// ```
    #[must_use]
    pub fn for_scale(max_abs_coord: f64) -> Eps {
        Eps(REL_ROUNDING * max_abs_coord.max(1.0))
    }

    /// Epsilon for a box.
    #[must_use]
    pub fn for_bounds(b: &crate::Aabb3) -> Eps {
        Self::for_scale(b.max_abs_coord())
    }
}

pub mod analysis {
    //! Thresholds of `scallop_analysis`, re-exported there as `scallop_analysis::tol`.
    //!
    //! Every numeric threshold and algorithm constant of this crate, in one place
    //! (house rule: no float literal thresholds in algorithms). Values quoted from the
    //! specification name the section of `finishing.md` they come from.

    /// A normal whose XY projection is shorter than this is horizontal-plane normal
    /// (`n = +-Z`): its steepest-slope direction theta is undefined and set to 0
    /// (finishing.md 4.4 \[DECISION\]). The same rule folds the XY projections of the PCA
    /// axes `S_I` and `S_III` into angles.
    pub const HORIZONTAL_XY: f64 = 1e-12;

    /// Below this `sin s`, Eq. 1.5 is treated as singular (horizontal plane) and the
    /// toroidal step-over is the flat-bottom cap `sod_max` (finishing.md 5.3).
    pub const SIN_SLOPE_HORIZONTAL: f64 = 1e-9;

    /// Annex E (finishing.md 12.7): a PCA plane with `|X_III . Z|` below this is
    /// vertical and its analytic time is `+inf` (not machinable by that model).
    pub const VERTICAL_PLANE_NZ: f64 = 1e-6;

    /// Annex E: a side region with fewer than this many (real) passes contributes
    /// nothing (finishing.md 12.7 "if N < 1e-12 the side term is 0").
    pub const ANNEX_E_MIN_SIDE_PASSES: f64 = 1e-12;

    /// PCA canonical signs: when `|S_III . Z|` is at most this, the plane is vertical
    /// and the sign of `S_II`, `S_III` is fixed by "largest-magnitude component of
    /// `S_III` positive" instead of "`S_III` upward" (finishing.md 9.1).
    pub const PCA_VERTICAL_NZ: f64 = 1e-12;

    /// The samples are degenerate (on a line or at a point; the PCA rectangle has no
    /// area) when `lambda_II <= DEGENERATE_EIGEN_REL * lambda_I`, or when `lambda_I`
    /// is at most `DEGENERATE_EIGEN_REL` times the squared coordinate scale.
    pub const DEGENERATE_EIGEN_REL: f64 = 1e-12;

    /// Shape-factor limit of the decision aid (finishing.md 8.5, thesis footnote):
    /// beyond `mu = 9` the model was not validated; the advisor still answers with the
    /// `s_c` rule and adds a note.
    pub const SHAPE_FACTOR_LIMIT: f64 = 9.0;

    /// Samples per chunk in the fixed-order reductions (moments, orientation sums):
    /// the chunking depends on this constant only, never on the thread count, so
    /// results are bit-identical with any number of threads.
    pub const REDUCTION_CHUNK: usize = 4096;

    /// Number of points of the critical curve `s_c(mu)` drawn by `scallop_analysis::plot_svg`.
    pub const PLOT_CURVE_POINTS: usize = 241;

    /// Largest sampling grid of a patch (cells): 4 million, about 400 MB of samples and a few
    /// seconds; the CLI's `--cells 2000` is the largest square grid under it.
    pub const MAX_GRID_CELLS: usize = 4_000_000;
}

pub mod cluster {
    //! Thresholds of `scallop_cluster`, re-exported there as `scallop_cluster::tol`.
    //!
    //! Every numeric threshold and algorithm constant of this crate, in one place
    //! (house rule: no float literal thresholds in algorithms). Values quoted from the
    //! specification name the section of `finishing.md` they come from.

    /// Iteration cap of K-means and RPCL (finishing.md 11.6, 11.7, section 13): one
    /// iteration is one full assignment sweep.
    pub const MAX_ITERATIONS: usize = 300;

    /// Incremental zone statistics are recomputed in batch every this many assignment
    /// iterations (and at termination) so rounding cannot accumulate (finishing.md 11.5).
    pub const BATCH_REFRESH_EVERY: usize = 10;

    /// Per-cluster Mahalanobis and standard-deviation metrics fall back to the global
    /// covariance for clusters with fewer cells than this (finishing.md 11.3, item 3).
    pub const MIN_CELLS_PER_CLUSTER_COVARIANCE: usize = 5;

    /// A symmetric covariance is singular when an eigenvalue is at most this times the
    /// largest one. The global Mahalanobis metric then uses the pseudo-inverse (the
    /// directions without spread, e.g. a constant slope on a plane, weigh 0); a
    /// per-cluster covariance falls back to the global one (finishing.md 11.3).
    pub const SINGULAR_EIGEN_REL: f64 = 1e-12;

    /// A standard deviation (rad or parameter units) at or below this is zero: the
    /// component is constant over the set and weighs 0 in the standard-deviation metric
    /// (globally), or the per-cluster metric falls back to the global one.
    pub const MIN_SIGMA: f64 = 1e-12;

    /// The PCA metric's extra term is 0 for clusters with fewer cells than this
    /// (finishing.md 11.3, item 6 \[DECISION\]).
    pub const PCA_MIN_CELLS: usize = 3;

    /// A vector whose XY projection is shorter than this (mm, or unit vectors) has no
    /// direction angle; the PCA metric's corresponding `sin^2` term is then 0
    /// (finishing.md 11.3, item 6 \[DECISION\]).
    pub const XY_DEGENERATE: f64 = 1e-12;

    /// Closed-form 3x3 eigenvectors: when the best cross product of two rows of
    /// `A - lambda_I I` is at most this times the squared Frobenius norm of `A`, the top
    /// eigenvalue is (nearly) repeated and the iterative solver is used instead.
    pub const EIGEN_CROSS_REL: f64 = 1e-10;

    /// RPCL winner learning rate at sweep 0 (finishing.md 11.7, section 13 \[DECISION\]).
    pub const RPCL_ALPHA_WINNER: f64 = 0.05;

    /// RPCL rival learning rate at sweep 0 (finishing.md 11.7, section 13 \[DECISION\]).
    pub const RPCL_ALPHA_RIVAL: f64 = 0.005;

    /// RPCL stops when both learning rates are below this (finishing.md 11.7).
    pub const RPCL_TOL_ALPHA: f64 = 1e-4;

    /// RPCL stops when fewer than this fraction of the cells changed cluster in a sweep
    /// (finishing.md 11.7: "1 % move threshold").
    pub const RPCL_TOL_MOVE: f64 = 0.01;

    /// Assignment sweeps run on the rayon pool when `cells x clusters` is at least this
    /// (the PCA metric always does); below, one thread is faster. Either way each cell's
    /// label depends only on frozen statistics, so the result is the same.
    pub const PARALLEL_MIN_PAIRS: usize = 1 << 17;

    /// Relative slack of Hamerly's K-means bounds: a cell skips the scan only when its
    /// upper bound times `1 + HAMERLY_SLACK` is below its lower bound, so rounding in
    /// the accumulated bounds (about 1e-16 per update) can never keep a cell in the
    /// wrong cluster.
    pub const HAMERLY_SLACK: f64 = 1e-9;

    /// Absolute margin (in the metric's units) added to the K-means scan's pruning
    /// radius `2 u (1 + HAMERLY_SLACK)`, so that rounding near `u = 0` never prunes
    /// a centre that could tie.
    pub const HAMERLY_ABSOLUTE: f64 = 1e-12;

    /// Cells per parallel assignment chunk.
    pub const PARALLEL_CHUNK: usize = 1024;

    /// Hierarchical clustering is O(n^2) in time (O(n) memory, nearest-neighbour
    /// chain): grids with more kept cells than this are rejected (about 5 s here); coarsen
    /// the clustering grid (the thesis recommends HAC only to suggest a K).
    pub const HAC_MAX_CELLS: usize = 40_000;
}

pub mod cutter {
    //! Thresholds of `scallop_cutter`, re-exported there as `scallop_cutter::tol`.
    //!
    //! The physical range of cutter sizes, named in one place.

    /// Largest cutter radius R (mm): a 1 m face mill is beyond any catalogue; past it a
    /// size is a typo (a diameter in microns, a missing decimal point), and the planning and
    /// simulation work it implies has no bound.
    pub const MAX_RADIUS: f64 = 500.0;

    /// Smallest cutter radius R (mm): 1 micron, below the smallest micro end mills (5 microns
    /// in diameter); a smaller radius makes scallop-driven spacings vanish.
    pub const MIN_RADIUS: f64 = 1e-3;

    /// Largest flute, shank or holder length and holder radius (mm): 2 m.
    pub const MAX_LENGTH: f64 = 2000.0;
}

pub mod field {
    //! Thresholds of `scallop_field`, re-exported there as `scallop_field::tol`.
    //!
    //! Every numeric threshold of the field engine, with its reason.

    /// Samples per axis of one storage block of a `scallop_field::Field`. A block whose
    /// centre is farther from the surface than the band cutoff plus its half-diagonal
    /// holds no sample in the band and is not stored (cell binning of the band).
    pub const BLOCK: usize = 8;

    /// Default bound on the number of grid samples (2^25, at most 256 MiB of f64
    /// per field). A grid over it is refused with `scallop_field::FieldError::GridTooLarge`,
    /// which names the smallest voxel size that fits.
    pub const DEFAULT_MAX_SAMPLES: usize = 1 << 25;

    /// The band cutoff exceeds the largest iso-value by this many voxel sizes. The
    /// longest edge of the Kuhn tetrahedra is `sqrt(3) h`, and the distance is
    /// 1-Lipschitz, so every edge that crosses an iso-value has both ends computed
    /// exactly when the cutoff is at least `iso + sqrt(3) h`; 2 leaves a margin. The
    /// grid margin around the surface uses the same count (a sheet is never clipped
    /// by the grid box).
    pub const BAND_MARGIN_VOXELS: f64 = 2.0;

    /// Relative clamp of the interpolation parameter on a crossed edge: the output
    /// vertex stays at least this fraction of the edge length away from both grid
    /// samples, so two vertices on different edges of one sample never coincide and
    /// welding by edge never makes a zero-area triangle. The position error it adds
    /// (`1e-4 h`) is far below the method's `h / 2` bound.
    pub const INTERP_CLAMP: f64 = 1e-4;

    /// Relative slack on the bound that a neighbouring sample's distance gives
    /// (`d(q) + |p - q|`, the distance being 1-Lipschitz): rounding of the square
    /// root and the sum can put the exact bound an ulp below the distance, which
    /// would miss the closest triangle; 1e-9 covers it many times over and costs
    /// no pruning worth measuring.
    pub const LIPSCHITZ_SLACK: f64 = 1e-9;
}

pub mod guides {
    //! Thresholds of `scallop_guides`, re-exported there as `scallop_guides::tol`.
    //!
    //! Thresholds of the guide-curve algorithms, each documented.

    /// Root finding on a Marching Facets edge stops when the exact field is within
    /// this of the iso-value, or the bracket is this short (mm). Far below the
    /// 1e-6 mm asked of edge points (issue 17; docs/guides-curves.md).
    pub const ROOT_TOLERANCE: f64 = 1e-10;

    /// Iteration cap of the edge root finding (Illinois false position with
    /// bisection steps); 2^-100 of an edge is far below [`ROOT_TOLERANCE`].
    pub const MAX_ROOT_ITERATIONS: usize = 100;

    /// Most segments of the stretch of the curves under a Marching Facets edge
    /// whose distance gives the first guess of its crossing (the two feet's
    /// segments, those between and one more at each end). A cost bound only:
    /// a guess is kept when the exact field confirms it within
    /// [`ROOT_TOLERANCE`], so results are within that tolerance either way
    /// (docs/guides-curves.md, "A first guess from the stretch under the edge").
    pub const ROOT_GUESS_SEGMENTS: usize = 16;

    /// A facet is flagged as crossed by the medial axis of the curve when the feet
    /// of its corners on the curve are farther apart than this many times the
    /// facet's longest edge (docs/guides-curves.md, "Medial-axis facets").
    pub const MEDIAL_FOOT_FACTOR: f64 = 3.0;

    /// Offsets stop after this many curves beyond `diagonal / a_e + 2` (a guard:
    /// every step shrinks the region, so it is never reached on a valid mesh).
    pub const EXTRA_STEPS: usize = 2;

    /// A vertex of a curve is a corner to round in the vectorial offset (Alg. 3,
    /// Jousselin 2020, Annex A) when the curve turns there by more than this
    /// (radians): gaps on straight stretches are not filled, since the radial push
    /// would bring the points closer than the offset distance to the curve.
    pub const CORNER_TURN: f64 = 0.1;

    /// Most axial levels of one guide set (bounds the work on absurd settings).
    pub const MAX_LEVELS: usize = 1000;

    /// Consecutive curve points closer than this (mm) are merged in a distance
    /// field (`scallop_guides::CurveField`): the mesh intersection and Marching Facets
    /// can leave points a rounding error apart, whose segment has no reliable
    /// direction (coordinates of 1e2 mm carry 1e-14 mm of rounding, a direction
    /// error of 1e-7 rad at this length), so its left vector could flip the side
    /// of the points whose nearest point is its end.
    pub const MERGE_DISTANCE: f64 = 1e-7;

    /// An offset loop whose mean width (`2 area / length`) is under this many
    /// facet sizes has vanished (`scallop_guides::offset_curves`): its shape is below
    /// the mesh's resolution (docs/guides-curves.md, "Slivers").
    pub const SLIVER_WIDTH_FACETS: f64 = 0.5;
}

pub mod machine {
    //! Thresholds of `scallop_machine`, re-exported there as `scallop_machine::tol`.
    //!
    //! Thresholds specific to machine kinematics.

    /// A declared axis direction (or tool axis) must have a norm within this of 1
    /// before it is normalised (spec 2.3).
    pub const DIRECTION_NORM: f64 = 1e-6;

    /// Two unit directions count as parallel when `|u x v|` is below this (rotary axes of
    /// one machine must not be parallel; a pivot direction is "along e_x" for the
    /// closed-form families when it differs from it by less than this).
    pub const PARALLEL: f64 = 1e-9;

    /// Largest absolute coordinate (mm) of a point in a description (part-frame origin,
    /// gauge point, pivot points): 100 m, beyond any machine; past it a value is a typo and
    /// the kinematics would overflow.
    pub const MAX_COORDINATE: f64 = 1e5;

    /// The three linear axes must span space: `|det [d_1 d_2 d_3]|` above this.
    pub const LINEAR_INDEPENDENCE: f64 = 1e-6;

    /// Default pole threshold: `rho = |sin(tilt)|` below this means the tool axis is on
    /// the pole and the free rotary axis is held (spec 2.3, `kinematics.pole_eps`).
    pub const POLE_EPS_DEFAULT: f64 = 1e-7;

    /// `mu3^2` of the two-rotary subproblem may be this far below zero from rounding and
    /// still count as the boundary of the reachable orientation set (then `mu3 = 0`).
    pub const SUBPROBLEM_ROUNDING: f64 = 1e-12;

    /// Slack on axis limits in internal units (mm, rad): a value this far outside a stroke
    /// is rounding, not a violation (the spec's MX330 vector puts A exactly at -125 deg).
    pub const LIMIT_SLACK: f64 = 1e-9;

    /// Acceptance of a numeric (Levenberg-Marquardt) inverse: the forward kinematics must
    /// reproduce the tip to this (mm) and the tool axis to this (unit vector) (spec 3.2).
    pub const NUMERIC_ACCEPT: f64 = 1e-9;

    /// Maximum Levenberg-Marquardt iterations of the numeric inverse.
    pub const NUMERIC_MAX_ITERATIONS: usize = 200;

    /// Initial damping of the Levenberg-Marquardt iteration (relative to `diag(J^T J)`).
    pub const NUMERIC_INITIAL_DAMPING: f64 = 1e-3;

    /// Two branch candidates whose continuity costs (s) differ by less than this are a tie,
    /// broken by the user preference (spec 3.5).
    pub const COST_TIE: f64 = 1e-12;

    /// Two rotary solutions closer than this (rad, after reduction modulo 2 pi) and two
    /// linear solutions closer than this (mm) are the same joint vector.
    pub const SAME_JOINTS: f64 = 1e-9;

    /// The damping grows until this; beyond it no step reduces the residual and the
    /// iteration stops.
    pub const NUMERIC_MAX_DAMPING: f64 = 1e12;

    /// Smallest damping (keeps the normal equations positive definite).
    pub const NUMERIC_MIN_DAMPING: f64 = 1e-15;

    /// Factor applied to the damping after a successful step.
    pub const NUMERIC_DAMPING_DECREASE: f64 = 0.1;

    /// Factor applied to the damping after a rejected step.
    pub const NUMERIC_DAMPING_INCREASE: f64 = 10.0;

    /// Marquardt scaling floor: a diagonal entry of `J^T J` counts as at least this times
    /// the largest one (a joint with no effect near a pole still gets damped).
    pub const NUMERIC_DIAGONAL_FLOOR: f64 = 1e-9;

    /// The orientation iteration stops once `|O(q) - O|` is below `NUMERIC_ACCEPT` times
    /// this (room for the rounding of the final linear solve).
    pub const NUMERIC_ORIENTATION_MARGIN: f64 = 1e-2;

    /// Default rotary jump (rad, 30 deg) above which a block counts as a flip or unwind
    /// (spec 3.5 `flip_threshold`).
    pub const FLIP_THRESHOLD_DEFAULT: f64 = std::f64::consts::PI / 6.0;

    /// Default time charged for a retract, reorientation and approach around a jump on a
    /// non-cutting move (s) [PLACEHOLDER until the time model provides it].
    pub const REORIENT_PENALTY_DEFAULT: f64 = 5.0;

    /// Candidate joint vectors kept per pose by the branch dynamic programme (spec 3.5: K <= 8).
    pub const PLAN_BEAM: usize = 8;

    /// Uniform samples per block when measuring the deviation of joint-linear motion
    /// (spec 3.10), before golden-section refinement of the worst one.
    pub const DEVIATION_SAMPLES: usize = 16;

    /// Golden-section iterations refining the worst deviation sample (interval shrinks by
    /// 0.618 per iteration: 40 iterations reach 1e-8 of the block).
    pub const DEVIATION_REFINE_ITERATIONS: usize = 40;

    /// Maximum bisection depth of the joint-space subdivision (spec 3.10).
    pub const SUBDIVISION_MAX_DEPTH: usize = 16;

    /// A G93 word within this relative distance of a multiple of the output step is that
    /// multiple (rounding noise of `60/T` must not round an exact feed down a step).
    pub const FEED_ROUNDING: f64 = 1e-12;

    /// Turning angle (rad, 10 deg) up to which a junction belongs to a smooth curve sampled
    /// by a polyline (spec 8.3 `theta_smooth`).
    pub const SMOOTH_JUNCTION: f64 = std::f64::consts::PI / 18.0;

    /// Bisection iterations of the time model's velocity searches (relative precision 2^-60).
    pub const TIME_BISECTION_ITERATIONS: usize = 60;

    /// A per-axis direction component below this (mm or rad per mm of path) does not
    /// limit a block's acceleration or jerk (the axis does not move in that block).
    pub const AXIS_DIRECTION_ZERO: f64 = 1e-12;

    /// Default share of the path tolerance for joint-space interpolation (mm; spec 3.10
    /// `tol_pos`).
    pub const JOINT_INTERPOLATION_DEFAULT: f64 = 0.005;

    /// Default angular tolerance of the tool axis under joint-space interpolation (rad,
    /// 0.05 deg; spec 3.10 `tol_ang`).
    pub const JOINT_ANGLE_DEFAULT: f64 = 0.05 * std::f64::consts::PI / 180.0;

    /// Slack on the verification of emitted blocks (relative): rate and deviation checks
    /// pass when within this fraction above their limit (rounding only).
    pub const VERIFY_SLACK: f64 = 1e-9;

    /// A pole-axis move above this (rad, 90 deg) marks a branch flip: the two branches of
    /// the standard families differ by 180 deg on the pole axis, a continuous pole crossing
    /// keeps it (used by the greedy planner's events and the subdivision's midpoint check).
    pub const BRANCH_JUMP: f64 = std::f64::consts::FRAC_PI_2;

    /// Factor applied to one axis's velocity, acceleration and jerk limits to measure the
    /// time that axis costs (`TimeReport::axis_time_lost`): large enough that the axis never
    /// binds, finite so the jerk-limited formulas stay defined.
    pub const RELAXED_AXIS_FACTOR: f64 = 1e9;

    /// Largest total rotation of one block (rad) for which `feed::deviation_bound` holds
    /// (its distance bound needs `3 Omega < 1`); larger blocks are sampled.
    pub const BOUND_MAX_ROTATION: f64 = 0.3;

    /// Relative and absolute (mm) inflation of the trigonometry-free distance bound of
    /// `feed::deviation_bound_relaxed`, so that it also bounds the rounded exact distance.
    pub const BOUND_PRETEST_SLACK: f64 = 1e-9;

    /// Relative inflation of the atan-free upper bound `r_ref tan(phi) / F` of the rotation
    /// term of `feed::inverse_time_feed` (covers the rounding of the exact term, a few ulps).
    pub const ROTATION_TERM_SLACK: f64 = 1e-12;

    /// Largest rotary turn (rad, 5 deg) of one step of `plan::track`, which follows a CL move
    /// continuously: well below the 180 deg between the two inverse branches on the pole
    /// axis, so the nearest solution of each step is the continuation.
    pub const TRACK_STEP: f64 = std::f64::consts::PI / 36.0;

    /// First (and largest) step of `plan::track` as a fraction of the move.
    pub const TRACK_FIRST_STEP: f64 = 1.0 / 8.0;

    /// Smallest step of `plan::track` (fraction of the move): a turn above `TRACK_STEP` over
    /// a step this small is a discontinuity (an exact singularity), not a motion.
    pub const TRACK_MIN_STEP: f64 = 1.0 / 1_073_741_824.0;

    /// Most inverse evaluations of one `plan::track` (a guard; a move turning several full
    /// revolutions near the pole needs a few thousand).
    pub const TRACK_MAX_EVALUATIONS: usize = 200_000;

    /// An inverse solution is the end of `plan::track`'s continuous motion when its rotaries
    /// equal the tracked ones within this (rad) modulo a turn; the tracked values are inverse
    /// solutions of the same pose, so only rounding separates them.
    pub const TRACK_MATCH: f64 = 1e-6;

    /// Default retract distance (mm) along the tool axis of a link that changes branch or
    /// unwinds (`program::ProgramOptions::retract`) [PLACEHOLDER: a job's clearance should
    /// set it].
    pub const LINK_RETRACT_DEFAULT: f64 = 10.0;
}

pub mod mesh {
    //! Thresholds of `scallop_mesh`, re-exported there as `scallop_mesh::tol`.
    //!
    //! Thresholds of the mesh queries (each documented where it is decided).

    /// Barycentric slack of the ray-triangle test (`scallop_mesh::ray_triangle`): a
    /// relative margin of a few thousand ulps so that a ray through a shared edge
    /// or vertex hits at least one of the triangles around it despite rounding.
    pub const RAY_EDGE_SLACK: f64 = 1e-12;
}

pub mod optim {
    //! Thresholds of `scallop_optim`, re-exported there as `scallop_optim::tol`.
    //!
    //! Named constants of the optimiser (finishing.md 12.9). Each is a setting of
    //! the normative compact OrthoMADS, not a tuning knob.

    /// Initial frame and mesh size `Delta_0` in scaled variables (`[0, 1]`).
    pub const INITIAL_FRAME: f64 = 0.1;

    /// Smallest mesh index `l` (`l >= -2`): the largest frame is `0.1 * 2^2 = 0.4`.
    pub const MIN_MESH_INDEX: i32 = -2;

    /// Stop when the mesh size `Delta^m` falls below this (scaled units).
    pub const MIN_MESH_SIZE: f64 = 1e-9;

    /// The mesh index at which `Delta^m = 0.1 * 4^-l < MIN_MESH_SIZE` first holds
    /// (`0.1 * 4^-14 = 3.7e-10`); the finest mesh ever polled is `l = 13`.
    pub const STOP_MESH_INDEX: i32 = 14;

    /// Lattice resolution: every point the optimiser evaluates has scaled
    /// coordinates `m / LATTICE` with an integer `m` in `[0, LATTICE]`.
    /// `LATTICE = 10 * 4^14`, so `1 / LATTICE` is the mesh size at
    /// [`STOP_MESH_INDEX`] and every coarser mesh size is an integer number of
    /// lattice steps; cache keys are exact integers and periodic wraps are exact.
    pub const LATTICE: i64 = 10 * (1 << 28);

    /// `Delta_0` in lattice steps (`0.1 * LATTICE = 2^28`).
    pub const INITIAL_FRAME_STEPS: i64 = 1 << 28;

    /// The quadratic-model search uses cached points within this multiple of the
    /// frame size `Delta^p` (infinity norm, scaled units) of the incumbent.
    pub const MODEL_RADIUS_FRAMES: f64 = 2.0;

    /// Relative weight of the constant and linear coefficients in the
    /// minimum-norm model fit: small, so the norm minimised is (almost only) the
    /// Frobenius norm of the Hessian, as in the minimum-Frobenius-norm models.
    pub const MODEL_LINEAR_WEIGHT: f64 = 1e-3;

    /// Singular values below this fraction of the largest are treated as zero in
    /// the model fit's pseudo-inverse.
    pub const MODEL_RANK_REL: f64 = 1e-10;

    /// Projected-gradient iterations when minimising the model in the frame box.
    pub const MODEL_DESCENT_STEPS: usize = 60;

    /// Most cached points used by one model fit, as a multiple of the number of
    /// coefficients of a full quadratic (beyond that the fit only gets slower).
    pub const MODEL_POINTS_PER_COEFFICIENT: usize = 2;
}

pub mod post {
    //! Thresholds of `scallop_post`, re-exported there as `scallop_post::tol`.
    //!
    //! Every numeric threshold of the crate, named.

    /// Relative slack under which a value counts as exactly representable when rounding
    /// feed words (binary floating point cannot hold 57.368 exactly).
    pub const ROUNDING_SLACK: f64 = 1e-9;

    /// Largest rotation (deg) of a modulo-360 rotary in one block: blocks turning this much
    /// or more are split (spec 3.7: the control takes the shortest path).
    pub const MODULO_HALF_TURN: f64 = 179.0;

    /// Tilt words within this many degrees of zero satisfy either solution sign.
    pub const ZERO_TILT_DEG: f64 = 1e-6;

    /// Cost added to a tilted-plane solution whose tilt sign contradicts the direction word.
    pub const WRONG_SOLUTION_PENALTY: f64 = 1e6;

    /// Largest distance (mm) of the tool tip from a rotary axis assumed when turning the
    /// rounding of rotary words into a tip allowance.
    pub const REACH: f64 = 1000.0;

    /// Number of rounded angles (two rotaries, or three plane angles with margin) in the
    /// rounding allowance.
    pub const ROUNDED_ANGLES: f64 = 4.0;

    /// Relative slack on the path tolerance and the axis-rate ratio in `scallop_post::check_replay`.
    pub const CHECK_SLACK: f64 = 1e-6;

    /// Samples of each joint-space block in `scallop_post::check_replay`.
    pub const CHECK_SAMPLES: u32 = 16;

    /// Distance from a rounding tie (in units of the last digit) below which `fmt_number`
    /// leaves its integer fast path for the exact formatter.
    pub const FAST_FORMAT_TIE_MARGIN: f64 = 1e-6;
}

pub mod report {
    //! Thresholds of `scallop_report`, re-exported there as `scallop_report::tol`.
    //!
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
}

pub mod rough {
    //! Thresholds of `scallop_rough`, re-exported there as `scallop_rough::tol`.
    //!
    //! Named tolerances and thresholds of the roughing planner (mm unless said).

    /// Extra width, as a share of the stepover, allowed around the band a
    /// tool-down link may cross: a link's radial engagement stays within about
    /// one stepover (see `offset.rs`).
    pub const LINK_MARGIN_SHARE: f64 = 0.05;

    /// Share of a region's area an erosion by the stepover may lose beyond
    /// the bound `P ae + pi ae^2 h` before the offset is taken as failed
    /// (`offset.rs`): room for the kernel's arcs and joins.
    pub const OFFSET_AREA_SLACK: f64 = 1e-3;

    /// Relative change of the offset distance when an erosion is computed
    /// again after a failed offset (`offset.rs`).
    pub const OFFSET_RETRY: f64 = 1e-4;

    /// A facet whose unit normal has `z` above this is horizontal (a floor that
    /// gets a level of its own): within 0.08 degrees of level.
    pub const FLAT_NORMAL_Z: f64 = 1.0 - 1e-6;

    /// Heights of flat facets closer than this are one floor.
    pub const FLAT_MERGE: f64 = 1e-3;

    /// Levels closer than this are one level (the higher is kept).
    pub const LEVEL_MERGE: f64 = 1e-3;

    /// A floor's level is this far above the floor plus the axial allowance, so
    /// the waterline height is never exactly a facet's height (where every grid
    /// sample would tie).
    pub const FLAT_LIFT: f64 = 1e-5;

    /// The offset pattern's rings are refitted as lines and arcs within this
    /// share of the chord tolerance (the region booleans' tolerance, the job's
    /// path tolerance): the level regions' boundaries are dense polygons.
    pub const RING_ARC_FIT_SHARE: f64 = 0.25;

    /// Rapids down into cleared area stop this far above the cleared level; a
    /// plunge at the plunge feed does the rest.
    pub const APPROACH: f64 = 1.0;

    /// Such a rapid stops above a cleared level only where the tool centre lies
    /// this far inside the level's region (mm), else above the level over it
    /// that does: the level's passes sweep its region's boundary within their
    /// chords, so a centre on that boundary may graze the step a sloped wall
    /// keeps above the level (on `octagonal_pocket` a rapid 1 mm above a level
    /// met 2 mm of stock at the tool's rim, 1.7 um out of the swept area).
    pub const ENTRY_MARGIN: f64 = 0.05;

    /// Largest sweep of one arc move (rad): longer arcs are split so that no
    /// move reads as a full circle and the centre words stay well defined.
    pub const MAX_ARC_SWEEP: f64 = std::f64::consts::FRAC_PI_2;

    /// Most offset passes of one region (bounds the work on absurd inputs).
    pub const MAX_PASSES: usize = 100_000;

    /// Most levels of one plan.
    pub const MAX_LEVELS: usize = 10_000;

    /// A region is grown by this before testing whether a link stays in it, so
    /// that passes on its contour count as inside (mm): the tool may go this far
    /// into the allowance on a link.
    pub const LINK_GROW: f64 = 1e-4;

    /// Waterline loops are thinned by Douglas-Peucker at this before the region
    /// booleans (mm): their points lie within the waterline's chord tolerance
    /// (1e-4 mm) of each other's chords, far denser than a roughing region needs.
    /// The region's boundary moves by at most this (into the allowance, and with
    /// no allowance into the part: within the job's path tolerance).
    pub const SIMPLIFY: f64 = 1e-3;

    /// Helical entries: the tool centre's circle has this share of the tool
    /// radius (the bore is 1.5 D wide, no core left in its middle).
    pub const HELIX_RADIUS_SHARE: f64 = 0.5;

    /// Helical entries descend this much per unit of length along the circle
    /// (tan of about 3 degrees).
    pub const HELIX_SLOPE: f64 = 0.05;

    /// A point this far inside a ring (from a chord's midpoint, along its
    /// normal) stands for the region in containment tests between levels (mm).
    pub const INTERIOR_NUDGE: f64 = 1e-3;

    /// Material less than this above a level (mm) is not worth a pass: the
    /// in-process stock's cells that hold only this much over the level count
    /// as cleared (see `material.rs`).
    pub const MIN_CHIP: f64 = 0.05;

    /// Offset clearing: a ring along which the tool centre stays farther than
    /// R less this from the level's material cuts nothing worth a pass (mm)
    /// and is left out (the ring around the stock's sides).
    pub const AIR_RING_CHIP: f64 = 0.01;

    /// Offset clearing: rings are tested against the material at samples
    /// at least this far apart (mm; farther for larger tools, see
    /// `scallop-rough`'s `offset.rs`).
    pub const AIR_RING_STEP: f64 = 0.05;

    /// Offset clearing: a ring's point lies on the open side of its level
    /// (its nearest boundary is air, not a wall) when it is deeper than its
    /// level's depth plus this share of ae in the region with its air.
    pub const OPEN_SIDE_SHARE: f64 = 0.25;

    /// Offset clearing: a ring is cut into the stretches that reach the
    /// material where the air between two of them is longer than this share
    /// of the tool radius; a shorter gap is cut through.
    pub const AIR_RUN_GAP_SHARE: f64 = 2.0;

    /// Most cells of an in-process stock map (bounds the memory of the outline
    /// tracing on absurd inputs).
    pub const MAX_MATERIAL_CELLS: usize = 64_000_000;

    /// Adaptive clearing: the grid's cell side as a share of the tool radius
    /// (R / 16: 0.19 mm for a 6 mm tool).
    pub const GRID_SHARE: f64 = 1.0 / 16.0;

    /// Adaptive clearing: most cells of one region's grid; larger regions get
    /// coarser cells.
    pub const MAX_GRID_CELLS: usize = 8_000_000;

    /// Adaptive clearing: a pass is kept when its largest engagement, measured
    /// on the grid every cell side with the periphery probed every
    /// [`ENGAGE_PROBES`]th of a turn, is at most this times the target (the
    /// planner's margin under the 1.1 bound of docs/roughing.md).
    pub const ENGAGE_ACCEPT: f64 = 1.03;

    /// Adaptive rest roughing: links may leave the rest level's region for
    /// the level's whole tool-centre region (cleared before) up to this
    /// share of the tool radius from it (docs/roughing.md, "Adaptive rest
    /// roughing: links through the level's room").
    pub const REST_LINK_ROOM_SHARE: f64 = 4.0;

    /// Adaptive clearing: points probed on the tool's periphery.
    pub const ENGAGE_PROBES: usize = 180;

    /// Adaptive clearing: the walking tool's step, as a share of the tool
    /// radius (R / 8: 0.375 mm for a 6 mm tool).
    pub const WALK_STEP_SHARE: f64 = 0.125;

    /// Adaptive clearing: the sharpest turn of one step towards the
    /// material (rad, 30 degrees).
    pub const WALK_TURN: f64 = 0.524;

    /// Adaptive clearing: the sharpest turn of one step away from the
    /// material (rad, 150 degrees).
    pub const WALK_TURN_HARD: f64 = 2.618;

    /// Adaptive clearing: the turn by which a step that would leave the
    /// region is turned further away before bisection (rad, 5 degrees).
    pub const WALK_WALL_TURN: f64 = 0.0873;

    /// Adaptive clearing: bisections of a step's turn.
    pub const WALK_BISECTIONS: usize = 8;

    /// Adaptive clearing: headings tried all round at a pass's start.
    pub const WALK_START_HEADINGS: usize = 72;

    /// Adaptive clearing: a step whose engagement is under this share of the
    /// target cuts air.
    pub const WALK_AIR: f64 = 0.1;

    /// Adaptive clearing: a pass ends after this much air (share of R).
    pub const WALK_AIR_SHARE: f64 = 1.0;

    /// Adaptive clearing: a pass's centres kept as starts of later passes,
    /// this far apart (share of R).
    pub const WALK_START_SPACING: f64 = 0.25;

    /// Adaptive clearing both ways: a pass's last centre is also a place to
    /// start (the next pass goes back from there) unless it lies within this
    /// share of [`WALK_START_SPACING`] of the centre listed before it.
    pub const WALK_END_START_SHARE: f64 = 0.25;

    /// Adaptive clearing both ways: only a pass at least this long (share of
    /// R) is followed by one back along its frontier; a shorter one's
    /// frontier is peeled from its head, as when climbing.
    pub const WALK_BOTH_WAYS_SHARE: f64 = 2.0;

    /// Adaptive clearing both ways: a pass that ends where the region across
    /// its last step is narrower than this (share of R: a bar 4.5 mm wider
    /// than a 6 mm tool) is not followed by one back along its frontier
    /// (the reversal there would stop the tool); its frontier is peeled from
    /// its head.
    pub const WALK_NARROW_END_SHARE: f64 = 1.5;

    /// Adaptive clearing: a pass of more steps than this may start again
    /// where it started (it made progress there) ...
    pub const WALK_RESTART_STEPS: usize = 4;

    /// Adaptive clearing: ... and when it cleared at least this share of its
    /// length times the stepover.
    pub const WALK_RESTART_SHARE: f64 = 0.25;

    /// Adaptive clearing: the radius (mm) of the fillets of the region's
    /// convex corners on the last pass along its rings: a sliver at most
    /// 0.42 x this thick stays in a right-angled corner.
    pub const RING_FILLET: f64 = 0.1;

    /// Adaptive clearing: the sharpest turn of a ring (rad, 100 degrees)
    /// that gets a fillet; sharper corners keep their tip.
    pub const RING_FILLET_TURN: f64 = 1.745;

    /// Adaptive clearing: the first arc of a corner's clearing, as a share
    /// of the tool radius (its radius).
    pub const CORNER_START_SHARE: f64 = 2.0;

    /// Adaptive clearing: most arcs in one corner.
    pub const CORNER_ARCS: usize = 16;

    /// Adaptive clearing: a corner's next arc is at least this share smaller
    /// than the last (else its clearing stops there).
    pub const CORNER_MIN_SHRINK: f64 = 0.05;

    /// Adaptive clearing: most entries into one region (parts the walk from
    /// the first could not reach).
    pub const MAX_ENTRIES: usize = 1000;

    /// Offset clearing's loops where a ring would slot (docs/roughing.md,
    /// "Offset clearing", "Slots"): samples along a ring at most this share
    /// of R apart (a loop's place and its look-ahead probe).
    pub const LOOP_SAMPLE_SHARE: f64 = 0.01;

    /// Adaptive clearing's rings (docs/roughing.md, "Adaptive clearing"):
    /// a run of loops along less than this share of R is left out (the ring
    /// slots there). Short runs are the tips of tooth gaps narrowing below
    /// any loop, where loops of shrinking radius cost seconds each and
    /// leave the tip's slot; channels the walk could not turn into are
    /// longer.
    pub const LOOP_MIN_RUN_SHARE: f64 = 3.0;

    /// Offset clearing's transitions from a ring to the next one out
    /// (docs/roughing.md, "Offset clearing", transitions): the engagement
    /// they are planned to hold, as a share of the target.
    pub const TRANSITION_ENGAGEMENT: f64 = 1.05;

    /// Or this share of the target above the ring's own engagement, where
    /// the ring's curvature takes that over [`TRANSITION_ENGAGEMENT`].
    pub const TRANSITION_OVER: f64 = 0.02;

    /// The ring's curvature for a transition: its mean along this share of R.
    pub const TRANSITION_BEND_SHARE: f64 = 4.0;

    /// Most steps of a transition's depth profile (bounds the work).
    pub const TRANSITION_MAX_STEPS: usize = 100_000;

    /// A transition's angle to the ring stays this share under what the
    /// engagement allows.
    pub const TRANSITION_MARGIN: f64 = 0.1;

    /// Points along a transition at most this share of R apart.
    pub const TRANSITION_STEP_SHARE: f64 = 0.05;

    /// Largest turn (rad) between chords of either ring along a transition
    /// (15 degrees; a corner or a loop there keeps the straight link).
    pub const TRANSITION_TURN: f64 = std::f64::consts::PI / 12.0;

    /// A transition's end lies on the next ring within this share of ae
    /// (else that ring is not the offset of the last one there).
    pub const TRANSITION_FIT_SHARE: f64 = 0.01;

    /// Most loops in one level (bounds the work on absurd inputs).
    pub const MAX_LOOPS: usize = 2_000_000;

    /// Bisections of a loop's advance (to 2 R / 2^16).
    pub const LOOP_BISECTIONS: usize = 16;

    /// Tool positions along one loop where its engagement is measured.
    pub const LOOP_POSITIONS: usize = 180;

    /// Adaptive clearing: the last stretch of a link to a pass's start may
    /// engage up to this share of the target, by the grid's all-round
    /// reading.
    pub const LINK_APPROACH: f64 = 1.0;

    /// Adaptive clearing: the chords of the region's walls in the walk's wall
    /// test (mm): a wall bending into the region is met this much early.
    pub const WALK_CHORD: f64 = 5e-5;

    /// Adaptive clearing: most steps of one region's walk.
    pub const MAX_WALK_STEPS: usize = 20_000_000;

    /// Adaptive clearing: a walked pass (and a corner's arc) is emitted as the
    /// fewest lines within this share of the tool radius of its steps, each
    /// inside the region (Douglas-Peucker): 0.02 mm for a 6 mm tool. The steps
    /// of R / 8 turn a little at each; as lines of a millimetre or more the
    /// pass runs nearer the feed under a jerk-limited controller, where short
    /// moves or arcs cut into short chords hold it far below the feed after
    /// every slow-down (docs/benchmarks.md, "Adaptive clearing: where the
    /// cycle time goes"). Moving a pass by `f R` changes its engagement by at
    /// most `f / sin(phi)`: 0.5 degree at 0.2 D.
    pub const WALK_FIT_SHARE: f64 = 1.0 / 150.0;

    /// Adaptive clearing: the strip along the walls, as a share of the tool
    /// radius, whose material tells no cutting from air in the walk (a pass
    /// ends, a start is dropped, with only that left) and that links may
    /// cross: the lines of [`WALK_FIT_SHARE`] leave slivers that thin where
    /// the tool slides along a wall, which the rings cut. The engagement
    /// itself counts them.
    pub const WALK_WALL_STRIP_SHARE: f64 = WALK_FIT_SHARE;

    /// Adaptive clearing: a tool-down link leaves a pass's end and meets the
    /// next pass's start along arcs of these radii (shares of the tool
    /// radius, the smallest that cuts nothing first), turning away from the
    /// material, joined by a common tangent or the link search (a Dubins
    /// path, Dubins 1957, Amer. J. Math. 79(3)): the tool reverses without
    /// stopping, where a jerk-limited controller stops at each reversal.
    /// The smallest first: under a jerk limit J the speed along an arc of
    /// radius rho is at most `(J rho^2)^(1/3)`, so a half turn takes at
    /// least `pi rho^(1/3) / J^(1/3)`, less on a smaller arc, which is also
    /// shorter (docs/benchmarks.md, "Adaptive clearing: small link turns and
    /// narrow pass ends, seventeenth session").
    pub const LINK_TURN_SHARES: [f64; 3] = [0.05, 0.15, 0.5];

    /// Adaptive clearing: the first arc of a link from a pass's end leaves
    /// along the pass's last heading, else turned further away from the
    /// material by the least of these (rad: 10, 20, 30, 45, 60, 90 degrees)
    /// whose arc fits: a pass that ends against a wall turns there instead
    /// of reversing (docs/benchmarks.md, "Adaptive clearing: cycle time and
    /// links, sixth session").
    pub const LINK_END_TURNS: [f64; 7] = [0.0, 0.175, 0.349, 0.524, 0.785, 1.047, 1.571];

    /// Adaptive clearing: a step's engagement is measured at these points
    /// along it (shares of its length from its start), and a line that
    /// replaces several steps at the same points along it: right after a
    /// turn towards the material, or halfway along a step, the front half
    /// can lie along the thin edge of what earlier cuts left where it does
    /// not at the step's end.
    pub const WALK_STEP_SAMPLES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

    /// Adaptive clearing: the chords of a link's arcs deviate this much from
    /// them (mm): 6 degrees between chords at a radius of 0.45 mm.
    pub const LINK_TURN_SAGITTA: f64 = 0.002;

    // Tool-down links of the adaptive pattern (`adaptive/links.rs`).

    /// Lattice of the link search: every this-many grid cells (R / 8 for the
    /// default grid of R / 16).
    pub const LATTICE: usize = 2;

    /// Probes on the tool's periphery when checking that a centre cuts nothing.
    pub const LINK_PROBES: usize = 128;

    /// A probe counts as in material when the swept field there exceeds R by
    /// more than this (mm): the bilinear reading of the distance to the swept
    /// centres is within about 2 um of the distance at R from them with cells of
    /// R / 16, so a link may touch material at most this deep.
    pub const LINK_SLACK: f64 = 0.005;

    /// The last this-many R of a link may engage material up to the accepted
    /// bound (the start of a closed front lies in material by the step).
    pub const APPROACH_SHARE: f64 = 2.0;

    /// A link path longer than this times the straight distance (plus
    /// [`DETOUR_EXTRA`] R) is a retract instead.
    pub const DETOUR: f64 = 3.0;

    /// See [`DETOUR`].
    pub const DETOUR_EXTRA: f64 = 10.0;

    /// Most lattice nodes one link search expands.
    pub const MAX_EXPAND: usize = 60_000;

    /// Most candidate ends (lattice nodes near the target) one link search tries.
    pub const MAX_GOALS: usize = 64;
}

pub mod rough5 {
    //! Thresholds of `scallop_rough5`, re-exported there as `scallop_rough5::tol`.
    //!
    //! Thresholds of 5-axis roughing, each documented.

    /// A tool axis whose x component is below this (in absolute value) builds its
    /// frame from +X, else from +Y (`scallop_rough5::place`): the frame is then never
    /// built from a vector nearly parallel to the axis.
    pub const FRAME_SWITCH: f64 = 0.9;

    /// A contact closer to the tool axis than this (mm) is on the axis: its
    /// normal is taken from the tool's centre point, not from the radial
    /// direction (which is then undefined).
    pub const ON_AXIS: f64 = 1e-12;

    /// A tool axis shorter than this (mm, the distance between a path point and
    /// its tilt point) is refused: the axis would be noise.
    pub const MIN_AXIS_LENGTH: f64 = 1e-6;

    /// Tool-axis steps below this (rad) are not subdivided (the axis is the
    /// same to rounding).
    pub const ANGLE_EPS: f64 = 1e-12;

    /// Body samples of the flank collision check are this far apart along the
    /// axis (mm); the check keeps a clearance of half of it, so it is
    /// conservative (see `collide.rs`).
    pub const BODY_STEP: f64 = 0.25;

    /// Most passes (curves) of one level that the assembly accepts: a guard
    /// against absurd settings.
    pub const MAX_PASSES: usize = 10_000;

    /// Most CL points of one pass (length over the step): a guard against
    /// absurd settings.
    pub const MAX_PASS_POINTS: usize = 1_000_000;

    /// Relative finite-difference step of the SQP gradients (times 1 + |x_i|,
    /// the polynomial coefficients being of order 1).
    pub const SQP_FD_STEP: f64 = 1e-6;

    /// A start whose constraint violation exceeds this is refused by the SQP.
    pub const SQP_FEASIBLE: f64 = 1e-9;

    /// The SQP stops when its step is below this in every coefficient.
    pub const SQP_STEP: f64 = 1e-9;

    /// The SQP stops when an iteration lowers the objective by less than this
    /// times (1 + |objective|).
    pub const SQP_REL_DECREASE: f64 = 1e-10;

    /// Most iterations of one active-set QP.
    pub const QP_MAX_ITER: usize = 500;

    /// A working-set multiplier above -this counts as non-negative in the QP.
    pub const QP_MULTIPLIER: f64 = 1e-10;

    /// The smallest joint progress g_T' + g_D' of the two guide points (Eq.
    /// 3.17 as corrected: never both stalled), per unit of s.
    pub const MIN_PROGRESS: f64 = 1e-3;

    /// Angular step (rad, 0.5 degree: Jousselin 2020's cone sweep as the spec
    /// fixes it) of the search for a collision-free axis in the correction plane
    /// (`scallop_rough5::correct_planar`, Eq. 3.31).
    pub const CONE_STEP: f64 = 0.5 * std::f64::consts::PI / 180.0;

    /// The limit of the visibility cone is found by bisection to this (rad, 0.01
    /// degree) once a free axis is found.
    pub const CONE_BISECTION: f64 = 0.01 * std::f64::consts::PI / 180.0;

    /// The correction plane is searched this far (rad) on each side of the
    /// projection of the axis on the (feed, normal) plane: a quarter turn.
    pub const CONE_HALF_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

    /// A corrected axis must have a z component above this (cos 60 degrees):
    /// the correction never leans the tool more than 60 degrees from +Z, past
    /// which the shank rather than the flutes would face the material.
    pub const CONE_MIN_Z: f64 = 0.5;

    /// Most rounds of collision correction of one pass (each corrects the pairs
    /// the angular-step limit inserted next to the last round's corrections):
    /// Jousselin 2020 caps its correction loop at 3 (Ch. 3 §3, Fig. 3.34).
    pub const CORRECTION_ROUNDS: usize = 3;

    /// A pair of a limit pass (along the flanks) keeps its guide-curve tilt
    /// where the vertical tool would leave, between its level and the level
    /// above, a step thicker than this many flank allowances (the horizontal
    /// run of the tilted axis over the level's height): a thinner step only
    /// takes the finishing tool's stock from one to at most two allowances,
    /// which a roughing program need not spend the rotary axes on
    /// (`scallop_rough5::Rough5Settings::vertical_thin_steps`; docs/rough5.md,
    /// "Limit passes: the tilt where it pays").
    pub const LIMIT_STEP_ALLOWANCES: f64 = 1.0;

    /// A stretch of vertical pairs of a guide-curve pass is thinned to pairs
    /// at most this many steps (`--step`) apart
    /// (`scallop_rough5::thin_vertical`): 20 mm blocks at the default 1 mm
    /// step, the guide points between them checked within the chord below.
    pub const THIN_SPAN_STEPS: f64 = 20.0;

    /// A vertical pair is dropped only if every guide point it stands for lies
    /// within this many flank allowances of the segment that replaces them
    /// (0.05 mm at a 0.5 mm allowance: a tenth of the material the finishing
    /// tool is given, the proof's own sweep tolerance).
    pub const THIN_CHORD_ALLOWANCES: f64 = 0.1;

    /// The fillet radius, in tool radii, of a convex corner of an inner pass
    /// (a path curve inside a level's limit curves) where the tool is vertical
    /// (`scallop_rough5::round_corners`; docs/rough5.md, "Corners and
    /// blocks"): 4 mm for the R 5 torus. With a_e at most the tool radius the
    /// next pass out covers what the fillet leaves outside the ring.
    pub const CORNER_FILLET_RADII: f64 = 0.8;

    /// The largest turn (rad, 120 degrees) of an inner pass's convex corner that
    /// gets a fillet of [`CORNER_FILLET_RADII`]; sharper corners, the limit
    /// passes' and concave ones are refitted within the thinning's chord only.
    pub const CORNER_FILLET_MAX_TURN: f64 = 2.094_395_102_393_195_5;

    /// Turns (rad, 1 degree) below this at a pair are part of a straight or
    /// gently curved stretch, not of a corner.
    pub const CORNER_TURN_NOISE: f64 = 0.017_453_292_519_943_295;

    /// The pairs of one corner are at most this many steps (`--step`) apart:
    /// a long block between two turns makes them two corners.
    pub const CORNER_LINK_STEPS: f64 = 1.5;

    /// A fillet's end within this (mm) of a pair kept beside it is that pair:
    /// no block of a few micrometres.
    pub const FILLET_MERGE: f64 = 0.01;

    /// A fillet's arc is written in chords that turn by at most this share of
    /// the time model's smooth junction (`machine::SMOOTH_JUNCTION`, 10 degrees):
    /// a sharper junction is timed as a corner the controller blends within
    /// its tolerance, which on short blocks is near a stop.
    pub const FILLET_TURN_SHARE: f64 = 0.9;

    /// A flank triangle whose outward normal (out of the volume to remove)
    /// rises above the horizontal by more than this sine (1 degree) is an
    /// undercut: the 3+2 baseline looks for setups that reach under it
    /// (`scallop_rough5::setup_axes`).
    pub const UNDERCUT_SIN: f64 = 0.017_452_406_437_283_5;

    /// A 3+2 setup's axis leans this much (rad, 3 degrees) beyond the mean
    /// undercut of its flanks, so the flutes clear the overhang it reaches
    /// under.
    pub const SETUP_MARGIN: f64 = 3.0 * std::f64::consts::PI / 180.0;

    /// The undercut flanks are grouped by the azimuth of their normals in
    /// this many equal sectors (the first centred on +X); each sector is one
    /// candidate 3+2 setup.
    pub const SETUP_SECTORS: usize = 4;

    /// A sector whose undercut area is below this share of the whole undercut
    /// area gets no setup of its own.
    pub const SETUP_MIN_SHARE: f64 = 0.05;

    /// Between two 3+2 setups the tool leaves along the old axis and comes
    /// back along the new one from this height above the stock (mm).
    pub const SETUP_CHANGE_LIFT: f64 = 50.0;

    /// Chord tolerance (mm) of the 3-axis baselines: the booleans of the level
    /// regions and the arcs of the z-level passes written as lines (a tilted
    /// setup has no XY arcs in the part frame).
    pub const BASELINE_CHORD: f64 = 0.005;

    /// The material map of a rest setup (the in-process stock seen along the
    /// setup's axis) has cells this many times the tri-dexel spacing, so that
    /// every cell holds a sample of the tilted rays.
    pub const MATERIAL_CELL_FACTOR: f64 = 2.0;
}

pub mod sim {
    //! Thresholds of `scallop_sim`, re-exported there as `scallop_sim::tol`.
    //!
    //! The simulator's named numeric thresholds (the workspace-wide ones are in
    //! `scallop_geom::tol`).

    /// A stock width within this relative distance of a whole number of cells is
    /// that number of cells (not one more): `60 / 0.05` is 1200 cells even when the
    /// division rounds to 1200.0000000000002.
    pub const GRID_SNAP: f64 = 1e-9;

    /// Default number of gouge cells listed in a `scallop_sim::SimError::Gouge`.
    pub const WORST_REPORTED: usize = 20;

    /// Cells of the machined surface over the scallop limit that
    /// `scallop_sim::split_rest` lists for a refinement, at most (the thickest).
    pub const OVER_REPORTED: usize = 20_000;

    /// Slopes `|dz / L|` of a move above this are treated as vertical: the
    /// horizontal travel is then below 1e-100 of the vertical one, far below
    /// rounding, and the slope's square stays finite in the closed forms.
    pub const VERTICAL_SLOPE: f64 = 1e100;

    /// Largest distance (mm) between a circular or helical move of a tri-dexel
    /// cut and the chords it is cut as (their vertices lie on the arc).
    pub const ARC_SAGITTA: f64 = 1e-4;

    /// Margin (mm) subtracted from the lower bounds of a swept floor that skip
    /// the exact per-cell solve (`z_low + h(distance)`): far above the rounding of
    /// both the bound and the solve (1e-14 mm at 100 mm), so that a skip never
    /// happens where the solve would have lowered the cell, and results are the
    /// same bits as without the bound.
    pub const FLOOR_BOUND_MARGIN: f64 = 1e-9;

    /// A probed point of the tool's periphery counts as cut by one of the tool's
    /// recent moves only when it lies deeper than this (mm) inside the disc swept
    /// by that move: the periphery of the current position is at exactly `R`
    /// from the path's last point, and rounding must not count it as cut.
    pub const ENGAGEMENT_CONTACT: f64 = 1e-6;

    /// Samples per block of an engagement evaluation: a block reads the raster of
    /// older cuts as it stood before the block, its samples run in parallel. A
    /// fixed count, so the figures do not depend on the thread count.
    pub const ENGAGEMENT_BLOCK: usize = 64;

    /// The engagement follows an arc move (G2/G3) along chords whose sagitta is
    /// at most this (mm, 1 um): as `scallop engagement` reads a program's arcs.
    pub const ENGAGEMENT_ARC_SAGITTA: f64 = 1e-3;

    /// On the in-process stock (`scallop_sim::stock_engagement`), a probe of the
    /// periphery is in material when the stock there rises more than this (mm)
    /// above the height where the tool's profile reaches its radius: thinner
    /// material (the floor a pass at the same level left, up to the z-map's
    /// rounding) is not engagement.
    pub const ENGAGEMENT_FLOOR: f64 = 0.01;

    /// A move at cutting depth whose end lies more than this (mm) below its
    /// start descends: it starts an entry (a plunge, ramp or helix reached by a
    /// tool-down link counts as one reached from a retract). Moves of one level
    /// share their height exactly; a ramp's smallest descent per move is far
    /// above this.
    pub const ENGAGEMENT_DESCENT: f64 = 1e-6;

    /// The smallest collision-free stick-out of a tri-dexel cut
    /// (`scallop_sim::DexelOptions::max_stick_out`) is bisected to within this
    /// (mm) above the length where the shank or the holder first meets stock.
    pub const STICK_OUT_TOL: f64 = 0.01;
}

pub mod strategy {
    //! Thresholds of `scallop_strategy`, re-exported there as `scallop_strategy::tol`.
    //!
    //! Every numeric threshold and algorithm constant of this crate.
    //!
    //! Path-tolerance budget (style guide 2.6): the tessellation of parametric
    //! surfaces takes [`crate::Tolerances::TESSELLATION_SHARE`] (0.25), the
    //! forward sampling along a pass [`SAMPLING_SHARE`] (0.5) and the merging of
    //! collinear points [`SIMPLIFY_SHARE`] (0.25): the total is `Tolerances::path`.
    //!
    //! Below the cutter-location surface (a gouge between cutter locations) only
    //! the sampling share counts: a feed or link move never lies deeper than
    //! `SAMPLING_SHARE * path` under the exact drop-cutter surface. The merging is
    //! one-sided (`scallop_toolpath::simplify_above`: a kept chord passes on or
    //! above every point it replaces), so its share is spent above the surface only.

    /// Share of the path tolerance for the chordal deviation of the sampled CL
    /// polyline (a step is bisected while the CL midpoint is farther than this
    /// share of `path` above or below the chord).
    pub const SAMPLING_SHARE: f64 = 0.5;

    /// Share of the path tolerance for merging nearly collinear CL points
    /// (`scallop_toolpath::simplify_above`: above the sampled polyline only).
    pub const SIMPLIFY_SHARE: f64 = 0.25;

    /// Share of the path tolerance for merging the CL points of parallel-planes
    /// passes and links, one-sided (`simplify_above`): half of [`SIMPLIFY_SHARE`].
    /// A kept chord passes above the valleys it smooths, and that material lies
    /// between the feed samples where the planner measures the scallop: with the
    /// full share the z-map simulation of the demo job (Choi, bull-nose R 5, r 2,
    /// sh 0.01 mm) found 0.01035 mm, over sh plus its resolution bound (0.01031).
    pub const PASS_SIMPLIFY_SHARE: f64 = 0.125;

    /// The one-sided merging's tolerance is also at most this share of the
    /// scallop height. A merged chord rides above the points it replaces, and the
    /// material under it adds to the scallop between the feed samples where the
    /// planner measures a pair of planes: the measure adds the larger lift of the
    /// two planes (a small Choi zone study simulated 0.01157 mm for sh 0.01 mm
    /// with the merging budgeted in the path tolerance only, docs/validation.md).
    pub const MERGE_SCALLOP_SHARE: f64 = 0.02;

    /// A forward step is split while the CL point at its middle, or at one of its
    /// quarter points (an inflection inside the step can put the middle on the
    /// chord), lies more than this fraction of the sampling share above the chord.
    /// Where the CL surface is concave over the step (a crest, the top of a
    /// descent), the chord's deepest point under it is at most twice the
    /// midpoint's depth, so the chord stays within the sampling share. Jumps of the CL surface (walls) are
    /// bisected down to `(GOUGE_MIDPOINT_SHARE * SAMPLING_SHARE * path)^2 / (2 R)`
    /// (over which a circular arc of radius up to the cutter radius `R` rises by
    /// at most that depth) and then stepped over vertically.
    pub const GOUGE_MIDPOINT_SHARE: f64 = 0.5;

    /// Pass ends are located by bisection of the region boundary until the bracket
    /// is shorter than this share of the path tolerance (mm along the pass).
    pub const BOUNDARY_SHARE: f64 = 0.5;

    /// Forward steps are never bisected below this fraction of `max_step`.
    pub const MIN_STEP_FRACTION: f64 = 1.0 / 4096.0;

    /// The smallest horizontal plane spacing (mm) the planner accepts (finishing.md
    /// 6.4 uses `Delta_min = 1e-6 m`); below it the scallop height cannot be met
    /// with this cutter and direction and planning fails.
    pub const MIN_SPACING: f64 = 1e-3;

    /// When the measured scallop between a plane and its tentative successor
    /// exceeds `sh`, the gap is multiplied by `sqrt(sh / h) * SPACING_SAFETY` (the
    /// scallop grows about as the square of the gap) and measured again.
    pub const SPACING_SAFETY: f64 = 1.0 - 1e-6;

    /// Retries of the tentative next plane before giving up.
    pub const MAX_SPACING_RETRIES: usize = 24;

    /// Iterations of the first-plane fixed point (its offset is half its own spacing).
    pub const FIRST_PLANE_ITERATIONS: usize = 4;

    /// Relative measurement slack of the scallop check: a measured height up to
    /// `sh * (1 + SCALLOP_REL_SLACK)` passes (rounding of the envelope search).
    pub const SCALLOP_REL_SLACK: f64 = 1e-6;

    /// Golden-section iterations of the envelope minimisation along one segment.
    pub const GOLDEN_ITERATIONS: usize = 64;

    /// Iterations of the cusp search (Illinois false position, then bisection).
    pub const CUSP_ITERATIONS: usize = 80;

    /// Relative convergence of the cusp search (times the plane gap).
    pub const CUSP_REL_TOL: f64 = 1e-9;

    /// Bins of the scallop histogram over `[0, sh]` (one more bin counts heights above `sh`).
    pub const HISTOGRAM_BINS: usize = 10;

    /// A normal whose XY projection is shorter than this is horizontal (slope 0).
    pub const HORIZONTAL_XY: f64 = 1e-12;

    /// A contact this far (relative to the cutter radius) outside the flat bottom
    /// of a bull-nose lies on its torus, whose normal is then used.
    pub const TORUS_CONTACT_REL: f64 = 1e-9;

    /// Bisection iterations of the look-ahead velocity solver.
    pub const VELOCITY_ITERATIONS: usize = 60;

    /// Moves shorter than this (mm) are ignored by the time models (no direction).
    pub const ZERO_LENGTH: f64 = 1e-12;

    /// An envelope minimum within this fraction of the cutter radius of a pass end
    /// comes from the end position (scallop samples there are skipped).
    pub const PASS_END_REL: f64 = 1e-9;

    /// A contact within this fraction of its triangle's longest edge from a vertex
    /// or an edge lies on it (for the region's boundary test).
    pub const ON_FEATURE_REL: f64 = 1e-9;

    /// Virtual planes (plus one) of the dense-pass reference of a cusp over the limit.
    pub const REFERENCE_PLANES: usize = 8;

    /// Forward step of the dense-pass reference, as a fraction of the cutter radius.
    pub const REFERENCE_STEP_FRACTION: f64 = 1.0 / 32.0;

    /// From the second retry on, the gap shrinks at least by this factor.
    pub const SPACING_MIN_SHRINK: f64 = 0.9;

    /// Lateral samples of the residual between two passes when the envelopes do
    /// not cross or the cutter is flat (its saw tooth need not peak at the crossing).
    pub const CUSP_SPAN_SAMPLES: usize = 32;

    /// The first retries of a plane measure the scallop against the part only;
    /// later ones also subtract rest material (dense virtual passes, costly).
    pub const RAW_RETRIES: usize = 3;

    /// Relative convergence of the golden-section envelope search (times the cutter
    /// radius): the envelope's value errs by the square of it (times the curvature).
    pub const GOLDEN_REL_TOL: f64 = 1e-6;

    /// Passes of the network planner shorter than this (mm) are dropped; their
    /// vertices still count for the spacing (finishing.md 6.3: `eps_pass = 1e-6 m`).
    pub const MIN_PASS_LENGTH: f64 = 1e-3;

    /// Segments of the polylines that estimate isoline lengths for the network
    /// resolution (finishing.md 6.3 \[DECISION\]).
    pub const NETWORK_ISOLINE_SEGMENTS: usize = 200;

    /// Parameters of the isolines whose longest length sets the network resolution
    /// (finishing.md 6.3: `v in {0, 1/4, 1/2, 3/4, 1}`, likewise for u).
    pub const NETWORK_ISOLINE_PARAMETERS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

    /// Largest number of network quads per direction (a 0.5 mm mesh of a 1 m part).
    pub const MAX_NETWORK_QUADS: usize = 2048;

    /// Relative slack of the spacing comparisons of the network sweep: a plane's
    /// spacing within this fraction below the gap accepts the gap (rounding).
    pub const LOOKAHEAD_REL: f64 = 1e-9;

    /// Moves of a tentative next plane (look-ahead) before the sweep gives up.
    pub const MAX_LOOKAHEAD_RETRIES: usize = 32;

    /// A network plane closer than this fraction of the zone's extent (at least
    /// 1 mm) to the lowest node is moved that far inside, so that a plane at
    /// `d_min` yields the boundary (nodes on a plane count as above it).
    pub const PLANE_NUDGE_REL: f64 = 1e-9;

    /// A far strip wider than half a spacing by less than this fraction of the
    /// spacing gets no further plane (rounding; ends the network sweep).
    pub const END_STRIP_REL: f64 = 1e-6;

    /// Look-ahead moves of the network sweep that go exactly to the spacing found;
    /// later ones shrink by an extra `LOOKAHEAD_SHRINK * 2^k` (at most 1/2).
    pub const LOOKAHEAD_PLAIN_RETRIES: usize = 4;

    /// See [`LOOKAHEAD_PLAIN_RETRIES`].
    pub const LOOKAHEAD_SHRINK: f64 = 1e-3;

    /// Where the spacing shrinks from plane to plane, the network sweep steps by
    /// `Delta_k - LOOKAHEAD_TREND (Delta_{k-1} - Delta_k)` instead of `Delta_k`, so
    /// that the next plane's own spacing usually accepts the gap at once (a
    /// slightly conservative step instead of a second plane).
    pub const LOOKAHEAD_TREND: f64 = 1.25;
    /// Measurements of the scallop per isoparametric pass pair while fitting the
    /// spacing (each scales the step by `sqrt(sh / h)`).
    pub const ISO_FIT_ITERATIONS: usize = 8;

    /// Points across the gap between two isoparametric passes, plus one, at which the
    /// scallop is measured (at every running sample).
    pub const ISO_LATERAL_SAMPLES: usize = 6;

    /// Most samples of one isoparametric pass.
    pub const ISO_MAX_SAMPLES: usize = 20_000;

    /// Largest isoparametric step-over, as a multiple of the cutter radius (where the
    /// effective radius is infinite: a horizontal flat bottom).
    pub const ISO_MAX_STEP_OVER: f64 = 1.8;

    /// The isoparametric scallop check walks a pass's segments outwards from the
    /// measured point's running parameter and stops after this many in a row that
    /// cannot come closer (a segment left out only enlarges the measured scallop).
    pub const ISO_WINDOW_MISSES: usize = 8;

    /// An isoparametric step whose measured scallop lies between this fraction of
    /// `sh` and `sh` is accepted without trying a larger one.
    pub const ISO_FIT_ACCEPT: f64 = 0.8;

    /// Budget of one plan in drop-cutter queries, checked before planning on a lower bound
    /// (forward samples per pass at `max_step` times the passes at the flat-surface spacing):
    /// 5e7 queries, a few minutes on 2 cores and about 1 GB of samples; a request over it is
    /// refused with the estimate.
    pub const MAX_PLAN_SAMPLES: f64 = 5e7;

    /// Forward samples of one pass at `max_step` (the samples of a plane are held at once):
    /// 1e7, 80 MB of abscissae and 0.6 GB of cutter locations.
    pub const MAX_PASS_SAMPLES: f64 = 1e7;

    /// The smallest path tolerance (mm) a plan accepts: a tenth of a micron, below the
    /// resolution of machine axes and of the G-code's four decimals; a smaller tolerance
    /// only multiplies samples, with forward steps bisected down to `MIN_STEP_FRACTION`.
    pub const MIN_PATH_TOLERANCE: f64 = 1e-4;

    /// Waterline levels of steep-and-shallow finishing stay this share of the path
    /// tolerance inside the steep triangles' z range and the part's (mm): the
    /// waterline exists strictly inside the part's height range.
    pub const LEVEL_EDGE_SHARE: f64 = 1.0;

    /// Most waterline levels of one steep-and-shallow plan (bounds the work before
    /// it is spent: a wall 1 m tall at the smallest spacing of a 0.1 mm ball).
    pub const MAX_LEVELS: usize = 20_000;

    /// A pass of a waterline level is linked to the previous pass's end by a
    /// straight feed move (when the move stays above the CL surface) only if they
    /// are at most this many cutter radii apart; farther, it retracts.
    pub const LEVEL_LINK_RADII: f64 = 2.0;

    /// Chord tolerance of the waterline loops of steep-and-shallow finishing, as a
    /// share of the path tolerance; the loops' points are pushed out by
    /// [`LEVEL_PUSH_CHORDS`] of it, so no chord cuts into a convex wall, and the
    /// level spacing holds the scallop height less the push.
    pub const LEVEL_CHORD_SHARE: f64 = 0.1;

    /// A triangle flatter than this slope (rad) is a floor: steep-and-shallow
    /// finishing runs a waterline level just above it (at the levels' edge margin).
    pub const FLAT_SLOPE: f64 = 1e-3;

    /// The level of a flat area runs this share of the path tolerance above it:
    /// the waterline there is the contour where a wall lifts the cutter off the
    /// floor, and the floor is left with no more than this.
    pub const FLAT_LIFT_SHARE: f64 = 0.01;

    /// A well of a flat area's level (the only place where the cutter reaches
    /// the floor of a pocket just wider than it, narrower than the waterline
    /// grid step) is looked for within this many grid steps of a valley bottom
    /// of the grid, and its contour within this many grid steps of the point found.
    pub const WELL_REACH_STEPS: f64 = 2.0;

    /// Most probes (moves and halvings of the step) of the descent from a
    /// valley bottom of the waterline grid towards a well.
    pub const WELL_DESCENT_MOVES: usize = 64;

    /// Rays of the first pass of a well's contour; each gap between two is
    /// halved while the contour leaves the chord by more than the chord
    /// tolerance, at most [`WELL_RAY_DEPTH`] times.
    pub const WELL_RAYS: usize = 32;

    /// Most halvings of a gap between two rays of a well's contour.
    pub const WELL_RAY_DEPTH: u32 = 6;

    /// The contact of a waterline loop point is probed this many chord
    /// tolerances inside the loop, where the part lifts the cutter above the level.
    pub const LEVEL_PROBE_CHORDS: f64 = 4.0;

    /// Waterline levels are spaced this fraction of the profile rule's spacing
    /// (the rule assumes a wall of constant slope between two levels; the stock
    /// simulation proves the result).
    pub const LEVEL_SPACING_SAFETY: f64 = 0.9;

    /// Waterline loop points are pushed out this many chord tolerances: the
    /// kernel bounds a chord's deviation at its midpoint, and on a near-vertical
    /// wall any inward step is a deep vertical gouge.
    pub const LEVEL_PUSH_CHORDS: f64 = 2.0;

    /// A link between two waterline passes is checked against the drop-cutter
    /// every this many chord tolerances along it.
    pub const LEVEL_LINK_SAMPLE_CHORDS: f64 = 10.0;

    /// When the planner tolerates rest material (steep-and-shallow) and a
    /// section of a plane pair has rest (a crease's normal, the foot of a wall
    /// that the waterline levels finish), the next plane is at most this share
    /// of the largest step-over away (and at most the rule's spacing); the
    /// other sections of the pair still hold sh, and the stock simulation
    /// reports what is left.
    pub const REST_SPACING_SHARE: f64 = 0.25;

    /// Half-width (degrees) of the slope band that both parallel planes and
    /// waterline levels finish in steep-and-shallow finishing.
    pub const STEEP_OVERLAP_DEG: f64 = 10.0;

    /// An edge or vertex contact whose cutter normal leans more than this
    /// (degrees) from the contacted facet's normal is a sharp convex feature of
    /// the part, not its tessellation: it does not set the pass spacing (see
    /// `Planner::rides_sharp_edge`). Tessellations of smooth surfaces within the
    /// usual chord tolerances bend by a few degrees between facets.
    pub const SHARP_EDGE_DEG: f64 = 30.0;

    /// With rest tolerated, a residual measured on one section (feed sample)
    /// above this many times sh at the spacing rule's gap, or at any smaller
    /// gap the planner tries, is rest material,
    /// not a scallop (a scallop grows with the square of the gap: the rule
    /// would be 4.5 times too wide): that section no longer sets the gap, which
    /// is at most `REST_SPACING_SHARE` of the largest step-over
    /// (`Planner::hold`). So is a section whose residual grows as the gap
    /// shrinks, or keeps more than half its height when the gap is more than
    /// halved (a scallop would fall to a quarter).
    pub const REST_RESIDUAL_FACTOR: f64 = 20.0;

    /// Splits of a level spacing between the two walls of a concave crease at
    /// which `steep::crease_residual` evaluates the cusp (the worst is kept).
    pub const CREASE_SPLITS: usize = 16;

    /// Times a level spacing is shrunk until the residual across the concave
    /// creases between the two levels holds the scallop height.
    pub const CREASE_RETRIES: usize = 4;

    /// A point of a waterline level is paired with the nearest point of the level
    /// above within this many times the horizontal offset of two levels on the
    /// shallowest steep wall (`dz / tan(threshold - overlap)`) when looking for a
    /// concave crease between them (`Levels::crease`).
    pub const CREASE_REACH: f64 = 1.5;

    /// Each chord of a waterline level, pushed out by [`LEVEL_PUSH_CHORDS`]
    /// chord tolerances, is probed with the drop-cutter at the `k /
    /// LEVEL_CHORD_SAMPLES` points of its length (`0 < k < LEVEL_CHORD_SAMPLES`):
    /// the kernel bounds a chord's deviation at its midpoint only, and a contour
    /// that crosses the chord there (an S bend) leaves it inside the part on
    /// both sides; on a near-vertical wall that is a deep vertical gouge.
    pub const LEVEL_CHORD_SAMPLES: usize = 4;

    /// Deepest recursion of the split of a waterline chord whose samples cut
    /// into the part (a chord is split at most this many times along one path).
    pub const LEVEL_CHORD_DEPTH: u32 = 16;

    /// Width of the bracket (in chord tolerances) to which the contour point
    /// added in a waterline chord is bisected; its outside end is kept.
    pub const LEVEL_CHORD_BRACKET: f64 = 0.01;
}

pub mod surface {
    //! Thresholds of `scallop_surface`, re-exported there as `scallop_surface::tol`.
    //!
    //! Thresholds and algorithm constants specific to parametric surfaces.

    /// A normal `Su x Sv` counts as degenerate when `|Su x Sv| <= NORMAL_DEGENERATE_REL * (|Su|^2 + |Sv|^2)`
    /// (spec finishing.md 4.2: "< 1e-12 relative").
    pub const NORMAL_DEGENERATE_REL: f64 = 1e-12;

    /// Last-resort normal fallback: first step towards the domain centre, as a fraction
    /// of the way there (doubled on each retry, see [`NORMAL_FALLBACK_STEPS`]).
    pub const NORMAL_FALLBACK_FIRST_STEP: f64 = 1e-9;

    /// Number of doublings of [`NORMAL_FALLBACK_FIRST_STEP`] tried before giving up and returning +Z.
    pub const NORMAL_FALLBACK_STEPS: usize = 30;

    /// Newton iterations stop when a step moves less than this fraction of the domain width.
    pub const PARAM_STEP_REL: f64 = 1e-14;

    /// Sufficient-decrease constant of the Armijo line search.
    pub const ARMIJO: f64 = 1e-4;

    /// Relative rounding of an objective evaluation (some tens of ulps times the
    /// magnitudes that enter it): the line search accepts a step whose value rises by no
    /// more than this uncertainty, so that Newton converges on its accurate gradient
    /// instead of stalling on noise in the value.
    pub const OBJECTIVE_ROUNDING_REL: f64 = 1e-14;

    /// Maximum step halvings in one line search.
    pub const LINE_SEARCH_HALVINGS: usize = 50;

    /// A steepest-descent step (used where the Hessian is not positive definite) starts
    /// at this fraction of the domain width.
    pub const STEEPEST_FIRST_STEP: f64 = 0.25;

    /// Safety factor applied to second-derivative maxima estimated by sampling (rational
    /// patches only; polynomial patches use a guaranteed control-net bound).
    pub const SAMPLED_BOUND_SAFETY: f64 = 1.5;

    /// Sampling intervals per knot span and direction when estimating second-derivative
    /// maxima of rational patches.
    pub const SAMPLES_PER_SPAN: usize = 16;

    /// Largest number of grid cells one patch may be tessellated into (two triangles each).
    pub const MAX_TESSELLATION_CELLS: usize = 4_000_000;

    /// Composite Gauss-Legendre area integration: sub-intervals per knot span and direction.
    pub const AREA_SUBDIVISIONS_PER_SPAN: usize = 8;

    /// Largest degree of a patch in either direction. CAD systems export degree 3 to 9
    /// (some allow up to 25); past this a degree is a typo, and the control net and the
    /// basis tables it implies are allocated only after this check.
    pub const MAX_DEGREE: usize = 32;
}

pub mod waterline {
    //! Thresholds of `scallop_waterline`, re-exported there as `scallop_waterline::tol`.
    //!
    //! Named thresholds of the waterline kernel (mm unless said otherwise).

    /// Default distance, along the probe direction, between the last sample with
    /// the cutter above the part and the last one with it cutting into the part
    /// when a contour point is refined by bisection. The point returned is the
    /// outside one, so the cutter placed there at height z never penetrates the part.
    pub const CROSSING_TOLERANCE: f64 = 1e-7;

    /// Default largest deviation, at a chord's midpoint, between a chord of a loop
    /// and the true contour: longer chords are split (adaptive refinement).
    pub const CHORD_TOLERANCE: f64 = 1e-4;

    /// Default grid step as a fraction of the cutter radius R. Features of the
    /// contour smaller than the step may be missed (see `docs/waterline.md`).
    pub const STEP_PER_RADIUS: f64 = 0.25;

    /// Most samples in the drop-cutter grid of one waterline computation
    /// (8 bytes each, plus a bit per level): a larger grid is an input error.
    pub const MAX_SAMPLES: usize = 50_000_000;

    /// Grid cells of padding around the mesh footprint widened by the cutter
    /// radius: every border sample is outside, so loops never reach the border.
    pub const PAD_CELLS: f64 = 2.0;

    /// Distance (mm) below the lowest contact used as the floor of the sampling grid,
    /// so that "nothing under the cutter" is always below every waterline height.
    pub const FLOOR_MARGIN: f64 = 1.0;

    /// A chord shorter than this many crossing tolerances is never split.
    pub const MIN_CHORD_PER_CROSSING: f64 = 16.0;

    /// Deepest recursion of the adaptive chord refinement (a chord is halved at
    /// most this many times).
    pub const MAX_REFINE_DEPTH: u32 = 40;

    /// A chord longer than this many times `sqrt(8 R chord_tolerance)` (the
    /// longest chord within the chord tolerance of a circle of the cutter's
    /// radius R) is accepted only if the contour is within the chord
    /// tolerance at its quarter points too, not only at its midpoint. A
    /// vertex's contour is a circle of radius at most R, where chords stay
    /// under that length; a longer chord spans a flatter piece, where a
    /// feature the midpoint misses (a notch, a bend off the middle) would
    /// otherwise hide (docs/waterline.md, step 6).
    pub const LONG_CHORD_SHARE: f64 = 2.0;

    /// Smallest tolerance accepted, relative to the model's largest |coordinate|:
    /// below it the bisection would be deciding rounding noise.
    pub const REL_MIN_TOLERANCE: f64 = 1e-13;

    /// How many times finer a block of 3 x 3 grid cells is sampled again where a
    /// mesh vertex above z lies with every sample of the block outside: a small
    /// island of the contour (see `docs/waterline.md`).
    pub const ISLAND_REFINE: f64 = 16.0;

    /// Margin, in chord tolerances, of the mesh points checked to lie inside a
    /// level's loops after tracing (`arms.rs`): a point of the mesh above z is
    /// inside the contour with a margin of the cutter's radius at its height
    /// above z; the loops stay within about a chord tolerance of the contour, so
    /// such a point outside them marks a missed arm of inside.
    pub const ARM_MARGIN: f64 = 8.0;

    /// Side of a block of the drop-cutter grid, in cutter radii (rounded to
    /// a power of two of samples, within [`BLOCK_SAMPLES_MIN`, `BLOCK_SAMPLES_MAX`]): each
    /// block is bounded by drop-cutters at its centre of cutters about half a
    /// side smaller and larger, and sampled only at the levels whose contour
    /// may pass through it (see `docs/waterline.md`).
    pub const BLOCK_SPAN_PER_RADIUS: f64 = 0.8;

    /// Fewest samples per side of a block (below, the two bounds per block
    /// would cost as much as the samples they spare); a power of two.
    pub const BLOCK_SAMPLES_MIN: usize = 4;

    /// Most samples per side of a block; a power of two.
    pub const BLOCK_SAMPLES_MAX: usize = 16;

    /// Rounding margin of the block bounds, relative to the model's largest
    /// |coordinate|: a block is taken as all inside or all outside only when
    /// the level is farther than this from its bounds.
    pub const REL_BLOCK_MARGIN: f64 = 1e-9;

    /// Most halvings of an ambiguous grid cell (two or more exits) when its
    /// crossings are linked by subdivision: features of the contour down to
    /// `step / 2^6` are followed through the cell; below, the inside is joined
    /// (see `cell.rs`).
    pub const MAX_SUBDIVISION_DEPTH: u32 = 6;
}
