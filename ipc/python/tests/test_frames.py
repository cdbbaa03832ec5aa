"""Pose frames published from numpy, result frames read as structured arrays, checked
against analytic answers; every error a frame's status can carry; frames without the
scene's frame key, and monitors reading a scene's results by its token."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
from support import FRAME_TIMEOUT, connect

from proxima_client import (
    POSE_DTYPE,
    RESULT_DTYPE,
    BodySpec,
    Client,
    Completeness,
    Cuboid,
    ErrorCode,
    InvalidPoseError,
    MalformedMessageError,
    Motion,
    NoSuchScene,
    NotOwned,
    NotOwnerError,
    PoseFrameHeader,
    ProtocolMismatchError,
    RecordKind,
    ResultFrame,
    SceneAccess,
    SceneLink,
    SceneReleasedError,
    SceneToken,
    Sphere,
    TransportError,
    UnknownBodyError,
    UnknownSceneError,
    frame_flags,
    pose_array,
    query,
)
from proxima_client import scene_link
from proxima_client.daemon_process import DaemonProcess
from proxima_client.transport import now
from proxima_client.wire import PROTOCOL_VERSION, U32_MAX

#: How long a test waits to be sure a frame is not answered, s.
UNANSWERED_WAIT = 0.5

IDENTITY = (0.0, 0.0, 0.0, 1.0)


@dataclass
class Spheres:
    """A scene of spheres and its link."""

    client: Client
    scene: int
    link: SceneLink
    bodies: list[int]


def spheres(client: Client, radii: list[float], positions: list[tuple[float, float, float]],
            margin: float = 0.5) -> Spheres:
    scene = client.create_scene()
    bodies = []
    for radius, position in zip(radii, positions):
        shape = client.register_primitive(scene, Sphere(radius))
        bodies.append(client.add_body(scene, BodySpec(shape=shape, position=position, margin=margin)))
    return Spheres(client, scene, client.open_scene(scene), bodies)


def answer(link: SceneLink, seq: int, flags: int, ids: list[int], positions: list[tuple[float, float, float]],
           orientations: object = None) -> ResultFrame:
    link.publish(seq, 0, flags, ids, positions, orientations)
    frame = link.receive_results_for(seq, FRAME_TIMEOUT)
    assert frame is not None, f"no answer to frame {seq}"
    return frame


def sphere_pair(pa: np.ndarray, ra: float, pb: np.ndarray, rb: float) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Distance, normal A→B and witness points of two spheres."""
    d = pb - pa
    length = float(np.linalg.norm(d))
    normal = d / length
    return length - ra - rb, normal, pa + normal * ra, pb - normal * rb


# -- analytic answers -------------------------------------------------------------------


def test_two_spheres_at_a_known_distance_give_distance_normal_and_witnesses(client: Client) -> None:
    pa, pb = np.array([1.0, 2.0, 3.0]), np.array([1.0 + 0.6, 2.0 + 0.8, 3.0])  # 1.0 apart
    s = spheres(client, [0.25, 0.45], [tuple(pa), (9.0, 9.0, 9.0)])
    with answer(s.link, 1, query.CLOSE, s.bodies, [tuple(pa), tuple(pb)]) as frame:
        frame.raise_for_status()
        assert frame.ok and frame.exact and frame.frame_seq == 1
        assert frame.header.protocol_version == PROTOCOL_VERSION and frame.header.error_body == U32_MAX
        assert (frame.header.pair_count, frame.header.contact_count, frame.header.toi_count) == (1, 0, 0)
        assert frame.records.dtype == RESULT_DTYPE and len(frame.records) == 1
        pair = frame.pairs[0]
        distance, normal, point_a, point_b = sphere_pair(pa, 0.25, pb, 0.45)
        assert pair["kind"] == RecordKind.PAIR
        assert (pair["body_a"], pair["body_b"]) == (s.bodies[0], s.bodies[1])
        assert pair["distance"] == pytest.approx(distance, abs=1e-12)
        assert pair["distance"] == pytest.approx(0.3, abs=1e-12)
        np.testing.assert_allclose(pair["normal"], normal, atol=1e-12)
        np.testing.assert_allclose(pair["point_a"], point_a, atol=1e-12)
        np.testing.assert_allclose(pair["point_b"], point_b, atol=1e-12)
        assert pair["time"] == 0.0 and pair["count"] == 0 and pair["flags"] == 0
        assert len(frame.contacts) == 0 and len(frame.tois) == 0


