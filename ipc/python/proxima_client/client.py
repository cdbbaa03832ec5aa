"""The control half of the client, mirroring ``ipc/src/client.rs``: connect to a
``proximad``, create scenes, register shapes, add, remove and update bodies.

.. code-block:: python

    from proxima_client import BodySpec, Client, Sphere

    with Client.connect(root="proxima") as client:
        scene = client.create_scene()
        ball = client.register_primitive(scene, Sphere(0.1))
        body = client.add_body(scene, BodySpec(shape=ball, position=(0.0, 0.0, 1.0)))
        client.remove_body(scene, body)
        client.drop_scene(scene)

Each call is one request on ``<root>/control`` and one reply, waited for up to the reply
timeout. Request–response ports cannot join a WaitSet (nor be waited on from Python), so
the reply is polled: a short spin, then sleeps (:mod:`~proxima_client.transport`). After
each request the client notifies ``<root>/control-events`` (event id 3), which wakes a
daemon blocked in its WaitSet.

**Shapes that take time to build.** Convex and mesh shapes are built by the daemon after
their registration is answered. :meth:`Client.register_convex` and
:meth:`Client.register_mesh` wait for the build (asking ``ShapeState``); the ``_no_wait``
variants return at once, and :meth:`Client.add_body` on a shape not built yet raises
:class:`~proxima_client.errors.ShapeNotReadyError`.

**Scenes are private.** A scene belongs to the client port that created it: other
clients' requests naming it raise :class:`~proxima_client.errors.NotOwnerError`. The
client keeps each scene's keys from its ``CreateScene`` reply (:meth:`Client.scene_access`:
the frame key its frames carry, the token that names its services), so only it can
:meth:`~Client.open_scene`; it may share the token with a monitor, which opens the
results alone (:meth:`Client.open_result_feed`).

**When the daemon goes away.** A client is bound to the daemon that answered its
``Hello``, and to its instance id, which every reply carries. Once that daemon is gone
(crashed, or replaced by a restart), requests raise
:class:`~proxima_client.errors.DaemonLost`: at once if no daemon serves the control
service, when the reply comes from another daemon (another server port or instance id),
or at the reply timeout.
"""

from __future__ import annotations

import ctypes
import time
from dataclasses import dataclass
from enum import Enum
from typing import Any, Callable, Optional, Sequence, Union

import iceoryx2 as iox
import numpy as np

from . import services
from .errors import (
    BuildTimeout,
    DaemonLost,
    NoDaemon,
    NotOwned,
    ProtocolMismatchError,
    ReplyTimeout,
    TransportError,
    UnexpectedDaemon,
    error_for,
)
from .result_feed import ResultFeed
from .scene_link import SceneAccess, SceneLink
from .services import SceneToken
from .transport import SHAPE_POLL_FIRST_S, SHAPE_POLL_MAX_S, now, poll_until, release_ports
from .wire import (
    PROTOCOL_VERSION,
    U32_MAX,
    BroadPhaseCode,
    Command,
    ControlReply,
    ControlRequest,
    ErrorCode,
    MotionCode,
    ShapeKindCode,
    reply_flags,
)

#: The default reply timeout, seconds.
DEFAULT_REPLY_TIMEOUT: float = 2.0
#: The default build timeout, seconds: long enough for the largest mesh the daemon admits.
DEFAULT_BUILD_TIMEOUT: float = 600.0
#: How long connect waits for the first ``Hello``'s reply before it sends ``Hello`` again
#: from a fresh port (a port whose connection failed on a loaded host stays unheard); each
#: further wait doubles.
FIRST_HELLO_WAIT: float = 0.25

#: How a body moves (an alias of :class:`~proxima_client.wire.MotionCode`).
Motion = MotionCode


