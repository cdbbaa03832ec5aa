"""Every control command against a real daemon, every error code a control request can get
back (checked by exception type and code), scene ownership between clients, and the
daemon's instance id."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import numpy as np
import pytest
from support import REPLY_TIMEOUT, connect

from proxima_client import (
    BodySpec,
    BroadPhaseCode,
    Capsule,
    Client,
    Command,
    Cone,
    ControlRequest,
    Cuboid,
    Cylinder,
    DaemonError,
    DaemonLost,
    EmptyGeometryError,
    ErrorCode,
    InvalidShapeError,
    LimitExceededError,
    MalformedMessageError,
    MeshIndexOutOfRangeError,
    Motion,
    NoDaemon,
    NotOwned,
    NotOwnerError,
    ProtocolMismatchError,
    ReplyTimeout,
    ShapeNotReadyError,
    ShapeState,
    Sphere,
    UnexpectedDaemon,
    UnknownBodyError,
    UnknownSceneError,
    UnknownShapeError,
    query,
)
from proxima_client.client import check_reply
from proxima_client.daemon_process import DaemonProcess
from proxima_client.wire import PROTOCOL_VERSION, U32_MAX, reply_flags

#: A unit cube's corners.
CUBE = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


def grid_mesh(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A flat ``n × n`` grid of quads in the XY plane, two triangles each."""
    xs = np.linspace(-1.0, 1.0, n + 1)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b, c, d = a + 1, a + n + 1, a + n + 2
    triangles = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)]).astype(np.uint32)
    return vertices, triangles


def raw(command: int, scene: int = 0, version: int = PROTOCOL_VERSION, **fields: int) -> ControlRequest:
    header = ControlRequest(protocol_version=version, command=int(command), scene=scene)
    for name, value in fields.items():
        setattr(header, name, value)
    return header


# -- connecting -------------------------------------------------------------------------


def test_hello_connects_and_the_daemon_speaks_our_version(client: Client) -> None:
    reply = client.request(raw(Command.HELLO))
    assert (reply.status, reply.id, reply.protocol_version) == (0, PROTOCOL_VERSION, PROTOCOL_VERSION)
    assert client.daemon_is_alive()


def test_connect_without_a_daemon_raises_no_daemon(daemon: DaemonProcess) -> None:
    with pytest.raises(NoDaemon):
        Client.connect(root=daemon.root + "-nobody", iceoryx_prefix=daemon.prefix, reply_timeout=0.3)


def test_a_request_in_another_protocol_version_gets_protocol_mismatch(client: Client) -> None:
    reply = client.request(raw(Command.HELLO, version=PROTOCOL_VERSION - 1))
    assert reply.status == ErrorCode.PROTOCOL_MISMATCH
    assert reply.id == U32_MAX and reply.flags == 0
    assert str(PROTOCOL_VERSION - 1) in reply.reason_text()
    with pytest.raises(ProtocolMismatchError) as caught:
        check_reply(reply)
    assert caught.value.code is ErrorCode.PROTOCOL_MISMATCH
    # The same version mismatch on a real command changes nothing.
    refused = client.request(raw(Command.CREATE_SCENE, version=PROTOCOL_VERSION + 1))
    assert refused.status == 1 and refused.frame_key == 0 and list(refused.scene_token) == [0, 0]
    assert client.scene_access(client.create_scene()) is not None


# -- scenes -----------------------------------------------------------------------------


def test_scenes_are_created_and_dropped_and_a_dropped_scene_is_unknown(client: Client) -> None:
    a, b = client.create_scene(), client.create_scene()
    assert a != b and U32_MAX not in (a, b)
    client.drop_scene(a)
    with pytest.raises(UnknownSceneError) as caught:
        client.drop_scene(a)
    assert caught.value.code is ErrorCode.UNKNOWN_SCENE and str(a) in caught.value.reason
    with pytest.raises(UnknownSceneError):
        client.register_primitive(a, Sphere(1.0))
    client.register_primitive(b, Sphere(1.0))


def test_scenes_beyond_max_scenes_are_refused_with_limit_exceeded(start_daemon) -> None:  # type: ignore[no-untyped-def]
    daemon = start_daemon(["--max-scenes", "1"])
    with connect(daemon) as client:
        scene = client.create_scene()
        with pytest.raises(LimitExceededError) as caught:
            client.create_scene()
        assert caught.value.code is ErrorCode.LIMIT_EXCEEDED
        client.drop_scene(scene)
        client.create_scene()


def test_every_broad_phase_is_accepted_and_an_undefined_one_is_malformed(client: Client) -> None:
    scene = client.create_scene()
    for code in BroadPhaseCode:
        client.set_broad_phase(scene, code)
    reply = client.request(raw(Command.SET_SCENE_PARAMS, scene, broad_phase=len(BroadPhaseCode)))
    with pytest.raises(MalformedMessageError):
        check_reply(reply)
    with pytest.raises(UnknownSceneError):
        client.set_broad_phase(scene + 1, BroadPhaseCode.AUTO)