def test_overlapping_spheres_give_one_contact_at_the_depth(client: Client) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (5.0, 0.0, 0.0)], margin=0.0)
    with answer(s.link, 1, query.CLOSE | query.CONTACTS, s.bodies, [(0.0, 0.0, 0.0), (0.0, 0.0, 0.8)]) as frame:
        assert (len(frame.pairs), len(frame.contacts)) == (1, 1)
        pair, contact = frame.pairs[0], frame.contacts[0]
        assert pair["distance"] == pytest.approx(-0.2, abs=1e-12)
        assert (pair["index"], pair["count"]) == (0, 1)
        assert frame.contacts_of(pair)[0] == contact
        assert contact["kind"] == RecordKind.CONTACT and contact["index"] == 0 and contact["count"] == 0
        assert contact["distance"] == pytest.approx(-0.2, abs=1e-12)
        np.testing.assert_allclose(contact["normal"], [0.0, 0.0, 1.0], atol=1e-12)
        np.testing.assert_allclose(contact["point_a"], [0.0, 0.0, 0.5], atol=1e-12)
        np.testing.assert_allclose(contact["point_b"], [0.0, 0.0, 0.3], atol=1e-12)


def test_a_sphere_passing_through_another_gives_its_time_of_impact(client: Client) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (5.0, 0.0, 0.0)], margin=0.0)
    with answer(s.link, 1, query.CLOSE, s.bodies[1:], [(5.0, 0.0, 0.0)]) as frame:
        assert len(frame.records) == 0  # 4 m apart: nothing close
    # From x = 5 to x = -5 in one frame: the spheres first touch at x = 1, 40 % along.
    with answer(s.link, 2, query.TOI, s.bodies[1:], [(-5.0, 0.0, 0.0)]) as frame:
        assert (frame.header.pair_count, frame.header.toi_count) == (0, 1)
        toi = frame.tois[0]
        assert toi["kind"] == RecordKind.TOI and toi["count"] == 1
        assert toi["time"] <= 0.4 + 1e-12
        assert toi["time"] == pytest.approx(0.4, abs=1e-5)
        assert 0.0 <= toi["distance"] <= toi["error_bound"] + 1e-12
        np.testing.assert_allclose(toi["normal"], [1.0, 0.0, 0.0], atol=1e-6)


