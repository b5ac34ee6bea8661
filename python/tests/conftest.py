# SPDX-License-Identifier: BSD-3-Clause
import os
import pathlib

import numpy as np
import pytest

DATA = pathlib.Path(os.environ.get("PCL_PROBCOLLISION_DATA", pathlib.Path(__file__).resolve().parents[2] / "data"))


def read_pcd_xyz(path):
    """The x y z float32 points of a binary PCD with exactly those fields (data/table_mug.pcd)."""
    raw = pathlib.Path(path).read_bytes()
    header = {}
    offset = 0
    while True:
        end = raw.index(b"\n", offset)
        line = raw[offset:end].decode("ascii").strip()
        offset = end + 1
        if line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key] = value
        if key == "DATA":
            break
    assert header["FIELDS"] == "x y z" and header["TYPE"] == "F F F" and header["DATA"] == "binary"
    n = int(header["POINTS"])
    return np.frombuffer(raw, dtype="<f4", count=3 * n, offset=offset).reshape(n, 3).copy()


@pytest.fixture(scope="session")
def table_path():
    return DATA / "table_mug.pcd"


@pytest.fixture(scope="session")
def table_points(table_path):
    return read_pcd_xyz(table_path)


def patch(n=20, size=0.04, seed=3):
    """A flat n x n square patch in z = 0 with a little jitter, float32."""
    rng = np.random.default_rng(seed)
    g = np.linspace(-size / 2, size / 2, n)
    x, y = np.meshgrid(g, g)
    pts = np.stack([x.ravel(), y.ravel(), np.zeros(n * n)], axis=1)
    pts += rng.normal(scale=1e-4, size=pts.shape)
    return pts.astype(np.float32)


def translation(x=0.0, y=0.0, z=0.0):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def write_pcd(path, points, viewpoint=(0, 0, 0, 1, 0, 0, 0), size=4):
    """A binary PCD with x y z fields: float32 (size 4) or float64 (size 8)."""
    points = np.ascontiguousarray(points, dtype="<f%d" % size)
    header = (f"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE {size} {size} {size}\nTYPE F F F\nCOUNT 1 1 1\n"
              f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT {' '.join(repr(float(v)) for v in viewpoint)}\n"
              f"POINTS {len(points)}\nDATA binary\n")
    pathlib.Path(path).write_bytes(header.encode("ascii") + points.tobytes())


def write_pcd_double(path, points, viewpoint=(0, 0, 0, 1, 0, 0, 0)):
    """A binary PCD with x y z float64 fields (a survey's or a map's coordinates, kept whole)."""
    write_pcd(path, points, viewpoint, size=8)


def sheet(n=30, size=0.06, noise=5e-4, seed=1):
    """A noisy flat n x n sheet in z = 0 (a scanned plane: the noise is along z), float32."""
    pts = patch(n, size, seed=seed).astype(np.float64)
    pts[:, 2] += np.random.default_rng(seed + 100).normal(scale=noise, size=len(pts))
    return pts.astype(np.float32)
