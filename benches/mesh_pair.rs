//! Mesh–mesh queries, Proxima against parry3d-f64 0.31, on the same meshes and the same
//! relative poses: mean time per query.
//!
//! # Scenes
//! - `bunny-fandisk`: FCL's protocol, the Stanford bunny (×10, 69,451 triangles) against
//!   fandisk (×0.3, 12,946 triangles) under the 200 transforms of
//!   `poses/bunny_fandisk.txt` in the data folder, `PROXIMA_DATA` (see [`common::mesh_scenes::bunny_fandisk`]).
//! - `tori`: two tori of 10,000 triangles each under 64 random poses from a fixed seed,
//!   exactly half of them intersecting (see [`common::mesh_scenes::tori`]).
//!
//! Everything is built before timing: Proxima's BVHs with [`MESH_TREE_PARAMS`], as the
//! daemon builds them (binned SAH, up to two triangles a leaf), parry's `TriMesh` shapes
//! from the very same `f64` vertices and index triples, and the poses (parry gets the same quaternion and translation, as
//! `pos1 = identity`, `pos2 = pose_ab`, so its `pos12` is Proxima's `pose_ab`). Each timed
//! iteration takes the next pose in order ([`common::cycle::cycle_bench`]).
//!
//! # What is compared
//! | query | Proxima (`proxima-obb`, `proxima-rss`, and `proxima-aabb` for `collide_bool`) | parry (`parry`) |
//! |---|---|---|
//! | `collide_bool` | [`intersects_mesh_mesh`]: tandem traversal of both BVHs, exact triangle–triangle test (robust predicates), stops at the first intersecting pair | `query::intersection_test`: walks A's AABB tree against B's root AABB, then for each surviving triangle of A walks B's AABB tree, deciding triangle pairs by GJK (with its tolerance); stops at the first hit |
//! | `contacts` | [`contacts_mesh_mesh`]: every intersecting triangle pair with its intersection segment, contact point and normal; the sink counts them | `DefaultQueryDispatcher::contact_manifolds` with prediction 0 (the persistent contact-manifold generator Rapier uses): one manifold per triangle pair whose AABBs overlap, filled by GJK/EPA (points, normal, depth); we count the manifolds that got points. One workspace and manifold vector are reused across iterations, as a simulation would, but consecutive poses are unrelated, so its contact reuse never applies |
//! | `distance` | [`distance_mesh_mesh`] with [`DistanceParams::EXACT`] and a fresh [`DistanceCache`] per query (cold): branch and bound over both trees, exact minimum triangle–triangle distance, 0 on intersection | `query::distance`: best-first over A's AABB tree (bound: AABB against B's whole AABB), each triangle of A against B's tree, triangle pairs by GJK distance; 0 on intersection |
//! | `distance_warm` | the same with one [`DistanceCache`] per pose, kept across laps: each query starts from the closest pair this same pose had last time (the best case of frame-to-frame coherence) | — (parry has no warm start for this query) |
//!
//! Both engines treat meshes as surfaces (a mesh inside a closed mesh does not intersect it)
//! and report 0 for intersecting meshes. Proxima reuses one [`MeshMeshWorkspace`] per bench.
//!
//! Before timing, each scene is checked once: Proxima's and parry's booleans on every pose
//! (the disagreement count is printed; more than 5% would mean the inputs differ, and
//! panics), their distances (largest difference printed) and their contact counts (totals
//! printed; parry's count may differ at touching pairs, since GJK decides them with a
//! tolerance).
//!
//! A mean covers every pose only when the run makes at least one lap of the poses (criterion
//! prints the iteration count): query cost varies a lot from pose to pose (hit or miss, deep
//! or grazing), so a run of fewer iterations than poses averages over the first poses only.
//! parry's `distance` takes about 0.5 s per query on `bunny-fandisk`, so one lap there needs
//! `--measurement-time` of about 120 s.
//!
//! `cargo bench --bench mesh_pair`; names are `mesh_pair/<query>/<engine>/<scene>`.

#[path = "../tests/support/mod.rs"]
mod support;

mod common;

