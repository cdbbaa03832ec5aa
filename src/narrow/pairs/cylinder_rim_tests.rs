//! The rim certificate against GJK run to a tighter tolerance, on random cylinder–box and
//! cylinder–cylinder pairs placed around the rim.

use super::*;
use crate::narrow::gjk::{GjkCache, GjkOutcome, GjkParams, gjk_distance};
use crate::test_support::{TestRng, around_the_rim, random_cylinder, rng, support_gap};
use rand::Rng;

/// GJK as the oracle: a hundredth of the dispatcher's tolerance, iterations to spare.
const ORACLE: GjkParams = GjkParams {
    rel_tol: 1e-12,
    epa_rel_tol: 1e-12,
    abs_tol: 0.0,
    max_iterations: 4_096,
    accelerated: false,
};

/// Whether `p` (A's frame) lies on a rim of `a`, to `tol` metres.
fn on_rim(a: &Cylinder, p: DVec3, tol: f64) -> bool {
    let rho = DVec3::new(p.x, p.y, 0.0).length();
    (p.z.abs() - a.half_height).abs() <= tol && (rho - a.radius).abs() <= tol
}

/// Checks one case: when the certificate answers, it agrees with the oracle to 1e-9
/// relative, its witnesses are a rim point of A and a point of B that far apart, and its
/// normal is their unit direction. Returns (answered, the oracle's nearest point of A on
/// a rim with the shapes apart, the oracle's bounds within 1e-9 of each other).
fn check<B: NearestPoint + std::fmt::Debug>(
    a: &Cylinder,
    b: &B,
    pose: &Isometry,
    case: usize,
) -> (bool, bool, bool) {
    let oracle = gjk_distance(a, b, pose, &ORACLE, &mut GjkCache::default());
    // Apart: converged, or stopped short of its tolerance with a plane between them.
    let apart = oracle.outcome == GjkOutcome::Separated
        || (oracle.outcome == GjkOutcome::DidNotConverge && oracle.lower_bound > 0.0);
    let scale = a.radius.max(a.half_height) + pose.translation.length();
    let rim_case = apart && on_rim(a, oracle.point_a, 1e-7 * scale);
    let Some(d) = certified_rim_distance(a, b, pose, 1e-10) else {
        return (false, rim_case, false);
    };
    let ctx = format!("case {case}: {a:?} {b:?} {pose:?}: oracle {oracle:?}, rim {d:?}");
    assert!(apart, "{ctx}: answered a pair that is not apart");
    // The oracle's bounds: its witnesses' distance above; below, the support planes along
    // its normal, or the best plane it found.
    let upper = (oracle.point_b - oracle.point_a).length();
    let lower = support_gap(a, b, pose, oracle.normal()).max(oracle.lower_bound);
    let tol = 1e-9 * upper + 64.0 * f64::EPSILON * scale;
    assert!(
        d.distance >= lower - tol && d.distance <= upper + tol,
        "{ctx}: outside the oracle's bounds [{lower:e}, {upper:e}]"
    );
    assert!(
        on_rim(a, d.point_a, 1e-12 * scale),
        "{ctx}: point_a off the rim"
    );
    let on_b = pose.inverse_transform_point(d.point_b);
    assert!(
        (b.nearest_point(on_b) - on_b).length() <= 1e-12 * scale,
        "{ctx}: point_b outside B"
    );
    assert!(
        ((d.point_b - d.point_a).length() - d.distance).abs() <= 1e-12 * scale,
        "{ctx}: witnesses not the distance apart"
    );
    assert!(
        (d.normal - (d.point_b - d.point_a) / d.distance).length() <= 1e-9,
        "{ctx}: normal not along the witnesses"
    );
    (true, rim_case, upper - lower <= 1e-9 * upper)
}

/// Tallies of one kind of pair: certified, oracle rim cases, and rim cases certified.
#[derive(Default, Debug)]
struct Tally {
    cases: usize,
    answered: usize,
    rim_cases: usize,
    rim_answered: usize,
    /// Answers checked against oracle bounds within 1e-9 of each other.
    tight: usize,
}

impl Tally {
    fn add(&mut self, (answered, rim_case, tight): (bool, bool, bool)) {
        self.tight += usize::from(tight);
        self.cases += 1;
        self.answered += usize::from(answered);
        self.rim_cases += usize::from(rim_case);
        self.rim_answered += usize::from(answered && rim_case);
    }

    /// Both outcomes occur, the certificate answers most pairs nearest at a rim, and most
    /// answers were checked against a tight bracket.
    fn assert_useful(&self, what: &str) {
        eprintln!("{what}: {self:?}");
        assert!(self.answered > self.cases / 10, "{what}: {self:?}");
        assert!(
            self.cases - self.answered > self.cases / 10,
            "{what}: {self:?}"
        );
        assert!(self.rim_cases > self.cases / 10, "{what}: {self:?}");
        assert!(
            self.rim_answered * 10 >= self.rim_cases * 9,
            "{what}: {self:?}"
        );
        assert!(self.tight * 10 >= self.answered * 9, "{what}: {self:?}");
    }
}

/// 10,000 seeded cases of a random cylinder A against `make_b`'s shape, placed around A's
/// rim at B's size (the second value), each checked, then the tally's usefulness asserted.
fn check_around_the_rim<B: NearestPoint + std::fmt::Debug>(
    what: &str,
    seed: u64,
    make_b: impl Fn(&mut TestRng) -> (B, f64),
) {
    let mut r = rng(seed);
    let mut tally = Tally::default();
    for case in 0..10_000 {
        let a = random_cylinder(&mut r);
        let (b, b_size) = make_b(&mut r);
        let pose = around_the_rim(&mut r, &a, b_size);
        tally.add(check(&a, &b, &pose, case));
    }
    tally.assert_useful(what);
}

#[test]
fn rim_distances_to_boxes_agree_with_gjk() {
    check_around_the_rim("cylinder–box", 0x51_4d, |r| {
        let b = Cuboid::new(DVec3::new(
            r.random_range(0.002..0.03),
            r.random_range(0.002..0.03),
            r.random_range(0.002..0.03),
        ));
        let size = b.half_extents.length();
        (b, size)
    });
}

#[test]
fn rim_distances_to_cylinders_agree_with_gjk() {
    check_around_the_rim("cylinder–cylinder", 0x51_4e, |r| {
        let b = random_cylinder(r);
        let size = b.half_height.hypot(b.radius);
        (b, size)
    });
}

/// Overlapping or touching pairs are never answered: the certificate is for pairs apart.
#[test]
fn overlapping_pairs_get_no_rim_answer() {
    let mut r = rng(0x51_4f);
    let mut overlapping = 0;
    for _ in 0..5_000 {
        let a = random_cylinder(&mut r);
        let b = Cuboid::new(DVec3::splat(r.random_range(0.005..0.03)));
        let pose = around_the_rim(&mut r, &a, 0.3 * b.half_extents.length());
        let oracle = gjk_distance(&a, &b, &pose, &ORACLE, &mut GjkCache::default());
        if matches!(
            oracle.outcome,
            GjkOutcome::Touching | GjkOutcome::Penetrating
        ) {
            overlapping += 1;
            assert!(certified_rim_distance(&a, &b, &pose, 1e-10).is_none());
        }
    }
    assert!(overlapping > 1_000, "{overlapping} overlapping");
}
