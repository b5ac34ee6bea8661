# SPDX-License-Identifier: BSD-3-Clause
"""Pose batches spread over Dask workers (issue #18).

    from distributed import Client
    from pcl_probcollision.dask import collide_poses
    client = Client("tcp://scheduler:8786")          # or LocalCluster(n_workers=2, threads_per_worker=1)
    r = collide_poses("gripper.obj", "table.pcd", poses, client=client, sigma=0.0015)
    r.probability, r.verdict                          # numpy arrays in pose order

Poses follow pcd_collision: a pose moves <a> into <b>'s frame (T_b_a, pcd_collision's -pose), as
(M, 4, 4) matrices or (M, 6) rows tx ty tz roll pitch yaw (R = Rz(yaw) Ry(pitch) Rx(roll)); witness
points and normals are in b's frame. collide_poses(a, b, P) answers what
collide_batch(A, B, invert_poses(P)) answers for the models A, B pcd_collision would build.

The clouds are read (and meshes sampled) once on the client and scattered once to every worker;
each worker builds the two models once per cloud pair and parameters (a worker-side cache) and
answers chunks of poses with collide_batch. The library itself stays single-process.
"""
from __future__ import annotations

import collections
import concurrent.futures
import hashlib
import math
import operator
import os
import re
import threading
import time
import uuid
import warnings
from typing import Any, Callable, Dict, Optional

import numpy as np

from .. import _core as core

__all__ = ["collide_poses", "connect", "prepare_input", "BatchResults", "InputWarning", "DEFAULT_OPTIONS", "OPTION_NAMES"]

#: pcd_collision's flags without the dash and their defaults (docs/CLI.md). The model and request
#: defaults come from the C++ structs; sensor and sigma are the tool's own (isotropic 5 mm).
_MODEL = core.CloudModelParams()
_REQUEST = core.CollisionRequest()
DEFAULT_OPTIONS: Dict[str, Any] = {
    "sensor": core.PCD_COLLISION_SENSOR,
    "sensor_a": None,
    "sensor_b": None,
    "sigma": None,        # None: 0.005 (pcd_collision's default) for every isotropic input
    "sigma_a": None,
    "sigma_b": None,
    "k": _MODEL.k,
    "thresholds": (_REQUEST.free_below, _REQUEST.collision_above),
    "measured": not _MODEL.surface_projection,
    "deterministic": True,
    "stochastic": _REQUEST.traversal == core.TraversalMode.Stochastic,
    "seed": _REQUEST.seed,
    "exhaustive": _REQUEST.exhaustive,
    # Every reached leaf pair's plane before any kernel rung (the same verdicts, faster).
    "defer_kernel_fits": _REQUEST.defer_kernel_fits,
    # At most this many leaf pairs tested a query, nearest first (0: no cap).
    "max_leaf_fits": _REQUEST.max_leaf_fits,
    # With the surface layer: about this many leaf pairs tested by it a query (0: no cap).
    "max_surface_pairs": _REQUEST.max_surface_pairs,
    # Samples closer than this many noise sigmas merged into one, where the gate lets them (0: none;
    # None: CloudModelParams' default, 2 without the surface layer and 0 with it, where a depth
    # scan's dense samples still merge at 2).
    "noise_resolution": _MODEL.noise_resolution,
    # Where it merges (pcd_collision's -noise_resolution_gate): everywhere, spacing (only samples
    # spaced closer than their noise) or cloud (a whole cloud sampled finer than its noise, else
    # its samples spaced closer than their noise where most are twice as dense as it).
    "noise_resolution_gate": _MODEL.noise_resolution_gate,
    # A hierarchy node of at most 160 points within this many noise sigmas is not split (0: off).
    "noise_stop": _MODEL.noise_stop,
    # The surface layer (experimental, issue #16): both models get a surface (meshes oriented by
    # their faces, clouds by their viewpoint or by propagation) and signed_distance is filled.
    "surface": _REQUEST.surface,
    # The surface layer pooled with the separators (the mean of the two P); implies surface.
    "surface_pooled": _REQUEST.surface_pooled,
    # The separators first, the surface layer only where they leave the answer open
    # (pcd_collision's -surface_ladder); implies surface, excludes surface_pooled.
    "surface_ladder": _REQUEST.surface_ladder,
    # With surface: P in [0.1, 0.9] through the calibration map fitted on the evaluation's
    # procedural scenes (pcd_collision's -surface_calibrated; off: the model's raw P).
    "surface_calibrated": _REQUEST.surface_calibrated,
    # Beyond the query's reach, signed_distance is the distance between the two clouds' nearest
    # samples (pcd_collision's -distance; CollisionRequest.distance).
    "distance": _REQUEST.distance,
    # With surface: a cloud file's normal_x normal_y normal_z are not read (pcd_collision's
    # -ignore_normals); the cloud is oriented as one without them.
    "ignore_normals": False,
    # With surface: both inputs (closed), or <a> or <b>, sample closed solids (pcd_collision's
    # -closed, -closed_a, -closed_b; CloudModelParams.closed_objects): a propagated orientation,
    # checked by the winding number, says where the inside is.
    "closed": False,
    "closed_a": _MODEL.closed_objects,
    "closed_b": _MODEL.closed_objects,
    # With surface: how both surfaces (orientation), or <a>'s or <b>'s, are oriented, by
    # pcd_collision's names (-orientation, -orientation_a, -orientation_b; CloudModelParams.
    # orientation): auto, point_normals, viewpoint or propagate. None: auto.
    "orientation": None,
    "orientation_a": None,
    "orientation_b": None,
    "nmax": _MODEL.n_max,
    "sigma_max": _MODEL.sigma_max,
    "epsilon": _MODEL.epsilon,
    "split": _MODEL.split,
    "mesh_density": None,
    # collide_batch threads per task (pcd_collision's -threads). 1 = Dask's worker threads give the
    # parallelism (one task per core); 0 = all cores of the worker machine; at most MAX_THREADS
    # (1,024, a ValueError above, as pcd_collision refuses it).
    "threads": 1,
}
OPTION_NAMES = tuple(DEFAULT_OPTIONS)
_DEFAULT_SIGMA = core.PCD_COLLISION_SIGMA
_MESH_SEED = core.PCD_COLLISION_MESH_SEED
_MESH_EXTENSIONS = (".ply", ".obj", ".stl", ".vtk")


