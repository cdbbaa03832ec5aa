//! The shape set every pair query matches on: [`Shape`], one variant per kind, in the
//! canonical order the dispatcher writes pairs in (sphere < capsule < cuboid < cylinder <
//! cone < convex < mesh < compound), and [`MeshShape`], a triangle mesh with everything its queries
//! need, built once when it is registered.

use crate::bounding::{Aabb, BoundingSphere, BoundingVolume, Obb, Rss};
use crate::budget::WorkClock;
use crate::bvh::{BuildParams, Bvh};
use crate::geometry::mesh::MeshEdges;
use crate::geometry::{Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, Sphere, TriMesh};
use crate::geometry::{Segment, SupportMap};
use crate::math::{DVec3, Isometry, Pose};
use crate::narrow::CompoundShape;
use crate::narrow::convex_manifold::ContactFeatures;
use crate::narrow::gjk::POINT;
use crate::narrow::mesh_hull::MeshHull;
use crate::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshDistance, MeshMeshWorkspace, Proximity, cached_pair_within,
    distance_mesh_mesh_within, proximity_mesh_mesh_within, rounding_bound,
};
use std::sync::Arc;

/// How a registered mesh's OBB and RSS trees are built: binned SAH, leaves of up to two
/// triangles.
///
/// Why two: a leaf of one triangle is bounded by a box or a rectangle of at least twice its
/// area, and a mesh's triangles come in pairs sharing an edge (quads, strips), whose volume
/// wastes far less. Measured against one a leaf on `examples/fcl_peer`'s four pairs
/// (2026-12-02, same run, µs mean): distance 42.4 → 19.9 (env×rob), 39.3 → 29.5
/// (tray×spot), 51.4 → 13.7 (plate×bunny), 170 → 166 (bunny×fandisk); all contacts
/// 2 % (env×rob), 7 % (bunny×fandisk), 17 % (plate×bunny) and 21 % (tray×spot) faster;
/// boolean 1.3–3.3× faster on three pairs, 7 % slower on bunny×fandisk. Three a leaf was
/// even on the whole, four and six slower.
pub const MESH_TREE_PARAMS: BuildParams = BuildParams::BINNED_SAH.with_leaf_size(2);

/// A triangle mesh ready for queries: the mesh and its three BVHs (OBB trees answer overlap
/// and contacts fastest, RSS trees distance, measured in `benches/mesh_pair.rs`; the sphere
/// tree is the third choice for distance, [`QueryVolume`]).
#[derive(Debug)]
pub struct MeshShape {
    /// The mesh, local frame.
    pub mesh: TriMesh,
    /// Tree of OBBs, built by [`MESH_TREE_PARAMS`].
    pub overlap_tree: Bvh<Obb>,
    /// Tree of RSSs, built by [`MESH_TREE_PARAMS`].
    pub distance_tree: Bvh<Rss>,
    /// Tree of spheres: the medial-axis or the octree construction, whichever holds less
    /// volume at the top levels ([`BuildParams::MEDIAL_AXIS`], [`BuildParams::OCTREE`]),
    /// kept only when the mesh chose it (a third tree costs about 200 bytes a triangle,
    /// and the closed surfaces measured never choose it). Pair queries told to refine
    /// spheres refine RSSs when either mesh kept none ([`MeshShape::pair_volume`]).
    pub sphere_tree: Option<Bvh<BoundingSphere>>,
    /// Edge adjacency and bends, for convex–mesh contacts without ghost normals.
    pub edges: MeshEdges,
    /// The tree distance queries on this mesh refine, the budgeted frontier's and the
    /// exact ones', by measured tightness ([`QueryVolume::measure`]).
    pub query_volume: QueryVolume,
    /// Convex hull of the vertices (`None` for a flat or degenerate mesh): a pair of
    /// meshes whose hulls are apart by more than their margins is apart with no traversal
    /// ([`MeshHull::gap`]).
    pub hull: Option<MeshHull>,
}

