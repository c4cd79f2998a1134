"""Shape-parameter gradients from Python: diffpills.proximity_shape_gradient and
signed_distance_shape_gradient against central differences of the plain queries with rebuilt
shapes; pickling; diffpills.torch.shape_proximity and shape_signed_distance by gradcheck, their
errors."""

import pickle

import numpy as np
import pytest
import torch

import diffpills
import diffpills.torch as dtorch
from shapes_for_tests import random_capsule, random_polygon, random_pose


def _parameters(shape):
    if isinstance(shape, diffpills.Capsule):
        return {"length": np.array(shape.length), "radius": np.array(shape.radius)}
    return {"C": np.array(shape.C), "d": np.array(shape.d), "radius": np.array(shape.radius)}


def _shape(parameters):
    if "length" in parameters:
        return diffpills.Capsule(float(parameters["length"]), float(parameters["radius"]))
    return diffpills.PaddedPolygon(parameters["C"], parameters["d"], float(parameters["radius"]))


def _differences(value, shape, h=1e-6):
    """Central differences of value(shape) along every parameter (forward at a bound of 0)."""
    base = _parameters(shape)
    out = {}
    for key, array in base.items():
        grad = np.zeros(array.shape)
        for index in np.ndindex(array.shape):
            def at(step):
                moved = {k: v.copy() for k, v in base.items()}
                moved[key][index] += step
                return value(_shape(moved))
            if array[index] - h < 0:
                grad[index] = (4 * at(h) - at(2 * h) - 3 * at(0.0)) / (2 * h)
            else:
                grad[index] = (at(h) - at(-h)) / (2 * h)
        out[key] = grad
    return out


@pytest.mark.parametrize("measure", ["phi", "distance"])
def test_matches_central_differences(measure):
    rng = np.random.default_rng(21)
    makers = (random_capsule, random_polygon)
    for trial in range(40):
        a, _ = makers[trial % 2](rng)
        b, _ = makers[(trial // 2) % 2](rng)
        pa, pb = random_pose(rng), random_pose(rng)
        if measure == "phi":
            result = diffpills.proximity_shape_gradient(a, pa, b, pb)
            value_of = lambda x, y: diffpills.proximity(x, pa, y, pb).phi
        else:
            result = diffpills.signed_distance_shape_gradient(a, pa, b, pb)
            value_of = lambda x, y: diffpills.signed_distance(x, pa, y, pb).distance
        numeric = (_differences(lambda s: value_of(s, b), a), _differences(lambda s: value_of(a, s), b))
        for side in range(2):
            for key, expected in numeric[side].items():
                got = np.asarray(result.shape_gradient[side][key])
                assert np.allclose(got, expected, rtol=1e-5, atol=1e-6), (trial, side, key, got, expected)


def test_results_pickle_and_refuse_new():
    rng = np.random.default_rng(22)
    a, _ = random_polygon(rng)
    b, _ = random_capsule(rng)
    for result in (
        diffpills.proximity_shape_gradient(a, random_pose(rng), b, random_pose(rng)),
        diffpills.signed_distance_shape_gradient(a, random_pose(rng), b, random_pose(rng)),
    ):
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            back = pickle.loads(pickle.dumps(result, protocol=protocol))
            assert type(back) is type(result)
            for side in range(2):
                for key, value in result.shape_gradient[side].items():
                    assert np.array_equal(back.shape_gradient[side][key], value)
        with pytest.raises(TypeError, match="made by __new__"):
            type(result).__new__(type(result)).shape_gradient
        with pytest.raises(ValueError, match=r"shape_gradient\[0\]: expected C of shape"):
            broken = type(result).__new__(type(result))
            state = result.__getstate__()
            bad = dict(state[1][0], d=np.zeros(1))
            broken.__setstate__((state[0], (bad, state[1][1])))


def _torch_shapes(dtype=torch.float64):
    capsule = {
        "length": torch.tensor(1.0, dtype=dtype, requires_grad=True),
        "radius": torch.tensor(0.1, dtype=dtype, requires_grad=True),
    }
    polygon = {
        "C": torch.tensor([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]], dtype=dtype, requires_grad=True),
        "d": torch.tensor([1.0, 1.0, 1.0, 1.0, 1.8], dtype=dtype, requires_grad=True),
        "radius": torch.tensor(0.05, dtype=dtype, requires_grad=True),
    }
    return capsule, polygon


@pytest.mark.parametrize("function", [dtorch.shape_proximity, dtorch.shape_signed_distance])
def test_torch_gradcheck(function):
    torch.manual_seed(3)
    capsule, polygon = _torch_shapes()
    r_a = (torch.randn(6, 3, dtype=torch.float64) * 0.6 + torch.tensor([0.0, 0.0, 1.2], dtype=torch.float64)).requires_grad_(True)
    q_a = torch.randn(6, 4, dtype=torch.float64).requires_grad_(True)
    r_b = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    q_b = torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=torch.float64, requires_grad=True)

    def f(length, radius, C, d, polygon_radius, r_a, q_a, r_b, q_b):
        return function({"length": length, "radius": radius}, r_a, q_a, {"C": C, "d": d, "radius": polygon_radius}, r_b, q_b)

    inputs = (capsule["length"], capsule["radius"], polygon["C"], polygon["d"], polygon["radius"], r_a, q_a, r_b, q_b)
    assert torch.autograd.gradcheck(f, inputs, eps=1e-6, atol=1e-6)


