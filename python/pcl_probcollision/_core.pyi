# SPDX-License-Identifier: BSD-3-Clause
# Type stub of the compiled extension pcl_probcollision._core (python/bindings.cpp).
# Defaults shown as "..." are the C++ structs' own defaults (see help() for their values).
import os
from typing import Any, ClassVar, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Pose = Union[npt.ArrayLike, Tuple[npt.ArrayLike, npt.ArrayLike]]
# A file path: str, bytes, or os.PathLike, as os.fsencode takes it (a name that is not UTF-8 too).
_Path = Union[str, bytes, os.PathLike]

class _Enum:
    """Not a runtime class: what every enum of the module has. They are pybind11 enums (py::enum_
    of pybind11 2.10, which has no py::native_enum), not enum.Enum: no int subclass, no iteration;
    == compares with the same enum only (Verdict.Free != 1), int(x) and operator.index(x) give the
    value, Verdict(1) gives the member, __members__ maps names to members in declaration order."""
    __members__: ClassVar[Dict[str, Any]]
    def __init__(self, value: int) -> None: ...
    def __eq__(self, other: object) -> bool: ...
    def __ne__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...
    def __int__(self) -> int: ...
    def __index__(self) -> int: ...
    def __getstate__(self) -> int: ...
    def __setstate__(self, state: int) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def value(self) -> int: ...

class Verdict(_Enum):
    Unknown: ClassVar[Verdict]
    Free: ClassVar[Verdict]
    InContact: ClassVar[Verdict]
    InCollision: ClassVar[Verdict]

class AnsweredBy(_Enum):
    Unknown: ClassVar[AnsweredBy]
    Separators: ClassVar[AnsweredBy]
    SurfaceLayer: ClassVar[AnsweredBy]
    Pooled: ClassVar[AnsweredBy]

class TraversalMode(_Enum):
    ExpectedWeight: ClassVar[TraversalMode]
    Stochastic: ClassVar[TraversalMode]
    ExpandedBV: ClassVar[TraversalMode]

class NormalOrientation(_Enum):
    Auto: ClassVar[NormalOrientation]
    PointNormals: ClassVar[NormalOrientation]
    Viewpoint: ClassVar[NormalOrientation]
    Propagate: ClassVar[NormalOrientation]

class SensorNoiseModel:
    def __init__(self) -> None: ...
    @staticmethod
    def none() -> SensorNoiseModel: ...
    @staticmethod
    def isotropic(sigma: float) -> SensorNoiseModel: ...
    @staticmethod
    def kinect() -> SensorNoiseModel: ...
    @staticmethod
    def stereo() -> SensorNoiseModel: ...
    @staticmethod
    def lidar() -> SensorNoiseModel: ...
    @staticmethod
    def from_name(name: str, sigma: float = ...) -> SensorNoiseModel: ...
    @property
    def name(self) -> str: ...
    @property
    def uses_sensor_pose(self) -> bool: ...

class CloudModelParams:
    k: int
    noise: SensorNoiseModel
    surface_projection: bool
    n_max: int
    n_min: int
    sigma_max: float
    epsilon: float
    k_sigma: float
    split: str
    surface: bool
    orientation: NormalOrientation
    closed_objects: bool
    noise_resolution: Optional[float]  # None (default): 2 without the surface model, 0 with it
    @property
    def noise_resolution_applied(self) -> float: ...
    noise_resolution_gate: str
    noise_resolution_gated: bool
    noise_resolution_whole_cloud: bool
    noise_stop: float
    n_noise_max: int
    leakage_bound: str  # 'min_slab' (default) or 'union_bound'
    keep_full_resolution: bool
    threads: int  # in [0, MAX_THREADS] (0: one per hardware thread); ValueError outside, as pcd_collision -threads
    def __init__(self, *, k: int = ..., noise: SensorNoiseModel = ..., surface_projection: bool = ...,
                 n_max: int = ..., n_min: Optional[int] = None, sigma_max: float = ..., epsilon: float = ...,
                 k_sigma: float = ..., surface: bool = False,
                 orientation: NormalOrientation = NormalOrientation.Auto, closed_objects: bool = False,
                 threads: int = 0, noise_resolution: Optional[float] = None, noise_resolution_gate: str = "cloud",
                 keep_full_resolution: bool = True, noise_stop: float = 0.0, split: str = "pca",
                 n_noise_max: int = 160, leakage_bound: str = "min_slab") -> None: ...
        # n_min None: min(8, n_max), as pcd_collision's -nmax sets it.
    def validate(self) -> None: ...