impl MeshShape {
    /// Builds the three trees over `mesh` (offline work: about 1 s for 70,000 triangles),
    /// its edge adjacency and its query volume choice.
    #[must_use]
    pub fn new(mesh: TriMesh) -> Self {
        let overlap_tree = Bvh::from_mesh(&mesh, &MESH_TREE_PARAMS);
        let distance_tree = Bvh::from_mesh(&mesh, &MESH_TREE_PARAMS);
        let (obb, rss) = (measured(&overlap_tree), measured(&distance_tree));
        let chosen = |sphere| QueryVolume::choose(obb, rss, Some(sphere)) == QueryVolume::Sphere;
        let sphere_tree = tighter_sphere_tree(&mesh, chosen);
        let query_volume = QueryVolume::choose(obb, rss, sphere_tree.as_ref().map(measured));
        Self {
            edges: MeshEdges::new(&mesh),
            hull: MeshHull::of(&mesh),
            sphere_tree,
            query_volume,
            overlap_tree,
            distance_tree,
            mesh,
        }
    }

    /// The same mesh with a sphere tree built by `params` (`None`: the tighter of the
    /// medial-axis and octree trees) and kept whatever the choice, for measurements of one
    /// tree against another, which then set [`query_volume`](Self::query_volume); the
    /// query volume is measured again.
    #[must_use]
    pub fn with_sphere_tree(mut self, params: Option<&BuildParams>) -> Self {
        let tree = match params {
            Some(params) => Bvh::from_mesh(&self.mesh, params),
            None => tighter_sphere_tree(&self.mesh, |_| true).expect("every tree is kept"),
        };
        self.query_volume = QueryVolume::measure(&self.overlap_tree, &self.distance_tree, &tree);
        self.sphere_tree = Some(tree);
        self
    }

    /// The volume type this mesh and `other` are refined with: [`QueryVolume::for_pair`] of
    /// their choices, or `volume` when given, and RSSs in place of spheres when either
    /// mesh kept no sphere tree.
    #[must_use]
    pub fn pair_volume(&self, other: &Self, volume: Option<QueryVolume>) -> QueryVolume {
        match volume.unwrap_or(QueryVolume::for_pair(self.query_volume, other.query_volume)) {
            QueryVolume::Sphere if self.sphere_tree.is_none() || other.sphere_tree.is_none() => {
                QueryVolume::Rss
            }
            chosen => chosen,
        }
    }

