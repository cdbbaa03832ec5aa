//! The budgeted frontier's side of a frame ([`step_within`](super::step_within) with a
//! limited budget): which mesh pairs it refines, with which seeds, and resuming last
//! frame's run while the bodies rest.

use super::pair_memory::PairMemories;
use super::{Budget, PipelineWorkspace, Query, body, elapsed_ns, mesh_pair};
use crate::broad::CandidatePair;
use crate::math::Pose;
use crate::narrow::MeshShape;
use crate::narrow::distance_triangle_triangle;
use crate::narrow::mesh_mesh::frontier::FrontierStats;
use crate::narrow::mesh_mesh::frontier::MeshPairTrees;
use crate::scene::Scene;
use std::time::Instant;

/// Answers the frame's mesh–mesh candidates that no kept answer covers through the
/// frontier, under `budget` (see [`step_within`]): resumes last frame's frontier when it
/// can ([`FrontierRun::resumes`]), else runs a fresh one over those pairs in candidate
/// order, its budget already spent by `spent` visits (the frame's hull tests). Leaves the
/// frontier's pairs in `workspace.frontier_pairs` and their answers in
/// `workspace.frontier_answers` (a superset of the pairs asked when resuming, in candidate
/// order); returns this frame's share of the frontier's counters.
pub(super) fn run_frontier(
    scene: &Scene,
    query: Query,
    budget: &mut dyn Budget,
    spent: u64,
    workspace: &mut PipelineWorkspace,
) -> FrontierStats {
    let PipelineWorkspace {
        candidates,
        memory,
        separated,
        frontier,
        frontier_answers,
        frontier_pairs,
        frontier_run,
        costs,
        ..
    } = workspace;
    // The mesh pairs no kept answer or separation answers, in candidate order.
    let needed = || {
        candidates
            .iter()
            .zip(separated.iter())
            .filter(|&(pair, &apart)| {
                !apart
                    && mesh_pair(scene, pair).is_some()
                    && memory.kept_answer(scene, pair, query).is_none()
            })
            .map(|(pair, _)| pair)
    };
    if !scene.has_mesh_shapes() || needed().next().is_none() {
        // Nothing to answer: no run (and nothing left to resume later).
        frontier_pairs.clear();
        frontier_answers.clear();
        frontier_run.trees.clear();
        return FrontierStats::default();
    }
    let resume = frontier_run.resumes(scene, query, frontier_pairs, candidates)
        && needed().all(|pair| frontier_pairs.binary_search(pair).is_ok());
    if !resume {
        frontier_pairs.clear();
        frontier_pairs.extend(needed());
        frontier_run.list(scene, query, frontier_pairs, memory);
    }
    // A resumed frontier's pairs are the same (unchanged bodies, so the same poses).
    let pairs = &frontier_run.trees;
    let before = if resume {
        *frontier.stats()
    } else {
        frontier.start(pairs);
        FrontierStats::default()
    };
    frontier.run(
        pairs,
        &mut Resumed {
            inner: budget,
            base: before.visits,
            spent,
        },
    );
    // Read every waiting entry, unpolled: the budget reserved its time per entry.
    let waiting = frontier.waiting();
    let answers_started = Instant::now();
    frontier.answers(pairs, frontier_answers);
    costs.note_answer_pass(elapsed_ns(answers_started), waiting);
    // A pair's seed is a proof of closeness (a triangle pair within its threshold), kept
    // while the pair may be close: the next frame tests it first and, while it holds or
    // until the undecided pairs are settled, spends nothing more on the pair.
    for (pair, answer) in frontier_pairs.iter().zip(frontier_answers.iter()) {
        match answer.witnesses {
            Some(w) if answer.distance_upper.is_some_and(|d| d <= answer.threshold) => {
                memory.entry(pair).seed = Some(w.triangles);
            }
            _ if !answer.maybe_close => {
                if let Some(record) = memory.get_mut(pair) {
                    record.seed = None;
                }
            }
            _ => {}
        }
    }
    let after = *frontier.stats();
    FrontierStats {
        visits: after.visits - before.visits,
        bv_tests: after.bv_tests - before.bv_tests,
        triangle_tests: after.triangle_tests - before.triangle_tests,
        rounds: after.rounds - before.rounds,
        polls: after.polls - before.polls,
    }
}

/// What last frame's frontier ran over, to resume it.
#[derive(Debug, Default)]
pub(super) struct FrontierRun {
    /// [`Scene::uid`] of its scene.
    scene: u64,
    query: Query,
    /// Both bodies' versions, per pair of `PipelineWorkspace::frontier_pairs`.
    versions: Vec<[u64; 2]>,
    /// Each pair as the frontier refines it (trees, pose, threshold, seed).
    trees: Vec<MeshPairTrees>,
}

