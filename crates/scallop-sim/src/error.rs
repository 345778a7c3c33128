//! The crate's one error type. Safety problems (gouges, rapids into stock,
//! shank or holder collisions) are errors, never warnings.

use scallop_geom::Point2;

use crate::{Collision, DexelCollision, DexelGouge, GougeCell, MoveId, RapidHit};

/// Why a stock cannot be built or a program is not safe. Each variant names
/// the place and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// The grid resolution is not a finite positive number of mm.
    #[error("z-map resolution must be a finite number > 0 mm, got {resolution}; use e.g. 0.05")]
    BadResolution {
        /// The value given.
        resolution: f64,
    },
    /// The stock box is empty, inverted or not finite.
    #[error("stock box {min:?} .. {max:?} is empty or not finite; give min < max on every axis (mm) in finite numbers")]
    BadStock {
        /// Lowest corner given.
        min: [f64; 3],
        /// Highest corner given.
        max: [f64; 3],
    },
    /// The grid would have more cells than the limit.
    #[error(
        "a z-map of {nx} x {ny} cells (about {} MB) exceeds the budget of {limit} cells; use a coarser resolution or a smaller stock",
        (*nx as u128 * *ny as u128 * 32) >> 20
    )]
    TooManyCells {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
        /// The limit ([`crate::MAX_CELLS`]).
        limit: usize,
    },
    /// A toolpath has more moves than a move id can name.
    #[error("toolpath of {moves} moves exceeds the simulator's limit of u32::MAX moves; split the program")]
    TooManyMoves {
        /// Number of moves.
        moves: usize,
    },
    /// The stock was cut below the part by more than the gouge tolerance.
    #[error(
        "gouge: {count} cells lie below the part by more than {tolerance} mm; the worst is {deepest}; \
         fix the toolpath there (drop-cutter contact, stepdown or linking)",
        deepest = Deepest(worst.first().map(|g| (g.depth, [g.at.x, g.at.y], g.cut_by)))
    )]
    Gouge {
        /// Number of gouged cells.
        count: usize,
        /// The gouge tolerance used (mm).
        tolerance: f64,
        /// The deepest cells, deepest first.
        worst: Vec<GougeCell>,
    },
    /// Rapid (or retract) moves went through stock.
    #[error(
        "{count} rapid moves hit the stock; the first is {first}; \
         raise the clearance height or turn the move into a feed move",
        first = FirstPlace(hits.first().map(|h| (h.id, h.at, h.depth)))
    )]
    RapidIntoStock {
        /// Number of rapid moves that removed material.
        count: usize,
        /// The first ones, in program order.
        hits: Vec<RapidHit>,
    },
    /// The shank or holder touched the in-process stock.
    #[error(
        "{count} moves drive the {what} into the stock; the first is {first}; \
         use longer flutes or a longer shank, or cut in more stepdowns",
        count = collisions.len(),
        what = first_part(collisions),
        first = first_collision(collisions)
    )]
    HolderCollision {
        /// The colliding moves, in program order.
        collisions: Vec<Collision>,
    },
    /// The shank or holder touched the design part itself.
    #[error(
        "{count} moves drive the {what} into the part; the first is {first} \
         (part surface above the {what}'s lower face); use a tool with longer flutes or a longer reach, \
         or keep the passes farther from that wall",
        count = collisions.len(),
        what = first_part(collisions),
        first = first_collision(collisions)
    )]
    PartCollision {
        /// The colliding moves, in program order.
        collisions: Vec<Collision>,
    },
    /// An uncut cell lies below the part: the stock box does not contain the part.
    #[error(
        "the part rises above the stock at ({x:.3}, {y:.3}): part z {part_z} > stock z {stock_z} where nothing was cut; \
         enlarge the stock box or move the part into it",
        x = at.x,
        y = at.y
    )]
    PartOutsideStock {
        /// Cell centre.
        at: Point2,
        /// Stock height there (uncut).
        stock_z: f64,
        /// Part top there.
        part_z: f64,
    },
    /// A [`crate::PartField`] was used with a z-map of another grid.
    #[error(
        "the part field was built on a grid of {} x {} cells but the z-map has {} x {} (or another stock box); \
         build the field with PartField::new on this z-map",
        field[0], field[1], zmap[0], zmap[1]
    )]
    FieldGrid {
        /// The field's cells along x and y.
        field: [usize; 2],
        /// The z-map's cells along x and y.
        zmap: [usize; 2],
    },
    /// The tri-dexel stock would have more rays than the limit.
    #[error("tri-dexel stock of {rays} rays exceeds the limit of {limit}; use a coarser resolution or a smaller stock")]
    TooManyRays {
        /// Rays asked for.
        rays: usize,
        /// The limit ([`crate::MAX_RAYS`]).
        limit: usize,
    },
    /// A tool axis is zero or not finite.
    #[error(
        "move {index}: tool axis {axis:?} (or tip) is not a finite non-zero vector; give i, j, k with a length > 0"
    )]
    BadAxis {
        /// Index of the move.
        index: usize,
        /// The axis given.
        axis: [f64; 3],
    },
    /// A move turns the tool axis by (nearly) 180 degrees, or needs too many sub-steps.
    #[error(
        "move {index}: the tool axis turns by {degrees:.3} deg in one move, which is a reversal or needs more than \
         {limit} sub-steps at the axis tolerance; split the move or raise the axis tolerance"
    )]
    AxisTurn {
        /// Index of the move.
        index: usize,
        /// The turn (degrees).
        degrees: f64,
        /// Sub-step limit ([`crate::MAX_SUBSTEPS`]).
        limit: usize,
    },
    /// A tolerance is not a finite positive number.
    #[error("{what} must be a finite number > 0 mm, got {value}")]
    BadTolerance {
        /// Which tolerance.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// Part material was removed beyond the gouge tolerance (tri-dexel stock).
    #[error(
        "gouge: {count} ray pieces of the part were cut deeper than {tolerance} mm; the worst is {deepest}; \
         fix the toolpath there (contact point, tool axis or linking)",
        deepest = Deepest(worst.first().map(|g| (g.depth, [g.at.x, g.at.y, g.at.z], g.cut_by)))
    )]
    DexelGouge {
        /// Number of gouged ray pieces.
        count: usize,
        /// The gouge tolerance used (mm).
        tolerance: f64,
        /// The deepest ones, deepest first.
        worst: Vec<DexelGouge>,
    },
    /// The shank or holder touched the in-process stock (tri-dexel stock).
    #[error(
        "{count} moves drive the shank or holder into the stock; the first: {first}; \
         use longer flutes or a longer shank, change the tool axis, or cut in more stepdowns",
        count = collisions.len(),
        first = collisions.first().map_or_else(String::new, ToString::to_string)
    )]
    DexelCollision {
        /// The collisions, in program order.
        collisions: Vec<DexelCollision>,
    },
    /// The shank or holder touched the design part itself (tri-dexel stock).
    #[error(
        "{count} moves drive the shank or holder into the part; the first: {first} (part material inside the \
         tool along a ray); use a tool with longer flutes or a longer reach, change the tool axis, or keep the \
         passes farther from that feature",
        count = collisions.len(),
        first = collisions.first().map_or_else(String::new, |c| c.to_string().replace("into the stock", "into the part"))
    )]
    DexelPartCollision {
        /// The collisions, in program order.
        collisions: Vec<DexelCollision>,
    },
    /// A pocket ring cannot be used.
    #[error("pocket ring {ring}: {why}; give closed rings of [x, y] points in mm, the outer boundary first")]
    BadPocket {
        /// The ring (0: the outer boundary).
        ring: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// An option of an engagement evaluation is out of range.
    #[error("engagement {what} must be a finite number in range, got {value}")]
    BadEngagement {
        /// The option.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A blank given as the starting stock is not a closed solid.
    #[error(
        "the blank is not a closed mesh (some edge has an odd number of triangles); give a closed solid as the starting stock"
    )]
    OpenBlank,
    /// The tool at cutting depth reaches beyond a wall of the pocket or an island.
    #[error(
        "gouge: the tool reaches {depth:.4} mm beyond a pocket wall (tolerance {tolerance} mm) with its centre at \
         ({x:.3}, {y:.3}) on move {index}; keep the tool centre at least its radius inside the pocket and outside the islands",
        x = at.x,
        y = at.y
    )]
    PocketGouge {
        /// How far beyond the wall (mm).
        depth: f64,
        /// The tool centre.
        at: Point2,
        /// The move (index in the program).
        index: usize,
        /// The gouge tolerance (mm).
        tolerance: f64,
    },
}

