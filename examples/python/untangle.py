"""Untangles a heap of overlapping capsules and padded polygons by gradient descent through
diffpills.torch, until every pair has phi >= 0, and draws the heap before and after.

The bodies lie flat on the plane z = 0 (capsules with their axis in the plane, polygons in it), so
that the top view shows every overlap exactly. Each body's pose is (x, y, yaw); its quaternion
q = [cos(yaw/2), 0, 0, sin(yaw/2)] is built in torch, so autograd carries the library's exact
d phi / d q back to the yaw. The loss is the sum over pairs of relu(R1 + R2 + margin - d)^2 with
d = sqrt(phi + (R1 + R2)^2) the cores' distance, minimized with Adam. One diffpills.torch.proximity call per pair of shape kinds handles all bodies of those kinds.

phi's gradient is zero while two cores intersect (the proximity is flat there), so the heap is
dealt so that padding overlaps but cores do not; the descent then only pushes cores apart.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/untangle.py [out_folder]
"""

import itertools
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402

import diffpills  # noqa: E402
import diffpills.torch  # noqa: E402


def regular_polygon(sides, circumradius, radius):
    angles = 2 * np.pi * (np.arange(sides) + 0.5) / sides
    C = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    return diffpills.PaddedPolygon(C, np.full(sides, circumradius * np.cos(np.pi / sides)), radius)


KINDS = [
    diffpills.Capsule(1.0, 0.12),
    diffpills.Capsule(0.5, 0.2),
    regular_polygon(6, 0.35, 0.08),
    regular_polygon(3, 0.4, 0.1),
    regular_polygon(4, 0.3, 0.15),
]


def yaw_quaternion(yaw):
    zeros = torch.zeros_like(yaw)
    return torch.stack([torch.cos(0.5 * yaw), zeros, zeros, torch.sin(0.5 * yaw)], dim=1)


def pair_phi(kinds, xy, yaw):
    """phi for every pair of bodies (i < j), grouped into one batch call per pair of kinds, and
    each pair's sum of radii."""
    n = len(kinds)
    position = torch.cat([xy, torch.zeros(n, 1, dtype=xy.dtype)], dim=1)
    q = yaw_quaternion(yaw)
    pairs, values, radii = [], [], []
    for ka, kb in itertools.combinations_with_replacement(range(len(KINDS)), 2):
        group = [
            (i, j) if kinds[i] == ka else (j, i)
            for i, j in itertools.combinations(range(n), 2)
            if sorted((kinds[i], kinds[j])) == [ka, kb]
        ]
        if not group:
            continue
        first = torch.tensor([i for i, _ in group])
        second = torch.tensor([j for _, j in group])
        phi = diffpills.torch.proximity(
            KINDS[ka], position[first], q[first], KINDS[kb], position[second], q[second]
        )
        pairs += group
        values.append(phi)
        radii.append(torch.full((len(group),), KINDS[ka].radius + KINDS[kb].radius, dtype=phi.dtype))
    return pairs, torch.cat(values), torch.cat(radii)


def deal_heap(rng, count, half_width):
    """Random flat bodies in a square, each placed where its core crosses no earlier core."""
    kinds, xy, yaw = [], [], []
    while len(kinds) < count:
        kind = int(rng.integers(len(KINDS)))
        candidate_xy = rng.uniform(-half_width, half_width, 2)
        candidate_yaw = rng.uniform(0, 2 * np.pi)
        pose = diffpills.Pose([*candidate_xy, 0.0], yaw_quaternion(torch.tensor([candidate_yaw]))[0].numpy())
        if all(
            not diffpills.proximity(
                KINDS[kind], pose, KINDS[k], diffpills.Pose([*p, 0.0], yaw_quaternion(torch.tensor([a]))[0].numpy())
            ).cores_intersect
            for k, p, a in zip(kinds, xy, yaw)
        ):
            kinds.append(kind)
            xy.append(candidate_xy)
            yaw.append(candidate_yaw)
    return kinds, np.array(xy), np.array(yaw)


