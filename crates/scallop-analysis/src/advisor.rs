//! Tool-choice advisor (finishing.md 10): PCA plane, critical slope, recommendation.

use serde::{Deserialize, Serialize};

use crate::cutter::Cutter;
use crate::error::AnalysisError;
use crate::kinematics::MachineLimits;
use crate::pca::Pca;
use crate::plane::{
    FeedDirection, PlaneTime, Rectangle, ToolOptions, critical_shape_factor, critical_slope, plane_time,
};
use crate::sample::{PcaWeighting, Samples};
use crate::tol;

/// The PCA plane of the samples, in report units (mm, mm^2).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PcaPlane {
    /// Centre `E` of the equivalent rectangle (mm).
    pub centroid: [f64; 3],
    /// Principal direction `S_I` (unit).
    pub principal_axis: [f64; 3],
    /// Second axis `S_II` (unit).
    pub secondary_axis: [f64; 3],
    /// PCA normal `S_III` (unit, upward unless the plane is vertical).
    pub normal: [f64; 3],
    /// `[lambda_I, lambda_II, lambda_III]` (mm^2).
    pub eigenvalues: [f64; 3],
    /// Equivalent rectangle width `sqrt(12 lambda_I)` along `S_I` (mm).
    pub width: f64,
    /// Equivalent rectangle height `sqrt(12 lambda_II)` along `S_II` (mm).
    pub height: f64,
}

/// One cutter/direction option with its analytic time on the PCA rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ToolOption {
    /// The cutter.
    pub cutter: Cutter,
    /// Feed direction.
    pub feed: FeedDirection,
    /// XY feed angle from X (degrees, in `(-90, 90]`).
    pub feed_angle_deg: f64,
    /// Step-over (mm), pass count (real), path length (mm) and time (s).
    pub estimate: PlaneTime,
}

/// Why the recommendation was made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Recommendation {
    /// `s~ > s_c`: ball-end cutter along the principal direction.
    BallAlongPrincipal,
    /// `s~ <= s_c`: toroidal cutter along the steepest slope.
    ToroidalAlongSlope,
}

/// Remarks on the validity of the analysis; they never change the answer.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "note", rename_all = "snake_case")]
pub enum Note {
    /// The PCA plane is horizontal: the steepest-slope direction is undefined and
    /// reported as 0 degrees; any feed direction gives the toroidal flat-bottom cut.
    HorizontalPlane,
    /// The PCA plane is vertical (`|S_III . Z| < tol::VERTICAL_PLANE_NZ`): 3-axis
    /// parallel planes are a poor fit (Annex E gives no finite time).
    VerticalPlane,
    /// `S_I` is vertical: the principal direction is reported as the slope direction.
    PrincipalAxisVertical,
    /// `mu~` above the validated limit 9 (finishing.md 8.5): the answer is
    /// extrapolated (the thesis says the principal direction is then better anyway).
    ShapeFactorAboveLimit {
        /// The limit ([`tol::SHAPE_FACTOR_LIMIT`]).
        limit: f64,
    },
    /// Rectangle height below `2 sqrt(V^3/J)`: toroidal passes along the slope do not
    /// reach the feed, so `s_c` (which assumes they do) is less accurate (8.4).
    ShortPasses {
        /// Rectangle height `h` (mm).
        height: f64,
        /// `2 sqrt(V^3/J)` (mm).
        critical_length: f64,
    },
    /// A step-over longer than `2 sqrt(V^3/J)`: connections reach the feed, outside
    /// the regime of `s_c` (8.4).
    LongConnections {
        /// The longer step-over (mm).
        step_over: f64,
        /// `2 sqrt(V^3/J)` (mm).
        critical_length: f64,
    },
}

