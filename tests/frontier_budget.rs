//! The budgeted breadth-first frontier (`proxima::narrow::mesh_mesh::frontier`) against an independent
//! oracle, at every interruption point of a counted budget.
//!
//! Oracle: the minimum of `distance_triangle_triangle` over *all* triangle pairs of a mesh
//! pair, with B's triangles mapped into A's frame by `Triangle::transformed` exactly as the
//! frontier maps them (so both see bit-identical triangles). The only shortcut is a cull
//! of triangle pairs whose axis-aligned boxes are farther apart than a distance known to be
//! reached (padded by a slack far above rounding), which is trivially correct: a brute-force
//! loop with a running best for the small meshes, a hash grid of B's boxes searched within
//! a radius that doubles until some pair is found for the large ones. No BVH is involved.
//! The two oracles are checked against each other on the small scenes.
//!
//! Scenes: degenerate pairs (coplanar faces touching or 1e-9 apart, a mesh against itself,
//! zero-area triangles, an open grid, triangle soup, zero thresholds), piles of six tori at
//! seeded random poses (about ten candidate pairs each, some touching, some within their
//! threshold, some beyond it), and the Stanford bunny, fandisk and a torus at placed poses
//! (from the data folder, `PROXIMA_DATA`; skipped with a line saying so when absent).
//!
//! At every interruption point (every budget `0 ..= unlimited visits`, the budget polled
//! after every entry or every few visits), reached by resuming one traversal with a
//! growing [`VisitBudget`], each pair's answer must be conservative (close pairs are `maybe_close`,
//! `distance_lower ≤ true ≤ distance_upper`, `true − distance_lower ≤ error_bound`) and
//! no worse than at the previous point (`distance_lower` never decreases; Exact answers
//! never change). Sampled budgets are re-run from scratch, twice: bit-identical to the
//! resumed state. The unlimited run must equal the oracle and the exact queries
//! (`distance_mesh_mesh`, `within_distance_mesh_mesh`). Truncated and Exact answers, and
//! touching, near and apart pairs, are all asserted to occur.
mod support;

use proxima::bounding::{Aabb, BoundingSphere, BoundingVolume, Kdop18, Lss, Obb, Rss};
use proxima::budget::{Completeness, Unlimited, VisitBudget};
use proxima::bvh::{BuildParams, Bvh};
use proxima::geometry::{TriMesh, Triangle};
use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::distance_triangle_triangle;
use proxima::narrow::mesh_mesh::frontier::MeshPairTrees;
use proxima::narrow::mesh_mesh::frontier::{
    FrontierAnswer, FrontierPair, FrontierWorkspace, PairTrees, RoundOrder, query_frontier,
};
use proxima::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshMeshWorkspace, distance_mesh_mesh, within_distance_mesh_mesh,
};
use proxima::narrow::{MeshShape, QueryVolume};
use rand::Rng;
use std::collections::HashMap;
use std::sync::Arc;
use support::meshes;
use support::triangle_pairs::{TriangleBox, TrianglePairs};
use support::{rng, rotation};

// ---------------------------------------------------------------------------------------
// The oracle.