#: pcd_collision's options by kind: the switches, and those with a value (its type; "pair" for
#: LOW,HIGH, "u64" for a non-negative 64-bit integer). The command line reads its flags by them.
_SWITCHES = ("measured", "deterministic", "stochastic", "exhaustive", "defer_kernel_fits", "surface", "surface_pooled",
             "surface_ladder", "surface_calibrated", "distance", "ignore_normals", "closed", "closed_a", "closed_b")
_VALUES = {"sensor": str, "sensor_a": str, "sensor_b": str, "sigma": float, "sigma_a": float, "sigma_b": float,
           "k": int, "thresholds": "pair", "seed": "u64", "nmax": int, "sigma_max": float, "epsilon": float,
           "split": str, "mesh_density": float, "max_leaf_fits": "u64", "max_surface_pairs": "u64",
           "noise_resolution": float,
           "noise_resolution_gate": str, "noise_stop": float, "orientation": str, "orientation_a": str,
           "orientation_b": str, "threads": int}
_INTEGERS = tuple(name for name, kind in _VALUES.items() if kind in (int, "u64"))


def _as_flags(options: Dict[str, Any]) -> list:
    """The options given, as pcd_collision's flags (a switch when true, a value unless None)."""
    flags = []
    for name, v in options.items():
        if name in _SWITCHES:
            if v:
                flags.append("-" + name)
            continue
        if v is None:
            continue
        try:
            if name == "thresholds":
                low, high = v
                text = f"{float(low)!r},{float(high)!r}"
            elif name in _INTEGERS:
                text = str(operator.index(v)) if not isinstance(v, bool) else repr(v)
            elif isinstance(v, str):
                text = v
            else:
                text = repr(float(v))
        except (TypeError, ValueError):
            raise TypeError(f"option {name}: expected {'two numbers (LOW, HIGH)' if name == 'thresholds' else 'an integer' if name in _INTEGERS else 'a number'}, got {v!r}") from None
        flags.append(f"-{name}={text}")
    return flags


def resolve_options(options: Dict[str, Any]) -> Dict[str, Any]:
    """pcd_collision's flags as a complete, checked dict (TypeError for an unknown name or a value
    of the wrong type, ValueError for a value pcd_collision would refuse: its own parser judges
    them, with its message, the options named without the dash)."""
    unknown = sorted(set(options) - set(DEFAULT_OPTIONS))
    if unknown:
        raise TypeError(f"unknown option(s) {', '.join(unknown)}; expected some of {', '.join(OPTION_NAMES)}")
    error = core.pcd_collision_usage_error(["a.pcd", "b.pcd", *_as_flags(options)])
    if error:
        # "option -sigma_b: ..." -> "option sigma_b: ...", as the keyword is spelt here.
        raise ValueError(re.sub(r"(?<![\w'])-(?=[a-z])", "", error.removesuffix(" (see -h)")))
    o = dict(DEFAULT_OPTIONS)
    o.update({k: v for k, v in options.items()})
    o["surface"] = bool(o["surface"] or o["surface_pooled"] or o["surface_ladder"])
    o["closed_a"] = bool(o["closed_a"] or o["closed"])
    o["closed_b"] = bool(o["closed_b"] or o["closed"])
    for side in ("a", "b"):
        o["orientation_" + side] = o["orientation_" + side] or o["orientation"] or _ORIENTATION_NAMES[_MODEL.orientation]
    o["sensor_a"] = o["sensor_a"] or o["sensor"]
    o["sensor_b"] = o["sensor_b"] or o["sensor"]
    for side in "ab":
        if o["sigma_" + side] is None:
            o["sigma_" + side] = _DEFAULT_SIGMA if o["sigma"] is None else o["sigma"]
    o["thresholds"] = tuple(float(t) for t in o["thresholds"])
    model_params(o, "a", exact=False).validate()
    request_of(o).validate()
    return o


