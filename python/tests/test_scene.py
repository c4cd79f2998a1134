"""diffpills.Body, diffpills.Scene and diffpills.torch.scene_contacts: contacts against every pair
of shapes posed here in NumPy and asked to diffpills.signed_distance directly, gradients against
central differences, gradcheck, pickling and errors."""

import itertools
import pickle

import numpy as np
import pytest
import torch

import diffpills
import diffpills.torch as dtorch
from shapes_for_tests import random_shape


def quaternion_product(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ]
    )


def rotate(q, v):
    q = q / np.linalg.norm(q)
    p = quaternion_product(quaternion_product(q, np.concatenate([[0.0], v])), q * [1, -1, -1, -1])
    return p[1:]


def random_scene(rng, count, spread):
    """Bodies of 1 to 3 shapes; every fourth pair (0, 3), (4, 7), ... excluded; odd bodies of
    category 2 whose mask leaves out category 2 (odd bodies ignore each other)."""
    bodies = []
    for i in range(count):
        shapes = []
        for _ in range(rng.integers(1, 4)):
            shape, _ = random_shape(rng, 0.5)
            q = rng.normal(size=4)
            shapes.append((shape, diffpills.Pose(rng.uniform(-0.4, 0.4, 3), q * rng.uniform(0.5, 2) / np.linalg.norm(q))))
        if i % 2:
            bodies.append(diffpills.Body(f"body{i}", shapes, category=2, mask=0xFFFFFFFD))
        else:
            bodies.append(diffpills.Body(f"body{i}", shapes))
    exclude = [(f"body{i + 3}", f"body{i}") for i in range(0, count - 3, 4)]
    r = rng.uniform(-spread, spread, (count, 3))
    q = rng.normal(size=(count, 4))
    return diffpills.Scene(bodies, exclude), r, q


def every_pair(scene, r, q, margin):
    """{(i, j, a, b): signed distance} of every pair of shapes of checked bodies, posed here."""
    out = {}
    for i, j in itertools.combinations(range(len(scene)), 2):
        if (i % 2 and j % 2) or (j == i + 3 and i % 4 == 0):
            continue
        for a, (shape_a, local_a) in enumerate(scene.bodies[i].shapes):
            for b, (shape_b, local_b) in enumerate(scene.bodies[j].shapes):
                pose_a = diffpills.Pose(r[i] + rotate(q[i], local_a.r), quaternion_product(q[i], local_a.q))
                pose_b = diffpills.Pose(r[j] + rotate(q[j], local_b.r), quaternion_product(q[j], local_b.q))
                sd = diffpills.signed_distance(shape_a, pose_a, shape_b, pose_b)
                if sd.distance <= margin:
                    out[(i, j, a, b)] = sd
    return out


@pytest.mark.parametrize("margin", [0.0, 0.2, -0.05])
def test_contacts_are_every_pair_within_the_margin(margin):
    rng = np.random.default_rng(11)
    compared = 0
    for _ in range(12):
        scene, r, q = random_scene(rng, int(rng.integers(2, 16)), 0.8)
        found = scene.contacts(r, q, margin)
        expected = every_pair(scene, r, q, margin)
        keys = [tuple(b) + tuple(s) for b, s in zip(found.bodies, found.shapes)]
        assert keys == sorted(expected)
        for k, key in enumerate(keys):
            assert found.distance[k] == pytest.approx(expected[key].distance, abs=1e-12)
            np.testing.assert_allclose(found.points[k], expected[key].points, atol=1e-9)
            np.testing.assert_allclose(found.normal[k], expected[key].normal, atol=1e-9)
        compared += len(keys)
    assert compared > 30


def test_gradients_match_central_differences():
    rng = np.random.default_rng(12)
    scene, r, q = random_scene(rng, 6, 0.5)
    found = scene.contacts(r, q, 0.3)
    assert len(found.distance) > 3
    h = 1e-6
    for k in range(len(found.distance)):
        key = tuple(found.bodies[k]) + tuple(found.shapes[k])

        def value(r, q, field):
            again = scene.contacts(r, q, 10.0)
            for m in range(len(again.distance)):
                if tuple(again.bodies[m]) + tuple(again.shapes[m]) == key:
                    return getattr(again, field)[m]
            raise AssertionError("contact lost")

        for side in range(2):
            body = found.bodies[k][side]
            for c in range(7):
                plus_r, minus_r, plus_q, minus_q = r.copy(), r.copy(), q.copy(), q.copy()
                if c < 3:
                    plus_r[body, c] += h
                    minus_r[body, c] -= h
                else:
                    plus_q[body, c - 3] += h
                    minus_q[body, c - 3] -= h
                for field, gradient in (("distance", found.gradient), ("phi", found.phi_gradient)):
                    numeric = (value(plus_r, plus_q, field) - value(minus_r, minus_q, field)) / (2 * h)
                    assert numeric == pytest.approx(gradient[k, 7 * side + c], abs=1e-5 * (1 + abs(numeric)))


