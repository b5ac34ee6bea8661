# SPDX-License-Identifier: BSD-3-Clause
"""pcl_probcollision.dask: the same answers as one process and as pcd_collision (issue #18)."""
import json
import os
import re
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

import pcl_probcollision as pc
from pcl_probcollision import dask as pcd

from conftest import DATA, patch, sheet, write_pcd, write_pcd_double

PYTHON = sys.executable
FIELDS = ("probability", "verdict", "status", "lower_bound", "budget_exhausted", "no_leaf_tested", "points_a", "points_b",
          "points_skipped_nonfinite", "leaf_pairs_tested", "bv_tests", "kernel_leaf_pairs",
          "degenerate_leaf_pairs", "classifier_iterations", "witness_side", "witness_index", "witness_point",
          "witness_normal")


def near_table_poses(m, seed=7):
    """Gripper poses over the demo table: half clear, half within 2 cm of its top (x y z r p y)."""
    rng = np.random.default_rng(seed)
    xyz = np.column_stack([rng.uniform(-0.2, 0.2, m), rng.uniform(-0.15, 0.15, m), rng.uniform(-0.02, 0.03, m)])
    xyz[::2, 2] += 0.2
    rpy = np.column_stack([rng.uniform(-0.2, 0.2, m), rng.uniform(-0.2, 0.2, m), rng.uniform(-3.1, 3.1, m)])
    return np.hstack([xyz, rpy])


def assert_same(r, s, fields=FIELDS):
    assert len(r) == len(s)
    for f in fields:
        np.testing.assert_array_equal(getattr(r, f), getattr(s, f), err_msg=f)


@pytest.fixture(scope="module")
def cluster():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc:
        with Client(lc) as client:
            yield client


def test_in_process_equals_collide_batch_bit_for_bit():
    a, b = patch(20, seed=1), patch(24, seed=2)
    rng = np.random.default_rng(9)  # b within a few sigma of a's plane: some P strictly in (0, 1)
    P = np.column_stack([rng.uniform(-0.01, 0.01, (40, 2)), rng.uniform(-0.004, 0.004, 40),
                         rng.uniform(-0.05, 0.05, (40, 2)), rng.uniform(-3, 3, 40)])
    calls = []
    r = pcd.collide_poses(a, b, P, sigma=0.002, k=8, chunk_size=16, progress=lambda done, total: calls.append(done))
    assert calls == [16, 32, 40], "in process: after each chunk, in pose order"
    o = pcd.resolve_options({"sigma": 0.002, "k": 8})
    A = pc.build_model(a, params=pcd.model_params(o, "a", exact=False))
    B = pc.build_model(b, params=pcd.model_params(o, "b", exact=False))
    ref = pc.collide_batch(A, B, pc.invert_poses(pc.poses_from_xyzrpy(P)), pcd.request_of(o))
    np.testing.assert_array_equal(r.probability, [x.probability for x in ref])
    np.testing.assert_array_equal(r.verdict, [int(x.verdict) for x in ref])
    np.testing.assert_array_equal(r.leaf_pairs_tested, [x.leaf_pairs_tested for x in ref])
    assert ((r.probability > 0) & (r.probability < 1)).any(), "the workload must have uncertain poses"
    # (M, 6) and the same poses as (M, 4, 4) are one batch.
    assert_same(pcd.collide_poses(a, b, pc.poses_from_xyzrpy(P), sigma=0.002, k=8), r)