# Resolved options pcd_collision_params is not given: the noise (set per input below), the forms
# resolved into per-input ones, the traversal's default, and what is not a model's or a query's
# (threads: collide_batch's; a worker's build uses its cores).
_NOT_PARAMS = {"sensor", "sensor_a", "sensor_b", "sigma", "sigma_a", "sigma_b", "closed", "orientation", "deterministic",
               "threads", "mesh_density", "ignore_normals"}


def _params(o: Dict[str, Any]):
    """pcd_collision's modelParamsFor (<a>, <b>) and requestFor of resolved options (the merging's
    gate only when not the default: pcd_collision refuses -noise_resolution_gate where nothing
    merges, and resolve_options has let a given one through its parser)."""
    given = {k: v for k, v in o.items() if k not in _NOT_PARAMS and (o["surface"] or not k.startswith("orientation"))
             and (k != "noise_resolution_gate" or v != DEFAULT_OPTIONS[k])}
    return core.pcd_collision_params(_as_flags(given))


def model_params(o: Dict[str, Any], side: str, exact: bool) -> core.CloudModelParams:
    """pcd_collision's modelParamsFor() (the same function), with the noise of one input (none for
    a mesh's exact samples, whose covariances are given)."""
    p = _params(o)[0 if side == "a" else 1]
    if not exact:
        p.noise = core.SensorNoiseModel.from_name(o["sensor_" + side], float(o["sigma_" + side]))
    return p


def request_of(o: Dict[str, Any]) -> core.CollisionRequest:
    """pcd_collision's requestFor() (the same function) without -o."""
    return _params(o)[2]


# ------------------------------------------------------------------------------------------------
# Inputs: what is scattered. A plain dict of numpy arrays and strings (picklable, hashable by Dask).

def _is_open3d_cloud(x) -> bool:
    t = type(x)
    return t.__name__ == "PointCloud" and t.__module__.startswith("open3d")


def prepare_input(x, name: Optional[str] = None, normals: bool = False) -> Dict[str, Any]:
    """An input as pcd_collision reads it: a path (.pcd, face-less .ply: a cloud; .ply .obj .stl
    .vtk: a mesh, sampled later against the other input), an (N, 3) numpy array or an Open3D
    PointCloud (a cloud whose viewpoint is the origin). normals (pcd_collision's -surface without
    -ignore_normals): a cloud file's normal_x normal_y normal_z too, as stored (the surface model
    takes them as outward and normalizes them); "normals" is None when the file has none."""
    if isinstance(x, dict) and "kind" in x:
        return x
    if isinstance(x, (str, os.PathLike)):
        path = os.fspath(x)
        if os.path.isdir(path):
            raise IsADirectoryError(21, "Is a directory", path)
        if not os.path.isfile(path):
            raise FileNotFoundError(2, "No such file", path)
        low = path.lower()
        if low.endswith(".pcd") or (low.endswith(".ply") and core.is_faceless_ply(path)):
            t0 = time.perf_counter()
            if normals:
                points, stored, viewpoint, width, height, rounding = core.read_cloud_with_normals(path, rounding=True)
            else:
                (points, viewpoint, width, height, rounding), stored = core.read_cloud(path, rounding=True), None
            finite = int(np.isfinite(points).all(axis=1).sum())
            if finite == 0:
                raise ValueError(f"'{path}' has no finite point ({len(points)} points, all NaN or Inf)")
            return {"kind": "cloud", "path": path, "name": name or os.path.basename(path), "points": points,
                    "viewpoint": viewpoint, "width": int(width), "height": int(height), "finite": finite,
                    "normals": stored, "rounding": rounding, "load_ms": (time.perf_counter() - t0) * 1e3}
        if low.endswith(_MESH_EXTENSIONS):
            t0 = time.perf_counter()
            vertices, triangles = core.read_mesh(path)
            return {"kind": "mesh", "path": path, "name": name or os.path.basename(path), "vertices": vertices,
                    "triangles": triangles, "load_ms": (time.perf_counter() - t0) * 1e3}
        raise ValueError(f"input '{path}': unsupported file type (expected .pcd, .ply, .obj, .stl or .vtk)")
    if _is_open3d_cloud(x):
        x = np.asarray(x.points)
    if isinstance(x, np.ndarray):
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError(f"points: expected shape (N, 3), got {x.shape}")
        if x.dtype not in (np.float32, np.float64):
            raise TypeError(f"points: expected dtype float32 or float64, got {x.dtype}")
        points = np.ascontiguousarray(x)
        finite = int(np.isfinite(points).all(axis=1).sum())
        return {"kind": "cloud", "path": None, "name": name or "cloud", "points": points, "viewpoint": None,
                "width": len(points), "height": 1, "finite": finite, "load_ms": 0.0}
    raise TypeError(f"expected a file path, an (N, 3) numpy array or an Open3D PointCloud, got {type(x).__name__}")


