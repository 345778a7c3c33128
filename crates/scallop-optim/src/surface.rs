//! The real black box of chapter 4 on one parametric patch: K-means with the
//! weighted pseudo-metric (`scallop-cluster`), connected components, per-zone
//! orientation, the fast parallel-planes planner on the isoparametric network
//! (`scallop_network`) and the jerk-limited time with inter-zone
//! transitions; and its static surrogates S3 (Annex E on the zones' PCA
//! rectangles) and S4 (the planner on a 5 mm network at `sh = 0.1 mm`), both
//! on a coarser clustering grid (finishing.md 12.2, 12.6).

use scallop_analysis::{
    Cutter, GridOptions, MachineLimits, Moments, Pca, annex_e_time, direction_angle_xy, sample_patch,
};
use scallop_cluster::{ClusterParams, Features, Method, Metric, Partition, partition};
use scallop_geom::nalgebra::Matrix3;
use scallop_geom::{Point3, Vec3};
use scallop_network::{
    CellLabels, Margins, Network, Orientation, Transitions, ZoneParams, ZonePlan, ZoneWorkspace, Zoning,
    plan_zone_with, plan_zones, surface_time,
};
use scallop_strategy::StrategyError;
use scallop_surface::Patch;

use crate::error::OptimError;
use crate::study::{Assessment, Design, Fidelity, Formulation, MachiningModel, PlanReport, ZoneReport};

/// Settings of the real model (mm, s; the job's `[optimize]` table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSettings {
    /// Cutter (ball or toroidal).
    pub tool: Cutter,
    /// Scallop height `sh` of the black box (mm).
    pub scallop_height: f64,
    /// Scallop height of S4 (mm; 0.1).
    pub surrogate_scallop_height: f64,
    /// Machine kinematics.
    pub machine: MachineLimits,
    /// Inter-zone transitions.
    pub transitions: Transitions,
    /// Clustering grid of the black box (80 x 80).
    pub grid: [usize; 2],
    /// Clustering grid of the surrogates (40 x 40).
    pub surrogate_grid: [usize; 2],
    /// Machining-mesh step of the black box (mm; 0.5).
    pub step: f64,
    /// Machining-mesh step of S4 (mm; 5).
    pub surrogate_step: f64,
    /// Direction change that splits a pass into two stop-to-stop moves (rad).
    pub sharp_corner: f64,
    /// The margin by which the written program dilates each zone (mm, XY; 0: not
    /// counted). The border strips are then machined by both zones: each zone's
    /// time is scaled by its share of cells within this distance of it in
    /// other zones (see [`margin_overlaps`]).
    pub zone_margin_mm: f64,
}

impl Default for SurfaceSettings {
    /// The spec's defaults (13): toroidal R 5 r 2, sh 0.01 mm (S4: 0.1 mm),
    /// V 5 m/min, A 6 m/s^2, J 40 m/s^3, RetractTraverse c = 5 mm, 80 x 80 /
    /// 40 x 40 clustering, 0.5 mm / 5 mm machining mesh, sharp corner 30°.
    fn default() -> Self {
        SurfaceSettings {
            tool: Cutter::Toroidal { radius: 5.0, corner: 2.0 },
            scallop_height: 0.01,
            surrogate_scallop_height: 0.1,
            machine: MachineLimits::default(),
            transitions: Transitions::default(),
            grid: [80, 80],
            surrogate_grid: [40, 40],
            step: 0.5,
            surrogate_step: 5.0,
            sharp_corner: 30f64.to_radians(),
            zone_margin_mm: 0.0,
        }
    }
}

/// One clustering grid with its machining network.
#[derive(Clone, Debug)]
struct Level {
    features: Features,
    points: Vec<Point3>,
    normals: Vec<Vec3>,
    network: Option<Network>,
}

impl Level {
    fn new(patch: &Patch, grid: [usize; 2], step: Option<f64>) -> Result<Level, OptimError> {
        let samples = sample_patch(patch, &GridOptions { cells_u: grid[0], cells_v: grid[1] })
            .map_err(|e| OptimError::Model(format!("sampling the surface on {grid:?} cells: {e}")))?;
        let features = Features::from_samples(&samples)
            .map_err(|e| OptimError::Model(format!("features of the {grid:?} grid: {e}")))?;
        let points = samples.samples().iter().map(|s| s.point).collect();
        let normals = samples.samples().iter().map(|s| s.normal).collect();
        let network = match step {
            Some(step) => Some(
                Network::new(patch, step)
                    .map_err(|e| OptimError::Model(format!("machining network at {step} mm: {e}")))?,
            ),
            None => None,
        };
        Ok(Level { features, points, normals, network })
    }
}