#[path = "common/parry_convert.rs"]
mod parry_convert;

use common::cycle::cycle_bench;
use common::mesh_scenes::{MeshScene, bunny_fandisk, tori};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main};
use parry_convert::{parry_mesh, parry_pose};
use parry3d_f64::math::Pose as ParryPose;
use parry3d_f64::query::{
    ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use parry3d_f64::shape::TriMesh as ParryMesh;
use proxima::bounding::{Aabb, BoundingVolume, Obb, Rss};
use proxima::bvh::Bvh;
use proxima::geometry::TriMesh;
use proxima::math::Pose;
use proxima::narrow::MESH_TREE_PARAMS;
use proxima::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshMeshWorkspace, contacts_mesh_mesh, distance_mesh_mesh,
    intersects_mesh_mesh,
};
use std::hint::black_box;
use std::ops::ControlFlow;

const SEED: u64 = 0x5EED_3E54;
const TORI_POSES: usize = 64;

/// Proxima's two BVHs of a scene, of one volume type.
struct ProximaPair<B> {
    a: Bvh<B>,
    b: Bvh<B>,
}

impl<B: BoundingVolume> ProximaPair<B> {
    fn new(a: &TriMesh, b: &TriMesh) -> Self {
        Self {
            a: Bvh::from_mesh(a, &MESH_TREE_PARAMS),
            b: Bvh::from_mesh(b, &MESH_TREE_PARAMS),
        }
    }

    fn engine(&self) -> String {
        format!("proxima-{}", B::NAME)
    }

    fn intersects(&self, pose_ab: &Pose, workspace: &mut MeshMeshWorkspace) -> bool {
        intersects_mesh_mesh(black_box(&self.a), black_box(&self.b), pose_ab, workspace)
    }

    fn contact_count(&self, pose_ab: &Pose, workspace: &mut MeshMeshWorkspace) -> usize {
        let mut count = 0;
        contacts_mesh_mesh(
            black_box(&self.a),
            black_box(&self.b),
            pose_ab,
            workspace,
            |contact| {
                black_box(contact);
                count += 1;
                ControlFlow::Continue(())
            },
        );
        count
    }

    fn distance(
        &self,
        pose_ab: &Pose,
        cache: &mut DistanceCache,
        workspace: &mut MeshMeshWorkspace,
    ) -> f64 {
        distance_mesh_mesh(
            black_box(&self.a),
            black_box(&self.b),
            pose_ab,
            &DistanceParams::EXACT,
            cache,
            workspace,
        )
        .distance
    }
}

/// parry's two meshes of a scene and the scene's poses in parry's types.
struct ParryPair {
    a: ParryMesh,
    b: ParryMesh,
    poses_ab: Vec<ParryPose>,
}

impl ParryPair {
    const ENGINE: &str = "parry";

    fn new(scene: &MeshScene) -> Self {
        Self {
            a: parry_mesh(&scene.a),
            b: parry_mesh(&scene.b),
            poses_ab: scene.poses_ab.iter().map(parry_pose).collect(),
        }
    }

    fn intersects(&self, pose_ab: &ParryPose) -> bool {
        parry3d_f64::query::intersection_test(
            &ParryPose::IDENTITY,
            black_box(&self.a),
            pose_ab,
            black_box(&self.b),
        )
        .expect("parry supports trimesh–trimesh intersection tests")
        .intersecting
    }

    fn contact_count(
        &self,
        pose_ab: &ParryPose,
        manifolds: &mut Vec<ContactManifold<(), ()>>,
        workspace: &mut Option<ContactManifoldsWorkspace>,
    ) -> usize {
        DefaultQueryDispatcher
            .contact_manifolds(
                pose_ab,
                black_box(&self.a),
                black_box(&self.b),
                0.0,
                manifolds,
                workspace,
            )
            .expect("parry supports trimesh–trimesh contact manifolds");
        manifolds.iter().filter(|m| !m.points.is_empty()).count()
    }

    fn distance(&self, pose_ab: &ParryPose) -> f64 {
        parry3d_f64::query::distance(
            &ParryPose::IDENTITY,
            black_box(&self.a),
            pose_ab,
            black_box(&self.b),
        )
        .expect("parry supports trimesh–trimesh distance")
        .distance
    }
}

