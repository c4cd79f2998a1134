"""proximity_batch equals single calls row by row, for every pair type, any thread count (also when
threads cannot start, and in a forked child) and broadcast single poses, with 0 rows too; it
releases the GIL; every object pickles."""

import os
import pickle
import signal
import subprocess
import sys
import threading

import numpy as np
import pytest

import diffpills
from shapes_for_tests import random_capsule, random_polygon, random_poses

MAKERS = {"capsule": random_capsule, "polygon": random_polygon}


def assert_row_agrees(a, b, pose_a, pose_b, value, gradient, single_value, single_gradient, lengths=2):
    """A batch row against the single call: rows of two capsules come from the vector kernel and agree
    to 1e-12 of the scene's size (to the power of the value's lengths: 2 for phi, 1 for the distance;
    one length less for the gradient's position parts, per unit of q for its quaternion parts). Every
    other row is the single call's, bit for bit."""
    if not (isinstance(a, diffpills.Capsule) and isinstance(b, diffpills.Capsule)):
        assert value == single_value  # bit-identical
        np.testing.assert_array_equal(gradient, single_gradient)
        return
    size = max(a.length, b.length, a.radius + b.radius, np.linalg.norm(pose_a.r - pose_b.r))
    unit = size if lengths == 2 else 1.0
    assert abs(value - single_value) <= 1e-12 * size * unit
    q_norms = np.repeat([np.linalg.norm(pose_a.q), np.linalg.norm(pose_b.q)], 7)
    quaternion = np.array([j in range(3, 7) or j >= 10 for j in range(14)])
    tolerance = 1e-12 * unit * np.where(quaternion, size / q_norms, 1.0)
    assert np.all(np.abs(gradient - single_gradient) <= tolerance)


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
        pose_a, pose_b = diffpills.Pose(r_a[i], q_a[i]), diffpills.Pose(r_b[i], q_b[i])
        single = diffpills.proximity(a, pose_a, b, pose_b)
        assert_row_agrees(a, b, pose_a, pose_b, phi[i], gradient[i], single.phi, single.gradient)


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


def test_a_million_threads_give_the_single_calls():
    # Counts above the hardware's are capped: 10**6 once meant a thread per 512-row block.
    rng = np.random.default_rng(15)
    a, _ = random_polygon(rng)
    b, _ = random_capsule(rng)
    r_a, q_a = random_poses(rng, 20_000)
    r_b, q_b = random_poses(rng, 20_000)
    phi, gradient = diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=10**6)
    for i in range(0, 20_000, 97):
        pose_a, pose_b = diffpills.Pose(r_a[i], q_a[i]), diffpills.Pose(r_b[i], q_b[i])
        single = diffpills.proximity(a, pose_a, b, pose_b)
        assert_row_agrees(a, b, pose_a, pose_b, phi[i], gradient[i], single.phi, single.gradient)


_LIMITED_BATCH = """
import resource, sys
import numpy as np
import diffpills

rng = np.random.default_rng(16)
capsule = diffpills.Capsule(1.0, 0.2)
poses = rng.uniform(-1, 1, (20_000, 3)), rng.normal(size=(20_000, 4)), np.zeros((20_000, 3)), rng.normal(size=(20_000, 4))
expected, _ = diffpills.proximity_batch(capsule, poses[0], poses[1], capsule, poses[2], poses[3], threads=1)
phi, gradient = np.empty(20_000), np.empty((20_000, 14))  # nothing left to allocate but threads
with open("/proc/self/status") as status:
    size = next(int(line.split()[1]) * 1024 for line in status if line.startswith("VmSize:"))
_, hard = resource.getrlimit(resource.RLIMIT_AS)
resource.setrlimit(resource.RLIMIT_AS, (size + int(sys.argv[1]), hard))
diffpills.proximity_batch(capsule, poses[0], poses[1], capsule, poses[2], poses[3], threads=int(sys.argv[2]),
                          out=(phi, gradient))
sys.exit(0 if np.array_equal(phi, expected) else 1)
"""


