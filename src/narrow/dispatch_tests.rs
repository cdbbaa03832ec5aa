//! The dispatcher's distance under a finite reporting limit against the same query without
//! one (the closed forms and GJK/EPA, exact).

use super::*;
use crate::test_support::{isometry, random_convex, rng};
use rand::Rng;

/// Random convex pairs of every kind (box, ball, capsule, cylinder, cone, hull), 0.6–3 cm,
/// within 4 cm of each other (centres in a cube of that half side), limits 0–3 cm. Within the limit the limited answer is the
/// exact one; beyond it, a lower bound above the limit. The support plane across the
/// shapes' origins (`beyond_along_centres`) is checked on its own too: when it answers, its
/// gap is above the limit and at most the exact distance, and its witnesses are at least
/// that far apart. Within, beyond, proven by that plane and beyond but not proven by it all
/// occur.
#[test]
fn limited_distances_are_exact_within_the_limit_and_lower_bounds_beyond_it() {
    let mut r = rng(0x11_317);
    let mut scratch = NarrowScratch::default();
    let (mut within, mut beyond, mut by_plane) = (0, 0, 0);
    for case in 0..20_000 {
        let a = random_convex(&mut r, 0.03, 6);
        let b = random_convex(&mut r, 0.03, 6);
        let pose = isometry(&mut r, 0.04);
        let limit = r.random_range(0.0..0.03);
        let exact = distance_convex(&a, &b, &pose, f64::INFINITY, &mut scratch);
        let limited = distance_convex(&a, &b, &pose, limit, &mut scratch);
        let tol = 1e-9 * exact.distance.abs().max(1e-3);
        let ctx = format!("case {case}: {a:?} {b:?} {pose:?} limit {limit}: exact {exact:?}");
        if exact.distance <= limit - tol {
            assert!(
                (limited.distance - exact.distance).abs() <= tol,
                "{ctx}, limited {limited:?}"
            );
            within += 1;
        } else if exact.distance > limit + tol {
            assert!(
                limited.distance > limit && limited.distance <= exact.distance + tol,
                "{ctx}, limited {limited:?}"
            );
            beyond += 1;
        }
        if let Some(d) = beyond_along_centres(&a, &b, &pose, limit) {
            assert!(
                d.distance > limit && d.distance <= exact.distance + tol,
                "{ctx}, plane {d:?}"
            );
            assert!(
                (d.point_b - d.point_a).length() >= d.distance - tol,
                "{ctx}, plane {d:?}"
            );
            by_plane += 1;
        }
    }
    eprintln!("{within} within the limit, {beyond} beyond, {by_plane} proven by the plane");
    assert!(
        within > 1_000 && beyond > 1_000,
        "{within} within, {beyond} beyond"
    );
    assert!(
        by_plane > 1_000 && by_plane < beyond,
        "{by_plane} of {beyond} by the plane"
    );
}
