//! Exact mesh–mesh queries against a brute-force oracle over every triangle pair.
//!
//! The oracle maps B's triangles into A's frame with `Triangle::transformed` (as the
//! queries do, so both see bit-identical triangles) and loops over *all* triangle pairs in
//! f64 with the triangle–triangle primitives; the only shortcut is a per-pair cull by the
//! two triangles' axis-aligned boxes, padded by a generous slack, which is trivially
//! correct. No BVH is involved, so every disagreement is the tree traversal's: a volume
//! test that culled a pair it must not cull, a pair reported twice, a bad witness.
//!
//! Every query is run over several mesh pairs (closed, open, soup, zero-area triangles,
//! real meshes), eight volume types, two builders and leaf sizes 1 and 4, on seeded random
//! poses drawn so that colliding and separated outcomes both occur (asserted). Stress
//! cases: coplanar touching boxes, nearly parallel faces a hair apart (near-ties of the
//! minimum distance), grazing poses moved along the witness direction to a gap of
//! 1e-3 … 1e-12 of what it was, meshes sharing vertices, meshes 1e5 m from the origin,
//! scales 1e-3 and 1e3, and spot × rob from `tests/data`.
//!
//! One property of the primitives shows through: disjoint triangles closer than rounding
//! may have distance `0.0` (documented by `distance_triangle_triangle`). Then the oracle's
//! minimum is 0 while its boolean says "separated", and the mesh distance must follow the
//! minimum; such poses are counted (`gaps_below_rounding`) and printed.
mod support;

use proxima::bounding::{
    Aabb, BoundingSphere, BoundingVolume, Kdop14, Kdop18, Kdop26, Lss, Obb, Rss,
};
use proxima::bvh::{BuildParams, Bvh};
use proxima::geometry::{TriMesh, Triangle};
use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, FALLBACK_NORMAL, MeshDistance, MeshMeshWorkspace,
    TriangleContact, contacts_mesh_mesh, distance_mesh_mesh, intersects_mesh_mesh,
    within_distance_mesh_mesh,
};
use proxima::narrow::{
    MESH_TREE_PARAMS, TriangleDistance, distance_triangle_triangle, intersects_triangle_triangle,
};
use rand::Rng;
use std::collections::HashSet;
use std::fmt;
use std::ops::ControlFlow;
use support::meshes::{self, reach};
use support::triangle_pairs::{TriangleBox, TrianglePairs};
use support::{TestRng, rng, rotation};

// ---------------------------------------------------------------------------------------
// Pose budget: at least 2,000 seeded random poses over the whole suite.

/// Random poses per procedural mesh pair in each of the four main tests.
const MAIN_POSES_PER_PAIR: usize = 100;
/// Procedural mesh pairs of the main tests (see [`procedural_pairs`]).
const MAIN_PAIRS: usize = 6;
/// Random poses per procedural mesh pair in the tolerance test.
const TOLERANCE_POSES_PER_PAIR: usize = 50;
/// Tree configurations: 8 volume types × the [`BUILDS`], and the octree and medial-axis
/// sphere trees (see [`all_configs`]).
const CONFIG_COUNT: usize = 8 * BUILDS.len() + 2;
/// Configurations each pose of the main tests is checked with.
const CONFIGS_PER_POSE: usize = CONFIG_COUNT;
/// Procedural pairs of the offset and scale stress tests (see [`stress_pairs`]).
const STRESS_PAIRS: usize = 3;
/// Random poses per pair of the offset test and of each scale of the scale test.
const STRESS_POSES: usize = 40;
/// Poses per procedural pair of the grazing test.
const GRAZING_POSES_PER_PAIR: usize = 25;
/// Random poses of the coplanar stacked-box cases (both pairs together).
const COPLANAR_POSES: usize = 60;
/// Random poses of the nearly parallel stacked-box cases (both pairs together).
const NEAR_PARALLEL_POSES: usize = 90;
/// Random poses of spot × rob.
const REAL_MESH_POSES: usize = 100;

/// Seeded random poses over the whole suite (the shared-vertex test's few fixed poses
/// not counted).
const TOTAL_RANDOM_POSES: usize = MAIN_PAIRS
    * (4 * MAIN_POSES_PER_PAIR + TOLERANCE_POSES_PER_PAIR + GRAZING_POSES_PER_PAIR)
    + 3 * STRESS_PAIRS * STRESS_POSES
    + COPLANAR_POSES
    + NEAR_PARALLEL_POSES
    + REAL_MESH_POSES;
const _: () = assert!(TOTAL_RANDOM_POSES >= 2000);

// ---------------------------------------------------------------------------------------
// The oracle.

/// Every triangle pair of A and of B placed at one pose, both in A's frame.
struct Oracle {
    a: Vec<Triangle>,
    a_boxes: Vec<TriangleBox>,
    /// B's triangles mapped into A's frame exactly as the queries map them.
    b: Vec<Triangle>,
    b_boxes: Vec<TriangleBox>,
    /// Largest coordinate magnitude of either mesh in A's frame: the scale of rounding.
    scale: f64,
    /// Box cull padding, far above rounding.
    slack: f64,
}

/// What the oracle says about one pose.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Truth {
    intersects: bool,
    distance: f64,
}

impl Oracle {
    fn new(a: &TriMesh, b: &TriMesh, pose_ab: &Pose) -> Self {
        let TrianglePairs {
            a,
            a_boxes,
            b,
            b_boxes,
            scale,
        } = TrianglePairs::new(a, b, pose_ab);
        Self {
            a,
            a_boxes,
            b,
            b_boxes,
            scale,
            slack: 1e-6 * scale + 1e-300,
        }
    }