def check_input_kinds(a: Dict[str, Any], b: Dict[str, Any], options: Dict[str, Any]) -> None:
    """pcd_collision's rules for options that need an input of some kind (its own
    inputKindsUsageError: mesh_density with two clouds would change nothing; sigma_a, sensor_a
    (or _b) for a mesh, sampled exactly, would be ignored): ValueError, the option named without
    its dash as resolve_options names it."""
    error = core.pcd_collision_input_usage_error(_as_flags(options), a["kind"] == "mesh", b["kind"] == "mesh",
                                                 a["path"] or a["name"], b["path"] or b["name"])
    if error:
        raise ValueError(re.sub(r"(?<![\w'])-(?=[a-z])", "", error))


def input_facts(spec: Dict[str, Any], o: Dict[str, Any], side: str):
    """What pcd_collision's input warnings judge of an input (core.InputFacts): a cloud's finite
    points and their bounding-box diagonal, a file's rounding to float, the side's noise; a
    mesh's size is its vertices'."""
    path = spec["path"] or spec["name"]
    if spec["kind"] == "mesh":
        return core.InputFacts(path=path, cloud=False, diagonal=core.mesh_diagonal(spec["vertices"], spec["triangles"]))
    return core.InputFacts(path=path, cloud=True, finite=spec["finite"], diagonal=core.finite_diagonal(spec["points"]),
                           rounding=spec.get("rounding", (0.0, 0.0)), sensor=o["sensor_" + side],
                           sigma=float(o["sigma_" + side]))


class InputWarning(RuntimeWarning):
    """A warning pcd_collision prints on stderr about its inputs or an answer (units, rounding to
    float, a model's precision, a free answer between two meshes' samples)."""


def _warn(message: str) -> None:
    """Issues pcd_collision's warning as an InputWarning (the command line prints it as
    pcd_collision does); nothing for ''."""
    if message:
        warnings.warn(message, InputWarning, stacklevel=3)


def _sample_meshes(a: Dict[str, Any], b: Dict[str, Any], o: Dict[str, Any]) -> None:
    """pcd_collision's MeshSampled mode: spacing from mesh_density, the other cloud, or the meshes'
    size; the samples become the input's points (exact: zero covariance). With surface, the
    samples carry their faces' outward normals (the same points), as pcd_collision's do."""
    for m, other in ((a, b), (b, a)):
        if m["kind"] != "mesh" or ("points" in m and (not o["surface"] or m.get("normals") is not None)):
            continue
        t0 = time.perf_counter()
        if o["mesh_density"] is not None:
            spacing, source = float(o["mesh_density"]), "-mesh_density"
        elif other["kind"] == "cloud":
            spacing = core.median_spacing(other["points"])
            source = f"median nearest-neighbour spacing of '{other['path'] or other['name']}'"
        else:
            spacing = core.mesh_pair_spacing(a["vertices"], a["triangles"], b["vertices"], b["triangles"])
            source = "both inputs are meshes: 1/100 of the smaller bounding-box diagonal, or wider for 500000 samples"
        if not (spacing > 0.0 and math.isfinite(spacing)):
            raise ValueError(f"cannot choose a sample spacing for mesh '{m['path']}' ({source} is 0); give -mesh_density")
        if o["surface"]:
            m["points"], m["normals"] = core.sample_mesh_with_normals(m["vertices"], m["triangles"], spacing, _MESH_SEED)
        else:
            m["points"] = core.sample_mesh(m["vertices"], m["triangles"], spacing, _MESH_SEED)
        m["spacing"], m["spacing_source"] = spacing, source
        m["finite"] = len(m["points"])
        m["sample_ms"] = (time.perf_counter() - t0) * 1e3


def _scattered(spec: Dict[str, Any], surface: bool = False) -> Dict[str, Any]:
    """What a worker needs to build the model, with a content token for its cache; a mesh's
    normals only with surface (the model of the points is the same without them)."""
    normals = spec.get("normals") if surface else None
    h = hashlib.blake2b(digest_size=16)
    h.update(spec["kind"].encode())
    h.update(spec["name"].encode() + b"\0")  # a model's messages name it: one cloud as a and b is two models
    h.update(np.ascontiguousarray(spec["points"]).tobytes())
    h.update(str(spec["points"].dtype).encode())
    if spec.get("viewpoint") is not None:
        h.update(np.asarray(spec["viewpoint"], dtype=np.float64).tobytes())
    if normals is not None:
        h.update(b"normals")
        h.update(np.ascontiguousarray(normals).tobytes())
    return {"token": h.hexdigest(), "kind": spec["kind"], "name": spec["name"], "points": spec["points"],
            "viewpoint": spec.get("viewpoint"), "normals": normals}


# ------------------------------------------------------------------------------------------------
# Worker side: the model cache and the chunk task.

_CACHE_SIZE = 8
_cache: "collections.OrderedDict[tuple, Any]" = collections.OrderedDict()
_cache_lock = threading.Lock()
_key_locks: Dict[tuple, threading.Lock] = {}
_builds = collections.Counter()  # models built in this process, by token (tests read it)


