"""Scene scripts shared with the Rust reference client ``ipc/examples/frame_dump.rs``.

A script builds one scene and publishes pose frames (the format is documented in
``frame_dump.rs``). :func:`generate` writes a seeded one; :func:`run` runs it through the
Python client and returns each result frame as the same JSON object ``frame_dump``
prints, floats as the hex of their bits, so the two compare exactly.
"""

from __future__ import annotations

from typing import Any, Iterator

import numpy as np

from proxima_client import (
    BodySpec,
    BroadPhaseCode,
    Capsule,
    Client,
    Cone,
    Cuboid,
    Cylinder,
    Motion,
    ResultFrame,
    Sphere,
    query,
)

FRAME_TIMEOUT = 10.0

#: Header fields compared (timing fields left out: elapsed_ns, stage_ns, budget_met).
HEADER_FIELDS = ("frame_seq", "protocol_version", "status", "error_body", "completeness", "deepest_level",
                 "pair_count", "contact_count", "candidate_count", "toi_count", "flags",
                 "dropped_candidates", "min_budget_ns")
INT_FIELDS = ("kind", "body_a", "body_b", "index", "count", "flags")
FLOAT_FIELDS = ("distance", "error_bound", "time")
VECTOR_FIELDS = ("point_a", "point_b", "normal")


def _num(x: float) -> str:
    """The shortest text that parses back to exactly ``x`` (in Python and in Rust)."""
    return repr(float(x))


def _nums(values: Any) -> str:
    return " ".join(_num(v) for v in np.ravel(values))


