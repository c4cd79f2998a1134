"""Untangles a 3-D heap of capsules and padded polygons whose cores cross each other, by gradient
descent through diffpills.torch.signed_distance, until every pair is apart; and shows why the
signed distance is the measure for it.

The heap: 24 bodies (sticks, plates, hexagons, triangles) thrown into a box at random positions
and attitudes, so that many cores cross: a stick through a plate, two plates through each other.
Each body's pose is its position r and a quaternion q (any nonzero 4-vector: the library normalizes
it, and its gradient includes that), both optimized by Adam on

    loss = sum over pairs of relu(margin - distance)^2,

distance being the signed distance of the two padded shapes: the gap between their surfaces, or
minus their penetration depth. One diffpills.torch.signed_distance call per pair of shape kinds
handles all bodies of those kinds.

The same descent is run a second time with the paper's proximity phi in place of the distance
(through the cores' distance sqrt(phi + (R1 + R2)^2), whose gradient keeps a unit size as cores
approach): where two cores cross, phi is -(R1 + R2)^2 with a zero gradient, so those pairs never
move apart, and the script reports how many are left. The signed distance has a slope there.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/untangle.py [out_folder]

writes out_folder/untangle_before.png and untangle_after.png (two perspective views of the cores;
red: a body that overlaps another) and exits 0 when the signed-distance descent separated every
pair.
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
    diffpills.Capsule(1.0, 0.06),
    diffpills.Capsule(0.6, 0.1),
    regular_polygon(4, 0.45, 0.03),
    regular_polygon(6, 0.35, 0.05),
    regular_polygon(3, 0.4, 0.04),
]
BODIES = 24
HALF_WIDTH = 0.6  # the box the heap is thrown into
MARGIN = 1e-3  # the descent aims for every distance >= MARGIN
STEPS = 3000


def kind_pairs(kinds):
    """The pairs of bodies (i < j) grouped by their kinds (ka <= kb), the first of each pair of kind
    ka, as index tensors: one batch call per group."""
    groups = []
    for ka, kb in itertools.combinations_with_replacement(range(len(KINDS)), 2):
        group = [
            (i, j) if kinds[i] == ka else (j, i)
            for i, j in itertools.combinations(range(len(kinds)), 2)
            if sorted((kinds[i], kinds[j])) == [ka, kb]
        ]
        if group:
            groups.append((ka, kb, torch.tensor([i for i, _ in group]), torch.tensor([j for _, j in group])))
    return groups


def measure(groups, r, q, kind="signed_distance"):
    """Every pair's signed distance (kind "signed_distance"), or its distance from phi as the cores'
    distance sqrt(phi + (R1 + R2)^2) - R1 - R2 (kind "phi", flat where cores cross), in the order of
    `groups`; and whether the pair's cores cross (their signed distance below -(R1 + R2))."""
    values, crossing = [], []
    for ka, kb, first, second in groups:
        radii = KINDS[ka].radius + KINDS[kb].radius
        signed = diffpills.torch.signed_distance(KINDS[ka], r[first], q[first], KINDS[kb], r[second], q[second])
        crossing.append(signed.detach() < -radii)
        if kind == "signed_distance":
            values.append(signed)
        else:
            phi = diffpills.torch.proximity(KINDS[ka], r[first], q[first], KINDS[kb], r[second], q[second])
            values.append(torch.sqrt(torch.clamp(phi + radii**2, min=0.0) + 1e-30) - radii)
    return torch.cat(values), torch.cat(crossing)


def deal_heap(rng):
    kinds = rng.integers(len(KINDS), size=BODIES)
    r = rng.uniform(-HALF_WIDTH, HALF_WIDTH, (BODIES, 3))
    q = rng.normal(size=(BODIES, 4))
    return list(kinds), r, q / np.linalg.norm(q, axis=1, keepdims=True)


