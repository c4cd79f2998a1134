"""PyTorch autograd for diffpills: ``diffpills.torch.proximity`` and
``diffpills.torch.signed_distance`` over batches of poses, ``diffpills.torch.scene_contacts`` over
the bodies of a scene.

    import torch, diffpills, diffpills.torch
    capsule = diffpills.Capsule(1.0, 0.2)
    r_a = torch.zeros(8, 3, requires_grad=True)
    q_a = torch.tensor([[1.0, 0.0, 0.0, 0.0]]).repeat(8, 1)
    phi = diffpills.torch.proximity(capsule, r_a, q_a, capsule, r_b, q_b)   # (8,)
    torch.relu(-phi).sum().backward()                                      # r_a.grad, ...

The forward pass is ``diffpills.proximity_batch`` on the CPU in float64; the backward pass
multiplies the incoming gradient by the library's exact gradient of phi (no finite differences, no
second derivatives: the function is once differentiable). Inputs may be float64 or float32, on any
device; phi comes back in the inputs' dtype and on their device. A result beyond float32's range
(3.4e38, phi of poses 1e19 apart), or a gradient that leaves it once summed over shared poses,
raises ValueError naming it instead of turning into inf: use float64 inputs for such scenes.
"""

import numpy as np
import torch

from . import _core

__all__ = ["proximity", "scene_contacts", "signed_distance"]


def _refuse_second_derivatives():
    # A backward pass that builds a graph (create_graph=True, as for Hessians or gradient
    # penalties) would treat the saved gradient as a constant and silently drop every second
    # derivative through it; torch's once_differentiable does not catch that when the incoming
    # gradient itself needs no grad. Say so instead.
    if torch.is_grad_enabled():
        raise RuntimeError(
            "diffpills.torch is once differentiable: second derivatives (backward with "
            "create_graph=True) are not available"
        )


def _as_numpy(tensor):
    return np.ascontiguousarray(tensor.detach().to(device="cpu", dtype=torch.float64).numpy())


_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _tensor(name, array, like):
    """The float64 result ``array`` as a tensor of ``like``'s dtype and device; ValueError if a
    finite value of it would overflow float32 (to inf, silently, in torch's conversion)."""
    if like["dtype"] == torch.float32 and array.size and np.max(np.abs(array)) > _FLOAT32_MAX:
        raise ValueError(
            f"{name}: {np.max(np.abs(array)):.3g} in magnitude is beyond float32's range "
            f"({_FLOAT32_MAX:.3g}); pass float64 tensors"
        )
    return torch.from_numpy(array).to(**like)


_POSE_COLUMNS = {"r_a": slice(0, 3), "q_a": slice(3, 7), "r_b": slice(7, 10), "q_b": slice(10, 14)}


class _Batch(torch.autograd.Function):
    """A value of N pose pairs (phi or the signed distance), with backward through the analytic
    gradient. ``batch`` is the diffpills batch function, called with keyword ``options``; each pose
    tensor has N rows or one shared by all N. The gradient stays in float64 until the backward
    pass has summed it over shared rows, so float32 inputs get a ValueError, not inf, if a sum
    leaves float32's range."""

    @staticmethod
    def forward(ctx, batch, a, b, options, n, r_a, q_a, r_b, q_b):
        poses = [
            np.ascontiguousarray(np.broadcast_to(_as_numpy(t), (n, t.shape[1])))
            for t in (r_a, q_a, r_b, q_b)
        ]
        value, gradient = batch(a, poses[0], poses[1], b, poses[2], poses[3], **options)
        like = {"device": r_a.device, "dtype": r_a.dtype}
        ctx.like = like
        ctx.shared = [t.shape[0] == 1 and n != 1 for t in (r_a, q_a, r_b, q_b)]
        ctx.save_for_backward(torch.from_numpy(gradient))
        return _tensor("phi" if batch is _core.proximity_batch else "distance", value, like)

    @staticmethod
    def backward(ctx, grad_value):
        _refuse_second_derivatives()
        (gradient,) = ctx.saved_tensors
        weighted = gradient * grad_value.detach().to(device="cpu", dtype=torch.float64).unsqueeze(1)
        grads = []
        for (name, columns), shared in zip(_POSE_COLUMNS.items(), ctx.shared):
            part = weighted[:, columns]
            if shared:
                part = part.sum(0, keepdim=True)
            grads.append(_tensor(f"the gradient of {name}", part.numpy(), ctx.like))
        return (None, None, None, None, None, *grads)