def test_cluster_equals_in_process_on_numpy_and_files(cluster, table_path, table_points):
    P = near_table_poses(300)
    gripper = DATA / "gripper.obj"
    calls = []  # progress: the poses answered so far after each chunk (chunks finish in any order)

    def check_progress(chunks):
        assert len(calls) == chunks and calls[-1] == (300, 300) and all(t == 300 for _, t in calls)
        assert [d for d, _ in calls] == sorted(d for d, _ in calls) and calls[0][0] > 0
        calls.clear()

    local = pcd.collide_poses(gripper, table_path, P, client=None, sigma=0.0015,
                              progress=lambda done, total: calls.append((done, total)))
    check_progress(local.chunks)
    for chunk in (7, 64):  # many small chunks, a few large ones, in pose order
        r = pcd.collide_poses(gripper, table_path, P, client=cluster, chunk_size=chunk, sigma=0.0015,
                              progress=lambda done, total: calls.append((done, total)))
        assert r.chunks == -(-300 // chunk)
        assert_same(r, local)
        check_progress(r.chunks)
    assert set(np.unique(local.verdict)) >= {int(pc.Verdict.Free), int(pc.Verdict.InCollision)}
    # numpy input, float64 and float32: the same model as the file's points (viewpoint at the origin).
    pts = table_points.astype(np.float64)
    r = pcd.collide_poses(patch(15), pts, P[:50], client=cluster, sigma_b=0.003, sensor_a="none")
    s = pcd.collide_poses(patch(15), table_points, P[:50], client=None, sigma_b=0.003, sensor_a="none")
    assert_same(r, s)


def test_each_worker_builds_each_model_once(cluster):
    a, b = patch(12, seed=5), patch(30, seed=6)
    P = near_table_poses(200, seed=3)
    before = cluster.run(lambda: dict(__import__("pcl_probcollision.dask", fromlist=["_builds"])._builds))
    for _ in range(2):
        pcd.collide_poses(a, b, P, client=cluster, chunk_size=10, sigma=0.002)
    after = cluster.run(lambda: dict(__import__("pcl_probcollision.dask", fromlist=["_builds"])._builds))
    tokens = {pcd._scattered(pcd.prepare_input(x, name))["token"] for x, name in ((a, "a"), (b, "b"))}
    for worker, counts in after.items():
        for t in tokens:
            built = counts.get(t, 0) - before[worker].get(t, 0)
            assert built <= 1, f"{worker} built model {t} {built} times for 40 chunks"
    assert sum(after[w].get(t, 0) for w in after for t in tokens) >= 2


def test_json_lines_name_what_is_missing_or_misshapen():
    """pcd_collision_json_lines (pcd_collision's writer, bound for the Dask command line) refuses
    columns it cannot read, naming them, and writes what it is given."""
    cloud = {"path": "a.pcd", "kind": "cloud", "points": 3, "finite": 3, "width": 3, "height": 1, "load_ms": 1.0,
             "merged_samples": 0, "surface": None}
    vec = np.array([[1.0, 2.0, 3.0]])
    fields = {k: np.array([0.0]) for k in ("probability", "verdict", "answered_by", "signed_distance",
                                           "signed_distance_std", "unobserved", "sample_distance", "lower_bound",
                                           "budget_exhausted", "full_resolution", "no_leaf_tested", "points_a",
                                           "points_b", "points_skipped_nonfinite", "leaf_pairs_tested", "bv_tests",
                                           "kernel_leaf_pairs", "degenerate_leaf_pairs", "classifier_iterations",
                                           "query_ms", "witness_side", "witness_index")}
    fields.update(nearest_point_a=vec, nearest_point_b=vec, witness_point=vec, witness_normal=vec,
                  probability=np.array([0.25]), verdict=np.array([2], dtype=np.int8), witness_side=np.array([-1]))
    pose = np.zeros((1, 6))
    [line] = pc._core.pcd_collision_json_lines(["-sigma=0.002"], cloud, dict(cloud, path="b.pcd"), fields, pose, 7.5)
    answer = json.loads(line)
    assert (answer["verdict"], answer["probability"], answer["build_ms"]) == ("contact", 0.25, 7.5)
    assert answer["witness"] == {"point": [1, 2, 3], "side": "b", "index": 0, "normal": [1, 2, 3]}
    assert answer["inputs"]["b"]["path"] == "b.pcd" and answer["parameters"]["sigma_a"] == 0.002
    with pytest.raises(KeyError, match="fields: missing 'query_ms'"):
        pc._core.pcd_collision_json_lines([], cloud, cloud, {k: v for k, v in fields.items() if k != "query_ms"}, pose, 0.0)
    with pytest.raises(KeyError, match="input_b: missing 'finite'"):
        pc._core.pcd_collision_json_lines([], cloud, {k: v for k, v in cloud.items() if k != "finite"}, fields, pose, 0.0)
    with pytest.raises(ValueError, match=r"fields\['witness_point'\]: expected 1 rows of 3"):
        pc._core.pcd_collision_json_lines([], cloud, cloud, dict(fields, witness_point=np.zeros(2)), pose, 0.0)
    with pytest.raises(ValueError, match=r"poses: expected shape \(M, 6\)"):
        pc._core.pcd_collision_json_lines([], cloud, cloud, fields, np.zeros((1, 5)), 0.0)
    with pytest.raises(ValueError, match="option -k: '0' must be >= 1"):
        pc._core.pcd_collision_json_lines(["-k=0"], cloud, cloud, fields, pose, 0.0)


def test_options_map_to_params_as_pcd_collision_maps_its_flags():
    """model_params and request_of are pcd_collision's modelParamsFor and requestFor (bound as
    pcd_collision_params), with the noise of each input set here."""
    a, b, request = pc._core.pcd_collision_params(["-nmax=5", "-surface_ladder", "-closed_a", "-k", "12",
                                                   "-thresholds=0.2,0.8", "-stochastic", "-seed=7", "-measured"])
    assert (a.k, a.n_max, a.n_min, a.surface, a.closed_objects, a.surface_projection) == (12, 5, 5, True, True, False)
    assert not b.closed_objects
    assert (request.free_below, request.collision_above, request.seed) == (0.2, 0.8, 7)
    assert request.surface_ladder and request.surface and not request.per_point and request.enable_timings
    assert request.traversal == pc.TraversalMode.Stochastic
    with pytest.raises(ValueError, match="option -nmax: '0' must be >= 1"):
        pc._core.pcd_collision_params(["-nmax=0"])
    o = pcd.resolve_options({"nmax": 5, "surface_ladder": True, "closed_a": True, "k": 12, "thresholds": (0.2, 0.8),
                             "stochastic": True, "seed": 7, "measured": True, "sensor_b": "kinect"})
    assert repr(pcd.model_params(o, "a", exact=True)) == repr(a)
    assert repr(pcd.request_of(o)) == repr(request)
    assert pcd.model_params(o, "b", exact=False).noise.name == "kinect"


def test_options_are_pcd_collision_flags():
    with pytest.raises(TypeError, match="unknown option"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), sigm=0.01)
    with pytest.raises(ValueError, match="isotropic"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), sensor="kinect", sigma=0.01)
    with pytest.raises(ValueError, match=r"^option sensor_b: 'sonar' must be one of isotropic, kinect"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), sensor_b="sonar")
    with pytest.raises(ValueError, match=r"^option sensor: 'sonar' must be one of"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), sensor="sonar")
    # pcd_collision's parser judges the options (its words, the dash dropped); a value of the
    # wrong type is a TypeError (k = 1.5 was taken as 1 before).
    with pytest.raises(ValueError, match=r"^option k: '0' must be >= 1$"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), k=0)
    with pytest.raises(TypeError, match=r"^option k: expected an integer, got 1.5$"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), k=1.5)
    with pytest.raises(ValueError, match=r"^option sigma_b: '-0.5' must be >= 0$"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), sigma_b=-0.5)
    with pytest.raises(ValueError, match=r"^options surface_pooled and surface_ladder cannot be combined$"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), surface_pooled=True, surface_ladder=True)
    with pytest.raises(ValueError, match=r"\(M, 4, 4\) or \(M, 6\)"):
        pcd.collide_poses(patch(), patch(), np.zeros((3, 5)))
    with pytest.raises(ValueError, match="last row"):
        pcd.collide_poses(patch(), patch(), np.zeros((2, 4, 4)))
    # A pose collide() refuses is refused here, naming it as the caller passed it, not by a
    # worker as "pose T_a_b" (a probe, 2026-12-03).
    scaled = np.eye(4)[None].repeat(3, axis=0)
    scaled[2, :3, :3] *= 1.5
    with pytest.raises(ValueError, match=r"^pose poses\[2\] is not a rotation plus translation \(R\^T R departs"):
        pcd.collide_poses(patch(), patch(), scaled)
    with pytest.raises(FileNotFoundError):
        pcd.collide_poses("/nonexistent/a.pcd", patch(), np.zeros((1, 6)))
    with pytest.raises(ValueError, match="thresholds|free_below|collision_above"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), thresholds=(0.9, 0.1))
    with pytest.raises(ValueError, match="noise_resolution_gate"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), noise_resolution=2, noise_resolution_gate="somewhere")
    with pytest.raises(ValueError, match=r"option sigma_a: <a> '.*gripper\.obj' is a mesh"):
        pcd.collide_poses(str(DATA / "gripper.obj"), patch(), np.zeros((1, 6)), sigma_a=0.01)
    with pytest.raises(ValueError, match=r"option sensor_b: <b> '.*gripper\.obj' is a mesh"):
        pcd.collide_poses(patch(), str(DATA / "gripper.obj"), np.zeros((1, 6)), sensor_b="kinect")
    # thresholds change verdicts, not probabilities
    P = near_table_poses(30)
    P[:, 2] = np.linspace(-0.01, 0.01, 30)
    r1 = pcd.collide_poses(patch(), patch(seed=4), P, sigma=0.003)
    r2 = pcd.collide_poses(patch(), patch(seed=4), P, sigma=0.003, thresholds=(0.001, 0.999))
    np.testing.assert_array_equal(r1.probability, r2.probability)
    assert (r2.verdict == int(pc.Verdict.InContact)).sum() >= (r1.verdict == int(pc.Verdict.InContact)).sum()