def descend(groups, r0, q0, kind):
    """Adam on the poses until every pair's distance (of `kind`) is >= 0, or STEPS steps."""
    r = torch.tensor(r0, requires_grad=True)
    q = torch.tensor(q0, requires_grad=True)
    optimizer = torch.optim.Adam([r, q], lr=0.005)
    steps = 0
    while steps < STEPS:
        optimizer.zero_grad()
        distance, _ = measure(groups, r, q, kind)
        if distance.min().item() >= 0.0:
            break
        torch.relu(MARGIN - distance).pow(2).sum().backward()
        optimizer.step()
        steps += 1
    with torch.no_grad():
        distance, crossing = measure(groups, r, q)  # judged by the signed distance in both runs
    return r.detach().numpy(), q.detach().numpy(), distance.numpy(), crossing.numpy(), steps


def rotation(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def core_vertices(shape, r, q):
    """The core's vertices in the world: a segment's two ends, a polygon's corners."""
    if isinstance(shape, diffpills.Capsule):
        body = np.array([[-0.5 * shape.length, 0.0, 0.0], [0.5 * shape.length, 0.0, 0.0]])
    else:
        body = np.hstack([shape.vertices, np.zeros((len(shape.vertices), 1))])
    return body @ rotation(q).T + r


VIEWS = [(25, -60), (25, 30)]  # (elevation, azimuth) of the two perspective views, degrees


def draw(path, title, kinds, r, q, groups, distance):
    """Two perspective views of the cores (polygons filled, capsules as tubes of their radius);
    red: a body that overlaps another."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    pairs = [(int(i), int(j)) for _, _, first, second in groups for i, j in zip(first, second)]
    overlapping = {body for pair, value in zip(pairs, distance) if value < 0 for body in pair}
    figure = plt.figure(figsize=(12, 6))
    for index, (elevation, azimuth) in enumerate(VIEWS):
        ax = figure.add_subplot(1, 2, index + 1, projection="3d")
        for body, kind in enumerate(kinds):
            shape = KINDS[kind]
            color = "#d62728" if body in overlapping else "#2ca02c"
            points = core_vertices(shape, r[body], q[body])
            if isinstance(shape, diffpills.Capsule):
                # A tube's width in points: the radius over the axes' span, times the figure's width.
                ax.plot(*points.T, color=color, linewidth=260 * shape.radius, solid_capstyle="round", alpha=0.8)
            else:
                ax.add_collection3d(Poly3DCollection([points], facecolor=color, edgecolor=color, alpha=0.45))
        for set_limits in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
            set_limits(-1.1, 1.1)
        ax.set_box_aspect((1, 1, 1))
        ax.view_init(elevation, azimuth)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_zlabel("z")
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def summary(distance, crossing):
    return (
        f"{int((distance < 0).sum())} overlapping pairs ({int(crossing.sum())} with crossing cores), "
        f"smallest signed distance {distance.min():.3g}"
    )


def main(out_folder):
    out = pathlib.Path(out_folder)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(0)
    kinds, r0, q0 = deal_heap(np.random.default_rng(7))
    groups = kind_pairs(kinds)
    with torch.no_grad():
        before, crossing_before = (v.numpy() for v in measure(groups, torch.tensor(r0), torch.tensor(q0)))
    draw(out / "untangle_before.png", f"before: {summary(before, crossing_before)}", kinds, r0, q0, groups, before)

    _, _, after_phi, crossing_phi, steps_phi = descend(groups, r0, q0, "phi")
    r, q, after, crossing, steps = descend(groups, r0, q0, "signed_distance")
    draw(
        out / "untangle_after.png",
        f"after {steps} steps on the signed distance: {summary(after, crossing)}",
        kinds, r, q, groups, after,
    )
    print(f"untangle: {BODIES} bodies, {len(before)} pairs; before: {summary(before, crossing_before)}")
    print(f"  signed distance: after {steps} steps, {summary(after, crossing)}")
    print(f"  phi:             after {steps_phi} steps, {summary(after_phi, crossing_phi)} (flat where cores cross)")
    print(f"  figures {out / 'untangle_before.png'}, {out / 'untangle_after.png'}")
    return 0 if after.min() >= 0.0 and crossing_before.sum() > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