impl FrontierRun {
    /// Lists `pairs` (mesh pairs of `scene`, candidate order) for a fresh run under `query`:
    /// each with its trees, pose, threshold (the margins, or under `DISTANCE` an upper bound
    /// of its distance) and seed, and both bodies' versions.
    fn list(
        &mut self,
        scene: &Scene,
        query: Query,
        pairs: &[CandidatePair],
        memory: &PairMemories,
    ) {
        self.scene = scene.uid();
        self.query = query;
        self.versions.clear();
        self.trees.clear();
        for pair in pairs {
            let (a, b) = (body(scene, pair.a), body(scene, pair.b));
            let (ma, mb) = mesh_pair(scene, pair).expect("a mesh pair");
            let pose_ab = Pose::relative(&a.pose, &b.pose).to_isometry();
            // Last frame's closest triangles: the warm start the exact queries have.
            let seed = memory.get(pair).and_then(|m| m.seed);
            let threshold = if query.distance {
                distance_upper_bound(ma, mb, &pose_ab, seed.unwrap_or([0, 0]))
            } else {
                a.margin + b.margin
            };
            self.versions.push([a.version(), b.version()]);
            self.trees
                .push(MeshPairTrees::new(ma, mb, pose_ab, threshold, seed));
        }
    }

    /// Whether the last frontier (over `pairs`) can go on this frame: same scene and query,
    /// every pair still a candidate with both bodies unchanged (so the same poses), and
    /// work left. A resumed frontier reaches the state a single run with the summed
    /// budgets would (as [`FrontierWorkspace::run`] documents), so a pair left truncated
    /// by a budget too small for it is refined frame after frame while its bodies rest.
    fn resumes(
        &self,
        scene: &Scene,
        query: Query,
        pairs: &[CandidatePair],
        candidates: &[CandidatePair],
    ) -> bool {
        !pairs.is_empty()
            && self.scene == scene.uid()
            && self.query == query
            && pairs.iter().zip(&self.versions).all(|(pair, versions)| {
                candidates.binary_search(pair).is_ok()
                    && *versions == [body(scene, pair.a).version(), body(scene, pair.b).version()]
            })
    }
}

/// A budget asked about the visits since `base` (a resumed frontier counts from its start)
/// plus the `spent` ones the frame made before the frontier (its hull tests).
struct Resumed<'b> {
    inner: &'b mut dyn Budget,
    base: u64,
    spent: u64,
}

impl Budget for Resumed<'_> {
    fn allows(&mut self, visits: u64) -> bool {
        self.inner.allows(visits - self.base + self.spent)
    }

    fn allows_pending(&mut self, visits: u64, pending: u64) -> bool {
        self.inner
            .allows_pending(visits - self.base + self.spent, pending)
    }
}

/// An upper bound of the distance between two meshes (B at `pose_ab` in A's frame): the
/// distance of the triangle pair `seed` (ids; the first triangles when out of range), padded
/// far above its rounding. The frontier's threshold under `DISTANCE`: nothing farther than
/// it can hold the minimum, so the frontier prunes from its first round (with `+∞` it would
/// descend every node pair down to the leaves before finding any distance). `+∞` for an
/// empty mesh. One triangle test per pair, outside the budget.
fn distance_upper_bound(
    ma: &MeshShape,
    mb: &MeshShape,
    pose_ab: &crate::math::Isometry,
    seed: [u32; 2],
) -> f64 {
    let (na, nb) = (ma.mesh.triangle_count(), mb.mesh.triangle_count());
    if na == 0 || nb == 0 {
        return f64::INFINITY;
    }
    let pick = |id: u32, n: usize| if (id as usize) < n { id as usize } else { 0 };
    let (ta, tb) = (
        ma.mesh.triangle(pick(seed[0], na)),
        mb.mesh.triangle(pick(seed[1], nb)).transformed(pose_ab),
    );
    let d = distance_triangle_triangle(&ta, &tb).distance.max(0.0);
    d * (1.0 + 1e-9) + 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow::mesh_mesh::{
        DistanceCache, DistanceParams, MeshMeshWorkspace, distance_mesh_mesh,
    };
    use crate::test_support::{meshes, point_in_cube, rng, rotation};
    use rand::Rng;

    #[test]
    fn the_distance_seed_is_an_upper_bound_of_the_mesh_distance() {
        let torus = MeshShape::new(meshes::torus(0.4, 0.12, 16, 8));
        let mut rng = rng(61);
        let mut below = 0;
        for case in 0..300 {
            let pose = Pose::new(point_in_cube(&mut rng, 1.5), rotation(&mut rng));
            let seed = [rng.random_range(0..300), rng.random_range(0..300)];
            let bound = distance_upper_bound(&torus, &torus, &pose.to_isometry(), seed);
            let exact = distance_mesh_mesh(
                &torus.distance_tree,
                &torus.distance_tree,
                &pose,
                &DistanceParams::EXACT,
                &mut DistanceCache::new(),
                &mut MeshMeshWorkspace::new(),
            );
            assert!(
                exact.distance <= bound,
                "case {case}: {} > {bound}",
                exact.distance
            );
            below += usize::from(exact.distance < bound);
        }
        assert!(
            below > 250,
            "the seed is a bound, rarely the minimum: {below}"
        );
    }
}
