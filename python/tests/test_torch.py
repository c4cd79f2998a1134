"""diffpills.torch.proximity: torch.autograd.gradcheck in float64, float32 within its precision,
shared poses' gradients summed, errors."""

import numpy as np
import pytest
import torch

import diffpills
import diffpills.torch as dtorch
from shapes_for_tests import random_capsule, random_polygon, random_poses

MAKERS = {"capsule": random_capsule, "polygon": random_polygon}


def _poses(rng, n):
    r, q = random_poses(rng, n)
    return torch.tensor(r, requires_grad=True), torch.tensor(q, requires_grad=True)


def _separated(rng, a, b, n):
    """Random pose pairs whose cores are apart (phi's gradient is zero, and not differentiable at
    the boundary, where cores touch)."""
    r_a, q_a = _poses(rng, 4 * n)
    r_b, q_b = _poses(rng, 4 * n)
    phi = dtorch.proximity(a, r_a, q_a, b, r_b, q_b)
    keep = phi.detach() > -(a.radius + b.radius) ** 2 + 1e-3
    keep = keep.nonzero().squeeze(1)[:n]
    pick = lambda t: t.detach()[keep].clone().requires_grad_(True)
    return pick(r_a), pick(q_a), pick(r_b), pick(q_b)


@pytest.mark.parametrize("first", ["capsule", "polygon"])
@pytest.mark.parametrize("second", ["capsule", "polygon"])
def test_gradcheck_float64(first, second):
    rng = np.random.default_rng(11)
    a, _ = MAKERS[first](rng)
    b, _ = MAKERS[second](rng)
    inputs = _separated(rng, a, b, 12)
    assert torch.autograd.gradcheck(
        lambda *x: dtorch.proximity(a, x[0], x[1], b, x[2], x[3]), inputs, eps=1e-6, atol=1e-6, rtol=1e-5
    )


def test_second_derivatives_are_refused_not_silently_wrong():
    # create_graph=True would treat the saved gradient as a constant: d/dr (dphi/dr)^2 would come
    # out as 0 instead of 2 (dphi/dr) (d2phi/dr2). A clear error instead.
    capsule = diffpills.Capsule(1.0, 0.1)
    r = torch.tensor([[0.0, 0.0, 1.0]], dtype=torch.float64, requires_grad=True)
    q = torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=torch.float64)
    phi = dtorch.proximity(capsule, r, q, capsule, torch.zeros(3, dtype=torch.float64), q)
    with pytest.raises(RuntimeError, match="once differentiable"):
        torch.autograd.grad(phi.sum(), r, create_graph=True)
    # The first derivative alone still works.
    phi = dtorch.proximity(capsule, r, q, capsule, torch.zeros(3, dtype=torch.float64), q)
    (g,) = torch.autograd.grad(phi.sum(), r)
    assert torch.allclose(g, torch.tensor([[0.0, 0.0, 2.0]], dtype=torch.float64))


def test_matches_the_batch_and_float32_is_within_its_precision():
    rng = np.random.default_rng(12)
    a, _ = random_polygon(rng)
    b, _ = random_capsule(rng)
    r_a, q_a = _poses(rng, 200)
    r_b, q_b = _poses(rng, 200)
    phi = dtorch.proximity(a, r_a, q_a, b, r_b, q_b)
    expected, gradient = diffpills.proximity_batch(
        a, r_a.detach().numpy(), q_a.detach().numpy(), b, r_b.detach().numpy(), q_b.detach().numpy()
    )
    np.testing.assert_array_equal(phi.detach().numpy(), expected)
    phi.sum().backward()
    np.testing.assert_array_equal(r_a.grad.numpy(), gradient[:, 0:3])
    np.testing.assert_array_equal(q_b.grad.numpy(), gradient[:, 10:14])

    single = [t.detach().float().requires_grad_(True) for t in (r_a, q_a, r_b, q_b)]
    phi32 = dtorch.proximity(a, single[0], single[1], b, single[2], single[3])
    assert phi32.dtype == torch.float32
    phi32.sum().backward()
    scale = 1.0 + np.abs(expected).max()
    np.testing.assert_allclose(phi32.detach().numpy(), expected, atol=1e-5 * scale)
    np.testing.assert_allclose(single[0].grad.numpy(), gradient[:, 0:3], atol=1e-4 * (1 + np.abs(gradient).max()))