/// The real machining model of one patch.
#[derive(Clone, Debug)]
pub struct SurfaceModel {
    settings: SurfaceSettings,
    black_box: Level,
    s3: Level,
    s4: Level,
}

/// A partition at one fidelity, with its network zoning.
#[derive(Clone, Debug)]
pub struct ZonePartition {
    fidelity: Fidelity,
    partition: Partition,
    zoning: Option<Zoning>,
    /// Per zone label: cells of other zones within the margin, over its own cells.
    overlaps: Vec<f64>,
}

/// The orientation of each zone and its accessibility violation.
struct Oriented {
    orientations: Vec<Option<Orientation>>,
    violation: f64,
}

impl ZonePartition {
    /// Number of zones.
    #[must_use]
    pub fn partition_zone_count(&self) -> usize {
        self.partition.zones.len()
    }

    /// The clustering itself (cluster and zone of every cell, zone records).
    #[must_use]
    pub fn clustering(&self) -> &Partition {
        &self.partition
    }
}

impl SurfaceModel {
    /// Samples, features and networks for the three fidelities.
    ///
    /// # Errors
    /// [`OptimError::Model`] when the surface cannot be sampled or meshed, or a
    /// setting is out of range.
    pub fn new(patch: &Patch, settings: SurfaceSettings) -> Result<SurfaceModel, OptimError> {
        let positive = |key: &'static str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(OptimError::BadSetting { key, value: v.to_string(), fix: "must be a finite number > 0" })
            }
        };
        positive("optimize.step", settings.step)?;
        positive("optimize.surrogate_step", settings.surrogate_step)?;
        positive("finishing.scallop_height", settings.scallop_height)?;
        positive("optimize.surrogate_scallop_height", settings.surrogate_scallop_height)?;
        let black_box = Level::new(patch, settings.grid, Some(settings.step))?;
        let s3 = Level::new(patch, settings.surrogate_grid, None)?;
        let s4 =
            Level {
                network: Some(Network::new(patch, settings.surrogate_step).map_err(|e| {
                    OptimError::Model(format!("machining network at {} mm: {e}", settings.surrogate_step))
                })?),
                ..s3.clone()
            };
        Ok(SurfaceModel { settings, black_box, s3, s4 })
    }

    fn level(&self, fidelity: Fidelity) -> &Level {
        match fidelity {
            Fidelity::BlackBox => &self.black_box,
            Fidelity::S3 => &self.s3,
            Fidelity::S4 => &self.s4,
        }
    }

    fn scallop_height(&self, fidelity: Fidelity) -> f64 {
        if fidelity == Fidelity::S4 { self.settings.surrogate_scallop_height } else { self.settings.scallop_height }
    }

    /// Points and normals of a zone's cells.
    fn zone_samples<'a>(
        &'a self,
        level: &'a Level,
        cells: &'a [u32],
    ) -> impl Iterator<Item = (&'a Point3, &'a Vec3)> + 'a {
        cells.iter().filter_map(move |&c| {
            let i = level.features.point_of_cell(c as usize)?;
            Some((&level.points[i], &level.normals[i]))
        })
    }

    /// The orientation of every zone under `design` and the violation
    /// `h = sum_k sum_i max(0, -n_i . a_k)^2` (12.9); `None` orientations in 3-axis.
    fn orient(&self, zp: &ZonePartition, formulation: Formulation, design: &Design) -> Oriented {
        let level = self.level(zp.fidelity);
        let p = &zp.partition;
        let mut orientations = Vec::with_capacity(p.zones.len());
        let mut violation = 0.0;
        for zone in &p.zones {
            let c = zone.cluster as usize;
            let axis = match formulation {
                Formulation::ThreeAxis => {
                    orientations.push(None);
                    continue;
                }
                Formulation::ThreePlusTwo => {
                    let a = design.axis(c);
                    Vec3::new(a[0], a[1], a[2])
                }
                Formulation::Heuristic => heuristic_axis(zone.geometry.as_ref().map(|g| &g.pca), design.zeta[c]),
            };
            // Rotation centre: the zone's mean in the heuristic, the origin in 3+2 so that the
            // zones of a cluster share one oriented network (times do not depend on it, 4.5).
            let mean = match formulation {
                Formulation::Heuristic => zone.geometry.as_ref().map_or_else(Point3::origin, |g| g.moments.mean()),
                _ => Point3::origin(),
            };
            for (_, n) in self.zone_samples(level, &zone.cells) {
                violation += (-n.dot(&axis)).max(0.0).powi(2);
            }
            let tilt = axis.z.clamp(-1.0, 1.0).acos();
            let azimuth = axis.y.atan2(axis.x);
            orientations.push(Some(Orientation::new(tilt, azimuth, mean)));
        }
        Oriented { orientations, violation }
    }

    fn params(&self, fidelity: Fidelity, direction: f64) -> ZoneParams {
        ZoneParams {
            direction,
            tool: self.settings.tool,
            scallop_height: self.scallop_height(fidelity),
            margins: Margins::HalfStep,
            sharp_corner: self.settings.sharp_corner,
            machine: self.settings.machine,
        }
    }

    /// Plans every zone (zones without any pass are skipped: they are smaller
    /// than a plane spacing and cost nothing to this model).
    fn plan(
        &self,
        zp: &ZonePartition,
        formulation: Formulation,
        design: &Design,
    ) -> Result<(Vec<ZonePlan>, f64), OptimError> {
        let level = self.level(zp.fidelity);
        let (Some(network), Some(zoning)) = (&level.network, &zp.zoning) else {
            return Err(OptimError::Model("internal: no machining network at this fidelity".into()));
        };
        let oriented = self.orient(zp, formulation, design);
        if formulation == Formulation::ThreeAxis {
            // Fast path: all zones with shared buffers; a zone without passes makes it
            // fail, and the loop below then skips that zone.
            let directions: Vec<f64> = zp.partition.zones.iter().map(|z| design.theta[z.cluster as usize]).collect();
            if let Ok(plans) = plan_zones(network, zoning, &directions, &self.params(zp.fidelity, 0.0)) {
                return Ok((with_margins(plans, &zp.overlaps), oriented.violation));
            }
        }
        let zones = &zp.partition.zones;
        let mut workspace = ZoneWorkspace::default();
        // Per zone, in zone order: the result of planning it (each zone is planned
        // once, in the group of its first zone; `None` only until then).
        let mut results: Vec<Option<Result<ZonePlan, StrategyError>>> = (0..zones.len()).map(|_| None).collect();
        // Zones planned by orientation group (3+2: a cluster; heuristic: one
        // zone; 3-axis: one zone, unoriented): one network buffer, rotated for
        // the group's zones only (`orient_into`), one workspace. The results are
        // then read in zone order, as the plans were made before.
        let mut buffer: Option<Network> = None;
        let mut done = vec![false; zones.len()];
        for z in 0..zones.len() {
            if done[z] {
                continue;
            }
            #[allow(clippy::cast_possible_truncation)]
            let group: Vec<u32> = if formulation == Formulation::ThreePlusTwo && oriented.orientations[z].is_some() {
                let c = zones[z].cluster;
                (z..zones.len()).filter(|&y| zones[y].cluster == c).map(|y| y as u32).collect()
            } else {
                vec![z as u32]
            };
            let net = match oriented.orientations[z] {
                None => network,
                Some(o) => {
                    let out = buffer.get_or_insert_with(|| network.clone());
                    network.orient_into(&o, zoning, &group, out);
                    &*out
                }
            };
            for &y in &group {
                let y = y as usize;
                done[y] = true;
                let params = self.params(zp.fidelity, design.theta[zones[y].cluster as usize]);
                #[allow(clippy::cast_possible_truncation)]
                let result = plan_zone_with(net, Some(zoning), y as u32, &params, &mut workspace);
                results[y] = Some(result);
            }
        }
        let mut plans = Vec::with_capacity(zones.len());
        for (z, result) in results.into_iter().enumerate() {
            match result {
                Some(Ok(plan)) => plans.push(plan),
                Some(Err(StrategyError::EmptyZone { .. })) | None => {}
                Some(Err(e)) => return Err(OptimError::Model(format!("planning zone {z}: {e}"))),
            }
        }
        Ok((with_margins(plans, &zp.overlaps), oriented.violation))
    }

    /// S3: Annex E on each zone's PCA rectangle (rotated by its orientation),
    /// plus transitions between consecutive zone means (12.7).
    fn s3(&self, zp: &ZonePartition, formulation: Formulation, design: &Design) -> Assessment {
        let oriented = self.orient(zp, formulation, design);
        let mut total = 0.0;
        let mut previous: Option<Point3> = None;
        for (z, zone) in zp.partition.zones.iter().enumerate() {
            let Some(g) = &zone.geometry else { continue };
            let c = zone.cluster as usize;
            let pca = match &oriented.orientations[z] {
                None => g.pca,
                Some(o) => rotated_pca(&g.moments, o),
            };
            total += annex_e_time(
                &pca,
                design.theta[c],
                &self.settings.tool,
                self.settings.scallop_height,
                &self.settings.machine,
            );
            let mean = g.moments.mean();
            if let Some(p) = previous {
                total += self.settings.transitions.time(&p, &mean, &self.settings.machine).0;
            }
            previous = Some(mean);
        }
        Assessment { time_s: total, violation: oriented.violation }
    }
}