    /// Both meshes' sphere trees; call only where [`pair_volume`](Self::pair_volume) said
    /// [`QueryVolume::Sphere`], which it says only when both are kept.
    #[must_use]
    pub fn sphere_trees<'a>(
        &'a self,
        other: &'a Self,
    ) -> (&'a Bvh<BoundingSphere>, &'a Bvh<BoundingSphere>) {
        match (&self.sphere_tree, &other.sphere_tree) {
            (Some(a), Some(b)) => (a, b),
            _ => unreachable!("pair_volume chooses spheres only when both meshes kept theirs"),
        }
    }

    /// The rounding bound of a triangle distance between this mesh and `other` placed at
    /// `iso`, as every path states it: [`rounding_bound`] of the RSS trees, whichever trees
    /// a query refined, so that a record does not depend on the choice.
    #[must_use]
    pub fn rounding_with(&self, other: &Self, iso: &Isometry) -> f64 {
        rounding_bound(&self.distance_tree, &other.distance_tree, iso)
    }

    /// The exact distance between this mesh and `other` placed at `pose_ab` (`other`'s
    /// frame in this one's), warm-started from `cache`:
    /// [`distance_mesh_mesh`](crate::narrow::mesh_mesh::distance_mesh_mesh) on the trees
    /// [`QueryVolume::for_pair`] chooses, with the error bound of
    /// [`rounding_with`](Self::rounding_with).
    #[must_use]
    pub fn distance_to(
        &self,
        other: &Self,
        pose_ab: &Pose,
        cache: &mut DistanceCache,
        workspace: &mut MeshMeshWorkspace,
    ) -> MeshDistance {
        let mut unlimited = WorkClock::default();
        self.distance_to_within(other, pose_ab, cache, workspace, &mut unlimited)
    }

    /// [`distance_to`](Self::distance_to), stopped when `clock` stops
    /// ([`distance_mesh_mesh_within`]): then `clock.stopped()`, and the distance is the
    /// closest pair found, with an error bound down to the search's lower bound.
    #[must_use]
    pub fn distance_to_within(
        &self,
        other: &Self,
        pose_ab: &Pose,
        cache: &mut DistanceCache,
        workspace: &mut MeshMeshWorkspace,
        clock: &mut WorkClock,
    ) -> MeshDistance {
        let exact = &DistanceParams::EXACT;
        let iso = pose_ab.to_isometry();
        // The RSS trees' rounding, whichever trees were searched, plus what the search left
        // unsearched (the other trees' own rounding is replaced), so a record does not
        // depend on the choice.
        let restated = |d: MeshDistance, searched_rounding: f64| MeshDistance {
            error_bound: self.rounding_with(other, &iso)
                + (d.error_bound - searched_rounding).max(0.0),
            ..d
        };
        match self.pair_volume(other, None) {
            QueryVolume::Obb => {
                let (a, b) = (&self.overlap_tree, &other.overlap_tree);
                let d = distance_mesh_mesh_within(a, b, pose_ab, exact, cache, workspace, clock);
                restated(d, rounding_bound(a, b, &iso))
            }
            QueryVolume::Rss => {
                let (a, b) = (&self.distance_tree, &other.distance_tree);
                distance_mesh_mesh_within(a, b, pose_ab, exact, cache, workspace, clock)
            }
            QueryVolume::Sphere => {
                let (a, b) = self.sphere_trees(other);
                let d = distance_mesh_mesh_within(a, b, pose_ab, exact, cache, workspace, clock);
                restated(d, rounding_bound(a, b, &iso))
            }
        }
    }

    /// Whether the last closest triangle pair of [`distance_to_within`](Self::distance_to_within)
    /// (remembered in `cache`) is within `max_distance` at `pose_ab`: a witness that
    /// [`proximity`](Self::proximity) would answer [`Proximity::Within`], on the same trees
    /// ([`mesh_mesh::cached_pair_within`](crate::narrow::mesh_mesh::cached_pair_within)).
    #[must_use]
    pub fn cached_pair_within(
        &self,
        other: &Self,
        pose_ab: &Pose,
        cache: &DistanceCache,
        max_distance: f64,
    ) -> bool {
        match self.pair_volume(other, None) {
            QueryVolume::Obb => {
                let (a, b) = (&self.overlap_tree, &other.overlap_tree);
                cached_pair_within(a, b, pose_ab, cache, max_distance)
            }
            QueryVolume::Rss => {
                let (a, b) = (&self.distance_tree, &other.distance_tree);
                cached_pair_within(a, b, pose_ab, cache, max_distance)
            }
            QueryVolume::Sphere => {
                let (a, b) = self.sphere_trees(other);
                cached_pair_within(a, b, pose_ab, cache, max_distance)
            }
        }
    }

    /// Whether some triangle of this mesh and one of `other` placed at `pose_ab` are within
    /// `max_distance`, with a lower bound of the distance when not
    /// ([`proximity_mesh_mesh`](crate::narrow::mesh_mesh::proximity_mesh_mesh) on the
    /// trees [`QueryVolume::for_pair`] chooses).
    #[must_use]
    pub fn proximity(
        &self,
        other: &Self,
        pose_ab: &Pose,
        max_distance: f64,
        workspace: &mut MeshMeshWorkspace,
    ) -> Proximity {
        WorkClock::run_to_end(|clock| {
            self.proximity_within(other, pose_ab, max_distance, workspace, clock)
        })
    }

    /// [`proximity`](Self::proximity), polling `clock` before each pair of leaves
    /// ([`proximity_mesh_mesh_within`]): `None` when the clock stopped it first.
    #[must_use]
    pub fn proximity_within(
        &self,
        other: &Self,
        pose_ab: &Pose,
        max_distance: f64,
        workspace: &mut MeshMeshWorkspace,
        clock: &mut WorkClock,
    ) -> Option<Proximity> {
        match self.pair_volume(other, None) {
            QueryVolume::Obb => {
                let (a, b) = (&self.overlap_tree, &other.overlap_tree);
                proximity_mesh_mesh_within(a, b, pose_ab, max_distance, workspace, clock)
            }
            QueryVolume::Rss => {
                let (a, b) = (&self.distance_tree, &other.distance_tree);
                proximity_mesh_mesh_within(a, b, pose_ab, max_distance, workspace, clock)
            }
            QueryVolume::Sphere => {
                let (a, b) = self.sphere_trees(other);
                proximity_mesh_mesh_within(a, b, pose_ab, max_distance, workspace, clock)
            }
        }
    }
}

