"""The Python records, codes and service settings agree with the Rust source they mirror.

Reads ``ipc/src/wire.rs`` and ``ipc/src/lib.rs`` and compares every enum value, bit,
constant, type name and field order, so a protocol change on the Rust side that is not
carried over fails here (no daemon needed).
"""

from __future__ import annotations

import ctypes
import enum
import re
from pathlib import Path

import numpy as np
import pytest

from proxima_client import errors, services, wire

IPC_SRC = Path(__file__).resolve().parents[2] / "src"
WIRE_RS = (IPC_SRC / "wire.rs").read_text()
LIB_RS = (IPC_SRC / "lib.rs").read_text()


def _snake_upper(camel: str) -> str:
    return re.sub(r"(?<=[a-z0-9])([A-Z])", r"_\1", camel).upper()


def _rust_enum(name: str) -> dict[str, int]:
    body = re.search(rf"pub enum {name} \{{(.*?)\n\}}", WIRE_RS, re.S)
    assert body, f"enum {name} not found in wire.rs"
    return {_snake_upper(v): int(n) for v, n in re.findall(r"^\s*(\w+) = (\d+),", body.group(1), re.M)}


@pytest.mark.parametrize(
    "rust, python",
    [
        ("ErrorCode", wire.ErrorCode),
        ("Command", wire.Command),
        ("ShapeKindCode", wire.ShapeKindCode),
        ("MotionCode", wire.MotionCode),
        ("BroadPhaseCode", wire.BroadPhaseCode),
        ("Completeness", wire.Completeness),
        ("RecordKind", wire.RecordKind),
    ],
)
def test_every_enum_has_the_rust_values(rust: str, python: type[enum.IntEnum]) -> None:
    assert {m.name: m.value for m in python} == _rust_enum(rust)


def _rust_bits(module: str) -> dict[str, int]:
    body = re.search(rf"pub mod {module} \{{(.*?)\n\}}", WIRE_RS, re.S)
    assert body, f"mod {module} not found"
    out = {}
    for name, value in re.findall(r"pub const (\w+): u\w+ = ([^;]+);", body.group(1)):
        expr = value
        for known, v in out.items():
            expr = re.sub(rf"\b{known}\b", str(v), expr)
        out[name] = eval(expr, {})  # shifts and ors of literals only
    return out


@pytest.mark.parametrize(
    "module, python",
    [("query", wire.query), ("frame_flags", wire.frame_flags), ("record_flags", wire.record_flags),
     ("reply_flags", wire.reply_flags), ("stage", wire.stage)],
)
def test_every_bit_set_has_the_rust_bits(module: str, python: type) -> None:
    rust = _rust_bits(module)
    assert rust, module
    assert {name: getattr(python, name) for name in rust} == rust


def _rust_const(source: str, name: str) -> int:
    match = re.search(rf"pub const {name}: \w+ = ([\d_]+);", source)
    assert match, name
    return int(match.group(1).replace("_", ""))


def test_constants_match() -> None:
    assert wire.PROTOCOL_VERSION == _rust_const(LIB_RS, "PROTOCOL_VERSION")
    assert wire.MAX_CONTACTS_PER_PAIR == _rust_const(WIRE_RS, "MAX_CONTACTS_PER_PAIR")
    assert wire.REASON_BYTES == _rust_const(WIRE_RS, "REASON_BYTES")
    assert wire.MAX_COMPOUND_PARTS == _rust_const(WIRE_RS, "MAX_COMPOUND_PARTS")
    for name in ("CONTROL_MAX_CLIENTS", "CONTROL_MAX_SERVERS", "CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT",
                 "CONTROL_MAX_RESPONSE_BUFFER_SIZE", "CONTROL_INITIAL_MAX_SLICE_LEN", "POSES_MAX_PUBLISHERS",
                 "RESULTS_MAX_SUBSCRIBERS", "FRAME_BUFFER", "EVENT_POSES_SENT", "EVENT_RESULTS_READY",
                 "EVENT_CONTROL_SENT", "DAEMON_EVENT_PORTS"):
        assert getattr(services, name) == _rust_const(LIB_RS, name), name
    assert f'"{services.DEFAULT_ROOT}"' in re.search(r"pub const DEFAULT_ROOT: &str = (.*);", LIB_RS).group(1)
    # Not a literal in lib.rs: one node per client plus the daemon's ports.
    assert "pub const CONTROL_MAX_NODES: usize = CONTROL_MAX_CLIENTS + DAEMON_EVENT_PORTS;" in LIB_RS
    assert services.CONTROL_MAX_NODES == services.CONTROL_MAX_CLIENTS + services.DAEMON_EVENT_PORTS