/// A's triangles and B's mapped into A's frame, with their boxes.
struct Oracle {
    a: Vec<Triangle>,
    b: Vec<Triangle>,
    a_boxes: Vec<TriangleBox>,
    b_boxes: Vec<TriangleBox>,
    /// Box-cull padding: far above the rounding of a distance at this scale.
    slack: f64,
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
            b,
            a_boxes,
            b_boxes,
            slack: 1e-9 * scale + 1e-300,
        }
    }

    /// Every pair, with a running best: a pair whose boxes are farther apart than the best
    /// distance so far (plus the slack) cannot be closer.
    fn brute_force(&self) -> f64 {
        let mut best = f64::INFINITY;
        for (ta, ba) in self.a.iter().zip(&self.a_boxes) {
            for (tb, bb) in self.b.iter().zip(&self.b_boxes) {
                if ba.gap(bb) <= best + self.slack {
                    best = best.min(distance_triangle_triangle(ta, tb).distance);
                }
            }
        }
        best
    }

    /// The minimum over the pairs whose boxes are within `radius` (plus the slack), when it
    /// is at most `radius` (then it is the minimum over all pairs), from a hash grid of B's
    /// boxes.
    fn minimum_within(&self, radius: f64) -> Option<f64> {
        let cell = radius.max(
            self.b_boxes
                .iter()
                .map(|b| (b.hi - b.lo).max_element())
                .sum::<f64>()
                / self.b_boxes.len() as f64,
        );
        let key = |p: DVec3| (p / cell).floor().as_i64vec3().to_array();
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (j, bb) in self.b_boxes.iter().enumerate() {
            let (lo, hi) = (key(bb.lo), key(bb.hi));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        grid.entry([x, y, z]).or_default().push(j as u32);
                    }
                }
            }
        }
        let reach = radius + self.slack;
        let mut stamp = vec![usize::MAX; self.b.len()];
        let mut best = f64::INFINITY;
        for (i, (ta, ba)) in self.a.iter().zip(&self.a_boxes).enumerate() {
            let (lo, hi) = (key(ba.lo - reach), key(ba.hi + reach));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        for &j in grid.get(&[x, y, z]).map_or(&[][..], Vec::as_slice) {
                            let j = j as usize;
                            if stamp[j] == i {
                                continue;
                            }
                            stamp[j] = i;
                            if ba.gap(&self.b_boxes[j]) <= reach {
                                best =
                                    best.min(distance_triangle_triangle(ta, &self.b[j]).distance);
                            }
                        }
                    }
                }
            }
        }
        (best <= radius).then_some(best)
    }

    /// The minimum over all pairs by [`minimum_within`](Self::minimum_within), doubling the
    /// radius from `radius` until a pair is found.
    fn by_grid(&self, mut radius: f64) -> f64 {
        loop {
            if let Some(d) = self.minimum_within(radius) {
                return d;
            }
            radius *= 2.0;
        }
    }
}

// ---------------------------------------------------------------------------------------
// Scenes.

/// One candidate pair: meshes by index, B's pose in A's frame, the margin sum.
#[derive(Debug, Clone, Copy)]
struct PairSpec {
    a: usize,
    b: usize,
    pose_ab: Pose,
    threshold: f64,
}

struct Scene {
    name: String,
    meshes: Vec<TriMesh>,
    pairs: Vec<PairSpec>,
    /// The oracle's distance of each pair.
    truth: Vec<f64>,
}

/// Six tori of random sizes at random poses around the points of a 3 × 2 grid; candidate pairs are those whose
/// bounding spheres come within the margin sum (about ten of the fifteen).
fn tori_pile(seed: u64) -> Scene {
    let mut r = rng(seed);
    let mut meshes = Vec::new();
    let mut spheres = Vec::new();
    let mut margins = Vec::new();
    for _ in 0..6 {
        let (major, minor) = (r.random_range(0.3..0.5), r.random_range(0.08..0.16));
        let around = r.random_range(12..=20);
        let across = r.random_range(6..=10);
        meshes.push(meshes::torus(major, minor, around, across));
        // A 3 × 2 grid, jittered: neighbours interact, diagonals sometimes.
        let k = meshes.len() - 1;
        let cell = DVec3::new((k % 3) as f64 - 1.0, (k / 3) as f64 - 0.5, 0.0) * 0.75;
        let pose = Pose::new(cell + support::point_in_cube(&mut r, 0.2), rotation(&mut r));
        spheres.push((pose, major + minor));
        margins.push(r.random_range(0.01..0.06));
    }
    let mut pairs = Vec::new();
    for i in 0..6 {
        for j in i + 1..6 {
            let threshold: f64 = margins[i] + margins[j];
            let ((pi, ri), (pj, rj)) = (spheres[i], spheres[j]);
            if pi.position.distance(pj.position) <= ri + rj + threshold {
                pairs.push(PairSpec {
                    a: i,
                    b: j,
                    pose_ab: Pose::relative(&pi, &pj),
                    threshold,
                });
            }
        }
    }
    let truth = pairs
        .iter()
        .map(|p| Oracle::new(&meshes[p.a], &meshes[p.b], &p.pose_ab).brute_force())
        .collect();
    Scene {
        name: format!("tori pile {seed}"),
        meshes,
        pairs,
        truth,
    }
}

