//! What every stateful broad phase ([`IncrementalSap`], [`HashGrid`], [`ColumnGrid`],
//! [`SkinGrid`]) owes,
//! as generic test bodies that each one's unit tests run with its own constructor and sizes.

use super::{CandidatePair, CollisionFilter, ColumnGrid, HashGrid, IncrementalSap, SkinGrid};
use crate::bounding::Aabb;
use crate::math::DVec3;
use crate::test_support::TestRng;

/// The body-level API the stateful broad phases share.
pub(super) trait Stateful {
    fn insert(&mut self, body: u32, bounds: Aabb, is_static: bool, filter: CollisionFilter);
    fn remove(&mut self, body: u32) -> bool;
    fn update(&mut self, body: u32, bounds: Aabb);
    fn pairs(&mut self, out: &mut Vec<CandidatePair>);
    fn validate(&self) -> Result<(), String>;
    fn contains(&self, body: u32) -> bool;
    fn len(&self) -> usize;
}

macro_rules! stateful {
    ($($phase:ident),+) => {$(
        impl Stateful for $phase {
            fn insert(&mut self, body: u32, bounds: Aabb, is_static: bool, filter: CollisionFilter) {
                $phase::insert(self, body, bounds, is_static, filter);
            }
            fn remove(&mut self, body: u32) -> bool {
                $phase::remove(self, body)
            }
            fn update(&mut self, body: u32, bounds: Aabb) {
                $phase::update(self, body, bounds);
            }
            fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
                $phase::pairs(self, out);
            }
            fn validate(&self) -> Result<(), String> {
                $phase::validate(self)
            }
            fn contains(&self, body: u32) -> bool {
                $phase::contains(self, body)
            }
            fn len(&self) -> usize {
                $phase::len(self)
            }
        }
    )+};
}

stateful!(IncrementalSap, HashGrid, ColumnGrid, SkinGrid);

/// A random box centred in the cube of half-size `spread`: one in `kinds` a point, one in
/// `kinds` huge (half-extents 2 to 20 m), the rest ordinary (half-extents up to 1 m).
pub(super) fn random_box(rng: &mut TestRng, spread: f64, kinds: u32) -> Aabb {
    use rand::Rng;
    let c = crate::test_support::point_in_cube(rng, spread);
    let h = match rng.random_range(0..kinds) {
        0 => DVec3::ZERO,
        1 => DVec3::splat(rng.random_range(2.0..20.0)),
        _ => DVec3::new(
            rng.random_range(0.0..1.0),
            rng.random_range(0.0..1.0),
            rng.random_range(0.0..1.0),
        ),
    };
    Aabb::new(c - h, c + h)
}

/// A 1 m cube with its low corner at `(x, y, z)`.
pub(super) fn unit_at(x: f64, y: f64, z: f64) -> Aabb {
    Aabb::new(DVec3::new(x, y, z), DVec3::new(x + 1.0, y + 1.0, z + 1.0))
}

/// The current pairs as `(a, b)`, after checking `validate()`.
pub(super) fn pairs_of(phase: &mut impl Stateful) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    phase.pairs(&mut out);
    phase.validate().unwrap();
    out.into_iter().map(|p| (p.a, p.b)).collect()
}

/// Five unit cubes in a row, body 2 removed, re-inserted far away, then back as a static
/// body whose filter meets only some of its neighbours, then replaced (present id) by
/// `replacement`, a box touching none of them. `phase` must start empty; it ends holding
/// the five bodies, for the caller's own checks before [`removing_every_body_empties_it`].
pub(super) fn removed_ids_come_back_with_new_bounds_kind_and_filter(
    phase: &mut impl Stateful,
    replacement: Aabb,
) {
    for id in 0..5 {
        phase.insert(
            id,
            unit_at(f64::from(id) * 0.5, 0.0, 0.0),
            false,
            CollisionFilter::ALL,
        );
    }
    assert_eq!(
        pairs_of(phase),
        [(0, 1), (0, 2), (1, 2), (1, 3), (2, 3), (2, 4), (3, 4)]
    );
    assert!(phase.remove(2));
    assert!(!phase.remove(2));
    assert!(!phase.contains(2));
    assert_eq!(pairs_of(phase), [(0, 1), (1, 3), (3, 4)]);
    // Same id, now far away, then back, static and filtered against body 3.
    phase.insert(2, unit_at(50.0, 0.0, 0.0), false, CollisionFilter::ALL);
    assert_eq!(pairs_of(phase), [(0, 1), (1, 3), (3, 4)]);
    assert!(phase.remove(2));
    let only_group_1 = CollisionFilter { group: 1, mask: 1 };
    phase.insert(
        3,
        unit_at(1.5, 0.0, 0.0),
        false,
        CollisionFilter { group: 2, mask: 2 },
    );
    phase.insert(2, unit_at(1.0, 0.0, 0.0), true, only_group_1);
    assert_eq!(
        pairs_of(phase),
        [(0, 1), (0, 2), (1, 2), (1, 3), (2, 4), (3, 4)]
    );
    // Inserting a present id replaces it.
    phase.insert(2, replacement, false, CollisionFilter::ALL);
    assert_eq!(phase.len(), 5);
    assert_eq!(pairs_of(phase), [(0, 1), (1, 3), (3, 4)]);
}

/// Removes the five bodies of [`removed_ids_come_back_with_new_bounds_kind_and_filter`],
/// validating after each.
pub(super) fn removing_every_body_empties_it(phase: &mut impl Stateful) {
    for id in [0, 4, 1, 3, 2] {
        assert!(phase.remove(id));
        phase.validate().unwrap();
    }
    assert_eq!(phase.len(), 0);
}

/// `count` bodies, every fourth one dynamic and the rest static, moved to fresh random boxes
/// for 50 frames: no pair is ever static–static, and more than `min_mixed` dynamic–static
/// pairs occur (so the check had overlapping statics to refuse).
pub(super) fn static_bodies_never_pair_with_each_other(
    phase: &mut impl Stateful,
    rng: &mut TestRng,
    count: u32,
    mut boxed: impl FnMut(&mut TestRng) -> Aabb,
    min_mixed: usize,
) {
    for id in 0..count {
        phase.insert(id, boxed(rng), id % 4 != 0, CollisionFilter::ALL);
    }
    let mut mixed = 0;
    for frame in 0..50 {
        for id in 0..count {
            phase.update(id, boxed(rng));
        }
        for (a, b) in pairs_of(phase) {
            assert!(
                a % 4 == 0 || b % 4 == 0,
                "frame {frame}: static pair ({a}, {b})"
            );
            mixed += usize::from(a % 4 != 0 || b % 4 != 0);
        }
    }
    assert!(mixed > min_mixed, "{mixed}");
}
