# SPDX-License-Identifier: BSD-3-Clause
"""The Python bindings (issue #18, part 1): equivalence with the C++ path, defaults, batches,
immutability, and the bad-input table of docs/RELIABILITY.md."""
import os
import pathlib
import threading

import numpy as np
import pytest

import pcl_probcollision as pc
from conftest import patch, translation

NOISE = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005))
Z = [0.0, 0.004, 0.006, 0.01, 0.03]  # patch heights over the table: collision .. contact .. free


def same_result(r, s):
    """Bit-identical query results (timings aside)."""
    assert r.status == s.status and r.message == s.message
    assert r.verdict == s.verdict
    assert r.probability == s.probability  # exact, not approx
    for f in ("lower_bound", "no_leaf_tested", "witness_side", "witness_index", "points_a", "points_b",
              "points_skipped_nonfinite", "bv_tests", "leaf_pairs_tested", "kernel_leaf_pairs",
              "degenerate_leaf_pairs", "classifier_iterations"):
        assert getattr(r, f) == getattr(s, f), f
    np.testing.assert_array_equal(r.witness_point, s.witness_point)
    np.testing.assert_array_equal(r.witness_normal, s.witness_normal)
    np.testing.assert_array_equal(r.probabilities_a, s.probabilities_a)
    np.testing.assert_array_equal(r.probabilities_b, s.probabilities_b)


@pytest.fixture(scope="module")
def table(table_path):
    return pc.load_model(table_path, NOISE)


@pytest.fixture(scope="module")
def gripper_patch():
    return pc.build_model(patch(), params=NOISE, name="patch")


def test_imported_from_the_build_tree():
    # ctest puts the build tree's python/ first: the tests exercise what was just built.
    expected = pathlib.Path(os.environ["PYTHONPATH"].split(os.pathsep)[0]).resolve()
    assert pathlib.Path(pc.__file__).resolve().parent.parent == expected
    assert pc._core.__file__.startswith(str(pathlib.Path(pc.__file__).parent))


def test_defaults_are_the_cpp_defaults():
    r = pc.CollisionRequest()
    assert (r.free_below, r.collision_above, r.exhaustive, r.per_point, r.rho_min, r.seed) == (0.1, 0.9, False, False, 1e-3, 1)
    assert r.traversal == pc.TraversalMode.ExpectedWeight and r.expanded_k_sigma == 3.0
    p = pc.CloudModelParams()
    assert (p.k, p.surface_projection, p.n_max, p.n_min, p.sigma_max, p.epsilon) == (10, True, 20, 8, 0.05, 0.02)
    assert p.noise.name == pc.SensorNoiseModel.none().name
    # help() shows every parameter with its default.
    doc = pc.CollisionRequest.__init__.__doc__
    for text in ("free_below: float = 0.1", "collision_above: float = 0.9", "exhaustive: bool = False",
                 "per_point: bool = False", "rho_min: float = 0.001", "seed: int = 1"):
        assert text in doc, text
    doc = pc.CloudModelParams.__init__.__doc__
    for text in ("k: int = 10", "n_max: int = 20", "n_min: int = 8", "sigma_max: float = 0.05", "epsilon: float = 0.02",
                 "noise: pcl_probcollision._core.SensorNoiseModel = SensorNoiseModel.none()"):
        assert text in doc, text
    assert "threads: int = 0" in pc.collide_batch.__doc__


def test_request_none_equals_default_request(table, gripper_patch):
    T = translation(0.1, 0.1, 0.004)
    same_result(pc.collide(table, gripper_patch, T), pc.collide(table, gripper_patch, T, pc.CollisionRequest()))


def test_numpy_equals_pcd_path_bit_for_bit(table, gripper_patch, table_points):
    # The same float32 points through numpy and through PCL's PCD reader give the same model and the
    # same answers, bit for bit (the viewpoint of the file does not matter to the isotropic model).
    from_numpy = pc.build_model(table_points, params=NOISE, name="table_mug.pcd")
    assert (from_numpy.size, from_numpy.skipped_points) == (table.size, table.skipped_points)
    np.testing.assert_array_equal(from_numpy.origin, table.origin)
    request = pc.CollisionRequest(exhaustive=True, per_point=True)
    probabilities = []
    for z in Z:
        T = translation(0.1, 0.1, z)
        r, s = pc.collide(table, gripper_patch, T, request), pc.collide(from_numpy, gripper_patch, T, request)
        same_result(r, s)
        probabilities.append(r.probability)
    assert max(probabilities) > 0.5 and min(probabilities) == 0.0  # the poses span collision to free
    assert len(set(pc.collide(table, gripper_patch, translation(0.1, 0.1, z)).verdict for z in Z)) >= 2