/// The result of [`analyze`] (report units: mm, mm^2, s, degrees), serialisable
/// with serde (JSON field order is fixed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnalysisReport {
    /// Number of samples.
    pub samples: usize,
    /// PCA weighting used.
    pub weighting: PcaWeighting,
    /// The PCA plane and its equivalent rectangle.
    pub plane: PcaPlane,
    /// Shape factor `mu~ = sqrt(lambda_I / lambda_II)`.
    pub shape_factor: f64,
    /// Size `chi~ = 12 sqrt(lambda_I lambda_II)` (mm^2).
    pub size_mm2: f64,
    /// PCA slope `s~ = arccos(|S_III . Z|)` (degrees).
    pub slope_deg: f64,
    /// Mean of the sample tilts `E(s_i)` (Eq. 2.15, degrees; informative).
    pub mean_sample_slope_deg: f64,
    /// Steepest-slope direction: XY angle of `S_III` (degrees, `(-90, 90]`).
    pub slope_direction_deg: f64,
    /// Principal direction: XY angle of `S_I` (degrees, `(-90, 90]`).
    pub principal_direction_deg: f64,
    /// Critical slope `s_c(mu~)` for `chi~` (degrees).
    pub critical_slope_deg: f64,
    /// Critical shape factor `mu_c(s~)` for `chi~`; `None` when infinite (horizontal
    /// plane: the toroidal cutter wins at every shape factor).
    pub critical_shape_factor: Option<f64>,
    /// The recommended cutter and direction.
    pub recommendation: Recommendation,
    /// Toroidal cutter along the steepest slope (`T1`, `L1`).
    pub toroidal_along_slope: ToolOption,
    /// Ball cutter along the principal direction (`T2`, `L2`).
    pub ball_along_principal: ToolOption,
    /// Cutters compared.
    pub tools: ToolOptions,
    /// Machine kinematics (mm/s, mm/s^2, mm/s^3).
    pub machine: MachineLimits,
    /// Scallop height `sh` (mm).
    pub scallop_height_mm: f64,
    /// Validity remarks.
    pub notes: Vec<Note>,
}

impl AnalysisReport {
    /// The recommended option (one of the two compared).
    #[must_use]
    pub fn recommended(&self) -> &ToolOption {
        match self.recommendation {
            Recommendation::BallAlongPrincipal => &self.ball_along_principal,
            Recommendation::ToroidalAlongSlope => &self.toroidal_along_slope,
        }
    }
}