/// Degenerate pairs: coplanar faces touching and a hair apart, a mesh against itself,
/// zero-area triangles, an open grid, random triangle soup, thresholds of zero.
fn degenerate_scene(seed: u64) -> Scene {
    let mut r = rng(seed);
    let half = DVec3::splat(0.5);
    let meshes = vec![
        meshes::cuboid(half),
        meshes::subdivided_cuboid(half, 3),
        meshes::grid(0.6, 6),
        meshes::zero_area_triangles(&mut r, 40, 0.5),
        meshes::with_zero_area_triangles(&mut r, DVec3::new(0.3, 0.4, 0.5), 12),
        meshes::torus(0.4, 0.1, 12, 6),
        meshes::triangle_soup(&mut r, 60, 0.5, 0.1),
    ];
    let up = |z: f64| Pose::from_translation(DVec3::new(0.0, 0.0, z));
    let mut pairs = vec![
        // Stacked boxes, faces coplanar: touching, then 1e-9 apart.
        (0, 1, up(1.0), 0.0),
        (0, 1, up(1.0 + 1e-9), 0.0),
        (0, 1, up(1.0 + 1e-9), 2e-9),
        (1, 0, up(-1.0 - 1e-3), 1e-3),
        // A mesh against itself at the same pose.
        (5, 5, Pose::IDENTITY, 0.01),
        (3, 3, Pose::IDENTITY, 0.0),
        // A torus lying on the open grid, a hair above it.
        (2, 5, up(0.1 + 1e-4), 1e-4),
        (2, 5, up(0.1 + 1e-4), 0.0),
        (5, 2, up(-0.3), 0.05),
    ];
    for _ in 0..6 {
        let (a, b) = ([3, 4, 6][r.random_range(0..3)], r.random_range(0..7));
        let pose = Pose::new(support::point_in_cube(&mut r, 0.8), rotation(&mut r));
        pairs.push((a, b, pose, r.random_range(0.0..0.1)));
    }
    let pairs: Vec<PairSpec> = pairs
        .into_iter()
        .map(|(a, b, pose_ab, threshold)| PairSpec {
            a,
            b,
            pose_ab,
            threshold,
        })
        .collect();
    let truth = pairs
        .iter()
        .map(|p| Oracle::new(&meshes[p.a], &meshes[p.b], &p.pose_ab).brute_force())
        .collect();
    Scene {
        name: format!("degenerate {seed}"),
        meshes,
        pairs,
        truth,
    }
}

/// A pose of B in A's frame, turned by `rotation`, placed so that the closest pair found by
/// the exact distance query from a far start is moved to `target` metres apart along its
/// witness direction (negative: pushed through). Other triangle pairs may end up closer;
/// the oracle decides.
fn placed(a: &Bvh<Obb>, b: &Bvh<Obb>, rotation: DQuat, direction: DVec3, target: f64) -> Pose {
    let far = a.root_bv().size() + b.root_bv().size();
    let start = Pose::new(direction.normalize() * far, rotation);
    let d = distance_mesh_mesh(
        a,
        b,
        &start,
        &DistanceParams::EXACT,
        &mut DistanceCache::new(),
        &mut MeshMeshWorkspace::new(),
    );
    assert!(d.distance > 0.0, "the start pose is separated");
    let normal = (d.point_b - d.point_a) / d.distance;
    Pose::new(start.position + normal * (target - d.distance), rotation)
}

/// The bunny (×10, 69,451 triangles), fandisk (×0.3, 12,946 triangles) and a torus, both
/// about 1.5 m across, at poses placed touching, within the threshold and beyond it.
fn bunny_fandisk(who: &str) -> Option<Scene> {
    let bunny = meshes::shared_data_mesh(who, "stanford-bunny.obj")?
        .scaled(10.0)
        .centered_on_bounds();
    let fandisk = meshes::shared_data_mesh(who, "fandisk.obj")?
        .scaled(0.3)
        .centered_on_bounds();
    let torus = meshes::torus(0.4, 0.1, 24, 12);
    let meshes = vec![bunny, fandisk, torus];
    let params = BuildParams::BINNED_SAH.with_leaf_size(4);
    let trees: Vec<Bvh<Obb>> = meshes.iter().map(|m| Bvh::from_mesh(m, &params)).collect();
    let mut r = rng(77);
    let threshold = 0.05;
    let mut pairs = Vec::new();
    for (a, b, targets) in [
        (0, 1, &[-0.05, 0.0, 0.02, 0.04, 0.08, 0.2][..]),
        (0, 2, &[-0.02, 0.03, 0.1][..]),
        (1, 2, &[0.01, 0.07][..]),
    ] {
        for &target in targets {
            let pose_ab = placed(
                &trees[a],
                &trees[b],
                rotation(&mut r),
                support::point_in_cube(&mut r, 1.0),
                target,
            );
            pairs.push(PairSpec {
                a,
                b,
                pose_ab,
                threshold,
            });
        }
    }
    let truth = pairs
        .iter()
        .map(|p| Oracle::new(&meshes[p.a], &meshes[p.b], &p.pose_ab).by_grid(0.1))
        .collect();
    Some(Scene {
        name: "bunny, fandisk, torus".into(),
        meshes,
        pairs,
        truth,
    })
}