def test_open3d_point_cloud_input(table_points):
    import open3d  # python3-open3d, installed by scripts/install-deps.sh

    cloud = open3d.geometry.PointCloud()
    cloud.points = open3d.utility.Vector3dVector(table_points.astype(np.float64))
    P = near_table_poses(40)
    r = pcd.collide_poses(patch(15), cloud, P, sigma=0.003)
    s = pcd.collide_poses(patch(15), table_points, P, sigma=0.003)
    assert_same(r, s)
    assert r.points_b[0] == len(table_points)


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_unreachable_scheduler_is_a_clear_error_within_the_timeout():
    address = f"tcp://127.0.0.1:{_free_port()}"
    t0 = time.monotonic()
    with pytest.raises(ConnectionError, match="cannot reach the Dask scheduler at " + address):
        pcd.connect(address, timeout=2)
    assert time.monotonic() - t0 < 15
    poses = DATA / "demo_poses.txt"
    t0 = time.monotonic()
    p = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", str(DATA / "gripper.obj"), str(DATA / "table_mug.pcd"),
                        str(poses), "--scheduler", address, "--timeout", "2"], capture_output=True, text=True,
                       timeout=60)
    assert p.returncode == 1
    assert p.stdout == ""
    assert "cannot reach the Dask scheduler" in p.stderr and address in p.stderr
    assert time.monotonic() - t0 < 30


def _pcd_collision():
    exe = os.environ.get("PCL_PROBCOLLISION_PCD_COLLISION")
    assert exe and os.access(exe, os.X_OK), "ctest sets PCL_PROBCOLLISION_PCD_COLLISION to the built pcd_collision"
    return exe


TIMING_KEYS = {"build_ms", "query_ms", "timings_ms"}


def _compare_json_lines(cpp_text, py_text):
    """Every key but the timings equal, signed_distance(_std), unobserved and parameters.surface included."""
    cpp = [json.loads(line) for line in cpp_text.splitlines()]
    py = [json.loads(line) for line in py_text.splitlines()]
    assert len(cpp) == len(py) > 0
    for c, p in zip(cpp, py):
        assert {"signed_distance", "signed_distance_std", "unobserved"} <= set(c) and "surface" in c["parameters"]
        keys = set(c) - TIMING_KEYS
        assert keys <= set(p), f"missing keys {keys - set(p)}"
        for k in sorted(keys):
            assert p[k] == c[k], f"pose {c['pose_index']}: {k}: {p[k]!r} != {c[k]!r}"
        assert list(p) == [k for k in c if k in p], "keys in pcd_collision's order"
    return cpp


@pytest.fixture(scope="module")
def cli_inputs(tmp_path_factory, table_points):
    """Two PCD clouds (the gripper's samples with a NaN row, the table seen by a tilted sensor)
    and a poses file in pcd_collision's format (comments, commas, tabs, a blank line)."""
    d = tmp_path_factory.mktemp("cli")
    gripper = pc.sample_mesh(*pc.read_mesh(DATA / "gripper.obj"), 0.004)
    gripper = np.vstack([gripper[:5], [[np.nan, np.nan, np.nan]], gripper[5:]])
    write_pcd(d / "gripper.pcd", gripper)
    write_pcd(d / "table.pcd", table_points, viewpoint=(0.1, -0.3, 0.8, 0.0, 0.9238795, 0.0, 0.3826834))
    rows = near_table_poses(60, seed=11)
    lines = ["# gripper over the table", *("{:.6f} {:.6f},{:.6f}\t{:.4f} {:.4f} {:.4f}".format(*r) for r in rows)]
    lines += ["", "-0.150 0.050 -0.020 0 0 0  # penetrating"]
    (d / "poses.txt").write_text("\n".join(lines) + "\n")
    return d


@pytest.mark.parametrize("flags", [
    ["-sigma", "0.0015"],
    ["-sensor_b", "kinect", "-k", "12", "-thresholds=0.2,0.8", "-exhaustive", "-nmax", "16", "-split", "octree"],
    ["-sigma", "0.0015", "-surface"],
    ["-sigma", "0.0015", "-surface_pooled"],
    ["-sigma", "0.0015", "-surface_ladder"],
    ["-sigma", "0.0015", "-surface", "-surface_calibrated"],
    ["-sigma", "0.0015", "-distance"],
])
def test_cli_writes_pcd_collision_json_lines(cli_inputs, flags):
    args = [str(cli_inputs / "gripper.pcd"), str(cli_inputs / "table.pcd")]
    poses = str(cli_inputs / "poses.txt")
    cpp = subprocess.run([_pcd_collision(), *args, "-poses", poses, "-json", *flags], capture_output=True,
                         text=True, timeout=300)
    assert cpp.returncode == 0, cpp.stderr
    py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, poses, "--scheduler", "local:2",
                         "--chunk-size", "8", *flags], capture_output=True, text=True, timeout=300)
    assert py.returncode == 0, py.stderr
    answers = _compare_json_lines(cpp.stdout, py.stdout)
    assert len(answers) == 61
    assert {a["verdict"] for a in answers} >= {"free", "collision"}
    assert answers[0]["points_skipped_nonfinite"] == 1
    distances = [a["signed_distance"] for a in answers]
    assert all(isinstance(a["unobserved"], bool) for a in answers)  # never null
    assert all(a["parameters"]["surface_pooled"] == ("-surface_pooled" in flags) for a in answers)
    assert all(a["parameters"]["surface_calibrated"] == ("-surface_calibrated" in flags) for a in answers)
    assert all(a["parameters"]["surface_ladder"] == ("-surface_ladder" in flags) for a in answers)
    assert all(a["parameters"]["distance"] == ("-distance" in flags) for a in answers)
    # -distance: the nearest samples' distance exactly where the query reached nothing.
    assert [a["sample_distance"] for a in answers] == [
        "-distance" in flags and a["no_leaf_tested"] and a["signed_distance"] is not None for a in answers]
    assert ("-distance" in flags) == any(a["sample_distance"] for a in answers)
    # answered_by (equal to pcd_collision's above): the setting's own answerer, the ladder's rung.
    answerers = {a["answered_by"] for a in answers}
    if "-surface_ladder" in flags:
        # The separators' answer stands where they reached nothing (no distance there); the
        # surface layer's distance where they reached a leaf pair and found no sure collision.
        assert all(a["parameters"]["surface"] for a in answers)
        assert all(a["signed_distance"] is None for a in answers if a["no_leaf_tested"])
        assert any(d is not None for d in distances)
        assert all(a["answered_by"] == "separators" for a in answers if a["no_leaf_tested"])
        assert "separators" in answerers and answerers - {"separators"}, answerers
    elif "-surface" in flags or "-surface_pooled" in flags:
        assert answerers == {"pooled" if "-surface_pooled" in flags else "surface"}
        assert all(a["parameters"]["surface"] for a in answers)
        assert sum(d is not None for d in distances) >= 10
        assert any(d is not None and d < 0 for d in distances)
    else:
        assert answerers == {"separators"}
        assert [d is not None for d in distances] == [a["sample_distance"] for a in answers]
        assert not any(a["unobserved"] for a in answers)  # only the surface layer sets it


