"""Service names, settings and builders, mirroring ``ipc/src/lib.rs``.

The daemon creates every service with one set of settings: the control services when it
starts, a scene's four when it creates the scene. Clients only open them (never create),
where the settings they state are minimum requirements: a control service that does not
exist means no daemon yet, a scene service that does not exist means no such scene. These
builders ask for exactly what the Rust builders set, and nothing else (the rest comes
from iceoryx2's config defaults on both sides).

A scene's services are named by its :class:`SceneToken` (from its ``CreateScene`` reply),
not by its id: ``<root>/scene-<token as 32 hex digits>/...``. Whoever holds the token can
open them, so it is the capability to read the scene's results.

======================================  =================================================
service                                 settings
======================================  =================================================
``<root>/control``                      request–response ``[u8]`` + ControlRequest header
                                        → ControlReply; 64 clients, 1 server, 66 nodes, 4
                                        requests in flight, 4 buffered responses
``<root>/control-events``               event; 64 notifiers, 2 listeners, 66 nodes
``<root>/scene-<token>/poses``          ``[PoseRecord]`` + PoseFrameHeader; 4 publishers,
                                        1 subscriber, buffer 2, history 0
``<root>/scene-<token>/results``        ``[ResultRecord]`` + ResultFrameHeader; 1
                                        publisher, 8 subscribers, buffer 2, history 0,
                                        safe overflow
``<root>/scene-<token>/poses-ready``    event; 4 notifiers, 2 listeners
``<root>/scene-<token>/results-ready``  event; 2 notifiers, 8 listeners
======================================  =================================================
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Any, Optional

import iceoryx2 as iox

from .errors import TransportError
from .wire import ControlReply, ControlRequest, PoseFrameHeader, PoseRecord, ResultFrameHeader, ResultRecord

#: The default root prefix of every service name.
DEFAULT_ROOT: str = "proxima"

#: Most clients the control service admits at once.
CONTROL_MAX_CLIENTS: int = 64
#: Servers of the control service: the one daemon.
CONTROL_MAX_SERVERS: int = 1
#: Control requests one client may have in flight.
CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT: int = 4
#: Responses buffered per control request.
CONTROL_MAX_RESPONSE_BUFFER_SIZE: int = 4
#: Initial byte capacity of a client's request slice (grows by powers of two).
CONTROL_INITIAL_MAX_SLICE_LEN: int = 4096

#: Client processes that may publish poses to one scene.
POSES_MAX_PUBLISHERS: int = 4
#: Processes that may subscribe to one scene's results.
RESULTS_MAX_SUBSCRIBERS: int = 8
#: Frames a subscriber keeps before the oldest is overwritten.
FRAME_BUFFER: int = 2
#: Pose records a publisher's first shared-memory segment holds (then powers of two).
POSES_INITIAL_MAX_SLICE_LEN: int = 1024

#: Event id a client sends after publishing a pose frame.
EVENT_POSES_SENT: int = 1
#: Event id the daemon sends after publishing a result frame.
EVENT_RESULTS_READY: int = 2
#: Event id a client sends after sending a control request.
EVENT_CONTROL_SENT: int = 3
#: Daemon ports on a daemon-side event service (the daemon plus a crashed predecessor).
DAEMON_EVENT_PORTS: int = 2
#: Nodes that may hold the control service (and the control event service) at once: one
#: per client, plus the daemon's ports.
CONTROL_MAX_NODES: int = CONTROL_MAX_CLIENTS + DAEMON_EVENT_PORTS

_U64_MAX = (1 << 64) - 1


@dataclass(frozen=True, repr=False)
class SceneToken:
    """A scene's token: 128 random bits, two u64 words from the scene's ``CreateScene``
    reply (``ControlReply.scene_token``), that name the scene's services. Whoever holds it
    can open them, so it is the capability to read the scene's results (sending frames
    needs the frame key as well). ``str()`` gives its 32 hex digits; ``repr()`` does not,
    so it stays out of logs.
    """

    words: tuple[int, int]

    def __post_init__(self) -> None:
        """Checks that there are two words, each a u64."""
        words = tuple(int(w) for w in self.words)
        if len(words) != 2 or not all(0 <= w <= _U64_MAX for w in words):
            raise ValueError("a scene token is two u64 words")
        object.__setattr__(self, "words", words)

    @classmethod
    def from_hex(cls, text: str) -> "SceneToken":
        """The token whose :func:`str` is ``text`` (32 hex digits).

        Raises:
            ValueError: not 32 hex digits.
        """
        text = text.strip()
        if len(text) != 32:
            raise ValueError(f"a scene token is 32 hex digits, not {len(text)} characters")
        return cls((int(text[:16], 16), int(text[16:], 16)))

    def __str__(self) -> str:
        """32 lowercase hex digits: ``words[0]``, then ``words[1]``."""
        return f"{self.words[0]:016x}{self.words[1]:016x}"

    def __repr__(self) -> str:
        return "SceneToken(…)"


def control_service_name(root: str) -> str:
    """``<root>/control``."""
    return f"{root}/control"


def control_events_service_name(root: str) -> str:
    """``<root>/control-events``."""
    return f"{root}/control-events"


def scene_services_name(root: str, token: SceneToken) -> str:
    """The common prefix of the services of the scene with token ``token``:
    ``<root>/scene-<token>``."""
    return f"{root}/scene-{token}"


def poses_service_name(root: str, token: SceneToken) -> str:
    """``<root>/scene-<token>/poses``."""
    return f"{scene_services_name(root, token)}/poses"


def results_service_name(root: str, token: SceneToken) -> str:
    """``<root>/scene-<token>/results``."""
    return f"{scene_services_name(root, token)}/results"


def poses_ready_service_name(root: str, token: SceneToken) -> str:
    """``<root>/scene-<token>/poses-ready``."""
    return f"{scene_services_name(root, token)}/poses-ready"


def results_ready_service_name(root: str, token: SceneToken) -> str:
    """``<root>/scene-<token>/results-ready``."""
    return f"{scene_services_name(root, token)}/results-ready"


def make_config(prefix: Optional[str] = None) -> Any:
    """A copy of iceoryx2's global config, with ``global.prefix`` set to ``prefix`` if given.

    The daemon's ``--iceoryx-prefix`` and the client's must be the same, or they never
    meet: every shared-memory file name carries it.

    Raises:
        TransportError: ``prefix`` is not a valid iceoryx2 file name.
    """
    config = iox.config.global_config()
    if prefix is not None:
        try:
            config.global_cfg.prefix = iox.FileName.new(prefix)
        except Exception as e:  # the bindings raise SemanticStringError
            raise TransportError(f"invalid iceoryx2 prefix {prefix!r}", e) from e
    return config


def _service_name(name: str) -> Any:
    """An iceoryx2 service name, its failure as a :class:`TransportError`."""
    try:
        return iox.ServiceName.new(name)
    except Exception as e:
        raise TransportError(f"invalid service name {name!r}", e) from e


def control_service_builder(node: Any, root: str) -> Any:
    """The builder of ``<root>/control`` with the daemon's settings (open it with
    :func:`try_open_service`)."""
    return (
        node.service_builder(_service_name(control_service_name(root)))
        .request_response(iox.Slice[ctypes.c_uint8], ControlReply)
        .request_header(ControlRequest)
        .max_clients(CONTROL_MAX_CLIENTS)
        .max_servers(CONTROL_MAX_SERVERS)
        .max_active_requests_per_client(CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT)
        .max_response_buffer_size(CONTROL_MAX_RESPONSE_BUFFER_SIZE)
        .max_nodes(CONTROL_MAX_NODES)
    )


def control_events_service_builder(node: Any, root: str) -> Any:
    """The builder of ``<root>/control-events``; clients notify :data:`EVENT_CONTROL_SENT`."""
    return (
        node.service_builder(_service_name(control_events_service_name(root)))
        .event()
        .max_notifiers(CONTROL_MAX_CLIENTS)
        .max_listeners(DAEMON_EVENT_PORTS)
        .max_nodes(CONTROL_MAX_NODES)
    )


def poses_service_builder(node: Any, root: str, token: SceneToken) -> Any:
    """The builder of ``<root>/scene-<token>/poses``."""
    return (
        node.service_builder(_service_name(poses_service_name(root, token)))
        .publish_subscribe(iox.Slice[PoseRecord])
        .user_header(PoseFrameHeader)
        .max_publishers(POSES_MAX_PUBLISHERS)
        .max_subscribers(1)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0)
    )


def results_service_builder(node: Any, root: str, token: SceneToken) -> Any:
    """The builder of ``<root>/scene-<token>/results``. Safe overflow is on (iceoryx2's
    default, stated): a subscriber that does not read loses its oldest frames and never
    holds the daemon up."""
    return (
        node.service_builder(_service_name(results_service_name(root, token)))
        .publish_subscribe(iox.Slice[ResultRecord])
        .user_header(ResultFrameHeader)
        .max_publishers(1)
        .max_subscribers(RESULTS_MAX_SUBSCRIBERS)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0)
        .enable_safe_overflow(True)
    )


def poses_ready_service_builder(node: Any, root: str, token: SceneToken) -> Any:
    """The builder of ``<root>/scene-<token>/poses-ready``; clients notify
    :data:`EVENT_POSES_SENT`."""
    return (
        node.service_builder(_service_name(poses_ready_service_name(root, token)))
        .event()
        .max_notifiers(POSES_MAX_PUBLISHERS)
        .max_listeners(DAEMON_EVENT_PORTS)
    )


def results_ready_service_builder(node: Any, root: str, token: SceneToken) -> Any:
    """The builder of ``<root>/scene-<token>/results-ready``; the daemon notifies
    :data:`EVENT_RESULTS_READY`."""
    return (
        node.service_builder(_service_name(results_ready_service_name(root, token)))
        .event()
        .max_notifiers(DAEMON_EVENT_PORTS)
        .max_listeners(RESULTS_MAX_SUBSCRIBERS)
    )


def try_open_service(builder: Any, what: str) -> Optional[Any]:
    """``builder.open()``: the service, or ``None`` when it does not exist (the daemon has
    not created it, or has removed it or is removing it). Clients never create a service.

    Raises:
        TransportError: any other failure (e.g. incompatible settings, too many nodes).
    """
    try:
        return builder.open()
    except Exception as e:
        # The bindings raise <Pattern>OpenError('DoesNotExist'), or
        # ('IsMarkedForDestruction') while the daemon is removing the service: gone too.
        gone = (("DoesNotExist",), ("IsMarkedForDestruction",))
        if type(e).__name__.endswith("OpenError") and e.args[:1] in gone:
            return None
        raise TransportError(f"opening the {what}", e) from e