/// Each zone's time and lengths scaled by `1 + overlaps[zone]` (the border
/// strips its margin adds; no scaling without overlaps).
fn with_margins(mut plans: Vec<ZonePlan>, overlaps: &[f64]) -> Vec<ZonePlan> {
    for plan in &mut plans {
        if let Some(&o) = overlaps.get(plan.zone as usize) {
            plan.time_s *= 1.0 + o;
            plan.cut_length_mm *= 1.0 + o;
            plan.link_length_mm *= 1.0 + o;
        }
    }
    plans
}

/// Per zone label, the cells of other zones within `margin` (XY) of one of its
/// cells, over its own cell count: the share of border strip that the written
/// program's zone dilation adds (zones are cut over their cells grown by the
/// margin, `scallop_engine::finish_zones`). `xy` is one point per cell (NaN: no
/// point), index `a * grid[1] + b`. The neighbourhood of a cell is the
/// `(u, v)` window that the smallest neighbour spacing of the grid needs to
/// reach `margin`, capped at a quarter of the grid.
#[must_use]
pub fn margin_overlaps(xy: &[[f64; 2]], grid: [usize; 2], zone_of_cell: &[u32], margin: f64) -> Vec<f64> {
    let [nu, nv] = grid;
    // Labels of masked cells (none on a whole patch) are left out.
    let zones = zone_of_cell.iter().filter(|&&z| z != u32::MAX).map(|&z| z as usize + 1).max().unwrap_or(0);
    let mut own = vec![0usize; zones];
    for &z in zone_of_cell.iter().filter(|&&z| z != u32::MAX) {
        own[z as usize] += 1;
    }
    let distance = |a: usize, b: usize| (xy[a][0] - xy[b][0]).hypot(xy[a][1] - xy[b][1]);
    let (mut hu, mut hv) = (f64::INFINITY, f64::INFINITY);
    for a in 0..nu {
        for b in 0..nv {
            let c = a * nv + b;
            if a + 1 < nu {
                hu = hu.min(distance(c, c + nv));
            }
            if b + 1 < nv {
                hv = hv.min(distance(c, c + 1));
            }
        }
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // capped at a quarter of the grid
    let reach = |h: f64, n: usize| if h > 0.0 { ((margin / h).ceil() as usize).min(n / 4) } else { n / 4 };
    let (ru, rv) = (reach(hu, nu), reach(hv, nv));
    let window = border_windows(grid, zone_of_cell, ru, rv);
    let mut near = vec![0usize; zones];
    let mut seen: Vec<u32> = Vec::new();
    for a in 0..nu {
        for b in 0..nv {
            let c = a * nv + b;
            if !window[c] {
                continue; // one zone over the whole window: nothing foreign near
            }
            seen.clear();
            for i in a.saturating_sub(ru)..(a + ru + 1).min(nu) {
                for j in b.saturating_sub(rv)..(b + rv + 1).min(nv) {
                    let d = i * nv + j;
                    let z = zone_of_cell[d];
                    if z != zone_of_cell[c] && !seen.contains(&z) && distance(c, d) <= margin {
                        seen.push(z);
                    }
                }
            }
            for &z in seen.iter().filter(|&&z| z != u32::MAX) {
                near[z as usize] += 1;
            }
        }
    }
    #[allow(clippy::cast_precision_loss)]
    near.iter().zip(&own).map(|(&n, &o)| if o == 0 { 0.0 } else { n as f64 / o as f64 }).collect()
}

/// Whether the `(2 ru + 1) x (2 rv + 1)` window of each cell holds a border cell
/// (one with a 4-neighbour in another zone). A window without one holds one zone
/// only (two cells of different zones in a rectangle are joined by a 4-path in it,
/// which crosses a border), so [`margin_overlaps`] skips it. Separable box
/// dilation of the border mask: along `u`, then along `v`.
fn border_windows(grid: [usize; 2], zone_of_cell: &[u32], ru: usize, rv: usize) -> Vec<bool> {
    let [nu, nv] = grid;
    let mut border = vec![false; nu * nv];
    for a in 0..nu {
        for b in 0..nv {
            let c = a * nv + b;
            let z = zone_of_cell[c];
            border[c] = (a + 1 < nu && zone_of_cell[c + nv] != z)
                || (a > 0 && zone_of_cell[c - nv] != z)
                || (b + 1 < nv && zone_of_cell[c + 1] != z)
                || (b > 0 && zone_of_cell[c - 1] != z);
        }
    }
    let mut along_u = vec![false; nu * nv];
    for a in 0..nu {
        for b in 0..nv {
            along_u[a * nv + b] = (a.saturating_sub(ru)..(a + ru + 1).min(nu)).any(|i| border[i * nv + b]);
        }
    }
    let mut out = vec![false; nu * nv];
    for a in 0..nu {
        for b in 0..nv {
            out[a * nv + b] = (b.saturating_sub(rv)..(b + rv + 1).min(nv)).any(|j| along_u[a * nv + j]);
        }
    }
    out
}

/// The heuristic tool axis of a zone (12.5): rotation 1 brings the PCA normal
/// `X_III` onto Z, rotation 2 turns by `zeta` about `X_II`; in the part frame the
/// axis is `cos(zeta) X_III + sin(zeta) X_I`.
fn heuristic_axis(pca: Option<&Pca>, zeta: f64) -> Vec3 {
    let Some(pca) = pca else { return Vec3::z() };
    let [x1, _, x3] = pca.axes;
    let (s, c) = zeta.sin_cos();
    (x3 * c + x1 * s).normalize()
}

/// The PCA of a zone seen in an oriented frame.
fn rotated_pca(moments: &Moments, o: &Orientation) -> Pca {
    let r: Matrix3<f64> = Matrix3::from_columns(&[o.rotate(&Vec3::x()), o.rotate(&Vec3::y()), o.rotate(&Vec3::z())]);
    let cov = r * moments.covariance() * r.transpose();
    Pca::from_covariance(&o.to_machine(&moments.mean()), &cov)
}

/// Doubled-angle circular mean of directions (modulo pi), in `(-pi/2, pi/2]`.
fn mean_direction(angles: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut c) = (0.0, 0.0);
    for a in angles {
        let (sa, ca) = (2.0 * a).sin_cos();
        s += sa;
        c += ca;
    }
    if s == 0.0 && c == 0.0 { 0.0 } else { 0.5 * s.atan2(c) }
}