/// Which of a mesh's three trees distance queries refine it with: the budgeted frontier
/// ([`MeshPairTrees`](crate::narrow::mesh_mesh::frontier::MeshPairTrees)) and the exact queries
/// ([`MeshShape::distance_to`], [`MeshShape::proximity`]).
///
/// The tighter tree wins both: exact queries prune sooner, and the frontier's bounds are
/// tighter per visit. The OBB's separating-axis gap costs a fraction of the RSS's exact
/// rectangle distance, so box-like CAD parts, whose RSSs hold clearly more volume than
/// their boxes, choose OBBs; curved meshes (tori, spheres), whose RSSs are as small as
/// their boxes and bound distance more tightly, choose RSSs. A sphere's bound costs least
/// of all (one centre distance, no rotation) but bounds a surface patch by its diameter
/// rather than its thickness, so only meshes whose sphere tree is nearly as tight as the
/// others choose it: clouds of loose triangles (debris, foliage, scanned fragments), never
/// the closed surfaces measured.
/// `examples/time_vs_error` (`--scene robot-chain` and `--scene mesh-pile`, `--volume`)
/// measures all three.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QueryVolume {
    /// The OBB tree: clearly the tighter of the two on this mesh.
    Obb,
    /// The RSS tree: about as tight as the boxes, and its distance bound is exact for
    /// rounded rectangles.
    Rss,
    /// The sphere tree: nearly as tight as the others at the top levels (clouds of loose
    /// pieces, not surfaces of solids), where its cheaper bound pays.
    Sphere,
}

impl QueryVolume {
    /// Depth of the top of the trees that is measured (the levels a budgeted frontier
    /// spends most of its visits in).
    const MEASURED_DEPTH: u32 = 5;
    /// RSS volume over OBB volume above which the boxes are taken.
    const OBB_TIGHTER: f64 = 1.15;
    /// Sphere volume over the smaller of the box and RSS volumes up to which the spheres are
    /// taken. Measured (`examples/time_vs_error --volume`, exact frames, two alternating
    /// runs): two clouds of loose triangles, at 1.28 and 1.43, ran 1.6× and 1.2× faster at
    /// the median on (octree) spheres than on boxes, though 1.2–1.3× slower at p99, and
    /// 1.8–2.5× faster at the median and 1.2× at p99 than on RSSs, which the box/RSS rule
    /// alone gives them. Closed meshes are at 2.0–2.4 (spot, fandisk, bunny, and the tori
    /// and balls of the mesh pile, which ran 2.5× slower on spheres than on RSSs) and CAD
    /// parts at 6–12 (robot-chain: 140× slower). Spheres bound a surface patch by its
    /// diameter, not its thickness.
    const SPHERE_TIGHT_ENOUGH: f64 = 1.6;

    /// The choice for a mesh with these trees: OBBs when the RSSs of the nodes down to
    /// depth 5 (`MEASURED_DEPTH`) hold more than 1.15 (`OBB_TIGHTER`) times the boxes'
    /// volume, else RSSs; spheres instead when theirs hold at most 1.6
    /// (`SPHERE_TIGHT_ENOUGH`) times the smaller of the two.
    #[must_use]
    pub fn measure(
        overlap_tree: &Bvh<Obb>,
        distance_tree: &Bvh<Rss>,
        sphere_tree: &Bvh<BoundingSphere>,
    ) -> Self {
        Self::choose(
            measured(overlap_tree),
            measured(distance_tree),
            Some(measured(sphere_tree)),
        )
    }

    /// [`measure`](Self::measure) from the trees' measured volumes, cubic metres (`sphere`:
    /// `None` when there is no sphere tree to choose).
    fn choose(obb: f64, rss: f64, sphere: Option<f64>) -> Self {
        if sphere.is_some_and(|sphere| sphere <= Self::SPHERE_TIGHT_ENOUGH * obb.min(rss)) {
            Self::Sphere
        } else if rss > Self::OBB_TIGHTER * obb {
            Self::Obb
        } else {
            Self::Rss
        }
    }

    /// The volume type a pair of meshes is refined with: the one both meshes chose, else
    /// RSSs (every mesh has its box and RSS trees).
    #[must_use]
    pub fn for_pair(a: Self, b: Self) -> Self {
        if a == b { a } else { Self::Rss }
    }
}