    /// Index pairs whose boxes are within `reach` of each other (plus the slack).
    fn near_pairs(&self, reach: f64) -> impl Iterator<Item = (usize, usize)> + '_ {
        let limit = reach + self.slack;
        (0..self.a.len()).flat_map(move |i| {
            (0..self.b.len())
                .filter(move |&j| self.a_boxes[i].gap(&self.b_boxes[j]) <= limit)
                .map(move |j| (i, j))
        })
    }

    /// Every intersecting pair `[id in A, id in B]`, sorted.
    fn pairs(&self) -> Vec<[u32; 2]> {
        self.near_pairs(0.0)
            .filter(|&(i, j)| intersects_triangle_triangle(&self.a[i], &self.b[j]))
            .map(|(i, j)| [i as u32, j as u32])
            .collect()
    }

    fn intersects(&self) -> bool {
        self.near_pairs(0.0)
            .any(|(i, j)| intersects_triangle_triangle(&self.a[i], &self.b[j]))
    }

    /// The minimum over all pairs of `distance_triangle_triangle`, with its witnesses.
    /// First bound: the exact distance of the pair with the smallest box gap; then every
    /// pair whose box gap does not exceed that bound (the others cannot be closer).
    fn closest(&self) -> TriangleDistance {
        let mut first = (f64::INFINITY, 0, 0);
        for (i, a_box) in self.a_boxes.iter().enumerate() {
            for (j, b_box) in self.b_boxes.iter().enumerate() {
                let gap = a_box.gap(b_box);
                if gap < first.0 {
                    first = (gap, i, j);
                }
            }
        }
        let bound = distance_triangle_triangle(&self.a[first.1], &self.b[first.2]);
        self.near_pairs(bound.distance)
            .map(|(i, j)| distance_triangle_triangle(&self.a[i], &self.b[j]))
            .fold(
                bound,
                |best, d| if d.distance < best.distance { d } else { best },
            )
    }

    fn truth(&self) -> Truth {
        Truth {
            intersects: self.intersects(),
            distance: self.closest().distance,
        }
    }
}

/// Distance from `p` to the closed triangle `t` (zero-area triangles included), computed
/// independently of the library: the plane distance when `p` projects inside a proper
/// triangle, else the nearest of the three edges.
fn point_triangle_distance(p: DVec3, t: &Triangle) -> f64 {
    let v = t.vertices();
    let edge = |a: DVec3, b: DVec3| {
        let ab = b - a;
        let len2 = ab.length_squared();
        let s = if len2 > 0.0 {
            ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        p.distance(a + ab * s)
    };
    let edges = edge(v[0], v[1]).min(edge(v[1], v[2])).min(edge(v[2], v[0]));
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    if n.length_squared() == 0.0 {
        return edges;
    }
    let n = n.normalize();
    let q = p - n * (p - v[0]).dot(n);
    let inside = (0..3).all(|k| (v[(k + 1) % 3] - v[k]).cross(q - v[k]).dot(n) >= 0.0);
    if inside {
        edges.min((p - v[0]).dot(n).abs())
    } else {
        edges
    }
}

// ---------------------------------------------------------------------------------------
// The trees under test: every volume type, two builders, leaf sizes 1 and 4.

/// The four queries on one pair of trees, whatever their volume type.
trait PairQueries {
    fn label(&self) -> &str;
    fn intersects(&mut self, pose: &Pose) -> bool;
    fn contacts(&mut self, pose: &Pose) -> Vec<TriangleContact>;
    /// Only the first contact (the sink stops the traversal).
    fn first_contact(&mut self, pose: &Pose) -> Vec<TriangleContact>;
    fn distance(
        &mut self,
        pose: &Pose,
        params: &DistanceParams,
        cache: &mut DistanceCache,
    ) -> MeshDistance;
    fn within(&mut self, pose: &Pose, max_distance: f64) -> bool;
}

struct Trees<B> {
    label: String,
    a: Bvh<B>,
    b: Bvh<B>,
    workspace: MeshMeshWorkspace,
}

impl<B: BoundingVolume> PairQueries for Trees<B> {
    fn label(&self) -> &str {
        &self.label
    }

    fn intersects(&mut self, pose: &Pose) -> bool {
        intersects_mesh_mesh(&self.a, &self.b, pose, &mut self.workspace)
    }

    fn contacts(&mut self, pose: &Pose) -> Vec<TriangleContact> {
        let mut out = Vec::new();
        contacts_mesh_mesh(&self.a, &self.b, pose, &mut self.workspace, |c| {
            out.push(c);
            ControlFlow::Continue(())
        });
        out
    }

    fn first_contact(&mut self, pose: &Pose) -> Vec<TriangleContact> {
        let mut out = Vec::new();
        contacts_mesh_mesh(&self.a, &self.b, pose, &mut self.workspace, |c| {
            out.push(c);
            ControlFlow::Break(())
        });
        out
    }

    fn distance(
        &mut self,
        pose: &Pose,
        params: &DistanceParams,
        cache: &mut DistanceCache,
    ) -> MeshDistance {
        distance_mesh_mesh(&self.a, &self.b, pose, params, cache, &mut self.workspace)
    }

    fn within(&mut self, pose: &Pose, max_distance: f64) -> bool {
        within_distance_mesh_mesh(&self.a, &self.b, pose, max_distance, &mut self.workspace)
    }
}

fn trees<B: BoundingVolume>(a: &TriMesh, b: &TriMesh, params: BuildParams) -> Box<dyn PairQueries> {
    let (ta, tb) = (
        Bvh::<B>::from_mesh(a, &params),
        Bvh::<B>::from_mesh(b, &params),
    );
    ta.validate().expect("tree of A is valid");
    tb.validate().expect("tree of B is valid");
    Box::new(Trees {
        label: format!(
            "{}/{:?}/leaf {}",
            B::NAME,
            params.strategy,
            params.leaf_size
        ),
        a: ta,
        b: tb,
        workspace: MeshMeshWorkspace::new(),
    })
}

/// The builds every pair is tested with: the daemon's ([`MESH_TREE_PARAMS`], leaves of up
/// to two) and others, leaves of one and of up to four.
const BUILDS: [BuildParams; 5] = [
    MESH_TREE_PARAMS,
    BuildParams::MEAN_VARIANCE,
    BuildParams::MEAN_VARIANCE.with_leaf_size(4),
    BuildParams::BINNED_SAH,
    BuildParams::BINNED_SAH.with_leaf_size(4),
];

/// Every volume type under every build of [`BUILDS`], and the two sphere-tree builds:
/// [`CONFIG_COUNT`] configurations.
fn all_configs(a: &TriMesh, b: &TriMesh) -> Vec<Box<dyn PairQueries>> {
    let mut out = Vec::new();
    for params in BUILDS {
        out.push(trees::<Obb>(a, b, params));
        out.push(trees::<Rss>(a, b, params));
        out.push(trees::<Aabb>(a, b, params));
        out.push(trees::<BoundingSphere>(a, b, params));
        out.push(trees::<Kdop18>(a, b, params));
        out.push(trees::<Kdop14>(a, b, params));
        out.push(trees::<Kdop26>(a, b, params));
        out.push(trees::<Lss>(a, b, params));
    }
    // The two sphere-tree constructions (issue #33), whose trees differ in shape only.
    for params in [BuildParams::OCTREE, BuildParams::MEDIAL_AXIS] {
        out.push(trees::<BoundingSphere>(a, b, params));
    }
    assert_eq!(out.len(), CONFIG_COUNT);
    out
}

/// The configurations one pose is checked with: `per_pose` of them, rotating with the pose
/// index so that every configuration sees many poses.
fn configs_for_pose(
    configs: &mut [Box<dyn PairQueries>],
    pose_index: usize,
    per_pose: usize,
) -> impl Iterator<Item = (usize, &mut Box<dyn PairQueries>)> {
    let stride = configs.len() / per_pose.clamp(1, configs.len());
    configs
        .iter_mut()
        .enumerate()
        .filter(move |(k, _)| (k + pose_index).is_multiple_of(stride))
}

// ---------------------------------------------------------------------------------------
// Mesh pairs and poses.

struct MeshPair {
    name: String,
    a: TriMesh,
    b: TriMesh,
    /// Poses put B's origin at distance `u · (reach A + reach B)` from A's, `u` uniform in
    /// `[0, spread]`.
    spread: f64,
}

impl MeshPair {
    fn new(name: &str, a: TriMesh, b: TriMesh, spread: f64) -> Self {
        Self {
            name: name.to_owned(),
            a,
            b,
            spread,
        }
    }

    fn pose(&self, rng: &mut TestRng) -> Pose {
        let direction = rotation(rng) * DVec3::X;
        let length = (reach(&self.a) + reach(&self.b)) * rng.random_range(0.0..=self.spread);
        Pose::new(direction * length, rotation(rng))
    }

    /// The same pair with both meshes scaled by `s` about their origins.
    fn scaled(&self, s: f64) -> Self {
        Self::new(
            &format!("{} ×{s:e}", self.name),
            self.a.scaled(s),
            self.b.scaled(s),
            self.spread,
        )
    }
}

/// The procedural pairs of the main tests.
fn procedural_pairs() -> Vec<MeshPair> {
    let mut r = rng(0x6d65_7368);
    let pairs = vec![
        MeshPair::new(
            "sphere × torus",
            meshes::uv_sphere(1.0, 16, 10),
            meshes::torus(0.8, 0.3, 24, 10),
            1.5,
        ),
        MeshPair::new(
            "fine box × box",
            meshes::subdivided_cuboid(DVec3::new(0.6, 0.4, 0.5), 6),
            meshes::cuboid(DVec3::new(0.3, 0.7, 0.2)),
            1.3,
        ),
        MeshPair::new(
            "soup × grid",
            meshes::triangle_soup(&mut r, 150, 1.0, 0.3),
            meshes::grid(1.0, 12),
            1.2,
        ),
        MeshPair::new(
            "zero-area box × sphere",
            meshes::with_zero_area_triangles(&mut r, DVec3::new(0.5, 0.6, 0.4), 60),
            meshes::uv_sphere(0.6, 12, 8),
            1.5,
        ),
        MeshPair::new(
            "torus × grid",
            meshes::torus(0.7, 0.25, 20, 8),
            meshes::grid(0.8, 8),
            1.2,
        ),
        MeshPair::new(
            "torus × torus",
            meshes::torus(0.7, 0.25, 20, 8),
            meshes::torus(0.6, 0.2, 16, 8),
            1.3,
        ),
    ];
    assert_eq!(pairs.len(), MAIN_PAIRS);
    pairs
}

// ---------------------------------------------------------------------------------------
// Checks of one query on one pose against the oracle.

/// Where a failure happened, with the pose written as literal numbers.
struct Case<'a> {
    pair: &'a str,
    config: &'a str,
    pose: &'a Pose,
}

