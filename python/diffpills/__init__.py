"""diffpills: differentiable collision detection for capsules and padded polygons.

Shapes: ``Capsule(length, radius)`` and ``PaddedPolygon(C, d, radius)``, each posed by
``Pose(r, q)`` with ``q`` a quaternion ``[w, x, y, z]``. For any pair of shapes:

``proximity(a, pose_a, b, pose_b)``
    phi, closest points, normal and the gradient d phi / d[r_a, q_a, r_b, q_b] (14,).
``proximity_jacobian(a, pose_a, b, pose_b)``
    the same plus the Jacobians (6, 14) of the closest points.
``proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=0)``
    phi (N,) and gradients (N, 14) for arrays of poses, on every core, without the GIL.
``signed_distance(a, pose_a, b, pose_b)``, ``signed_distance_jacobian``, ``signed_distance_batch``
    the signed distance (the gap, or minus the penetration depth) with its exact gradient, which
    keeps a slope where phi is flat (overlapping cores).
``proximity_hessian(a, pose_a, b, pose_b)``, ``signed_distance_hessian``
    the same plus the (14, 14) Hessian with respect to both poses.
``proximity_with_hessian(a, pose_a, b, pose_b)``
    proximity plus the same Hessian, without the Jacobians: what Newton-type solvers need.
``proximity_shape_gradient(a, pose_a, b, pose_b)``, ``signed_distance_shape_gradient``
    the same plus ``shape_gradient``: the derivatives with respect to each shape's own parameters
    (a capsule's length and radius, a polygon's C, d and radius).

``Body(name, [(shape, pose), ...])`` and ``Scene(bodies, exclude)``
    rigid sets of primitives and scenes of named bodies; ``scene.contacts(r, q, margin)`` returns
    every pair of shapes of two bodies within the margin, with gradients with respect to the
    body poses, as NumPy arrays (a ``Contacts`` named tuple). ``world_pose(body, local)`` poses a
    shape as the query does, so that a contact's pair can be asked again.

``phi = ||p1 - p2||^2 - (R1 + R2)^2`` is negative exactly when the shapes overlap. Bad input raises
ValueError (a bad value or shape) or TypeError (a wrong type: complex numbers, a str, a tensor that
requires grad) naming the field. ``import diffpills.torch`` for ``diffpills.torch.proximity`` and
``diffpills.torch.signed_distance`` and ``diffpills.torch.scene_contacts``, PyTorch autograd
functions over batches and scenes (not imported here, so that ``import diffpills`` stays fast
without PyTorch).
"""

from ._core import (
    Body,
    Capsule,
    Contacts,
    PaddedPolygon,
    Pose,
    Proximity,
    ProximityHessian,
    ProximityJacobian,
    ProximityShapeGradient,
    ProximityWithHessian,
    SignedDistance,
    SignedDistanceHessian,
    SignedDistanceJacobian,
    SignedDistanceShapeGradient,
    Scene,
    SolverError,
    __version__,
    proximity,
    proximity_batch,
    proximity_hessian,
    proximity_jacobian,
    proximity_shape_gradient,
    proximity_with_hessian,
    signed_distance,
    signed_distance_batch,
    signed_distance_hessian,
    signed_distance_jacobian,
    signed_distance_shape_gradient,
    world_pose,
)

__all__ = [
    "Body",
    "Capsule",
    "Contacts",
    "PaddedPolygon",
    "Pose",
    "Proximity",
    "ProximityHessian",
    "ProximityJacobian",
    "ProximityShapeGradient",
    "ProximityWithHessian",
    "SignedDistance",
    "SignedDistanceHessian",
    "SignedDistanceJacobian",
    "SignedDistanceShapeGradient",
    "Scene",
    "SolverError",
    "__version__",
    "proximity",
    "proximity_batch",
    "proximity_hessian",
    "proximity_jacobian",
    "proximity_shape_gradient",
    "proximity_with_hessian",
    "signed_distance",
    "signed_distance_batch",
    "signed_distance_hessian",
    "signed_distance_jacobian",
    "signed_distance_shape_gradient",
    "world_pose",
]


def _restore(cls, state):
    """Rebuilds a pickled diffpills object from its state (any pickle protocol)."""
    instance = cls.__new__(cls)
    instance.__setstate__(state)
    return instance


def _reduce_ex(self, protocol):
    # pickle protocols 0 and 1 go through copyreg._reduce_ex, which for pybind11 classes ends the
    # interpreter (pybind11 issue 3745: "new instance has no pybind11-registered base types"); every
    # protocol takes this path instead.
    return _restore, (type(self), self.__getstate__())


for _class in (
    Body,
    Capsule,
    PaddedPolygon,
    Pose,
    Proximity,
    ProximityHessian,
    ProximityJacobian,
    ProximityShapeGradient,
    ProximityWithHessian,
    Scene,
    SignedDistance,
    SignedDistanceHessian,
    SignedDistanceJacobian,
    SignedDistanceShapeGradient,
):
    _class.__reduce_ex__ = _reduce_ex
del _class