class KernelMode(_Enum):
    Linear: ClassVar[KernelMode]
    RFF: ClassVar[KernelMode]
    Ladder: ClassVar[KernelMode]

class TrainingMode(_Enum):
    Standard: ClassVar[TrainingMode]
    Robust: ClassVar[TrainingMode]

class Loss(_Enum):
    SquaredHinge: ClassVar[Loss]
    Huber: ClassVar[Loss]

class ClassifierParams:
    """The separators' leaf-pair classifier (METHOD.md 5.7); CollisionRequest.classifier."""
    kernel: KernelMode
    training: TrainingMode
    confidence: float
    gamma_cap: float
    C: float
    rbf_gamma: float
    rff_features: int
    rff_features_large: int
    rff_seed: int
    ladder_depth_sigmas: float
    ladder_fraction: float
    exact_points_in_maximum: bool
    max_iterations: int
    loss: Loss
    def __init__(self, *, kernel: KernelMode = ..., training: TrainingMode = ..., confidence: float = ...,
                 gamma_cap: float = ..., C: float = ..., rbf_gamma: float = ..., rff_features: int = ...,
                 rff_features_large: int = ..., rff_seed: int = ..., ladder_depth_sigmas: float = ...,
                 ladder_fraction: float = ..., exact_points_in_maximum: bool = ..., max_iterations: int = ...,
                 loss: Loss = ...) -> None: ...
    def validate(self) -> None: ...

class CollisionRequest:
    free_below: float
    collision_above: float
    exhaustive: bool
    per_point: bool
    enable_timings: bool
    traversal: TraversalMode
    rho_min: float
    seed: int
    expanded_k_sigma: float
    defer_kernel_fits: bool
    max_leaf_fits: int
    max_surface_pairs: int
    surface: bool
    surface_pooled: bool
    surface_ladder: bool
    surface_calibrated: bool
    distance: bool
    classifier: ClassifierParams
    def __init__(self, *, free_below: float = ..., collision_above: float = ..., exhaustive: bool = ...,
                 per_point: bool = ..., enable_timings: bool = ..., traversal: TraversalMode = ...,
                 rho_min: float = ..., seed: int = ..., expanded_k_sigma: float = ...,
                 defer_kernel_fits: bool = ..., max_leaf_fits: int = ...,
                 max_surface_pairs: int = ..., surface: bool = False,
                 surface_pooled: bool = False, surface_ladder: bool = False,
                 surface_calibrated: bool = False, distance: bool = False,
                 classifier: ClassifierParams = ...) -> None: ...
    def validate(self) -> None: ...

class CollisionResult:
    class Status(_Enum):
        Ok: ClassVar[CollisionResult.Status]
        InvalidInput: ClassVar[CollisionResult.Status]
        NumericalFailure: ClassVar[CollisionResult.Status]
    def __init__(self) -> None: ...
    @property
    def status(self) -> CollisionResult.Status: ...
    @property
    def message(self) -> str: ...
    @property
    def verdict(self) -> Verdict: ...
    @property
    def probability(self) -> float: ...
    @property
    def answered_by(self) -> AnsweredBy:
        """Whose answer probability is: Separators, SurfaceLayer or Pooled (the ladder's rung)."""
    @property
    def signed_distance(self) -> float:
        """Signed distance between the surfaces (> 0 gap, < 0 minus the penetration depth); NaN when not computed."""
    @property
    def signed_distance_std(self) -> float:
        """Standard deviation of signed_distance; NaN with it."""
    @property
    def lower_bound(self) -> bool: ...
    @property
    def budget_exhausted(self) -> bool:
        """True when the query stopped at request.max_leaf_fits (or the surface layer at
        request.max_surface_pairs) with leaf pairs left: P is a lower bound."""
    @property
    def no_leaf_tested(self) -> bool: ...
    @property
    def full_resolution(self) -> bool:
        """True when the answer is the unmerged models' (CloudModelParams.keep_full_resolution)."""
    @property
    def sample_distance(self) -> bool:
        """True when signed_distance is the distance between the two clouds' nearest samples (request.distance)."""
    @property
    def nearest_point_a(self) -> npt.NDArray[np.float64]: ...
    @property
    def nearest_point_b(self) -> npt.NDArray[np.float64]: ...
    @property
    def unobserved(self) -> bool:
        """True when the surface layer's answer rests on surface the samples do not show (a bridged hole or
        occlusion shadow, or space behind a scanned sheet: a point clear of the scan's surface there, where
        none reads inside, reads unknown: P 0.5, at least 0.25 pooled); always False without request.surface."""
    @property
    def witness_side(self) -> int:
        """Which input holds the point attaining P: +1 a (collide's first model), -1 b, 0 none."""
    @property
    def witness_index(self) -> int:
        """That point's index in its own input (-1 when none)."""
    @property
    def witness_point(self) -> npt.NDArray[np.float64]: ...
    @property
    def witness_normal(self) -> npt.NDArray[np.float64]: ...
    @property
    def points_a(self) -> int: ...
    @property
    def points_b(self) -> int: ...
    @property
    def points_skipped_nonfinite(self) -> int: ...
    @property
    def bv_tests(self) -> int: ...
    @property
    def leaf_pairs_tested(self) -> int: ...
    @property
    def kernel_leaf_pairs(self) -> int: ...
    @property
    def degenerate_leaf_pairs(self) -> int: ...
    @property
    def classifier_iterations(self) -> int: ...
    @property
    def build_ms(self) -> float: ...
    @property
    def query_ms(self) -> float: ...
    @property
    def probabilities_a(self) -> npt.NDArray[np.float32]: ...
    @property
    def probabilities_b(self) -> npt.NDArray[np.float32]: ...
    @property
    def ok(self) -> bool: ...
    def in_frame(self, pose: npt.ArrayLike) -> CollisionResult:
        """A copy with witness_point, witness_normal and (with sample_distance) the nearest points mapped by
        pose ((4, 4) rigid): collide(a, b, T_a_b) answers in a's frame, in_frame(invert_poses(T_a_b)) in b's,
        with the bits pcd_collision prints."""