def test_cli_surface_with_a_mesh_equals_pcd_collision():
    # A mesh with -surface: its samples carry the faces' normals (sample_mesh_with_normals, as
    # pcd_collision's), the table is oriented by its VIEWPOINT above it; same JSON lines.
    args = [str(DATA / "gripper.obj"), str(DATA / "table_mug.pcd")]
    poses = str(DATA / "demo_poses.txt")
    cpp = subprocess.run([_pcd_collision(), *args, "-poses", poses, "-json", "-surface", "-sigma", "0.0015"],
                         capture_output=True, text=True, timeout=300)
    assert cpp.returncode == 0, cpp.stderr
    py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, poses, "--scheduler", "local:1",
                         "-surface", "-sigma", "0.0015"], capture_output=True, text=True, timeout=300)
    assert py.returncode == 0, py.stderr
    clear, touching, penetrating = _compare_json_lines(cpp.stdout, py.stdout)
    assert clear["signed_distance"] is None and clear["no_leaf_tested"]    # 15 cm above: out of reach
    assert abs(touching["signed_distance"]) < 2e-3                          # fingertips on the table
    assert penetrating["signed_distance"] < -1e-3                           # 2 cm in (a bound: stopped early)
    assert touching["signed_distance_std"] > 0 and penetrating["parameters"]["surface"] is True


def _sphere_with_normals(n=600, radius=0.1, normal_length=1.0):
    """n points on a sphere (a Fibonacci lattice) and their outward normals of normal_length."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    u = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    return radius * u, normal_length * u


def _both_clis_with_surface(args, poses, extra):
    """pcd_collision and the Dask CLI on the same inputs with -surface -sigma 0.001 and extra:
    both succeed and print the same JSON lines (returned parsed), and pcd_collision's stderr."""
    cpp = subprocess.run([_pcd_collision(), *args, "-poses", poses, "-json", "-surface", "-sigma", "0.001", *extra],
                         capture_output=True, text=True, timeout=300)
    assert cpp.returncode == 0, cpp.stderr
    py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, poses, "--scheduler", "local:1",
                         "-surface", "-json", "-sigma", "0.001", *extra], capture_output=True, text=True, timeout=300)
    assert py.returncode == 0, py.stderr
    return _compare_json_lines(cpp.stdout, py.stdout), cpp.stderr


def test_cli_surface_with_stored_normals_equals_pcd_collision(tmp_path):
    # A cloud file with normal_x normal_y normal_z (of length 2: the surface model normalizes
    # them, as pcd_collision reads them): with -surface both CLIs orient the sphere by them (the
    # probe inside it collides) and print the same JSON lines; with -ignore_normals too.
    points, normals = _sphere_with_normals(normal_length=2.0)
    rows = "\n".join(" ".join(f"{v:.9g}" for v in (*p, *q)) for p, q in zip(points, normals))
    (tmp_path / "sphere.pcd").write_text(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n"
        f"TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(points)}\nDATA ascii\n{rows}\n")
    g = np.linspace(-0.01, 0.01, 5)
    probe = np.array([[x, y, 0.0] for x in g for y in g], dtype=np.float32)
    write_pcd(tmp_path / "probe.pcd", probe)
    # probe at the centre (inside), on the surface, just outside, far away
    (tmp_path / "poses.txt").write_text("0 0 0 0 0 0\n0 0 0.1 0 0 0\n0 0 0.12 0 0 0\n0.5 0 0 0 0 0\n")
    args = [str(tmp_path / "probe.pcd"), str(tmp_path / "sphere.pcd")]
    poses = str(tmp_path / "poses.txt")
    answers = {}
    for extra in ([], ["-ignore_normals"], ["-orientation_b", "propagate"]):
        answers[" ".join(extra)], stderr = _both_clis_with_surface(args, poses, extra)
        assert ("[point_normals:" in stderr) != bool(extra), stderr
    inside = answers[""][0]
    assert inside["verdict"] == "collision" and inside["signed_distance"] < -0.05
    assert answers[""][3]["verdict"] == "free"
    # -orientation_b propagate: the stored normals are not taken, the sphere is two-sided, and the
    # probe at its centre, out of reach of its surface, reads free; both CLIs say which.
    propagated = answers["-orientation_b propagate"]
    assert propagated[0]["verdict"] == "free" and propagated[0]["parameters"]["orientation_b"] == "propagate"
    assert propagated[0]["inputs"]["b"]["surface"]["orientation"] == "propagate"
    assert propagated[0]["inputs"]["b"]["surface"]["inside_known"] is False