def _params_key(o: Dict[str, Any], side: str, exact: bool) -> tuple:
    """The model cache's key beside the token: every member of the CloudModelParams the model is
    built with, read from the object so that no option can be left out of it (a cached model
    built with other settings would answer silently wrong); the noise by its options, since a
    SensorNoiseModel shows no sigma; threads left out, the model being the same for any count."""
    p = model_params(o, side, exact)
    members = tuple((name, repr(getattr(p, name))) for name in dir(p)
                    if not name.startswith("_") and name not in ("validate", "threads", "noise"))
    noise = None if exact else (o["sensor_" + side], float(o["sigma_" + side]))
    return members + (noise,)


def _model(spec: Dict[str, Any], o: Dict[str, Any], side: str):
    """The model of a scattered cloud under o, built once per process (threads wait for the one
    that builds it)."""
    exact = spec["kind"] == "mesh"
    key = (spec["token"], _params_key(o, side, exact))
    with _cache_lock:
        model = _cache.get(key)
        if model is not None:
            _cache.move_to_end(key)
            return model
        lock = _key_locks.setdefault(key, threading.Lock())
    with lock:
        with _cache_lock:
            model = _cache.get(key)
        if model is None:
            points = spec["points"]
            covariances = np.zeros((len(points), 3, 3), dtype=np.float32) if exact else None
            # A cloud file's stored normals are of any length, as pcd_collision reads them.
            model = core.build_model(points, covariances=covariances, params=model_params(o, side, exact),
                                     name=spec["name"], viewpoint=spec["viewpoint"], normals=spec.get("normals"),
                                     any_length_normals=not exact, warn=False)
            with _cache_lock:
                _cache[key] = model
                _builds[spec["token"]] += 1
                while len(_cache) > _CACHE_SIZE:
                    _cache.popitem(last=False)
    return model


_INT_FIELDS = ("points_a", "points_b", "points_skipped_nonfinite", "leaf_pairs_tested", "bv_tests",
               "kernel_leaf_pairs", "degenerate_leaf_pairs", "classifier_iterations", "witness_index")


# NormalOrientation as orientationName() spells it (pcd_collision's JSON).
_ORIENTATION_NAMES = {core.NormalOrientation.Auto: "auto", core.NormalOrientation.PointNormals: "point_normals",
                      core.NormalOrientation.Viewpoint: "viewpoint", core.NormalOrientation.Propagate: "propagate"}


def surface_summary(model) -> Optional[Dict[str, Any]]:
    """How a model's surface was oriented, pcd_collision's JSON member "surface" of an input
    (NaN for its nulls); None without a surface model."""
    if not model.has_surface:
        return None
    return {"orientation": _ORIENTATION_NAMES[model.surface_orientation], "inside_known": model.surface_inside_known,
            "hidden_from_viewpoint": model.surface_hidden_from_viewpoint,
            "closed_share": model.surface_closed_share, "solid_share": model.surface_solid_share}


def answer_chunk(a: Dict[str, Any], b: Dict[str, Any], T_b_a: np.ndarray, start: int, o: Dict[str, Any]) -> Dict[str, Any]:
    """Answers poses[start:start + len(T_b_a)] with collide_batch; plain numpy arrays back, and
    the models' build time and surface summaries."""
    A = _model(a, o, "a")
    B = _model(b, o, "b")
    # check_units=False: collide_poses said it once, as pcd_collision does, not once a chunk.
    results = core.collide_batch(A, B, core.invert_poses(T_b_a), request_of(o), threads=int(o["threads"]),
                                 check_units=False)
    n = len(results)
    out: Dict[str, np.ndarray] = {
        "index": np.arange(start, start + n, dtype=np.int64),
        "probability": np.array([r.probability for r in results], dtype=np.float64),
        "verdict": np.array([int(r.verdict) for r in results], dtype=np.int8),
        # Whose answer P is (int8 of AnsweredBy): with surface_ladder it varies from pose to pose.
        "answered_by": np.array([int(r.answered_by) for r in results], dtype=np.int8),
        "status": np.array([int(r.status) for r in results], dtype=np.int8),
        "lower_bound": np.array([r.lower_bound for r in results], dtype=bool),
        "budget_exhausted": np.array([r.budget_exhausted for r in results], dtype=bool),
        # The answer is the unmerged models' (CloudModelParams.keep_full_resolution); False unless merged.
        "full_resolution": np.array([r.full_resolution for r in results], dtype=bool),
        "no_leaf_tested": np.array([r.no_leaf_tested for r in results], dtype=bool),
        # NaN without surface (or where the surfaces never came within reach), as in CollisionResult.
        "signed_distance": np.array([r.signed_distance for r in results], dtype=np.float64),
        "signed_distance_std": np.array([r.signed_distance_std for r in results], dtype=np.float64),
        # The surface layer's answer rests on surface the samples do not show; False without surface.
        "unobserved": np.array([r.unobserved for r in results], dtype=bool),
        # With distance: signed_distance is the nearest samples' (the objects beyond reach).
        "sample_distance": np.array([r.sample_distance for r in results], dtype=bool),
        "witness_side": np.array([r.witness_side for r in results], dtype=np.int8),
        "query_ms": np.array([r.query_ms for r in results], dtype=np.float64),
    }
    for f in _INT_FIELDS:
        out[f] = np.array([getattr(r, f) for r in results], dtype=np.int64)
    # collide() answers in A's frame; pcd_collision reports the witness (and the nearest samples,
    # NaN without sample_distance) in b's frame, mapped by the library's own code
    # (CollisionResult.in_frame): the same bits as pcd_collision's.
    moved = [r.in_frame(T) for r, T in zip(results, T_b_a)]
    for field in ("witness_point", "witness_normal", "nearest_point_a", "nearest_point_b"):
        out[field] = np.array([getattr(r, field) for r in moved], dtype=np.float64).reshape(n, 3)
    out["build_ms"] = np.array([A.build_ms + B.build_ms])
    out["surfaces"] = {"a": surface_summary(A), "b": surface_summary(B)}
    out["merged_samples"] = {"a": A.merged_samples, "b": B.merged_samples}
    # The models' precision warnings (CloudModel.warning), reported by the client.
    out["model_warnings"] = {"a": A.warning, "b": B.warning}
    out["pid"] = np.array([os.getpid()])
    return out