def test_random_sphere_pairs_match_the_closed_form_hits_and_misses_alike(client: Client) -> None:
    rng = np.random.default_rng(2024)
    pairs = 40
    margin = 0.2
    radii = rng.uniform(0.1, 1.0, (pairs, 2))
    gaps = rng.uniform(-0.3, 1.0, pairs)  # hits (gap ≤ 2·margin) and misses
    directions = rng.normal(size=(pairs, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    centres = np.stack([np.arange(pairs) * 10.0, np.zeros(pairs), np.zeros(pairs)], 1)  # far apart
    pa = centres
    pb = centres + directions * (radii.sum(1) + gaps)[:, None]
    s = spheres(client, list(radii.ravel()), [tuple(p) for p in np.stack([pa, pb], 1).reshape(-1, 3)], margin)
    ids = np.array(s.bodies, dtype=np.uint32)
    positions = np.stack([pa, pb], 1).reshape(-1, 3)
    with answer(s.link, 1, query.CLOSE | query.CONTACTS, list(ids), positions) as frame:
        reported = {(int(p["body_a"]), int(p["body_b"])): p for p in frame.pairs}
        hits = misses = 0
        for k in range(pairs):
            key = (int(ids[2 * k]), int(ids[2 * k + 1]))
            distance, normal, point_a, point_b = sphere_pair(pa[k], radii[k, 0], pb[k], radii[k, 1])
            if distance <= 2 * margin:
                hits += 1
                pair = reported.pop(key)
                assert pair["distance"] == pytest.approx(distance, abs=1e-9)
                np.testing.assert_allclose(pair["normal"], normal, atol=1e-9)
                np.testing.assert_allclose(pair["point_a"], point_a, atol=1e-9)
                np.testing.assert_allclose(pair["point_b"], point_b, atol=1e-9)
                assert len(frame.contacts_of(pair)) == (1 if distance <= 0 else 0)
            else:
                misses += 1
                assert key not in reported
        assert not reported, f"pairs reported that are not close: {list(reported)}"
        assert hits >= 10 and misses >= 10, (hits, misses)


# -- publishing from numpy --------------------------------------------------------------


def test_every_way_of_publishing_writes_the_same_frame(client: Client) -> None:
    s = spheres(client, [0.5] * 4, [(float(3 * i), 0.0, 0.0) for i in range(4)], margin=0.0)
    ids = np.array(s.bodies, dtype=np.uint32)
    positions = np.array([[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [5.0, 0.0, 0.0], [5.0, 0.95, 0.0]])
    angle = 0.3
    orientations = np.tile([0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)], (4, 1))
    flags = query.CLOSE | query.CONTACTS
    other = np.zeros(4, dtype=[("orientation", "<f8", 4), ("position", "<f8", 3), ("body", "<i8")])
    other["body"], other["position"], other["orientation"] = ids, positions, orientations

    def by_loan(seq: int) -> None:
        with s.link.loan_frame(seq, 0, flags, 4) as pending:
            pending.poses["body"] = ids
            pending.poses["reserved"] = 0
            pending.poses["position"] = positions
            pending.poses["orientation"] = orientations

    ways = [
        lambda seq: s.link.publish(seq, 0, flags, ids, positions, orientations),
        lambda seq: s.link.publish_poses(seq, 0, flags, pose_array(ids, positions, orientations)),
        lambda seq: s.link.publish_poses(seq, 0, flags, other),
        by_loan,
    ]
    results = []
    # One frame at a time: the daemon keeps only the newest frames of a burst.
    for seq, publish in enumerate(ways, start=1):
        publish(seq)
        copy = s.link.receive_copy_for(seq, FRAME_TIMEOUT)
        assert copy is not None and copy.ok
        results.append(copy.records)
    assert len(results[0]) == 4  # two pairs, a contact each
    for other_records in results[1:]:
        assert other_records.tobytes() == results[0].tobytes()


def test_one_array_updated_in_place_and_two_arrays_in_turn_each_send_their_current_poses(client: Client) -> None:
    # The link remembers the address of the array it sent last: every frame must still
    # carry what the array holds now, and another array's frame that array's poses.
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (5.0, 0.0, 0.0)], margin=5.0)
    ids = np.array(s.bodies, dtype=np.uint32)
    moving = pose_array(ids, [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    parked = pose_array(ids, [[0.0, 0.0, 0.0], [0.0, 0.0, 0.8]])
    seen = []
    for seq, (poses, x) in enumerate([(moving, 3.0), (moving, 2.0), (parked, None), (moving, 0.9),
                                      (parked, None), (moving, 4.0)], start=1):
        if x is not None:
            poses["position"][1, 0] = x
        s.link.publish_poses(seq, 0, query.CLOSE, poses)
        copy = s.link.receive_copy_for(seq, FRAME_TIMEOUT)
        assert copy is not None and copy.ok and len(copy.pairs) == 1
        seen.append(float(copy.pairs[0]["distance"]))
    np.testing.assert_allclose(seen, [2.0, 1.0, -0.2, -0.1, -0.2, 3.0], atol=1e-12)


@pytest.mark.parametrize("staged_max", [4096, 0])
def test_field_frames_carry_each_frames_orientations_and_sizes(client: Client, staged_max: int,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    # `publish` gathers small frames in a staging array it keeps (identity orientations
    # written only when the last frame had others): each frame must still carry its own
    # orientations, identity when none are given, and its own bodies. With a staging
    # limit of 0 every frame is written straight into the sample instead.
    monkeypatch.setattr(scene_link, "_STAGED_MAX_POSES", staged_max)
    scene = client.create_scene()
    small = client.register_primitive(scene, Cuboid((0.1, 0.1, 0.1)))
    long = client.register_primitive(scene, Cuboid((1.0, 0.1, 0.1)))
    a = client.add_body(scene, BodySpec(shape=small, position=(0.0, 0.0, 0.0), margin=5.0))
    b = client.add_body(scene, BodySpec(shape=long, position=(2.0, 0.0, 0.0), margin=5.0))
    link = client.open_scene(scene)
    quarter_turn = [0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)]
    both = np.array([a, b], dtype=np.uint32)
    centres = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    frames = [
        (both, centres, np.array([IDENTITY, quarter_turn]), 1.8),  # B turned: 0.1 deep in x
        (both, centres, None, 0.9),  # identity again: B reaches to x = 1
        (both, centres, np.array([IDENTITY, quarter_turn]), 1.8),
        (both[1:], centres[1:] + [0.5, 0.0, 0.0], None, 1.4),  # one body, B moved, A kept
        (both, centres, None, 0.9),
    ]
    for seq, (ids, positions, orientations, distance) in enumerate(frames, start=1):
        link.publish(seq, 0, query.CLOSE, ids, positions, orientations)
        copy = link.receive_copy_for(seq, FRAME_TIMEOUT)
        assert copy is not None and copy.ok and len(copy.pairs) == 1, f"frame {seq}"
        assert float(copy.pairs[0]["distance"]) == pytest.approx(distance, abs=1e-9), f"frame {seq}"


def test_a_frame_number_budget_or_flags_out_of_range_is_refused_before_sending(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    poses = pose_array(np.array(s.bodies, dtype=np.uint32), [[0.0, 0.0, 0.0]])
    for seq, budget, flags in [(-1, 0, query.CLOSE), (1, 1 << 64, query.CLOSE), (1, 0, 1 << 32)]:
        with pytest.raises(ValueError):
            s.link.publish_poses(seq, budget, flags, poses)
    s.link.publish_poses(1, 0, query.CLOSE, poses)
    assert s.link.receive_results_for(1, FRAME_TIMEOUT) is not None


def test_pose_arrays_are_checked_before_anything_is_loaned(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    with pytest.raises(ValueError):
        s.link.publish(1, 0, query.CLOSE, [s.bodies[0]], [[0.0, 0.0]])
    with pytest.raises(ValueError):
        s.link.publish(1, 0, query.CLOSE, [s.bodies[0]], [[0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    with pytest.raises(ValueError):
        s.link.publish_poses(1, 0, query.CLOSE, np.zeros(3, dtype=[("body", "<u4")]))
    s.link.publish(1, 0, query.CLOSE, [s.bodies[0]], [[0.0, 0.0, 0.0]])
    assert s.link.receive_results_for(1, FRAME_TIMEOUT) is not None


# -- zero copy, copies and holding ------------------------------------------------------


def test_records_are_a_read_only_view_until_released_and_copies_live_on(client: Client) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)], margin=0.0)
    frame = answer(s.link, 1, query.CLOSE | query.CONTACTS, s.bodies, [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)])
    assert frame.held
    records = frame.records
    assert not records.flags.owndata and not records.flags.writeable
    with pytest.raises(ValueError):
        records["distance"][0] = 1.0
    owned = frame.copy()
    assert owned.records.flags.owndata
    assert owned.records.tobytes() == records.tobytes()
    assert owned.header.pair_count == frame.header.pair_count
    frame.release()
    assert not frame.held and len(frame.records) == 0
    frame.release()  # idempotent
    assert owned.pairs[0]["distance"] == pytest.approx(-0.1, abs=1e-12)
    assert len(owned.contacts_of(owned.pairs[0])) == 1


def test_a_subscriber_lends_two_frames_and_refuses_the_third(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    held = [answer(s.link, seq, query.CLOSE, s.bodies, [(0.0, 0.0, 0.0)]) for seq in (1, 2)]
    s.link.publish(3, 0, query.CLOSE, s.bodies, [(0.0, 0.0, 0.0)])
    with pytest.raises(TransportError):
        s.link.receive_results_for(3, FRAME_TIMEOUT)
    held[0].release()
    frame = s.link.receive_results_for(3, FRAME_TIMEOUT)
    assert frame is not None and frame.frame_seq == 3


def test_no_frame_published_means_none_after_the_timeout(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    assert s.link.receive_results(0.05) is None
    assert s.link.try_receive_results() is None


# -- frame errors: the status of the answer ---------------------------------------------


def test_a_nan_pose_is_invalid_pose_naming_the_body(client: Client) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (3.0, 0.0, 0.0)])
    with answer(s.link, 1, query.CLOSE, s.bodies, [(0.0, 0.0, 0.0), (float("nan"), 0.0, 0.0)]) as frame:
        assert frame.status is ErrorCode.INVALID_POSE and not frame.ok
        assert frame.header.error_body == s.bodies[1] and len(frame.records) == 0
        with pytest.raises(InvalidPoseError) as caught:
            frame.raise_for_status()
        assert caught.value.code is ErrorCode.INVALID_POSE and caught.value.body == s.bodies[1]


def test_a_non_unit_quaternion_is_invalid_pose(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    with answer(s.link, 1, query.CLOSE, s.bodies, [(0.0, 0.0, 0.0)], [(0.0, 0.0, 0.0, 2.0)]) as frame:
        assert frame.status is ErrorCode.INVALID_POSE


def test_a_pose_for_an_unknown_body_is_unknown_body(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    with answer(s.link, 1, query.CLOSE, [s.bodies[0] + 10], [(0.0, 0.0, 0.0)]) as frame:
        with pytest.raises(UnknownBodyError) as caught:
            frame.raise_for_status()
        assert caught.value.body == s.bodies[0] + 10


@pytest.mark.parametrize("flags", [0, 1 << 7], ids=["no-flag", "undefined-bit"])
def test_a_frame_asking_nothing_or_undefined_is_malformed(client: Client, flags: int) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    with answer(s.link, 1, flags, s.bodies, [(0.0, 0.0, 0.0)]) as frame:
        with pytest.raises(MalformedMessageError) as caught:
            frame.raise_for_status()
        assert caught.value.code is ErrorCode.MALFORMED_MESSAGE and caught.value.body is None


def _raw_answer(s: Spheres, header: PoseFrameHeader, poses: np.ndarray) -> ResultFrame:
    s.link.publish_raw(header, poses)
    frame = s.link.receive_results_for(header.frame_seq, FRAME_TIMEOUT)
    assert frame is not None
    return frame


def test_raw_frames_with_a_bad_count_version_or_scene_are_refused(client: Client) -> None:
    s = spheres(client, [0.5], [(0.0, 0.0, 0.0)])
    poses = pose_array(s.bodies, [(0.0, 0.0, 0.0)])

    def header(seq: int, **fields: int) -> PoseFrameHeader:
        h = PoseFrameHeader(protocol_version=PROTOCOL_VERSION, scene=s.scene, frame_seq=seq,
                            budget_ns=0, query_flags=query.CLOSE, count=1,
                            frame_key=s.link.access.frame_key)
        for name, value in fields.items():
            setattr(h, name, value)
        return h

    with _raw_answer(s, header(1, count=2), poses) as frame:
        with pytest.raises(MalformedMessageError):
            frame.raise_for_status()
    with _raw_answer(s, header(2, protocol_version=PROTOCOL_VERSION + 1), poses) as frame:
        with pytest.raises(ProtocolMismatchError):
            frame.raise_for_status()
    with _raw_answer(s, header(3, scene=(s.scene + 5) & U32_MAX), poses) as frame:
        with pytest.raises(UnknownSceneError):
            frame.raise_for_status()
    with _raw_answer(s, header(4), poses) as frame:
        frame.raise_for_status()
        assert frame.header.completeness == Completeness.EXACT


def test_a_refused_frame_leaves_the_poses_unchanged(client: Client) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)], margin=0.0)
    with answer(s.link, 1, 0, s.bodies, [(0.0, 0.0, 0.0), (5.0, 0.0, 0.0)]) as frame:
        assert frame.status is ErrorCode.MALFORMED_MESSAGE
    # Body 1 was not moved to x = 5 by the refused frame: still touching body 0.
    with answer(s.link, 2, query.CLOSE, s.bodies[:1], [(0.0, 0.0, 0.0)]) as frame:
        assert len(frame.pairs) == 1 and frame.pairs[0]["distance"] == pytest.approx(-0.1, abs=1e-12)


def test_static_bodies_never_pair_with_each_other(client: Client) -> None:
    scene = client.create_scene()
    shape = client.register_primitive(scene, Sphere(0.5))
    a = client.add_body(scene, BodySpec(shape=shape, motion=Motion.STATIC))
    b = client.add_body(scene, BodySpec(shape=shape, position=(0.5, 0.0, 0.0), motion=Motion.STATIC))
    c = client.add_body(scene, BodySpec(shape=shape, position=(0.0, 0.5, 0.0)))
    link = client.open_scene(scene)
    with answer(link, 1, query.OVERLAP, [c], [(0.0, 0.5, 0.0)]) as frame:
        assert sorted((int(p["body_a"]), int(p["body_b"])) for p in frame.pairs) == [(a, c), (b, c)]


# -- frame keys and tokens --------------------------------------------------------------


def test_a_frame_without_the_scenes_frame_key_is_not_answered_and_changes_nothing(
    daemon: DaemonProcess, client: Client
) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (5.0, 0.0, 0.0)], margin=0.0)
    access = s.link.access
    # Another client that learned the token, not the frame key, publishes to the scene.
    forged = SceneAccess(scene=s.scene, token=access.token, frame_key=access.frame_key ^ 1,
                         instance=access.instance)
    with connect(daemon) as intruder, SceneLink(intruder.node, intruder.root, forged) as link:
        link.publish(1, 0, query.CLOSE, s.bodies[1:], [(0.9, 0.0, 0.0)])  # would touch body 0
        assert link.receive_results_for(1, UNANSWERED_WAIT) is None
    assert s.link.receive_results_for(1, UNANSWERED_WAIT) is None
    # The owner's next frame is answered, and body 1 is still where the owner put it.
    with answer(s.link, 2, query.CLOSE, s.bodies[:1], [(0.0, 0.0, 0.0)]) as frame:
        frame.raise_for_status()
        assert len(frame.pairs) == 0
    # The same with the owner's own link and a raw header carrying another key.
    header = PoseFrameHeader(protocol_version=PROTOCOL_VERSION, scene=s.scene, frame_seq=3, budget_ns=0,
                             query_flags=query.CLOSE, count=1, frame_key=access.frame_key + 1)
    s.link.publish_raw(header, pose_array(s.bodies[1:], [(0.9, 0.0, 0.0)]))
    assert s.link.receive_results_for(3, UNANSWERED_WAIT) is None
    with answer(s.link, 4, query.CLOSE, s.bodies[:1], [(0.0, 0.0, 0.0)]) as frame:
        assert frame.ok and len(frame.pairs) == 0


