//! Compound shapes through the real `proximad` over shared memory: a client registers a
//! solid of two cubes and a closed mesh the daemon decomposes, and the contacts of a ball
//! reaching into them carry the true penetration depth, checked against the analytic
//! answer (a mesh, a surface, would say the ball is apart once it is inside).

#[path = "support/daemon.rs"]
mod daemon_harness;

use daemon_harness::Daemon;
use proxima_ipc::client::{BodySpec, Decomposition, Motion, Primitive};
use proxima_ipc::wire::{ErrorCode, PoseRecord, RecordKind, ResultRecord, query};
use std::time::Duration;

const TIMEOUT: Duration = Duration::from_secs(10);
const RADIUS: f64 = 0.2;

/// The corners of the axis-aligned box `[lo, hi]`.
fn corners(lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect()
}

/// The closed triangle mesh of the box `[lo, hi]`, faces counter-clockwise from outside.
fn box_mesh(lo: [f64; 3], hi: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let faces = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    (corners(lo, hi), faces)
}

fn spec(shape: u32) -> BodySpec {
    BodySpec {
        shape,
        position: [0.0; 3],
        orientation: [0.0, 0.0, 0.0, 1.0],
        motion: Motion::Dynamic,
        group: u32::MAX,
        mask: u32::MAX,
        margin: Some(0.0),
    }
}

fn at(body: u32, position: [f64; 3]) -> PoseRecord {
    PoseRecord {
        body,
        reserved: 0,
        position,
        orientation: [0.0, 0.0, 0.0, 1.0],
    }
}

/// The pair record of bodies `solid` and `ball`, its distance and its normal from the
/// solid to the ball; `None` when the frame has no such pair.
fn pair_of(records: &[ResultRecord], solid: u32, ball: u32) -> Option<(f64, [f64; 3])> {
    records
        .iter()
        .find(|r| {
            r.kind == RecordKind::Pair as u32
                && [r.body_a, r.body_b].contains(&solid)
                && [r.body_a, r.body_b].contains(&ball)
        })
        .map(|r| {
            let n = if r.body_a == solid {
                r.normal
            } else {
                r.normal.map(|x| -x)
            };
            (r.distance, n)
        })
}

/// A ball deep inside either cube of a two-cube compound, inside a decomposed box mesh,
/// and between the cubes: the depth is the ball's radius plus its centre's distance to the
/// nearest face, along that face's normal, and the ball between the cubes touches
/// neither.
#[test]
fn a_ball_inside_a_compound_gets_the_true_depth() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let (left, right) = (
        corners([0.0; 3], [1.0; 3]),
        corners([3.0, 0.0, 0.0], [4.0, 1.0, 1.0]),
    );
    let cubes = client
        .register_compound(scene, &[&left[..], &right[..]])
        .unwrap();
    let (vertices, faces) = box_mesh([0.0, 0.0, 10.0], [2.0, 1.0, 11.0]);
    let decomposed = client
        .register_decomposed_mesh(scene, &vertices, &faces, Decomposition::default())
        .unwrap();
    let ball = client
        .register_primitive(scene, Primitive::Sphere { radius: RADIUS })
        .unwrap();
    let solids = [
        client.add_body(scene, &spec(cubes)).unwrap(),
        client.add_body(scene, &spec(decomposed)).unwrap(),
    ];
    let ball_body = client.add_body(scene, &spec(ball)).unwrap();
    let link = client.open_scene(scene).unwrap();
    // (solid, ball centre, expected signed distance, expected normal).
    let cases = [
        (0, [0.5, 0.5, 0.85], -(0.15 + RADIUS), [0.0, 0.0, 1.0]),
        (0, [3.5, 0.4, 0.5], -(0.4 + RADIUS), [0.0, -1.0, 0.0]),
        (1, [1.5, 0.5, 10.3], -(0.3 + RADIUS), [0.0, 0.0, -1.0]),
        (1, [0.3, 0.45, 10.5], -(0.3 + RADIUS), [-1.0, 0.0, 0.0]),
    ];
    for (frame, (solid, centre, depth, normal)) in cases.iter().enumerate() {
        let frame = frame as u64 + 1;
        let records = [
            at(solids[0], [0.0; 3]),
            at(solids[1], [0.0; 3]),
            at(ball_body, *centre),
        ];
        link.publish_poses(frame, 0, query::DISTANCE | query::CONTACTS, &records)
            .unwrap();
        let result = link
            .receive_results_for(frame, TIMEOUT)
            .unwrap()
            .expect("a result frame");
        assert_eq!(
            ErrorCode::from_u32(result.header().status),
            Some(ErrorCode::Ok)
        );
        let (d, n) = pair_of(result.records(), solids[*solid], ball_body)
            .unwrap_or_else(|| panic!("frame {frame}: no pair"));
        assert!(
            (d - depth).abs() < 1e-9,
            "frame {frame}: {d} against {depth}"
        );
        let off: f64 = n.iter().zip(normal).map(|(a, b)| (a - b).abs()).sum();
        assert!(off < 1e-9, "frame {frame}: normal {n:?} against {normal:?}");
        let contacts = result
            .records()
            .iter()
            .filter(|r| r.kind == RecordKind::Contact as u32)
            .count();
        assert!(contacts >= 1, "frame {frame}: no contact");
    }
    // Between the two cubes, 0.8 m from each: no pair with the cubes.
    let records = [
        at(solids[0], [0.0; 3]),
        at(solids[1], [0.0; 3]),
        at(ball_body, [2.0, 0.5, 0.5]),
    ];
    link.publish_poses(9, 0, query::CONTACTS, &records).unwrap();
    let result = link
        .receive_results_for(9, TIMEOUT)
        .unwrap()
        .expect("a result frame");
    assert!(pair_of(result.records(), solids[0], ball_body).is_none());
}
