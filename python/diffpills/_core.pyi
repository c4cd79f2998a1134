# Type stubs for diffpills._core (the pybind11 module), re-exported by the package diffpills.
# Arrays and numbers must hold real numbers (floats or ints of any width); complex, bool and str
# raise TypeError at run time.
from typing import Literal, Optional, Tuple, Union, overload

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
