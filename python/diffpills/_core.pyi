# Type stubs for diffpills._core (the pybind11 module), re-exported by the package diffpills.
# Arrays and numbers must hold real numbers (floats or ints of any width); complex, bool and str
# raise TypeError at run time.
from typing import Any, Dict, List, Literal, NamedTuple, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Method = Literal["default", "interior_point"]

__version__: str

class SolverError(RuntimeError): ...

class Capsule:
    def __init__(self, length: float, radius: float) -> None: ...
    @property
    def length(self) -> float: ...
    @property
    def radius(self) -> float: ...

class PaddedPolygon:
    def __init__(self, C: ArrayLike, d: ArrayLike, radius: float) -> None: ...
    @property
    def C(self) -> np.ndarray: ...
    @property
    def d(self) -> np.ndarray: ...
    @property
    def radius(self) -> float: ...
    @property
    def vertices(self) -> np.ndarray: ...

Shape = Union[Capsule, PaddedPolygon]

class Pose:
    @overload
    def __init__(self) -> None: ...
    @overload
    def __init__(self, r: ArrayLike, q: ArrayLike) -> None: ...
    @property
    def r(self) -> np.ndarray: ...
    @property
    def q(self) -> np.ndarray: ...

class Proximity:
    @property
    def phi(self) -> float: ...
    @property
    def core_points(self) -> np.ndarray: ...
    @property
    def points(self) -> np.ndarray: ...
    @property
    def normal(self) -> np.ndarray: ...
    @property
    def cores_intersect(self) -> bool: ...
    @property
    def gradient(self) -> np.ndarray: ...

class ProximityJacobian(Proximity):
    @property
    def core_points_jacobian(self) -> np.ndarray: ...
    @property
    def points_jacobian(self) -> np.ndarray: ...

def proximity(
    a: Shape, pose_a: Pose, b: Shape, pose_b: Pose, method: Method = "default"
) -> Proximity: ...
def proximity_jacobian(
    a: Shape, pose_a: Pose, b: Shape, pose_b: Pose, method: Method = "default"
) -> ProximityJacobian: ...
def proximity_batch(
    a: Shape,
    r_a: ArrayLike,
    q_a: ArrayLike,
    b: Shape,
    r_b: ArrayLike,
    q_b: ArrayLike,
    threads: int = 0,
    method: Method = "default",
    out: Optional[Tuple[np.ndarray, np.ndarray]] = None,
) -> Tuple[np.ndarray, np.ndarray]: ...

class SignedDistance:
    @property
    def distance(self) -> float: ...
    @property
    def core_points(self) -> np.ndarray: ...
    @property
    def points(self) -> np.ndarray: ...
    @property
    def normal(self) -> np.ndarray: ...
    @property
    def penetrating(self) -> bool: ...
    @property
    def gradient(self) -> np.ndarray: ...

class SignedDistanceJacobian(SignedDistance):
    @property
    def core_points_jacobian(self) -> np.ndarray: ...
    @property
    def points_jacobian(self) -> np.ndarray: ...

class ProximityShapeGradient(Proximity):
    @property
    def shape_gradient(self) -> Tuple[Dict[str, Any], Dict[str, Any]]: ...

class SignedDistanceShapeGradient(SignedDistance):
    @property
    def shape_gradient(self) -> Tuple[Dict[str, Any], Dict[str, Any]]: ...

def proximity_shape_gradient(
    a: Shape, pose_a: Pose, b: Shape, pose_b: Pose, method: Method = "default"
) -> ProximityShapeGradient: ...
def signed_distance_shape_gradient(
    a: Shape, pose_a: Pose, b: Shape, pose_b: Pose
) -> SignedDistanceShapeGradient: ...
def signed_distance(a: Shape, pose_a: Pose, b: Shape, pose_b: Pose) -> SignedDistance: ...
def signed_distance_jacobian(a: Shape, pose_a: Pose, b: Shape, pose_b: Pose) -> SignedDistanceJacobian: ...
def signed_distance_batch(
    a: Shape,
    r_a: ArrayLike,
    q_a: ArrayLike,
    b: Shape,
    r_b: ArrayLike,
    q_b: ArrayLike,
    threads: int = 0,
    out: Optional[Tuple[np.ndarray, np.ndarray]] = None,
) -> Tuple[np.ndarray, np.ndarray]: ...

class Body:
    def __init__(
        self,
        name: str,
        shapes: Sequence[Tuple[Shape, Pose]],
        category: int = 1,
        mask: int = 0xFFFFFFFF,
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def shapes(self) -> List[Tuple[Shape, Pose]]: ...
    @property
    def category(self) -> int: ...
    @property
    def mask(self) -> int: ...

class Contacts(NamedTuple):
    bodies: np.ndarray
    shapes: np.ndarray
    distance: np.ndarray
    phi: np.ndarray
    points: np.ndarray
    normal: np.ndarray
    gradient: np.ndarray
    phi_gradient: np.ndarray

class Scene:
    def __init__(
        self, bodies: Sequence[Body], exclude: Optional[Sequence[Tuple[str, str]]] = None
    ) -> None: ...
    def __len__(self) -> int: ...
    @property
    def bodies(self) -> List[Body]: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def exclude(self) -> List[Tuple[str, str]]: ...
    def index_of(self, name: str) -> int: ...
    def contacts(self, r: ArrayLike, q: ArrayLike, margin: float = 0.0) -> Contacts: ...
