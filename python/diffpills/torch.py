"""PyTorch autograd for diffpills: ``diffpills.torch.proximity`` and
``diffpills.torch.signed_distance`` over batches of poses, ``diffpills.torch.scene_contacts`` over
the bodies of a scene, ``diffpills.torch.shape_proximity`` and ``shape_signed_distance`` whose
shapes' own parameters (lengths, radii, C and d) are tensors too.

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

__all__ = [
    "proximity",
    "scene_contacts",
    "shape_proximity",
    "shape_signed_distance",
    "signed_distance",
]


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


def _pose_gradients(weighted, shared, like):
    """The (N, 14) weighted float64 gradients split into r_a, q_a, r_b, q_b's, each summed over
    the rows where its pose was shared, in ``like``'s dtype and device (checked for overflow)."""
    out = []
    for (name, columns), is_shared in zip(_POSE_COLUMNS.items(), shared):
        part = weighted[:, columns]
        if is_shared:
            part = part.sum(0, keepdim=True)
        out.append(_tensor(f"the gradient of {name}", part.numpy(), like))
    return out


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
        return (None, None, None, None, None, *_pose_gradients(weighted, ctx.shared, ctx.like))


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


def _floating(name, tensor):
    """TypeError naming ``name`` unless the tensor holds float64 or float32 (the element type is
    part of the type, as numpy arrays of complex or bool are refused with TypeError)."""
    if tensor.dtype not in (torch.float64, torch.float32):
        raise TypeError(f"{name}: expected float64 or float32, got {tensor.dtype}")


def _like(name, tensor, like, like_name):
    """TypeError if ``tensor``'s dtype is not ``like``'s, ValueError if its device is not."""
    if tensor.dtype != like.dtype:
        raise TypeError(f"{name}: dtype {tensor.dtype} must match {like_name}'s {like.dtype}")
    if tensor.device != like.device:
        raise ValueError(f"{name}: device {tensor.device} must match {like_name}'s {like.device}")


def _readable(name, tensor):
    """TypeError naming ``name`` unless ``tensor`` is a torch.Tensor laid out densely (strided: not
    sparse), ValueError if it is on the meta device, which holds no numbers to read."""
    if not isinstance(tensor, torch.Tensor):
        raise TypeError(f"{name}: expected a torch.Tensor, got {type(tensor).__name__}")
    if tensor.layout != torch.strided:
        raise TypeError(f"{name}: expected a dense tensor, got layout {tensor.layout}")
    if tensor.is_meta:
        raise ValueError(f"{name}: is on the meta device, which holds no numbers")


def _rows(name, tensor, width):
    _readable(name, tensor)
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


def _pose_rows(r_a, q_a, r_b, q_b):
    """The four pose tensors as rows, checked, and N: the row count of those that are not a
    single pose (1 if all are; the largest would make a 0-row batch with a shared pose fail)."""
    r_a, q_a = _rows("r_a", r_a, 3), _rows("q_a", q_a, 4)
    r_b, q_b = _rows("r_b", r_b, 3), _rows("q_b", q_b, 4)
    tensors = {"r_a": r_a, "q_a": q_a, "r_b": r_b, "q_b": q_b}
    for name, tensor in tensors.items():
        _floating(name, tensor)
        _like(name, tensor, r_a, "r_a")
    n, n_from = 1, None
    for name, tensor in tensors.items():
        if tensor.shape[0] == 1:
            continue
        if n_from is None:
            n, n_from = tensor.shape[0], name
        elif tensor.shape[0] != n:
            raise ValueError(f"{name}: has {tensor.shape[0]} rows, {n_from} has {n}")
    return n, (r_a, q_a, r_b, q_b)


def _apply(batch, a, b, options, r_a, q_a, r_b, q_b):
    n, poses = _pose_rows(r_a, q_a, r_b, q_b)
    return _Batch.apply(batch, a, b, options, n, *poses)


_SHAPE_KEYS = {"capsule": ("length", "radius"), "polygon": ("C", "d", "radius")}


def _shape_parameters(name, shape, like):
    """A shape given by tensors: its kind and its tensors in _SHAPE_KEYS order, checked."""
    if not isinstance(shape, dict):
        raise TypeError(
            f"{name}: expected a dict of tensors, {{'length', 'radius'}} or {{'C', 'd', 'radius'}},"
            f" got {type(shape).__name__}"
        )
    kinds = [kind for kind, keys in _SHAPE_KEYS.items() if set(shape) == set(keys)]
    if not kinds:
        raise ValueError(
            f"{name}: expected the keys length, radius (a capsule) or C, d, radius (a polygon), "
            f"got {sorted(map(str, shape))}"
        )
    kind = kinds[0]
    tensors = []
    for key in _SHAPE_KEYS[kind]:
        tensor = shape[key]
        field = f"{name}[{key!r}]"
        _readable(field, tensor)
        _like(field, tensor, like, "r_a")
        tensors.append(tensor)
    if kind == "polygon":
        C, d, radius = tensors
        if C.dim() != 2 or C.shape[1] != 2 or d.dim() != 1 or d.shape[0] != C.shape[0]:
            raise ValueError(
                f"{name}: expected C of shape (m, 2) and d of shape (m,), got "
                f"{tuple(C.shape)} and {tuple(d.shape)}"
            )
    for key, tensor in zip(_SHAPE_KEYS[kind], tensors):
        if key in ("length", "radius") and tensor.numel() != 1:
            raise ValueError(f"{name}[{key!r}]: expected one number, got shape {tuple(tensor.shape)}")
    return kind, tensors


