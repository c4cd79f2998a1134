"""diffpills.signed_distance, signed_distance_jacobian, signed_distance_batch and
diffpills.torch.signed_distance: against a brute-force convex hull written here in NumPy, the
batch against the single calls, gradcheck in penetration and apart, errors and pickling."""

import itertools
import pickle

import numpy as np
import pytest
import torch

import diffpills
import diffpills.torch as dtorch
from shapes_for_tests import random_capsule, random_polygon, random_poses

MAKERS = {"capsule": random_capsule, "polygon": random_polygon}


def rotation(q):
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def hull_core_distance(world_a, world_b, closest_gap):
    """s of the cores: closest_gap when apart; when they meet, minus the distance from 0 to the
    boundary of D = conv{va - vb}: the smallest offset of a plane through three points of D's
    vertex set with all points on one side (0 when D is flat)."""
    if closest_gap > 1e-9:
        return closest_gap
    w = (world_a[:, None, :] - world_b[None, :, :]).reshape(-1, 3)
    triples = np.array(list(itertools.combinations(range(len(w)), 3)))
    normals = np.cross(w[triples[:, 1]] - w[triples[:, 0]], w[triples[:, 2]] - w[triples[:, 0]])
    lengths = np.linalg.norm(normals, axis=1)
    keep = lengths > 1e-9
    normals = normals[keep] / lengths[keep, None]
    offsets = np.einsum("ij,ij->i", normals, w[triples[keep, 0]])
    heights = normals @ w.T
    below = np.all(heights <= offsets[:, None] + 1e-12, axis=1)
    above = np.all(heights >= offsets[:, None] - 1e-12, axis=1)
    depths = np.concatenate([offsets[below], -offsets[above]])
    return -depths.min() if len(depths) else 0.0


@pytest.mark.parametrize("first, second", itertools.product(MAKERS, MAKERS))
def test_matches_a_brute_force_hull(first, second):
    rng = np.random.default_rng(31)
    penetrating = 0
    for _ in range(150):
        a, body_a = MAKERS[first](rng)
        b, body_b = MAKERS[second](rng)
        (r_a, r_b), (q_a, q_b) = random_poses(rng, 2)
        r_b = r_a + 0.3 * (r_b - r_a)  # close: about half of the pairs overlap
        pose_a, pose_b = diffpills.Pose(r_a, q_a), diffpills.Pose(r_b, q_b)
        result = diffpills.signed_distance(a, pose_a, b, pose_b)
        gap = np.linalg.norm(np.diff(diffpills.proximity(a, pose_a, b, pose_b).core_points, axis=0))
        world_a = r_a + body_a @ rotation(q_a).T
        world_b = r_b + body_b @ rotation(q_b).T
        expected = hull_core_distance(world_a, world_b, gap) - a.radius - b.radius
        assert result.distance == pytest.approx(expected, abs=1e-9)
        assert np.allclose(result.points[1] - result.points[0], result.distance * result.normal, atol=1e-9)
        penetrating += result.penetrating
    if first == "polygon" or second == "polygon":
        assert penetrating > 20


def test_analytic_capsule_through_a_square():
    square = diffpills.PaddedPolygon([[1, 0], [0, 1], [-1, 0], [0, -1]], [1, 1, 1, 1], 0.05)
    capsule = diffpills.Capsule(1.0, 0.1)
    upright = [np.cos(-np.pi / 4), 0.0, np.sin(-np.pi / 4), 0.0]  # body x -> world z
    result = diffpills.signed_distance_jacobian(square, diffpills.Pose(), capsule, diffpills.Pose([0.5, 0, 0.2], upright))
    assert result.distance == pytest.approx(-0.45, abs=1e-14)  # out through the top: 0.3 + radii
    assert result.penetrating
    assert np.allclose(result.normal, [0, 0, 1], atol=1e-14)
    assert np.allclose(result.core_points, [[0.5, 0, 0], [0.5, 0, -0.3]], atol=1e-14)
    assert result.points_jacobian.shape == (6, 14)
    copy = pickle.loads(pickle.dumps(result))
    assert copy.distance == result.distance and np.array_equal(copy.points_jacobian, result.points_jacobian)