def test_cli_closed_equals_pcd_collision(tmp_path):
    # The sphere's points without normals (PCL's default VIEWPOINT, which is no scan's): -closed_b
    # declares it a closed solid, so both CLIs check its propagated orientation and the probe at
    # its centre collides, printing the same JSON lines; without it the surface is two-sided and
    # the probe, out of reach of it, reads free. closed needs surface, in both.
    points, _ = _sphere_with_normals(normal_length=1.0)
    write_pcd(tmp_path / "sphere.pcd", points.astype(np.float32))
    g = np.linspace(-0.01, 0.01, 5)
    write_pcd(tmp_path / "probe.pcd", np.array([[x, y, 0.0] for x in g for y in g], dtype=np.float32))
    (tmp_path / "poses.txt").write_text("0 0 0 0 0 0\n0.5 0 0 0 0 0\n")
    args = [str(tmp_path / "probe.pcd"), str(tmp_path / "sphere.pcd")]
    poses = str(tmp_path / "poses.txt")
    verdicts = {}
    for extra in ([], ["-closed_b"]):
        lines, _ = _both_clis_with_surface(args, poses, extra)
        assert all(line["parameters"]["closed_b"] == bool(extra) and not line["parameters"]["closed_a"] for line in lines)
        verdicts[bool(extra)] = [line["verdict"] for line in lines]
    assert verdicts == {False: ["free", "free"], True: ["collision", "free"]}
    with pytest.raises(ValueError, match="need surface"):
        pcd.resolve_options({"closed": True})
    with pytest.raises(ValueError, match="surface_calibrated needs surface"):
        pcd.resolve_options({"surface_calibrated": True})
    o = pcd.resolve_options({"closed": True, "surface_ladder": True})
    assert o["closed_a"] and o["closed_b"]
    assert pcd.model_params(o, "a", exact=False).closed_objects


def test_model_cache_rebuilds_when_a_model_option_changes():
    # The model cache (per process: the workers', and this one's without a client) once keyed on a
    # list of options that missed closed_a / closed_b: a call after one with the other setting
    # reused its model and answered silently wrong, whichever came first. The probe inside the
    # closed sphere collides only with closed_b; each answer must equal a first call's.
    points, _ = _sphere_with_normals()
    g = np.linspace(-0.01, 0.01, 5)
    probe = np.array([[x, y, 0.0] for x in g for y in g])
    P = np.zeros((1, 6))
    results = [pcd.collide_poses(probe, points, P, surface=True, sigma=0.001, closed_b=closed)
               for closed in (True, False, True, False)]
    assert [r.verdict[0] for r in results] == [int(pc.Verdict.InCollision), int(pc.Verdict.Free)] * 2
    # The results say which model answered: b's inside known only where declared closed.
    assert [r.surfaces["b"]["inside_known"] for r in results] == [True, False] * 2
    assert all(r.surfaces["b"]["orientation"] == "propagate" for r in results)
    assert pcd.collide_poses(probe, points, P, sigma=0.001).surfaces == {"a": None, "b": None}
    # Every member of the built CloudModelParams is in the key, whatever option sets it.
    o = pcd.resolve_options({"surface": True})
    for change in ({"closed_b": True}, {"k": 7}, {"noise_stop": 2.0}, {"split": "octree"}, {"measured": True},
                   {"sigma_b": 0.002}, {"sensor_b": "kinect"}):
        changed = pcd.resolve_options({"surface": True, **change})
        assert pcd._params_key(changed, "b", exact=False) != pcd._params_key(o, "b", exact=False), change
    assert pcd._params_key(pcd.resolve_options({"surface": True, "threads": 1}), "b", False) == \
        pcd._params_key(o, "b", False)  # the model is the same for any thread count


def test_surface_in_process_equals_collide_batch_and_fills_signed_distance():
    # Two noisy sheets, b under and over a: surface=True gives the surface models' answers and
    # signed distances (in b's frame a pose moves a: a above b is a gap); off, NaN as before.
    a, b = sheet(20, 0.03, seed=1), sheet(30, 0.06, seed=2)
    z = np.array([-0.004, -0.002, 0.002, 0.004, 0.2])
    P = np.column_stack([np.zeros((5, 2)), z, np.zeros((5, 3))])
    r = pcd.collide_poses(a, b, P, sigma=0.001, surface=True)
    o = pcd.resolve_options({"sigma": 0.001, "surface": True})
    A = pc.build_model(a, params=pcd.model_params(o, "a", exact=False))
    B = pc.build_model(b, params=pcd.model_params(o, "b", exact=False))
    assert A.has_surface and B.has_surface and pcd.request_of(o).surface
    ref = pc.collide_batch(A, B, pc.invert_poses(pc.poses_from_xyzrpy(P)), pcd.request_of(o))
    np.testing.assert_array_equal(r.signed_distance, [x.signed_distance for x in ref])
    np.testing.assert_array_equal(r.signed_distance_std, [x.signed_distance_std for x in ref])
    np.testing.assert_array_equal(r.probability, [x.probability for x in ref])
    assert r.unobserved.dtype == bool
    np.testing.assert_array_equal(r.unobserved, [x.unobserved for x in ref])
    np.testing.assert_array_equal(r.answered_by, [int(x.answered_by) for x in ref])
    assert (r.answered_by == int(pc.AnsweredBy.SurfaceLayer)).all()
    assert "answered_by={'SurfaceLayer': 5}" in repr(r)
    assert np.isfinite(r.signed_distance[:4]).all() and np.isnan(r.signed_distance[4])
    # Sheets oriented by propagation have no known outside: only |d| is meaningful here; the
    # sign is asserted with oriented sheets in test_bindings.py and with the mesh above.
    np.testing.assert_allclose(np.abs(r.signed_distance[:4]), np.abs(z[:4]), atol=1.5e-3)
    off = pcd.collide_poses(a, b, P, sigma=0.001)
    assert np.isnan(off.signed_distance).all() and np.isnan(off.signed_distance_std).all()
    assert off.unobserved.dtype == bool and not off.unobserved.any()
    assert (off.answered_by == int(pc.AnsweredBy.Separators)).all()
    assert "answered_by" not in repr(off)