def test_scene_services_are_named_by_the_token_as_in_rust() -> None:
    # The same token and names as `scene_services_live_under_the_root_and_the_scene_token`
    # in ipc/src/tests.rs.
    token = services.SceneToken((0x0123_4567_89AB_CDEF, 0xFE))
    assert services.poses_service_name("proxima", token) == "proxima/scene-0123456789abcdef00000000000000fe/poses"
    assert services.results_service_name("t-1", token) == "t-1/scene-0123456789abcdef00000000000000fe/results"
    assert services.poses_ready_service_name("r", token).endswith("/poses-ready")
    assert services.results_ready_service_name("r", token).endswith("/results-ready")
    assert 'format!("{root}/scene-{token}")' in LIB_RS
    assert 'write!(f, "{:016x}{:016x}", self.0[0], self.0[1])' in LIB_RS
    assert services.SceneToken.from_hex(str(token)) == token
    assert "0123" not in repr(token), "tokens stay out of logs"
    with pytest.raises(ValueError):
        services.SceneToken((1 << 64, 0))
    with pytest.raises(ValueError):
        services.SceneToken.from_hex("abc")


RECORDS = [wire.PoseFrameHeader, wire.PoseRecord, wire.ResultFrameHeader, wire.ResultRecord,
           wire.ControlRequest, wire.ControlReply]


@pytest.mark.parametrize("record", RECORDS, ids=lambda r: r.__name__)
def test_records_have_the_rust_type_name_fields_and_size(record: type[ctypes.Structure]) -> None:
    name = record.__name__
    struct = re.search(rf'#\[type_name\("([^"]+)"\)\]\npub struct {name} \{{(.*?)\n\}}', WIRE_RS, re.S)
    assert struct, name
    assert record.type_name() == struct.group(1)
    assert [f for f, _ in record._fields_] == re.findall(r"pub (\w+):", struct.group(2))
    size = re.search(rf"size_of::<{name}>\(\) == (\d+)", WIRE_RS)
    assert ctypes.sizeof(record) == int(size.group(1))


@pytest.mark.parametrize(
    "record, dtype",
    [(wire.PoseFrameHeader, wire.POSE_FRAME_HEADER_DTYPE), (wire.PoseRecord, wire.POSE_DTYPE),
     (wire.ResultFrameHeader, wire.RESULT_FRAME_HEADER_DTYPE), (wire.ResultRecord, wire.RESULT_DTYPE)],
    ids=lambda x: getattr(x, "__name__", ""),
)
def test_numpy_dtypes_round_trip_through_the_ctypes_layout(record: type, dtype: np.dtype) -> None:
    rng = np.random.default_rng(7)
    raw = rng.integers(0, 256, dtype.itemsize, dtype=np.uint8).tobytes()
    as_struct = record.from_buffer_copy(raw)
    as_numpy = np.frombuffer(raw, dtype)[0]
    for name, _ in record._fields_:
        value = getattr(as_struct, name)
        expected = list(value) if isinstance(value, ctypes.Array) else value
        got = as_numpy[name].tolist()
        assert np.array_equal(np.asarray(got), np.asarray(expected), equal_nan=True), name


def test_every_error_code_has_its_exception_class() -> None:
    for code in wire.ErrorCode:
        if code is wire.ErrorCode.OK:
            with pytest.raises(ValueError):
                errors.error_for(code)
            continue
        error = errors.error_for(code, "why", body=3)
        assert type(error) is errors.error_class(code)
        assert isinstance(error, errors.DaemonError)
        assert error.code is code and error.reason == "why" and error.body == 3
        assert code.name in str(error)
    unknown = errors.error_for(99, "later version")
    assert isinstance(unknown, errors.UnknownStatusError) and unknown.code == 99


def test_control_reply_reason_stops_at_the_first_zero() -> None:
    reply = wire.ControlReply()
    text = "no scene 4 – gone".encode()
    ctypes.memmove(reply.reason, text, len(text))
    assert reply.reason_text() == "no scene 4 – gone"