// ---------------------------------------------------------------------------------------
// The checks.

/// What the checks saw, to assert that every outcome occurred.
#[derive(Debug, Default)]
struct Tally {
    /// Interruption points checked.
    states: usize,
    /// Answers checked, by completeness.
    truncated: usize,
    exact: usize,
    /// Truncated answers that already hold a witness pair.
    truncated_with_upper: usize,
    /// Pairs by the oracle: intersecting, within threshold but apart, beyond threshold.
    touching: usize,
    near: usize,
    apart: usize,
    /// Fresh runs compared bit for bit with the resumed state.
    fresh_runs: usize,
}

impl Tally {
    fn assert_every_outcome(&self, what: &str) {
        assert!(self.truncated > 0, "{what}: no truncated answer: {self:?}");
        assert!(self.exact > 0, "{what}: no exact answer: {self:?}");
        assert!(self.truncated_with_upper > 0, "{what}: {self:?}");
        assert!(self.touching > 0, "{what}: no touching pair: {self:?}");
        assert!(self.near > 0, "{what}: no near pair: {self:?}");
        assert!(self.apart > 0, "{what}: no apart pair: {self:?}");
        assert!(self.fresh_runs > 0, "{what}: {self:?}");
    }
}

/// Bit-for-bit equality of answers (Debug prints every distinct f64 distinctly).
fn same_bits(x: &[FrontierAnswer], y: &[FrontierAnswer]) -> bool {
    format!("{x:?}") == format!("{y:?}")
}

/// The conservative contract of one answer against the oracle's distance `truth`.
fn check_conservative(answer: &FrontierAnswer, truth: f64, threshold: f64, at: &str) {
    let ctx = || format!("{at}: truth {truth:e}, threshold {threshold}, {answer:?}");
    if truth <= threshold {
        assert!(answer.maybe_close, "false negative: {}", ctx());
    }
    assert!(
        answer.distance_lower <= truth,
        "lower above truth: {}",
        ctx()
    );
    if let Some(upper) = answer.distance_upper {
        assert!(truth <= upper, "upper below truth: {}", ctx());
    }
    assert!(
        answer.error_bound.is_finite() && answer.error_bound >= 0.0,
        "{}",
        ctx()
    );
    assert!(
        (answer.distance() - truth).abs() <= answer.error_bound,
        "error bound: {}",
        ctx()
    );
    assert!(
        answer.clamped_error_bound() <= answer.error_bound,
        "{}",
        ctx()
    );
    if answer.is_exact() {
        assert_eq!(answer.maybe_close, truth <= threshold, "{}", ctx());
        if answer.maybe_close {
            assert_eq!(answer.distance_lower, truth, "{}", ctx());
            assert_eq!(answer.distance_upper, Some(truth), "{}", ctx());
            let w = answer
                .witnesses
                .expect("an exact close answer has witnesses");
            let d = w.point_a.distance(w.point_b);
            assert!((d - truth).abs() <= 1e-12 * (1.0 + truth), "{}", ctx());
        } else {
            assert!(answer.distance_lower > threshold, "{}", ctx());
        }
    } else {
        assert!(answer.maybe_close, "{}", ctx());
        assert!(answer.distance_lower <= threshold, "{}", ctx());
    }
}