/// One scene with every engine's structures built.
struct Engines {
    scene: MeshScene,
    obb: ProximaPair<Obb>,
    rss: ProximaPair<Rss>,
    aabb: ProximaPair<Aabb>,
    parry: ParryPair,
}

impl Engines {
    fn new(scene: MeshScene) -> Self {
        let engines = Self {
            obb: ProximaPair::new(&scene.a, &scene.b),
            rss: ProximaPair::new(&scene.a, &scene.b),
            aabb: ProximaPair::new(&scene.a, &scene.b),
            parry: ParryPair::new(&scene),
            scene,
        };
        engines.check_agreement();
        engines
    }

    /// Compares Proxima (OBB trees) with parry on every pose, untimed, and prints the result.
    ///
    /// # Panics
    /// When more than 5% of the booleans disagree: that is a conversion bug, not a tie.
    fn check_agreement(&self) {
        let (proxima, parry, scene) = (&self.obb, &self.parry, &self.scene);
        let mut workspace = MeshMeshWorkspace::new();
        let (mut manifolds, mut parry_workspace) = (Vec::new(), None);
        let (mut disagreements, mut hits) = (0, 0);
        let (mut proxima_contacts, mut parry_contacts) = (0, 0);
        let mut largest_distance_gap: f64 = 0.0;
        for (i, (pose, parry_pose)) in scene.poses_ab.iter().zip(&parry.poses_ab).enumerate() {
            let hit = proxima.intersects(pose, &mut workspace);
            let parry_hit = parry.intersects(parry_pose);
            let distance = proxima.distance(pose, &mut DistanceCache::new(), &mut workspace);
            let parry_distance = parry.distance(parry_pose);
            hits += usize::from(hit);
            if hit != parry_hit {
                disagreements += 1;
                eprintln!(
                    "{}: pose {i}: proxima says {hit} (distance {distance:e}), parry says \
                     {parry_hit} (distance {parry_distance:e})",
                    scene.name
                );
            }
            largest_distance_gap = largest_distance_gap.max((distance - parry_distance).abs());
            proxima_contacts += proxima.contact_count(pose, &mut workspace);
            parry_contacts += parry.contact_count(parry_pose, &mut manifolds, &mut parry_workspace);
        }
        let n = scene.poses_ab.len();
        eprintln!(
            "{}: {} × {} triangles, {hits} of {n} poses intersect; boolean disagreements with \
             parry: {disagreements}; largest |distance − parry distance|: \
             {largest_distance_gap:e} m; intersecting triangle pairs over all poses: proxima \
             {proxima_contacts}, parry {parry_contacts}",
            scene.name,
            scene.a.triangle_count(),
            scene.b.triangle_count(),
        );
        assert!(
            disagreements * 20 <= n,
            "{}: {disagreements} of {n} booleans disagree with parry: the inputs differ",
            scene.name
        );
    }
}

fn bench_collide_bool(group: &mut BenchmarkGroup<'_, WallTime>, engines: &Engines) {
    fn proxima<B: BoundingVolume>(
        group: &mut BenchmarkGroup<'_, WallTime>,
        scene: &MeshScene,
        pair: &ProximaPair<B>,
    ) {
        let mut workspace = MeshMeshWorkspace::new();
        let id = BenchmarkId::new(pair.engine(), scene.name);
        cycle_bench(group, id, &scene.poses_ab, |_, pose| {
            f64::from(u8::from(pair.intersects(pose, &mut workspace)))
        });
    }
    let Engines {
        scene,
        obb,
        rss,
        aabb,
        parry,
    } = engines;
    proxima(group, scene, obb);
    proxima(group, scene, rss);
    proxima(group, scene, aabb);
    let id = BenchmarkId::new(ParryPair::ENGINE, scene.name);
    cycle_bench(group, id, &parry.poses_ab, |_, pose| {
        f64::from(u8::from(parry.intersects(pose)))
    });
}