@dataclass(frozen=True)
class Sphere:
    """A ball about the origin; ``radius`` in metres."""

    radius: float

    def to_wire(self) -> tuple[ShapeKindCode, tuple[float, float, float, float]]:
        """The wire kind and ``dimensions``."""
        return ShapeKindCode.SPHERE, (self.radius, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Capsule:
    """A segment from ``-half_height`` to ``+half_height`` on local Z, swept by a ball."""

    radius: float
    half_height: float

    def to_wire(self) -> tuple[ShapeKindCode, tuple[float, float, float, float]]:
        """The wire kind and ``dimensions``."""
        return ShapeKindCode.CAPSULE, (self.radius, self.half_height, 0.0, 0.0)


@dataclass(frozen=True)
class Cuboid:
    """A box centred on the origin; half extents along X, Y, Z in metres."""

    half_extents: tuple[float, float, float]

    def to_wire(self) -> tuple[ShapeKindCode, tuple[float, float, float, float]]:
        """The wire kind and ``dimensions``."""
        x, y, z = self.half_extents
        return ShapeKindCode.CUBOID, (x, y, z, 0.0)


@dataclass(frozen=True)
class Cylinder:
    """A cylinder from ``-half_height`` to ``+half_height`` on local Z."""

    radius: float
    half_height: float

    def to_wire(self) -> tuple[ShapeKindCode, tuple[float, float, float, float]]:
        """The wire kind and ``dimensions``."""
        return ShapeKindCode.CYLINDER, (self.radius, self.half_height, 0.0, 0.0)


@dataclass(frozen=True)
class Cone:
    """A cone with its base at ``-half_height`` and apex at ``+half_height`` on local Z."""

    radius: float
    half_height: float

    def to_wire(self) -> tuple[ShapeKindCode, tuple[float, float, float, float]]:
        """The wire kind and ``dimensions``."""
        return ShapeKindCode.CONE, (self.radius, self.half_height, 0.0, 0.0)


#: Any primitive shape.
Primitive = Union[Sphere, Capsule, Cuboid, Cylinder, Cone]


@dataclass(frozen=True)
class BodySpec:
    """A body to add to a scene.

    Attributes:
        shape: the shape id (from a ``register_*`` call).
        position: initial position of the body's origin, metres, world frame.
        orientation: initial orientation, unit quaternion ``(x, y, z, w)``.
        motion: how the body moves.
        group: collision group bits (a pair is tested when each group meets the other's mask).
        mask: collision mask bits.
        margin: close-pair margin, metres, ``>= 0``; ``None`` = the scene's default.
    """

    shape: int
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0)
    motion: MotionCode = MotionCode.DYNAMIC
    group: int = 1
    mask: int = U32_MAX
    margin: Optional[float] = None


@dataclass(frozen=True)
class Registration:
    """A convex or mesh shape the daemon accepted: its id, and whether it is built."""

    shape: int
    ready: bool


class ShapeState(Enum):
    """Whether a registered shape may take bodies yet."""

    BUILDING = "building"
    READY = "ready"


def _margin_to_wire(margin: Optional[float]) -> float:
    """Negative on the wire means "the scene's default"."""
    return -1.0 if margin is None else float(margin)


def check_reply(reply: ControlReply) -> tuple[int, int]:
    """The id and flags of a success reply.

    Raises:
        DaemonError: the matching subclass for the reply's status, with its reason.
    """
    if reply.status == ErrorCode.OK:
        return reply.id, reply.flags
    raise error_for(reply.status, reply.reason_text())


def _geometry(vertices: Any, triangles: Any) -> tuple[np.ndarray, np.ndarray]:
    """Vertices as C-contiguous float64 ``(n, 3)`` and indices as uint32 ``(m, 3)``.

    Raises:
        ValueError: wrong shapes, indices outside ``[0, 2**32)``, or counts beyond u32.
    """
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        if v.size == 0:
            v = v.reshape(0, 3)
        else:
            raise ValueError(f"vertices must have shape (n, 3), not {v.shape}")
    t = np.asarray(triangles)
    if t.size == 0:
        t = np.zeros((0, 3), dtype=np.uint32)
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"triangles must have shape (m, 3), not {t.shape}")
    if t.dtype.kind not in "ui":
        raise ValueError(f"triangle indices must be integers, not {t.dtype}")
    if t.size and (int(t.min()) < 0 or int(t.max()) > U32_MAX):
        raise ValueError("triangle indices must fit in u32")
    t = np.ascontiguousarray(t, dtype=np.uint32)
    if len(v) > U32_MAX or t.size > U32_MAX:
        raise ValueError("more than 2**32 - 1 vertices or indices")
    return v, t


