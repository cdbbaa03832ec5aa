//! A piece with its convex hull and its concavity.

use super::concavity::{Surface, concavity};
use super::nearest::SampleGrid;
use super::piece::Piece;
use crate::geometry::ConvexPolyhedron;
use crate::math::{DVec3, bounds_of};

/// A piece of the solid, measured.
#[derive(Debug, Clone)]
pub(super) struct Fitted {
    pub piece: Piece,
    pub hull: ConvexPolyhedron,
    /// Where concavity is measured: the piece's surface samples (see
    /// [`Piece::surface_samples`]).
    pub samples: Vec<DVec3>,
    /// Enclosed volume of the piece, m³.
    pub volume: f64,
    /// Concavity, metres (see `concavity.rs`).
    pub concavity: f64,
    /// Axis-aligned bounds of the hull, metres.
    pub bounds: (DVec3, DVec3),
    /// Spacing of the surface samples, metres; the pieces cut from this one use it too.
    pub spacing: f64,
}

impl Fitted {
    /// Measures `piece`, sampling its surface about `spacing` metres apart (see
    /// [`Piece::surface_samples`]); `None` when it has no corners.
    pub fn new(piece: Piece, spacing: f64) -> Option<Self> {
        let corners: Vec<DVec3> = piece.corner_points().collect();
        let hull = ConvexPolyhedron::try_from_points(&corners).ok()?;
        let samples = piece.surface_samples(spacing);
        let volume = piece.volume();
        let concavity = hull_concavity(&hull, &samples, &piece, spacing);
        Some(Self {
            bounds: bounds_of(hull.vertices().iter().copied()),
            piece,
            hull,
            samples,
            volume,
            concavity,
            spacing,
        })
    }

    /// The union of two pieces, measured; `None` if the hull of both cannot be built.
    pub fn merged(&self, other: &Fitted) -> Option<Fitted> {
        let hull = self.merged_hull(other)?;
        let mut samples = self.samples.clone();
        samples.extend_from_slice(&other.samples);
        let piece = self.piece.merged(&other.piece);
        let concavity = hull_concavity(&hull, &samples, &piece, self.spacing);
        Some(Self {
            bounds: bounds_of(hull.vertices().iter().copied()),
            piece,
            hull,
            samples,
            volume: self.volume + other.volume,
            concavity,
            spacing: self.spacing,
        })
    }

    /// The concavity the union of two pieces would have, metres, without building it.
    pub fn merged_concavity(&self, other: &Fitted) -> Option<f64> {
        let hull = self.merged_hull(other)?;
        let mut samples = self.samples.clone();
        samples.extend_from_slice(&other.samples);
        let piece = self.piece.merged(&other.piece);
        Some(hull_concavity(&hull, &samples, &piece, self.spacing))
    }

    /// The hull of the union of two pieces (the hull of their hulls).
    pub fn merged_hull(&self, other: &Fitted) -> Option<ConvexPolyhedron> {
        let mut points = self.hull.vertices().to_vec();
        points.extend_from_slice(other.hull.vertices());
        ConvexPolyhedron::try_from_points(&points).ok()
    }

    /// Whether the two pieces' hull bounds touch or overlap, within `slack` metres: the
    /// cheap test for "may share a cut", which merging starts from.
    pub fn may_touch(&self, other: &Fitted, slack: f64) -> bool {
        let (a, b) = (self.bounds, other.bounds);
        let slack = DVec3::splat(slack);
        (a.0 - slack).cmple(b.1).all() && (b.0 - slack).cmple(a.1).all()
    }
}

/// The concavity of a piece with this hull, surface samples and cut planes, metres.
fn hull_concavity(hull: &ConvexPolyhedron, samples: &[DVec3], piece: &Piece, spacing: f64) -> f64 {
    // A hull that is not solid (a sliver of a piece) holds no concavity.
    let Some(triangles) = ConvexPolyhedron::quick_hull_triangles(hull.vertices()) else {
        return 0.0;
    };
    let grid = SampleGrid::new(samples);
    let surface = Surface {
        grid: &grid,
        member: &|_| true,
        extra: &[],
        piece,
        pending: None,
        spacing,
    };
    concavity(&triangles, samples, &surface)
}