fn bench_contacts(group: &mut BenchmarkGroup<'_, WallTime>, engines: &Engines) {
    fn proxima<B: BoundingVolume>(
        group: &mut BenchmarkGroup<'_, WallTime>,
        scene: &MeshScene,
        pair: &ProximaPair<B>,
    ) {
        let mut workspace = MeshMeshWorkspace::new();
        let id = BenchmarkId::new(pair.engine(), scene.name);
        cycle_bench(group, id, &scene.poses_ab, |_, pose| {
            pair.contact_count(pose, &mut workspace) as f64
        });
    }
    let Engines {
        scene,
        obb,
        rss,
        parry,
        ..
    } = engines;
    proxima(group, scene, obb);
    proxima(group, scene, rss);
    let (mut manifolds, mut workspace) = (Vec::new(), None);
    let id = BenchmarkId::new(ParryPair::ENGINE, scene.name);
    cycle_bench(group, id, &parry.poses_ab, |_, pose| {
        parry.contact_count(pose, &mut manifolds, &mut workspace) as f64
    });
}

fn bench_distance(group: &mut BenchmarkGroup<'_, WallTime>, engines: &Engines) {
    fn proxima<B: BoundingVolume>(
        group: &mut BenchmarkGroup<'_, WallTime>,
        scene: &MeshScene,
        pair: &ProximaPair<B>,
    ) {
        let mut workspace = MeshMeshWorkspace::new();
        let id = BenchmarkId::new(pair.engine(), scene.name);
        cycle_bench(group, id, &scene.poses_ab, |_, pose| {
            pair.distance(pose, &mut DistanceCache::new(), &mut workspace)
        });
    }
    let Engines {
        scene,
        obb,
        rss,
        parry,
        ..
    } = engines;
    proxima(group, scene, obb);
    proxima(group, scene, rss);
    let id = BenchmarkId::new(ParryPair::ENGINE, scene.name);
    cycle_bench(group, id, &parry.poses_ab, |_, pose| parry.distance(pose));
}

fn bench_distance_warm(group: &mut BenchmarkGroup<'_, WallTime>, engines: &Engines) {
    fn proxima<B: BoundingVolume>(
        group: &mut BenchmarkGroup<'_, WallTime>,
        scene: &MeshScene,
        pair: &ProximaPair<B>,
    ) {
        let mut workspace = MeshMeshWorkspace::new();
        let mut caches = vec![DistanceCache::new(); scene.poses_ab.len()];
        let id = BenchmarkId::new(pair.engine(), scene.name);
        cycle_bench(group, id, &scene.poses_ab, |i, pose| {
            pair.distance(pose, &mut caches[i], &mut workspace)
        });
    }
    proxima(group, &engines.scene, &engines.obb);
    proxima(group, &engines.scene, &engines.rss);
}

/// Adds one query's benches, for every engine that has it, to the query's group.
type QueryBench = fn(&mut BenchmarkGroup<'_, WallTime>, &Engines);

/// The tori scene's poses are sorted into hits and misses by Proxima's exact answer.
fn exact_classifier(a: &TriMesh, b: &TriMesh) -> impl FnMut(&Pose) -> bool + use<> {
    let pair = ProximaPair::<Obb>::new(a, b);
    let mut workspace = MeshMeshWorkspace::new();
    move |pose_ab| pair.intersects(pose_ab, &mut workspace)
}

fn mesh_pair(c: &mut Criterion) {
    let all: Vec<Engines> = bunny_fandisk()
        .into_iter()
        .chain([tori(SEED, TORI_POSES, exact_classifier)])
        .map(Engines::new)
        .collect();
    let queries: [(&str, QueryBench); 4] = [
        ("collide_bool", bench_collide_bool),
        ("contacts", bench_contacts),
        ("distance", bench_distance),
        ("distance_warm", bench_distance_warm),
    ];
    for (query, bench) in queries {
        let mut group = c.benchmark_group(format!("mesh_pair/{query}"));
        for engines in &all {
            bench(&mut group, engines);
        }
        group.finish();
    }
}

criterion_group!(benches, mesh_pair);
criterion_main!(benches);