/// More budget is never worse.
fn check_monotone(prev: &[FrontierAnswer], next: &[FrontierAnswer], at: &str) {
    for (i, (p, n)) in prev.iter().zip(next).enumerate() {
        let ctx = || format!("{at}, pair {i}: {p:?} then {n:?}");
        assert!(
            n.distance_lower >= p.distance_lower,
            "lower decreased: {}",
            ctx()
        );
        if p.is_exact() {
            assert!(
                same_bits(&[*p], &[*n]),
                "an exact answer changed: {}",
                ctx()
            );
        }
        if !p.maybe_close {
            assert!(!n.maybe_close, "{}", ctx());
        }
        if let Some(u) = p.distance_upper {
            assert!(n.distance_upper.is_some_and(|v| v <= u), "{}", ctx());
        }
        if let (Completeness::Truncated { level: a }, Completeness::Truncated { level: b }) =
            (p.completeness, n.completeness)
        {
            assert!(b >= a, "level went up the tree: {}", ctx());
        }
    }
}

/// How a scene is stepped through.
#[derive(Debug, Clone, Copy)]
struct Plan {
    /// Visits between budget polls.
    poll_every: u64,
    /// Budgets checked: every `step`-th from 0 to the unlimited visit count.
    step: u64,
    /// Budgets re-run from scratch (evenly spread).
    fresh: u64,
    build: BuildParams,
    /// Whether pairs start from a seed triangle pair (`FrontierPair::seed`): the exact
    /// closest pair for even pairs, an arbitrary one for odd pairs.
    seeded: bool,
    /// The frontier's order of processing.
    order: RoundOrder,
}

/// Runs every check of the module docs on `scene` with volume type `B`; returns the
/// unlimited run's visits and rounds.
/// One interruption point: every answer conservative against the oracle and, after the
/// first point, no worse than at the previous one (`prev`); counted into `tally`.
fn check_state(
    scene: &Scene,
    prev: &[FrontierAnswer],
    now: &[FrontierAnswer],
    at: &str,
    tally: &mut Tally,
) {
    tally.states += 1;
    for (i, ((answer, spec), &truth)) in now.iter().zip(&scene.pairs).zip(&scene.truth).enumerate()
    {
        check_conservative(answer, truth, spec.threshold, &format!("{at}, pair {i}"));
        if answer.is_exact() {
            tally.exact += 1;
        } else {
            tally.truncated += 1;
            tally.truncated_with_upper += usize::from(answer.distance_upper.is_some());
        }
    }
    if !prev.is_empty() {
        check_monotone(prev, now, at);
    }
}

