# SPDX-License-Identifier: BSD-3-Clause
"""pcl_probcollision: probabilistic collision checking between noisy point clouds.

Build a model per cloud once, then query pairs of models under poses::

    import numpy as np, pcl_probcollision as pc
    a = pc.build_model(points_a, params=pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(0.005)))
    r = pc.collide(a, b, np.eye(4))       # b placed in a's frame by T_a_b
    print(r.verdict, r.probability)

The compiled core is pcl_probcollision._core; everything public is re-exported here.
Pose batches over Dask workers: pcl_probcollision.dask (needs python3-distributed).
"""
from ._core import __version__  # noqa: F401
from ._core import (  # noqa: F401
    AnsweredBy,
    ClassifierParams,
    CloudModel,
    CloudModelParams,
    CollisionRequest,
    CollisionResult,
    KernelMode,
    Loss,
    NormalOrientation,
    SensorNoiseModel,
    TrainingMode,
    TraversalMode,
    Verdict,
    build_model,
    collide,
    collide_batch,
    invert_poses,
    is_closed_mesh,
    is_faceless_ply,
    load_model,
    median_spacing,
    mesh_diagonal,
    mesh_signed_volume,
    organized_sensor_pose,
    parse_poses,
    poses_from_xyzrpy,
    read_cloud,
    read_mesh,
    read_poses,
    sample_mesh,
    sample_mesh_with_normals,
    verdict_for,
)

__all__ = [
    "AnsweredBy",
    "ClassifierParams",
    "CloudModel",
    "CloudModelParams",
    "CollisionRequest",
    "CollisionResult",
    "KernelMode",
    "Loss",
    "NormalOrientation",
    "SensorNoiseModel",
    "TrainingMode",
    "TraversalMode",
    "Verdict",
    "build_model",
    "collide",
    "collide_batch",
    "invert_poses",
    "is_closed_mesh",
    "is_faceless_ply",
    "load_model",
    "median_spacing",
    "mesh_diagonal",
    "mesh_signed_volume",
    "organized_sensor_pose",
    "parse_poses",
    "poses_from_xyzrpy",
    "read_cloud",
    "read_mesh",
    "read_poses",
    "sample_mesh",
    "sample_mesh_with_normals",
    "verdict_for",
]