# ------------------------------------------------------------------------------------------------
# Client side.

class BatchResults:
    """Answers in pose order, one numpy array per field: probability, verdict (int8 of Verdict),
    answered_by (int8 of AnsweredBy: separators, surface layer or pooled, the ladder's rung), status, lower_bound, budget_exhausted, no_leaf_tested, signed_distance(_std) (with surface=True; NaN otherwise),
    unobserved (bool: with surface=True, the answer rests on surface the samples do not show; False otherwise),
    sample_distance (bool: with distance=True, signed_distance is the nearest samples' distance) and
    nearest_point_a/_b (those samples, b's frame; NaN otherwise),
    the counters (points_a, points_b, points_skipped_nonfinite, leaf_pairs_tested, bv_tests,
    kernel_leaf_pairs, degenerate_leaf_pairs, classifier_iterations),
    witness_side/_index/_point/_normal (b's frame), query_ms; inputs describes a and b; surfaces
    how each model's surface was oriented ({"a": ..., "b": ...}, surface_summary(); None without
    surface); merged_samples the samples of each model merged by noise_resolution ({"a": n, "b": n},
    CloudModel.merged_samples); model_warnings each model's precision warning ({"a": text, "b": text},
    CloudModel.warning, '' for none); chunk_size and chunks how it was split."""

    def __init__(self, fields: Dict[str, np.ndarray], inputs, chunk_size: int, chunks: int, build_ms: float,
                 surfaces: Dict[str, Optional[Dict[str, Any]]], merged_samples: Dict[str, int],
                 model_warnings: Dict[str, str]):
        self.fields = fields
        self.model_warnings = model_warnings
        self.surfaces = surfaces
        self.merged_samples = merged_samples
        for k, v in fields.items():
            setattr(self, k, v)
        self.inputs = inputs
        self.chunk_size = chunk_size
        self.chunks = chunks
        self.build_ms = build_ms

    def __len__(self) -> int:
        return len(self.probability)

    def verdicts(self):
        return [core.Verdict(int(v)) for v in self.verdict]

    def __repr__(self) -> str:
        counts = collections.Counter(core.Verdict(int(v)).name for v in self.verdict)
        # Who answered, shown when the surface layer answered any pose (surface, pooled, ladder).
        answered = collections.Counter(core.AnsweredBy(int(v)).name for v in self.answered_by)
        by = "" if set(answered) <= {"Separators"} else f", answered_by={dict(sorted(answered.items()))}"
        return (f"BatchResults({len(self)} poses, {dict(counts)}{by}, chunk_size={self.chunk_size}, "
                f"chunks={self.chunks})")


def as_pose_matrices(poses) -> np.ndarray:
    """(M, 4, 4) or (M, 6) (pcd_collision's -pose rows) -> (M, 4, 4) float64 T_b_a. ValueError naming
    the first pose collide() would refuse, here rather than on a worker (core.check_poses)."""
    P = np.asarray(poses, dtype=np.float64)
    if P.ndim == 1 and P.shape == (6,):
        P = P[None, :]
    if P.ndim == 2 and P.shape[1] == 6:
        P = core.poses_from_xyzrpy(P)
    elif not (P.ndim == 3 and P.shape[1:] == (4, 4)):
        raise ValueError(f"poses: expected shape (M, 4, 4) or (M, 6), got {P.shape}")
    core.check_poses(P)
    return np.ascontiguousarray(P)


def connect(scheduler: str, timeout: float = 10.0):
    """A distributed.Client for 'local' / 'local:N' (a LocalCluster of N single-threaded worker
    processes, N = cores by default) or a scheduler address. ConnectionError after `timeout`
    seconds when the scheduler cannot be reached."""
    from distributed import Client, LocalCluster

    if scheduler == "local" or scheduler.startswith("local:"):
        n = scheduler.partition(":")[2]
        try:
            workers = int(n) if n else (os.cpu_count() or 1)
        except ValueError:
            raise ValueError(f"scheduler: expected local or local:N, got {scheduler!r}") from None
        if workers < 1:
            raise ValueError(f"scheduler: local:N needs N >= 1, got {workers}")
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        return Client(cluster)
    try:
        return Client(scheduler, timeout=timeout)
    except (OSError, TimeoutError) as e:
        raise ConnectionError(f"cannot reach the Dask scheduler at {scheduler} within {timeout:g} s ({e})") from None