impl fmt::Display for Case<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (p, q) = (self.pose.position, self.pose.rotation);
        write!(
            f,
            "pair {}, {}, pose_ab = Pose::new(DVec3::new({:?}, {:?}, {:?}), \
             DQuat::from_xyzw({:?}, {:?}, {:?}, {:?}))",
            self.pair, self.config, p.x, p.y, p.z, q.x, q.y, q.z, q.w
        )
    }
}

fn check_intersects(q: &mut dyn PairQueries, case: &Case, truth: &Truth) {
    assert_eq!(
        q.intersects(case.pose),
        truth.intersects,
        "intersects_mesh_mesh disagrees with the oracle: {case}"
    );
}

/// The set of reported pairs is the oracle's; each contact lies on both triangles, its
/// normal is A's (or B's reversed) and unit, and no pair comes twice. A sink that stops
/// gets exactly one contact when there is any.
fn check_contacts(q: &mut dyn PairQueries, case: &Case, oracle: &Oracle, expected: &[[u32; 2]]) {
    let contacts = q.contacts(case.pose);
    let tolerance = 1e-9 * oracle.scale;
    let mut seen = HashSet::new();
    for c in &contacts {
        assert!(
            seen.insert(c.triangles),
            "pair {:?} reported twice: {case}",
            c.triangles
        );
        let [i, j] = c.triangles.map(|t| t as usize);
        assert!(
            i < oracle.a.len() && j < oracle.b.len(),
            "bad ids {:?}: {case}",
            c.triangles
        );
        let (ta, tb) = (&oracle.a[i], &oracle.b[j]);
        for p in [c.point, c.segment[0], c.segment[1]] {
            let (da, db) = (
                point_triangle_distance(p, ta),
                point_triangle_distance(p, tb),
            );
            assert!(
                da <= tolerance && db <= tolerance,
                "contact point {p} of pair {:?} is {da:e} from A's triangle and {db:e} from \
                 B's: {case}",
                c.triangles
            );
        }
        assert!(
            c.point.distance(c.segment[0].midpoint(c.segment[1])) <= 1e-12 * oracle.scale,
            "contact point is not the segment's midpoint: {case}"
        );
        assert!(
            (c.normal.length() - 1.0).abs() <= 1e-12,
            "normal {} is not unit: {case}",
            c.normal
        );
        let expected_normal = ta
            .normal()
            .or_else(|| tb.normal().map(|n| -n))
            .unwrap_or(FALLBACK_NORMAL);
        assert!(
            c.normal.dot(expected_normal) >= 1.0 - 1e-12,
            "normal {} is not A's triangle normal {expected_normal}: {case}",
            c.normal
        );
    }
    let mut got: Vec<[u32; 2]> = seen.into_iter().collect();
    got.sort_unstable();
    if got != expected {
        let want: HashSet<_> = expected.iter().copied().collect();
        let have: HashSet<_> = got.iter().copied().collect();
        let missing: Vec<_> = want.difference(&have).take(8).collect();
        let extra: Vec<_> = have.difference(&want).take(8).collect();
        panic!(
            "contacts_mesh_mesh pair set differs from the oracle ({} vs {} pairs; missing \
             {missing:?}, extra {extra:?}): {case}",
            got.len(),
            expected.len()
        );
    }
    let first = q.first_contact(case.pose);
    assert_eq!(
        first.len(),
        usize::from(!expected.is_empty()),
        "a sink that breaks must get exactly one contact: {case}"
    );
}

