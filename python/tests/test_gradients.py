"""The gradient of phi and the Jacobians of the points against central differences on seeded
random cases, every ordering of the two shape types."""

import numpy as np
import pytest

import diffpills
from shapes_for_tests import random_capsule, random_polygon, random_quaternion

MAKERS = {"capsule": random_capsule, "polygon": random_polygon}


def _query(a, b, x, jacobian=False):
    pose_a = diffpills.Pose(x[0:3], x[3:7])
    pose_b = diffpills.Pose(x[7:10], x[10:14])
    if jacobian:
        return diffpills.proximity_jacobian(a, pose_a, b, pose_b)
    return diffpills.proximity(a, pose_a, b, pose_b)


@pytest.mark.parametrize("first", ["capsule", "polygon"])
@pytest.mark.parametrize("second", ["capsule", "polygon"])
def test_derivatives_match_central_differences(first, second):
    rng = np.random.default_rng({"capsule": 1, "polygon": 2}[first] * 10 + len(second))
    h = 1e-6
    for _ in range(100):
        a, _ = MAKERS[first](rng)
        b, _ = MAKERS[second](rng)
        x = np.concatenate(
            [rng.uniform(-1.5, 1.5, 3), random_quaternion(rng), rng.uniform(-1.5, 1.5, 3), random_quaternion(rng)]
        )
        result = _query(a, b, x, jacobian=True)
        numeric_phi = np.zeros(14)
        numeric_points = np.zeros((6, 14))
        for i in range(14):
            plus, minus = x.copy(), x.copy()
            plus[i] += h
            minus[i] -= h
            hi, lo = _query(a, b, plus), _query(a, b, minus)
            numeric_phi[i] = (hi.phi - lo.phi) / (2 * h)
            numeric_points[:, i] = (hi.points.ravel() - lo.points.ravel()) / (2 * h)
        np.testing.assert_allclose(result.gradient, numeric_phi, atol=1e-6 * (1 + np.abs(numeric_phi).max()))
        if not result.cores_intersect:
            np.testing.assert_allclose(result.points_jacobian, numeric_points, atol=1e-5)