def test_float32_and_float64_inputs_agree(table_points, gripper_patch):
    # float64 values that are exact float32 values give the same model (points are stored as float32).
    a32 = pc.build_model(table_points, params=NOISE)
    a64 = pc.build_model(table_points.astype(np.float64), params=NOISE)
    np.testing.assert_array_equal(a32.origin, a64.origin)
    for z in Z:
        T = translation(0.1, 0.1, z)
        same_result(pc.collide(a32, gripper_patch, T), pc.collide(a64, gripper_patch, T))
    # float32 and float64 covariances too.
    covs = np.tile(np.diag([1e-5, 2e-5, 4e-5]), (len(table_points), 1, 1))
    c32 = pc.build_model(table_points, covs.astype(np.float32))
    c64 = pc.build_model(table_points, covs)
    same_result(pc.collide(c32, gripper_patch, translation(0.1, 0.1, 0.004)),
                pc.collide(c64, gripper_patch, translation(0.1, 0.1, 0.004)))


def test_strided_fortran_and_readonly_arrays(table_points, gripper_patch):
    T = translation(0.1, 0.1, 0.004)
    reference = pc.collide(pc.build_model(table_points[::2].copy(), params=NOISE), gripper_patch, T)
    wide = np.zeros((len(table_points), 5), dtype=np.float32)
    wide[:, 1:4] = table_points
    variants = [table_points[::2], np.asfortranarray(table_points[::2]), wide[::2, 1:4]]
    ro = table_points[::2].copy()
    ro.flags.writeable = False
    variants.append(ro)
    for pts in variants:
        same_result(pc.collide(pc.build_model(pts, params=NOISE), gripper_patch, T), reference)


def test_pose_as_rotation_and_translation(table, gripper_patch):
    c, s = np.cos(0.3), np.sin(0.3)
    T = np.array([[c, -s, 0, 0.1], [s, c, 0, 0.1], [0, 0, 1, 0.004], [0, 0, 0, 1]])
    r = pc.collide(table, gripper_patch, T)
    assert r.probability > 0
    same_result(r, pc.collide(table, gripper_patch, (T[:3, :3], T[:3, 3])))
    same_result(r, pc.collide(table, gripper_patch, (T[:3, :3].tolist(), list(T[:3, 3]))))


def test_pose_means_T_a_b(table, gripper_patch):
    # b above a by 5 cm is free; the inverse pose (a's frame seen from b) swapped the same way agrees.
    T = translation(0.1, 0.1, 0.004)
    r_ab = pc.collide(table, gripper_patch, T)
    r_ba = pc.collide(gripper_patch, table, np.linalg.inv(T))
    assert r_ab.verdict == r_ba.verdict and r_ab.probability > 0.1
    assert pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.05)).probability == 0.0
    assert pc.collide(table, gripper_patch, translation(0.1, 0.1, -0.05)).probability == 0.0


def test_collide_batch_equals_collide_pose_by_pose(table, gripper_patch):
    rng = np.random.default_rng(7)
    poses = []
    for i in range(24):
        angle = rng.uniform(-np.pi, np.pi)
        c, s = np.cos(angle), np.sin(angle)
        T = np.eye(4)
        T[:2, :2] = [[c, -s], [s, c]]
        T[:3, 3] = (rng.uniform(-0.2, 0.2), rng.uniform(-0.15, 0.15), rng.uniform(-0.005, 0.02))
        poses.append(T)
    poses = np.array(poses)
    request = pc.CollisionRequest(per_point=True)
    batch = pc.collide_batch(table, gripper_patch, poses, request, threads=2)
    assert len(batch) == len(poses)
    for T, r in zip(poses, batch):
        same_result(r, pc.collide(table, gripper_patch, T, request))
    for r, s in zip(batch, pc.collide_batch(table, gripper_patch, poses, request, threads=1)):
        same_result(r, s)
    assert len({r.verdict for r in batch}) >= 2
    assert pc.collide_batch(table, gripper_patch, np.zeros((0, 4, 4))) == []


def test_collide_batch_releases_the_gil(table, gripper_patch):
    # A Python thread keeps ticking while the batch computes: ticks inside the middle of the
    # batch's time window exist only if the GIL was released (held, the thread gets none there).
    import time
    poses = np.array([translation(0.1, 0.1, 0.004)] * 300)
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    try:
        time.sleep(0.01)
        start = time.perf_counter()
        pc.collide_batch(table, gripper_patch, poses, pc.CollisionRequest(exhaustive=True), threads=1)
        end = time.perf_counter()
    finally:
        stop.set()
        t.join()
    duration = end - start
    assert duration > 0.05
    inside = [x for x in ticks if start + 0.2 * duration < x < end - 0.2 * duration]
    assert len(inside) >= 5


