# SPDX-License-Identifier: BSD-3-Clause
"""The Python bindings (issue #18, part 1): equivalence with the C++ path, defaults, batches,
immutability, and the bad-input table of docs/RELIABILITY.md."""
import os
import pathlib
import threading
import warnings

import numpy as np
import pytest

import pcl_probcollision as pc
from conftest import DATA, patch, sheet, translation, write_pcd, write_pcd_double

NOISE = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005))
Z = [0.0, 0.004, 0.006, 0.01, 0.03]  # patch heights over the table: collision .. contact .. free


def same_result(r, s, same_message=True):
    """Bit-identical query results (timings aside; the message too unless same_message is False)."""
    assert r.status == s.status and (r.message == s.message or not same_message)
    assert r.verdict == s.verdict
    assert r.probability == s.probability  # exact, not approx
    # The surface layer's distance: exact too, NaN (not computed) on both sides alike.
    np.testing.assert_array_equal([r.signed_distance, r.signed_distance_std], [s.signed_distance, s.signed_distance_std])
    for f in ("answered_by", "lower_bound", "budget_exhausted", "no_leaf_tested", "unobserved", "witness_side", "witness_index", "points_a", "points_b",
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


# The patch unmerged (noise_resolution 0), as the tests below take it; by default its 400 samples
# merge (test_noise_resolution_merges_a_patch_sampled_finer_than_its_noise).
UNMERGED = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005), noise_resolution=0.0)


@pytest.fixture(scope="module")
def gripper_patch():
    return pc.build_model(patch(), params=UNMERGED, name="patch")


def test_noise_resolution_merges_a_patch_sampled_finer_than_its_noise(gripper_patch, table, table_path):
    # 400 samples 2 mm apart under 5 mm noise: merged by default (noise_resolution None: 2 without
    # the surface model), as with noise_resolution = 2, into a few points, while the table (5 mm
    # noise on about 5.3 mm spacing) is kept whole; unmerged with 0 or with the surface model.
    assert gripper_patch.size == 400 and gripper_patch.merged_samples == 0
    by_default = pc.build_model(patch(), params=NOISE)
    assert 0 < by_default.size < 40 and by_default.merged_samples == 400 - by_default.size
    assert by_default.keeps_full_resolution is True
    with_surface = pc.build_model(patch(), params=pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005),
                                                                        surface=True))
    assert with_surface.size == 400 and with_surface.merged_samples == 0
    merging = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005))
    merging.noise_resolution = 2.0
    merged = pc.build_model(patch(), params=merging)
    assert 0 < merged.size < 40 and merged.merged_samples == 400 - merged.size
    assert merged.size == by_default.size
    kept = pc.load_model(table_path, merging)
    assert kept.size == table.size == 10848 and kept.merged_samples == 0
    # The merged patch keeps its unmerged model for the full-resolution rung; nothing else does.
    assert merged.keeps_full_resolution is True
    assert gripper_patch.keeps_full_resolution is False and kept.keeps_full_resolution is False
    merging.keep_full_resolution = False
    alone = pc.build_model(patch(), params=merging)
    assert alone.size == merged.size and alone.keeps_full_resolution is False
    # At the table (contact at P 0.53-0.81 for z = -0.001 to 0.002): the rung asks those contacts
    # again, so the answers of the two models agree except where result.full_resolution says the
    # unmerged models answered.
    for z in (-0.002, -0.001, 0.0, 0.001, 0.002, 0.01):
        r = pc.collide(kept, merged, translation(0.1, 0.1, z))
        s = pc.collide(kept, alone, translation(0.1, 0.1, z))
        assert isinstance(r.full_resolution, bool) and s.full_resolution is False
        if not r.full_resolution:
            assert (r.probability, r.verdict) == (s.probability, s.verdict)
        else:
            assert s.verdict == pc.Verdict.InContact and s.probability >= 0.5 and r.verdict == pc.Verdict.InCollision


def test_imported_from_the_build_tree():
    # ctest puts the build tree's python/ first: the tests exercise what was just built.
    expected = pathlib.Path(os.environ["PYTHONPATH"].split(os.pathsep)[0]).resolve()
    assert pathlib.Path(pc.__file__).resolve().parent.parent == expected
    assert pc._core.__file__.startswith(str(pathlib.Path(pc.__file__).parent))


def test_defaults_are_the_cpp_defaults():
    r = pc.CollisionRequest()
    assert (r.free_below, r.collision_above, r.exhaustive, r.per_point, r.rho_min, r.seed) == (0.1, 0.9, False, False, 1e-3, 1)
    assert r.traversal == pc.TraversalMode.ExpectedWeight and r.expanded_k_sigma == 3.0
    assert r.surface is False
    p = pc.CloudModelParams()
    assert (p.k, p.surface_projection, p.n_max, p.n_min, p.sigma_max, p.epsilon) == (10, True, 20, 8, 0.05, 0.02)
    assert p.surface is False and p.orientation == pc.NormalOrientation.Auto and p.closed_objects is False
    # Issue #17's resolution: unset by default, which merges a whole cloud sampled finer than its
    # noise at 2 sigmas without the surface model and nothing with it.
    assert p.noise_resolution is None and p.noise_resolution_gate == "cloud" and p.keep_full_resolution is True
    assert p.noise_resolution_applied == 2.0 and pc.CloudModelParams(surface=True).noise_resolution_applied == 0.0
    assert pc.CloudModelParams(surface=True, noise_resolution=1.5).noise_resolution_applied == 1.5
    assert p.noise_stop == 0.0
    assert p.noise_resolution_whole_cloud is True and p.noise_resolution_gated is False
    p.noise_resolution_gated = True  # one gate: the last set wins
    assert p.noise_resolution_gated is True and p.noise_resolution_gate == "spacing"
    p.noise_resolution_gated = False
    assert p.noise_resolution_whole_cloud is False and p.noise_resolution_gate == "everywhere"
    p.noise_resolution_gate = "cloud"
    assert p.noise_resolution_whole_cloud is True
    with pytest.raises(ValueError, match="noise_resolution_gate: expected one of everywhere, spacing, cloud"):
        p.noise_resolution_gate = "somewhere"
    assert p.noise_resolution_gate == "cloud"
    assert p.threads == 0
    assert [o.name for o in pc.NormalOrientation.__members__.values()] == ["Auto", "PointNormals", "Viewpoint", "Propagate"]
    assert p.noise.name == pc.SensorNoiseModel.none().name
    # help() shows every parameter with its default.
    doc = pc.CollisionRequest.__init__.__doc__
    for text in ("free_below: float = 0.1", "collision_above: float = 0.9", "exhaustive: bool = False",
                 "per_point: bool = False", "rho_min: float = 0.001", "seed: int = 1", "surface: bool = False"):
        assert text in doc, text
    doc = pc.CloudModelParams.__init__.__doc__
    for text in ("k: int = 10", "n_max: int = 20", "n_min: Optional[int] = min(8, n_max)", "sigma_max: float = 0.05", "epsilon: float = 0.02",
                 "noise: pcl_probcollision._core.SensorNoiseModel = SensorNoiseModel.none()", "surface: bool = False",
                 "orientation: pcl_probcollision._core.NormalOrientation = <NormalOrientation.Auto: 0>",
                 "closed_objects: bool = False"):
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
    # t as a column or a row view of T: read in its own order, not by the last axis' stride
    same_result(r, pc.collide(table, gripper_patch, (T[:3, :3], T[:3, 3:4])))
    same_result(r, pc.collide(table, gripper_patch, (T[:3, :3], T[:3, 3:4].T)))


def test_none_is_not_a_model(table):
    with pytest.raises(TypeError):
        pc.collide(table, None, np.eye(4))
    with pytest.raises(TypeError):
        pc.collide_batch(None, table, np.eye(4)[None])


def test_triangle_indices_must_be_integers():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    assert len(pc.sample_mesh(V, np.array([[0, 1, 2]], np.uint8), 0.1)) > 0
    with pytest.raises(TypeError, match="integer"):
        pc.sample_mesh(V, [[0, 1, 1.9]], 0.1)
    with pytest.raises(ValueError, match="missing vertex"):
        pc.sample_mesh(V, np.array([[0, 1, 2**32 + 2]], np.int64), 0.1)


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


def test_a_built_model_gives_median_spacing_without_a_search_of_its_own(table_points):
    pts = table_points.astype(np.float64)
    pts[7, 0] = np.nan
    model = pc.build_model(pts, params=NOISE)
    assert model.median_neighbour_spacing == pc.median_spacing(pts)
    assert model.median_neighbour_spacing > 0
    # Covariances given: no neighbour search, so the model does not know it.
    exact = pc.build_model(pts, np.zeros((len(pts), 3, 3)), params=NOISE)
    assert np.isnan(exact.median_neighbour_spacing)


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


def test_thresholds_that_leave_a_verdict_unreachable_and_probabilities_outside_0_1_are_refused(table, gripper_patch):
    """free_below = 0 left nothing free and collision_above = 1 nothing in collision (a probe,
    2026-12-04); verdict_for took P = 1.5. The C++ rule and words (CollisionRequest::thresholdsError)."""
    for request, words in ((pc.CollisionRequest(free_below=0.0), r"free_below 0 outside \(0, 0\.5\]"),
                           (pc.CollisionRequest(collision_above=1.0), r"collision_above 1 outside \[0\.5, 1\)")):
        with pytest.raises(ValueError, match=words):
            request.validate()
        with pytest.raises(ValueError, match=words):
            pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.03), request)
        with pytest.raises(ValueError, match=words):
            pc.verdict_for(0.5, request)
    for p in (1.5, -0.1, np.inf):
        with pytest.raises(ValueError, match=r"probability .* outside \[0, 1\]"):
            pc.verdict_for(p, pc.CollisionRequest())
    assert pc.verdict_for(np.nan, pc.CollisionRequest()) == pc.Verdict.Unknown
    edges = pc.CollisionRequest(free_below=1e-12, collision_above=1 - 1e-12)
    assert pc.verdict_for(0.0, edges) == pc.Verdict.Free and pc.verdict_for(1.0, edges) == pc.Verdict.InCollision


def test_result_repr_and_verdict_enum(table, gripper_patch):
    r = pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.03))
    assert isinstance(r.verdict, pc.Verdict) and r.verdict == pc.Verdict.Free
    assert r.verdict == pc.verdict_for(r.probability, pc.CollisionRequest())
    with pytest.raises(ValueError, match="collision_above 1.5"):
        pc.verdict_for(0.5, pc.CollisionRequest(collision_above=1.5))
    text = repr(r)
    assert text.startswith("CollisionResult(status=Ok, verdict=Verdict.Free, probability=0.0")
    assert r.ok and r.status == pc.CollisionResult.Status.Ok
    assert np.isnan(r.query_ms)
    timed = pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.004), pc.CollisionRequest(enable_timings=True))
    assert timed.query_ms >= 0
    assert "size=10848" in repr(table)
    assert np.isnan(pc.CollisionResult().probability) and pc.CollisionResult().verdict == pc.Verdict.Unknown


def test_result_repr_shows_every_member(table, gripper_patch):
    # The repr left out answered_by (unless the surface layer answered), the nearest points of a
    # sample distance, the witness point and normal, points_skipped_nonfinite, the fit counts and
    # the timings (a probe, 2026-12-03). Each member is now shown where it means something: the
    # per-point arrays, the derived ok and the Status enum aside, every attribute is named by a
    # near result with timings, a far one with a sample distance, one stopped by its budget or
    # one with a message; a flag only when set.
    T = translation(0.1, 0.1, 0.004)
    near = pc.collide(table, gripper_patch, T, pc.CollisionRequest(enable_timings=True))
    far = pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.5), pc.CollisionRequest(distance=True))
    capped = pc.collide(table, gripper_patch, T, pc.CollisionRequest(max_leaf_fits=1, exhaustive=True))
    told = pc.collide(table, gripper_patch, T, pc.CollisionRequest(surface=True))  # no surface model: a message
    assert near.witness_side != 0 and far.sample_distance and far.no_leaf_tested
    assert capped.budget_exhausted and told.message
    results = (near, far, capped, told)
    members = {n for n in dir(pc.CollisionResult) if not n.startswith("_")} - {
        "probabilities_a", "probabilities_b", "ok", "Status", "in_frame"}  # in_frame: a method
    flags = {"full_resolution", "unobserved"}  # not set by these queries (tested with their layers)
    shown = {m for m in members if any(f"{m}=" in repr(r) for r in results)}
    assert shown == members - flags, sorted(members - flags - shown)
    for r in results:
        for f in flags | {"budget_exhausted", "sample_distance"}:
            assert (f"{f}=True" in repr(r)) == getattr(r, f), (f, repr(r))
        assert f"message={r.message!r}" in repr(r) if r.message else "message=" not in repr(r)

    def vector(v):
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"

    text = repr(near)
    assert "answered_by=AnsweredBy.Separators, lower_bound=" in text  # shown for the separators too
    assert f"witness_point={vector(near.witness_point)}, witness_normal={vector(near.witness_normal)}" in text
    assert f"query_ms={near.query_ms!r}" in text and f"kernel_leaf_pairs={near.kernel_leaf_pairs}," in text
    assert "nearest_point_a" not in text and "sample_distance" not in text
    text = repr(far)
    assert (f"sample_distance=True, nearest_point_a={vector(far.nearest_point_a)}, "
            f"nearest_point_b={vector(far.nearest_point_b)}") in text
    assert "witness_point" not in text and "query_ms" not in text  # no witness, no timings asked