def _quaternion(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def _bumpy_grid(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    xs = np.linspace(-0.8, 0.8, n + 1)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    z = rng.uniform(-0.1, 0.1, x.shape)
    vertices = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    triangles = np.concatenate([np.stack([a, a + n + 1, a + 1], 1), np.stack([a + 1, a + n + 1, a + n + 2], 1)])
    return vertices, triangles


def _box_mesh(h: float) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
    t = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, t


def generate(seed: int, bodies: int = 30, frames: int = 8) -> str:
    """A script of every shape kind, ``bodies`` bodies packed so that some touch and some
    do not, and ``frames`` frames over every query flag, with updates, a removal, broad-phase
    changes, a budgeted frame and a refused (NaN) frame between them."""
    rng = np.random.default_rng(seed)
    lines = [f"# seed {seed}",
             "shape sphere 0.5", "shape capsule 0.3 0.6", "shape cuboid 0.4 0.3 0.5",
             "shape cylinder 0.35 0.4", "shape cone 0.4 0.5"]
    points = rng.uniform(-0.5, 0.5, (24, 3))
    lines.append(f"convex {len(points)} {_nums(points)}")
    for vertices, triangles in (_bumpy_grid(6, rng), _box_mesh(0.45)):
        lines.append(f"mesh {len(vertices)} {len(triangles)} {_nums(vertices)} {' '.join(str(int(i)) for i in triangles.ravel())}")
    shapes = 8
    motions = []
    positions = rng.uniform(-2.5, 2.5, (bodies, 3))
    for b in range(bodies):
        motion = "static" if b % 7 == 0 else ("kinematic" if b % 5 == 0 else "dynamic")
        motions.append(motion)
        margin = "default" if b % 4 == 0 else _num(rng.uniform(0.0, 0.3))
        group, mask = (1, 0xFFFFFFFF) if b % 6 else (2, 0xFFFFFFFD)
        lines.append(f"body {b % shapes} {motion} {group} {mask} {margin} {_nums(positions[b])} {_nums(_quaternion(rng))}")
    flag_sets = [query.CLOSE | query.CONTACTS, query.DISTANCE, query.OVERLAP, query.TOI | query.CLOSE,
                 query.ALL, query.OVERLAP | query.CONTACTS, query.TOI, query.CLOSE]
    removed: set[int] = set()
    for f in range(frames):
        seq = f + 1
        if f == 2:
            lines.append("update 3 kinematic 1 4294967295 0.25")
            lines.append("broad 2")
        if f == 4:
            lines.append("remove 8")
            removed.add(8)
            lines.append("broad 3")
        if f == 6:
            lines.append("broad 5")
        moving = [b for b in range(bodies) if motions[b] != "static" and b not in removed]
        positions[moving] += rng.normal(scale=0.25, size=(len(moving), 3))
        budget = 1_000_000_000 if f == 5 else 0
        lines.append(f"frame {seq} {budget} {flag_sets[f % len(flag_sets)]} {len(moving)}")
        for b in moving:
            lines.append(f"pose {b} {_nums(positions[b])} {_nums(_quaternion(rng))}")
    # A refused frame: a NaN coordinate names its body.
    lines.append(f"frame {frames + 1} 0 {query.CLOSE} 2")
    lines.append("pose 1 0.0 0.0 0.0 0.0 0.0 0.0 1.0")
    lines.append("pose 2 nan 0.0 0.0 0.0 0.0 0.0 1.0")
    return "\n".join(lines) + "\n"


def _lines(text: str) -> Iterator[list[str]]:
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            yield line.split()


def _primitive(words: list[str]) -> Any:
    kind, d = words[0], [float(w) for w in words[1:]]
    return {"sphere": lambda: Sphere(*d), "capsule": lambda: Capsule(*d), "cuboid": lambda: Cuboid(tuple(d)),
            "cylinder": lambda: Cylinder(*d), "cone": lambda: Cone(*d)}[kind]()


def _margin(word: str) -> "float | None":
    return None if word == "default" else float(word)


def run(client: Client, text: str) -> list[dict[str, Any]]:
    """Runs script ``text`` on a fresh scene; every result frame as :func:`frame_json`."""
    scene = client.create_scene()
    link = client.open_scene(scene)
    out = []
    lines = _lines(text)
    for words in lines:
        command, rest = words[0], words[1:]
        if command == "shape":
            client.register_primitive(scene, _primitive(rest))
        elif command == "convex":
            client.register_convex(scene, np.array([float(w) for w in rest[1:]]).reshape(-1, 3))
        elif command == "mesh":
            nv, nt = int(rest[0]), int(rest[1])
            coordinates = np.array([float(w) for w in rest[2:2 + 3 * nv]]).reshape(nv, 3)
            triangles = np.array([int(w) for w in rest[2 + 3 * nv:]], dtype=np.uint32).reshape(nt, 3)
            client.register_mesh(scene, coordinates, triangles)
        elif command == "body":
            shape, motion, group, mask, margin = rest[:5]
            pose = [float(w) for w in rest[5:]]
            client.add_body(scene, BodySpec(shape=int(shape), motion=Motion[motion.upper()], group=int(group),
                                            mask=int(mask), margin=_margin(margin), position=pose[:3],
                                            orientation=pose[3:]))
        elif command == "update":
            body, motion, group, mask, margin = rest
            client.update_body(scene, int(body), Motion[motion.upper()], int(group), int(mask), _margin(margin))
        elif command == "remove":
            client.remove_body(scene, int(rest[0]))
        elif command == "broad":
            client.set_broad_phase(scene, BroadPhaseCode(int(rest[0])))
        elif command == "frame":
            seq, budget, flags, n = (int(w) for w in rest)
            poses = [next(lines) for _ in range(n)]
            ids = np.array([int(p[1]) for p in poses], dtype=np.uint32)
            values = np.array([[float(w) for w in p[2:]] for p in poses]).reshape(n, 7)
            link.publish(seq, budget, flags, ids, values[:, :3], values[:, 3:])
            frame = link.receive_results_for(seq, FRAME_TIMEOUT)
            if frame is None:
                raise TimeoutError(f"no answer to frame {seq}")
            with frame:
                out.append(frame_json(frame))
        else:
            raise ValueError(f"unknown command {command!r}")
    client.drop_scene(scene)
    link.close()
    return out


def _bits(values: np.ndarray) -> list[str]:
    return [format(int(b), "016x") for b in np.ascontiguousarray(values, dtype="<f8").view("<u8").ravel()]


def frame_json(frame: ResultFrame) -> dict[str, Any]:
    """A result frame as ``frame_dump`` prints it: compared header fields, and every record
    with floats as the hex of their bits."""
    out: dict[str, Any] = {name: int(getattr(frame.header, name)) for name in HEADER_FIELDS}
    records = []
    for r in frame.records:
        record: dict[str, Any] = {name: int(r[name]) for name in INT_FIELDS}
        for name in FLOAT_FIELDS:
            record[name] = _bits(np.array([r[name]]))[0]
        for name in VECTOR_FIELDS:
            record[name] = _bits(r[name])
        records.append(record)
    out["records"] = records
    return out


def describe(record: dict[str, Any]) -> dict[str, Any]:
    """A record of :func:`frame_json` with its floats decoded, for failure messages."""
    def value(bits: str) -> float:
        return float(np.array([int(bits, 16)], dtype="<u8").view("<f8")[0])

    out = dict(record)
    for name in FLOAT_FIELDS:
        out[name] = value(record[name])
    for name in VECTOR_FIELDS:
        out[name] = [value(b) for b in record[name]]
    return out