def test_a_monitor_opens_the_results_with_the_owners_token_and_sees_the_owners_frames(
    daemon: DaemonProcess, client: Client
) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)], margin=0.0)
    token = s.link.access.token
    with connect(daemon) as monitor, monitor.open_result_feed(token) as feed:
        with answer(s.link, 1, query.CLOSE | query.CONTACTS, s.bodies, [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)]) as frame:
            owners = frame.copy()
        seen = feed.receive_for(1, FRAME_TIMEOUT)
        assert seen is not None
        with seen:
            assert seen.header.instance == monitor.daemon_instance == client.daemon_instance
            assert (seen.header.pair_count, seen.header.contact_count) == (1, 1)
            assert seen.records.tobytes() == owners.records.tobytes()
        # Reading is all the token allows.
        with pytest.raises(NotOwned):
            monitor.open_scene(s.scene)
        with pytest.raises(NotOwnerError):
            monitor.drop_scene(s.scene)


def test_a_monitor_learns_from_the_last_frame_that_the_owner_dropped_the_scene(
    daemon: DaemonProcess, client: Client
) -> None:
    s = spheres(client, [0.5, 0.5], [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)], margin=0.0)
    with connect(daemon) as monitor, monitor.open_result_feed(s.link.access.token) as feed:
        with answer(s.link, 1, query.CLOSE, s.bodies, [(0.0, 0.0, 0.0), (0.9, 0.0, 0.0)]) as frame:
            assert not frame.header.flags & frame_flags.OWNER_GONE
        seen = feed.receive_for(1, FRAME_TIMEOUT)
        assert seen is not None
        seen.release()
        client.drop_scene(s.scene)
        with pytest.raises(SceneReleasedError) as released:
            feed.receive(FRAME_TIMEOUT)
        assert released.value.code == ErrorCode.SCENE_RELEASED
        assert not released.value.owner_gone


def test_a_token_no_scene_has_opens_nothing(client: Client) -> None:
    with pytest.raises(NoSuchScene):
        client.open_result_feed(SceneToken((1, 2)))
    scene = client.create_scene()
    token = client.scene_access(scene).token  # type: ignore[union-attr]
    client.open_result_feed(token).close()
    client.drop_scene(scene)
    # The daemon lets go of the scene's services after the reply: wait for them to go.
    deadline = now() + FRAME_TIMEOUT
    while True:
        try:
            client.open_result_feed(token).close()
        except NoSuchScene:
            break
        assert now() < deadline, "the dropped scene's services outlived it"