fn check_scene<B: BoundingVolume>(scene: &Scene, plan: Plan, tally: &mut Tally) -> (u64, u64) {
    let label = format!(
        "{} / {} / poll {} / {:?}",
        scene.name,
        B::NAME,
        plan.poll_every,
        plan.order
    );
    let trees: Vec<Bvh<B>> = scene
        .meshes
        .iter()
        .map(|m| Bvh::from_mesh(m, &plan.build))
        .collect();
    let mut pairs: Vec<FrontierPair<'_, B>> = scene
        .pairs
        .iter()
        .map(|p| FrontierPair {
            a: &trees[p.a],
            b: &trees[p.b],
            pose_ab: p.pose_ab.to_isometry(),
            threshold: p.threshold,
            seed: None,
        })
        .collect();
    let label = if plan.seeded {
        let (mut ws, mut unseeded) = (FrontierWorkspace::new(), Vec::new());
        query_frontier(&pairs, &mut Unlimited, &mut ws, &mut unseeded);
        for (i, (pair, answer)) in pairs.iter_mut().zip(&unseeded).enumerate() {
            let (na, nb) = (
                pair.a.triangle_count() as u32,
                pair.b.triangle_count() as u32,
            );
            let arbitrary = [(i as u32 * 7_919) % na, (i as u32 * 104_729) % nb];
            pair.seed = match answer.witnesses {
                Some(w) if i % 2 == 0 => Some(w.triangles),
                _ => Some(arbitrary),
            };
        }
        format!("{label} / seeded")
    } else {
        label
    };
    for (&t, p) in scene.truth.iter().zip(&scene.pairs) {
        match t {
            0.0 => tally.touching += 1,
            t if t <= p.threshold => tally.near += 1,
            _ => tally.apart += 1,
        }
    }

    // Unlimited: the exact answers.
    let workspace = || FrontierWorkspace::with_poll_every(plan.poll_every).with_order(plan.order);
    let mut ws = workspace();
    let mut exact = Vec::new();
    assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut exact));
    let (total, rounds) = (ws.stats().visits, ws.stats().rounds);
    let mut mesh_ws = MeshMeshWorkspace::new();
    for (i, ((answer, spec), &truth)) in
        exact.iter().zip(&scene.pairs).zip(&scene.truth).enumerate()
    {
        let at = format!("{label}: unlimited, pair {i}");
        assert!(answer.is_exact(), "{at}");
        check_conservative(answer, truth, spec.threshold, &at);
        let (a, b) = (&trees[spec.a], &trees[spec.b]);
        let within = within_distance_mesh_mesh(a, b, &spec.pose_ab, spec.threshold, &mut mesh_ws);
        assert_eq!(answer.maybe_close, within, "{at}");
        if answer.maybe_close {
            let d = distance_mesh_mesh(
                a,
                b,
                &spec.pose_ab,
                &DistanceParams::EXACT,
                &mut DistanceCache::new(),
                &mut mesh_ws,
            );
            assert!(
                (answer.distance_lower - d.distance).abs() <= 1e-12 * d.distance,
                "{at}: {answer:?} vs {d:?}"
            );
            assert!((truth - d.distance).abs() <= 1e-12 * truth, "{at}");
        }
    }

    let states_before = tally.states;
    // Every interruption point, by resuming one traversal with a growing budget.
    let fresh_every = (total / plan.step / plan.fresh.max(1)).max(1);
    let mut resumed = workspace();
    resumed.start(&pairs);
    let (mut prev, mut now) = (Vec::new(), Vec::new());
    let mut last_visits = None;
    let (mut fresh_ws, mut fresh_out, mut again) = (workspace(), Vec::new(), Vec::new());
    let (mut budget, mut iteration) = (0, 0u64);
    loop {
        let finished = resumed.run(&pairs, &mut VisitBudget(budget));
        let visits = resumed.stats().visits;
        if last_visits != Some(visits) {
            last_visits = Some(visits);
            resumed.answers(&pairs, &mut now);
            let at = format!("{label}: budget {budget}, {visits} visits");
            check_state(scene, &prev, &now, &at, tally);
            std::mem::swap(&mut prev, &mut now);
        }
        if iteration % fresh_every == 0 || finished {
            // Same input and budget, from scratch, twice: the same answers, bit for bit.
            let f1 = query_frontier(
                &pairs,
                &mut VisitBudget(budget),
                &mut fresh_ws,
                &mut fresh_out,
            );
            assert_eq!(fresh_ws.stats().visits, visits, "{label}: budget {budget}");
            let f2 = query_frontier(&pairs, &mut VisitBudget(budget), &mut fresh_ws, &mut again);
            assert_eq!((f1, f2), (finished, finished));
            assert!(same_bits(&fresh_out, &prev), "{label}: budget {budget}");
            assert!(same_bits(&fresh_out, &again), "{label}: budget {budget}");
            tally.fresh_runs += 1;
        }
        if finished {
            break;
        }
        budget += plan.step;
        iteration += 1;
    }
    assert_eq!(resumed.stats().visits, total, "{label}");
    assert!(
        same_bits(&prev, &exact),
        "{label}: the end of the steps is the exact answer"
    );
    eprintln!(
        "{label}: {} pairs, unlimited {total} visits in {rounds} rounds (widest round {}), \
         {} states checked",
        pairs.len(),
        ws.entries_per_round().iter().max().unwrap(),
        tally.states - states_before
    );
    (total, rounds)
}

// ---------------------------------------------------------------------------------------
// Tests.

const PILE_SEEDS: [u64; 4] = [11, 12, 13, 14];

#[test]
fn tori_piles_have_about_ten_candidate_pairs_of_every_kind() {
    let (mut touching, mut near, mut apart, mut pairs) = (0, 0, 0, 0);
    for seed in PILE_SEEDS {
        let scene = tori_pile(seed);
        assert!(
            (7..=13).contains(&scene.pairs.len()),
            "{}: {}",
            scene.name,
            scene.pairs.len()
        );
        pairs += scene.pairs.len();
        for (&t, p) in scene.truth.iter().zip(&scene.pairs) {
            // The grid oracle agrees with the brute force.
            let grid =
                Oracle::new(&scene.meshes[p.a], &scene.meshes[p.b], &p.pose_ab).by_grid(0.05);
            assert_eq!(grid, t, "{}", scene.name);
            match t {
                0.0 => touching += 1,
                t if t <= p.threshold => near += 1,
                _ => apart += 1,
            }
        }
    }
    eprintln!("{pairs} pairs: {touching} touching, {near} near, {apart} apart");
    assert!(
        touching >= 3 && near >= 3 && apart >= 3,
        "{touching} {near} {apart}"
    );
}