impl MachiningModel for SurfaceModel {
    type Partition = ZonePartition;

    fn partition(&self, k: usize, omega: &[f64; 4], fidelity: Fidelity) -> Result<ZonePartition, OptimError> {
        let level = self.level(fidelity);
        let params = ClusterParams {
            k,
            omega: *omega,
            metric: Metric::Euclidean,
            method: Method::KMeans,
            ..ClusterParams::default()
        };
        let partition =
            partition(&level.features, &params).map_err(|e| OptimError::Model(format!("clustering K = {k}: {e}")))?;
        let zoning = match &level.network {
            Some(network) => {
                let labels = CellLabels {
                    cells_u: partition.grid[0],
                    cells_v: partition.grid[1],
                    labels: partition.zone_of_cell.clone(),
                };
                Some(Zoning::new(network, &labels).map_err(|e| OptimError::Model(format!("zones K = {k}: {e}")))?)
            }
            None => None,
        };
        let overlaps = if self.settings.zone_margin_mm > 0.0 {
            let xy: Vec<[f64; 2]> = (0..partition.zone_of_cell.len())
                .map(|c| {
                    level.features.point_of_cell(c).map_or([f64::NAN; 2], |i| [level.points[i].x, level.points[i].y])
                })
                .collect();
            margin_overlaps(&xy, partition.grid, &partition.zone_of_cell, self.settings.zone_margin_mm)
        } else {
            Vec::new()
        };
        Ok(ZonePartition { fidelity, partition, zoning, overlaps })
    }