def test_a_shared_pose_gets_the_summed_gradient():
    rng = np.random.default_rng(13)
    a, _ = random_capsule(rng)
    b, _ = random_polygon(rng)
    r_a, q_a = _poses(rng, 30)
    r_b = torch.tensor([0.2, -0.1, 0.3], dtype=torch.float64, requires_grad=True)
    q_b = torch.tensor([1.0, 0.2, 0.0, 0.1], dtype=torch.float64, requires_grad=True)
    phi = dtorch.proximity(a, r_a, q_a, b, r_b, q_b)
    phi.sum().backward()
    _, gradient = diffpills.proximity_batch(
        a, r_a.detach().numpy(), q_a.detach().numpy(), b, r_b.detach().numpy(), q_b.detach().numpy()
    )
    np.testing.assert_allclose(r_b.grad.numpy(), gradient[:, 7:10].sum(axis=0), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(q_b.grad.numpy(), gradient[:, 10:14].sum(axis=0), rtol=1e-12, atol=1e-12)


def test_bad_input():
    capsule = diffpills.Capsule(1.0, 0.1)
    r = torch.zeros(4, 3, dtype=torch.float64)
    q = torch.tensor([[1.0, 0.0, 0.0, 0.0]] * 4, dtype=torch.float64)
    with pytest.raises(ValueError, match="q_a"):
        dtorch.proximity(capsule, r, torch.zeros(4, 3, dtype=torch.float64), capsule, r, q)
    with pytest.raises(TypeError, match="^r_b: dtype torch.float32 must match r_a's torch.float64$"):
        dtorch.proximity(capsule, r, q, capsule, r.float(), q)
    with pytest.raises(ValueError, match="q_b"):
        dtorch.proximity(capsule, r, q, capsule, r, q[:3])
    with pytest.raises(ValueError, match=r"q_a\[0\]"):
        dtorch.proximity(capsule, r, torch.zeros(4, 4, dtype=torch.float64), capsule, r, q)
    with pytest.raises(TypeError, match="r_a"):
        dtorch.proximity(capsule, np.zeros((4, 3)), q, capsule, r, q)


def test_float32_results_beyond_its_range_raise_instead_of_inf():
    capsule = diffpills.Capsule(1.0, 0.1)
    q = torch.tensor([1.0, 0.0, 0.0, 0.0])
    near, far = torch.zeros(3), torch.tensor([1e20, 0.0, 0.0])
    # phi = 1e40 > 3.4e38: float32 cannot hold it.
    with pytest.raises(ValueError, match=r"^phi: 1e\+40 in magnitude is beyond float32's range"):
        dtorch.proximity(capsule, near, q, capsule, far, q)
    # The distance itself (1e20) fits; in float64 phi does too.
    distance = dtorch.signed_distance(capsule, near, q, capsule, far, q)
    assert distance.dtype == torch.float32 and torch.isfinite(distance).all()
    phi = dtorch.proximity(capsule, near.double(), q.double(), capsule, far.double(), q.double())
    assert phi.item() == pytest.approx(1e40, rel=1e-6)  # 1e20 in float32 is 1.00000002e20
    scene = diffpills.Scene([diffpills.Body("a", [(capsule, diffpills.Pose())]),
                             diffpills.Body("b", [(capsule, diffpills.Pose())])])
    r = torch.stack([near, far])
    with pytest.raises(ValueError, match="^phi: .* beyond float32's range"):
        dtorch.scene_contacts(scene, r, torch.stack([q, q]), margin=1e21)
    assert dtorch.scene_contacts(scene, r.double(), torch.stack([q, q]).double(), margin=1e21).phi.item() > 1e39


def test_float32_gradients_summed_beyond_its_range_raise_instead_of_inf():
    # Each row's gradient (2.97e38 in q_a) fits float32; their sum over the shared q_a does not.
    f = torch.float32
    long_stick, stick = diffpills.Capsule(3e38, 0.0), diffpills.Capsule(1.0, 0.1)
    q_a = torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=f, requires_grad=True)
    r_b = torch.tensor([[1.485e38, 1.0, 0.0]] * 2, dtype=f)
    identity = torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=f)
    distance = dtorch.signed_distance(long_stick, torch.zeros(3, dtype=f), q_a, stick, r_b, identity)
    assert torch.isfinite(distance).all()
    with pytest.raises(ValueError, match="^the gradient of q_a: .* beyond float32's range"):
        distance.sum().backward()
    # In float64 the same sum is finite, and twice one row's.
    q64 = q_a.detach().double().requires_grad_(True)
    d64 = dtorch.signed_distance(long_stick, torch.zeros(3).double(), q64, stick, r_b.double(), identity.double())
    d64.sum().backward()
    one = diffpills.signed_distance(long_stick, diffpills.Pose(), stick, diffpills.Pose(r_b[0].double().numpy(), [1, 0, 0, 0]))
    assert np.allclose(q64.grad.numpy(), 2 * one.gradient[3:7], rtol=1e-12)
    # Through a scene: two long sticks of one body near one stick of another.
    scene = diffpills.Scene([diffpills.Body("a", [(long_stick, diffpills.Pose())] * 2),
                             diffpills.Body("b", [(stick, diffpills.Pose())])])
    r = torch.tensor([[0.0, 0.0, 0.0], [1.485e38, 1.0, 0.0]], dtype=f)
    q = torch.tensor([[1.0, 0.0, 0.0, 0.0]] * 2, dtype=f, requires_grad=True)
    contacts = dtorch.scene_contacts(scene, r, q, margin=10.0)
    with pytest.raises(ValueError, match="^the gradient of q: .* beyond float32's range"):
        contacts.distance.sum().backward()
    # A forward pass that needs no gradient is not refused for one.
    with torch.no_grad():
        assert torch.isfinite(dtorch.signed_distance(long_stick, torch.zeros(3, dtype=f), identity, stick, r_b, identity)).all()


