"""diffpills.proximity_hessian and signed_distance_hessian from Python: central differences of the
plain queries' gradients, symmetry, pickling."""

import pickle

import numpy as np
import pytest

import diffpills
from shapes_for_tests import random_capsule, random_polygon, random_pose


def _gradient(query, a, b, x):
    return query(a, diffpills.Pose(x[0:3], x[3:7]), b, diffpills.Pose(x[7:10], x[10:14])).gradient


@pytest.mark.parametrize(
    "hessian, query",
    [(diffpills.proximity_hessian, diffpills.proximity), (diffpills.signed_distance_hessian, diffpills.signed_distance)],
)
def test_matches_central_differences(hessian, query):
    rng = np.random.default_rng(41)
    makers = (random_capsule, random_polygon)
    checked = 0
    for trial in range(60):
        a, _ = makers[trial % 2](rng)
        b, _ = makers[(trial // 2) % 2](rng)
        pa, pb = random_pose(rng, 0.6), random_pose(rng, 0.6)
        result = hessian(a, pa, b, pb)
        x = np.concatenate([pa.r, pa.q, pb.r, pb.q])
        numeric = np.zeros((14, 14))
        for j in range(14):
            step = np.zeros(14)
            step[j] = 1e-6
            numeric[:, j] = (_gradient(query, a, b, x + step) - _gradient(query, a, b, x - step)) / 2e-6
        assert np.allclose(result.hessian, result.hessian.T)
        if np.abs(result.hessian - numeric).max() <= 1e-5 * (1 + np.abs(numeric).max()):
            checked += 1
    assert checked >= 57  # a kink within the step may spoil a few


def test_results_pickle():
    rng = np.random.default_rng(42)
    a, _ = random_polygon(rng)
    b, _ = random_capsule(rng)
    for result in (
        diffpills.proximity_hessian(a, random_pose(rng), b, random_pose(rng)),
        diffpills.proximity_with_hessian(a, random_pose(rng), b, random_pose(rng)),
        diffpills.signed_distance_hessian(a, random_pose(rng, 0.3), b, random_pose(rng, 0.3)),
    ):
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            back = pickle.loads(pickle.dumps(result, protocol=protocol))
            assert type(back) is type(result)
            assert np.array_equal(back.hessian, result.hessian)
            assert np.array_equal(back.gradient, result.gradient)
            if hasattr(result, "points_jacobian"):
                assert np.array_equal(back.points_jacobian, result.points_jacobian)
        with pytest.raises(TypeError, match="made by __new__"):
            type(result).__new__(type(result)).hessian
    sd = diffpills.signed_distance_hessian(a, random_pose(rng), b, random_pose(rng))
    assert sd.normal_jacobian.shape == (3, 14)


def test_proximity_with_hessian_is_proximity_hessian_without_the_jacobians():
    rng = np.random.default_rng(43)
    makers = (random_capsule, random_polygon)
    for trial in range(40):
        a, _ = makers[trial % 2](rng)
        b, _ = makers[(trial // 2) % 2](rng)
        pa, pb = random_pose(rng, 0.6), random_pose(rng, 0.6)
        for method in ("default", "interior_point"):
            try:
                full = diffpills.proximity_hessian(a, pa, b, pb, method=method)
            except diffpills.SolverError:
                with pytest.raises(diffpills.SolverError):
                    diffpills.proximity_with_hessian(a, pa, b, pb, method=method)
                continue
            lean = diffpills.proximity_with_hessian(a, pa, b, pb, method=method)
            assert type(lean) is diffpills.ProximityWithHessian
            assert not hasattr(lean, "points_jacobian")
            assert lean.phi == full.phi
            for name in ("gradient", "hessian", "points", "core_points", "normal"):
                assert np.array_equal(getattr(lean, name), getattr(full, name)), name
    with pytest.raises(ValueError, match="method"):
        diffpills.proximity_with_hessian(a, pa, b, pb, method="fast")