    fn assess(
        &self,
        zp: &ZonePartition,
        formulation: Formulation,
        design: &Design,
        fidelity: Fidelity,
    ) -> Result<Assessment, OptimError> {
        if fidelity == Fidelity::S3 {
            return Ok(self.s3(zp, formulation, design));
        }
        let (plans, violation) = self.plan(zp, formulation, design)?;
        let time = surface_time(&plans, &self.settings.transitions, &self.settings.machine);
        Ok(Assessment { time_s: time.total_s, violation })
    }

    fn initial_design(&self, k: usize, formulation: Formulation, zp: &ZonePartition) -> Result<Design, OptimError> {
        let level = self.level(zp.fidelity);
        let p = &zp.partition;
        let mut design = Design::zeros(k);
        // Reachability: a zone is reachable when the vertical axis or its mean normal sees
        // every sample (a sufficient test; 3+2 and heuristic only).
        if formulation != Formulation::ThreeAxis {
            for (z, zone) in p.zones.iter().enumerate() {
                let normals: Vec<Vec3> = self.zone_samples(level, &zone.cells).map(|(_, n)| *n).collect();
                let mean: Vec3 = normals.iter().sum::<Vec3>();
                let sees = |a: &Vec3| normals.iter().all(|n| n.dot(a) >= 0.0);
                if !sees(&Vec3::z()) && (mean.norm() == 0.0 || !sees(&mean.normalize())) {
                    return Err(OptimError::Model(format!(
                        "K = {k}: zone {z} (cluster {}, {} cells): no tool orientation reaches all its samples \
                         (its normals spread over more than a hemisphere); machine it in 3-axis or split the surface",
                        zone.cluster,
                        zone.len()
                    )));
                }
            }
        }
        for c in 0..k.min(p.clusters) {
            let cells = p.cluster_of_cell.iter().enumerate().filter(|(_, l)| **l as usize == c).map(|(i, _)| i);
            design.theta[c] = match formulation {
                Formulation::ThreeAxis | Formulation::ThreePlusTwo => mean_direction(cells.filter_map(|cell| {
                    level.features.point_of_cell(cell).map(|i| level.features.feature(i).slope_direction)
                })),
                Formulation::Heuristic => {
                    // The largest zone of the cluster, after its heuristic orientation (zeta = 0).
                    let zone = p.zones.iter().filter(|z| z.cluster as usize == c).max_by_key(|z| z.len());
                    zone.map_or(0.0, |zone| {
                        let axis = heuristic_axis(zone.geometry.as_ref().map(|g| &g.pca), 0.0);
                        let o =
                            Orientation::new(axis.z.clamp(-1.0, 1.0).acos(), axis.y.atan2(axis.x), Point3::origin());
                        let (mut dx, mut dy) = (0.0, 0.0);
                        for (_, n) in self.zone_samples(level, &zone.cells) {
                            let r = o.rotate(n);
                            dx += r.x;
                            dy += r.y;
                        }
                        direction_angle_xy(dx, dy)
                    })
                }
            };
        }
        Ok(design)
    }