def test_torch_scene_contacts_gradcheck_and_sums():
    rng = np.random.default_rng(13)
    scene, r0, q0 = random_scene(rng, 5, 0.5)
    r = torch.tensor(r0, requires_grad=True)
    q = torch.tensor(q0, requires_grad=True)
    contacts = dtorch.scene_contacts(scene, r, q, 0.3)
    assert contacts.distance.shape[0] > 0
    assert contacts.bodies.dtype == torch.int64
    # The set of contacts must not change within gradcheck's steps: a margin well above them all.
    for field in ("distance", "phi"):
        assert torch.autograd.gradcheck(lambda r, q: getattr(dtorch.scene_contacts(scene, r, q, 5.0), field), (r, q))
    # The backward pass sums each contact's gradient into its two bodies' rows.
    contacts.distance.sum().backward()
    expected_r = np.zeros((len(scene), 3))
    for k, (i, j) in enumerate(contacts.bodies.numpy()):
        expected_r[i] += contacts.gradient[k, 0:3].numpy()
        expected_r[j] += contacts.gradient[k, 7:10].numpy()
    np.testing.assert_allclose(r.grad.numpy(), expected_r, atol=1e-15)
    with pytest.raises(RuntimeError, match="once differentiable"):
        total = dtorch.scene_contacts(scene, r, q, 0.3).distance.sum()
        (g,) = torch.autograd.grad(total, r, create_graph=True)


def test_exclusions_filters_and_empty_scenes():
    stick = diffpills.Capsule(1.0, 0.1)
    bodies = [diffpills.Body(name, [(stick, diffpills.Pose())]) for name in "abcd"]
    r, q = np.zeros((4, 3)), np.tile([1.0, 0, 0, 0], (4, 1))
    assert len(diffpills.Scene(bodies).contacts(r, q).distance) == 6
    scene = diffpills.Scene(bodies, exclude=[("c", "a"), ("b", "d")])
    assert scene.exclude == [("a", "c"), ("b", "d")]
    assert scene.contacts(r, q).bodies.tolist() == [[0, 1], [0, 3], [1, 2], [2, 3]]
    empty = diffpills.Scene([]).contacts(np.zeros((0, 3)), np.zeros((0, 4)))
    assert empty.distance.shape == (0,) and empty.gradient.shape == (0, 14)
    one = diffpills.Scene([diffpills.Body("pile", [(stick, diffpills.Pose()), (stick, diffpills.Pose())])])
    assert len(one.contacts([[0, 0, 0]], [[1, 0, 0, 0]]).distance) == 0
    assert scene.index_of("d") == 3 and scene.index_of("x") == -1
    assert scene.names == ["a", "b", "c", "d"]


def test_body_repr_escapes_the_name():
    name = "it's\n\"odd\""
    text = repr(diffpills.Body(name, []))
    assert text == "diffpills.Body(" + repr(name) + ", 0 shapes)"
    assert "\n" not in text


def test_pickling_keeps_the_scene():
    rng = np.random.default_rng(14)
    scene, r, q = random_scene(rng, 8, 0.6)
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        again = pickle.loads(pickle.dumps(scene, protocol))
        np.testing.assert_array_equal(again.contacts(r, q, 0.2).distance, scene.contacts(r, q, 0.2).distance)
        assert again.exclude == scene.exclude
        body = pickle.loads(pickle.dumps(scene.bodies[1], protocol))
        assert (body.name, body.category, body.mask) == ("body1", 2, 0xFFFFFFFD)