# --- the surface layer (issue #16): signed distances -----------------------------------------------

SURFACE = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True)
GAPS = [-0.004, -0.002, 0.002, 0.004]  # b's height over a: penetrating .. clear


@pytest.fixture(scope="module")
def sheets():
    """A noisy 6 cm sheet a with outward normals up (+z) and a 3 cm sheet b with normals down,
    as numpy points with normals."""
    a, b = sheet(30, 0.06, seed=1), sheet(20, 0.03, seed=2)
    up = np.tile(np.float32([0, 0, 1]), (len(a), 1))
    return a, b, pc.build_model(a, params=SURFACE, normals=up), pc.build_model(b, params=SURFACE, normals=-up[:len(b)])


def test_surface_signed_distance_has_the_sign_of_the_gap(sheets):
    _, _, A, B = sheets
    assert A.has_surface and B.has_surface
    assert A.surface_orientation == B.surface_orientation == pc.NormalOrientation.PointNormals
    request = pc.CollisionRequest(surface=True)
    for z in GAPS:
        r = pc.collide(A, B, translation(0.005, -0.003, z), request)
        assert r.ok and np.isfinite(r.signed_distance) and np.isfinite(r.signed_distance_std), z
        assert np.sign(r.signed_distance) == np.sign(z), (z, r.signed_distance)
        assert abs(r.signed_distance - z) < 1e-3, (z, r.signed_distance)
        assert 0 < r.signed_distance_std < 3e-3
        # penetrating is a collision, a 4 mm gap (4 sigma) free
        assert r.verdict == {-0.004: pc.Verdict.InCollision, 0.004: pc.Verdict.Free}.get(z, r.verdict)
        text = repr(r)
        assert f"signed_distance={r.signed_distance!r}, signed_distance_std={r.signed_distance_std!r}" in text
    # Out of reach: no leaf pair, no distance.
    far = pc.collide(A, B, translation(0, 0, 0.2), request)
    assert far.no_leaf_tested and np.isnan(far.signed_distance) and np.isnan(far.signed_distance_std)
    assert "signed_distance" not in repr(far)


def test_surface_signed_distance_is_nan_when_off(sheets):
    a, b, A, B = sheets
    T = translation(0.005, -0.003, -0.002)
    off = pc.collide(A, B, T)  # request.surface off: the separators answer
    assert np.isnan(off.signed_distance) and np.isnan(off.signed_distance_std)
    assert "signed_distance" not in repr(off)
    # request.surface on, models built without a surface: the separators answer as well, the
    # same answer bit for bit as without the request's flag.
    plain = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    A0, B0 = pc.build_model(a, params=plain), pc.build_model(b, params=plain)
    assert not A0.has_surface and A0.surface_orientation is None
    r = pc.collide(A0, B0, T, pc.CollisionRequest(surface=True))
    assert np.isnan(r.signed_distance)
    # ... and the message says why (it said nothing before 2026-12-04).
    assert r.message == ("request.surface: model a was built without a surface model (CloudModelParams::surface), "
                         "so the separators answered")
    same_result(r, pc.collide(A0, B0, T), same_message=False)
    # The surface only adds to the points' model: the separators' answer is unchanged by it.
    same_result(off, r, same_message=False)


def test_unobserved_is_false_without_the_surface_layer(sheets):
    # CollisionResult.unobserved: a read-only bool, set only by the surface layer (an answer that
    # rests on surface the samples do not show); shown in the repr only when True.
    a, b, A, B = sheets
    assert pc.CollisionResult().unobserved is False
    T = translation(0.005, -0.003, -0.002)
    near, far = pc.collide(A, B, T), pc.collide(A, B, translation(0, 0, 0.2))
    assert near.ok and near.leaf_pairs_tested > 0 and far.no_leaf_tested
    for r in (near, far, *pc.collide_batch(A, B, np.stack([T, T]), threads=1)):
        assert r.unobserved is False
        assert "unobserved" not in repr(r)
    with pytest.raises(AttributeError):
        near.unobserved = True
    assert "surface" in type(near).unobserved.__doc__
    # With the surface layer the attribute is a bool either way; whether it is set depends on the
    # surface layer's detection (tested with it), so only the repr's consistency is asserted here.
    on = pc.collide(A, B, T, pc.CollisionRequest(surface=True))
    assert isinstance(on.unobserved, bool)
    assert ("unobserved=True" in repr(on)) == on.unobserved


def test_surface_pooled_is_the_mean_of_surface_and_separators(sheets):
    # CollisionRequest.surface_pooled: P is the mean of the surface layer's P and the
    # separators' on the same pair; the signed distance stays the surface layer's.
    _, _, A, B = sheets
    T = translation(0.005, -0.003, -0.002)
    # The mean is the raw one: the calibration map (surface_calibrated) acts on it afterwards.
    surface = pc.collide(A, B, T, pc.CollisionRequest(surface=True, exhaustive=True, surface_calibrated=False))
    separators = pc.collide(A, B, T, pc.CollisionRequest(exhaustive=True))
    pooled = pc.collide(A, B, T, pc.CollisionRequest(surface=True, surface_pooled=True, exhaustive=True,
                                                     surface_calibrated=False))
    assert pooled.probability == 0.5 * (surface.probability + separators.probability)
    assert pooled.signed_distance == surface.signed_distance
    assert "surface_pooled=True" in repr(pc.CollisionRequest(surface=True, surface_pooled=True))
    assert not pc.CollisionRequest().surface_calibrated
    # Without surface each switch would change nothing: the separators' answer under a request
    # naming the surface layer (the demo's pose 2 read 0.820 here against the CLI's 0.908).
    for switch in ("surface_pooled", "surface_ladder", "surface_calibrated"):
        with pytest.raises(ValueError, match=switch + " needs surface"):
            pc.collide(A, B, T, pc.CollisionRequest(**{switch: True}))
    assert "surface_calibrated=False" in repr(pc.CollisionRequest(surface=True, surface_calibrated=False))
    # The surface layer's cap: nothing to cap without it; with it, a capped answer is a flagged
    # lower bound of the uncapped one.
    with pytest.raises(ValueError, match="max_surface_pairs needs surface"):
        pc.collide(A, B, T, pc.CollisionRequest(max_surface_pairs=8))
    capped = pc.collide(A, B, T, pc.CollisionRequest(surface=True, exhaustive=True, surface_calibrated=False,
                                                     max_surface_pairs=1))
    assert capped.budget_exhausted and capped.lower_bound
    assert capped.probability <= surface.probability
    assert "max_surface_pairs=1" in repr(pc.CollisionRequest(surface=True, max_surface_pairs=1))


def test_surface_ladder_answers_as_the_rung_it_reaches(sheets):
    # CollisionRequest.surface_ladder: the separators' answer where they reached nothing or read
    # collision, else the surface layer's, alone in the contact band and pooled where they read
    # free. Over a sweep through contact at least two of the rungs answer.
    _, _, A, B = sheets
    rungs = set()
    sure_collisions = 0
    for z in np.linspace(-0.004, 0.03, 18):
        T = translation(0.005, -0.003, z)
        separators = pc.collide(A, B, T)
        surface = pc.collide(A, B, T, pc.CollisionRequest(surface=True))
        pooled = pc.collide(A, B, T, pc.CollisionRequest(surface=True, surface_pooled=True))
        ladder = pc.collide(A, B, T, pc.CollisionRequest(surface=True, surface_ladder=True))
        if separators.no_leaf_tested or separators.probability > 0.9:
            expected, rung = separators, "separators"
        elif separators.probability >= 0.1:
            expected, rung = surface, "surface"
        else:
            expected, rung = pooled, "pooled"
        rungs.add(rung)
        assert ladder.probability == expected.probability, (z, rung)
        assert ladder.verdict == expected.verdict
        # answered_by names each setting, and the ladder's rung.
        assert separators.answered_by == pc.AnsweredBy.Separators
        assert surface.answered_by == pc.AnsweredBy.SurfaceLayer
        assert pooled.answered_by == pc.AnsweredBy.Pooled
        assert ladder.answered_by == expected.answered_by, (z, rung)
        assert f"answered_by=AnsweredBy.{ladder.answered_by.name}," in repr(ladder)
        # A distance asked for: where the separators' sure collision stands, the surface layer's
        # distance (as it gives it alone) with their probability.
        if rung == "separators" and not separators.no_leaf_tested:
            asked = pc.collide(A, B, T, pc.CollisionRequest(surface=True, surface_ladder=True, distance=True))
            alone = pc.collide(A, B, T, pc.CollisionRequest(surface=True, distance=True))
            assert np.isnan(ladder.signed_distance), z
            assert asked.probability == separators.probability, z
            assert asked.answered_by == pc.AnsweredBy.Separators
            assert np.isfinite(alone.signed_distance), z
            assert asked.signed_distance == alone.signed_distance, z
            assert asked.signed_distance_std == alone.signed_distance_std, z
            sure_collisions += 1
    assert len(rungs) >= 2, rungs
    assert sure_collisions >= 1, "no sure collision of the separators in the sweep"
    assert pc.CollisionResult().answered_by == pc.AnsweredBy.Unknown
    assert "surface_ladder=True" in repr(pc.CollisionRequest(surface=True, surface_ladder=True))
    with pytest.raises(ValueError, match="surface_pooled and surface_ladder"):
        pc.CollisionRequest(surface=True, surface_pooled=True, surface_ladder=True).validate()


def test_distance_request_gives_the_nearest_samples_beyond_reach(sheets):
    # CollisionRequest.distance: beyond reach, signed_distance is the distance between the two
    # clouds' nearest samples (brute force here), nearest_point_a/_b those samples in A's frame.
    a, b, A, B = sheets
    T = translation(0.01, 0.02, 0.2)
    plain = pc.collide(A, B, T)
    assert plain.no_leaf_tested and np.isnan(plain.signed_distance) and not plain.sample_distance
    for request in (pc.CollisionRequest(distance=True), pc.CollisionRequest(distance=True, surface=True)):
        r = pc.collide(A, B, T, request)
        assert r.ok and r.no_leaf_tested and r.sample_distance
        moved = np.asarray(b, dtype=np.float64) + T[:3, 3]
        gaps = np.linalg.norm(np.asarray(a, dtype=np.float64)[:, None, :] - moved[None, :, :], axis=2)
        # The models hold the projected (denoised) samples: equal to the raw ones within the noise.
        assert r.signed_distance == pytest.approx(gaps.min(), abs=2e-3)
        assert np.linalg.norm(r.nearest_point_a - r.nearest_point_b) == pytest.approx(r.signed_distance, abs=1e-9)
        assert r.signed_distance_std > 0
        assert "sample_distance=True" in repr(r)
    # Within reach the surface layer's distance stands.
    near = pc.collide(A, B, translation(0.005, -0.003, -0.002), pc.CollisionRequest(distance=True, surface=True))
    assert not near.sample_distance and np.isnan(near.nearest_point_a).all()
    assert "distance=True" in repr(pc.CollisionRequest(distance=True))
    assert pc.CollisionRequest(distance=True) != pc.CollisionRequest()


def test_surface_numpy_equals_pcd_path_bit_for_bit(sheets, tmp_path):
    # The sheets as scans, a seen from above and b from below (PCD VIEWPOINT; Auto orients them
    # toward it): load_model of the files and build_model of the same floats with the same
    # viewpoint give the same surface answers bit for bit, collide and collide_batch alike.
    a, b, _, _ = sheets
    view_a, view_b = (0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0), (0.0, 0.0, -0.5, 1.0, 0.0, 0.0, 0.0)
    write_pcd(tmp_path / "a.pcd", a, view_a)
    write_pcd(tmp_path / "b.pcd", b, view_b)
    files = pc.load_model(tmp_path / "a.pcd", SURFACE), pc.load_model(tmp_path / "b.pcd", SURFACE)
    arrays = (pc.build_model(a, params=SURFACE, viewpoint=view_a, name="a.pcd"),
              pc.build_model(b, params=SURFACE, viewpoint=view_b, name="b.pcd"))
    assert files[0].surface_orientation == arrays[0].surface_orientation == pc.NormalOrientation.Viewpoint
    # Auto weighed the viewpoint, outside the sheet, and found no point hidden from it.
    assert files[0].surface_hidden_from_viewpoint == arrays[0].surface_hidden_from_viewpoint == 0.0
    request = pc.CollisionRequest(surface=True, exhaustive=True, per_point=True)
    poses = np.array([translation(0.005, -0.003, z) for z in GAPS + [0.2]])
    batch = pc.collide_batch(*arrays, poses, request, threads=2)
    for T, z, rb in zip(poses, GAPS + [0.2], batch):
        r, s = pc.collide(*files, T, request), pc.collide(*arrays, T, request)
        same_result(r, s)
        same_result(rb, s)
        if z < 0.1:
            # Within about one sigma_eff (1.4 mm): exhaustive, the deepest of 900 noisy points
            # answers, which the noise biases deeper (docs/SURFACE.md, shared error).
            assert np.sign(r.signed_distance) == np.sign(z) and abs(r.signed_distance - z) < 1.5e-3, (z, r.signed_distance)
        else:
            assert np.isnan(r.signed_distance)