/// The medial-axis sphere tree of `mesh` or its octree sphere tree, whichever holds less
/// volume down to [`QueryVolume`]'s measured depth, if `keep` takes its volume. The medial
/// axis groups the triangles of a closed solid's tubes and plates into slices, but a surface
/// with no inside (a cloud of pieces, an open sheet) has no medial axis worth the name, and
/// there the octree's cells are tighter (measured in `examples/sphere_trees.rs`).
///
/// Built one after the other, and a tree `keep` refuses is dropped at once: a third tree
/// costs about 200 bytes a triangle, and most meshes keep none.
fn tighter_sphere_tree(mesh: &TriMesh, keep: impl Fn(f64) -> bool) -> Option<Bvh<BoundingSphere>> {
    let mut kept: Option<(Bvh<BoundingSphere>, f64)> = None;
    for params in [BuildParams::MEDIAL_AXIS, BuildParams::OCTREE] {
        let tree = Bvh::from_mesh(mesh, &params);
        let volume = measured(&tree);
        if keep(volume) && kept.as_ref().is_none_or(|(_, best)| volume < *best) {
            kept = Some((tree, volume));
        }
    }
    kept.map(|(tree, _)| tree)
}

/// The volume [`QueryVolume`] measures a tree by: its nodes' down to the measured depth.
fn measured<B: BoundingVolume>(tree: &Bvh<B>) -> f64 {
    top_volume(tree, QueryVolume::MEASURED_DEPTH)
}

/// Total volume, cubic metres, of the nodes of `tree` down to `depth` (the root at 0).
fn top_volume<B: BoundingVolume>(tree: &Bvh<B>, depth: u32) -> f64 {
    let nodes = tree.nodes();
    let mut total = 0.0;
    let mut stack = vec![(0_usize, 0_u32)];
    while let Some((i, d)) = stack.pop() {
        let node = &nodes[i];
        total += node.bv.volume();
        if d < depth && !node.is_leaf() {
            stack.extend(node.children().map(|c| (c, d + 1)));
        }
    }
    total
}

/// A registered shape, in its local frame. Large shapes are shared (`Arc`) so bodies and
/// frames never copy geometry.
#[derive(Debug, Clone)]
pub enum Shape {
    /// A sphere about the origin.
    Sphere(Sphere),
    /// A capsule along local Z.
    Capsule(Capsule),
    /// A box about the origin.
    Cuboid(Cuboid),
    /// A cylinder along local Z.
    Cylinder(Cylinder),
    /// A cone along local Z, apex at `+half_height`.
    Cone(Cone),
    /// A convex polyhedron.
    Convex(Arc<ConvexPolyhedron>),
    /// A triangle mesh with its BVHs.
    Mesh(Arc<MeshShape>),
    /// A solid made of convex parts, with the tree of their boxes.
    Compound(Arc<CompoundShape>),
}

impl Shape {
    /// The smallest axis-aligned box of the local frame containing the shape.
    #[must_use]
    pub fn local_bounds(&self) -> Aabb {
        let symmetric = |half: DVec3| Aabb::new(-half, half);
        match self {
            Self::Sphere(s) => symmetric(DVec3::splat(s.radius)),
            Self::Capsule(c) => symmetric(DVec3::new(c.radius, c.radius, c.half_height + c.radius)),
            Self::Cuboid(c) => symmetric(c.half_extents),
            Self::Cylinder(c) => symmetric(DVec3::new(c.radius, c.radius, c.half_height)),
            Self::Cone(c) => symmetric(DVec3::new(c.radius, c.radius, c.half_height)),
            Self::Convex(c) => Aabb::fit_points(c.vertices()),
            Self::Mesh(m) => {
                let (min, max) = m.mesh.bounds();
                Aabb::new(min, max)
            }
            Self::Compound(c) => c.local_bounds(),
        }
    }
}