def _default_client():
    try:
        from distributed import default_client
        return default_client()
    except (ImportError, ValueError):
        return None


def collide_poses(a, b, poses, client=None, chunk_size: Optional[int] = None,
                  progress: Optional[Callable[[int, int], None]] = None, **options) -> BatchResults:
    """Answers every pose of an (M, 4, 4) or (M, 6) array, pcd_collision-style, on Dask workers.

    a, b: file paths (.pcd, face-less .ply; meshes .ply .obj .stl .vtk, sampled as pcd_collision
        does), (N, 3) numpy arrays, or Open3D PointClouds. A pose moves a into b's frame.
    client: a distributed.Client; None = the default client if there is one, else this process.
    chunk_size: poses per task (default: about 8 tasks per worker thread, 32 to 2000 poses).
    progress: called as progress(answered, total) with the poses answered so far, each time a
        chunk's answers arrive (in whatever order the chunks finish).
    options: pcd_collision's flags without the dash (sensor, sensor_a, sensor_b, sigma, sigma_a,
        sigma_b, k, thresholds=(low, high), measured, stochastic, seed, exhaustive, defer_kernel_fits, surface, nmax,
        sigma_max, epsilon, split, mesh_density, ignore_normals, closed, closed_a, closed_b, orientation,
        orientation_a, orientation_b, ...: OPTION_NAMES) and threads (collide_batch threads per task).
        surface=True is pcd_collision's -surface: both models get the oriented surface (meshes
        by their faces' normals, a cloud file with normal_x normal_y normal_z by them unless
        ignore_normals) and signed_distance / signed_distance_std are filled (NaN
        otherwise, and for poses where the surfaces never came within reach), and unobserved may
        be True (the answer rests on surface the samples do not show; always False otherwise).
        distance=True is pcd_collision's -distance: beyond the query's reach signed_distance is
        the distance between the two clouds' nearest samples (sample_distance True).
    Returns BatchResults in pose order, identical to the single-process answers. A chunk the
    cluster cancels (Dask may, where a worker dies holding the scattered clouds) is asked again
    with the clouds scattered anew, at most 3 times (a RuntimeWarning counts them); past that,
    RuntimeError.
    pcd_collision's warnings (inputs' sizes or sigma in other units, coordinates rounded far from
    the origin, a model's precision, a free answer between two meshes' samples, a mesh under the
    surface layer that is not closed or is wound inward) come as
    InputWarnings (RuntimeWarnings); the command line prints them as pcd_collision does."""
    o = resolve_options(options)
    T = as_pose_matrices(poses)
    stored = o["surface"] and not o["ignore_normals"]
    A, B = prepare_input(a, "a", stored), prepare_input(b, "b", stored)
    check_input_kinds(A, B, options)
    # pcd_collision's warnings about the inputs (units, noise, rounding to float), in its order.
    facts = (input_facts(A, o, "a"), input_facts(B, o, "b"))
    _warn(core.scale_warning(*facts))
    for f in facts:
        _warn(core.noise_warning(f))
    for f in facts:
        _warn(core.rounding_warning(f))
    # A mesh oriented by its faces under the surface layer: not closed, or closed and wound inward.
    for side, spec in (("a", A), ("b", B)):
        if o["surface"] and spec["kind"] == "mesh" and o["orientation_" + side] not in ("propagate", "viewpoint"):
            # '' exactly for a closed mesh (MeshEdges::isClosed): the edges are counted once.
            open_warning = core.open_mesh_warning(spec["path"], spec["vertices"], spec["triangles"], "-orientation_" + side)
            _warn(open_warning)
            _warn(core.inside_out_mesh_warning(spec["path"], not open_warning,
                                               core.mesh_signed_volume(spec["vertices"], spec["triangles"]),
                                               "-orientation_" + side, "-closed_" + side))
    _sample_meshes(A, B, o)
    sa, sb = _scattered(A, o["surface"]), _scattered(B, o["surface"])
    m = len(T)
    if client is None:
        client = _default_client()
    workers = 1
    if client is not None:
        workers = max(1, sum(client.nthreads().values()))
    if chunk_size is None:
        chunk_size = min(2000, max(32, math.ceil(m / (8 * workers))))
    if chunk_size < 1:
        raise ValueError(f"chunk_size: must be >= 1, got {chunk_size}")
    starts = list(range(0, m, chunk_size))
    if client is None:
        parts = []
        for s in starts:
            parts.append(answer_chunk(sa, sb, T[s:s + chunk_size], s, o))
            if progress is not None:
                progress(min(s + chunk_size, m), m)
    else:
        run = uuid.uuid4().hex[:12]
        attempts = [0] * len(starts)

        def submit(i: int):
            # _scatter sends a cloud again where its scattered copy was cancelled.
            fa, fb = (_scatter(client, x) for x in (sa, sb))
            s = starts[i]
            key = f"pcl_probcollision-{run}-{s}" + (f"-r{attempts[i]}" if attempts[i] else "")
            return client.submit(answer_chunk, fa, fb, T[s:s + chunk_size], s, o, key=key, pure=False)

        futures = [submit(i) for i in range(len(starts))]
        # Results are fetched as chunks finish, so a worker lost later takes no answer with it;
        # a chunk whose worker died before it was fetched is recomputed by the scheduler.
        from distributed import as_completed

        parts = [None] * len(futures)
        where = {f.key: i for i, f in enumerate(futures)}
        answered = resubmitted = 0
        try:
            pending = as_completed(futures)
            for future in pending:
                i = where[future.key]
                try:
                    part = future.result()
                except (concurrent.futures.CancelledError, TypeError):
                    # Debian's distributed 2022.12 raises TypeError ("exceptions must derive from
                    # BaseException") from result() where the cancel lands while it waits.
                    if future.status != "cancelled":
                        raise
                    # Dask cancels the tasks that depend on scattered data it believes lost, which a
                    # worker's death can cause even with a replica on every worker (dask/distributed
                    # issue 3149). The chunk is asked again, a bounded number of times, unless
                    # the client itself is closing.
                    if client.status != "running" or attempts[i] >= _RESUBMITS:
                        raise RuntimeError(f"pcl_probcollision.dask: the chunk of poses {starts[i]}.."
                                           f"{min(starts[i] + chunk_size, m) - 1} was cancelled by the cluster "
                                           f"{attempts[i] + 1} time(s) (client {client.status})") from None
                    attempts[i] += 1
                    resubmitted += 1
                    futures[i] = submit(i)
                    where[futures[i].key] = i
                    pending.add(futures[i])
                    continue
                parts[i] = part
                if progress is not None:
                    answered += len(part["index"])
                    progress(answered, m)
        finally:
            for f in futures:
                f.release()
        if resubmitted:
            warnings.warn(f"pcl_probcollision.dask: {resubmitted} chunk(s) cancelled by the cluster (scattered "
                          f"clouds lost with a worker?) were asked again; every pose was answered once",
                          RuntimeWarning, stacklevel=2)
    r = _assemble(parts, m, (A, B), chunk_size)
    # The models' precision warnings (built on the workers, which leave them to the client).
    for f, side in zip(facts, "ab"):
        _warn(core.model_warning(f, r.model_warnings[side]))
    free = np.flatnonzero((r.verdict == int(core.Verdict.Free)) & (r.leaf_pairs_tested > 0))
    if A["kind"] == B["kind"] == "mesh":
        if free.size:
            _warn(core.between_samples_warning(True, True, int(r.leaf_pairs_tested[free[0]]), f"pose {free[0]}",
                                               max(A["spacing"], B["spacing"])))
    elif "mesh" in (A["kind"], B["kind"]) and o["mesh_density"] is not None and free.size:
        # One mesh sampled at the user's mesh_density, coarser than the cloud it meets.
        mesh, cloud = (A, B) if A["kind"] == "mesh" else (B, A)
        _warn(core.coarse_mesh_warning(True, int(r.leaf_pairs_tested[free[0]]), f"pose {free[0]}",
                                       mesh["path"], mesh["spacing"], core.median_spacing(cloud["points"])))
    return r