def test_cli_errors_match_pcd_collision(tmp_path):
    bad = tmp_path / "p5.txt"
    bad.write_text("0 0 0 0 0 0\n1 2 3 4 5\n")
    args = [str(DATA / "gripper.obj"), str(DATA / "table_mug.pcd")]
    cpp = subprocess.run([_pcd_collision(), *args, "-poses", str(bad), "-json"], capture_output=True, text=True)
    py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, str(bad), "--scheduler", "local:1"],
                        capture_output=True, text=True, timeout=120)
    assert (py.returncode, py.stdout) == (cpp.returncode, "") == (1, "")
    assert cpp.stderr.strip().split("error: ", 1)[1] == py.stderr.strip().split("error: ", 1)[1]
    usage = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, str(bad), "--scheduler", "local:1",
                            "-sigma", "1O"], capture_output=True, text=True, timeout=60)
    assert usage.returncode == 2 and "option -sigma: '1O' is not a number" in usage.stderr
    # Runtime failures are exit 1 as in pcd_collision, not usage errors: a number too large for a
    # double in a poses file, and a one-point cloud, which gives a mesh no sample spacing.
    huge = tmp_path / "huge.txt"
    huge.write_text("0 0 0 0 0 1e999\n")
    far = tmp_path / "far.txt"
    far.write_text("# a comment\n0 0 0 0 0 0\n1e16 0 0 0 0 0\n")
    one = tmp_path / "one.pcd"
    one.write_text("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                   "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n0 0 0\n")
    ok = tmp_path / "ok.txt"
    ok.write_text("0 0 0 0 0 0\n")
    # Both read the poses file with the same reader (pcd_collision::parsePoses): a word where a
    # number belongs, and a form feed, a blank inside a line there (Python's splitlines() ended
    # the line at it and read line 1 as malformed).
    word = tmp_path / "word.txt"
    word.write_text("0 0 0 0 0 0\n1 2 3 4 5 six\n")
    feed = tmp_path / "feed.txt"
    feed.write_text("0 0 0\f0 0 0\n1 2 3 4 5\n")
    for inputs, poses in ((args, huge), (args, far), (args, word), (args, feed), ([str(DATA / "gripper.obj"), str(one)], ok)):
        cpp = subprocess.run([_pcd_collision(), *inputs, "-poses", str(poses), "-json"], capture_output=True, text=True)
        py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *inputs, str(poses), "--scheduler", "local:1"],
                            capture_output=True, text=True, timeout=120)
        assert (py.returncode, py.stdout) == (cpp.returncode, "") == (1, ""), (py.stderr, cpp.stderr)
        if poses is not ok:  # refused with its line, before any query, in the same words
            assert cpp.stderr.strip().split("error: ", 1)[1] == py.stderr.strip().split("error: ", 1)[1]
    # "-" reads the poses from standard input in both, with the same message for a malformed line.
    stdin_text = bad.read_text()
    cpp = subprocess.run([_pcd_collision(), *args, "-poses", "-", "-json"], input=stdin_text, capture_output=True, text=True)
    py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, "-", "--scheduler", "local:1"],
                        input=stdin_text, capture_output=True, text=True, timeout=120)
    assert (py.returncode, py.stdout) == (cpp.returncode, "") == (1, ""), (py.stderr, cpp.stderr)
    assert cpp.stderr.strip().split("error: ", 1)[1] == py.stderr.strip().split("error: ", 1)[1] == \
        "standard input:2: expected 6 numbers (tx ty tz roll pitch yaw), got 5"


def _warnings(stderr):
    """The warnings of a command line's stderr, without the program's name."""
    return [line.split(": warning: ", 1)[1] for line in stderr.splitlines() if ": warning: " in line]


def test_cli_warns_as_pcd_collision_does(tmp_path, table_points):
    """pcd_collision's warnings on stderr, in the same words and order: the units (a millimetre
    cloud against a metre one, the default sigma on the millimetres), a float64 file rounded far
    from its origin, a float32 one whose model says so, and a free answer between two meshes'
    samples, and under the surface layer a mesh wound inward and one not closed. The answers stay
    equal."""
    write_pcd(tmp_path / "mm.pcd", table_points * 1000.0)
    write_pcd_double(tmp_path / "far.pcd", table_points.astype(np.float64) + np.array([1e4, 0.0, 0.0]))
    write_pcd(tmp_path / "far32.pcd", table_points.astype(np.float64) + np.array([1e5, 0.0, 0.0]))
    (tmp_path / "plate.obj").write_text("v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3\nf 1 3 4\n")
    corners = [(x, y, z) for x in (-0.05, 0.05) for y in (-0.05, 0.05) for z in (-0.05, 0.05)]
    faces = [(1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2), (3, 4, 8), (3, 8, 7), (1, 3, 7),
             (1, 7, 5), (2, 6, 8), (2, 8, 4)]
    (tmp_path / "cube.obj").write_text("".join("v %g %g %g\n" % c for c in corners) + "".join("f %d %d %d\n" % f for f in faces))
    (tmp_path / "ground.obj").write_text("".join("v %d %d %d\n" % (x, y, z) for z in (-1, 0) for y in (-5, 5) for x in (-5, 5))
                                         + "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 2 4 8 6\nf 4 3 7 8\nf 3 1 5 7\n")
    grid = np.arange(26) * 0.002
    cube = np.array([(x, y, z) for x in grid for y in grid for z in grid
                     if min(x, y, z) == 0 or max(x, y, z) > 0.0499]) + np.array([0.1, -2.5, -0.02])
    write_pcd(tmp_path / "cube.pcd", cube)
    (tmp_path / "inside_out.obj").write_text("".join("v %g %g %g\n" % c for c in corners) +
                                             "".join("f %d %d %d\n" % (f[0], f[2], f[1]) for f in faces))
    poses = tmp_path / "poses.txt"
    poses.write_text("0 0 0 0 0 0\n0 0 0.5 0 0 0\n")
    runs = {
        "units and rounding": ([str(tmp_path / "mm.pcd"), str(tmp_path / "far.pcd")], ["-sigma_b", "0.002"], 3),
        "the models' precision": ([str(tmp_path / "far32.pcd")] * 2, ["-sigma", "0.002"], 2),
        # the cube through the plate, sampled 8 cm apart: free at pose 0, which collides
        "between samples": ([str(tmp_path / "cube.obj"), str(tmp_path / "plate.obj")], ["-mesh_density", "0.08"], 1),
        # a cloud 2 cm into a mesh sampled 0.3 m apart, over 100 times its spacing: free at pose 0 (and
        # their sizes differ by over 100x)
        "a coarse mesh": ([str(tmp_path / "cube.pcd"), str(tmp_path / "ground.obj")],
                          ["-mesh_density", "0.3", "-sigma", "0.001"], 2),
        # under the surface layer: the cube wound inward, the plate not closed
        "meshes' winding": ([str(tmp_path / "inside_out.obj"), str(tmp_path / "plate.obj")],
                            ["-surface", "-mesh_density", "0.02"], 2),
    }
    for name, (inputs, flags, count) in runs.items():
        cpp = subprocess.run([_pcd_collision(), *inputs, "-poses", str(poses), "-json", *flags], capture_output=True,
                             text=True)
        py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *inputs, str(poses), "--scheduler", "local:1",
                             *flags], capture_output=True, text=True, timeout=120)
        assert (cpp.returncode, py.returncode) == (0, 0), (name, cpp.stderr, py.stderr)
        said = _warnings(cpp.stderr)
        assert len(said) == count, (name, cpp.stderr)
        assert _warnings(py.stderr) == said, (name, py.stderr, cpp.stderr)
        assert all(line.startswith("pcl_probcollision.dask: ") for line in py.stderr.splitlines() if ": warning: " in line)
        _compare_json_lines(cpp.stdout, py.stdout)
    # Through the library: RuntimeWarnings (InputWarning), the same words.
    with pytest.warns(pcd.InputWarning) as caught:
        pcd.collide_poses(str(tmp_path / "mm.pcd"), str(tmp_path / "far.pcd"), np.zeros((1, 6)), sigma_b=0.002)
    assert [str(w.message) for w in caught if w.category is pcd.InputWarning] == _warnings(
        subprocess.run([_pcd_collision(), str(tmp_path / "mm.pcd"), str(tmp_path / "far.pcd"), "-json", "-sigma_b", "0.002"],
                       capture_output=True, text=True).stderr)