def test_batch_equals_the_single_calls_and_checks_its_arguments():
    rng = np.random.default_rng(5)
    a, _ = random_polygon(rng)
    b, _ = random_capsule(rng)
    r_a, q_a = random_poses(rng, 300)
    r_b, q_b = random_poses(rng, 300)
    r_b = r_a + 0.3 * (r_b - r_a)
    distance, gradient = diffpills.signed_distance_batch(a, r_a, q_a, b, r_b, q_b, threads=2)
    for i in range(300):
        single = diffpills.signed_distance(a, diffpills.Pose(r_a[i], q_a[i]), b, diffpills.Pose(r_b[i], q_b[i]))
        assert distance[i] == single.distance
        assert np.array_equal(gradient[i], single.gradient)
    out = (np.empty(300), np.empty((300, 14)))
    returned = diffpills.signed_distance_batch(a, r_a, q_a, b, r_b, q_b, out=out)
    assert returned[0] is out[0] and np.array_equal(out[0], distance)
    with pytest.raises(ValueError, match="^threads: "):
        diffpills.signed_distance_batch(a, r_a, q_a, b, r_b, q_b, threads=-1)
    with pytest.raises(TypeError, match="^out: expected a tuple \\(distance, gradient\\)"):
        diffpills.signed_distance_batch(a, r_a, q_a, b, r_b, q_b, out=[1, 2])
    q_a[7] = 0.0
    with pytest.raises(ValueError, match="^q_a\\[7\\]: quaternion must be nonzero"):
        diffpills.signed_distance_batch(a, r_a, q_a, b, r_b, q_b)
    empty, _ = diffpills.signed_distance_batch(a, np.zeros((0, 3)), [1, 0, 0, 0], b, [0, 0, 0], [1, 0, 0, 0])
    assert empty.shape == (0,)


def test_results_made_by_new_are_refused():
    with pytest.raises(TypeError, match="diffpills.signed_distance"):
        diffpills.SignedDistance.__new__(diffpills.SignedDistance).distance


def test_repr_names_the_result_class():
    capsule = diffpills.Capsule(1.0, 0.1)
    above = diffpills.Pose([0, 0, 1], [1, 0, 0, 0])
    results = {
        "SignedDistance": diffpills.signed_distance(capsule, diffpills.Pose(), capsule, above),
        "SignedDistanceJacobian": diffpills.signed_distance_jacobian(capsule, diffpills.Pose(), capsule, above),
        "Proximity": diffpills.proximity(capsule, diffpills.Pose(), capsule, above),
        "ProximityJacobian": diffpills.proximity_jacobian(capsule, diffpills.Pose(), capsule, above),
    }
    for name, result in results.items():
        assert repr(result).startswith(f"diffpills.{name}("), repr(result)


@pytest.mark.parametrize("first, second", itertools.product(MAKERS, MAKERS))
def test_torch_gradcheck_in_penetration_and_apart(first, second):
    rng = np.random.default_rng(17)
    a, _ = MAKERS[first](rng)
    b, _ = MAKERS[second](rng)
    r_a, q_a = random_poses(rng, 40)
    r_b, q_b = random_poses(rng, 40)
    r_b = r_a + 0.15 * (r_b - r_a)  # most pairs overlap
    distance, _ = diffpills.signed_distance_batch(a, r_a, q_a, b, r_b, q_b)
    # Away from the kinks (a change of facet or of closest features): keep the pairs whose
    # distance is smooth at the scale of gradcheck's steps, by comparing two step sizes.
    inputs = [torch.tensor(x, requires_grad=True) for x in (r_a, q_a, r_b, q_b)]
    f = lambda *x: dtorch.signed_distance(a, x[0], x[1], b, x[2], x[3])  # noqa: E731
    smooth = []
    for i in range(40):
        def fd(h):
            rows = []
            for k, x in enumerate(inputs):
                for j in range(x.shape[1]):
                    plus = [t.detach().clone() for t in inputs]
                    minus = [t.detach().clone() for t in inputs]
                    plus[k][i, j] += h
                    minus[k][i, j] -= h
                    rows.append((f(*plus)[i] - f(*minus)[i]).item() / (2 * h))
            return np.array(rows)
        if np.allclose(fd(1e-6), fd(2.5e-7), atol=1e-5):
            smooth.append(i)
    assert len(smooth) >= 30
    penetrating = int((distance[smooth] < -(a.radius + b.radius) + 1e-9).sum())
    picked = tuple(t.detach()[smooth].clone().requires_grad_(True) for t in inputs)
    assert torch.autograd.gradcheck(f, picked, eps=1e-6, atol=1e-5, rtol=1e-5)
    if first == "polygon" or second == "polygon":
        assert penetrating > 0


def test_torch_matches_the_batch_and_refuses_second_derivatives():
    rng = np.random.default_rng(3)
    a, _ = random_polygon(rng)
    r_a, q_a = random_poses(rng, 20)
    r = torch.tensor(r_a, requires_grad=True)
    q = torch.tensor(q_a)
    distance = dtorch.signed_distance(a, r, q, a, torch.zeros(3, dtype=torch.float64), torch.tensor([1.0, 0, 0, 0], dtype=torch.float64))
    expected, gradient = diffpills.signed_distance_batch(a, r_a, q_a, a, [0, 0, 0], [1, 0, 0, 0])
    assert np.array_equal(distance.detach().numpy(), expected)
    distance.sum().backward()
    assert np.array_equal(r.grad.numpy(), gradient[:, 0:3])
    with pytest.raises(RuntimeError, match="once differentiable"):
        distance = dtorch.signed_distance(a, r, q, a, torch.zeros(3, dtype=torch.float64), torch.tensor([1.0, 0, 0, 0], dtype=torch.float64))
        torch.autograd.grad(distance.sum(), r, create_graph=True)