def test_world_pose_is_the_contacts_geometry():
    """world_pose against the composition written here (to rounding), and each contact's pair
    asked again at world_pose's poses: the contact's distance and points, bit for bit."""
    rng = np.random.default_rng(21)
    scene, r, q = random_scene(rng, 8, 0.6)
    found = scene.contacts(r, q, 0.2)
    assert len(found.distance) > 3
    for k in range(len(found.distance)):
        posed = []
        for side in range(2):
            body, shape = found.bodies[k][side], found.shapes[k][side]
            shape_object, local = scene.bodies[body].shapes[shape]
            pose = diffpills.world_pose(diffpills.Pose(r[body], q[body]), local)
            attitude = quaternion_product(q[body] / np.linalg.norm(q[body]), local.q / np.linalg.norm(local.q))
            np.testing.assert_allclose(pose.r, r[body] + rotate(q[body], local.r), rtol=0, atol=1e-14)
            np.testing.assert_allclose(pose.q, attitude, rtol=0, atol=1e-15)
            posed.append((shape_object, pose))
        again = diffpills.signed_distance(posed[0][0], posed[0][1], posed[1][0], posed[1][1])
        assert again.distance == found.distance[k]
        assert np.array_equal(again.points, found.points[k])


def test_errors_name_the_field():
    stick = diffpills.Capsule(1.0, 0.1)
    good = diffpills.Body("a", [(stick, diffpills.Pose())])
    far_scene = diffpills.Scene([diffpills.Body("far", [(stick, diffpills.Pose([1e100, 0, 0], [1, 0, 0, 0]))])])
    cases = [
        (lambda: diffpills.Body("", []), ValueError, "body.name: must not be empty"),
        (lambda: diffpills.Body(3, []), TypeError, "name: expected a str"),
        (lambda: diffpills.Body("a", stick), TypeError, "shapes: expected a list"),
        (lambda: diffpills.Body("a", [stick]), TypeError, r"shapes\[0\]: expected a \(shape, pose\) pair"),
        (lambda: diffpills.Body("a", [(stick, 1)]), TypeError, r"shapes\[0\]\[1\]: expected diffpills.Pose"),
        (lambda: diffpills.Body("a", [(1, diffpills.Pose())]), TypeError, r"shapes\[0\]\[0\]: expected diffpills.Capsule"),
        (lambda: diffpills.Body("a", [], category=-1), ValueError, "category: must be from 0 to 4294967295"),
        (lambda: diffpills.Body("a", [], mask=2**32), ValueError, "mask: must be from 0"),
        (lambda: diffpills.Body("a", [], mask=True), TypeError, "mask: expected an int"),
        (lambda: diffpills.Scene([good, good]), ValueError, r"bodies\[1\].name: 'a' is also the name of bodies\[0\]"),
        (lambda: diffpills.Scene([good, 1]), TypeError, r"bodies\[1\]: expected diffpills.Body"),
        (lambda: diffpills.Scene([good], [("a", "b")]), ValueError, r"exclude\[0\]: no body is named 'b'"),
        (lambda: diffpills.Scene([good], [("a",)]), TypeError, r"exclude\[0\]: expected a \(name, name\) pair"),
        (lambda: diffpills.Scene([good]).contacts(np.zeros((2, 3)), [[1, 0, 0, 0]]), ValueError, r"r: expected shape \(1, 3\)"),
        (lambda: diffpills.Scene([good]).contacts([[0, 0, 0]], [[0, 0, 0, 0]]), ValueError, r"q\[0\]: quaternion must be nonzero"),
        (lambda: diffpills.Scene([good]).contacts([[np.nan, 0, 0]], [[1, 0, 0, 0]]), ValueError, r"r\[0\]"),
        (lambda: diffpills.Scene([good]).contacts([[0, 0, 0]], [[1, 0, 0, 0]], margin=np.inf), ValueError, "margin: must be finite"),
        (lambda: diffpills.Scene([good]).contacts([[0, 0, 0]], [[1, 0, 0, 0]], margin="x"), TypeError, "margin"),
        (lambda: diffpills.Scene.__new__(diffpills.Scene).contacts([], []), TypeError, "made by __new__"),
        (lambda: diffpills.world_pose(1, diffpills.Pose()), TypeError, "body: expected diffpills.Pose"),
        (lambda: diffpills.world_pose(diffpills.Pose(), None), TypeError, "local: expected diffpills.Pose"),
        (lambda: diffpills.world_pose(diffpills.Pose([1e100, 0, 0], [1, 0, 0, 0]), diffpills.Pose([1e100, 0, 0], [1, 0, 0, 0])),
         ValueError, r"^body, local: the world pose's pose.r\[0\]: magnitude must be <= 1e100"),
        (lambda: far_scene.contacts([[1e100, 0, 0]], [[1, 0, 0, 0]]), ValueError,
         r"^r\[0\] and q\[0\] \(body 'far'\), shape 0: its world position is beyond 1e100"),
    ]
    for make, error, message in cases:
        with pytest.raises(error, match=message):
            make()