@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs Linux's /proc")
@pytest.mark.parametrize(
    "headroom, threads",
    [(64 << 20, 10**6), (1 << 20, 0), (1 << 20, 10**6)],
    ids=["room for a few threads", "room for none", "room for none, 10**6 asked"],
)
def test_the_batch_survives_when_threads_cannot_start(headroom, threads):
    # In a process whose address space can grow by only `headroom`, the system refuses a thread once
    # its stack (8 MB by default) no longer fits. 10**6 threads over 40 blocks once started 40 and
    # ended the process (std::terminate) at the first refusal; now the batch starts no more threads
    # than there are cores, and goes on without those the system refuses.
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    child = subprocess.run(
        [sys.executable, "-c", _LIMITED_BATCH, str(headroom), str(threads)], env=env, capture_output=True, text=True,
        timeout=300,
    )
    assert child.returncode == 0, child.stderr


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_a_forked_child_gets_the_single_calls_in_time():
    # A data loader's workers are forked from a process whose batches already started the worker
    # threads, which the child does not inherit (fork copies only the calling thread). The child's
    # batch must neither wait for them nor fail: it starts its own.
    rng = np.random.default_rng(17)
    a, _ = random_capsule(rng)
    b, _ = random_polygon(rng)
    r_a, q_a = random_poses(rng, 20_000)
    r_b, q_b = random_poses(rng, 20_000)
    expected, expected_gradient = diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=2)
    child = os.fork()
    if child == 0:
        status = 1
        try:
            signal.alarm(60)  # a hang ends the child with SIGALRM
            phi, gradient = diffpills.proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=2)
            status = 0 if np.array_equal(phi, expected) and np.array_equal(gradient, expected_gradient) else 1
        finally:
            os._exit(status)
    _, status = os.waitpid(child, 0)
    assert os.WIFEXITED(status), f"the child was killed by signal {os.WTERMSIG(status)}"
    assert os.WEXITSTATUS(status) == 0


@pytest.mark.parametrize("single", ["r_a", "q_a", "r_b", "q_b", "all but r_a"])
def test_zero_rows_with_a_single_pose_give_empty_results(single):
    capsule = diffpills.Capsule(1.0, 0.1)
    arrays = {"r_a": np.zeros((0, 3)), "q_a": np.zeros((0, 4)), "r_b": np.zeros((0, 3)), "q_b": np.zeros((0, 4))}
    pose = {"r_a": [0.0, 0.0, 0.0], "q_a": [1.0, 0.0, 0.0, 0.0], "r_b": [[0.0, 0.0, 1.0]], "q_b": [1.0, 0.0, 0.0, 0.0]}
    for name in (["q_a", "r_b", "q_b"] if single == "all but r_a" else [single]):
        arrays[name] = pose[name]
    args = (capsule, arrays["r_a"], arrays["q_a"], capsule, arrays["r_b"], arrays["q_b"])
    phi, gradient = diffpills.proximity_batch(*args)
    assert phi.shape == (0,) and gradient.shape == (0, 14)
    out = (np.empty(0), np.empty((0, 14)))
    returned = diffpills.proximity_batch(*args, out=out)
    assert returned[0] is out[0] and returned[1] is out[1]


def test_caller_owned_outputs_must_not_overlap_anything():
    # The threads write the outputs while they read the inputs: an overlap would make the results
    # depend on the thread timing.
    rng = np.random.default_rng(17)
    capsule, _ = random_capsule(rng)
    r, q = random_poses(rng, 10)
    phi, gradient = np.empty(10), np.empty((10, 14))
    shared = np.empty(10 * 14 + 10)
    for out, match in [
        ((shared[:10], shared[10:].reshape(10, 14)), None),  # adjacent, not overlapping: fine
        ((gradient.reshape(-1)[5:15], gradient), "out: phi and gradient share memory"),
        ((phi, np.empty((10, 14))), None),
    ]:
        if match is None:
            diffpills.proximity_batch(capsule, r, q, capsule, r[::-1].copy(), q, out=out)
        else:
            with pytest.raises(ValueError, match=match):
                diffpills.proximity_batch(capsule, r, q, capsule, r, q, out=out)
    big = np.zeros((10, 14))
    q_inside = big.reshape(-1)[:40].reshape(10, 4)  # float64, C-contiguous: read in place
    q_inside[:] = q
    with pytest.raises(ValueError, match=r"out\[1\]: shares memory with an input array"):
        diffpills.proximity_batch(capsule, r, q_inside, capsule, r, q, out=(phi, big))
    with pytest.raises(ValueError, match=r"out\[0\]: shares memory with an input array"):
        diffpills.proximity_batch(capsule, phi.reshape(-1)[:9].reshape(3, 3), q[:3], capsule, r[:3], q[:3],
                                  out=(phi[:3], gradient[:3]))
    read_only = np.empty(10)
    read_only.setflags(write=False)
    for out, error, match in [
        ((read_only, gradient), ValueError, r"out\[0\]: array is read-only"),
        ([phi, gradient], TypeError, "out: expected a tuple"),
        ((None, gradient), ValueError, r"out\[0\]"),
        ((phi, gradient[:, :, None]), ValueError, r"out\[1\]: expected shape \(10, 14\)"),
        ((phi.astype(np.float32), gradient), ValueError, r"out\[0\]"),
        ((phi, gradient, phi), ValueError, "out"),
    ]:
        with pytest.raises(error, match=match):
            diffpills.proximity_batch(capsule, r, q, capsule, r, q, out=out)