class CloudModel:
    @property
    def size(self) -> int: ...
    @property
    def source_size(self) -> int: ...
    @property
    def skipped_points(self) -> int: ...
    @property
    def merged_samples(self) -> int: ...
    @property
    def coincident_samples(self) -> int: ...
    @property
    def neighbour_scatter_ratio(self) -> float: ...
    @property
    def keeps_full_resolution(self) -> bool: ...
    @property
    def origin(self) -> npt.NDArray[np.float64]: ...
    @property
    def warning(self) -> str: ...
    @property
    def build_ms(self) -> float: ...
    @property
    def bytes(self) -> int: ...
    @property
    def median_neighbour_spacing(self) -> float: ...
    @property
    def precision_ratio(self) -> float: ...
    @property
    def diagonal(self) -> float: ...
    @property
    def params(self) -> CloudModelParams: ...
    @property
    def has_surface(self) -> bool: ...
    @property
    def surface_orientation(self) -> Optional[NormalOrientation]: ...
    @property
    def surface_inside_known(self) -> Optional[bool]: ...
    @property
    def surface_closed_share(self) -> float: ...
    @property
    def surface_solid_share(self) -> float: ...
    @property
    def surface_hidden_from_viewpoint(self) -> float: ...
    @property
    def surface_normals_turned_to_viewpoint(self) -> Optional[bool]: ...
    @property
    def surface_given_normal_spread_ratio(self) -> float: ...
    @property
    def surface_normals_off_surface(self) -> Optional[bool]: ...
    @property
    def surface_given_normal_side_disagreement(self) -> float: ...
    @property
    def surface_given_normals_misoriented(self) -> Optional[bool]: ...
    def __len__(self) -> int: ...

__version__: str  # the library's version, "MAJOR.MINOR.PATCH" (pcd_collision -version)
MAX_COORDINATE: float  # the library's coordinate and pose-translation bound (1e15)
MAX_THREADS: int  # the library's cap on a thread count (1024; pcd_collision -threads, collide_batch's threads
                  # and CloudModelParams.threads refuse more with a ValueError)
PCD_COLLISION_SENSOR: str  # pcd_collision's default -sensor ("isotropic")
PCD_COLLISION_SIGMA: float  # pcd_collision's default -sigma (0.005)
PCD_COLLISION_MESH_SEED: int  # the seed pcd_collision samples meshes with

def build_model(points: npt.NDArray[np.floating], covariances: Optional[npt.NDArray[np.floating]] = None,
                params: Optional[CloudModelParams] = None, name: str = "cloud",
                viewpoint: Optional[npt.ArrayLike] = None,
                normals: Optional[npt.NDArray[np.floating]] = None, *,
                any_length_normals: bool = False, warn: bool = True) -> CloudModel: ...
def organized_sensor_pose(points: npt.NDArray[np.floating]) -> Optional[Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]: ...
def load_model(path: _Path, params: Optional[CloudModelParams] = None,
               name: Optional[str] = None) -> CloudModel: ...
# check_units: a RuntimeWarning when the models' diagonals differ by over 100x (units).
def collide(a: CloudModel, b: CloudModel, pose: _Pose, request: Optional[CollisionRequest] = None, *,
            check_units: bool = True) -> CollisionResult: ...
