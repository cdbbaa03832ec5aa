"""Service names, settings and builders, mirroring ``ipc/src/lib.rs``.

The daemon and its clients open every service with one set of settings; whichever comes
first creates the service with them, the other opens it, where they are minimum
requirements. These builders ask for exactly what the Rust builders set, and nothing
else (the rest comes from iceoryx2's config defaults on both sides).

=========================================  ===========================================
service                                    settings
=========================================  ===========================================
``<root>/control``                         request–response ``[u8]`` + ControlRequest
                                           header → ControlReply; 64 clients, 1 server,
                                           4 requests in flight, 4 buffered responses
``<root>/control-events``                  event; 64 notifiers, 2 listeners, 66 nodes
``<root>/<scene>/poses``                   ``[PoseRecord]`` + PoseFrameHeader; 4
                                           publishers, 1 subscriber, buffer 2, history 0
``<root>/<scene>/results``                 ``[ResultRecord]`` + ResultFrameHeader; 1
                                           publisher, 8 subscribers, buffer 2, history 0
``<root>/<scene>/poses-ready``              event; 4 notifiers, 2 listeners
``<root>/<scene>/results-ready``            event; 2 notifiers, 8 listeners
=========================================  ===========================================
"""

from __future__ import annotations

import ctypes
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


def control_service_name(root: str) -> str:
    """``<root>/control``."""
    return f"{root}/control"


def control_events_service_name(root: str) -> str:
    """``<root>/control-events``."""
    return f"{root}/control-events"


def poses_service_name(root: str, scene: int) -> str:
    """``<root>/<scene>/poses``."""
    return f"{root}/{scene}/poses"


def results_service_name(root: str, scene: int) -> str:
    """``<root>/<scene>/results``."""
    return f"{root}/{scene}/results"


def poses_ready_service_name(root: str, scene: int) -> str:
    """``<root>/<scene>/poses-ready``."""
    return f"{root}/{scene}/poses-ready"


def results_ready_service_name(root: str, scene: int) -> str:
    """``<root>/<scene>/results-ready``."""
    return f"{root}/{scene}/results-ready"


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
    """The builder of ``<root>/control`` with the daemon's settings; call ``open_or_create()``."""
    return (
        node.service_builder(_service_name(control_service_name(root)))
        .request_response(iox.Slice[ctypes.c_uint8], ControlReply)
        .request_header(ControlRequest)
        .max_clients(CONTROL_MAX_CLIENTS)
        .max_servers(CONTROL_MAX_SERVERS)
        .max_active_requests_per_client(CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT)
        .max_response_buffer_size(CONTROL_MAX_RESPONSE_BUFFER_SIZE)
    )


def control_events_service_builder(node: Any, root: str) -> Any:
    """The builder of ``<root>/control-events``; clients notify :data:`EVENT_CONTROL_SENT`."""
    return (
        node.service_builder(_service_name(control_events_service_name(root)))
        .event()
        .max_notifiers(CONTROL_MAX_CLIENTS)
        .max_listeners(DAEMON_EVENT_PORTS)
        .max_nodes(CONTROL_MAX_CLIENTS + DAEMON_EVENT_PORTS)
    )


def poses_service_builder(node: Any, root: str, scene: int) -> Any:
    """The builder of ``<root>/<scene>/poses``."""
    return (
        node.service_builder(_service_name(poses_service_name(root, scene)))
        .publish_subscribe(iox.Slice[PoseRecord])
        .user_header(PoseFrameHeader)
        .max_publishers(POSES_MAX_PUBLISHERS)
        .max_subscribers(1)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0)
    )


def results_service_builder(node: Any, root: str, scene: int) -> Any:
    """The builder of ``<root>/<scene>/results``."""
    return (
        node.service_builder(_service_name(results_service_name(root, scene)))
        .publish_subscribe(iox.Slice[ResultRecord])
        .user_header(ResultFrameHeader)
        .max_publishers(1)
        .max_subscribers(RESULTS_MAX_SUBSCRIBERS)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0)
    )


def poses_ready_service_builder(node: Any, root: str, scene: int) -> Any:
    """The builder of ``<root>/<scene>/poses-ready``; clients notify :data:`EVENT_POSES_SENT`."""
    return (
        node.service_builder(_service_name(poses_ready_service_name(root, scene)))
        .event()
        .max_notifiers(POSES_MAX_PUBLISHERS)
        .max_listeners(DAEMON_EVENT_PORTS)
    )


def results_ready_service_builder(node: Any, root: str, scene: int) -> Any:
    """The builder of ``<root>/<scene>/results-ready``; the daemon notifies
    :data:`EVENT_RESULTS_READY`."""
    return (
        node.service_builder(_service_name(results_ready_service_name(root, scene)))
        .event()
        .max_notifiers(DAEMON_EVENT_PORTS)
        .max_listeners(RESULTS_MAX_SUBSCRIBERS)
    )


def open_service(builder: Any, what: str) -> Any:
    """``builder.open_or_create()``, its failure as a :class:`TransportError`."""
    try:
        return builder.open_or_create()
    except Exception as e:
        raise TransportError(f"opening the {what}", e) from e
