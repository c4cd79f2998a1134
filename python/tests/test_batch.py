"""proximity_batch equals single calls row by row, for every pair type, any thread count and
broadcast single poses; it releases the GIL; every object pickles."""

import pickle
import threading

import numpy as np
import pytest

import diffpills
from shapes_for_tests import random_capsule, random_polygon, random_poses

MAKERS = {"capsule": random_capsule, "polygon": random_polygon}


@pytest.mark.parametrize("first", ["capsule", "polygon"])
@pytest.mark.parametrize("second", ["capsule", "polygon"])
@pytest.mark.parametrize("threads", [0, 1, 2, 3])
def test_batch_equals_single_calls(first, second, threads):
    rng = np.random.default_rng(7)
    a, _ = MAKERS[first](rng)
    b, _ = MAKERS[second](rng)
    r_a, q_a = random_poses(rng, 700)
    r_b, q_b = random_poses(rng, 700)
    phi, gradient = diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=threads)
    assert phi.shape == (700,) and gradient.shape == (700, 14)
    for i in range(0, 700, 7):
        single = diffpills.proximity(a, diffpills.Pose(r_a[i], q_a[i]), b, diffpills.Pose(r_b[i], q_b[i]))
        assert phi[i] == single.phi  # bit-identical
        np.testing.assert_array_equal(gradient[i], single.gradient)


def test_single_pose_broadcasts_and_float32_lists_are_accepted():
    rng = np.random.default_rng(8)
    a, _ = random_polygon(rng)
    b, _ = random_capsule(rng)
    r_a, q_a = random_poses(rng, 50)
    r_b, q_b = [0.1, 0.2, 0.3], [1.0, 0.0, 0.0, 0.0]
    phi, gradient = diffpills.proximity_batch(a, r_a.astype(np.float32), q_a, b, r_b, q_b)
    for i in range(50):
        single = diffpills.proximity(
            a, diffpills.Pose(r_a[i].astype(np.float32), q_a[i]), b, diffpills.Pose(r_b, q_b)
        )
        assert phi[i] == single.phi
        np.testing.assert_array_equal(gradient[i], single.gradient)


def test_batch_releases_the_gil():
    # While a long batch runs in a thread, the main thread keeps executing Python.
    capsule = diffpills.Capsule(1.0, 0.1)
    rng = np.random.default_rng(9)
    r, q = random_poses(rng, 400_000)
    done = threading.Event()
    worker = threading.Thread(
        target=lambda: (diffpills.proximity_batch(capsule, r, q, capsule, r[::-1].copy(), q, threads=1), done.set())
    )
    ticks = 0
    worker.start()
    while not done.is_set():
        ticks += 1
        done.wait(0.001)
    worker.join()
    assert ticks > 3


def test_objects_pickle():
    rng = np.random.default_rng(10)
    capsule, _ = random_capsule(rng)
    polygon, _ = random_polygon(rng)
    pose_a, pose_b = diffpills.Pose([1, 2, 3], [1, 0.5, 0, 0]), diffpills.Pose([0, 0, 0.5], [0, 0, 1, 0])
    for shape in (capsule, polygon):
        copy = pickle.loads(pickle.dumps(shape))
        assert type(copy) is type(shape) and copy.radius == shape.radius
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(polygon)).vertices, polygon.vertices)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(pose_a)).q, pose_a.q)
    result = diffpills.proximity_jacobian(capsule, pose_a, polygon, pose_b)
    copy = pickle.loads(pickle.dumps(result))
    assert isinstance(copy, diffpills.ProximityJacobian)
    assert copy.phi == result.phi and copy.cores_intersect == result.cores_intersect
    for field in ("core_points", "points", "normal", "gradient", "core_points_jacobian", "points_jacobian"):
        np.testing.assert_array_equal(getattr(copy, field), getattr(result, field))
    plain = diffpills.proximity(capsule, pose_a, polygon, pose_b)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(plain)).gradient, plain.gradient)


def test_caller_owned_outputs_are_written_in_place():
    rng = np.random.default_rng(14)
    a, _ = random_capsule(rng)
    b, _ = random_polygon(rng)
    r_a, q_a = random_poses(rng, 100)
    r_b, q_b = random_poses(rng, 100)
    phi, gradient = np.empty(100), np.empty((100, 14))
    returned = diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, out=(phi, gradient))
    assert returned[0] is phi and returned[1] is gradient
    expected_phi, expected_gradient = diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b)
    np.testing.assert_array_equal(phi, expected_phi)
    np.testing.assert_array_equal(gradient, expected_gradient)
    for bad, match in [
        ((np.empty(99), gradient), r"out\[0\]"),
        ((phi, np.empty((100, 14), dtype=np.float32)), r"out\[1\]"),
        ((phi, np.empty((14, 100)).T), r"out\[1\]"),
        ((phi,), "out"),
    ]:
        with pytest.raises(ValueError, match=match):
            diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, out=bad)
