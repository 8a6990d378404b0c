"""Meshes for a URDF: a compiled MuJoCo mesh's triangles, a unit sphere (for ellipsoids), binary STL files.

Any thread may call these functions.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np


def compiled_mesh(m: mujoco.MjModel, mesh_id: int) -> tuple[np.ndarray, np.ndarray]:
    v0, nv = int(m.mesh_vertadr[mesh_id]), int(m.mesh_vertnum[mesh_id])
    f0, nf = int(m.mesh_faceadr[mesh_id]), int(m.mesh_facenum[mesh_id])
    return np.array(m.mesh_vert[v0 : v0 + nv], dtype=float), np.array(m.mesh_face[f0 : f0 + nf], dtype=np.int64)


def unit_sphere(rings: int = 16, segments: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """A sphere of radius 1 as ``(vertices (n, 3), faces (k, 3))``: ``rings`` bands of ``segments`` quads,
    outward-facing triangles (counter-clockwise seen from outside)."""
    vertices = [(0.0, 0.0, 1.0)]
    for i in range(1, rings):
        theta = math.pi * i / rings
        for k in range(segments):
            phi = 2 * math.pi * k / segments
            vertices.append((math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)))
    vertices.append((0.0, 0.0, -1.0))
    south = len(vertices) - 1

    def at(ring: int, k: int) -> int:  # ring 1 .. rings-1
        return 1 + (ring - 1) * segments + k % segments

    faces = [(0, at(1, k), at(1, k + 1)) for k in range(segments)]
    for ring in range(1, rings - 1):
        for k in range(segments):
            a, b, c, d = at(ring, k), at(ring + 1, k), at(ring + 1, k + 1), at(ring, k + 1)
            faces += [(a, b, c), (a, c, d)]
    faces += [(at(rings - 1, k), south, at(rings - 1, k + 1)) for k in range(segments)]
    return np.array(vertices), np.array(faces, dtype=np.int64)


def write_stl(path, vertices: np.ndarray, faces: np.ndarray) -> Path:
    """Write a triangle mesh (m) as a binary STL file; the path.  Any thread.

    Binary STL: an 80-byte header, the triangle count (uint32), then per
    triangle its unit normal and three vertices (12 float32) and 2 bytes.
    """
    path = Path(path)
    triangles = np.asarray(vertices, dtype=float)[np.asarray(faces, dtype=np.int64)]  # (k, 3, 3)
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    record = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
    data = np.zeros(len(triangles), dtype=record)
    data["normal"], data["vertices"] = normals, triangles
    with open(path, "wb") as f:
        f.write(b"rtt-urdf: a MuJoCo mesh".ljust(80, b" "))
        f.write(np.uint32(len(triangles)).tobytes())
        f.write(data.tobytes())
    return path