def test_a_pose_refuses_a_tensor_that_requires_grad():
    # A Pose holds plain numbers outside autograd: reading a tensor that requires grad would silently
    # cut it from its graph, so the error says to detach it (or to use diffpills.torch.proximity).
    r = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    q = torch.tensor([1.0, 0.0, 0.0, 0.0], requires_grad=True)
    with pytest.raises(TypeError, match=r"^r: a tensor that requires grad; pass r\.detach\(\)"):
        diffpills.Pose(r, q.detach())
    with pytest.raises(TypeError, match=r"^q: .*q\.detach\(\)"):
        diffpills.Pose(r.detach(), q)
    pose = diffpills.Pose(r.detach() + 1.0, q.detach())
    np.testing.assert_array_equal(pose.r, [1.0, 1.0, 1.0])
    capsule = diffpills.Capsule(1.0, 0.1)
    with pytest.raises(TypeError, match=r"^q_b: .*q_b\.detach\(\)"):
        diffpills.proximity_batch(capsule, r.detach(), q.detach(), capsule, r.detach(), q)
    phi, _ = diffpills.proximity_batch(capsule, r.detach(), q.detach(), capsule, r.detach() + 1.0, q.detach())
    assert phi.shape == (1,)


@pytest.mark.parametrize("single", ["r_a", "q_b"])
def test_zero_rows_with_a_single_pose(single):
    capsule = diffpills.Capsule(1.0, 0.1)
    tensors = {
        "r_a": torch.zeros(0, 3, dtype=torch.float64, requires_grad=True),
        "q_a": torch.zeros(0, 4, dtype=torch.float64, requires_grad=True),
        "r_b": torch.zeros(0, 3, dtype=torch.float64, requires_grad=True),
        "q_b": torch.zeros(0, 4, dtype=torch.float64, requires_grad=True),
    }
    tensors[single] = torch.tensor([1.0, 0.0, 0.0, 0.0][: 3 if single.startswith("r") else 4],
                                   dtype=torch.float64, requires_grad=True)
    phi = dtorch.proximity(capsule, tensors["r_a"], tensors["q_a"], capsule, tensors["r_b"], tensors["q_b"])
    assert phi.shape == (0,)
    phi.sum().backward()
    assert tensors[single].grad.shape == tensors[single].shape and not tensors[single].grad.any()
    assert tensors["q_a"].grad.shape == (0, 4)


def test_mismatched_rows_and_bad_arguments_name_them():
    capsule = diffpills.Capsule(1.0, 0.1)
    r = torch.zeros(4, 3, dtype=torch.float64)
    q = torch.tensor([[1.0, 0.0, 0.0, 0.0]] * 4, dtype=torch.float64)
    with pytest.raises(ValueError, match=r"^r_b: has 3 rows, r_a has 4$"):
        dtorch.proximity(capsule, r, q, capsule, r[:3], q)
    with pytest.raises(ValueError, match="^q_a: expected shape"):
        dtorch.proximity(capsule, r, q[:, :, None], capsule, r, q)
    # A tensor's element type is part of its type: TypeError, as for numpy arrays of these.
    for dtype in (torch.complex128, torch.bool, torch.int64, torch.float16, torch.bfloat16):
        with pytest.raises(TypeError, match=f"^q_b: expected float64 or float32, got {dtype}$"):
            dtorch.proximity(capsule, r, q, capsule, r, q.to(dtype))
        with pytest.raises(TypeError, match=f"^r: expected float64 or float32, got {dtype}$"):
            dtorch.scene_contacts(diffpills.Scene([]), r.to(dtype), q)
    with pytest.raises(TypeError, match="^q: dtype torch.float32 must match r's torch.float64$"):
        dtorch.scene_contacts(diffpills.Scene([]), r, q.float())
    # Tensors whose numbers cannot be read as an array: sparse ones, and the meta device's.
    with pytest.raises(TypeError, match="^r_b: expected a dense tensor, got layout torch.sparse_coo$"):
        dtorch.proximity(capsule, r, q, capsule, r.to_sparse(), q)
    for function in (dtorch.proximity, dtorch.signed_distance):
        with pytest.raises(ValueError, match="^r_a: is on the meta device"):
            function(capsule, r.to("meta"), q.to("meta"), capsule, r.to("meta"), q.to("meta"))
    with pytest.raises(ValueError, match="^r: is on the meta device"):
        dtorch.scene_contacts(diffpills.Scene([]), r.to("meta"), q.to("meta"))
    with pytest.raises(ValueError, match=r"^r_a\[1\]: must be finite"):
        dtorch.proximity(capsule, r.index_fill(0, torch.tensor([1]), float("nan")), q, capsule, r, q)
    with pytest.raises(ValueError, match="^threads"):
        dtorch.proximity(capsule, r, q, capsule, r, q, threads=-1)
    with pytest.raises(TypeError, match="^method"):
        dtorch.proximity(capsule, r, q, capsule, r, q, method=None)
    with pytest.raises(TypeError, match="^b: expected diffpills.Capsule"):
        dtorch.proximity(capsule, r, q, "capsule", r, q)