/// Exact distance: the oracle's minimum, zero exactly when intersecting, witnesses on the
/// reported triangles, `|point_a − point_b| = distance`; the same again with the cache warm.
fn check_distance_exact(
    q: &mut dyn PairQueries,
    case: &Case,
    oracle: &Oracle,
    truth: &Truth,
    cache: &mut DistanceCache,
) {
    let r = q.distance(case.pose, &DistanceParams::EXACT, cache);
    let expected = truth.distance;
    assert!(
        (r.distance - expected).abs() <= 1e-9 * expected,
        "distance_mesh_mesh {:e} but oracle {expected:e} (triangles {:?}): {case}",
        r.distance,
        r.triangles
    );
    // Zero exactly when the meshes intersect, or when the oracle's own minimum is zero for
    // disjoint triangles: a gap below rounding, which `distance_triangle_triangle` documents
    // may come out as 0 (counted by `Tally::gaps_below_rounding`).
    assert_eq!(
        r.distance == 0.0,
        truth.intersects || truth.distance == 0.0,
        "distance {:e} is zero iff the meshes intersect ({}): {case}",
        r.distance,
        truth.intersects
    );
    assert!(
        r.error_bound >= (r.distance - expected).abs(),
        "error bound {:e} does not cover {:e}: {case}",
        r.error_bound,
        (r.distance - expected).abs()
    );
    check_witnesses(case, oracle, &r);
    let again = q.distance(case.pose, &DistanceParams::EXACT, cache);
    assert_eq!(
        again.distance, r.distance,
        "warm repeated query gives another distance: {case}"
    );
}

fn check_witnesses(case: &Case, oracle: &Oracle, r: &MeshDistance) {
    let [i, j] = r.triangles.map(|t| t as usize);
    assert!(
        i < oracle.a.len() && j < oracle.b.len(),
        "bad ids {:?}: {case}",
        r.triangles
    );
    let tolerance = 1e-9 * oracle.scale;
    let (da, db) = (
        point_triangle_distance(r.point_a, &oracle.a[i]),
        point_triangle_distance(r.point_b, &oracle.b[j]),
    );
    assert!(
        da <= tolerance && db <= tolerance,
        "witnesses {} and {} are {da:e} and {db:e} off triangles {:?}: {case}",
        r.point_a,
        r.point_b,
        r.triangles
    );
    let gap = r.point_a.distance(r.point_b);
    assert!(
        (gap - r.distance).abs() <= 1e-12 * r.distance,
        "|point_a − point_b| = {gap:e} but distance {:e}: {case}",
        r.distance
    );
    let pair = distance_triangle_triangle(&oracle.a[i], &oracle.b[j]).distance;
    assert!(
        (pair - r.distance).abs() <= 1e-12 * r.distance,
        "the reported triangles are {pair:e} apart, not {:e}: {case}",
        r.distance
    );
}

/// With tolerances: `oracle ≤ d ≤ oracle + max(abs, rel · oracle) + rounding`, and the
/// error bound covers the difference.
fn check_distance_tolerant(
    q: &mut dyn PairQueries,
    case: &Case,
    oracle: &Oracle,
    truth: &Truth,
    params: &DistanceParams,
    cache: &mut DistanceCache,
) {
    let r = q.distance(case.pose, params, cache);
    let expected = truth.distance;
    let allowed = params.abs_err.max(params.rel_err * expected) + 1e-12 * oracle.scale;
    assert!(
        expected <= r.distance && r.distance <= expected + allowed,
        "distance_mesh_mesh with {params:?} gave {:e}, oracle {expected:e}: {case}",
        r.distance
    );
    assert!(
        r.error_bound >= r.distance - expected,
        "error bound {:e} does not cover {:e} with {params:?}: {case}",
        r.error_bound,
        r.distance - expected
    );
    check_witnesses(case, oracle, &r);
}

/// `within_distance_mesh_mesh(d) == (oracle ≤ d)`, unless `d` is within 1e-9 relative of
/// the oracle distance (then `None`: too close to call).
fn check_within(q: &mut dyn PairQueries, case: &Case, truth: &Truth, d: f64) -> Option<bool> {
    if (truth.distance - d).abs() < 1e-9 * truth.distance.max(d) {
        return None;
    }
    let expected = truth.distance <= d;
    assert_eq!(
        q.within(case.pose, d),
        expected,
        "within_distance_mesh_mesh({d:e}) disagrees with oracle distance {:e}: {case}",
        truth.distance
    );
    Some(expected)
}