def _core_shape(name, kind, tensors):
    values = [_as_numpy(t) for t in tensors]
    try:
        if kind == "capsule":
            return _core.Capsule(float(values[0].item()), float(values[1].item()))
        return _core.PaddedPolygon(values[0], values[1], float(values[2].item()))
    except ValueError as error:  # "capsule.length: ..." as "a: capsule.length: ..."
        raise ValueError(f"{name}: {error}") from None


class _ShapePairs(torch.autograd.Function):
    """A measure of N pose pairs of two shapes whose parameters are tensors, differentiable with
    respect to the poses and the parameters: one library call per row (shape_gradient.hpp), the
    gradients summed over the rows in float64."""

    @staticmethod
    def forward(ctx, query, value_of, kinds, counts, n, *tensors):
        shape_tensors = tensors[: counts[0] + counts[1]]
        poses = tensors[counts[0] + counts[1] :]
        a = _core_shape("a", kinds[0], shape_tensors[: counts[0]])
        b = _core_shape("b", kinds[1], shape_tensors[counts[0] :])
        rows = [np.broadcast_to(_as_numpy(t), (n, t.shape[1])) for t in poses]
        values = np.empty(n)
        pose_gradients = np.empty((n, 14))
        shape_gradients = ([], [])
        for i in range(n):
            result = query(a, _core.Pose(rows[0][i], rows[1][i]), b, _core.Pose(rows[2][i], rows[3][i]))
            values[i] = value_of(result)
            pose_gradients[i] = result.gradient
            for side in range(2):
                gradient = result.shape_gradient[side]
                keys = _SHAPE_KEYS[kinds[side]]
                shape_gradients[side].append([np.asarray(gradient[key], dtype=np.float64) for key in keys])
        like = {"device": poses[0].device, "dtype": poses[0].dtype}
        ctx.like = like
        ctx.shared = [t.shape[0] == 1 and n != 1 for t in poses]
        ctx.shape_gradients = shape_gradients
        ctx.shape_sizes = [[t.shape for t in shape_tensors[: counts[0]]], [t.shape for t in shape_tensors[counts[0] :]]]
        ctx.save_for_backward(torch.from_numpy(pose_gradients))
        return _tensor("phi" if value_of is _phi_of else "distance", values, like)

    @staticmethod
    def backward(ctx, grad_value):
        _refuse_second_derivatives()
        (pose_gradient,) = ctx.saved_tensors
        weights = grad_value.detach().to(device="cpu", dtype=torch.float64)
        shape_grads = []
        for side, name in enumerate("ab"):
            rows = ctx.shape_gradients[side]
            for k, size in enumerate(ctx.shape_sizes[side]):
                total = np.zeros(size)
                for i, row in enumerate(rows):
                    total = total + float(weights[i]) * row[k].reshape(size)
                shape_grads.append(
                    _tensor(f"the gradient of {name}'s parameters", np.asarray(total), ctx.like)
                )
        pose_grads = _pose_gradients(pose_gradient * weights.unsqueeze(1), ctx.shared, ctx.like)
        return (None, None, None, None, None, *shape_grads, *pose_grads)


def _phi_of(result):
    return result.phi


def _distance_of(result):
    return result.distance


def shape_proximity(a, r_a, q_a, b, r_b, q_b, method="default"):
    """phi (N,) of two shapes whose parameters are tensors, differentiable with respect to them
    as well as to the poses: for fitting and designing shapes.

    a, b: dicts of tensors, ``{"length": (), "radius": ()}`` for a capsule or ``{"C": (m, 2),
    "d": (m,), "radius": ()}`` for a padded polygon (C y <= d in its body x-y plane).
    r_a, q_a, r_b, q_b: poses as for ``proximity`` (single poses shared by all rows allowed).
    Every tensor shares r_a's dtype (float64 or float32) and device. The gradients are the
    library's exact ones (shape_gradient.hpp, by the envelope theorem); the rows are computed one
    library call each, for fitting a few shapes, not for millions of pairs (use ``proximity``).
    """
    return _apply_shapes(
        lambda *args: _core.proximity_shape_gradient(*args, method=method), _phi_of,
        a, r_a, q_a, b, r_b, q_b,
    )


def shape_signed_distance(a, r_a, q_a, b, r_b, q_b):
    """The signed distance (N,) of two shapes whose parameters are tensors, differentiable with
    respect to them and to the poses; arguments as for ``shape_proximity``."""
    return _apply_shapes(
        _core.signed_distance_shape_gradient, _distance_of, a, r_a, q_a, b, r_b, q_b
    )


def _apply_shapes(query, value_of, a, r_a, q_a, b, r_b, q_b):
    n, poses = _pose_rows(r_a, q_a, r_b, q_b)
    kind_a, tensors_a = _shape_parameters("a", a, poses[0])
    kind_b, tensors_b = _shape_parameters("b", b, poses[0])
    counts = (len(tensors_a), len(tensors_b))
    return _ShapePairs.apply(
        query, value_of, (kind_a, kind_b), counts, n, *tensors_a, *tensors_b, *poses
    )


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
    _floating("r", r)
    _like("q", q, r, "r")
    outputs = _SceneContacts.apply(scene, margin, r, q)
    distance, phi, bodies, shapes, points, normal, gradient, phi_gradient = outputs
    return _core.Contacts(bodies, shapes, distance, phi, points, normal, gradient, phi_gradient)