def test_an_undefined_command_or_a_stray_payload_is_malformed(client: Client) -> None:
    with pytest.raises(MalformedMessageError):
        check_reply(client.request(raw(99)))
    with pytest.raises(MalformedMessageError) as caught:
        check_reply(client.request(raw(Command.CREATE_SCENE), b"\x01\x02"))
    assert "payload" in caught.value.reason


# -- shapes -----------------------------------------------------------------------------


def test_every_primitive_registers_and_is_ready_at_once(client: Client) -> None:
    scene = client.create_scene()
    shapes = [Sphere(0.5), Capsule(0.2, 0.5), Cuboid((0.5, 0.25, 1.0)), Cylinder(0.3, 0.4), Cone(0.3, 0.4)]
    ids = [client.register_primitive(scene, s) for s in shapes]
    assert len(set(ids)) == len(ids)
    assert all(client.shape_state(scene, i) is ShapeState.READY for i in ids)


@pytest.mark.parametrize("shape", [Sphere(-1.0), Sphere(float("nan")), Capsule(0.1, -0.5), Cuboid((1.0, 0.0, -1.0))])
def test_bad_primitive_dimensions_are_invalid_shape(client: Client, shape: object) -> None:
    scene = client.create_scene()
    with pytest.raises(InvalidShapeError) as caught:
        client.register_primitive(scene, shape)  # type: ignore[arg-type]
    assert caught.value.code is ErrorCode.INVALID_SHAPE and caught.value.reason


def test_a_convex_hull_is_built_and_takes_bodies(client: Client) -> None:
    scene = client.create_scene()
    shape = client.register_convex(scene, CUBE * 0.5)
    assert client.shape_state(scene, shape) is ShapeState.READY
    client.add_body(scene, BodySpec(shape=shape))


def test_a_convex_without_points_is_empty_geometry(client: Client) -> None:
    scene = client.create_scene()
    with pytest.raises(EmptyGeometryError) as caught:
        client.register_convex(scene, np.zeros((0, 3)))
    assert caught.value.code is ErrorCode.EMPTY_GEOMETRY


def test_a_mesh_is_built_and_its_state_asked(client: Client) -> None:
    scene = client.create_scene()
    vertices, triangles = grid_mesh(4)
    shape = client.register_mesh(scene, vertices, triangles)
    assert client.shape_state(scene, shape) is ShapeState.READY
    client.add_body(scene, BodySpec(shape=shape, motion=Motion.STATIC))


def test_a_mesh_index_past_the_vertices_is_out_of_range_and_stays_so(client: Client) -> None:
    scene = client.create_scene()
    registration = client.register_mesh_no_wait(scene, CUBE[:4], [[0, 1, 2], [1, 2, 9]])
    with pytest.raises(MeshIndexOutOfRangeError) as caught:
        client.wait_shape(scene, registration.shape)
    assert caught.value.code is ErrorCode.MESH_INDEX_OUT_OF_RANGE
    # A failed build is told the same way each time; bodies cannot use the shape.
    with pytest.raises(MeshIndexOutOfRangeError):
        client.shape_state(scene, registration.shape)
    with pytest.raises(UnknownShapeError):
        client.add_body(scene, BodySpec(shape=registration.shape))


def test_a_mesh_without_triangles_is_empty_geometry(client: Client) -> None:
    scene = client.create_scene()
    with pytest.raises(EmptyGeometryError):
        client.register_mesh(scene, CUBE, np.zeros((0, 3), dtype=np.uint32))


def test_a_geometry_payload_that_disagrees_with_its_counts_is_malformed(client: Client) -> None:
    scene = client.create_scene()
    header = raw(Command.REGISTER_SHAPE, scene, shape_kind=5, vertex_count=8)
    with pytest.raises(MalformedMessageError):
        check_reply(client.request(header, CUBE[:4].tobytes()))


#: The closed mesh of the cube ``CUBE`` (corner ``i`` has bit ``k`` set for ``+1`` on axis
#: ``2 - k``), faces counter-clockwise from outside.
CUBE_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
], dtype=np.uint32)


def test_a_compound_and_a_decomposed_mesh_are_built_and_take_bodies(client: Client) -> None:
    scene = client.create_scene()
    compound = client.register_compound(scene, [CUBE * 0.5, CUBE * 0.5 + [3.0, 0.0, 0.0]])
    decomposed = client.register_decomposed_mesh(scene, CUBE, CUBE_FACES, max_parts=4)
    fast = client.register_decomposed_mesh(scene, CUBE, CUBE_FACES, max_concavity=0.05, fast=True)
    for shape in (compound, decomposed, fast):
        assert client.shape_state(scene, shape) is ShapeState.READY
        client.add_body(scene, BodySpec(shape=shape))


