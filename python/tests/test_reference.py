"""phi and the closest points against the brute-force reference, every ordering of the two shape
types, three scales, both methods."""

import zlib

import numpy as np
import pytest

import diffpills
from reference import core_distance, point_to_core
from shapes_for_tests import random_capsule, random_polygon, random_pose, to_world

MAKERS = {"capsule": random_capsule, "polygon": random_polygon}


@pytest.mark.parametrize("first", ["capsule", "polygon"])
@pytest.mark.parametrize("second", ["capsule", "polygon"])
@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("method", ["default", "interior_point"])
def test_matches_brute_force(first, second, scale, method):
    rng = np.random.default_rng(zlib.crc32(f"{first} {second} {scale} {method}".encode()))
    for _ in range(60):
        a, body_a = MAKERS[first](rng, scale)
        b, body_b = MAKERS[second](rng, scale)
        pose_a, pose_b = random_pose(rng, 1.5 * scale), random_pose(rng, 1.5 * scale)
        world_a, world_b = to_world(body_a, pose_a), to_world(body_b, pose_b)
        distance = core_distance(world_a, world_b)
        radii = a.radius + b.radius
        result = diffpills.proximity(a, pose_a, b, pose_b, method=method)
        expected_phi = distance**2 - radii**2
        assert result.phi == pytest.approx(expected_phi, abs=1e-9 * scale**2)
        p1, p2 = result.core_points
        assert np.linalg.norm(p1 - p2) == pytest.approx(distance, abs=1e-9 * scale)
        # the points lie on their cores, and the surface points on the padded surfaces
        assert point_to_core(p1, world_a)[0] <= 1e-9 * scale
        assert point_to_core(p2, world_b)[0] <= 1e-9 * scale
        assert np.linalg.norm(result.normal) == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(result.points[0], p1 + a.radius * result.normal, atol=1e-9 * scale)
        np.testing.assert_allclose(result.points[1], p2 - b.radius * result.normal, atol=1e-9 * scale)


def test_analytic_parallel_capsules():
    capsule = diffpills.Capsule(2.0, 0.25)
    result = diffpills.proximity(
        capsule, diffpills.Pose([0, 0, 0], [1, 0, 0, 0]), capsule, diffpills.Pose([0.5, 1, 0], [1, 0, 0, 0])
    )
    assert result.phi == pytest.approx(1.0 - 0.25, abs=1e-14)
    np.testing.assert_allclose(result.normal, [0, 1, 0], atol=1e-14)