class _SceneContacts(torch.autograd.Function):
    """The contacts of a scene: distance and phi (K,) differentiable with respect to the body
    poses r (n, 3), q (n, 4); the rest returned alongside, not differentiable. The gradients are
    summed per body in float64, as in _Batch."""

    @staticmethod
    def forward(ctx, scene, margin, r, q):
        found = scene.contacts(_as_numpy(r), _as_numpy(q), margin)
        like = {"device": r.device, "dtype": r.dtype}
        distance = _tensor("distance", found.distance, like)
        phi = _tensor("phi", found.phi, like)
        bodies = torch.from_numpy(found.bodies.astype(np.int64))
        ctx.save_for_backward(
            bodies, torch.from_numpy(found.gradient), torch.from_numpy(found.phi_gradient)
        )
        ctx.like = like
        ctx.bodies = r.shape[0]
        others = (
            bodies.to(device=r.device),
            torch.from_numpy(found.shapes.astype(np.int64)).to(device=r.device),
            _tensor("points", found.points, like),
            torch.from_numpy(found.normal).to(**like),
            _tensor("gradient", found.gradient, like),
            _tensor("phi_gradient", found.phi_gradient, like),
        )
        ctx.mark_non_differentiable(*others)
        return (distance, phi) + others

    @staticmethod
    def backward(ctx, grad_distance, grad_phi, *unused):
        _refuse_second_derivatives()
        bodies, gradient, phi_gradient = ctx.saved_tensors
        cpu64 = {"device": "cpu", "dtype": torch.float64}
        weighted = gradient * grad_distance.detach().to(**cpu64).unsqueeze(1)
        weighted += phi_gradient * grad_phi.detach().to(**cpu64).unsqueeze(1)
        grad_r = weighted.new_zeros(ctx.bodies, 3)
        grad_q = weighted.new_zeros(ctx.bodies, 4)
        for side, offset in ((0, 0), (1, 7)):
            grad_r.index_add_(0, bodies[:, side], weighted[:, offset : offset + 3])
            grad_q.index_add_(0, bodies[:, side], weighted[:, offset + 3 : offset + 7])
        return (
            None,
            None,
            _tensor("the gradient of r", grad_r.numpy(), ctx.like),
            _tensor("the gradient of q", grad_q.numpy(), ctx.like),
        )


def _rows(name, tensor, width):
    if not isinstance(tensor, torch.Tensor):
        raise TypeError(f"{name}: expected a torch.Tensor, got {type(tensor).__name__}")
    if tensor.dim() == 1 and tensor.shape[0] == width:
        return tensor.unsqueeze(0)
    if tensor.dim() != 2 or tensor.shape[1] != width:
        raise ValueError(
            f"{name}: expected shape (N, {width}) or ({width},), got {tuple(tensor.shape)}"
        )
    return tensor