/// A tolerance for the distance query: absolute, relative or both, never both zero.
fn random_params(rng: &mut TestRng, scale: f64) -> DistanceParams {
    let abs = scale * rng.random_range(1e-4..0.2);
    let rel = rng.random_range(1e-3..0.5);
    match rng.random_range(0..3) {
        0 => DistanceParams {
            abs_err: abs,
            rel_err: 0.0,
        },
        1 => DistanceParams {
            abs_err: 0.0,
            rel_err: rel,
        },
        _ => DistanceParams {
            abs_err: abs,
            rel_err: rel,
        },
    }
}

/// A query distance for `within`: the true distance itself (a tie, skipped), a hair either
/// side of it (relative 1e-8 to 1e-3), near it (either side), or anywhere up to the
/// meshes' size.
fn random_within_distance(rng: &mut TestRng, truth: &Truth, size: f64) -> f64 {
    let t = truth.distance;
    match rng.random_range(0..10) {
        0 if t > 0.0 => t,
        1..=3 if t > 0.0 => {
            let hair = 10f64.powf(rng.random_range(-8.0..-3.0));
            t * if rng.random_bool(0.5) {
                1.0 + hair
            } else {
                1.0 - hair
            }
        }
        4..=6 if t > 0.0 => t * rng.random_range(0.5..1.5),
        _ => size * rng.random_range(1e-6..0.3),
    }
}

// ---------------------------------------------------------------------------------------
// Outcome bookkeeping.

/// Oracle outcomes of the poses of one test.
#[derive(Debug, Default)]
struct Tally {
    poses: usize,
    colliding: usize,
    separated: usize,
    /// Separated poses whose oracle distance is nevertheless 0 (a gap below rounding).
    gaps_below_rounding: usize,
}

impl Tally {
    fn pose(&mut self, truth: &Truth) {
        self.poses += 1;
        if truth.intersects {
            self.colliding += 1;
        } else {
            self.separated += 1;
            if truth.distance == 0.0 {
                self.gaps_below_rounding += 1;
            }
        }
    }

    /// Colliding and separated poses each at least 10 %.
    fn assert_both_outcomes(&self, test: &str) {
        eprintln!("{test}: {self:?}");
        assert!(
            10 * self.colliding >= self.poses && 10 * self.separated >= self.poses,
            "{test}: one outcome is rarer than 10 %: {self:?}"
        );
    }
}

/// Outcomes of `within_distance_mesh_mesh` checks.
#[derive(Debug, Default)]
struct WithinTally {
    within: usize,
    beyond: usize,
    /// Query distances within 1e-9 relative of the oracle's: too close to call, not checked.
    skipped: usize,
}

impl WithinTally {
    fn add(&mut self, outcome: Option<bool>) {
        match outcome {
            Some(true) => self.within += 1,
            Some(false) => self.beyond += 1,
            None => self.skipped += 1,
        }
    }

    /// Both answers each at least 10 % of the decided checks.
    fn assert_both_outcomes(&self, test: &str) {
        eprintln!("{test} within_distance: {self:?}");
        let decided = self.within + self.beyond;
        assert!(
            10 * self.within >= decided && 10 * self.beyond >= decided,
            "{test}: one within_distance answer is rarer than 10 %: {self:?}"
        );
    }
}

/// One configuration's turn on one pose.
struct Visit<'a> {
    case: Case<'a>,
    oracle: &'a Oracle,
    truth: &'a Truth,
    /// Index of the configuration in [`all_configs`].
    config: usize,
    /// Whether this is the first configuration checked on this pose.
    first: bool,
}

/// Runs `check` on `poses` seeded random poses of every pair, each pose on
/// `configs_per_pose` rotating configurations, with the oracle computed once per pose.
fn for_random_poses(
    pairs: &[MeshPair],
    seed: u64,
    poses: usize,
    configs_per_pose: usize,
    check: impl FnMut(&mut dyn PairQueries, &Visit, &mut TestRng),
) -> Tally {
    let pose_of = |pair: &MeshPair, r: &mut TestRng, _| pair.pose(r);
    for_poses(pairs, seed, poses, configs_per_pose, pose_of, check)
}

/// [`for_random_poses`] with poses from `pose_of(pair, rng, index)`.
fn for_poses(
    pairs: &[MeshPair],
    seed: u64,
    poses: usize,
    configs_per_pose: usize,
    mut pose_of: impl FnMut(&MeshPair, &mut TestRng, usize) -> Pose,
    mut check: impl FnMut(&mut dyn PairQueries, &Visit, &mut TestRng),
) -> Tally {
    let mut r = rng(seed);
    let mut tally = Tally::default();
    for pair in pairs {
        let colliding_before = tally.colliding;
        let mut configs = all_configs(&pair.a, &pair.b);
        for k in 0..poses {
            let pose = pose_of(pair, &mut r, k);
            let oracle = Oracle::new(&pair.a, &pair.b, &pose);
            let truth = oracle.truth();
            tally.pose(&truth);
            let chosen = configs_for_pose(&mut configs, k, configs_per_pose);
            for (turn, (config, q)) in chosen.enumerate() {
                let label = q.label().to_owned();
                let visit = Visit {
                    case: Case {
                        pair: &pair.name,
                        config: &label,
                        pose: &pose,
                    },
                    oracle: &oracle,
                    truth: &truth,
                    config,
                    first: turn == 0,
                };
                check(q.as_mut(), &visit, &mut r);
            }
        }
        eprintln!(
            "{}: {} of {poses} poses colliding",
            pair.name,
            tally.colliding - colliding_before
        );
    }
    tally
}

// ---------------------------------------------------------------------------------------
// 1–4: the four queries on random poses of the procedural pairs.

#[test]
fn intersects_mesh_mesh_equals_the_brute_force_boolean() {
    let tally = for_random_poses(
        &procedural_pairs(),
        1,
        MAIN_POSES_PER_PAIR,
        CONFIGS_PER_POSE,
        |q, v, _| check_intersects(q, &v.case, v.truth),
    );
    tally.assert_both_outcomes("intersects");
}