class Client:
    """A connection to one ``proximad``: its control requests, and the node that scene
    links are opened on.

    Not thread-safe (iceoryx2's ``ipc`` ports are single-threaded). Close it (or use it as
    a context manager) to release its ports; the daemon drops the scenes it created once
    its grace period after the client is gone has passed.
    """

    def __init__(self, *, root: str, node: Any, service: Any, events: Any, notifier: Any,
                 reply_timeout: float, build_timeout: float) -> None:
        """Use :meth:`connect`."""
        self._root = root
        self._node = node
        self._service = service
        self._events = events
        self._notifier = notifier
        self._port: Any = None
        self._daemon: Optional[int] = None
        self._instance = 0
        self._scenes: dict[int, SceneAccess] = {}
        self.reply_timeout = reply_timeout
        self.build_timeout = build_timeout
        self._event_id = iox.EventId.new(services.EVENT_CONTROL_SENT)

    # -- connecting --------------------------------------------------------------------

    @classmethod
    def connect(
        cls,
        root: str = services.DEFAULT_ROOT,
        iceoryx_prefix: Optional[str] = None,
        reply_timeout: float = DEFAULT_REPLY_TIMEOUT,
        build_timeout: float = DEFAULT_BUILD_TIMEOUT,
        node_name: str = "proxima-py-client",
        expect_instance: Optional[int] = None,
    ) -> "Client":
        """Creates the node, opens the control services and checks the daemon's protocol
        version with ``Hello``, waiting up to ``reply_timeout`` seconds for a daemon: the
        daemon creates the services, so until it has, there is no daemon to talk to.

        Args:
            root: the daemon's ``--root``.
            iceoryx_prefix: the daemon's ``--iceoryx-prefix`` (``None``: iceoryx2's global
                config decides, as for a daemon started without one).
            reply_timeout: seconds each request waits for its reply.
            build_timeout: seconds the waiting registrations wait for a shape's build.
            node_name: the iceoryx2 node name (shows in iceoryx2's tools).
            expect_instance: connect only to the daemon run with this instance id (as
                ``proximad`` logs it at start and writes it with ``--instance-file``).

        Raises:
            NoDaemon: no daemon answered in time.
            ProtocolMismatchError: the daemon speaks another protocol version.
            UnexpectedDaemon: the daemon that answered has another instance id than
                ``expect_instance``.
            TransportError: bad root or prefix, or iceoryx2 failed.
        """
        deadline = now() + reply_timeout
        config = services.make_config(iceoryx_prefix)
        try:
            node = (
                iox.NodeBuilder.new()
                .name(iox.NodeName.new(node_name))
                .signal_handling_mode(iox.SignalHandlingMode.Disabled)
                .config(config)
                .create(iox.ServiceType.Ipc)
            )
        except Exception as e:
            raise TransportError("creating the node", e) from e
        nobody = f"no proxima daemon serves {services.control_service_name(root)!r}"
        service = poll_until(deadline, lambda: services.try_open_service(
            services.control_service_builder(node, root), "control service"))
        if service is None:
            raise NoDaemon(nobody)
        events = poll_until(deadline, lambda: services.try_open_service(
            services.control_events_service_builder(node, root), "control event service"))
        if events is None:
            raise NoDaemon(nobody)
        try:
            notifier = events.notifier_builder().create()
        except Exception as e:
            raise TransportError("creating the control notifier", e) from e
        client = cls(root=root, node=node, service=service, events=events, notifier=notifier,
                     reply_timeout=reply_timeout, build_timeout=build_timeout)
        client._port = client._new_port()
        # A request sent before the daemon's server port exists is lost: wait for it first.
        served = poll_until(deadline, lambda: True if service.dynamic_config.number_of_servers > 0 else None)
        if served is None:
            client.close()
            raise NoDaemon(nobody)
        hello = client._header(Command.HELLO, 0)
        wait = FIRST_HELLO_WAIT
        while True:
            attempt_deadline = min(deadline, now() + wait)
            answer = client._request_until(hello, 0, None, attempt_deadline)
            if answer is not None:
                reply, daemon = answer
                break
            if now() >= deadline:
                client.close()
                raise NoDaemon("the daemon did not answer Hello in time")
            # iceoryx2 connects ports once, when a port list changes: a fresh port makes
            # the daemon connect anew. Hello changes nothing, so a late reply is harmless.
            client._port.delete()
            client._port = client._new_port()
            wait *= 2
        try:
            check_reply(reply)
        except Exception:
            client.close()
            raise
        if reply.id != PROTOCOL_VERSION:
            client.close()
            raise ProtocolMismatchError(
                ErrorCode.PROTOCOL_MISMATCH,
                f"the daemon speaks protocol {reply.id}, this client {PROTOCOL_VERSION}",
            )
        if expect_instance is not None and reply.instance != expect_instance:
            client.close()
            raise UnexpectedDaemon(reply.instance)
        client._daemon = daemon
        client._instance = reply.instance
        return client

    def _new_port(self) -> Any:
        """A fresh client port of the control service (PowerOfTwo slices, so meshes of any size fit)."""
        try:
            return (
                self._service.client_builder()
                .initial_max_slice_len(services.CONTROL_INITIAL_MAX_SLICE_LEN)
                .allocation_strategy(iox.AllocationStrategy.PowerOfTwo)
                .create()
            )
        except Exception as e:
            raise TransportError("creating the control client port", e) from e

    # -- properties and lifetime -------------------------------------------------------

    @property
    def root(self) -> str:
        """The daemon's service root."""
        return self._root

    @property
    def node(self) -> Any:
        """The iceoryx2 node every port of this client lives on."""
        return self._node

    @property
    def daemon_instance(self) -> int:
        """The instance id of the daemon this client is connected to (random per daemon
        run, never 0)."""
        return self._instance

    def close(self) -> None:
        """Releases the client's ports (idempotent). Scene links opened from it stay usable."""
        release_ports(self, "_port", "_notifier")

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- scenes ------------------------------------------------------------------------

    def open_scene(self, scene: int) -> SceneLink:
        """Opens the frame path (pose publisher and result subscriber) of scene ``scene``,
        which this client created.

        Raises:
            NotOwned: this client did not create ``scene`` (or dropped it).
            NoSuchScene: the daemon no longer serves it.
            TransportError: iceoryx2 failed.
        """
        access = self.scene_access(scene)
        if access is None:
            raise NotOwned(scene)
        return SceneLink(self._node, self._root, access)

    def open_result_feed(self, token: SceneToken) -> ResultFeed:
        """Subscribes to the result frames of the scene with token ``token`` (a monitor:
        the token is what the scene's owner shares), accepting only frames of this
        client's daemon.

        Raises:
            NoSuchScene: the daemon serves no scene with this token.
            TransportError: iceoryx2 failed.
        """
        feed = ResultFeed(self._node, self._root, token)
        feed.expect_instance(self._instance)
        return feed

    def scene_access(self, scene: int) -> Optional[SceneAccess]:
        """The keys of scene ``scene``, if this client created it and has not dropped it.
        Its ``token`` is the capability to read the scene's results: give it only to a
        monitor that may."""
        return self._scenes.get(scene)

    def create_scene(self) -> int:
        """Creates a scene owned by this client; returns its id (the client keeps its keys,
        see :meth:`scene_access`)."""
        reply = self.request(self._header(Command.CREATE_SCENE, 0))
        scene, _ = check_reply(reply)
        self._scenes[scene] = SceneAccess(scene=scene, token=SceneToken(tuple(reply.scene_token)),
                                          frame_key=reply.frame_key, instance=reply.instance)
        return scene

    def drop_scene(self, scene: int) -> None:
        """Drops scene ``scene`` with all its bodies (also a quarantined scene's id)."""
        self._call(self._header(Command.DROP_SCENE, scene))
        self._scenes.pop(scene, None)

    def set_broad_phase(self, scene: int, broad_phase: BroadPhaseCode) -> None:
        """Sets which broad phase scene ``scene``'s frames run from its next frame on
        (results do not depend on it, only their cost)."""
        header = self._header(Command.SET_SCENE_PARAMS, scene)
        header.broad_phase = int(broad_phase)
        self._call(header)

    # -- shapes ------------------------------------------------------------------------

    def register_primitive(self, scene: int, shape: Primitive) -> int:
        """Registers a primitive shape for scene ``scene``; returns the shape id."""
        kind, dimensions = shape.to_wire()
        header = self._header(Command.REGISTER_SHAPE, scene)
        header.shape_kind = int(kind)
        header.dimensions[:] = [float(d) for d in dimensions]
        return self._call(header)

    def register_convex(self, scene: int, points: Any) -> int:
        """Registers the convex hull of ``points`` (``(n, 3)``, metres, local frame) and
        waits until it is built; returns the shape id.

        Raises:
            BuildTimeout: not built within the build timeout.
            DaemonError: refused (e.g. :class:`EmptyGeometryError`).
        """
        return self._wait_registered(scene, self.register_convex_no_wait(scene, points))

    def register_convex_no_wait(self, scene: int, points: Any) -> Registration:
        """Registers a convex hull like :meth:`register_convex`, returning once the daemon
        accepted the points; geometry refused while building is told by :meth:`shape_state`."""
        v, t = _geometry(points, ())
        return self._register_geometry(scene, ShapeKindCode.CONVEX, v, t.ravel())

    def register_mesh(self, scene: int, vertices: Any, triangles: Any) -> int:
        """Registers a triangle mesh (vertices ``(n, 3)`` metres, triangles ``(m, 3)``
        vertex indices) and waits until it is built; returns the shape id.

        Raises:
            BuildTimeout: not built within the build timeout.
            DaemonError: refused (e.g. :class:`MeshIndexOutOfRangeError`).
        """
        return self._wait_registered(scene, self.register_mesh_no_wait(scene, vertices, triangles))

    def register_mesh_no_wait(self, scene: int, vertices: Any, triangles: Any) -> Registration:
        """Registers a mesh like :meth:`register_mesh`, returning once the daemon accepted
        the geometry, before its BVHs are built."""
        v, t = _geometry(vertices, triangles)
        return self._register_geometry(scene, ShapeKindCode.MESH, v, t.ravel())

    def register_compound(self, scene: int, parts: Sequence[Any]) -> int:
        """Registers a solid made of convex parts, each the hull of its points (``(n_i, 3)``
        arrays, metres, local frame), and waits until it is built; returns the shape id.
        Its contacts report true penetration depth, part pair by part pair.

        Raises:
            BuildTimeout: not built within the build timeout.
            DaemonError: refused (e.g. :class:`LimitExceededError` beyond
                :data:`~proxima_client.wire.MAX_COMPOUND_PARTS` parts).
        """
        arrays = [_geometry(p, ())[0] for p in parts]
        v = np.concatenate(arrays) if arrays else np.zeros((0, 3))
        sizes = np.array([len(a) for a in arrays], dtype=np.uint32)
        registration = self._register_geometry(scene, ShapeKindCode.COMPOUND, v, sizes)
        return self._wait_registered(scene, registration)

    def register_decomposed_mesh(self, scene: int, vertices: Any, triangles: Any, *,
                                 max_concavity: float = 0.0, max_parts: int = 0,
                                 fast: bool = False) -> int:
        """Registers a closed triangle mesh (as :meth:`register_mesh`) that the daemon
        decomposes into convex parts, answered as that compound (true penetration depth);
        waits until built (seconds to a minute: set the build timeout accordingly) and
        returns the shape id. ``max_concavity`` is relative to the mesh's bounding-box
        diagonal (0: the daemon's 0.02), ``max_parts`` at most
        :data:`~proxima_client.wire.MAX_COMPOUND_PARTS` (0: 64); ``fast`` chooses
        relaxation over the quality-first cut search.

        Raises:
            BuildTimeout: not built within the build timeout.
            DaemonError: refused (:class:`InvalidShapeError` for a mesh enclosing no
                volume or undefined options).
        """
        v, t = _geometry(vertices, triangles)
        dimensions = (float(max_concavity), float(max_parts), 1.0 if fast else 0.0, 0.0)
        registration = self._register_geometry(scene, ShapeKindCode.DECOMPOSED_MESH, v,
                                               t.ravel(), dimensions)
        return self._wait_registered(scene, registration)

    def shape_state(self, scene: int, shape: int) -> ShapeState:
        """Whether shape ``shape`` of scene ``scene`` is built.

        Raises:
            DaemonError: the build failed (its code and reason), or no such shape.
        """
        header = self._header(Command.SHAPE_STATE, scene)
        header.target = shape
        _, flags = check_reply(self.request(header))
        return ShapeState.BUILDING if flags & reply_flags.SHAPE_BUILDING else ShapeState.READY

    def wait_shape(self, scene: int, shape: int) -> None:
        """Waits until shape ``shape`` is built, asking after pauses doubling from
        :data:`~proxima_client.transport.SHAPE_POLL_FIRST_S` to ``SHAPE_POLL_MAX_S``.

        Raises:
            BuildTimeout: still being built at the build timeout.
        """
        deadline = now() + self.build_timeout
        pause = SHAPE_POLL_FIRST_S
        while self.shape_state(scene, shape) is ShapeState.BUILDING:
            left = deadline - now()
            if left <= 0:
                raise BuildTimeout(shape)
            time.sleep(min(pause, left))
            pause = min(pause * 2, SHAPE_POLL_MAX_S)

    # -- bodies ------------------------------------------------------------------------

    def add_body(self, scene: int, body: BodySpec) -> int:
        """Adds a body to scene ``scene``; returns the body id.

        Raises:
            ShapeNotReadyError: its shape is still being built.
        """
        header = self._header(Command.ADD_BODY, scene)
        header.target = body.shape
        header.motion = int(body.motion)
        header.group = body.group
        header.mask = body.mask
        header.margin = _margin_to_wire(body.margin)
        header.position[:] = [float(x) for x in body.position]
        header.orientation[:] = [float(x) for x in body.orientation]
        return self._call(header)

    def remove_body(self, scene: int, body: int) -> None:
        """Removes body ``body`` from scene ``scene``."""
        header = self._header(Command.REMOVE_BODY, scene)
        header.target = body
        self._call(header)

    def update_body(self, scene: int, body: int, motion: MotionCode, group: int, mask: int,
                    margin: Optional[float]) -> None:
        """Changes body ``body``'s motion, collision group and mask, and margin (metres;
        ``None`` = the scene's default)."""
        header = self._header(Command.UPDATE_BODY, scene)
        header.target = body
        header.motion = int(motion)
        header.group = group
        header.mask = mask
        header.margin = _margin_to_wire(margin)
        self._call(header)

    # -- raw requests ------------------------------------------------------------------

    def request(self, header: ControlRequest, payload: "bytes | np.ndarray" = b"") -> ControlReply:
        """Sends one raw request and returns the raw reply (a copy), its status not
        interpreted. For tests and tools; the typed methods are built on it.

        Raises:
            ReplyTimeout, DaemonLost, TransportError.
        """
        data = np.frombuffer(payload, dtype=np.uint8) if isinstance(payload, (bytes, bytearray)) \
            else np.ascontiguousarray(payload).view(np.uint8).reshape(-1)

        def fill(address: int) -> None:
            """Writes the payload at ``address``."""
            if data.size:
                ctypes.memmove(address, data.ctypes.data, data.size)

        return self._request(header, data.size, fill)

    def daemon_is_alive(self) -> bool:
        """Whether a daemon still serves the control service, after removing the ports of
        crashed processes (so a daemon killed without cleaning up counts as gone)."""
        try:
            self._node.try_cleanup_dead_nodes()
        except Exception:  # cleanup is best effort; the count below decides
            pass
        return self._service.dynamic_config.number_of_servers > 0

    # -- internals ---------------------------------------------------------------------

    @staticmethod
    def _header(command: Command, scene: int) -> ControlRequest:
        """A request header for ``command`` on ``scene``, every other field zero."""
        header = ControlRequest()
        header.protocol_version = PROTOCOL_VERSION
        header.command = int(command)
        header.scene = scene
        return header

    def _call(self, header: ControlRequest) -> int:
        """One request with an empty payload; the reply's id on success."""
        return check_reply(self.request(header))[0]

    def _register_geometry(self, scene: int, kind: ShapeKindCode, v: np.ndarray, t: np.ndarray,
                           dimensions: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0),
                           ) -> Registration:
        """Registers a shape with its geometry payload: the points ``v`` (float64
        ``(n, 3)``), then the u32 entries ``t`` (a mesh's indices, a compound's part sizes);
        the registration."""
        header = self._header(Command.REGISTER_SHAPE, scene)
        header.shape_kind = int(kind)
        header.dimensions[:] = list(dimensions)
        header.vertex_count = len(v)
        header.index_count = t.size
        v_bytes, t_bytes = v.nbytes, t.nbytes

        def fill(address: int) -> None:
            """Writes the payload at ``address``."""
            if v_bytes:
                ctypes.memmove(address, v.ctypes.data, v_bytes)
            if t_bytes:
                ctypes.memmove(address + v_bytes, t.ctypes.data, t_bytes)

        shape, flags = check_reply(self._request(header, v_bytes + t_bytes, fill))
        return Registration(shape=shape, ready=not flags & reply_flags.SHAPE_BUILDING)

    def _wait_registered(self, scene: int, registration: Registration) -> int:
        """The id of an accepted registration, once its shape is built."""
        if not registration.ready:
            self.wait_shape(scene, registration.shape)
        return registration.shape

    def _request(self, header: ControlRequest, length: int, fill: Callable[[int], None]) -> ControlReply:
        """One request and its reply; raises on timeout, a lost daemon or a foreign reply."""
        answer = self._request_until(header, length, fill, now() + self.reply_timeout)
        if answer is None:
            if not self.daemon_is_alive():
                raise DaemonLost("the daemon is gone")
            raise ReplyTimeout(f"no reply within {self.reply_timeout} s")
        reply, origin = answer
        if self._daemon is not None and origin != self._daemon:
            raise DaemonLost("the reply came from another daemon (a restart)")
        if self._instance and reply.instance != self._instance:
            raise DaemonLost("the reply came from another daemon instance (a restart)")
        return reply

    def _request_until(self, header: ControlRequest, length: int,
                       fill: Optional[Callable[[int], None]],
                       deadline: float) -> Optional[tuple[ControlReply, int]]:
        """Loans a ``length``-byte request, lets ``fill`` write it at its address, sends
        it, wakes the daemon and polls for the reply until ``deadline``; returns the reply
        (copied) and the id of the server port that sent it, or ``None`` at the deadline.

        Raises:
            DaemonLost: before sending, when no daemon serves the control service any more.
        """
        if self._port is None:
            raise TransportError("the client is closed")
        if self._daemon is not None and self._service.dynamic_config.number_of_servers == 0:
            raise DaemonLost("no daemon serves the control service any more")
        try:
            request = self._port.loan_slice_uninit(length)
            ctypes.memmove(request.user_header_ptr, ctypes.addressof(header), ctypes.sizeof(header))
            if fill is not None and length:
                fill(request.payload_ptr)
            pending = request.assume_init().send()
        except Exception as e:
            raise TransportError(f"sending a {length}-byte control request", e) from e
        try:
            # No listener (a daemon that never blocks) is no error: the reply wait decides.
            self._notifier.notify_with_custom_event_id(self._event_id)
        except Exception:
            pass

        def poll() -> Optional[tuple[ControlReply, int]]:
            """The reply (copied) and its server id, if one has arrived."""
            try:
                response = pending.receive()
            except Exception as e:
                raise TransportError("receiving a control reply", e) from e
            if response is None:
                return None
            reply = ControlReply()
            ctypes.memmove(ctypes.addressof(reply), response.payload_ptr, ctypes.sizeof(reply))
            origin = response.header.server_id.value
            response.delete()
            return reply, origin

        try:
            return poll_until(deadline, poll)
        finally:
            pending.delete()
