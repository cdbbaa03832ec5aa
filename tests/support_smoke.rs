//! The shared generators themselves: rotations are unit and clouds have the requested size.
mod support;

use support::{CloudKind, cloud, rng, rotation};

#[test]
fn generators_give_unit_rotations_and_requested_clouds() {
    let mut r = rng(1);
    for _ in 0..1000 {
        assert!((rotation(&mut r).length() - 1.0).abs() < 1e-12);
    }
    for kind in CloudKind::ALL {
        let pts = cloud(&mut r, kind, 50, proxima::math::DVec3::splat(1e6), 1e-4);
        assert_eq!(
            pts.len(),
            if kind == CloudKind::Single { 1 } else { 50 },
            "{kind:?}"
        );
        assert!(pts.iter().all(|p| p.is_finite()));
    }
}