#[test]
fn contacts_mesh_mesh_reports_exactly_the_brute_force_pairs() {
    let mut expected = Vec::new();
    let tally = for_random_poses(
        &procedural_pairs(),
        2,
        MAIN_POSES_PER_PAIR,
        CONFIGS_PER_POSE,
        |q, v, _| {
            if v.first {
                expected = v.oracle.pairs();
            }
            check_contacts(q, &v.case, v.oracle, &expected);
        },
    );
    tally.assert_both_outcomes("contacts");
}

#[test]
fn distance_mesh_mesh_is_the_brute_force_minimum_with_witnesses_on_their_triangles() {
    // One cache per configuration, carried across poses and pairs: warm starts from the
    // previous pose's closest pair (and from another mesh pair's slots) must be harmless.
    let mut caches = vec![DistanceCache::new(); CONFIG_COUNT];
    let tally = for_random_poses(
        &procedural_pairs(),
        3,
        MAIN_POSES_PER_PAIR,
        CONFIGS_PER_POSE,
        |q, v, _| check_distance_exact(q, &v.case, v.oracle, v.truth, &mut caches[v.config]),
    );
    tally.assert_both_outcomes("distance");
}

#[test]
fn distance_with_tolerances_stays_within_abs_and_rel_error_of_the_minimum() {
    let tally = for_random_poses(
        &procedural_pairs(),
        4,
        TOLERANCE_POSES_PER_PAIR,
        CONFIGS_PER_POSE,
        |q, v, r| {
            let params = random_params(r, v.oracle.scale);
            let mut cache = DistanceCache::new();
            check_distance_tolerant(q, &v.case, v.oracle, v.truth, &params, &mut cache);
        },
    );
    tally.assert_both_outcomes("distance with tolerances");
}

#[test]
fn within_distance_mesh_mesh_equals_the_brute_force_comparison() {
    let mut within = WithinTally::default();
    let tally = for_random_poses(
        &procedural_pairs(),
        5,
        MAIN_POSES_PER_PAIR,
        CONFIGS_PER_POSE,
        |q, v, r| {
            let d = random_within_distance(r, v.truth, v.oracle.scale);
            within.add(check_within(q, &v.case, v.truth, d));
        },
    );
    tally.assert_both_outcomes("within");
    within.assert_both_outcomes("within");
}

// ---------------------------------------------------------------------------------------
// 5: stress cases, every query on every pose.

/// Every query on one pose against the oracle; `pairs` is the oracle's pair set of the pose.
fn check_every_query(
    q: &mut dyn PairQueries,
    v: &Visit,
    pairs: &[[u32; 2]],
    r: &mut TestRng,
    within: &mut WithinTally,
) {
    check_intersects(q, &v.case, v.truth);
    check_contacts(q, &v.case, v.oracle, pairs);
    let mut cache = DistanceCache::new();
    check_distance_exact(q, &v.case, v.oracle, v.truth, &mut cache);
    let params = random_params(r, v.oracle.scale);
    check_distance_tolerant(q, &v.case, v.oracle, v.truth, &params, &mut cache);
    let d = random_within_distance(r, v.truth, v.oracle.scale);
    within.add(check_within(q, &v.case, v.truth, d));
}

/// [`for_poses`] running [`check_every_query`]; returns the pose and `within` tallies.
fn every_query_on_poses(
    pairs: &[MeshPair],
    seed: u64,
    poses: usize,
    configs_per_pose: usize,
    pose_of: impl FnMut(&MeshPair, &mut TestRng, usize) -> Pose,
) -> (Tally, WithinTally) {
    let mut within = WithinTally::default();
    let mut expected = Vec::new();
    let tally = for_poses(pairs, seed, poses, configs_per_pose, pose_of, |q, v, r| {
        if v.first {
            expected = v.oracle.pairs();
        }
        check_every_query(q, v, &expected, r, &mut within);
    });
    (tally, within)
}

/// Half extents of the two stacked boxes: dyadic, so every coordinate below is exact.
const LOWER_HALF: DVec3 = DVec3::new(1.0, 1.0, 1.0);
const UPPER_HALF: DVec3 = DVec3::new(0.5, 0.75, 0.25);

#[test]
fn stacked_boxes_touching_face_to_face_intersect_and_a_gap_of_1e_9_separates_them() {
    let pairs = [
        MeshPair::new(
            "box on box",
            meshes::cuboid(LOWER_HALF),
            meshes::cuboid(UPPER_HALF),
            0.0,
        ),
        MeshPair::new(
            "fine box on fine box",
            meshes::subdivided_cuboid(LOWER_HALF, 4),
            meshes::subdivided_cuboid(UPPER_HALF, 2),
            0.0,
        ),
    ];
    let gap = 1e-9 * 2.0;
    let touching_z = LOWER_HALF.z + UPPER_HALF.z;
    let reach_xy = LOWER_HALF.truncate() + UPPER_HALF.truncate();
    // Pose k: vertical offset touching, a gap above, or a gap into A (by k % 3); identity
    // rotation for even k (faces and edges aligned, side faces sometimes coplanar too),
    // else a random rotation about z (keeps every z coordinate exact).
    let pose_of = |pair: &MeshPair, r: &mut TestRng, k: usize| {
        let offset = [0.0, gap, -gap][k % 3];
        let (x, y) = if k.is_multiple_of(5) {
            // B's side faces in A's side planes as well.
            (LOWER_HALF.x - UPPER_HALF.x, -(LOWER_HALF.y - UPPER_HALF.y))
        } else {
            (
                r.random_range(-1.2..=1.2) * reach_xy.x,
                r.random_range(-1.2..=1.2) * reach_xy.y,
            )
        };
        let aligned = k.is_multiple_of(2);
        let rotation = if aligned {
            DQuat::IDENTITY
        } else {
            DQuat::from_rotation_z(r.random_range(0.0..std::f64::consts::TAU))
        };
        let pose = Pose::new(DVec3::new(x, y, touching_z + offset), rotation);
        if aligned {
            // Aligned boxes: the truth is known, and the oracle must find it.
            let faces_meet = x.abs() <= reach_xy.x && y.abs() <= reach_xy.y;
            let truth = Oracle::new(&pair.a, &pair.b, &pose).truth();
            assert_eq!(
                truth.intersects,
                faces_meet && offset <= 0.0,
                "{}, {pose:?}",
                pair.name
            );
            if faces_meet && offset > 0.0 {
                assert!(
                    (truth.distance - offset).abs() <= 1e-6 * offset,
                    "{truth:?}"
                );
            }
        }
        pose
    };
    let (tally, within) =
        every_query_on_poses(&pairs, 51, COPLANAR_POSES / 2, CONFIG_COUNT, pose_of);
    tally.assert_both_outcomes("stacked boxes");
    within.assert_both_outcomes("stacked boxes");
}