def test_closed_objects_know_their_inside():
    # A sphere's samples without normals or a viewpoint: declared closed objects, the propagated
    # orientation is checked by the winding number and trusted, so a small ball wholly inside it,
    # out of reach of its surface, reads collision; undeclared, the surface is two-sided and the
    # ball reads free.
    i = np.arange(3000) + 0.5
    polar, azimuth = np.arccos(1.0 - 2.0 * i / 3000), np.pi * (1.0 + 5.0 ** 0.5) * i
    unit = np.stack([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=1)
    big = 0.5 * unit + [1.0, 2.0, 3.0]
    params = dict(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True, orientation=pc.NormalOrientation.Propagate)
    closed = pc.CloudModelParams(**params, closed_objects=True)
    assert closed.closed_objects and "closed_objects=True" in repr(closed)
    declared = pc.build_model(big, params=closed)
    undeclared = pc.build_model(big, params=pc.CloudModelParams(**params))
    assert declared.surface_inside_known is True and declared.surface_closed_share > 0.9
    assert declared.surface_solid_share > 0.9  # a smooth sphere: every probe behind reads inside
    assert undeclared.surface_inside_known is False and np.isnan(undeclared.surface_closed_share)
    assert np.isnan(undeclared.surface_solid_share) and np.isnan(declared.surface_hidden_from_viewpoint)
    ball = pc.build_model(0.05 * unit[::10] + [1.1, 2.0, 3.0], params=pc.CloudModelParams(**params))
    request = pc.CollisionRequest(surface=True)
    inside = pc.collide(ball, declared, np.eye(4), request)
    assert inside.verdict == pc.Verdict.InCollision and inside.signed_distance < -0.2, inside
    assert pc.collide(ball, undeclared, np.eye(4), request).verdict == pc.Verdict.Free


def test_normals_turned_toward_a_viewpoint_beside_a_solid_are_set_aside():
    # A sphere's normals as PCL's normal estimation leaves them, turned toward a viewpoint beside
    # it: most point in. Auto sets them aside and propagates; declared closed, a ball inside reads
    # collision. Asked for by name (PointNormals), they are taken as they are.
    i = np.arange(3000) + 0.5
    polar, azimuth = np.arccos(1.0 - 2.0 * i / 3000), np.pi * (1.0 + 5.0 ** 0.5) * i
    unit = np.stack([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=1)
    centre, view = np.array([0.6, 0.0, 0.0]), (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    points = 0.2 * unit + centre
    turned = np.where((np.einsum("ij,ij->i", unit, -points) < 0)[:, None], -unit, unit)
    assert np.mean(np.einsum("ij,ij->i", turned, unit) < 0) > 0.5
    closed = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True, closed_objects=True)
    aside = pc.build_model(points, params=closed, normals=turned, viewpoint=view)
    assert aside.surface_normals_turned_to_viewpoint is True
    assert aside.surface_orientation == pc.NormalOrientation.Propagate and aside.surface_inside_known is True
    assert aside.surface_hidden_from_viewpoint > 0.1
    outward = pc.build_model(points, params=closed, normals=unit, viewpoint=view)
    assert outward.surface_normals_turned_to_viewpoint is False
    assert outward.surface_orientation == pc.NormalOrientation.PointNormals
    asked = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True,
                                orientation=pc.NormalOrientation.PointNormals)
    taken = pc.build_model(points, params=asked, normals=turned, viewpoint=view)
    assert taken.surface_orientation == pc.NormalOrientation.PointNormals
    assert taken.surface_normals_turned_to_viewpoint is False
    assert pc.build_model(points).surface_normals_turned_to_viewpoint is None  # no surface model
    ball = pc.build_model(0.05 * unit[::10] + centre, params=pc.CloudModelParams(surface=True))
    inside = pc.collide(ball, aside, np.eye(4), pc.CollisionRequest(surface=True))
    assert inside.verdict == pc.Verdict.InCollision, inside


def test_normals_not_moved_with_their_points_are_set_aside(capfd):
    # A box's samples rotated 90 degrees about x, their face normals not (as transformPointCloud
    # leaves them): Auto sets them aside with a RuntimeWarning, asked for by name they are taken.
    g = np.linspace(-0.1, 0.1, 21)
    u, v = [a.ravel() for a in np.meshgrid(g, g)]
    points, normals = [], []
    for axis in range(3):
        for side in (-1.0, 1.0):
            p = np.zeros((u.size, 3))
            p[:, axis], p[:, (axis + 1) % 3], p[:, (axis + 2) % 3] = 0.1 * side, u, v
            n = np.zeros_like(p)
            n[:, axis] = side
            points.append(p)
            normals.append(n)
    points, normals = np.concatenate(points), np.concatenate(normals)
    rotated = np.stack([points[:, 0], -points[:, 2], points[:, 1]], axis=1)
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True, closed_objects=True)
    with pytest.warns(RuntimeWarning, match="lie along its surface"):
        aside = pc.build_model(rotated, params=params, normals=normals)
    assert "lie along its surface" not in capfd.readouterr().err  # said once, not on PCL's console too
    assert aside.surface_normals_off_surface is True
    assert aside.surface_given_normal_spread_ratio > 1.2
    assert aside.surface_orientation == pc.NormalOrientation.Propagate and aside.surface_inside_known is True
    moved = np.stack([normals[:, 0], -normals[:, 2], normals[:, 1]], axis=1)
    kept = pc.build_model(rotated, params=params, normals=moved)
    assert kept.surface_normals_off_surface is False and kept.surface_given_normal_spread_ratio < 0.1
    assert kept.surface_orientation == pc.NormalOrientation.PointNormals
    assert np.isnan(pc.build_model(rotated, params=params).surface_given_normal_spread_ratio)  # none given
    ball = pc.build_model(0.03 * rotated[::20] / 0.1, params=pc.CloudModelParams(surface=True))
    inside = pc.collide(ball, aside, np.eye(4), pc.CollisionRequest(surface=True))
    assert inside.verdict == pc.Verdict.InCollision, inside


def test_a_room_scanned_from_within_holds_a_part_under_its_floor():
    # A room's floor and four walls scanned from inside, oriented by that viewpoint as asked (Auto
    # takes no viewpoint within the cloud's box): behind the floor its walls' winding numbers
    # cancel the floor's, and a 1 cm cube 2 cm under the floor read free, d = +2 cm (8 of 10
    # positions; a probe, 2026-12-07). Behind is now measured from the viewpoint's own winding
    # number: the cube reads collision, unobserved; 1.8 cm over the floor it reads free.
    rng = np.random.default_rng(4)
    spacing, sigma = 0.03, 0.003

    def face(origin, u, v, lu, lv):
        a, b = np.meshgrid(np.arange(0, lu, spacing), np.arange(0, lv, spacing))
        a = a.ravel() + rng.uniform(0, 0.6 * spacing, a.size)
        b = b.ravel() + rng.uniform(0, 0.6 * spacing, b.size)
        return np.asarray(origin, float) + np.outer(a, u) + np.outer(b, v)

    room = np.vstack([face([0, 0, 0], [1, 0, 0], [0, 1, 0], 3, 3),
                      face([0, 0, 0], [0, 1, 0], [0, 0, 1], 3, 2.5), face([0, 0, 0], [1, 0, 0], [0, 0, 1], 3, 2.5),
                      face([3, 0, 0], [0, 1, 0], [0, 0, 1], 3, 2.5), face([0, 3, 0], [1, 0, 0], [0, 0, 1], 3, 2.5)])
    room += rng.normal(0, sigma, room.shape)
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(sigma), surface=True,
                                 orientation=pc.NormalOrientation.Viewpoint)
    scene = pc.build_model(room, params=params, viewpoint=[1.5, 1.5, 1.6, 1, 0, 0, 0])
    assert scene.surface_orientation == pc.NormalOrientation.Viewpoint
    corners = np.array([[x, y, z] for x in (-0.005, 0.005) for y in (-0.005, 0.005) for z in (-0.005, 0.005)])
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.int32)
    points, normals = pc.sample_mesh_with_normals(corners, faces, 0.001, 1)
    centre = points.mean(axis=0)
    normals *= np.sign(np.sum((points - centre) * normals, axis=1))[:, None]  # outward, whatever the winding
    cube = pc.build_model(points, np.zeros((len(points), 3, 3)), pc.CloudModelParams(surface=True), name="cube",
                          normals=normals)
    request = pc.CollisionRequest(surface=True, distance=True)
    spots = rng.uniform(0.5, 2.5, (10, 2))
    under = [pc.collide(scene, cube, translation(x, y, -0.025), request) for x, y in spots]
    assert [r.verdict for r in under] == [pc.Verdict.InCollision] * 10, [(r.verdict, r.signed_distance) for r in under]
    assert all(r.unobserved for r in under)
    above = [pc.collide(scene, cube, translation(x, y, 0.023), request) for x, y in spots]
    assert [r.verdict for r in above] == [pc.Verdict.Free] * 10, [(r.verdict, r.probability) for r in above]


def test_coincident_samples_are_modelled_once(table_points):
    # Every point twice (np.repeat) answers as the cloud once, bit for bit.
    points = table_points[np.isfinite(table_points).all(axis=1)][::7]
    once, twice = pc.build_model(points), pc.build_model(np.repeat(points, 2, axis=0))
    assert (once.coincident_samples, twice.coincident_samples) == (0, len(points))
    assert len(twice) == len(once)
    probe = pc.build_model(points[:200] + np.array([0.0, 0.0, 0.004], dtype=points.dtype))
    request = pc.CollisionRequest(per_point=True)
    r1, r2 = pc.collide(once, probe, np.eye(4), request), pc.collide(twice, probe, np.eye(4), request)
    assert r2.probability == r1.probability
    np.testing.assert_array_equal(np.asarray(r2.probabilities_a), np.repeat(np.asarray(r1.probabilities_a), 2))


def test_a_sparse_table_passing_under_a_fingertip_is_no_crossing():
    # The gripper's exact samples (its corners' vertices carry blended normals) over a table
    # sampled every 12 mm, 1 mm noise: a pair of table points either side of a finger, passing
    # 2.5-3 mm under its tip, read as crossing the finger (P = 1) at 3 of these 64 layouts, where
    # the fingertip's face had ended short of the crossing point (past its edge) but samples of the
    # side faces, within a corner-tilted plane's band, surrounded it. 3 mm into the table every
    # layout reads collision.
    v, f = pc.read_mesh(DATA / "gripper.obj")
    points, normals = pc.sample_mesh_with_normals(v, f, 0.003, 20111)
    params = lambda noise: pc.CloudModelParams(noise=noise, surface=True, threads=1)
    gripper = pc.build_model(np.asarray(points, float), params=params(pc.SensorNoiseModel.none()),
                             normals=np.asarray(normals, float), warn=False)
    spacing = 0.012
    for height, clear in ((-0.0025, True), (-0.003, True), (0.003, False)):
        answers = []
        for x0 in np.arange(0.0, spacing, 0.0015):
            for y0 in np.arange(0.0, spacing, 0.003):
                X, Y = np.meshgrid(np.arange(-0.09, 0.09, spacing) + x0, np.arange(-0.05, 0.05, spacing) + y0)
                table = pc.build_model(np.stack([X.ravel(), Y.ravel(), np.full(X.size, height)], 1),
                                       params=params(pc.SensorNoiseModel.isotropic(0.001)),
                                       viewpoint=(0, 0, 1, 1, 0, 0, 0), warn=False)
                answers.append(pc.collide(table, gripper, np.eye(4), pc.CollisionRequest(surface=True)).verdict)
        if clear:
            assert pc.Verdict.InCollision not in answers, (height, answers)
        else:
            assert answers == [pc.Verdict.InCollision] * len(answers), (height, answers)


