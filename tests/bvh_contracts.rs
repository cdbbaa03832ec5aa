//! The `Bvh` contract, checked for every build preset, leaf sizes 1 and 4 and every volume
//! type a mesh is bounded with (AABB, OBB, sphere, 18-DOP, LSS, RSS), over procedural
//! meshes that include the degenerate cases (one triangle, identical triangles, zero-area
//! triangles, a flat grid of coplanar triangles, coordinates 1e5 from the origin, scales
//! 1e-3 and 1e3) and over the shared real meshes:
//!
//! - `validate()` holds after every build;
//! - the slot map is a permutation and every slot holds the input triangle it names;
//! - median trees have exactly the least depth any tree with those leaves can have,
//!   `⌈log₂⌈n / leaf_size⌉⌉`, and no tree is shallower;
//! - building is deterministic.
//!
//! Refit contracts (validity after motion in both modes, `Fit` on unmoved triangles
//! reproducing the build) and corrupted trees being caught by `validate()` are unit tests
//! in `src/bvh/build/bottom_up.rs`: `RefitMode` cannot be named from outside the crate, and
//! a tree cannot be corrupted through the public API.

mod support;

use proxima::bounding::{Aabb, BoundingSphere, BoundingVolume, Kdop18, Lss, Obb, Rss};
use proxima::bvh::{BuildParams, BuildStrategy, Bvh};
use proxima::geometry::{TriMesh, Triangle};
use proxima::math::DVec3;
use rand::Rng;
use support::meshes::{self, grid, torus, triangle_soup, uv_sphere, zero_area_triangles};
use support::{CENTERS, SCALES, rng};

/// Every preset; each is built with leaf sizes 1 and 4.
const PRESETS: [BuildParams; 6] = [
    BuildParams::MEDIAN,
    BuildParams::MEAN_VARIANCE,
    BuildParams::BINNED_SAH,
    BuildParams::AGGLOMERATIVE,
    BuildParams::OCTREE,
    BuildParams::MEDIAL_AXIS,
];

/// Leaf sizes every preset is built with.
const LEAF_SIZES: [u32; 2] = [1, 4];

/// Runs `$check::<B>($args)` for every volume type.
macro_rules! for_each_volume {
    ($check:ident($($arg:expr),*)) => {
        $check::<Aabb>($($arg),*);
        $check::<Obb>($($arg),*);
        $check::<BoundingSphere>($($arg),*);
        $check::<Kdop18>($($arg),*);
        $check::<Lss>($($arg),*);
        $check::<Rss>($($arg),*);
    };
}

/// The procedural meshes, named for failure messages.
fn named_meshes() -> Vec<(&'static str, Vec<Triangle>)> {
    let mut rng = rng(401);
    let p = DVec3::new(0.3, -0.2, 0.7);
    let one = Triangle::new(p, p + DVec3::X, p + DVec3::new(0.2, 0.9, 0.1));
    let sphere = uv_sphere(1.0, 12, 8);
    let ring = torus(2.0, 0.5, 16, 6);
    let soup = triangle_soup(&mut rng, 150, 1.0, 0.3);
    let far = DVec3::new(1e5, -1e5, 1e5);
    vec![
        ("single triangle", vec![one]),
        ("identical triangles", vec![one; 40]),
        (
            "zero-area triangles",
            meshes::triangles(&zero_area_triangles(&mut rng, 90, 1.0)),
        ),
        ("uv sphere", meshes::triangles(&sphere)),
        ("torus", meshes::triangles(&ring)),
        ("soup", meshes::triangles(&soup)),
        // 9 × 9 unit cells: 162 coplanar triangles, a count that is no power of two.
        ("flat grid", meshes::triangles(&grid(4.5, 9))),
        (
            "sphere 1e5 from origin",
            meshes::triangles(&sphere.translated(far)),
        ),
        ("torus at scale 1e-3", meshes::triangles(&ring.scaled(1e-3))),
        (
            "soup at scale 1e3, far",
            meshes::triangles(&soup.scaled(1e3).translated(far)),
        ),
    ]
}