def proximity(a, r_a, q_a, b, r_b, q_b, threads=0, method="default"):
    """phi (N,) of shape ``a`` at poses (r_a[i], q_a[i]) and ``b`` at (r_b[i], q_b[i]).

    a, b: ``diffpills.Capsule`` or ``diffpills.PaddedPolygon``.
    r_a, r_b: (N, 3) tensors; q_a, q_b: (N, 4) quaternions [w, x, y, z] (need not be unit: they
    are normalized inside, and the gradient includes that). Any of the four may be a single pose,
    (3,) or (4,) or one row, shared by all N pairs (its gradient is then summed over the pairs);
    N may be 0. All four must share one dtype (float64 or float32) and device.
    threads, method: as for ``diffpills.proximity_batch``.
    Differentiable with respect to all four; the backward pass uses the exact gradient.
    Raises ValueError for bad shapes or values, TypeError for wrong types (naming the argument,
    and the row of a bad value).
    """
    options = {"threads": threads, "method": method}
    return _apply(_core.proximity_batch, a, b, options, r_a, q_a, r_b, q_b)


def signed_distance(a, r_a, q_a, b, r_b, q_b, threads=0):
    """The signed distance (N,) of shape ``a`` at poses (r_a[i], q_a[i]) and ``b`` at
    (r_b[i], q_b[i]): the gap between the padded surfaces, or minus their penetration depth.

    Arguments, broadcasting of single poses, dtypes, devices and errors as for ``proximity``.
    Differentiable with respect to all four through the exact gradient, which keeps a slope where
    phi is flat (overlapping cores): the measure to push overlapping shapes apart.
    """
    return _apply(_core.signed_distance_batch, a, b, {"threads": threads}, r_a, q_a, r_b, q_b)


def _apply(batch, a, b, options, r_a, q_a, r_b, q_b):
    r_a, q_a = _rows("r_a", r_a, 3), _rows("q_a", q_a, 4)
    r_b, q_b = _rows("r_b", r_b, 3), _rows("q_b", q_b, 4)
    tensors = {"r_a": r_a, "q_a": q_a, "r_b": r_b, "q_b": q_b}
    for name, tensor in tensors.items():
        if tensor.dtype not in (torch.float64, torch.float32):
            raise ValueError(f"{name}: expected float64 or float32, got {tensor.dtype}")
        if tensor.dtype != r_a.dtype or tensor.device != r_a.device:
            raise ValueError(f"{name}: dtype and device must match r_a's")
    # N is the row count of the tensors that are not a single pose (1 if all are): the largest row
    # count would make a 0-row batch with a shared pose fail, 0 rows against 1.
    n, n_from = 1, None
    for name, tensor in tensors.items():
        if tensor.shape[0] == 1:
            continue
        if n_from is None:
            n, n_from = tensor.shape[0], name
        elif tensor.shape[0] != n:
            raise ValueError(f"{name}: has {tensor.shape[0]} rows, {n_from} has {n}")
    return _Batch.apply(batch, a, b, options, n, r_a, q_a, r_b, q_b)


def scene_contacts(scene, r, q, margin=0.0):
    """The contacts of ``scene`` (a ``diffpills.Scene``) with its bodies at poses r (n, 3) and
    q (n, 4) (one row per body, in the scene's order): a ``diffpills.Contacts`` of tensors, whose
    ``distance`` and ``phi`` (K,) are differentiable with respect to r and q through the exact
    gradients (chain rule through the shapes' local poses, quaternion normalization included);
    ``bodies`` and ``shapes`` (K, 2) are int64, the rest as in ``Scene.contacts``, not
    differentiable. The set of contacts (pairs within ``margin``) is taken at the given poses.
    r and q must share one dtype (float64 or float32) and device; errors as ``Scene.contacts``.
    """
    r, q = _rows("r", r, 3), _rows("q", q, 4)
    for name, tensor in (("r", r), ("q", q)):
        if tensor.dtype not in (torch.float64, torch.float32):
            raise ValueError(f"{name}: expected float64 or float32, got {tensor.dtype}")
    if q.dtype != r.dtype or q.device != r.device:
        raise ValueError("q: dtype and device must match r's")
    outputs = _SceneContacts.apply(scene, margin, r, q)
    distance, phi, bodies, shapes, points, normal, gradient, phi_gradient = outputs
    return _core.Contacts(bodies, shapes, distance, phi, points, normal, gradient, phi_gradient)