def test_cli_shows_progress_on_a_terminal_only(tmp_path, table_points):
    """As pcd_collision: "\\r[k/n poses]" on stderr while a batch runs, when stderr is a terminal,
    erased at the end; through a pipe nothing of it."""
    import pty

    write_pcd(tmp_path / "table.pcd", table_points)
    poses = tmp_path / "poses.txt"
    rows = near_table_poses(3000, seed=5)  # about 2 s of answers on one worker
    poses.write_text("".join("{:.5f} {:.5f} {:.5f} {:.4f} {:.4f} {:.4f}\n".format(*r) for r in rows))
    args = [PYTHON, "-m", "pcl_probcollision.dask", str(DATA / "gripper.obj"), str(tmp_path / "table.pcd"), str(poses),
            "--scheduler", "local:1", "--chunk-size", "25", "-sigma", "0.0015"]
    master, slave = pty.openpty()
    with open(tmp_path / "out.jsonl", "w") as out_file:  # a file: a full pipe would stall the run
        p = subprocess.Popen(args, stdout=out_file, stderr=slave)
    os.close(slave)
    shown = b""
    while True:
        try:
            got = os.read(master, 4096)
        except OSError:  # the terminal closed with the process
            break
        if not got:
            break
        shown += got
    p.wait(timeout=300)
    os.close(master)
    assert p.returncode == 0, shown
    assert len((tmp_path / "out.jsonl").read_text().splitlines()) == 3000
    text = shown.decode()
    lines = re.findall(r"\r\[(\d+)/3000 poses\]", text)
    assert lines and all(0 < int(k) < 3000 for k in lines), text
    assert [int(k) for k in lines] == sorted(int(k) for k in lines)
    assert text.rfind("\r\x1b[K") > text.rfind("poses]"), "erased at the end"
    piped = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert piped.returncode == 0 and "\r" not in piped.stderr and "poses]" not in piped.stderr


def test_options_that_would_change_nothing_are_refused_as_pcd_collision_refuses_them(tmp_path, capsys):
    """A probe (2026-12-03) found -mesh_density accepted with two clouds and -noise_resolution_gate
    where nothing merges (now -noise_resolution 0, or -surface without a radius), both changing nothing; pcd_collision refuses them now, and so does
    this layer, by the same rules (its parser; inputKindsUsageError once the inputs are read) in the
    same words, before the scheduler is reached."""
    from pcl_probcollision.dask import cli
    poses = tmp_path / "p.txt"
    poses.write_text("0 0 1 0 0 0\n")
    table = str(DATA / "table_mug.pcd")
    clouds = [table, table, str(poses)]
    cpp = subprocess.run([_pcd_collision(), table, table, "-poses", str(poses), "-mesh_density", "0.01"],
                         capture_output=True, text=True)
    assert cpp.returncode == 2 and "Loading" not in cpp.stderr, cpp.stderr
    assert cpp.stderr.startswith("pcd_collision: error: option -mesh_density: neither input is a mesh"), cpp.stderr
    assert cli.main(clouds + ["--scheduler", "local", "-mesh_density", "0.01"]) == 2
    err = capsys.readouterr().err
    assert err.split("error: ", 1)[1] == cpp.stderr.split("error: ", 1)[1] and "Scheduler" not in err, err
    with pytest.raises(ValueError, match=r"^option mesh_density: neither input is a mesh \(both are point clouds"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), mesh_density=0.01)
    with pytest.raises(ValueError, match=r"^option noise_resolution_gate needs noise_resolution C > 0"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), surface=True, noise_resolution_gate="spacing")
    with pytest.raises(ValueError, match=r"^option noise_resolution_gate needs noise_resolution C > 0"):
        pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), noise_resolution=0, noise_resolution_gate="spacing")
    # The default radius merges without -surface, so a gate given alone is passed on, not dropped.
    from pcl_probcollision import dask as pdask
    o = pdask.resolve_options({"noise_resolution_gate": "everywhere"})
    assert pdask.model_params(o, "b", exact=False).noise_resolution_gate == "everywhere"
    assert pdask.model_params(o, "b", exact=False).noise_resolution_applied == 2.0
    assert pdask.model_params(pdask.resolve_options({}), "b", exact=False).noise_resolution_gate == "cloud"
    # A mesh among the inputs takes the spacing; merging takes its gate.
    r = pcd.collide_poses(str(DATA / "gripper.obj"), patch(), np.array([[0, 0, 1, 0, 0, 0]]), mesh_density=0.01)
    assert r.inputs[0]["spacing"] == 0.01
    pcd.collide_poses(patch(), patch(), np.zeros((1, 6)), noise_resolution=2, noise_resolution_gate="everywhere")


