//! Unit tests of the brute-force oracle.

use super::*;
use crate::bounding::Aabb;
use crate::broad::CollisionFilter;
use crate::math::DVec3;
use crate::test_support::{point_in_cube, rng};
use rand::Rng;

/// Spheres with margins: the exact close-pair rule is `|c_a − c_b| − r_a − r_b ≤ m_a + m_b`.
#[test]
fn every_pair_of_spheres_within_their_margins_is_a_candidate_and_filters_hold() {
    let mut rng = rng(61);
    let (mut close, mut far) = (0, 0);
    for case in 0..300 {
        let n = rng.random_range(1..60);
        let spheres: Vec<(DVec3, f64, f64)> = (0..n)
            .map(|_| {
                (
                    point_in_cube(&mut rng, 2.5),
                    rng.random_range(0.0..1.0),
                    rng.random_range(0.0..0.5),
                )
            })
            .collect();
        let proxies: Vec<Proxy> = spheres
            .iter()
            .enumerate()
            .map(|(i, &(c, r, m))| Proxy {
                body: (n - i) as u32 * 3, // ids not in input order
                bounds: Aabb::new(c - DVec3::splat(r + m), c + DVec3::splat(r + m)),
                is_static: rng.random_range(0..4) == 0,
                filter: CollisionFilter {
                    group: 1 << rng.random_range(0..3),
                    mask: rng.random_range(1..8),
                },
            })
            .collect();
        let mut pairs = Vec::new();
        pairs_brute_force(&proxies, &mut pairs);
        assert!(
            pairs.windows(2).all(|w| w[0] < w[1]),
            "case {case}: sorted, no duplicates"
        );
        for i in 0..n {
            for j in i + 1..n {
                let (p, q) = (&proxies[i], &proxies[j]);
                let ((ci, ri, mi), (cj, rj, mj)) = (spheres[i], spheres[j]);
                let key = CandidatePair {
                    a: p.body.min(q.body),
                    b: p.body.max(q.body),
                };
                let reported = pairs.binary_search(&key).is_ok();
                // Written out, not through `may_pair`, so the test states the rule itself.
                let (f, g) = (p.filter, q.filter);
                let allowed =
                    !(p.is_static && q.is_static) && f.group & g.mask != 0 && g.group & f.mask != 0;
                if !allowed {
                    assert!(!reported, "case {case}: filtered pair {key:?} reported");
                } else if ci.distance(cj) - ri - rj <= mi + mj {
                    assert!(reported, "case {case}: close pair {key:?} missed");
                    close += 1;
                } else {
                    far += 1;
                }
            }
        }
    }
    assert!(close > 1_000 && far > 1_000, "close {close}, far {far}");
}