def test_surface_normals_and_orientation_options(sheets):
    a, b, A, B = sheets
    # The normals change the surface only: the points' model (origin, size) is the same.
    A0 = pc.build_model(a, params=SURFACE)
    np.testing.assert_array_equal(A0.origin, A.origin)
    assert A0.size == A.size and A0.surface_orientation == pc.NormalOrientation.Propagate  # viewpoint inside
    assert A0.surface_inside_known is False and np.isnan(A0.surface_closed_share)  # two-sided, not checked
    for mode in (pc.NormalOrientation.Propagate, pc.NormalOrientation.Viewpoint):
        p = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True, orientation=mode)
        assert p.orientation == mode and f"orientation=NormalOrientation.{mode.name}" in repr(p)
        view = (0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0)
        assert pc.build_model(a, params=p, viewpoint=view).surface_orientation == mode
    # Flipped normals flip the sign: b seen as having its outside up, a's points are inside it.
    flipped = pc.build_model(b, params=SURFACE, normals=np.tile([0.0, 0.0, 1.0], (len(b), 1)))
    r = pc.collide(A, flipped, translation(0.005, -0.003, 0.004), pc.CollisionRequest(surface=True))
    assert r.signed_distance < 0
    # NaN or zero rows have no normal (oriented from their neighbours); bad ones are refused.
    partial = np.tile(np.float32([0, 0, 1]), (len(a), 1))
    partial[::3] = np.nan
    partial[1::3] = 0
    assert pc.build_model(a, params=SURFACE, normals=partial).surface_orientation == pc.NormalOrientation.PointNormals
    # PointNormals asked for without normals: nothing to take the sides from, so propagation
    # (two-sided), not a side picked and trusted.
    asked = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001), surface=True,
                                orientation=pc.NormalOrientation.PointNormals)
    none = pc.build_model(a, params=asked)
    assert none.surface_orientation == pc.NormalOrientation.Propagate and none.surface_inside_known is False
    # Normals without the surface model, which alone reads them, changed nothing without a word.
    with pytest.warns(RuntimeWarning, match=r"^cloud: normals given without params.surface: only the surface model"):
        unused = pc.build_model(a, normals=np.tile([0.0, 0.0, 1.0], (len(a), 1)))
    assert unused.size == pc.build_model(a).size
    with pytest.raises(ValueError, match="normals"):
        pc.build_model(a, normals=np.zeros((len(a) - 1, 3)))
    with pytest.raises(ValueError, match="normals"):
        pc.build_model(a, normals=np.zeros((len(a), 2)))
    with pytest.raises(ValueError, match="unit length"):
        pc.build_model(a, normals=np.tile([0.0, 0.0, 2.0], (len(a), 1)))
    broken = np.tile([0.0, 0.0, 1.0], (len(a), 1))
    broken[4, 1] = np.inf
    with pytest.raises(ValueError, match="point 4 has a normal with an infinite component"):
        pc.build_model(a, params=SURFACE, normals=broken)
    with pytest.raises(TypeError, match="normals"):
        pc.build_model(a, normals=np.zeros((len(a), 3), dtype=np.int32))


def write_pcd_with_normals(path, points, normals, fields="normal_x normal_y normal_z"):
    """An ascii PCD with x y z and the given normal fields (float32), the viewpoint at the origin."""
    rows = np.hstack([points, normals]).astype(np.float32)
    names = ("x y z " + fields).split()
    k = len(names)
    header = (f"VERSION 0.7\nFIELDS {' '.join(names)}\nSIZE {' '.join(['4'] * k)}\nTYPE {' '.join(['F'] * k)}\n"
              f"COUNT {' '.join(['1'] * k)}\nWIDTH {len(rows)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
              f"POINTS {len(rows)}\nDATA ascii\n")
    body = "".join(" ".join(repr(float(v)) for v in r) + "\n" for r in rows)
    pathlib.Path(path).write_text(header + body)


def test_load_model_uses_the_files_normals(sheets, tmp_path):
    # A PCD with normal_x normal_y normal_z: with params.surface, load_model orients its surface by
    # them (PointNormals, as build_model(normals=)), the same model bit for bit; reversed in the
    # file, they flip the sign of the distance. Without a surface they are not read.
    a, b, A, B = sheets
    up = np.tile(np.float32([0, 0, 1]), (len(a), 1))
    write_pcd_with_normals(tmp_path / "a.pcd", a, up)
    write_pcd_with_normals(tmp_path / "b.pcd", b, -up[:len(b)])
    write_pcd_with_normals(tmp_path / "b_up.pcd", b, up[:len(b)])
    write_pcd(tmp_path / "b_plain.pcd", b)
    FA, FB = pc.load_model(tmp_path / "a.pcd", SURFACE), pc.load_model(tmp_path / "b.pcd", SURFACE)
    assert FA.surface_orientation == FB.surface_orientation == pc.NormalOrientation.PointNormals
    # Without normals in the file, the same sheet (viewpoint inside its box) is propagated.
    assert pc.load_model(tmp_path / "b_plain.pcd", SURFACE).surface_orientation == pc.NormalOrientation.Propagate
    request = pc.CollisionRequest(surface=True, exhaustive=True, per_point=True)
    for z in GAPS:
        T = translation(0.005, -0.003, z)
        same_result(pc.collide(FA, FB, T, request), pc.collide(A, B, T, request))
    # b's file normals reversed (outside up): a 4 mm gap reads as a's points inside b.
    T = translation(0.005, -0.003, 0.004)
    assert pc.collide(FA, FB, T, request).signed_distance > 0
    flipped = pc.load_model(tmp_path / "b_up.pcd", SURFACE)
    assert flipped.surface_orientation == pc.NormalOrientation.PointNormals
    assert pc.collide(FA, flipped, T, request).signed_distance < 0
    # Without params.surface the file's normals are not read: the plain file's model.
    plain = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    no_surface = pc.load_model(tmp_path / "b.pcd", plain)
    assert not no_surface.has_surface and no_surface.surface_orientation is None
    same_result(pc.collide(FA, no_surface, T), pc.collide(FA, pc.load_model(tmp_path / "b_plain.pcd", plain), T))


def test_load_model_refuses_partial_normal_fields(sheets, tmp_path):
    a = sheets[0]
    write_pcd_with_normals(tmp_path / "half.pcd", a, np.zeros((len(a), 2)), fields="normal_x normal_z")
    with pytest.raises(ValueError, match="half.pcd.*'normal_y'"):
        pc.load_model(tmp_path / "half.pcd", SURFACE)
    # Without a surface the normals are not read, and the file is a plain cloud.
    assert len(pc.load_model(tmp_path / "half.pcd")) == len(a)


def test_sample_mesh_with_normals_is_sample_mesh_with_outward_normals():
    V, F = pc.read_mesh(DATA / "gripper.obj")
    points, normals = pc.sample_mesh_with_normals(V, F, 0.004)
    np.testing.assert_array_equal(points, pc.sample_mesh(V, F, 0.004))
    assert points.dtype == normals.dtype == np.float32 and normals.shape == points.shape
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
    # Outward: on the whole, normals point away from the mesh's centre.
    assert np.mean(np.sum((points - points.mean(axis=0)) * normals, axis=1)) > 0
    # The gripper's exact model with its faces' normals, as pcd_collision builds it with -surface.
    g = pc.build_model(points, np.zeros((len(points), 3, 3)), params=pc.CloudModelParams(surface=True), normals=normals)
    assert g.surface_orientation == pc.NormalOrientation.PointNormals


# --- the bad-input table (docs/RELIABILITY.md) ----------------------------------------------------

GOOD = patch(5)


@pytest.mark.parametrize("points, covariances, exc, words", [
    (GOOD.tolist(), None, TypeError, "points"),                             # not a numpy array
    (GOOD.astype(np.int32), None, TypeError, "points"),                     # integer dtype
    (GOOD.astype(np.float16), None, TypeError, "points"),                   # other float dtype
    (GOOD.astype(">f8"), None, TypeError, "points"),                        # foreign byte order
    (GOOD[:, :2], None, ValueError, "points"),                              # (N, 2)
    (GOOD.ravel(), None, ValueError, "points"),                             # 1-D
    (np.zeros((0, 3)), None, ValueError, "^cloud has no finite point"),     # empty
    (np.full((4, 3), np.nan), None, ValueError, "^cloud has no finite point"),  # all NaN
    (GOOD, np.full((len(GOOD), 3, 3), np.nan), ValueError,                  # all covariances missing
     r"with a finite covariance \(\d+ given, 0 non-finite, \d+ with a non-finite covariance\)"),
    (np.array([[1e300, 0, 0]] + [[0, 0, 0]] * 3), None, ValueError, "float range"),
    (GOOD, np.zeros((len(GOOD), 3)), ValueError, "covariances"),            # wrong covariance shape
    (GOOD, np.zeros((len(GOOD) - 1, 3, 3)), ValueError, "covariances"),     # wrong count
    (GOOD, np.zeros((len(GOOD), 3, 3), dtype=np.int64), TypeError, "covariances"),
    (GOOD, np.tile([[1e-4, 1e-5, 0], [0, 1e-4, 0], [0, 0, 1e-4]], (len(GOOD), 1, 1)), ValueError, "symmetric"),
])
def test_bad_points(points, covariances, exc, words, capfd):
    with pytest.raises(exc, match=words):
        pc.build_model(points, covariances)
    # The error is the exception alone: nothing printed besides (an empty array printed PCL's
    # "input_ is empty!" on stderr).
    assert capfd.readouterr().err == ""


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


def test_thread_counts_above_the_cap_are_refused_as_pcd_collision_refuses_them():
    # collide_batch(threads=10**6) was accepted and read as the library's cap (a probe, 2026-12-03)
    # where pcd_collision refuses -threads above it: one rule now (detail::threadsRangeError), the
    # same words, naming threads and the limit; CloudModelParams.threads too.
    a = pc.build_model(GOOD)
    limit = pc._core.MAX_THREADS
    assert limit == 1024
    words = pc._core.pcd_collision_usage_error(["a.pcd", "b.pcd", "-threads", str(limit + 1)])
    assert words == f"option -threads: '{limit + 1}' must be in [0, {limit}] (0: one per hardware thread)"
    for threads in (limit + 1, 10**6, -1):
        message = rf"^threads: must be in \[0, {limit}\] \(0: one per hardware thread\), got {threads}$"
        with pytest.raises(ValueError, match=message):
            pc.collide_batch(a, a, np.eye(4)[None], threads=threads)
        p = pc.CloudModelParams()
        with pytest.raises(ValueError, match=message):
            p.threads = threads
        assert p.threads == 0
    assert len(pc.collide_batch(a, a, np.stack([np.eye(4)] * 3), threads=limit)) == 3
    p.threads = limit
    assert p.threads == limit and len(pc.build_model(GOOD, params=p)) == len(pc.build_model(GOOD))


def test_huge_thread_counts_are_refused_as_any_other_out_of_range_count():
    # threads=10**12 raised pybind11's TypeError of a wrong type (beyond C int), where 1025 and -1
    # raise the ValueError naming threads (docs/RELIABILITY.md): a Python int of any size now gets
    # that ValueError, saying the count given, in each place threads is taken; a non-integer is
    # still a TypeError.
    a = pc.build_model(GOOD)
    limit = pc._core.MAX_THREADS
    for threads in (2**31, 10**12, -10**12, 10**100, -2**63 - 1):
        message = rf"^threads: must be in \[0, {limit}\] \(0: one per hardware thread\), got {threads}$"
        with pytest.raises(ValueError, match=message):
            pc.collide_batch(a, a, np.eye(4)[None], threads=threads)
        with pytest.raises(ValueError, match=message):
            pc.CloudModelParams(threads=threads)
        p = pc.CloudModelParams()
        with pytest.raises(ValueError, match=message):
            p.threads = threads
    for wrong in (1.5, "2", None):
        with pytest.raises(TypeError):
            pc.collide_batch(a, a, np.eye(4)[None], threads=wrong)
        with pytest.raises(TypeError):
            pc.CloudModelParams(threads=wrong)
        with pytest.raises(TypeError):
            p.threads = wrong
    # Integers that are not int (numpy's, a bool) still count, as pybind11's int caster took them.
    p.threads = np.int64(2)
    assert p.threads == 2 and pc.CloudModelParams(threads=np.uint8(3)).threads == 3
    assert len(pc.collide_batch(a, a, np.eye(4)[None], threads=np.int32(1))) == 1
    p.threads = True
    assert p.threads == 1
    p.threads = limit
    assert p.threads == limit and len(pc.build_model(GOOD, params=p)) == len(pc.build_model(GOOD))