_SCATTERED = 8  # clouds kept scattered per client, the most recent
_RESUBMITS = 3  # times a chunk the cluster cancelled is asked again before the batch fails


def _scatter(client, spec):
    """The cloud scattered once per client: a later call with the same cloud reuses it. Broadcast,
    so every worker holds a replica and losing a worker loses no cloud. The futures are kept on
    the client object (dropping them to the garbage collector while a new scatter of the same
    key is in flight would delete the new data)."""
    cache = client.__dict__.setdefault("_pcl_probcollision_scattered", collections.OrderedDict())
    future = cache.get(spec["token"])
    if future is None or future.status != "finished":
        # A list, not the dict itself (scatter reads a dict as {key: data}).
        [future] = client.scatter([spec], broadcast=True, hash=False)
        cache[spec["token"]] = future
        while len(cache) > _SCATTERED:
            cache.popitem(last=False)
    cache.move_to_end(spec["token"])
    return future


def _assemble(parts, m: int, inputs, chunk_size: int) -> BatchResults:
    if not parts:
        raise ValueError("poses: no pose given")
    fields = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]
              if k not in ("build_ms", "pid", "surfaces", "merged_samples", "model_warnings")}
    index = fields.pop("index")
    # Every pose answered exactly once, in pose order.
    if len(index) != m or not np.array_equal(index, np.arange(m)):
        raise RuntimeError(f"internal error: {len(index)} answers for {m} poses")
    build_ms = float(parts[0]["build_ms"][0])
    return BatchResults(fields, inputs, chunk_size, len(parts), build_ms, parts[0]["surfaces"],
                        parts[0]["merged_samples"], parts[0]["model_warnings"])