/// The first place of a list of hits or collisions, shown as
/// `MOVE at (x, y), DEPTH mm deep` (move 0 at the origin for an empty list,
/// which the simulator never reports).
struct FirstPlace(Option<(MoveId, Point2, f64)>);

impl std::fmt::Display for FirstPlace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (id, at, depth) = self.0.unwrap_or((MoveId { operation: 0, index: 0 }, Point2::origin(), 0.0));
        write!(f, "{id} at ({:.3}, {:.3}), {depth:.4} mm deep", at.x, at.y)
    }
}

/// The deepest gouge, shown as `DEPTH mm deep at (x, y[, z]), cut by MOVE`
/// (zeros and "no move" for an empty list, which the verifiers never report).
struct Deepest<const N: usize>(Option<(f64, [f64; N], Option<MoveId>)>);

impl<const N: usize> std::fmt::Display for Deepest<N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (depth, at, cut_by) = self.0.unwrap_or((0.0, [0.0; N], None));
        let at: Vec<String> = at.iter().map(|c| format!("{c:.3}")).collect();
        write!(f, "{depth:.4} mm deep at ({}), cut by ", at.join(", "))?;
        match cut_by {
            Some(id) => write!(f, "{id}"),
            None => f.write_str("no move"),
        }
    }
}

fn first_collision(collisions: &[Collision]) -> FirstPlace {
    FirstPlace(collisions.first().map(|c| (c.id, c.at, c.depth)))
}

/// The part of the tool of the first collision ("shank" for an empty list).
fn first_part(collisions: &[Collision]) -> &'static str {
    collisions.first().map_or("shank", |c| c.part.name())
}

#[cfg(test)]
mod tests {
    use super::{Deepest, SimError};
    use crate::{GougeCell, MoveId};
    use scallop_geom::Point2;

    #[test]
    fn a_gouge_names_its_deepest_cell_and_the_move() {
        let cell = GougeCell {
            cell: (3, 4),
            at: Point2::new(1.25, -2.5),
            stock_z: 0.9,
            part_z: 1.0,
            depth: 0.1,
            cut_by: Some(MoveId { operation: 1, index: 7 }),
        };
        let text = SimError::Gouge { count: 1, tolerance: 0.01, worst: vec![cell] }.to_string();
        assert!(
            text.contains("the worst is 0.1000 mm deep at (1.250, -2.500), cut by move 7 of operation 1;"),
            "{text}"
        );
        let none = Deepest::<3>(None).to_string();
        assert_eq!(none, "0.0000 mm deep at (0.000, 0.000, 0.000), cut by no move");
    }
}