/// Calls `check(name, triangles, params)` for every mesh, preset and leaf size.
fn for_each_case(mut check: impl FnMut(&str, &[Triangle], BuildParams)) {
    for (name, triangles) in named_meshes() {
        for preset in PRESETS {
            for leaf_size in LEAF_SIZES {
                check(name, &triangles, preset.with_leaf_size(leaf_size));
            }
        }
    }
}

/// `⌈log₂ k⌉` for `k ≥ 1`.
fn ceil_log2(k: usize) -> usize {
    k.next_power_of_two().ilog2() as usize
}

fn builds_validate<B: BoundingVolume>() {
    for_each_case(|name, triangles, params| {
        let bvh = Bvh::<B>::from_triangles(triangles, &params);
        assert_eq!(bvh.validate(), Ok(()), "{} {name} {params:?}", B::NAME);
        assert_eq!(bvh.triangle_count(), triangles.len());
        assert_eq!(bvh.leaf_size(), params.leaf_size as usize);
        // A full binary tree: one fewer internal node than leaves.
        let leaves = bvh.nodes().iter().filter(|n| n.is_leaf()).count();
        assert_eq!(
            bvh.nodes().len(),
            2 * leaves - 1,
            "{} {name} {params:?}",
            B::NAME
        );
        let slots: usize = bvh.nodes().iter().map(|n| n.slots().len()).sum();
        assert_eq!(slots, triangles.len(), "{} {name} {params:?}", B::NAME);
    });
}

#[test]
fn every_build_of_every_mesh_validates() {
    for_each_volume!(builds_validate());
}

fn slots_hold_their_triangles<B: BoundingVolume>() {
    for_each_case(|name, triangles, params| {
        let bvh = Bvh::<B>::from_triangles(triangles, &params);
        let what = format!("{} {name} {params:?}", B::NAME);
        let mut seen = vec![false; triangles.len()];
        for slot in 0..bvh.triangle_count() {
            let id = bvh.triangle_id(slot) as usize;
            assert!(id < triangles.len(), "{what}: id {id} out of range");
            assert!(
                !std::mem::replace(&mut seen[id], true),
                "{what}: id {id} repeated"
            );
            assert_eq!(bvh.triangles()[slot], triangles[id], "{what}: slot {slot}");
        }
        assert!(seen.iter().all(|&s| s), "{what}: an id is missing");
        // `slot_of` inverts the map.
        for id in 0..triangles.len() {
            let slot = bvh.slot_of(id as u32).expect("every id has a slot");
            assert_eq!(bvh.triangle_id(slot) as usize, id, "{what}");
        }
        assert_eq!(bvh.slot_of(triangles.len() as u32), None, "{what}");
    });
}

#[test]
fn triangle_ids_are_a_permutation_and_each_slot_holds_the_triangle_it_names() {
    for_each_volume!(slots_hold_their_triangles());
}

fn depth_is_bounded<B: BoundingVolume>() {
    for_each_case(|name, triangles, params| {
        let bvh = Bvh::<B>::from_triangles(triangles, &params);
        let n = triangles.len();
        let leaf_size = params.leaf_size as usize;
        // A tree of depth d has at most 2^d leaves, each with at most `leaf_size` triangles.
        let least = ceil_log2(n.div_ceil(leaf_size));
        let depth = bvh.depth();
        let what = format!("{} {name} {params:?}: depth {depth}", B::NAME);
        assert!(depth >= least, "{what} below the least possible {least}");
        // Every internal node splits its triangles into two non-empty parts.
        assert!(depth < n.max(2), "{what}");
        if params.strategy == BuildStrategy::Median {
            // Halving leaves ⌈n / 2^d⌉ triangles at depth d; a node splits only when it holds
            // more than `leaf_size`, so no leaf is deeper than `least`.
            assert_eq!(depth, least, "{what}");
        }
    });
}

#[test]
fn median_trees_have_the_least_possible_depth_and_no_tree_is_shallower() {
    for_each_volume!(depth_is_bounded());
}

