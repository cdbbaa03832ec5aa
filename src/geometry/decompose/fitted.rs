//! A piece with its convex hull and its concavity.

use super::cap_outline::CapOutlines;
use super::concavity::{Surface, concavity};
use super::nearest::SampleGrid;
use super::piece::Piece;
use crate::geometry::{ConvexHullError, ConvexPolyhedron, HullTriangle};
use crate::math::{DVec3, bounds_of};

/// A piece's convex hull as the search weighs it: quickhull's triangles, unchecked and
/// unmerged, and the points they span. A search builds thousands of these and keeps a few
/// dozen, so the checked [`ConvexPolyhedron`] (faces merged, validated, every input point
/// tested against it) is built only for the parts kept ([`Fitted::polyhedron`]).
#[derive(Debug, Clone)]
pub(super) struct QuickHull {
    /// The hull's corners; every input point when the hull spans no solid.
    pub points: Vec<DVec3>,
    /// Counter-clockwise from outside; empty when the points span no solid (a sliver).
    pub triangles: Vec<HullTriangle>,
}

impl QuickHull {
    /// The hull of `points` (finite).
    pub fn of(points: Vec<DVec3>) -> Self {
        let Some(triangles) = ConvexPolyhedron::quick_hull_triangles(&points) else {
            return Self {
                points,
                triangles: Vec::new(),
            };
        };
        let mut corners: Vec<DVec3> = triangles.iter().flat_map(|t| t.corners).collect();
        corners.sort_unstable_by(|a, b| {
            (a.x.total_cmp(&b.x))
                .then(a.y.total_cmp(&b.y))
                .then(a.z.total_cmp(&b.z))
        });
        corners.dedup();
        Self {
            points: corners,
            triangles,
        }
    }

    /// Enclosed volume, m³ (0 for a sliver).
    pub fn volume(&self) -> f64 {
        let Some(o) = self.triangles.first().map(|t| t.corners[0]) else {
            return 0.0;
        };
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.corners.map(|p| p - o);
                a.dot(b.cross(c))
            })
            .sum::<f64>()
            / 6.0
    }
}

/// A piece of the solid, measured.
#[derive(Debug, Clone)]
pub(super) struct Fitted {
    pub piece: Piece,
    pub hull: QuickHull,
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
        Self::new_up_to(piece, spacing, f64::INFINITY)
    }

    /// [`Fitted::new`], its concavity measured only up to `bar` (see [`concavity`]): a
    /// piece measured above `bar` is only known to be above it.
    pub fn new_up_to(piece: Piece, spacing: f64, bar: f64) -> Option<Self> {
        let corners = piece.used_points();
        if corners.is_empty() {
            return None;
        }
        let hull = QuickHull::of(corners);
        let samples = piece.surface_samples(spacing);
        let volume = piece.volume();
        let concavity = hull_concavity(&hull, &samples, &piece, spacing, bar);
        Some(Self {
            bounds: bounds_of(hull.points.iter().copied()),
            piece,
            hull,
            samples,
            volume,
            concavity,
            spacing,
        })
    }

    /// The union of two pieces, measured.
    pub fn merged(&self, other: &Fitted) -> Fitted {
        self.union(other, f64::INFINITY)
    }

    /// The concavity of the union of two pieces, metres, when at most `bar`; above `bar`,
    /// some value between `bar` and the concavity (see [`concavity`]).
    pub fn union_concavity(&self, other: &Fitted, bar: f64) -> f64 {
        self.union(other, bar).concavity
    }

    /// The union of two pieces, its concavity measured up to `bar` (see [`concavity`]).
    fn union(&self, other: &Fitted, bar: f64) -> Fitted {
        let hull = self.merged_hull(other);
        let mut samples = self.samples.clone();
        samples.extend_from_slice(&other.samples);
        let piece = self.piece.merged(&other.piece);
        let concavity = hull_concavity(&hull, &samples, &piece, self.spacing, bar);
        Self {
            bounds: bounds_of(hull.points.iter().copied()),
            piece,
            hull,
            samples,
            volume: self.volume + other.volume,
            concavity,
            spacing: self.spacing,
        }
    }

    /// The hull of the union of two pieces (the hull of their hulls).
    pub fn merged_hull(&self, other: &Fitted) -> QuickHull {
        let mut points = self.hull.points.clone();
        points.extend_from_slice(&other.hull.points);
        QuickHull::of(points)
    }

    /// Whether the two pieces' hull bounds touch or overlap, within `slack` metres: the
    /// cheap test for "may share a cut", which merging starts from.
    pub fn may_touch(&self, other: &Fitted, slack: f64) -> bool {
        let (a, b) = (self.bounds, other.bounds);
        let slack = DVec3::splat(slack);
        (a.0 - slack).cmple(b.1).all() && (b.0 - slack).cmple(a.1).all()
    }

    /// The part's checked hull: of every corner of the piece, so it contains the piece
    /// whatever quickhull's tolerance left out of [`QuickHull::points`].
    pub fn polyhedron(&self) -> Result<ConvexPolyhedron, ConvexHullError> {
        ConvexPolyhedron::try_from_points(&self.piece.used_points())
    }
}

/// The concavity of a piece with this hull, surface samples and cut planes, metres, up to
/// `bar` (see [`concavity`]).
fn hull_concavity(
    hull: &QuickHull,
    samples: &[DVec3],
    piece: &Piece,
    spacing: f64,
    bar: f64,
) -> f64 {
    // A hull that is not solid (a sliver of a piece) holds no concavity.
    if hull.triangles.is_empty() {
        return 0.0;
    }
    let grid = SampleGrid::new(samples);
    let surface = Surface {
        grid: &grid,
        member: &|_| true,
        extra: &[],
        caps: &CapOutlines::new(piece),
        pending: None,
        spacing,
    };
    concavity(&hull.triangles, samples, &surface, bar)
}