# threads: in [0, MAX_THREADS] (0: one per hardware thread); ValueError naming threads outside it.
def collide_batch(a: CloudModel, b: CloudModel, poses: npt.ArrayLike, request: Optional[CollisionRequest] = None,
                  threads: int = 0, *, check_units: bool = True) -> List[CollisionResult]: ...
def verdict_for(probability: float, request: CollisionRequest) -> Verdict: ...
# rounding=True appends (largest change of a coordinate, largest |coordinate|) to the tuple.
def read_cloud(path: _Path, *, rounding: bool = False) -> Tuple[Any, ...]: ...
def read_cloud_with_normals(path: _Path, *, rounding: bool = False) -> Tuple[Any, ...]: ...
class InputFacts:
    def __init__(self, *, path: str, cloud: bool = True, finite: int = 0, diagonal: float = 0.0,
                 rounding: Tuple[float, float] = (0.0, 0.0), sensor: str = "isotropic", sigma: float = 0.0) -> None: ...
    @property
    def path(self) -> str: ...
    @property
    def cloud(self) -> bool: ...
    @property
    def finite(self) -> int: ...
    @property
    def diagonal(self) -> float: ...
    @property
    def sensor(self) -> str: ...
    @property
    def sigma(self) -> float: ...
def finite_diagonal(points: npt.NDArray[np.floating]) -> float: ...
def scale_warning(a: InputFacts, b: InputFacts) -> str: ...
def noise_warning(input: InputFacts) -> str: ...
def rounding_warning(input: InputFacts) -> str: ...
def model_warning(input: InputFacts, model_warning: str) -> str: ...
def between_samples_warning(both_meshes: bool, free: bool, leaf_pairs_tested: int, where: str, spacing: float) -> str: ...
def is_faceless_ply(path: _Path) -> bool: ...
def read_mesh(path: _Path) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]: ...
def sample_mesh(vertices: npt.ArrayLike, triangles: npt.ArrayLike, spacing: float, seed: int = 20111) -> npt.NDArray[np.float32]: ...
def sample_mesh_with_normals(vertices: npt.ArrayLike, triangles: npt.ArrayLike, spacing: float,
                             seed: int = 20111) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def coarse_mesh_warning(free: bool, leaf_pairs_tested: int, where: str, mesh_path: str, mesh_spacing: float,
                        cloud_spacing: float) -> str: ...
def is_closed_mesh(vertices: npt.ArrayLike, triangles: npt.ArrayLike) -> bool: ...
def mesh_signed_volume(vertices: npt.ArrayLike, triangles: npt.ArrayLike) -> float: ...
def open_mesh_warning(path: str, vertices: npt.ArrayLike, triangles: npt.ArrayLike, orientation_option: str) -> str: ...
def inside_out_mesh_warning(path: str, closed: bool, signed_volume: float, orientation_option: str,
                            closed_option: str) -> str: ...
def mesh_diagonal(vertices: npt.ArrayLike, triangles: npt.ArrayLike) -> float: ...
def mesh_pair_spacing(vertices_a: npt.ArrayLike, triangles_a: npt.ArrayLike, vertices_b: npt.ArrayLike,
                      triangles_b: npt.ArrayLike) -> float:
    """pcd_collision's sample spacing when both inputs are meshes."""
def median_spacing(points: npt.NDArray[np.floating]) -> float: ...
def pcd_collision_params(flags: Sequence[str]) -> Tuple[CloudModelParams, CloudModelParams, CollisionRequest]: ...
def pcd_collision_usage_error(args: Sequence[str]) -> str: ...
# pcd_collision's usage error for flags needing a mesh input among inputs that are none ("" when none).
def pcd_collision_input_usage_error(flags: Sequence[str], mesh_a: bool, mesh_b: bool, name_a: str = "a.pcd",
                                    name_b: str = "b.pcd") -> str: ...
def pcd_collision_json_lines(flags: Sequence[str], input_a: Dict[str, Any], input_b: Dict[str, Any],
                             fields: Dict[str, npt.ArrayLike], poses: npt.ArrayLike, build_ms: float) -> List[str]:
    """pcd_collision's -json lines, by its own writer, for answers held as columns."""
def read_poses(path: _Path) -> npt.NDArray[np.float64]: ...
def parse_poses(text: bytes, name: str = "standard input") -> npt.NDArray[np.float64]: ...
def poses_from_xyzrpy(poses: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
def check_poses(poses: npt.ArrayLike) -> None: ...
def invert_poses(poses: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