#[test]
fn a_mesh_against_itself_and_two_halves_of_one_mesh_agree_where_they_share_vertices() {
    let mut r = rng(52);
    let sphere = meshes::uv_sphere(1.0, 16, 10);
    let torus = meshes::torus(0.8, 0.3, 24, 10);
    let fine_box = meshes::subdivided_cuboid(DVec3::new(0.6, 0.4, 0.5), 5);
    let zero_area = meshes::with_zero_area_triangles(&mut r, DVec3::new(0.5, 0.6, 0.4), 40);
    let grid = meshes::grid(1.0, 10);
    let halves = |name: &str, m: &TriMesh| {
        let (left, right) = meshes::halves(m);
        MeshPair::new(name, left, right, 0.0)
    };
    let pairs = [
        MeshPair::new("sphere itself", sphere.clone(), sphere.clone(), 0.0),
        MeshPair::new("torus itself", torus.clone(), torus.clone(), 0.0),
        MeshPair::new("fine box itself", fine_box.clone(), fine_box.clone(), 0.0),
        MeshPair::new("zero-area box itself", zero_area.clone(), zero_area, 0.0),
        MeshPair::new("grid itself", grid.clone(), grid, 0.0),
        halves("sphere halves", &sphere),
        halves("torus halves", &torus),
        halves("fine box halves", &fine_box),
    ];
    // Identity (every shared vertex and edge touches); a rotation by one segment of the
    // sphere about z (vertices land on vertices up to rounding); tiny shifts, 1e-12 and
    // 1e-9 of the size, in random directions; and one random rotation about z.
    let step = DQuat::from_rotation_z(std::f64::consts::TAU / 16.0);
    let mut identity_checked = 0;
    let pose_of = |pair: &MeshPair, r: &mut TestRng, k: usize| {
        let shift = rotation(r) * DVec3::X;
        let pose = match k {
            0 => Pose::IDENTITY,
            1 => Pose::from_rotation(step),
            2 => Pose::from_translation(shift * 1e-12),
            3 => Pose::from_translation(shift * 1e-9),
            _ => Pose::from_rotation(DQuat::from_rotation_z(r.random_range(0.0..1.0))),
        };
        if k == 0 {
            let oracle = Oracle::new(&pair.a, &pair.b, &pose);
            assert!(oracle.truth().intersects, "{} touches itself", pair.name);
            if pair.a == pair.b {
                let pairs = oracle.pairs();
                assert!(
                    (0..pair.a.triangle_count() as u32).all(|i| pairs.contains(&[i, i])),
                    "every triangle meets itself"
                );
            }
            identity_checked += 1;
        }
        pose
    };
    let (tally, within) = every_query_on_poses(&pairs, 53, 5, CONFIG_COUNT, pose_of);
    assert_eq!(identity_checked, pairs.len());
    eprintln!("shared vertices: {tally:?}, within_distance: {within:?}");
    assert!(tally.colliding >= pairs.len());
}

/// Random poses of a few procedural pairs, for the offset and scale stress tests.
fn stress_pairs() -> Vec<MeshPair> {
    let mut pairs = procedural_pairs();
    pairs.retain(|p| ["sphere × torus", "fine box × box", "soup × grid"].contains(&&*p.name));
    assert_eq!(pairs.len(), STRESS_PAIRS);
    pairs
}

#[test]
fn meshes_1e5_from_the_origin_agree_with_the_oracle() {
    // Both meshes moved by `far` in their own frames; the pose keeps B where it was
    // relative to A: x_A' = R x_B' + (t + far − R far).
    let far = DVec3::new(1.0, -1.0, 1.0).normalize() * 1e5;
    let pairs: Vec<MeshPair> = stress_pairs()
        .into_iter()
        .map(|p| {
            let name = format!("{} at 1e5", p.name);
            MeshPair::new(&name, p.a.translated(far), p.b.translated(far), p.spread)
        })
        .collect();
    let originals = stress_pairs();
    let pose_of = |pair: &MeshPair, r: &mut TestRng, _| {
        let original = originals
            .iter()
            .find(|o| pair.name.starts_with(&o.name))
            .expect("original pair");
        let near = original.pose(r);
        Pose::new(near.position + far - near.rotation * far, near.rotation)
    };
    let (tally, within) = every_query_on_poses(&pairs, 54, STRESS_POSES, 8, pose_of);
    tally.assert_both_outcomes("far from the origin");
    within.assert_both_outcomes("far");
}

#[test]
fn scales_1e_minus_3_and_1e3_of_the_same_pairs_agree_with_the_oracle() {
    let pairs: Vec<MeshPair> = stress_pairs()
        .iter()
        .flat_map(|p| [p.scaled(1e-3), p.scaled(1e3)])
        .collect();
    let (tally, within) =
        every_query_on_poses(&pairs, 55, STRESS_POSES, 8, |pair, r, _| pair.pose(r));
    tally.assert_both_outcomes("scaled");
    within.assert_both_outcomes("scaled");
}