def silhouette(shape, x, y, yaw):
    """Top-view outline of a flat padded shape: the convex hull of circles of its radius around
    its core's vertices (exact for a convex core), as a closed polygon."""
    if isinstance(shape, diffpills.Capsule):
        core = np.array([[-0.5 * shape.length, 0.0], [0.5 * shape.length, 0.0]])
    else:
        core = shape.vertices
    c, s = np.cos(yaw), np.sin(yaw)
    core = core @ np.array([[c, s], [-s, c]]) + [x, y]
    circle = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    ring = shape.radius * np.stack([np.cos(circle), np.sin(circle)], axis=1)
    points = (core[:, None, :] + ring[None, :, :]).reshape(-1, 2) if shape.radius > 0 else core
    return convex_hull(points)


def convex_hull(points):
    """Andrew's monotone chain, counterclockwise."""
    points = sorted(map(tuple, points))

    def half(sequence):
        chain = []
        for p in sequence:
            while len(chain) >= 2 and np.cross(np.subtract(chain[-1], chain[-2]), np.subtract(p, chain[-2])) <= 0:
                chain.pop()
            chain.append(p)
        return chain[:-1]

    return np.array(half(points) + half(reversed(points)))


def draw(path, title, kinds, xy, yaw, phi, pairs):
    overlapping = {i for (i, j), value in zip(pairs, phi) if value < 0} | {
        j for (i, j), value in zip(pairs, phi) if value < 0
    }
    figure, axes = plt.subplots(figsize=(6, 6))
    for index, (kind, (x, y), angle) in enumerate(zip(kinds, xy, yaw)):
        outline = silhouette(KINDS[kind], x, y, angle)
        color = "#d62728" if index in overlapping else "#2ca02c"
        axes.fill(outline[:, 0], outline[:, 1], color=color, alpha=0.35, linewidth=1.0, edgecolor=color)
    axes.set_aspect("equal")
    axes.set_xlim(-2.6, 2.6)
    axes.set_ylim(-2.6, 2.6)
    axes.set_title(f"{title}: {len(overlapping)} of {len(kinds)} bodies overlap, min phi {min(phi):.3g}")
    axes.set_xlabel("x")
    axes.set_ylabel("y")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main(out_folder):
    out = pathlib.Path(out_folder)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(4)
    kinds, xy0, yaw0 = deal_heap(rng, count=24, half_width=1.6)
    xy = torch.tensor(xy0, requires_grad=True)
    yaw = torch.tensor(yaw0, requires_grad=True)
    pairs, phi, _ = pair_phi(kinds, xy, yaw)
    before = phi.detach().numpy()
    draw(out / "untangle_before.png", "before", kinds, xy0, yaw0, before, pairs)

    optimizer = torch.optim.Adam([xy, yaw], lr=0.01)
    margin = 1e-3
    for step in range(5000):
        optimizer.zero_grad()
        pairs, phi, radii = pair_phi(kinds, xy, yaw)
        if phi.min().item() >= 0.0:
            break
        # The cores' distance d = sqrt(phi + (R1 + R2)^2): its gradient keeps unit size as the
        # cores approach, where phi's own gradient 2 d n fades, so jammed bodies keep separating.
        distance = torch.sqrt(torch.clamp(phi + radii**2, min=1e-12))
        loss = torch.relu(radii + margin - distance).pow(2).sum()
        loss.backward()
        optimizer.step()
    after = phi.detach().numpy()
    draw(out / "untangle_after.png", "after", kinds, xy.detach().numpy(), yaw.detach().numpy(), after, pairs)
    print(
        f"untangle: {len(kinds)} bodies, {len(pairs)} pairs; overlapping pairs {int((before < 0).sum())} -> "
        f"{int((after < 0).sum())} in {step} steps, min phi {before.min():.3g} -> {after.min():.3g}; "
        f"figures {out / 'untangle_before.png'}, {out / 'untangle_after.png'}"
    )
    return 0 if after.min() >= 0.0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