def test_model_is_immutable_and_rebuilding_moved_points_changes_the_answer(table_points, gripper_patch):
    pts = table_points.copy()
    a = pc.build_model(pts, params=NOISE)
    T = translation(0.1, 0.1, 0.004)
    before = pc.collide(a, gripper_patch, T)
    assert before.probability > 0.1
    pts[:, 0] += 1000.0  # move the cloud 1 km in place: the model never sees it
    same_result(pc.collide(a, gripper_patch, T), before)
    moved = pc.build_model(pts, params=NOISE)
    assert pc.collide(moved, gripper_patch, T).probability == 0.0
    assert moved.origin[0] > 999.0
    # 1 km away with the pose moved along, the answer keeps its verdict (the local frame).
    far = pc.collide(moved, gripper_patch, translation(1000.1, 0.1, 0.004))
    assert far.verdict == before.verdict
    assert abs(far.probability - before.probability) < 0.05


def test_nan_rows_are_skipped_and_counted(table_points, gripper_patch):
    pts = table_points.astype(np.float64)
    pts[[5, 17], 1] = np.nan
    pts[40, 2] = np.inf
    a = pc.build_model(pts, params=NOISE)
    assert (a.size, a.skipped_points, a.source_size) == (len(pts) - 3, 3, len(pts))
    r = pc.collide(a, gripper_patch, translation(0.1, 0.1, 0.004), pc.CollisionRequest(per_point=True, exhaustive=True))
    assert r.points_skipped_nonfinite == 3 and r.points_a == len(pts) - 3
    assert len(r.probabilities_a) == len(pts)
    assert np.isnan(r.probabilities_a[[5, 17, 40]]).all()
    assert np.nanmax(r.probabilities_a) > 0


def test_result_repr_and_verdict_enum(table, gripper_patch):
    r = pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.03))
    assert isinstance(r.verdict, pc.Verdict) and r.verdict == pc.Verdict.Free
    assert r.verdict == pc.verdict_for(r.probability, pc.CollisionRequest())
    text = repr(r)
    assert text.startswith("CollisionResult(status=Ok, verdict=Verdict.Free, probability=0.0")
    assert r.ok and r.status == pc.CollisionResult.Status.Ok
    assert np.isnan(r.query_ms)
    timed = pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.004), pc.CollisionRequest(enable_timings=True))
    assert timed.query_ms >= 0
    assert "size=10848" in repr(table)
    assert np.isnan(pc.CollisionResult().probability) and pc.CollisionResult().verdict == pc.Verdict.Unknown


# --- the bad-input table (docs/RELIABILITY.md) ----------------------------------------------------

GOOD = patch(5)


@pytest.mark.parametrize("points, covariances, exc, words", [
    (GOOD.tolist(), None, TypeError, "points"),                             # not a numpy array
    (GOOD.astype(np.int32), None, TypeError, "points"),                     # integer dtype
    (GOOD.astype(np.float16), None, TypeError, "points"),                   # other float dtype
    (GOOD.astype(">f8"), None, TypeError, "points"),                        # foreign byte order
    (GOOD[:, :2], None, ValueError, "points"),                              # (N, 2)
    (GOOD.ravel(), None, ValueError, "points"),                             # 1-D
    (np.zeros((0, 3)), None, ValueError, "no finite point"),                # empty
    (np.full((4, 3), np.nan), None, ValueError, "no finite point"),         # all NaN
    (np.array([[1e300, 0, 0]] + [[0, 0, 0]] * 3), None, ValueError, "float range"),
    (GOOD, np.zeros((len(GOOD), 3)), ValueError, "covariances"),            # wrong covariance shape
    (GOOD, np.zeros((len(GOOD) - 1, 3, 3)), ValueError, "covariances"),     # wrong count
    (GOOD, np.zeros((len(GOOD), 3, 3), dtype=np.int64), TypeError, "covariances"),
    (GOOD, np.tile([[1e-4, 1e-5, 0], [0, 1e-4, 0], [0, 0, 1e-4]], (len(GOOD), 1, 1)), ValueError, "symmetric"),
])
def test_bad_points(points, covariances, exc, words):
    with pytest.raises(exc, match=words):
        pc.build_model(points, covariances)