/// A convex shape as GJK sees it: a core and a radius (a sphere is a point swept by its
/// radius, a capsule a segment; the others have no radius).
///
/// One concrete support map: each support call resolves the kind by a `match` instead of a
/// virtual call, so GJK and EPA, monomorphised once for it, inline every kind's support
/// function. [`Support`](Self::Support) takes any other map (a triangle, a test's shape).
// PERF: `benches/pile.rs` (the GJK pairs: cylinders and hulls against everything).
#[derive(Clone, Copy)]
pub enum Core<'s> {
    /// A sphere's centre.
    Point,
    /// A capsule's axis.
    Segment(Segment),
    /// A box.
    Cuboid(&'s Cuboid),
    /// A cylinder.
    Cylinder(&'s Cylinder),
    /// A cone.
    Cone(&'s Cone),
    /// A convex hull.
    Convex(&'s ConvexPolyhedron),
    /// Any other convex shape, through its support map.
    Support(&'s dyn SupportMap),
}

impl Core<'_> {
    /// The core's support map.
    #[must_use]
    pub fn support_map(&self) -> &dyn SupportMap {
        self
    }
}

impl SupportMap for Core<'_> {
    #[inline(always)]
    fn support(&self, direction: DVec3) -> DVec3 {
        match self {
            Self::Point => POINT.support(direction),
            Self::Segment(s) => s.support(direction),
            Self::Cuboid(b) => b.support(direction),
            Self::Cylinder(c) => c.support(direction),
            Self::Cone(c) => c.support(direction),
            Self::Convex(c) => c.support(direction),
            Self::Support(s) => s.support(direction),
        }
    }

    #[inline(always)]
    fn support_from(&self, direction: DVec3, hint: &mut u32) -> DVec3 {
        match self {
            Self::Convex(c) => c.support_from(direction, hint),
            Self::Support(s) => s.support_from(direction, hint),
            _ => self.support(direction),
        }
    }
}

/// The core and radius of a convex shape; `None` for a mesh or a compound.
#[must_use]
pub fn core_of(shape: &Shape) -> Option<(Core<'_>, f64)> {
    Some(match shape {
        Shape::Sphere(s) => (Core::Point, s.radius),
        Shape::Capsule(c) => (Core::Segment(c.segment()), c.radius),
        Shape::Cuboid(b) => (Core::Cuboid(b), 0.0),
        Shape::Cylinder(c) => (Core::Cylinder(c), 0.0),
        Shape::Cone(c) => (Core::Cone(c), 0.0),
        Shape::Convex(c) => (Core::Convex(c.as_ref()), 0.0),
        Shape::Mesh(_) | Shape::Compound(_) => return None,
    })
}

/// The contact features of a convex shape (the caller's arm guarantees it is not a mesh).
pub(crate) fn features_of(shape: &Shape) -> &dyn ContactFeatures {
    match shape {
        Shape::Sphere(s) => s,
        Shape::Capsule(c) => c,
        Shape::Cuboid(b) => b,
        Shape::Cylinder(c) => c,
        Shape::Cone(c) => c,
        Shape::Convex(c) => c.as_ref(),
        Shape::Mesh(_) | Shape::Compound(_) => {
            unreachable!("the dispatcher sends only convex pairs here")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{meshes, pose, rng};

    #[test]
    fn the_frontier_takes_boxes_for_box_like_meshes_and_rsss_for_curved_ones() {
        let choice = |m: TriMesh| MeshShape::new(m).query_volume;
        assert_eq!(choice(meshes::torus(0.4, 0.12, 32, 16)), QueryVolume::Rss);
        let slab = meshes::subdivided_cuboid(DVec3::new(1.0, 0.6, 0.3), 6);
        assert_eq!(choice(slab), QueryVolume::Obb);
        // The meshes the rule was measured on: FCL's robot link (in the repository) and
        // room (in the data folder, when present).
        assert_eq!(choice(meshes::data_mesh("rob.obj")), QueryVolume::Obb);
        let who = "the_frontier_takes_boxes_for_box_like_meshes (FCL's room)";
        if let Some(m) = meshes::shared_data_mesh(who, "env.obj") {
            assert_eq!(choice(m), QueryVolume::Obb);
        }
        let pair = QueryVolume::for_pair;
        assert_eq!(pair(QueryVolume::Obb, QueryVolume::Obb), QueryVolume::Obb);
        assert_eq!(pair(QueryVolume::Obb, QueryVolume::Rss), QueryVolume::Rss);
        assert_eq!(pair(QueryVolume::Rss, QueryVolume::Obb), QueryVolume::Rss);
        assert_eq!(
            pair(QueryVolume::Sphere, QueryVolume::Obb),
            QueryVolume::Rss
        );
        assert_eq!(
            pair(QueryVolume::Sphere, QueryVolume::Sphere),
            QueryVolume::Sphere
        );
    }

    /// A cloud of loose triangles in a ball takes its sphere tree and keeps it; a closed
    /// surface keeps none, and a pair told to refine spheres then refines RSSs.
    #[test]
    fn clouds_of_loose_pieces_take_spheres_and_surfaces_keep_none() {
        let dust = MeshShape::new(meshes::dust_ball(&mut rng(5), 2_000, 0.5, 0.02));
        assert_eq!(dust.query_volume, QueryVolume::Sphere);
        assert!(dust.sphere_tree.is_some());
        let torus = MeshShape::new(meshes::torus(0.4, 0.12, 32, 16));
        assert!(torus.sphere_tree.is_none());
        assert_eq!(dust.pair_volume(&dust, None), QueryVolume::Sphere);
        assert_eq!(dust.pair_volume(&torus, None), QueryVolume::Rss);
        let told = Some(QueryVolume::Sphere);
        assert_eq!(torus.pair_volume(&torus, told), QueryVolume::Rss);
        assert_eq!(dust.pair_volume(&dust, told), QueryVolume::Sphere);
        // Forced for a measurement: the torus then has one, and refines it when told.
        let forced = MeshShape::new(meshes::torus(0.4, 0.12, 32, 16)).with_sphere_tree(None);
        assert_eq!(forced.pair_volume(&forced, told), QueryVolume::Sphere);
    }

    /// The exact queries refine the trees the pair's volume names (OBBs for two slabs, RSSs
    /// when a ball is in the pair, spheres for two dust clouds) and answer as the brute force over every triangle pair
    /// does, with the RSS trees' rounding bound on either path; `proximity` agrees with the
    /// distance on both sides of the limit, and its lower bound when apart is one.
    #[test]
    fn exact_queries_on_every_volume_match_the_brute_force() {
        let slab = MeshShape::new(meshes::subdivided_cuboid(DVec3::new(0.5, 0.3, 0.15), 3));
        let ball = MeshShape::new(meshes::uv_sphere(0.35, 12, 8));
        let dust = MeshShape::new(meshes::dust_ball(&mut rng(6), 300, 0.4, 0.03));
        let mut r = rng(91);
        let mut workspace = MeshMeshWorkspace::new();
        let (mut within, mut beyond) = (0, 0);
        for (a, b, volume) in [
            (&slab, &slab, QueryVolume::Obb),
            (&slab, &ball, QueryVolume::Rss),
            (&ball, &ball, QueryVolume::Rss),
            (&dust, &dust, QueryVolume::Sphere),
        ] {
            assert_eq!(
                QueryVolume::for_pair(a.query_volume, b.query_volume),
                volume
            );
            let mut cache = DistanceCache::new();
            for case in 0..100 {
                let pose_ab = pose(&mut r, 0.9);
                let truth = meshes::brute_force_distance(&a.mesh, &b.mesh, &pose_ab);
                let d = a.distance_to(b, &pose_ab, &mut cache, &mut workspace);
                let iso = pose_ab.to_isometry();
                let rounding = rounding_bound(&a.distance_tree, &b.distance_tree, &iso);
                assert_eq!(d.error_bound, rounding, "{volume:?} case {case}");
                assert!(
                    (d.distance - truth).abs() <= d.error_bound,
                    "{volume:?} case {case}: {} against {truth}",
                    d.distance
                );
                let limit = 0.05;
                let proximity = a.proximity(b, &pose_ab, limit, &mut workspace);
                if let Proximity::Apart { lower_bound } = proximity {
                    assert!(
                        lower_bound > limit && lower_bound <= truth + rounding,
                        "{volume:?} case {case}: bound {lower_bound}, truth {truth}"
                    );
                }
                if truth <= limit - rounding {
                    assert_eq!(
                        proximity,
                        Proximity::Within,
                        "{volume:?} case {case}: {truth}"
                    );
                    within += 1;
                } else if truth > limit + rounding {
                    assert_ne!(
                        proximity,
                        Proximity::Within,
                        "{volume:?} case {case}: {truth}"
                    );
                    beyond += 1;
                }
            }
        }
        assert!(
            within > 40 && beyond > 40,
            "{within} within, {beyond} beyond"
        );
    }
}
