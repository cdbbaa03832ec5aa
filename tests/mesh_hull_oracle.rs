//! Hull proofs on the real meshes of the data folder (`PROXIMA_DATA`) (FCL's robot link and room, the
//! fandisk, spot and the Stanford bunny, each scaled to about a metre): a hull gap is
//! never more than the meshes' exact distance by the tree query (a second algorithm,
//! within its error bound), over random poses where both outcomes occur, and every vertex
//! left out of a hull lies within its outside allowance, which stays rounding-sized.
//! Skipped, with a line saying so, when the data folder is absent.

#[path = "support/mod.rs"]
mod support;

use proxima::math::Pose;
use proxima::narrow::MeshShape;
use proxima::narrow::gjk::GjkCache;
use proxima::narrow::mesh_mesh::{DistanceCache, MeshMeshWorkspace};
use support::{meshes, point_in_cube, rng, rotation};

/// The shared meshes, each scaled so its largest bounding-box edge is 1 m and centred.
fn unit_meshes(who: &str) -> Option<Vec<(&'static str, MeshShape)>> {
    let mut out = Vec::new();
    for name in [
        "rob.obj",
        "env.obj",
        "fandisk.obj",
        "spot.obj",
        "stanford-bunny.obj",
    ] {
        let mesh = meshes::shared_data_mesh(who, name)?;
        let (lo, hi) = mesh.bounds();
        let unit = mesh
            .scaled(1.0 / (hi - lo).max_element())
            .centered_on_bounds();
        out.push((name, MeshShape::new(unit)));
    }
    Some(out)
}

#[test]
fn hull_gaps_of_real_meshes_never_exceed_their_exact_distance() {
    let Some(shapes) = unit_meshes("hull_gaps_of_real_meshes_never_exceed_their_exact_distance")
    else {
        return;
    };
    for (name, shape) in &shapes {
        let hull = shape.hull.as_ref().expect("a solid mesh has a hull");
        // A vertex outside the hull by more than rounding would mean a hull that lost
        // part of its mesh; the allowance covers it either way.
        assert!(hull.outside() < 1e-9, "{name}: outside {}", hull.outside());
    }
    let mut rng = rng(53);
    let mut workspace = MeshMeshWorkspace::new();
    let (mut proofs, mut beyond_a_centimetre, mut meeting) = (0, 0, 0);
    for case in 0..400 {
        let (i, j) = (case % shapes.len(), (case / shapes.len()) % shapes.len());
        let ((na, a), (nb, b)) = (&shapes[i], &shapes[j]);
        // Centres up to 1.2 m apart on each axis: apart, near and overlapping placements.
        let pose_ab = Pose::new(point_in_cube(&mut rng, 1.2), rotation(&mut rng));
        let (ha, hb) = (a.hull.as_ref().unwrap(), b.hull.as_ref().unwrap());
        let Some(gap) = ha.gap(hb, &pose_ab.to_isometry(), &mut GjkCache::default()) else {
            meeting += 1;
            continue;
        };
        proofs += 1;
        beyond_a_centimetre += usize::from(gap > 0.01);
        let exact = a.distance_to(b, &pose_ab, &mut DistanceCache::default(), &mut workspace);
        assert!(
            gap <= exact.distance + exact.error_bound,
            "case {case}: {na} and {nb}: hull gap {gap} beyond the distance {} (± {})",
            exact.distance,
            exact.error_bound
        );
    }
    assert!(
        proofs > 200 && beyond_a_centimetre > 200 && meeting > 50,
        "{proofs} proofs ({beyond_a_centimetre} beyond 1 cm), {meeting} meeting"
    );
}