/// Analyses sampled surface points and recommends a cutter and a feed direction
/// without any machining simulation (finishing.md 10, TOOL_CHOICE):
///
/// 1. covariance of the sample points (1/n, [`Samples::moments`]), PCA;
/// 2. `s~ = arccos(|S_III . Z|)`, slope direction = XY angle of `S_III`;
/// 3. `mu~ = sqrt(lambda_I/lambda_II)`, `chi~ = 12 sqrt(lambda_I lambda_II)`;
/// 4. `s_c(mu~)` with `chi = chi~` ([`critical_slope`]);
/// 5. `s_c < s~`: ball along the principal direction, otherwise toroidal along the
///    steepest slope. Also reported: `mu_c(s~)`, the analytic time and length of
///    both options on the PCA rectangle `(w, h, s~)` ([`plane_time`]), and notes.
///
/// Defaults for a CLI: [`ToolOptions::default`] (ball R 5, toroidal 5/2 mm),
/// [`MachineLimits::default`] (5 m/min, 6 m/s^2, 40 m/s^3), `scallop_height` 0.01 mm.
///
/// ```
/// use scallop_analysis::{analyze, sample_patch, MachineLimits, Recommendation, ToolOptions};
/// let set = scallop_surface::builtin("rubio").unwrap();
/// let samples = sample_patch(&set.patches()[0], &Default::default()).unwrap();
/// let report = analyze(&samples, &ToolOptions::default(), &MachineLimits::default(), 0.01).unwrap();
/// assert_eq!(report.recommendation, Recommendation::BallAlongPrincipal);            // A9
/// assert!((report.slope_deg - 42.35).abs() < 0.01);
/// ```
///
/// # Errors
/// [`AnalysisError::BadTool`], [`AnalysisError::BadMachine`],
/// [`AnalysisError::BadScallopHeight`] for invalid inputs;
/// [`AnalysisError::DegenerateSamples`] when the samples lie on a line or at a point.
pub fn analyze(
    samples: &Samples,
    tools: &ToolOptions,
    machine: &MachineLimits,
    scallop_height: f64,
) -> Result<AnalysisReport, AnalysisError> {
    tools.validate(scallop_height)?;
    machine.validate()?;
    let pca = Pca::from_moments(&samples.moments());
    // Coordinate scale: the centroid's distance from the origin plus the rectangle size.
    let scale = (pca.mean.coords.abs().max() + pca.width()).max(1.0);
    if pca.is_degenerate(scale) || !pca.eigenvalues.iter().all(|l| l.is_finite()) {
        return Err(AnalysisError::DegenerateSamples { eigenvalues: pca.eigenvalues });
    }
    let (mu, chi, slope) = (pca.shape_factor(), pca.size(), pca.slope());
    let s_c = critical_slope(mu, chi, tools, scallop_height, machine);
    let mu_c = critical_shape_factor(slope, chi, tools, scallop_height, machine);
    let recommendation =
        if s_c < slope { Recommendation::BallAlongPrincipal } else { Recommendation::ToroidalAlongSlope };

    let rect = Rectangle { width: pca.width(), height: pca.height(), slope };
    let (slope_direction, principal_direction) = (pca.slope_direction(), pca.principal_direction());
    let option = |cutter: Cutter, feed: FeedDirection, angle: f64| ToolOption {
        cutter,
        feed,
        feed_angle_deg: angle.to_degrees(),
        estimate: plane_time(&rect, &cutter, feed, scallop_height, machine),
    };
    let toroidal_along_slope = option(tools.toroidal(), FeedDirection::SteepestSlope, slope_direction);
    let ball_along_principal = option(tools.ball(), FeedDirection::Principal, principal_direction);

    let mut notes = Vec::new();
    let [s1, _, s3] = pca.axes;
    if s3.x.hypot(s3.y) < tol::HORIZONTAL_XY {
        notes.push(Note::HorizontalPlane);
    }
    if s3.z.abs() < tol::VERTICAL_PLANE_NZ {
        notes.push(Note::VerticalPlane);
    }
    if s1.x.hypot(s1.y) < tol::HORIZONTAL_XY {
        notes.push(Note::PrincipalAxisVertical);
    }
    if mu > tol::SHAPE_FACTOR_LIMIT {
        notes.push(Note::ShapeFactorAboveLimit { limit: tol::SHAPE_FACTOR_LIMIT });
    }
    let critical_length = machine.critical_segment_length();
    if rect.height < critical_length {
        notes.push(Note::ShortPasses { height: rect.height, critical_length });
    }
    let longest = toroidal_along_slope.estimate.step_over.max(ball_along_principal.estimate.step_over);
    if longest > critical_length {
        notes.push(Note::LongConnections { step_over: longest, critical_length });
    }

    Ok(AnalysisReport {
        samples: samples.len(),
        weighting: samples.weighting(),
        plane: PcaPlane {
            centroid: pca.mean.coords.into(),
            principal_axis: pca.axes[0].into(),
            secondary_axis: pca.axes[1].into(),
            normal: pca.axes[2].into(),
            eigenvalues: pca.eigenvalues,
            width: rect.width,
            height: rect.height,
        },
        shape_factor: mu,
        size_mm2: chi,
        slope_deg: slope.to_degrees(),
        mean_sample_slope_deg: samples.mean_slope().to_degrees(),
        slope_direction_deg: slope_direction.to_degrees(),
        principal_direction_deg: principal_direction.to_degrees(),
        critical_slope_deg: s_c.to_degrees(),
        critical_shape_factor: mu_c.is_finite().then_some(mu_c),
        recommendation,
        toroidal_along_slope,
        ball_along_principal,
        tools: *tools,
        machine: *machine,
        scallop_height_mm: scallop_height,
        notes,
    })
}