@pytest.mark.parametrize("pose, exc, words", [
    (np.diag([2.0, 1, 1, 1]), ValueError, "rotation"),                     # scaled: not rigid
    (np.array([[1.0, 0.1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]), ValueError, "rotation"),  # sheared
    (translation(np.nan), ValueError, "not finite"),                        # non-finite
    (np.full((4, 4), np.nan), ValueError, "not finite"),                    # all NaN: not "last row"
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
    poses[1] = np.nan
    with pytest.raises(ValueError, match=r"poses\[1\]: the pose is not finite"):
        pc.collide_batch(a, a, poses)
    with pytest.raises(ValueError, match="poses"):
        pc.collide_batch(a, a, np.zeros((3, 3, 3)))
    with pytest.raises(TypeError, match="poses"):
        pc.collide_batch(a, a, "all")


def test_read_poses_reads_pcd_collisions_poses_files(tmp_path):
    """The demo's poses file as pcd_collision reads it (its -poses format: blanks or one comma,
    comments, blank lines), and its messages for malformed lines."""
    P = pc.read_poses(DATA / "demo_poses.txt")
    assert P.shape == (3, 6) and P.dtype == np.float64
    np.testing.assert_array_equal(P[2], [-0.15, 0.05, -0.02, 0, 0, 0])
    mixed = tmp_path / "mixed.txt"
    mixed.write_text("# tx ty tz roll pitch yaw\n\n1, 2, 3, 0.1, 0.2, 0.3  # a comment\n4 5 6\f0 0 0\n")
    np.testing.assert_array_equal(pc.read_poses(mixed), [[1, 2, 3, 0.1, 0.2, 0.3], [4, 5, 6, 0, 0, 0]])
    for text, words in (("0 0 0 0 0 0\n1 2 3 4 5\n", "p.txt:2: expected 6 numbers (tx ty tz roll pitch yaw), got 5"),
                        ("1 2 3 4 5 six\n", "p.txt:1: 'six' is not a number"),
                        ("1 2 3 4 5 nan\n", "p.txt:1: 'nan' is not a finite number"),
                        ("1,,2,3,4,5,6\n", "p.txt:1: empty field between commas"),
                        ("# nothing\n", "p.txt: no pose in the file")):
        bad = tmp_path / "p.txt"
        bad.write_text(text)
        with pytest.raises(ValueError) as e:
            pc.read_poses(bad)
        assert str(e.value) == f"path: {bad}{words[5:]}", (str(e.value), words)
    with pytest.raises(FileNotFoundError):
        pc.read_poses(tmp_path / "missing.txt")
    with pytest.raises(IsADirectoryError):
        pc.read_poses(tmp_path)


def test_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError):
        pc.load_model(tmp_path / "missing.pcd")
    with pytest.raises(IsADirectoryError):
        pc.load_model(tmp_path)  # a directory is not a file
    # The readers check the path before PCL sees it (on a directory its reader never returned).
    for read in (pc.read_cloud, pc._core.read_cloud_with_normals):
        with pytest.raises(IsADirectoryError):
            read(tmp_path)
        with pytest.raises(FileNotFoundError):
            read(tmp_path / "missing.pcd")
    not_pcd = tmp_path / "cloud.xyz"
    not_pcd.write_text("0 0 0\n")
    with pytest.raises(ValueError, match=r"\.pcd"):
        pc.load_model(not_pcd)
    garbage = tmp_path / "garbage.pcd"
    garbage.write_bytes(b"this is not a PCD file\n")
    with pytest.raises((ValueError, OSError), match="garbage.pcd"):
        pc.load_model(garbage)


def test_malformed_mesh_files(tmp_path, capfd):
    # VTK's readers crashed the interpreter on these (found in review); now a ValueError naming the file.
    xyz = "property float x\nproperty float y\nproperty float z\n"
    faces = "element face 1\nproperty list uchar int vertex_indices\n"
    cases = {
        "novertex.ply": "ply\nformat ascii 1.0\nelement vertex 0\n" + xyz + faces + "end_header\n3 0 1 2\n",
        "truncated.ply": "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + faces + "end_header\n0 0 0\n",
        "short.obj": "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    }
    for name, text in cases.items():
        (tmp_path / name).write_text(text)
        with pytest.raises(ValueError, match=name):
            pc.read_mesh(tmp_path / name)
    (tmp_path / "slashes.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/2/2 3/3/3\n")
    V, F = pc.read_mesh(tmp_path / "slashes.obj")
    assert V.shape == (3, 3) and F.tolist() == [[0, 1, 2]]
    assert capfd.readouterr().err == ""


def test_malformed_pcd_files(tmp_path, table_path, capfd):
    header = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 10\nHEIGHT 1\nPOINTS 10\nDATA binary\n"
    cases = {
        "nofields.pcd": b"VERSION 0.7\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n0 0 0\n",
        "truncated.pcd": header + b"\0" * 12,
        "no_z.pcd": b"VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n0 0\n",
        "empty.pcd": header.replace(b"10", b"0"),
        "cut.pcd": table_path.read_bytes()[:4000],
        # PCL's ASCII reader would read "abc" as 0: the value is named instead
        "word.pcd": b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\n"
                    b"DATA ascii\n0 0 0\n1 abc 1\n",
    }
    for name, content in cases.items():
        f = tmp_path / name
        f.write_bytes(content)
        with pytest.raises(ValueError, match=name):
            pc.load_model(f)
    with pytest.raises(ValueError, match=r"word\.pcd' line 11, value 2: 'abc' is not a number"):
        pc.load_model(tmp_path / "word.pcd")
    # An ascii PLY's likewise (PCL's reader took `abc` for NaN, a point skipped; a probe, 2026-12-03).
    ply = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    (tmp_path / "word.ply").write_bytes(ply + b"0 0 0\n1 abc 1\n")
    (tmp_path / "short.ply").write_bytes(ply + b"0 0 0\n1 1\n")
    for read in (pc.load_model, pc.read_cloud, pc._core.read_cloud_with_normals):
        with pytest.raises(ValueError, match=r"word\.ply' line 9, value 2: 'abc' is not a number"):
            read(tmp_path / "word.ply")
        with pytest.raises(ValueError, match=r"short\.ply' line 9: 2 values, expected 3"):
            read(tmp_path / "short.ply")
    # The exception is the one report: PCL's reader printed its own lines on stderr before.
    assert capfd.readouterr().err == ""


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


def test_noise_stop_keeps_nodes_within_the_noise_whole(table_points, gripper_patch):
    # BVHParams::noise_stop through CloudModelParams: the table's 5 mm noise on 3-4 mm spacing
    # leaves nodes within 20 sigmas unsplit, so the hierarchy is smaller and a query tests fewer boxes.
    params = pc.CloudModelParams(noise=NOISE.noise)
    stopped_params = pc.CloudModelParams(noise=NOISE.noise)
    stopped_params.noise_stop = 20.0
    assert stopped_params.noise_stop == 20.0
    plain, stopped = pc.build_model(table_points, params=params), pc.build_model(table_points, params=stopped_params)
    assert stopped.size == plain.size and stopped.bytes < plain.bytes
    T = translation(0.1, 0.1, 0.004)
    assert pc.collide(stopped, gripper_patch, T).bv_tests < pc.collide(plain, gripper_patch, T).bv_tests
    stopped_params.noise_stop = -1.0
    with pytest.raises(ValueError, match="noise_stop"):
        pc.build_model(table_points, params=stopped_params)


def test_wrong_argument_types_and_values_are_typeerror_and_valueerror():
    # pybind11's own cast failure is a RuntimeError; the README promises TypeError / ValueError.
    a = pc.build_model(np.random.default_rng(2).random((30, 3)))
    with pytest.raises(TypeError, match="params: expected CloudModelParams"):
        pc.build_model(np.random.default_rng(2).random((30, 3)), params=5)
    with pytest.raises(TypeError, match="request: expected CollisionRequest"):
        pc.collide(a, a, np.eye(4), request="x")
    with pytest.raises(TypeError, match="request: expected CollisionRequest"):
        pc.collide_batch(a, a, np.eye(4)[None], request=5)
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    for spacing in (0.0, float("nan"), 1e-9):
        with pytest.raises(ValueError, match="spacing"):
            pc.sample_mesh(V, [[0, 1, 2]], spacing)
        with pytest.raises(ValueError, match="spacing"):
            pc.sample_mesh_with_normals(V, [[0, 1, 2]], spacing)


def test_a_model_that_lost_precision_far_from_the_origin_warns():
    # 100 km out a float keeps 7.8 mm, far above a tenth of the 1 mm noise: CloudModel.warning,
    # which Python users see as a RuntimeWarning (the library's PCL console message goes unseen).
    # float32 points there were rounded by the caller; float64 ones lose nothing (they are taken
    # about an offset: test_float64_points_far_from_the_origin_lose_no_precision).
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    points = sheet().astype(np.float64)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pc.build_model(points + np.array([1e5, 0.0, 0.0]), params=params).warning == ""
    far = (points + np.array([1e5, 0.0, 0.0])).astype(np.float32)
    with pytest.warns(RuntimeWarning, match="float spacing") as caught:
        model = pc.build_model(far, params=params, name="far_sheet")
    assert model.warning and "far_sheet" in model.warning
    assert str(caught[0].message) == model.warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RuntimeWarning, match="float spacing"):
            pc.build_model(far, params=params)
        # At the origin: no warning at all.
        assert pc.build_model(points, params=params).warning == ""


def test_load_model_warns_as_build_model_does(tmp_path):
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    path = tmp_path / "far.pcd"
    write_pcd(path, sheet().astype(np.float64) + np.array([1e5, 0.0, 0.0]))
    with pytest.warns(RuntimeWarning, match="float spacing"):
        model = pc.load_model(path, params=params)
    assert "far.pcd" in model.warning


def test_load_model_warns_of_a_double_file_rounded_far_from_the_origin(tmp_path):
    # 10 km out a float keeps x to about 0.5 mm: over a tenth of the 1 mm sigma. load_model says
    # so of the file, as pcd_collision does, instead of the model's float-spacing warning.
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    points = sheet().astype(np.float64)
    far = tmp_path / "far.pcd"
    write_pcd_double(far, points + np.array([1e4, 0.0, 0.0]))
    *_, (change, magnitude) = pc.read_cloud(far, rounding=True)
    assert 1e-4 < change <= 4.9e-4 and magnitude == pytest.approx(1e4, abs=0.1)
    assert pc._core.read_cloud_with_normals(far, rounding=True)[-1] == (change, magnitude)
    assert len(pc.read_cloud(far)) == 4  # the tuple without rounding=True is unchanged
    with pytest.warns(RuntimeWarning) as caught:
        pc.load_model(far, params=params)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "'" + str(far) + "' stores x y z in double precision up to 10000" in messages[0]
    assert "of its sigma 0.001" in messages[0] and "float spacing" not in messages[0]
    # 1 km out (about 0.03 mm) and a float32 file: nothing to say of either.
    near = tmp_path / "near.pcd"
    write_pcd_double(near, points + np.array([1e3, 0.0, 0.0]))
    flat = tmp_path / "flat.pcd"
    write_pcd(flat, points)
    assert pc.read_cloud(flat, rounding=True)[-1] == (0.0, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for path in (near, flat):
            assert pc.load_model(path, params=params).warning == ""
    # build_model(warn=False) leaves the model's warning to the caller.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        quiet = pc.build_model((points + np.array([1e5, 0.0, 0.0])).astype(np.float32), params=params, warn=False)
    assert "float spacing" in quiet.warning


def test_collide_warns_when_the_models_sizes_differ_as_pcd_collision_does(table_points):
    # A model built from millimetres against one in metres answers for the numbers given (a plate
    # through a table reads free): collide and collide_batch say so with pcd_collision's words.
    points = table_points[np.isfinite(table_points).all(axis=1)]
    metres = pc.build_model(points)
    millimetres = pc.build_model(points * 1000.0, params=pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(5.0)))
    assert metres.diagonal == pytest.approx(pc._core.finite_diagonal(points), rel=1e-6)
    expected = pc._core.scale_warning(
        pc._core.InputFacts(path="a", finite=len(metres), diagonal=metres.diagonal),
        pc._core.InputFacts(path="b", finite=len(millimetres), diagonal=millimetres.diagonal))
    assert expected.startswith("the inputs' sizes differ by 999x") and "in 'a'" in expected  # float rounding
    with pytest.warns(RuntimeWarning) as caught:
        pc.collide(metres, millimetres, np.eye(4))
    assert [str(w.message) for w in caught] == [expected]
    with pytest.warns(RuntimeWarning, match=r"^the inputs' sizes differ by 999x"):
        pc.collide_batch(millimetres, metres, np.eye(4)[None], threads=1)
    # The same units, or check_units=False: not a word.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pc.collide(metres, metres, np.eye(4))
        pc.collide_batch(metres, millimetres, np.eye(4)[None], threads=1, check_units=False)
        pc.collide(millimetres, metres, np.eye(4), check_units=False)


def test_input_warnings_are_pcd_collisions():
    # The rules and words pcd_collision prints (io/input_warnings.h), as the Dask command line uses them.
    core = pc._core
    mm = core.InputFacts(path="mm.pcd", finite=1000, diagonal=700.0, sensor="isotropic", sigma=0.005)
    m = core.InputFacts(path="m.pcd", finite=1000, diagonal=0.7, sensor="isotropic", sigma=0.005)
    assert core.scale_warning(mm, m).startswith("the inputs' sizes differ by 1000x")
    assert core.scale_warning(m, m) == ""
    assert "the noise sigma 0.005 of 'mm.pcd'" in core.noise_warning(mm) and core.noise_warning(m) == ""
    far = core.InputFacts(path="far.pcd", finite=1000, diagonal=0.7, rounding=(0.0005, 1e4), sensor="isotropic", sigma=0.002)
    assert "0.25 of its sigma 0.002" in core.rounding_warning(far)
    assert core.model_warning(far, "float spacing") == "" and core.model_warning(m, "float spacing") == "'m.pcd': float spacing"
    assert core.between_samples_warning(True, True, 2, "pose 1", 0.08).startswith("pose 1 reads free")
    assert core.between_samples_warning(True, True, 0, "pose 1", 0.08) == ""
    # The size pcd_collision judges a cloud by: its finite points' bounding box.
    points = np.array([[0, 0, 0], [3, 4, 12], [np.nan, 0, 0], [1, 1, 1]], dtype=np.float32)
    assert core.finite_diagonal(points) == 13.0 and core.finite_diagonal(points[:1]) == 0.0


def test_load_model_reads_a_faceless_ply_as_pcd_collision_does(tmp_path):
    # pcd_collision and read_cloud take a .ply without faces as a cloud; load_model refused it.
    points = sheet()
    ply = tmp_path / "sheet.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n" % len(points) + "".join("%r %r %r\n" % tuple(map(float, p)) for p in points))
    pcd = tmp_path / "sheet.pcd"
    write_pcd(pcd, points)
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    a, b = pc.load_model(ply, params=params), pc.load_model(pcd, params=params)
    assert len(a) == len(b) == len(points)
    r = pc.collide(a, b, translation(z=0.0005))
    assert r.probability == pc.collide(b, b, translation(z=0.0005)).probability
    mesh = tmp_path / "triangle.ply"
    mesh.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    with pytest.raises(ValueError, match="triangle.ply' is a mesh"):
        pc.load_model(mesh)


def test_parse_poses_reads_text_as_read_poses_reads_a_file(tmp_path):
    text = b"# poses\n0 0 0.1 0 0 0\n1,2,3,0.1,0.2,0.3\n"
    f = tmp_path / "p.txt"
    f.write_bytes(text)
    assert np.array_equal(pc.parse_poses(text), pc.read_poses(f))
    with pytest.raises(ValueError, match=r"^text: standard input:2: expected 6 numbers"):
        pc.parse_poses(b"0 0 0 0 0 0\n1 2 3\n")
    with pytest.raises(ValueError, match=r"^text: pipe: no pose in the file"):
        pc.parse_poses(b"# nothing\n", "pipe")


def test_the_version_is_the_projects():
    # project(VERSION) in CMakeLists.txt is the one owner; pcd_collision -version prints it too.
    import re
    cmake = (pathlib.Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text()
    version = re.search(r"project\(pcl_probcollision VERSION (\d+\.\d+\.\d+)", cmake).group(1)
    assert pc.__version__ == version
    assert pc._core.__version__ == version


def test_the_stub_names_what_the_module_has():
    # _core.pyi lacked full_resolution, sample_distance, nearest_point_a/_b and
    # keeps_full_resolution (a probe, 2026-12-03): every public name of the module and of each of
    # its classes is in the stub, and the stub names nothing the module lacks.
    import ast
    core = pc._core
    tree = ast.parse(pathlib.Path(pc.__file__).with_name("_core.pyi").read_text())

    def names(body):
        out = set()
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                out.add(node.name)
            elif isinstance(node, ast.AnnAssign):
                out.add(node.target.id)
            elif isinstance(node, ast.Assign):
                out |= {t.id for t in node.targets if isinstance(t, ast.Name)}
        return out

    top = {n for n in names(tree.body) if not n.startswith("_")}  # _Pose, _Path, _Enum: the stub's own
    assert top == {n for n in dir(core) if not n.startswith("_")}
    classes = [node for node in tree.body if isinstance(node, ast.ClassDef) and not node.name.startswith("_")]
    enum_base = next(node for node in tree.body if isinstance(node, ast.ClassDef) and node.name == "_Enum")
    assert len(classes) >= 8
    for node in classes:
        have = {n for n in dir(getattr(core, node.name)) if not n.startswith("_")}
        stub = names(node.body) - {"__init__", "__len__"}
        if any(isinstance(b, ast.Name) and b.id == "_Enum" for b in node.bases):
            stub |= {n for n in names(enum_base.body) if not n.startswith("_")}  # name, value
        assert have == stub, (node.name, sorted(have - stub), sorted(stub - have))


def test_the_stub_describes_the_enums_the_module_has():
    # The stub declared the enums enum.IntEnum; the module's are pybind11's py::enum_ (pybind11 2.10
    # has no py::native_enum): no int subclass, == only with their own kind (docs/RELIABILITY.md).
    # The stub now says so (its _Enum), and what it says holds: each enum's members, in order, are
    # its __members__, each has what _Enum declares, and a member is its value to int() and index().
    import ast
    import enum
    import operator
    core = pc._core
    tree = ast.parse(pathlib.Path(pc.__file__).with_name("_core.pyi").read_text())
    stub = {}

    def walk(body, prefix):
        for node in body:
            if isinstance(node, ast.ClassDef):
                bases = [ast.unparse(b) for b in node.bases]
                if bases in (["enum.IntEnum"], ["_Enum"]):
                    stub[prefix + node.name] = bases[0], [n.target.id for n in node.body if isinstance(n, ast.AnnAssign)]
                walk(node.body, prefix + node.name + ".")

    walk(tree.body, "")
    runtime = {}
    for name, cls in vars(core).items():
        if isinstance(cls, type):
            runtime.update({name: cls} if "__members__" in vars(cls) else {})
            runtime.update({name + "." + n: c for n, c in vars(cls).items() if isinstance(c, type) and "__members__" in vars(c)})
    assert len(runtime) == 8 and set(stub) == set(runtime)
    for name, (claimed_base, members) in stub.items():
        assert issubclass(runtime[name], enum.IntEnum) == (claimed_base == "enum.IntEnum"), (name, claimed_base)
        assert members == list(runtime[name].__members__), name
    base = next(node for node in tree.body if isinstance(node, ast.ClassDef) and node.name == "_Enum")
    declared = [n.name if isinstance(n, ast.FunctionDef) else n.target.id for n in base.body
                if isinstance(n, (ast.FunctionDef, ast.AnnAssign))]
    assert {"__int__", "__index__", "__members__", "name", "value"} <= set(declared)
    for name, cls in runtime.items():
        assert [attr for attr in declared if not hasattr(cls, attr)] == [], name
        for member_name, member in cls.__members__.items():
            assert member.name == member_name and getattr(cls, member_name) == member
            assert int(member) == operator.index(member) == member.value and cls(member.value) == member
    # As _Enum's docstring says: not an int, equal to its own kind only, an index all the same.
    assert not isinstance(pc.Verdict.Free, int) and pc.Verdict.Free != 1 and int(pc.Verdict.Free) == 1
    assert ["a", "b"][pc.Verdict.Free] == "b"


def test_the_stub_gives_each_function_the_module_s_parameters():
    # Beside the names (above): every function and method of the stub takes the parameters the
    # module's takes, by name and kind (positional, keyword-only), read from pybind11's signature
    # line; CloudModelParams' constructor lacked n_noise_max and leakage_bound in both.
    import ast
    core = pc._core
    tree = ast.parse(pathlib.Path(pc.__file__).with_name("_core.pyi").read_text())

    def split_top(text):
        parts, depth, cur = [], 0, ""
        for ch in text:
            depth += ch in "([{"
            depth -= ch in ")]}"
            if ch == "," and depth == 0:
                parts.append(cur.strip())
                cur = ""
            else:
                cur += ch
        return parts + ([cur.strip()] if cur.strip() else [])

    def module_params(obj):
        line = (obj.__doc__ or "").splitlines()[0]
        start = line.index("(")
        depth = 0
        for end in range(start, len(line)):
            depth += (line[end] == "(") - (line[end] == ")")
            if depth == 0:
                break
        positional, keyword, star = [], [], False
        for part in split_top(line[start + 1:end]):
            if part == "*":
                star = True
                continue
            (keyword if star else positional).append(part.split(":")[0].split("=")[0].strip())
        return [n for n in positional if n != "self"], keyword

    def stub_params(node):
        positional = [a.arg for a in node.args.posonlyargs + node.args.args if a.arg not in ("self", "cls")]
        return positional, [a.arg for a in node.args.kwonlyargs]

    checked = 0

    enums = [v for v in vars(core).values() if isinstance(v, type) and hasattr(v, "__members__")]

    def check(body, owner, where):
        nonlocal checked
        for node in body:
            if isinstance(node, ast.ClassDef) and node.name == "_Enum":  # stub-only: every enum's methods
                for e in enums + [core.CollisionResult.Status]:
                    check(node.body, e, where + e.__name__ + ".")
            elif isinstance(node, ast.ClassDef):
                check(node.body, getattr(owner, node.name), where + node.name + ".")
            elif isinstance(node, ast.FunctionDef) and not any(
                    isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
                if node.name == "__len__":
                    continue
                assert stub_params(node) == module_params(getattr(owner, node.name)), where + node.name
                checked += 1

    check(tree.body, core, "")
    assert checked >= 40, checked


def test_a_path_that_is_not_utf8_is_read_and_named_in_its_errors(tmp_path):
    # A path whose bytes are not UTF-8 (bytes, or a str holding them as surrogates, os.fsdecode)
    # gave an empty ValueError, a missing one UnicodeDecodeError (docs/RELIABILITY.md). Each reader
    # now raises what it raises for any path: FileNotFoundError and IsADirectoryError with the
    # filename os.fsdecode gives (as open()), ValueError naming it with \xNN; and such a file reads.
    raw = os.fsencode(tmp_path) + b"/x\xff"
    readers = (pc.load_model, pc.read_cloud, pc._core.read_cloud_with_normals, pc.read_mesh, pc.read_poses,
               pc.is_faceless_ply)
    os.mkdir(raw + b".d")
    for f in readers:
        for given in (bytes, os.fsdecode, lambda p: pathlib.Path(os.fsdecode(p))):
            with pytest.raises(FileNotFoundError) as missing:
                f(given(raw + b".pcd"))
            assert missing.value.filename == os.fsdecode(raw + b".pcd")
            with pytest.raises(IsADirectoryError) as directory:
                f(given(raw + b".d"))
            assert directory.value.filename == os.fsdecode(raw + b".d")
    escaped = os.fsdecode(raw).replace("\udcff", "\\xff")  # the name as the messages spell it
    bad = raw + b"_bad.pcd"
    with open(bad, "wb") as f:
        f.write(b"not a point cloud\n")
    for f in (pc.load_model, pc.read_cloud, pc._core.read_cloud_with_normals, pc.read_mesh, pc.read_poses):
        with pytest.raises(ValueError) as refused:
            f(bad)
        assert escaped + "_bad.pcd" in str(refused.value), (f.__name__, str(refused.value))
    os.rename(bad, raw + b"_bad.txt")
    with pytest.raises(ValueError, match=r"only \.pcd and face-less \.ply files are read, got '.*x\\xff_bad\.txt'"):
        pc.load_model(raw + b"_bad.txt")
    # Such a file reads as under any name; the model's default name and the file's warning say it.
    points = sheet()
    write_pcd(os.fsdecode(raw + b".pcd"), points)
    write_pcd(tmp_path / "plain.pcd", points)
    for given in (raw + b".pcd", os.fsdecode(raw + b".pcd")):
        assert np.array_equal(pc.read_cloud(given)[0], pc.read_cloud(tmp_path / "plain.pcd")[0])
        assert len(pc.load_model(given)) == len(pc.load_model(tmp_path / "plain.pcd"))
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.001))
    write_pcd_double(os.fsdecode(raw + b"_far.pcd"), points.astype(np.float64) + np.array([1e4, 0.0, 0.0]))
    with pytest.warns(RuntimeWarning) as caught:
        pc.load_model(raw + b"_far.pcd", params=params)
    assert [escaped + "_far.pcd' stores x y z in double precision" in str(w.message) for w in caught] == [True]
    write_pcd(os.fsdecode(raw + b"_f32.pcd"), points.astype(np.float64) + np.array([1e5, 0.0, 0.0]))
    with pytest.warns(RuntimeWarning, match=r"^x\\xff_f32\.pcd: .*float spacing"):
        pc.load_model(raw + b"_f32.pcd", params=params)


def test_a_name_holding_a_nul_is_refused():
    # A NUL in name cut the messages naming the cloud ("ab\0cd" gave ValueError('ab'), a probe):
    # build_model and load_model refuse it, naming name, rather than cut a message later.
    message = r"^name: contains a NUL character \(at index 2\), which would cut the messages naming the cloud, got 'ab\\x00cd'$"
    with pytest.raises(ValueError, match=message):
        pc.build_model(GOOD, name="ab\0cd")
    with pytest.raises(ValueError, match=message):
        pc.build_model(np.zeros((0, 3)), name="ab\0cd")  # before the points' own error, which names it
    with pytest.raises(ValueError, match=message):
        pc.load_model(DATA / "table_mug.pcd", name="ab\0cd")
    assert len(pc.build_model(GOOD, name="ab cd")) == len(pc.build_model(GOOD))


def test_missing_mesh_files_raise_file_not_found():
    # read_mesh of a missing file raised ValueError and is_faceless_ply answered False (a probe,
    # 2026-12-03): both now raise what open() would, as read_cloud and load_model do.
    for f in (pc.read_mesh, pc._core.is_faceless_ply, pc.read_cloud):
        with pytest.raises(FileNotFoundError):
            f("/no/such/dir/mesh.ply")
        with pytest.raises(IsADirectoryError):
            f(DATA)


def test_cloud_model_params_takes_every_member_as_a_keyword():
    # CloudModelParams(split=..., threads=..., noise_resolution=...) raised TypeError, and
    # n_max=5 failed validation with n_min left at 8 where pcd_collision's -nmax 5 works (a probe,
    # 2026-12-03).
    p = pc.CloudModelParams(threads=1, noise_resolution=2.0, noise_resolution_gate="spacing",
                            keep_full_resolution=False, noise_stop=1.5, split="octree", n_max=5,
                            noise=pc.SensorNoiseModel.isotropic(0.0031))
    assert (p.threads, p.noise_resolution, p.noise_resolution_gate, p.keep_full_resolution, p.noise_stop, p.split) == \
        (1, 2.0, "spacing", False, 1.5, "octree")
    assert (p.n_max, p.n_min) == (5, 5)
    p.validate()
    assert pc.CloudModelParams(n_max=5, n_min=3).n_min == 3
    assert pc.CloudModelParams().n_min == 8 and pc.CloudModelParams(n_max=40).n_min == 8
    flags = pc._core.pcd_collision_params(["-nmax=5"])[0]
    assert (flags.n_max, flags.n_min) == (5, 5)
    # The attribute leaves n_min as it is; the refusal says to set it too (it said only that
    # n_min 8 was out of range).
    q = pc.CloudModelParams()
    q.n_max = 5
    with pytest.raises(ValueError, match=r"n_min 8 outside \[1, n_max = 5\]: set n_min too when lowering n_max"):
        q.validate()
    with pytest.raises(ValueError, match="set n_min too"):
        pc.build_model(GOOD, params=q)
    q.n_min = 5
    q.validate()
    # The repr holds every member and builds the same parameters back.
    q = eval(repr(p), {"CloudModelParams": pc.CloudModelParams, "SensorNoiseModel": pc.SensorNoiseModel,
                       "NormalOrientation": pc.NormalOrientation})
    assert repr(q) == repr(p)
    assert "noise=SensorNoiseModel.isotropic(0.0031)" in repr(p)  # it read isotropic(...)
    assert repr(pc.SensorNoiseModel.isotropic(0.25)) == "SensorNoiseModel.isotropic(0.25)"
    with pytest.raises(ValueError, match="split: expected 'pca' or 'octree', got 'kd'"):
        pc.CloudModelParams(split="kd")
    with pytest.raises(ValueError, match="noise_resolution_gate"):
        pc.CloudModelParams(noise_resolution_gate="nowhere")
    with pytest.raises(ValueError, match="threads"):
        pc.CloudModelParams(threads=-1)


def test_params_and_request_take_every_attribute_as_a_keyword_and_show_it():
    # CloudModelParams lacked n_noise_max and leakage_bound (BVHParams members the C++ struct has)
    # as keywords, attributes and in its repr. Every attribute of CloudModelParams and
    # CollisionRequest is now a keyword of its constructor and named in its repr, which builds it
    # back; the two noise_resolution_gate views and the applied radius are the only ones left out
    # (derived, not members).
    derived = {"noise_resolution_gated", "noise_resolution_whole_cloud", "noise_resolution_applied"}
    scope = {"CloudModelParams": pc.CloudModelParams, "CollisionRequest": pc.CollisionRequest,
             "SensorNoiseModel": pc.SensorNoiseModel, "NormalOrientation": pc.NormalOrientation,
             "TraversalMode": pc.TraversalMode, "ClassifierParams": pc.ClassifierParams,
             "KernelMode": pc.KernelMode, "TrainingMode": pc.TrainingMode, "Loss": pc.Loss}
    for cls in (pc.CloudModelParams, pc.CollisionRequest, pc.ClassifierParams):
        default = cls()
        names = [n for n in dir(cls) if not n.startswith("_") and n not in derived and not callable(getattr(default, n))]
        assert len(names) >= 14, names
        for n in names:
            made = cls(**{n: getattr(default, n)})  # TypeError for a member that is no keyword
            assert f"{n}=" in repr(made), (cls.__name__, n, repr(made))
        assert repr(eval(repr(default), scope)) == repr(default)
    p = pc.CloudModelParams(n_noise_max=80, leakage_bound="union_bound", noise_stop=2.0)
    assert (p.n_noise_max, p.leakage_bound) == (80, "union_bound")
    assert "n_noise_max=80" in repr(p) and "leakage_bound='union_bound'" in repr(p)
    assert repr(eval(repr(p), scope)) == repr(p)
    assert (pc.CloudModelParams().n_noise_max, pc.CloudModelParams().leakage_bound) == (160, "min_slab")
    with pytest.raises(ValueError, match="leakage_bound: expected 'min_slab' or 'union_bound', got 'max'"):
        pc.CloudModelParams(leakage_bound="max")
    with pytest.raises(ValueError, match="n_noise_max 0"):
        pc.CloudModelParams(n_noise_max=0).validate()
    # They reach the model's build.
    m = pc.build_model(patch(20), params=pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.002),
                                                       leakage_bound="union_bound"))
    assert m.params.leakage_bound == "union_bound"