def test_torch_agrees_with_the_batch_and_names_bad_input():
    capsule, polygon = _torch_shapes()
    r = torch.tensor([[0.2, 0.1, 1.5], [0.0, 0.3, -0.2]], dtype=torch.float64)
    q = torch.tensor([[1.0, 0.2, 0.0, 0.0], [0.8, 0.0, 0.3, 0.1]], dtype=torch.float64)
    phi = dtorch.shape_proximity(capsule, r, q, polygon, torch.zeros(3, dtype=torch.float64), torch.tensor([1.0, 0, 0, 0], dtype=torch.float64))
    plain = dtorch.proximity(
        diffpills.Capsule(1.0, 0.1), r, q,
        diffpills.PaddedPolygon(polygon["C"].detach().numpy(), polygon["d"].detach().numpy(), 0.05),
        torch.zeros(3, dtype=torch.float64), torch.tensor([1.0, 0, 0, 0], dtype=torch.float64),
    )
    assert torch.equal(phi.detach(), plain.detach())
    identity = torch.tensor([1.0, 0, 0, 0], dtype=torch.float64)
    origin = torch.zeros(3, dtype=torch.float64)
    with pytest.raises(TypeError, match="^a: expected a dict of tensors"):
        dtorch.shape_proximity(diffpills.Capsule(1.0, 0.1), origin, identity, polygon, origin, identity)
    with pytest.raises(ValueError, match="^b: expected the keys length, radius"):
        dtorch.shape_proximity(capsule, origin, identity, {"C": polygon["C"]}, origin, identity)
    with pytest.raises(TypeError, match=r"^b\['d'\]: dtype torch.float32 must match r_a's torch.float64$"):
        dtorch.shape_proximity(capsule, origin, identity, dict(polygon, d=polygon["d"].float()), origin, identity)
    with pytest.raises(TypeError, match=r"^b\['d'\]: expected a dense tensor"):
        dtorch.shape_proximity(capsule, origin, identity, dict(polygon, d=polygon["d"].detach().to_sparse()), origin, identity)
    with pytest.raises(ValueError, match=r"^b: expected C of shape \(m, 2\) and d of shape \(m,\)"):
        dtorch.shape_proximity(capsule, origin, identity, dict(polygon, d=polygon["d"][:3]), origin, identity)
    with pytest.raises(ValueError, match=r"^a: capsule.radius: must be >= 0"):
        dtorch.shape_proximity(dict(capsule, radius=torch.tensor(-1.0, dtype=torch.float64)), origin, identity, polygon, origin, identity)
    with pytest.raises(ValueError, match=r"^a\['length'\]: expected one number"):
        dtorch.shape_proximity(dict(capsule, length=torch.ones(2, dtype=torch.float64)), origin, identity, polygon, origin, identity)