#[test]
fn spot_against_rob_agrees_with_the_oracle() {
    // Spot is about 1.7 m tall; rob (FCL's robot mesh, in millimetres) is scaled to about
    // 1.5 m. Both centred on their bounding boxes.
    let spot = meshes::data_mesh("spot.obj").centered_on_bounds();
    let rob = meshes::data_mesh("rob.obj")
        .scaled(1.5e-3)
        .centered_on_bounds();
    assert_eq!((spot.triangle_count(), rob.triangle_count()), (5856, 216));
    let pairs = [MeshPair::new("spot × rob", spot, rob, 0.9)];
    let (tally, within) =
        every_query_on_poses(&pairs, 56, REAL_MESH_POSES, 4, every_other_pose_grazing);
    tally.assert_both_outcomes("spot × rob");
    within.assert_both_outcomes("spot × rob");
}

#[test]
fn large_flat_triangles_against_detailed_meshes_agree_with_the_oracle() {
    // A leaf of one large triangle is tested by the triangle itself against the small
    // nodes of the other tree (its volume, a rectangle or box around it, is half empty):
    // a two-triangle plate and one big triangle against fine meshes, every other pose
    // grazing, so that pairs near the volumes' empty half, touching and apart all occur.
    let big = TriMesh::try_new(
        vec![
            DVec3::new(-1.2, -0.9, 0.0),
            DVec3::new(1.3, -0.7, 0.05),
            DVec3::new(-0.2, 1.1, -0.03),
        ],
        vec![[0, 1, 2]],
    )
    .expect("one triangle");
    let pairs = [
        MeshPair::new(
            "plate × fine sphere",
            meshes::grid(1.0, 1),
            meshes::uv_sphere(0.5, 40, 24),
            1.2,
        ),
        MeshPair::new(
            "big triangle × torus",
            big,
            meshes::torus(0.4, 0.15, 40, 16),
            1.1,
        ),
    ];
    let (tally, within) =
        every_query_on_poses(&pairs, 57, STRESS_POSES, 8, every_other_pose_grazing);
    tally.assert_both_outcomes("large flat triangles");
    within.assert_both_outcomes("large flat triangles");
}

/// Pose `k` of a pair: a random one for even `k`, a grazing one (see [`grazing_pose`])
/// for odd `k`, cycling through [`GRAZING_EPSILONS`].
fn every_other_pose_grazing(pair: &MeshPair, r: &mut TestRng, k: usize) -> Pose {
    if k.is_multiple_of(2) {
        pair.pose(r)
    } else {
        grazing_pose(pair, r, GRAZING_EPSILONS[(k / 2) % GRAZING_EPSILONS.len()])
    }
}

/// Relative gaps left by [`grazing_pose`].
const GRAZING_EPSILONS: [f64; 6] = [1e-3, 1e-6, 1e-9, 1e-12, 0.0, -1e-9];

/// A random separated pose of `pair` with B then moved along the oracle's witness
/// direction until the witness pair's gap is `epsilon` times what it was.
fn grazing_pose(pair: &MeshPair, r: &mut TestRng, epsilon: f64) -> Pose {
    loop {
        let pose = pair.pose(r);
        let closest = Oracle::new(&pair.a, &pair.b, &pose).closest();
        if closest.distance > 0.0 {
            let shift = (closest.point_a - closest.point_b) * (1.0 - epsilon);
            return Pose::new(pose.position + shift, pose.rotation);
        }
    }
}

#[test]
fn grazing_poses_a_hair_from_contact_agree_with_the_oracle() {
    // From a random separated pose, B is moved along the oracle's witness direction so that
    // the witness pair's gap shrinks to ε · d: the node pairs near the contact are then a
    // hair apart (or a hair into each other), where a volume test that is not conservative
    // culls a pair it must keep.
    let pose_of = |pair: &MeshPair, r: &mut TestRng, k: usize| {
        grazing_pose(pair, r, GRAZING_EPSILONS[k % GRAZING_EPSILONS.len()])
    };
    let (tally, within) = every_query_on_poses(
        &procedural_pairs(),
        57,
        GRAZING_POSES_PER_PAIR,
        CONFIG_COUNT,
        pose_of,
    );
    tally.assert_both_outcomes("grazing");
    within.assert_both_outcomes("grazing");
}

#[test]
fn nearly_parallel_faces_a_small_gap_apart_give_the_exact_minimum() {
    // B's bottom face over A's top face, tilted by a tiny angle about a random horizontal
    // axis: many triangle pairs are within a hair of the minimum, so a distance search that
    // skips node pairs "almost as far as the best" returns a slightly wrong minimum, and
    // the contact set of a tilted touching pose is a few pairs among many near misses.
    let pairs = [
        MeshPair::new(
            "box over box",
            meshes::cuboid(LOWER_HALF),
            meshes::cuboid(UPPER_HALF),
            0.0,
        ),
        MeshPair::new(
            "fine box over fine box",
            meshes::subdivided_cuboid(LOWER_HALF, 6),
            meshes::subdivided_cuboid(UPPER_HALF, 4),
            0.0,
        ),
    ];
    const GAPS: [f64; 5] = [1e-3, 1e-6, 2e-9, 0.0, -2e-9];
    const TILTS: [f64; 3] = [1e-5, 1e-7, 1e-9];
    let touching_z = LOWER_HALF.z + UPPER_HALF.z;
    let pose_of = |_: &MeshPair, r: &mut TestRng, k: usize| {
        let gap = GAPS[k % GAPS.len()];
        let tilt = TILTS[(k / GAPS.len()) % TILTS.len()];
        let axis_angle = r.random_range(0.0..std::f64::consts::TAU);
        let axis = DVec3::new(axis_angle.cos(), axis_angle.sin(), 0.0);
        let spin = DQuat::from_rotation_z(r.random_range(0.0..std::f64::consts::TAU));
        let rotation = (DQuat::from_axis_angle(axis, tilt) * spin).normalize();
        let x = r.random_range(-0.4..=0.4);
        let y = r.random_range(-0.2..=0.2);
        Pose::new(DVec3::new(x, y, touching_z + gap), rotation)
    };
    let (tally, within) =
        every_query_on_poses(&pairs, 58, NEAR_PARALLEL_POSES / 2, CONFIG_COUNT, pose_of);
    tally.assert_both_outcomes("nearly parallel faces");
    within.assert_both_outcomes("nearly parallel");
}