def test_bad_compounds_and_decompositions_get_their_codes(client: Client) -> None:
    scene = client.create_scene()
    with pytest.raises(EmptyGeometryError):
        client.register_compound(scene, [])
    with pytest.raises(MalformedMessageError):
        client.register_compound(scene, [np.zeros((0, 3)), CUBE])
    with pytest.raises(LimitExceededError):
        client.register_compound(scene, [CUBE[:1]] * 1025)
    with pytest.raises(InvalidShapeError):
        client.register_decomposed_mesh(scene, CUBE, CUBE_FACES, max_concavity=-1.0)
    with pytest.raises(InvalidShapeError):
        client.register_decomposed_mesh(scene, CUBE, CUBE_FACES, max_parts=2000)
    # One triangle encloses no volume.
    with pytest.raises(InvalidShapeError):
        client.register_decomposed_mesh(scene, CUBE, CUBE_FACES[:1])


def test_a_mesh_still_building_refuses_add_body_with_shape_not_ready(client: Client) -> None:
    scene = client.create_scene()
    # AddBody follows the registration's reply within a millisecond or so; a mesh whose
    # build takes longer is refused. Start small and grow until the build outlasts it,
    # so the test does not depend on how fast this machine builds.
    n = 24
    while True:
        vertices, triangles = grid_mesh(n)
        registration = client.register_mesh_no_wait(scene, vertices, triangles)
        assert not registration.ready  # a mesh is always built after the reply
        try:
            client.add_body(scene, BodySpec(shape=registration.shape))
        except ShapeNotReadyError as e:
            assert e.code is ErrorCode.SHAPE_NOT_READY
            break
        assert n < 400, "even a 320,000-triangle mesh was built before AddBody arrived"
        n *= 2
    client.wait_shape(scene, registration.shape)
    assert client.shape_state(scene, registration.shape) is ShapeState.READY
    client.add_body(scene, BodySpec(shape=registration.shape))


def test_shape_state_of_an_id_never_handed_out_is_unknown_shape(client: Client) -> None:
    scene = client.create_scene()
    with pytest.raises(UnknownShapeError):
        client.shape_state(scene, 42)
    reply = client.request(raw(Command.SHAPE_STATE, scene, target=42))
    assert reply.status == ErrorCode.UNKNOWN_SHAPE and not reply.flags & reply_flags.SHAPE_BUILDING


# -- bodies -----------------------------------------------------------------------------


def test_bodies_are_added_updated_and_removed(client: Client) -> None:
    scene = client.create_scene()
    shape = client.register_primitive(scene, Sphere(0.5))
    a = client.add_body(scene, BodySpec(shape=shape, position=(0.0, 0.0, 0.0), margin=0.1))
    b = client.add_body(scene, BodySpec(shape=shape, position=(2.0, 0.0, 0.0), motion=Motion.STATIC))
    assert a != b
    client.update_body(scene, a, Motion.KINEMATIC, 2, 0xFFFF, None)
    client.remove_body(scene, a)
    with pytest.raises(UnknownBodyError) as caught:
        client.remove_body(scene, a)
    assert caught.value.code is ErrorCode.UNKNOWN_BODY
    with pytest.raises(UnknownBodyError):
        client.update_body(scene, a, Motion.DYNAMIC, 1, 1, 0.0)


def test_a_body_on_an_unknown_shape_is_unknown_shape(client: Client) -> None:
    scene = client.create_scene()
    with pytest.raises(UnknownShapeError) as caught:
        client.add_body(scene, BodySpec(shape=7))
    assert caught.value.code is ErrorCode.UNKNOWN_SHAPE


def test_a_body_with_an_undefined_motion_is_malformed(client: Client) -> None:
    scene = client.create_scene()
    shape = client.register_primitive(scene, Sphere(0.5))
    header = raw(Command.ADD_BODY, scene, target=shape, motion=7)
    header.orientation[3] = 1.0
    with pytest.raises(DaemonError) as caught:
        check_reply(client.request(header))
    assert caught.value.code is ErrorCode.MALFORMED_MESSAGE


def test_a_body_with_a_nan_initial_pose_is_refused(client: Client) -> None:
    scene = client.create_scene()
    shape = client.register_primitive(scene, Sphere(0.5))
    with pytest.raises(DaemonError) as caught:
        client.add_body(scene, BodySpec(shape=shape, position=(float("nan"), 0.0, 0.0)))
    assert caught.value.code is ErrorCode.INVALID_POSE


# -- ownership --------------------------------------------------------------------------