def test_bad_params_and_request():
    with pytest.raises(ValueError, match="k"):
        pc.build_model(GOOD, params=pc.CloudModelParams(k=0))
    with pytest.raises(ValueError, match="sigma"):
        pc.SensorNoiseModel.isotropic(-1.0)
    with pytest.raises(ValueError, match="bogus"):
        pc.SensorNoiseModel.from_name("bogus")
    a = pc.build_model(GOOD)
    with pytest.raises(ValueError, match="free_below"):
        pc.collide(a, a, np.eye(4), pc.CollisionRequest(free_below=0.7))
    with pytest.raises(ValueError, match="threads"):
        pc.collide_batch(a, a, np.eye(4)[None], threads=-1)
    with pytest.raises(TypeError):
        pc.collide(GOOD, a, np.eye(4))  # a must be a CloudModel


@pytest.mark.parametrize("pose, exc, words", [
    (np.diag([2.0, 1, 1, 1]), ValueError, "rotation"),                     # scaled: not rigid
    (np.array([[1.0, 0.1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]), ValueError, "rotation"),  # sheared
    (translation(np.nan), ValueError, "T_a_b"),                             # non-finite
    (np.eye(3), ValueError, "pose"),                                        # wrong shape
    (np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]), ValueError, "last row"),
    ((np.eye(3), [0, 0]), ValueError, "pose"),                              # (R, t) with t of 2
    ((np.eye(3),), ValueError, "pose"),                                     # a 1-tuple
    ("identity", TypeError, "pose"),                                        # not numeric
])
def test_bad_pose(pose, exc, words):
    a = pc.build_model(GOOD)
    with pytest.raises(exc, match=words):
        pc.collide(a, a, pose)


def test_bad_poses_in_a_batch():
    a = pc.build_model(GOOD)
    poses = np.array([np.eye(4), np.diag([2.0, 1, 1, 1]), np.eye(4)])
    with pytest.raises(ValueError, match=r"poses\[1\].*rotation"):
        pc.collide_batch(a, a, poses)
    with pytest.raises(ValueError, match="poses"):
        pc.collide_batch(a, a, np.zeros((3, 3, 3)))
    with pytest.raises(TypeError, match="poses"):
        pc.collide_batch(a, a, "all")


def test_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError):
        pc.load_model(tmp_path / "missing.pcd")
    with pytest.raises(FileNotFoundError):
        pc.load_model(tmp_path)  # a directory is not a file
    not_pcd = tmp_path / "cloud.xyz"
    not_pcd.write_text("0 0 0\n")
    with pytest.raises(ValueError, match=r"\.pcd"):
        pc.load_model(not_pcd)
    garbage = tmp_path / "garbage.pcd"
    garbage.write_bytes(b"this is not a PCD file\n")
    with pytest.raises((ValueError, OSError), match="garbage.pcd"):
        pc.load_model(garbage)


def test_malformed_pcd_files(tmp_path, table_path):
    header = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 10\nHEIGHT 1\nPOINTS 10\nDATA binary\n"
    cases = {
        "nofields.pcd": b"VERSION 0.7\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n0 0 0\n",
        "truncated.pcd": header + b"\0" * 12,
        "no_z.pcd": b"VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n0 0\n",
        "empty.pcd": header.replace(b"10", b"0"),
        "cut.pcd": table_path.read_bytes()[:4000],
    }
    for name, content in cases.items():
        f = tmp_path / name
        f.write_bytes(content)
        with pytest.raises(ValueError, match=name):
            pc.load_model(f)


def test_cmake_install_gives_an_importable_package(tmp_path):
    # cmake --install's rules for python/ into a scratch prefix; Debian's python3 imports it from there.
    import subprocess
    import sys
    prefix = tmp_path / "prefix"
    subprocess.run([os.environ["CMAKE_COMMAND"], f"-DCMAKE_INSTALL_PREFIX={prefix}", "-P",
                    os.environ["PCL_PROBCOLLISION_PYTHON_INSTALL_SCRIPT"]], check=True, capture_output=True)
    site = prefix / os.environ["PCL_PROBCOLLISION_PYTHON_INSTALL_DIR"]
    for name in ("__init__.py", "_core.pyi", "py.typed"):
        assert (site / "pcl_probcollision" / name).is_file(), name
    env = dict(os.environ, PYTHONPATH=str(site))
    out = subprocess.run([sys.executable, "-c", "import pcl_probcollision as pc; print(pc.__file__); "
                          "print(pc.collide(pc.build_model(__import__('numpy').zeros((3, 3))), "
                          "pc.build_model(__import__('numpy').zeros((3, 3))), __import__('numpy').eye(4)).verdict)"],
                         env=env, check=True, capture_output=True, text=True, cwd=tmp_path).stdout.split("\n")
    assert out[0].startswith(str(site))
    assert out[1] in ("Verdict.InContact", "Verdict.InCollision")