#[test]
fn every_interruption_point_of_the_tori_piles_is_conservative_and_monotone() {
    let mut tally = Tally::default();
    for seed in PILE_SEEDS {
        let scene = tori_pile(seed);
        // Every visit a budget, the budget polled between every two entries.
        let fine = Plan {
            poll_every: 1,
            step: 1,
            fresh: 40,
            build: BuildParams::BINNED_SAH.with_leaf_size(4),
            seeded: false,
            order: RoundOrder::default(),
        };
        check_scene::<Obb>(&scene, fine, &mut tally);
        // Plain breadth-first rounds, without the default's stages.
        check_scene::<Obb>(
            &scene,
            Plan {
                order: RoundOrder::SmallestBound,
                ..fine
            },
            &mut tally,
        );
        // Warm-started from a seed triangle pair, as the pipeline runs it.
        check_scene::<Obb>(
            &scene,
            Plan {
                seeded: true,
                ..fine
            },
            &mut tally,
        );
        check_scene::<Rss>(
            &scene,
            Plan {
                build: BuildParams::MEDIAN,
                ..fine
            },
            &mut tally,
        );
        // The default batch, every budget.
        let batched = Plan {
            poll_every: 32,
            ..fine
        };
        check_scene::<Aabb>(&scene, batched, &mut tally);
        check_scene::<BoundingSphere>(
            &scene,
            Plan {
                build: BuildParams::AGGLOMERATIVE,
                ..batched
            },
            &mut tally,
        );
        check_scene::<Kdop18>(
            &scene,
            Plan {
                build: BuildParams::MEAN_VARIANCE.with_leaf_size(2),
                ..batched
            },
            &mut tally,
        );
    }
    eprintln!("{tally:?}");
    tally.assert_every_outcome("tori piles");
}

/// `pair` on the given trees of its meshes, as a pair of one volume type.
fn typed<'a, B>(a: &'a Bvh<B>, b: &'a Bvh<B>, pair: &MeshPairTrees) -> FrontierPair<'a, B> {
    FrontierPair {
        a,
        b,
        pose_ab: pair.pose_ab,
        threshold: pair.threshold,
        seed: pair.seed,
    }
}

/// The unlimited answer of one pair run alone.
fn alone<P: PairTrees>(pair: &P) -> FrontierAnswer {
    let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
    assert!(query_frontier(
        std::slice::from_ref(pair),
        &mut Unlimited,
        &mut ws,
        &mut out
    ));
    out[0]
}