def test_invert_poses_refuses_what_collide_refuses():
    # invert_poses took a scaled matrix and returned its "inverse" by transposing the rotation
    # (a probe, 2026-12-03): it now checks as collide() does, naming the pose.
    good = np.eye(4)[None].repeat(2, axis=0)
    good[1, :3, 3] = (1.0, 2.0, 3.0)
    np.testing.assert_allclose(pc.invert_poses(good)[1, :3, 3], (-1.0, -2.0, -3.0))
    scaled = good.copy()
    scaled[1, :3, :3] *= 2.0
    with pytest.raises(ValueError, match=r"poses\[1\] is not a rotation plus translation"):
        pc.invert_poses(scaled)
    reflected = good.copy()
    reflected[0, 0, 0] = -1.0
    with pytest.raises(ValueError, match="a reflection"):
        pc.invert_poses(reflected)
    row = good.copy()
    row[0, 3, 0] = 1.0
    with pytest.raises(ValueError, match=r"poses\[0\]: the last row"):
        pc.invert_poses(row)


def quaternion_pose(q, t):
    """The 4x4 pose of quaternion (w, x, y, z) q, NOT normalised (as Eigen's toRotationMatrix and a
    hand-written conversion take one read from a file), and translation t."""
    w, x, y, z = q
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = t
    return T