    fn describe(
        &self,
        zp: &ZonePartition,
        formulation: Formulation,
        design: &Design,
    ) -> Result<PlanReport, OptimError> {
        let (plans, violation) = self.plan(zp, formulation, design)?;
        let time = surface_time(&plans, &self.settings.transitions, &self.settings.machine);
        let oriented = self.orient(zp, formulation, design);
        let p = &zp.partition;
        let zones = p
            .zones
            .iter()
            .enumerate()
            .map(|(z, zone)| {
                let c = zone.cluster as usize;
                let plan = plans.iter().find(|pl| pl.zone as usize == z);
                let (phi, psi) = oriented.orientations[z].map_or((0.0, 0.0), |o| (o.tilt, o.azimuth));
                ZoneReport {
                    zone: z,
                    cluster: c,
                    cells: zone.len(),
                    theta_deg: design.theta[c].to_degrees(),
                    phi_deg: phi.to_degrees(),
                    psi_deg: psi.to_degrees(),
                    zeta_deg: design.zeta[c].to_degrees(),
                    time_s: plan.map_or(0.0, |pl| pl.time_s),
                    length_mm: plan.map_or(0.0, |pl| pl.cut_length_mm + pl.link_length_mm),
                    passes: plan.map_or(0, |pl| pl.passes),
                }
            })
            .collect();
        let level = self.level(zp.fidelity);
        let cell_xy = (0..p.zone_of_cell.len())
            .map(|cell| {
                level.features.point_of_cell(cell).map_or([f64::NAN; 2], |i| [level.points[i].x, level.points[i].y])
            })
            .collect();
        Ok(PlanReport {
            time_s: time.total_s,
            transition_time_s: time.transitions_s,
            violation,
            grid: p.grid,
            labels: p.zone_of_cell.clone(),
            cell_xy,
            zones,
        })
    }
}