def test_a_second_client_gets_not_owner_on_the_first_clients_scene(daemon: DaemonProcess, client: Client) -> None:
    scene = client.create_scene()
    shape = client.register_primitive(scene, Sphere(0.5))
    body = client.add_body(scene, BodySpec(shape=shape))
    with connect(daemon) as other:
        for command in (
            lambda: other.register_primitive(scene, Sphere(1.0)),
            lambda: other.shape_state(scene, shape),
            lambda: other.add_body(scene, BodySpec(shape=shape)),
            lambda: other.update_body(scene, body, Motion.STATIC, 1, 1, None),
            lambda: other.remove_body(scene, body),
            lambda: other.set_broad_phase(scene, BroadPhaseCode.AUTO),
            lambda: other.drop_scene(scene),
        ):
            with pytest.raises(NotOwnerError) as caught:
                command()
            assert caught.value.code is ErrorCode.NOT_OWNER and str(scene) in caught.value.reason
        # Its own scenes are its own; an id that names no scene is unknown, not foreign.
        mine = other.create_scene()
        other.register_primitive(mine, Sphere(1.0))
        with pytest.raises(NotOwnerError):
            client.drop_scene(mine)
        with pytest.raises(UnknownSceneError):
            other.drop_scene(next(i for i in range(3) if i not in (scene, mine)))
    # Nothing the other client tried changed the owner's scene.
    client.update_body(scene, body, Motion.KINEMATIC, 1, 1, None)
    client.remove_body(scene, body)


def test_only_the_creator_opens_a_scene_and_forgets_it_once_dropped(daemon: DaemonProcess, client: Client) -> None:
    scene = client.create_scene()
    access = client.scene_access(scene)
    assert access is not None and access.scene == scene
    assert access.frame_key != 0 and access.token.words != (0, 0)
    assert str(access.token) not in repr(access), "the keys stay out of logs"
    with connect(daemon) as other:
        with pytest.raises(NotOwned) as caught:
            other.open_scene(scene)
        assert caught.value.scene == scene and other.scene_access(scene) is None
    client.open_scene(scene).close()
    client.drop_scene(scene)
    assert client.scene_access(scene) is None
    with pytest.raises(NotOwned):
        client.open_scene(scene)


# -- the daemon's instance id -----------------------------------------------------------


def test_the_instance_id_is_the_same_in_every_reply_and_result_header(start_daemon) -> None:  # type: ignore[no-untyped-def]
    first, second = start_daemon(), start_daemon()
    with connect(first) as client, connect(second) as other:
        instance = client.daemon_instance
        assert instance != 0 and other.daemon_instance not in (0, instance)
        assert client.request(raw(Command.HELLO)).instance == instance
        refused = client.request(raw(Command.SHAPE_STATE, scene=7))
        assert refused.status == ErrorCode.UNKNOWN_SCENE and refused.instance == instance
        scene = client.create_scene()
        access = client.scene_access(scene)
        assert access is not None and access.instance == instance
        shape = client.register_primitive(scene, Sphere(0.5))
        body = client.add_body(scene, BodySpec(shape=shape))
        with client.open_scene(scene) as link:
            link.publish(1, 0, query.CLOSE, [body], [(0.0, 0.0, 0.0)])
            frame = link.receive_results_for(1, REPLY_TIMEOUT)
            assert frame is not None
            with frame:
                frame.raise_for_status()
                assert frame.header.instance == instance


def test_expect_instance_connects_only_to_that_daemon(start_daemon, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "instance"
    daemon = start_daemon(["--instance-file", str(path)])
    with connect(daemon) as client:
        # Written before the daemon serves, so before Hello is answered.
        instance = int(path.read_text().strip(), 16)
        assert instance == client.daemon_instance
    assert path.stat().st_mode & 0o777 == 0o600
    with connect(daemon, expect_instance=instance) as same:
        assert same.daemon_instance == instance
    with pytest.raises(UnexpectedDaemon) as caught:
        connect(daemon, expect_instance=instance ^ 1)
    assert caught.value.instance == instance


# -- the daemon going away --------------------------------------------------------------


def test_a_stopped_daemon_times_out_and_a_killed_one_is_lost(daemon: DaemonProcess) -> None:
    client = connect(daemon, reply_timeout=0.5)
    scene = client.create_scene()
    assert daemon.pid is not None
    os.kill(daemon.pid, signal.SIGSTOP)
    try:
        with pytest.raises(ReplyTimeout):
            client.create_scene()
        assert client.daemon_is_alive()
    finally:
        os.kill(daemon.pid, signal.SIGCONT)
    client.reply_timeout = REPLY_TIMEOUT
    client.register_primitive(scene, Sphere(1.0))
    # A killed daemon's port stays listed until its node is cleaned up: the request waits
    # out the reply timeout, then finds the daemon gone.
    client.reply_timeout = 1.0
    daemon.kill()
    with pytest.raises(DaemonLost):
        client.create_scene()
    assert not client.daemon_is_alive()
    client.close()
