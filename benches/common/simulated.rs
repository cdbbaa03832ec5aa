//! A simulation's frames in-process, as its client would send them to the daemon: the
//! moving bodies' poses from the point-mass world set on the library's scene, one unlimited
//! `step` a frame, and the records the world bounces its bodies with.
//!
//! Include with `#[path = "common/simulated.rs"] mod simulated;`; it expects the scenes'
//! point-mass world at the crate root as `point_mass`.

use super::point_mass::World;
use proxima::daemon::records::{contact_record, pair_record};
use proxima::math::{DQuat, DVec3, Pose};
use proxima::pipeline::{FrameResults, PipelineWorkspace, Query, step};
use proxima::scene::{BodyId, Motion, Scene};
use proxima_ipc::wire::ResultRecord;

/// Each moving body's pose in one frame.
pub type PoseSet = Vec<(BodyId, Pose)>;

/// Runs `frames` frames of `world` on `scene` at `rate_hz`, each an unlimited `step` asking
/// `query` whose records bounce the bodies, and returns every frame's moving poses (the
/// scene is left at the last frame).
pub fn simulate(
    world: &mut World,
    scene: &mut Scene,
    rate_hz: f64,
    query: Query,
    frames: usize,
) -> Vec<PoseSet> {
    let (mut workspace, mut results) = (PipelineWorkspace::default(), FrameResults::default());
    let (mut pairs, mut contacts) = (Vec::new(), Vec::new());
    (0..frames)
        .map(|_| {
            world.integrate(1.0 / rate_hz);
            for i in 0..world.moving_count() {
                let r = world.pose(i);
                let [x, y, z, w] = r.orientation;
                let pose =
                    Pose::try_new(DVec3::from_array(r.position), DQuat::from_xyzw(x, y, z, w))
                        .expect("the solver keeps poses valid");
                scene.set_pose(BodyId(r.body), pose).expect("a moving body");
            }
            step(scene, query, &mut workspace, &mut results);
            scene.end_frame();
            records(&results, &mut pairs, &mut contacts);
            world.resolve(&pairs, &contacts);
            moving_poses(scene)
        })
        .collect()
}

/// The records of a frame's pairs and contacts, as the daemon writes them.
fn records(
    results: &FrameResults,
    pairs: &mut Vec<ResultRecord>,
    contacts: &mut Vec<ResultRecord>,
) {
    pairs.clear();
    pairs.extend(results.pairs.iter().map(pair_record));
    contacts.clear();
    contacts.extend((results.contacts.iter()).map(|c| contact_record(&results.pairs, c)));
}

/// The poses of the scene's moving bodies.
pub fn moving_poses(scene: &Scene) -> PoseSet {
    scene
        .bodies()
        .filter(|(_, b)| b.motion != Motion::Static)
        .map(|(id, b)| (id, b.pose))
        .collect()
}

/// Sets the bodies of `poses` to them.
pub fn set_poses(scene: &mut Scene, poses: &PoseSet) {
    for &(id, pose) in poses {
        scene.set_pose(id, pose).expect("a moving body");
    }
}