#[test]
fn a_frontier_mixing_obb_rss_and_sphere_pairs_is_conservative_monotone_and_exact_per_pair() {
    let mut tally = Tally::default();
    for seed in PILE_SEEDS {
        let scene = tori_pile(seed);
        let meshes: Vec<Arc<MeshShape>> = scene
            .meshes
            .iter()
            .map(|m| Arc::new(MeshShape::new(m.clone()).with_sphere_tree(None)))
            .collect();
        // Rotate the volume type from pair to pair, whatever the meshes chose.
        let pairs: Vec<MeshPairTrees> = scene
            .pairs
            .iter()
            .enumerate()
            .map(|(i, p)| {
                MeshPairTrees::new(
                    &meshes[p.a],
                    &meshes[p.b],
                    p.pose_ab.to_isometry(),
                    p.threshold,
                    None,
                )
                .with_volume([QueryVolume::Obb, QueryVolume::Rss, QueryVolume::Sphere][i % 3])
            })
            .collect();
        // Every mesh kept a sphere tree, so no pair was moved off the type it was given.
        for (i, pair) in pairs.iter().enumerate() {
            let given = [QueryVolume::Obb, QueryVolume::Rss, QueryVolume::Sphere][i % 3];
            assert_eq!(pair.volume(), given, "seed {seed}, pair {i}");
        }
        for (&t, p) in scene.truth.iter().zip(&scene.pairs) {
            match t {
                0.0 => tally.touching += 1,
                t if t <= p.threshold => tally.near += 1,
                _ => tally.apart += 1,
            }
        }
        // Unlimited: every pair as exact as its own type's frontier run alone.
        let (mut ws, mut exact) = (FrontierWorkspace::new(), Vec::new());
        assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut exact));
        for (i, (pair, answer)) in pairs.iter().zip(&exact).enumerate() {
            let [a, b] = &pair.meshes;
            let own = match pair.volume() {
                QueryVolume::Obb => alone(&typed(&a.overlap_tree, &b.overlap_tree, pair)),
                QueryVolume::Rss => alone(&typed(&a.distance_tree, &b.distance_tree, pair)),
                QueryVolume::Sphere => {
                    let (ta, tb) = a.sphere_trees(b);
                    alone(&typed(ta, tb, pair))
                }
            };
            assert!(same_bits(&[*answer], &[own]), "seed {seed}, pair {i}");
        }
        // Every interruption point: conservative and monotone; sampled fresh runs equal.
        let mut resumed = FrontierWorkspace::with_poll_every(1);
        resumed.start(&pairs);
        let (mut prev, mut now, mut fresh) = (Vec::new(), Vec::new(), Vec::new());
        for budget in 0.. {
            let finished = resumed.run(&pairs, &mut VisitBudget(budget));
            resumed.answers(&pairs, &mut now);
            let at = format!("mixed tori pile {seed}: budget {budget}");
            check_state(&scene, &prev, &now, &at, &mut tally);
            if budget % 97 == 0 || finished {
                let mut fresh_ws = FrontierWorkspace::with_poll_every(1);
                query_frontier(&pairs, &mut VisitBudget(budget), &mut fresh_ws, &mut fresh);
                assert!(same_bits(&fresh, &now), "{at}");
                tally.fresh_runs += 1;
            }
            std::mem::swap(&mut prev, &mut now);
            if finished {
                assert!(
                    same_bits(&prev, &exact),
                    "{at}: the last state is the exact one"
                );
                break;
            }
        }
    }
    eprintln!("{tally:?}");
    tally.assert_every_outcome("mixed tori piles");
}

#[test]
fn every_interruption_point_of_degenerate_pairs_is_conservative_and_monotone() {
    let mut tally = Tally::default();
    for seed in [21, 22, 23] {
        let scene = degenerate_scene(seed);
        let plan = Plan {
            poll_every: 1,
            step: 1,
            fresh: 20,
            build: BuildParams::BINNED_SAH.with_leaf_size(2),
            seeded: false,
            order: RoundOrder::default(),
        };
        check_scene::<Obb>(&scene, plan, &mut tally);
        check_scene::<Obb>(
            &scene,
            Plan {
                seeded: true,
                ..plan
            },
            &mut tally,
        );
        check_scene::<Rss>(&scene, plan, &mut tally);
        check_scene::<Lss>(
            &scene,
            Plan {
                poll_every: 5,
                ..plan
            },
            &mut tally,
        );
        check_scene::<Aabb>(
            &scene,
            Plan {
                build: BuildParams::MEDIAN,
                ..plan
            },
            &mut tally,
        );
        check_scene::<Kdop18>(
            &scene,
            Plan {
                build: BuildParams::AGGLOMERATIVE,
                ..plan
            },
            &mut tally,
        );
    }
    eprintln!("{tally:?}");
    tally.assert_every_outcome("degenerate pairs");
}

#[test]
fn every_interruption_point_of_bunny_fandisk_and_a_torus_is_conservative_and_monotone() {
    let who = "every_interruption_point_of_bunny_fandisk_and_a_torus_is_conservative_and_monotone";
    let Some(scene) = bunny_fandisk(who) else {
        return;
    };
    let mut tally = Tally::default();
    for (i, &t) in scene.truth.iter().enumerate() {
        eprintln!(
            "{}: pair {i} {:?}, true distance {t:e}",
            scene.name,
            (scene.pairs[i].a, scene.pairs[i].b)
        );
    }
    let build = BuildParams::BINNED_SAH.with_leaf_size(4);
    // Every budget; polled after every entry, and at the default batch.
    let plan = Plan {
        poll_every: 1,
        step: 1,
        fresh: 12,
        build,
        seeded: true,
        order: RoundOrder::default(),
    };
    check_scene::<Rss>(&scene, plan, &mut tally);
    check_scene::<Obb>(
        &scene,
        Plan {
            poll_every: 32,
            ..plan
        },
        &mut tally,
    );
    eprintln!("{tally:?}");
    tally.assert_every_outcome("bunny, fandisk, torus");
}