#[cfg(test)]
mod margin_tests {
    use super::margin_overlaps;
    use proptest::prelude::*;

    /// A separable grid: `x` from the `u` index, `y` from the `v` index.
    fn grid(xs: &[f64], ys: &[f64]) -> Vec<[f64; 2]> {
        xs.iter().flat_map(|&x| ys.iter().map(move |&y| [x, y])).collect()
    }

    fn brute_force(xy: &[[f64; 2]], zone_of_cell: &[u32], margin: f64) -> Vec<f64> {
        let zones = zone_of_cell.iter().map(|&z| z as usize + 1).max().unwrap_or(0);
        (0..zones)
            .map(|z| {
                let z = u32::try_from(z).unwrap_or(u32::MAX);
                let own: Vec<usize> = (0..xy.len()).filter(|&c| zone_of_cell[c] == z).collect();
                let near = (0..xy.len())
                    .filter(|&d| zone_of_cell[d] != z)
                    .filter(|&d| own.iter().any(|&c| (xy[c][0] - xy[d][0]).hypot(xy[c][1] - xy[d][1]) <= margin))
                    .count();
                #[allow(clippy::cast_precision_loss)]
                if own.is_empty() { 0.0 } else { near as f64 / own.len() as f64 }
            })
            .collect()
    }

    /// Two halves of a 1 mm grid, margin 2.5 mm: each zone gains the two nearest
    /// columns of the other, 40 of its 200 cells.
    #[test]
    fn two_halves_gain_two_columns_each() {
        let xs: Vec<f64> = (0..20).map(f64::from).collect();
        let xy = grid(&xs, &xs);
        let labels: Vec<u32> = (0..400).map(|c| u32::from(c / 20 >= 10)).collect();
        let o = margin_overlaps(&xy, [20, 20], &labels, 2.5);
        assert_eq!(o.len(), 2);
        assert!((o[0] - 0.2).abs() < 1e-12 && (o[1] - 0.2).abs() < 1e-12, "{o:?}");
        // One zone: no border, nothing to add.
        assert_eq!(margin_overlaps(&xy, [20, 20], &[0; 400], 2.5), vec![0.0]);
    }

    proptest! {
        /// The windowed count equals the brute force over all cell pairs on
        /// uneven (separable, increasing) grids with blocky random labels.
        #[test]
        fn window_matches_brute_force(
            dx in proptest::collection::vec(0.5f64..1.5, 23),
            dy in proptest::collection::vec(0.5f64..1.5, 23),
            seeds in proptest::collection::vec(0u32..4, 16),
            margin in 0.5f64..3.0,
        ) {
            let along = |d: &[f64]| -> Vec<f64> {
                std::iter::once(0.0).chain(d.iter().scan(0.0, |s, x| { *s += x; Some(*s) })).collect()
            };
            let xy = grid(&along(&dx), &along(&dy));
            // 4 x 4 blocks of 6 x 6 cells, each block a random label.
            let labels: Vec<u32> = (0..24 * 24).map(|c| seeds[(c / 24 / 6) * 4 + (c % 24) / 6]).collect();
            let got = margin_overlaps(&xy, [24, 24], &labels, margin);
            let want = brute_force(&xy, &labels, margin);
            prop_assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                prop_assert!((g - w).abs() < 1e-12, "{:?} vs {:?}", got, want);
            }
        }
    }
}