fn builds_repeat<B: BoundingVolume + PartialEq>() {
    for_each_case(|name, triangles, params| {
        let (a, b) = (
            Bvh::<B>::from_triangles(triangles, &params),
            Bvh::<B>::from_triangles(triangles, &params),
        );
        assert!(a.nodes() == b.nodes(), "{} {name} {params:?}", B::NAME);
        let ids = |bvh: &Bvh<B>| {
            (0..bvh.triangle_count())
                .map(|slot| bvh.triangle_id(slot))
                .collect::<Vec<_>>()
        };
        assert_eq!(ids(&a), ids(&b), "{} {name} {params:?}", B::NAME);
    });
}

#[test]
fn building_twice_gives_the_same_tree() {
    // Structure does not depend on the volume type for top-down builders, and bottom-up
    // clusters on boxes for every type: two types cover both fitting paths.
    builds_repeat::<Aabb>();
    builds_repeat::<Obb>();
}

/// Random cases per volume type in [`random_meshes_build_valid_trees_of_bounded_depth`].
const RANDOM_CASES: usize = 1000;

fn random_cases<B: BoundingVolume>(seed: u64) {
    let mut rng = rng(seed);
    for case in 0..RANDOM_CASES {
        let (n, size) = (rng.random_range(1..120), rng.random_range(0.0..0.5));
        let base = match case % 3 {
            0 => triangle_soup(&mut rng, n, 1.0, size),
            1 => zero_area_triangles(&mut rng, n, 1.0),
            _ => uv_sphere(1.0, 3 + (n % 11) as u32, 2 + (n % 7) as u32),
        };
        let center = support::rotation(&mut rng) * DVec3::X * CENTERS[case % CENTERS.len()];
        let scale = SCALES[rng.random_range(0..SCALES.len())];
        let triangles = meshes::triangles(&base.scaled(scale).translated(center));
        let preset = PRESETS[rng.random_range(0..PRESETS.len())];
        let params = preset.with_leaf_size(rng.random_range(1..9));
        let bvh = Bvh::<B>::from_triangles(&triangles, &params);
        let what = format!("{} case {case} {params:?}", B::NAME);
        assert_eq!(bvh.validate(), Ok(()), "{what}");
        for slot in 0..bvh.triangle_count() {
            assert_eq!(
                bvh.triangles()[slot],
                triangles[bvh.triangle_id(slot) as usize],
                "{what}"
            );
        }
        let least = ceil_log2(triangles.len().div_ceil(params.leaf_size as usize));
        assert!(bvh.depth() >= least, "{what}");
        if preset == BuildParams::MEDIAN {
            assert_eq!(bvh.depth(), least, "{what}");
        }
    }
}

#[test]
fn random_meshes_build_valid_trees_of_bounded_depth() {
    for_each_volume!(random_cases(402));
}

fn real_mesh_validates<B: BoundingVolume>(mesh: &TriMesh, name: &str, leaf_sizes: &[u32]) {
    for preset in PRESETS {
        for &leaf_size in leaf_sizes {
            let params = preset.with_leaf_size(leaf_size);
            let bvh = Bvh::<B>::from_mesh(mesh, &params);
            assert_eq!(bvh.validate(), Ok(()), "{} {name} {params:?}", B::NAME);
            assert_eq!(bvh.triangle_count(), mesh.triangle_count());
        }
    }
}

#[test]
fn real_meshes_build_valid_trees_with_every_preset() {
    let spot = meshes::data_mesh("spot.obj");
    real_mesh_validates::<Obb>(&spot, "spot", &[1]);
    real_mesh_validates::<Rss>(&spot, "spot", &[4]);
    let rob = meshes::data_mesh("rob.obj");
    for_each_volume!(real_mesh_validates(&rob, "rob.obj", &LEAF_SIZES));
}

#[test]
fn fcl_room_builds_valid_trees_with_every_preset() {
    let Some(env) =
        meshes::shared_data_mesh("fcl_room_builds_valid_trees_with_every_preset", "env.obj")
    else {
        return;
    };
    for_each_volume!(real_mesh_validates(&env, "env.obj", &LEAF_SIZES));
}