def test_a_rotation_rounded_to_a_few_digits_is_taken_to_the_nearest_rotation(gripper_patch, table):
    # A quaternion printed with 6 decimals (a YAML pose; tf_echo prints 3) gives a matrix whose
    # R^T R departs from the identity by up to 6e-6: about half of such poses were refused as
    # "not a rotation plus translation" (a probe, 2026-12-06). collide(), collide_batch() and
    # invert_poses() take them as their nearest rotation now.
    # Tilted 4 degrees from z: 6 decimals depart by 2.8e-6, 3 by 2.5e-3.
    angle, axis = 1.83, np.array([0.05, 0.05, 1.0]) / np.sqrt(1.005)
    exact = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])
    t = (0.002, -0.001, 0.004)
    want = pc.collide(gripper_patch, table, quaternion_pose(exact, t))
    assert want.leaf_pairs_tested > 0  # near contact: the rotation matters
    for decimals in (6, 3):
        T = quaternion_pose(np.round(exact, decimals), t)
        R = T[:3, :3]
        assert np.abs(R.T @ R - np.eye(3)).max() > 1e-6  # refused before
        got = pc.collide(gripper_patch, table, T)
        same_result(got, pc.collide_batch(gripper_patch, table, T[None], threads=1)[0])
        inverse = pc.invert_poses(T[None])[0]
        np.testing.assert_allclose(inverse[:3, :3] @ inverse[:3, :3].T, np.eye(3), rtol=0, atol=1e-15)
        np.testing.assert_allclose(inverse[:3, :3].T, R, rtol=0, atol=2e-3)  # the nearest rotation
        if decimals == 6:
            assert got.verdict == want.verdict
            assert abs(got.probability - want.probability) < 1e-3
    scaled = np.eye(4)
    scaled[:3, :3] *= 1.01
    with pytest.raises(ValueError, match=r"departs from the identity by 0\.0201, more than the tolerance 0\.01"):
        pc.collide(gripper_patch, table, scaled)


def test_in_frame_maps_the_witness_and_nearest_points_as_pcd_collision_reports_them(gripper_patch, table):
    # collide() answers in a's frame; in_frame(T_b_a) gives b's, with the library's own arithmetic
    # (the Dask layer's numpy rotation differed from pcd_collision's in the last bit of a normal).
    yaw = 0.7
    T_b_a = pc.poses_from_xyzrpy([[0.01, -0.02, 0.005, 0.1, -0.05, yaw]])
    T_a_b = pc.invert_poses(T_b_a)[0]
    r = pc.collide(gripper_patch, table, T_a_b, pc.CollisionRequest(distance=True))
    assert r.witness_side != 0
    moved = r.in_frame(T_b_a[0])
    R, t = T_b_a[0, :3, :3], T_b_a[0, :3, 3]
    np.testing.assert_allclose(moved.witness_point, R @ r.witness_point + t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(moved.witness_normal, R @ r.witness_normal, rtol=0, atol=1e-15)
    assert np.linalg.norm(moved.witness_point - r.witness_point) > 1e-3  # it did move
    assert moved.probability == r.probability and moved.verdict == r.verdict
    far = pc.collide(gripper_patch, table, translation(z=-0.5), pc.CollisionRequest(distance=True))
    assert far.sample_distance
    far_b = far.in_frame(translation(z=0.5))
    np.testing.assert_allclose(far_b.nearest_point_a, far.nearest_point_a + (0, 0, 0.5), rtol=0, atol=1e-15)
    np.testing.assert_allclose(far_b.nearest_point_b, far.nearest_point_b + (0, 0, 0.5), rtol=0, atol=1e-15)
    scaled = np.eye(4) * 2.0
    scaled[3, 3] = 1.0
    with pytest.raises(ValueError, match="not a rotation plus translation"):
        r.in_frame(scaled)


def test_float64_points_far_from_the_origin_lose_no_precision():
    # float64 points in a UTM-like frame were rounded to float32 (0.25-0.5 m steps) before the
    # model centred them: a 2 cm cube 1 cm into a table read free (a probe, 2026-12-06). They are
    # now taken about an offset in double (offsetModel), and answer as the same scene at the origin.
    rng = np.random.default_rng(0)
    g = np.linspace(-0.2, 0.2, 60)
    table = np.stack(np.meshgrid(g, g) + [np.zeros((60, 60))], -1).reshape(-1, 3) + rng.normal(0, 0.002, (3600, 3))
    face = rng.integers(0, 6, 2000)
    cube = rng.uniform(-0.01, 0.01, (2000, 3))
    cube[np.arange(2000), face // 2] = np.where(face % 2, 0.01, -0.01)
    cube[:, 2] += 0.01
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.002), surface=True)
    far = np.array([500000.0, 4200000.0, 100.0])
    view = (0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no precision warning: nothing was lost
        a_far = pc.build_model(table + far, params=params, viewpoint=(far[0], far[1], far[2] + 1.0, 1.0, 0.0, 0.0, 0.0))
        b_far = pc.build_model(cube + far, params=params)
    a = pc.build_model(table, params=params, viewpoint=view)
    b = pc.build_model(cube, params=params)
    np.testing.assert_allclose(a_far.origin - far, a.origin, atol=1e-6)
    for request in (pc.CollisionRequest(), pc.CollisionRequest(surface=True, distance=True)):
        for x, z in ((0.0, -0.01), (0.05, -0.01), (0.0, 0.03), (0.0, 0.3), (0.3, 0.0)):
            near, mapped = (pc.collide(m_a, m_b, translation(x=x, z=z), request) for m_a, m_b in ((a, b), (a_far, b_far)))
            assert mapped.verdict == near.verdict, (x, z, request.surface)
            assert mapped.probability == pytest.approx(near.probability, abs=0.02), (x, z)
            if request.surface:
                assert mapped.signed_distance == pytest.approx(near.signed_distance, abs=2e-4), (x, z)
        deep = pc.collide(a_far, b_far, translation(z=-0.01), request)  # the cube 1 cm into the table
        assert deep.verdict == pc.Verdict.InCollision
    # float32 points there are still what the caller rounded, and still warned of.
    with pytest.warns(RuntimeWarning, match="lost precision"):
        pc.build_model((table + far).astype(np.float32), params=params)


def test_normals_facing_away_from_a_viewpoint_outside_are_warned_of():
    # A sensor sees a surface's front: a table's normals given pointing down, its sensor above,
    # read a plate 12 mm over it as collision without a word (a probe, 2026-12-06). They are still
    # taken as given, and the model says so; the right way up, seen edge-on from a viewpoint in the
    # table's plane, or a sphere's outward normals (half face any viewpoint outside it), say nothing.
    rng = np.random.default_rng(0)
    g = np.linspace(-0.2, 0.2, 60)
    table = np.stack(np.meshgrid(g, g) + [np.zeros((60, 60))], -1).reshape(-1, 3) + rng.normal(0, 0.002, (3600, 3))
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.002), surface=True)
    above = (0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0)
    down, up = (np.tile([0.0, 0.0, z], (len(table), 1)) for z in (-1.0, 1.0))
    with pytest.warns(RuntimeWarning, match="its normals face away from its viewpoint"):
        flipped = pc.build_model(table, params=params, normals=down, viewpoint=above)
    assert flipped.surface_orientation == pc.NormalOrientation.PointNormals  # taken as given
    ball = rng.normal(size=(2000, 3))
    ball /= np.linalg.norm(ball, axis=1, keepdims=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for points, normals, view in ((table, up, above), (table, down, (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)),
                                      (0.1 * ball, ball, (0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0))):
            assert "face away" not in pc.build_model(points, params=params, normals=normals, viewpoint=view).warning


def test_a_viewpoint_that_is_not_finite_is_refused():
    # build_model(viewpoint=[inf, ...]) went on to a misleading message (a probe, 2026-12-03).
    with pytest.raises(ValueError, match="viewpoint: value 1 is not finite"):
        pc.build_model(GOOD, viewpoint=[np.inf, 0, 0, 1, 0, 0, 0])
    with pytest.raises(ValueError, match="viewpoint: value 5 is not finite"):
        pc.build_model(GOOD, viewpoint=[0, 0, 0, 1, np.nan, 0, 0])


def test_the_classifier_is_a_keyword_of_the_request_and_reaches_the_query(table, gripper_patch):
    # CollisionRequest.classifier (kernel, training, C, kappa, ...) was not bound: a Python request
    # always fitted with the C++ defaults (2026-12-04 pass). It is now a ClassifierParams, checked
    # by validate() and by the query, and held by reference (request.classifier.C = 10 sets it).
    default = pc.ClassifierParams()
    assert (default.kernel, default.training, default.loss) == \
        (pc.KernelMode.Ladder, pc.TrainingMode.Robust, pc.Loss.SquaredHinge)
    assert (default.confidence, default.C, default.rff_features) == (0.9, 1000.0, 256)
    r = pc.CollisionRequest()
    r.classifier.C = 10.0
    assert r.classifier.C == 10.0 and r.classifier != default
    with pytest.raises(ValueError, match="confidence"):
        pc.CollisionRequest(classifier=pc.ClassifierParams(confidence=0.4)).validate()
    with pytest.raises(ValueError, match="confidence"):
        pc.collide(table, gripper_patch, translation(0.1, 0.1, 0.004),
                   pc.CollisionRequest(classifier=pc.ClassifierParams(confidence=0.4)))
    # The paper's plain SVM (Standard training) against the chance-constrained one, near contact:
    # a different fit, so a different P (exhaustive and per point, every pair's fit counts).
    T = translation(0.1, 0.1, 0.004)
    robust = pc.collide(table, gripper_patch, T, pc.CollisionRequest(exhaustive=True, per_point=True))
    plain = pc.collide(table, gripper_patch, T, pc.CollisionRequest(
        exhaustive=True, per_point=True, classifier=pc.ClassifierParams(training=pc.TrainingMode.Standard)))
    assert robust.ok and plain.ok
    assert not np.array_equal(robust.probabilities_b, plain.probabilities_b)
    again = pc.collide(table, gripper_patch, T, pc.CollisionRequest(exhaustive=True, per_point=True))
    np.testing.assert_array_equal(robust.probabilities_b, again.probabilities_b)


def test_is_closed_mesh_tells_a_solid_from_an_open_container(tmp_path):
    # pcd_collision warns of a mesh that is not closed (-surface takes its faces to enclose an
    # inside: a box resting in an open bin read collision, 0.45 m deep, 2026-12-04).
    V = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    box = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                    [1, 3, 7], [1, 7, 5], [3, 2, 6], [3, 6, 7], [2, 0, 4], [2, 4, 6]])
    assert pc.is_closed_mesh(V, box)
    assert not pc.is_closed_mesh(V, box[[i for i in range(12) if i not in (2, 3)]])  # the top removed
    flipped = box.copy()
    flipped[0] = flipped[0][::-1]
    assert not pc.is_closed_mesh(V, flipped)


