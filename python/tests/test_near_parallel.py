"""Nearly parallel capsules against a 50-digit reference (mpmath).

Two segments twisted by a small angle theta about their common perpendicular, a distance D of
order theta apart, in a random orientation and place: their closest points are unique and interior,
and the problem itself is conditioned as eps / theta. The reference solves the closest-point
problem of the inputs exactly as given (the double-precision quaternions and positions), in 50
digits; the library's points must be within 1e-13 / theta of it, and so must the gradient of phi
(the envelope theorem's, differentiated in 50 digits).
"""

import mpmath as mp
import numpy as np
import pytest

import diffpills

mp.mp.dps = 50


def _rotation(q):
    w, x, y, z = q
    n = mp.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return mp.matrix(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _exact(values):
    return [mp.mpf(float(v)) for v in values]


def _closest(capsule_a, capsule_b):
    """The stationary point of |p + s u - q - t v|^2 in 50 digits; it must be interior."""
    (length_a, r_a, q_a), (length_b, r_b, q_b) = capsule_a, capsule_b
    u = _rotation(q_a) * mp.matrix([length_a, 0, 0])
    v = _rotation(q_b) * mp.matrix([length_b, 0, 0])
    p = mp.matrix(r_a) - u / 2
    q = mp.matrix(r_b) - v / 2
    w = p - q
    a, b, e = (u.T * u)[0], (u.T * v)[0], (v.T * v)[0]
    c, f = (u.T * w)[0], (v.T * w)[0]
    det = a * e - b * b
    s = (b * f - c * e) / det
    t = (a * f - b * c) / det
    assert 0 < s < 1 and 0 < t < 1
    return p + s * u, q + t * v


def _phi(capsule_a, capsule_b):
    p1, p2 = _closest(capsule_a, capsule_b)
    d = p1 - p2
    return (d.T * d)[0]


def _multiply(p, q):
    """Hamilton product in double: the test's inputs are whatever it rounds to."""
    return np.array([p[0] * q[0] - p[1:] @ q[1:], *(p[0] * q[1:] + q[0] * p[1:] + np.cross(p[1:], q[1:]))])


def _rotate(q, v):
    return _multiply(_multiply(q, np.array([0.0, *v])), q * np.array([1.0, -1.0, -1.0, -1.0]))[1:]


def _twisted_pair(rng, theta, separation):
    """Segment a along x, segment b turned by theta about z, lifted by `separation` and crossing
    a's line at x = c when seen along z; then both moved by one random rigid motion."""
    length_a, length_b = rng.uniform(0.8, 1.5), rng.uniform(0.8, 1.5)
    c = rng.uniform(-0.2, 0.2)
    m = rng.normal(size=4)
    m /= np.linalg.norm(m)
    twist = np.array([np.cos(theta / 2), 0.0, 0.0, np.sin(theta / 2)])
    t = rng.uniform(-1, 1, 3)
    return (length_a, t, m), (length_b, t + _rotate(m, [c, 0.0, separation]), _multiply(m, twist))


def _exact_capsule(capsule):
    length, r, q = capsule
    return mp.mpf(float(length)), _exact(r), _exact(q)


@pytest.mark.parametrize("theta", [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10])
def test_nearly_parallel_capsules_are_backward_stable(theta):
    rng = np.random.default_rng(round(-np.log10(theta)))
    worst_points = worst_gradient = 0.0
    for _ in range(10):
        for separation in (theta, 0.1 * theta):
            a, b = _twisted_pair(rng, theta, separation)
            result = diffpills.proximity(
                diffpills.Capsule(a[0], 0.0), diffpills.Pose(a[1], a[2]),
                diffpills.Capsule(b[0], 0.0), diffpills.Pose(b[1], b[2]),
            )  # fmt: skip
            exact_a, exact_b = _exact_capsule(a), _exact_capsule(b)
            p1, p2 = _closest(exact_a, exact_b)
            for exact, computed in ((p1, result.core_points[0]), (p2, result.core_points[1])):
                worst_points = max(worst_points, max(abs(float(exact[i]) - computed[i]) for i in range(3)))
            # d phi / d(r, q) of each capsule in 50 digits: phi is smooth where the points are interior.
            for block, which in ((0, 0), (7, 1)):
                for k in range(7):

                    def phi_along(h, k=k, which=which):
                        capsules = [list(exact_a), list(exact_b)]
                        length, r, q = capsules[which]
                        r, q = list(r), list(q)
                        (r if k < 3 else q)[k if k < 3 else k - 3] += h
                        capsules[which] = (length, r, q)
                        return _phi(*capsules)

                    exact = mp.diff(phi_along, 0)
                    worst_gradient = max(worst_gradient, abs(float(exact) - result.gradient[block + k]))
    assert worst_points <= 1e-13 / theta, worst_points
    assert worst_gradient <= 1e-13 / theta, worst_gradient


def _exact_poses(a, b):
    """[r_a, q_a, r_b, q_b] of a pair in 50 digits, the inputs exactly as given."""
    return [*_exact(a[1]), *_exact(a[2]), *_exact(b[1]), *_exact(b[2])]


def _capsules_at(lengths, x):
    return (lengths[0], x[0:3], x[3:7]), (lengths[1], x[7:10], x[10:14])


def _moved(x, steps):
    """x with steps {coordinate: h} added."""
    x = list(x)
    for k, h in steps.items():
        x[k] += h
    return x


@pytest.mark.parametrize("theta", [1e-3, 1e-5, 1e-7, 1e-9, 1e-11])
def test_nearly_parallel_jacobian_and_hessian_are_exact(theta):
    """The points' Jacobian and phi's Hessian where the points are unique, right down to the
    solvers' parallel threshold (|sin| <= 1e-12): differentiated in 50 digits. (The implicit
    function theorem's solve once called directions with sines below 1e-6 parallel and gave
    these pairs the parallel answer, 1e12 off at theta = 1e-6.) The Jacobian, of size ~1 / theta,
    is held to its own conditioning, 1e-14 / theta of its size. The Hessian is of size 1 here but
    comes out of terms of the Jacobian's size squared, and is held to the rounding of those:
    1e-15 |J|^2, an absolute error of ~1e-15 / theta^2 (measured 2e-10 at theta = 1e-3, 0.03 at
    1e-7, 2e6 at 1e-11: near the threshold the Hessian is noise, as proximity.hpp says)."""
    rng = np.random.default_rng(100 + round(-np.log10(theta)))
    for _ in range(2):
        a, b = _twisted_pair(rng, theta, theta)
        lengths = (mp.mpf(float(a[0])), mp.mpf(float(b[0])))
        x = _exact_poses(a, b)
        result = diffpills.proximity_hessian(
            diffpills.Capsule(a[0], 0.0), diffpills.Pose(a[1], a[2]),
            diffpills.Capsule(b[0], 0.0), diffpills.Pose(b[1], b[2]),
        )  # fmt: skip
        jacobian = np.zeros((6, 14))
        for k in range(14):
            for row in range(6):

                def coordinate(h, k=k, row=row):
                    points = _closest(*_capsules_at(lengths, _moved(x, {k: h})))
                    return points[row // 3][row % 3]

                jacobian[row, k] = float(mp.diff(coordinate, 0))
        hessian = np.zeros((14, 14))
        for i in range(14):
            for j in range(i + 1):

                def phi(h, g, i=i, j=j):
                    steps = {i: h} if i == j else {i: h, j: g}
                    return _phi(*_capsules_at(lengths, _moved(x, steps)))

                order = (2, 0) if i == j else (1, 1)
                hessian[i, j] = hessian[j, i] = float(mp.diff(phi, (0, 0), order))
        jacobian_error = np.abs(result.core_points_jacobian - jacobian).max()
        hessian_error = np.abs(result.hessian - hessian).max()
        size = np.abs(jacobian).max()
        assert jacobian_error <= 1e-14 / theta * size, (jacobian_error, size)
        assert hessian_error <= 1e-15 * max(size * size, np.abs(hessian).max()), (hessian_error, size)
