//! The budgeted frontier's cost per visit, on the meshes of `examples/time_vs_error --scene
//! robot-chain`: FCL's environment (2,180 triangles, scaled to 6 m) and six copies of its
//! robot link (216 triangles, 1.2 m) placed at random in the room, 21 mesh pairs a frame
//! with 2 cm margins each (4 cm thresholds).
//!
//! 64 frames of link poses from a fixed seed, built before timing with the OBB trees
//! the pipeline uses ([`MESH_TREE_PARAMS`]). Each iteration answers the next frame with a fresh frontier
//! ([`query_frontier`]): `visits-250` under a counted budget of 250 visits (the work a
//! quarter of an exact frame affords on the 2-core VM), `exact` without limit. The setup
//! prints the mean visits per frame, so time per visit is the mean time divided by it.
//! Counted budgets make the work the same in every run: only the cost of a visit (a
//! volume bound, a triangle test, the frontier's bookkeeping) changes the figure.
//!
//! `cargo bench --bench frontier`; names are `frontier/<budget>/robot-chain`.

#[path = "../tests/support/mod.rs"]
mod support;

// Shared with the mesh-pair bench, which uses the scenes this one does not.
#[allow(dead_code)]
mod common;

use common::cycle::cycle_bench;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use proxima::bounding::Obb;
use proxima::budget::VisitBudget;
use proxima::bvh::Bvh;
use proxima::geometry::TriMesh;
use proxima::math::{DVec3, Pose};
use proxima::narrow::MESH_TREE_PARAMS;
use proxima::narrow::mesh_mesh::frontier::{FrontierPair, FrontierWorkspace, query_frontier};

/// Links per frame.
const LINKS: usize = 6;
/// Frames of poses the iterations go round.
const FRAMES: usize = 64;
/// Each pair's threshold: two 2 cm margins, metres.
const THRESHOLD: f64 = 0.04;

/// The two trees and the frames' poses: body 0 is the environment at the identity, bodies
/// 1..=6 the links.
struct RobotChain {
    env: Bvh<Obb>,
    link: Bvh<Obb>,
    frames: Vec<[Pose; LINKS + 1]>,
}

/// `None`, after a line saying so, without the data folder (`PROXIMA_DATA`).
fn robot_chain() -> Option<RobotChain> {
    let data = support::data::data_dir_or_skip("frontier/robot-chain")?;
    let load = |name: &str| {
        let path = data.join("meshes").join(name);
        TriMesh::load(&path)
            .unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
            .scaled(0.001)
            .centered_on_bounds()
    };
    let params = MESH_TREE_PARAMS;
    let (env, link) = (
        Bvh::from_mesh(&load("env.obj"), &params),
        Bvh::from_mesh(&load("rob.obj"), &params),
    );
    let mut rng = support::rng(7);
    let frames = (0..FRAMES)
        .map(|_| {
            std::array::from_fn(|body| {
                if body == 0 {
                    return Pose::IDENTITY;
                }
                // The movers' region of the example's scene: around (−1.5, 0, 0.2) m.
                let centre = DVec3::new(-1.5, 0.0, 0.2)
                    + support::point_in_cube(&mut rng, 1.0) * DVec3::new(1.2, 1.0, 0.4);
                Pose::new(centre, support::rotation(&mut rng))
            })
        })
        .collect();
    Some(RobotChain { env, link, frames })
}

impl RobotChain {
    /// Every pair of one frame's bodies, as the frontier takes them.
    fn pairs(&self, frame: &[Pose; LINKS + 1]) -> Vec<FrontierPair<'_, Obb>> {
        let tree = |body: usize| if body == 0 { &self.env } else { &self.link };
        let mut pairs = Vec::new();
        for a in 0..=LINKS {
            for b in a + 1..=LINKS {
                pairs.push(FrontierPair {
                    a: tree(a),
                    b: tree(b),
                    pose_ab: Pose::relative(&frame[a], &frame[b]).to_isometry(),
                    threshold: THRESHOLD,
                    seed: None,
                });
            }
        }
        pairs
    }
}

fn frontier(c: &mut Criterion) {
    let Some(scene) = robot_chain() else {
        return;
    };
    let frames: Vec<_> = scene.frames.iter().map(|f| scene.pairs(f)).collect();
    let mut group = c.benchmark_group("frontier");
    // A counted budget of `u64::MAX` never refuses: the exact answers.
    for (name, visits) in [("visits-250", 250), ("exact", u64::MAX)] {
        let (mut workspace, mut answers) = (FrontierWorkspace::new(), Vec::new());
        let mut made = 0;
        for pairs in &frames {
            query_frontier(
                pairs,
                &mut VisitBudget(visits),
                &mut workspace,
                &mut answers,
            );
            made += workspace.stats().visits;
        }
        println!(
            "frontier/{name}: {:.1} visits a frame on average",
            made as f64 / FRAMES as f64
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new(name, "robot-chain"),
            &frames,
            |_, pairs| {
                query_frontier(
                    pairs,
                    &mut VisitBudget(visits),
                    &mut workspace,
                    &mut answers,
                );
                workspace.stats().visits as f64
            },
        );
    }
    group.finish();
}

criterion_group!(benches, frontier);
criterion_main!(benches);