def test_mesh_signed_volume_tells_a_solid_from_one_inside_out():
    # pcd_collision -surface warns of a closed mesh wound inward: a part inside it reads free, as
    # in a cavity (2026-12-04).
    V = np.array([[x, y, z] for z in (0, 2) for y in (0, 1) for x in (0, 1)], float) + 1e4
    box = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                    [1, 3, 7], [1, 7, 5], [3, 2, 6], [3, 6, 7], [2, 0, 4], [2, 4, 6]])
    assert pc.mesh_signed_volume(V, box) == pytest.approx(2.0, rel=1e-9)
    assert pc.mesh_signed_volume(V, box[:, ::-1]) == pytest.approx(-2.0, rel=1e-9)
    assert pc.is_closed_mesh(V, box[:, ::-1])


def _pinhole_image(sensor, target, noise=0.002, box=True, seed=3):
    # A 48 x 64 pinhole depth image (60 px focal length) of a 20 cm box on an 80 cm table, with
    # range noise along each ray; NaN where a ray meets nothing.
    f = (target - sensor) / np.linalg.norm(target - sensor)
    r = np.cross(f, [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    d = np.cross(f, r)
    u, v = np.meshgrid((np.arange(64) - 31.5) / 60.0, (np.arange(48) - 23.5) / 60.0)
    rays = f + u[..., None] * r + v[..., None] * d
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -sensor[2] / rays[..., 2]
        p = sensor + t[..., None] * rays
        t = np.where((t > 0) & (np.abs(p[..., 0]) < 0.4) & (np.abs(p[..., 1]) < 0.4), t, np.inf)
        if box:
            lo, hi = np.array([-0.1, -0.1, 0.0]), np.array([0.1, 0.1, 0.2])
            t0, t1 = (lo - sensor) / rays, (hi - sensor) / rays
            enter, leave = np.minimum(t0, t1).max(axis=-1), np.maximum(t0, t1).min(axis=-1)
            t = np.where((enter < leave) & (enter > 0) & (enter < t), enter, t)
    t = t + np.random.default_rng(seed).normal(0.0, noise, t.shape)
    return np.where(np.isfinite(t)[..., None], sensor + t[..., None] * rays, np.nan)


def test_organized_sensor_pose_finds_the_sensor_of_a_moved_image(tmp_path):
    sensor, target = np.array([0.6, -0.6, 0.7]), np.array([0.0, 0.0, 0.1])
    image = _pinhole_image(sensor, target)
    origin, axis = pc.organized_sensor_pose(image)
    assert np.linalg.norm(origin - sensor) < 1e-4
    assert axis @ (target - sensor) / np.linalg.norm(target - sensor) > 0.9999
    # Moved into a robot's frame, as pcl::transformPointCloud moves a cloud: the pose moves along.
    c, s = np.cos(2.0), np.sin(2.0)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    t = np.array([0.3, -1.2, 0.8])
    moved = image @ R.T + t
    origin, axis = pc.organized_sensor_pose(moved.astype(np.float32))
    assert np.linalg.norm(origin - (R @ sensor + t)) < 1e-4
    assert pc.organized_sensor_pose(_pinhole_image(sensor, target, noise=0.0, box=False)) is None  # rows are lines
    with pytest.raises(ValueError, match=r"expected shape \(H, W, 3\)"):
        pc.organized_sensor_pose(image.reshape(-1, 3))
    # An organized file moved without its VIEWPOINT: load_model takes the sensor's pose and warns.
    path = tmp_path / "moved.pcd"
    rows = "\n".join(" ".join("nan" if not np.isfinite(x) else "%.6f" % x for x in p) for p in moved.reshape(-1, 3))
    path.write_text("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 64\nHEIGHT 48\n"
                    "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3072\nDATA ascii\n" + rows + "\n")
    params = pc.CloudModelParams(surface=True)
    with pytest.warns(RuntimeWarning, match="where the planes of its rows and columns of points meet"):
        model = pc.load_model(path, params=params)
    assert model.surface_orientation == pc.NormalOrientation.Viewpoint
    # build_model takes the image as an organized cloud too; its rows flattened, it cannot tell.
    with pytest.warns(RuntimeWarning, match="where the planes of its rows and columns of points meet"):
        image_model = pc.build_model(moved, params=params)
    assert image_model.size == model.size and image_model.surface_orientation == pc.NormalOrientation.Viewpoint
    with pytest.warns(RuntimeWarning, match="rows and columns"):  # covariances per pixel, as the points
        given = pc.build_model(moved, covariances=np.tile(1e-6 * np.eye(3), (48, 64, 1, 1)))
    assert given.size == model.size
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pc.build_model(moved.reshape(-1, 3), params=params)
    with pytest.raises(ValueError, match=r"expected shape \(H, W, 3\)"):
        pc.build_model(np.zeros((4, 5, 4)))
    with pytest.raises(ValueError, match=r"normals: expected shape"):
        pc.build_model(moved, params=params, normals=np.zeros((48, 64, 2)))


# --- The probe of 2026-12-06 (docs/RELIABILITY.md, "Found and fixed (2026-12-06)") ---------------

INTERRUPTED_BATCH = """
import sys
import numpy as np
import pcl_probcollision as pc

if __name__ == "__main__":
    table = pc.load_model(sys.argv[1], pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005)))
    poses = np.repeat(np.eye(4)[None], 1000, axis=0)  # exhaustive self-queries: minutes in all
    print("start", flush=True)
    pc.collide_batch(table, table, poses, pc.CollisionRequest(exhaustive=True), threads=int(sys.argv[2]))
    print("done", flush=True)
"""


@pytest.mark.parametrize("threads", [1, 2])
def test_ctrl_c_stops_a_batch(tmp_path, table_path, threads):
    # The batch takes minutes uninterrupted (about 0.2 s a pose); SIGINT must end it at the next
    # pose with KeyboardInterrupt (it went on to the end before: half a minute for the probe's).
    import signal
    import subprocess
    import sys
    script = tmp_path / "batch.py"
    script.write_text(INTERRUPTED_BATCH)
    p = subprocess.Popen([sys.executable, str(script), str(table_path), str(threads)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)  # a hang bound, far under the batch's minutes
    finally:
        p.kill()
    assert "done" not in out
    assert "KeyboardInterrupt" in err, err
    assert p.returncode != 0


def test_model_params_are_a_copy(table):
    # A live reference let a built model report parameters it was not built with.
    params = table.params
    params.k = 3
    params.n_max = 1
    assert table.params.k == NOISE.k and table.params.n_max == NOISE.n_max


def test_load_model_refuses_a_name_that_is_no_string(table_path):
    for name in (123, ["a"]):
        with pytest.raises(TypeError, match="name: expected str"):
            pc.load_model(table_path, NOISE, name=name)


def test_covariances_beyond_the_float_range_are_refused():
    points = patch(n=10)
    cov = np.tile(np.eye(3) * 1e-6, (100, 1, 1))
    cov[5, 0, 0] = 1e45  # finite, but Inf as float32: its point was dropped without a word
    with pytest.raises(ValueError, match="covariances: matrix 5 has an entry beyond the float range"):
        pc.build_model(points, covariances=cov, params=NOISE)


@pytest.mark.parametrize("row, words", [
    ([np.nan, 0, 0, 0, 0, 0], "tx is not a finite number"),
    ([0, 0, 0, np.inf, 0, 0], "roll is not a finite number"),
    ([1e300, 0, 0, 0, 0, 0], "translation beyond the supported range"),
])
def test_poses_from_xyzrpy_refuses_what_read_poses_refuses(row, words):
    with pytest.raises(ValueError, match=r"poses\[1\]: " + words):
        pc.poses_from_xyzrpy([[0, 0, 0, 0, 0, 0], row])


def test_sample_mesh_names_a_vertex_it_cannot_take():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    triangles = np.array([[0, 1, 2]])
    for bad in (np.nan, 1e300):
        v = vertices.copy()
        v[1, 2] = bad
        with pytest.raises(ValueError, match=r"vertices: row 1 \(a corner of triangle 0\)"):
            pc.sample_mesh(v, triangles, 0.01)
    with pytest.raises(ValueError, match="raise spacing$"):  # not pcd_collision's -mesh_density
        pc.sample_mesh(vertices, triangles, 1e-9)


def test_poses_must_hold_real_numbers(table):
    T = np.eye(4)
    assert pc.collide(table, table, T.tolist()).probability == pc.collide(table, table, T).probability
    for bad in (T * (1 + 0j), T.astype(object)):
        with pytest.raises(TypeError, match="real numbers"):
            pc.collide(table, table, bad)
        with pytest.raises(TypeError, match="real numbers"):
            pc.collide_batch(table, table, bad[None])
    with pytest.raises(TypeError, match="real numbers"):
        pc.poses_from_xyzrpy(np.zeros((1, 6), dtype=complex))