def test_cli_reads_options_as_pcd_collision_does(tmp_path, capsys):
    """One dash for pcd_collision's options and two for this command's own (found in review: any
    number of dashes was taken, `--sigma` too), decimal numbers only in both (pcd_collision took
    hex floats), and pcd_collision's -threads, checked against the library's cap."""
    from pcl_probcollision.dask import cli
    poses = tmp_path / "p.txt"
    poses.write_text("0 0 0 0 0 0\n")
    args = [str(DATA / "gripper.obj"), str(DATA / "table_mug.pcd"), str(poses)]
    _, options, own = cli.parse(args + ["--scheduler", "local:1", "-threads", "2", "-sigma=0.01"])
    assert (options["threads"], options["sigma"], own["scheduler"]) == (2, 0.01, "local:1")
    for bad, words in ((["--scheduler", "local:1", "--sigma", "0.01"], "unknown option '--sigma'"),
                       (["-scheduler", "local:1"], "unknown option '-scheduler'"),
                       (["--scheduler", "local:1", "-sigma", "0x1p-3"], "not a number")):
        with pytest.raises(cli.Usage, match=words):
            cli.parse(args + bad)
    # pcd_collision's usage errors, found by parsing alone (before the cluster starts, exit 2): an
    # input type read from its name, a noise model given to a mesh, this command's own bad values.
    # A bare address (localhost:8786) is left to the connection.
    for bad, words in (([str(DATA / "gripper.obj"), str(DATA / "table_mug.xyz"), str(poses), "--scheduler", "local"],
                        "unsupported file type"),
                       (args + ["--scheduler", "local:0"], "local:N needs a whole number N >= 1"),
                       (args + ["--scheduler", "local:x"], "local:N needs a whole number"),
                       (args + ["--scheduler", "local", "--chunk-size", "0"], "option --chunk-size: must be >= 1"),
                       (args + ["--scheduler", "local", "--scheduler", "local"], "option --scheduler given twice"),
                       (args + ["--scheduler", "local", "-o", "x.pcd"], "per-point results stay on the workers")):
        with pytest.raises(cli.Usage, match=words):
            cli.parse(bad)
    # A noise model given to a mesh: found once the inputs are read, still before the scheduler.
    for flag, value, words in (("-sigma_a", "0.01", r"option -sigma_a: <a> '.*gripper\.obj' is a mesh"),
                               ("-sensor_a", "kinect", "option -sensor_a: <a>")):
        assert cli.main(args + ["--scheduler", "local", flag, value]) == 2
        err = capsys.readouterr().err
        assert re.search(words, err) and "Scheduler" not in err, err
    assert cli.parse(args + ["--scheduler", "localhost:8786"])[2]["scheduler"] == "localhost:8786"
    assert cli._as_flag_message("[pcl_probcollision::BVHParams::validate] epsilon 0.7 outside [0, 0.5)") == \
        "option -epsilon: 0.7 outside [0, 0.5)"
    assert cli._as_flag_message("option threads: must be >= 0") == "option -threads: must be >= 0"
    with pytest.raises(SystemExit):  # -h wins over an unknown option, as in pcd_collision
        cli.parse(["-sigm", "-h"])
    capsys.readouterr()
    with pytest.raises(SystemExit) as version:  # so does -version, naming the library's
        cli.parse(["-sigm", "-version"])
    assert version.value.code == 0
    assert capsys.readouterr().out == f"pcl_probcollision.dask {pc.__version__} (library {pc.__version__})\n"
    with pytest.raises(ValueError, match="threads"):
        pcd.resolve_options({"threads": pc._core.MAX_THREADS + 1})
    # The flags this command passes on are pcd_collision's, all of them but -pose, -poses and -o
    # (its help names each): a flag added there and not here would be refused as unknown.
    shown = subprocess.run([_pcd_collision(), "-h"], capture_output=True, text=True).stdout
    flags = set(re.findall(r"(?:^|[ ,])(-[a-z_]+)\b", shown, re.M)) - {"-h", "-help", "-version", "-pose", "-poses", "-o"}
    assert flags == {"-" + name for name in (*cli._VALUES, *cli._SWITCH)}
    # Both command lines refuse the same arguments as usage errors (exit 2), before any work, in
    # the same words: pcd_collision's parser judges its flags for both (before, the Dask command
    # line had its own copy of the rules, which had drifted into other words for 20 of these).
    refused = [["-sigma", "0x1p-3"], ["-threads", str(pc._core.MAX_THREADS + 1)], ["-threads", "-1"], ["-k", "0"],
               ["-k", "1.5"], ["-sigma", "-1"], ["-sigma", "1e16"], ["-sigma_a", "1e400"], ["-nmax", "0"],
               ["-epsilon", "0.5"], ["-thresholds", "0.6,0.9"], ["-thresholds", "0.1"], ["-seed", "-1"],
               ["-max_leaf_fits", "-1"], ["-noise_stop", "1e999"], ["-noise_resolution", "-1"], ["-mesh_density", "0"],
               ["-sensor", "bogus"], ["-sensor", "kinect", "-sigma", "0.01"], ["-closed"], ["-orientation", "propagate"],
               ["-surface_pooled", "-surface_ladder"], ["-sigma_max", "-1"], ["-split", "kd"],
               ["-noise_resolution_gate", "x"], ["-surface", "-noise_resolution_gate", "cloud"],
               ["-noise_resolution", "0", "-noise_resolution_gate", "cloud"], ["-stochastic", "-deterministic"],
               ["-surface_calibrated"],
               ["-sigma=0.01", "-sigma", "0.02"], ["-json=1"], ["-bogus", "1"], ["-sigma"]]
    for bad in refused:
        cpp = subprocess.run([_pcd_collision(), *args[:2], "-poses", str(poses), *bad], capture_output=True, text=True)
        assert cpp.returncode == 2, (bad, cpp.stderr)
        with pytest.raises(cli.Usage) as e:
            cli.parse(args + ["--scheduler", "local:1", *bad])
        assert "pcd_collision: error: " + str(e.value) == cpp.stderr.strip().splitlines()[0], (bad, cpp.stderr)
    for flag, value in (("-sigma", "0x1p-3"), ("-threads", str(pc._core.MAX_THREADS + 1))):
        cpp = subprocess.run([_pcd_collision(), *args[:2], "-poses", str(poses), flag, value], capture_output=True, text=True)
        py = subprocess.run([PYTHON, "-m", "pcl_probcollision.dask", *args, "--scheduler", "local:1", flag, value],
                            capture_output=True, text=True, timeout=60)
        assert (cpp.returncode, py.returncode) == (2, 2), (flag, cpp.stderr, py.stderr)
        assert cpp.stderr.split("error: ", 1)[1] == py.stderr.split("error: ", 1)[1], (cpp.stderr, py.stderr)
