"""Fits two capsules and a padded square to the outline of an L-shaped bracket by gradient descent
on their sizes and poses, through the derivatives with respect to the shapes' own parameters
(diffpills.torch.shape_signed_distance).

The bracket: two arms of width 0.5 and length 2 in the x-y plane, meeting at a square outer corner,
their free ends rounded: a non-convex outline that no single primitive covers. Samples: points on
its outline, inside it and just outside it, placed by the bracket's own signed distance function
(written here, apart from the library). Each sample is a point (a capsule of length 0 and radius
0), and its signed distance to the model is the smallest of its signed distances to the
primitives (the model is their union). The loss is

    mean over outline points of distance^2
    + mean over inside points of relu(distance)^2            (covered)
    + mean over outside points of relu(0.05 - distance)^2    (left uncovered),

minimized by Adam over every primitive's pose in the plane (x, y and an angle about z) and its own
parameters: a capsule's length and radius, the square's four offsets d and radius (kept positive
through exponentials and a softplus). Gradients with respect to lengths, radii and offsets come
from the envelope theorem (include/diffpills/shape_gradient.hpp), with respect to poses from the
signed distance's gradient.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fit_bracket.py [out_folder] [steps]

writes out_folder/fit.svg (the bracket's outline, the samples, the first guess and the fitted
shapes) and exits 0 when every outline point ends within 0.02 of the model's surface.
"""

import math
import pathlib
import sys

import numpy as np
import torch

import diffpills.torch

DTYPE = torch.float64
ARM = 0.5  # the arms' width
LENGTH = 2.0  # from the outer corner to an arm's rounded end
TOLERANCE = 0.02  # outline points must end this close to the model's surface
OUTSIDE_GAP = 0.05  # outside samples lie at least this far out, and must stay uncovered


def bracket_distance(p):
    """The bracket's signed distance function at points p (N, 2): the union of the two arms (each
    a segment from the corner square's centre, padded by ARM / 2) and the corner square."""
    half = ARM / 2
    centre = np.array([half, half])

    def arm(end):
        ab = end - centre
        t = np.clip((p - centre) @ ab / (ab @ ab), 0.0, 1.0)
        return np.linalg.norm(p - (centre + t[:, None] * ab), axis=1) - half

    q = np.abs(p - centre) - half  # the square [0, ARM]^2
    square = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
    ends = (np.array([LENGTH - half, half]), np.array([half, LENGTH - half]))
    return np.minimum(np.minimum(arm(ends[0]), arm(ends[1])), square)


def samples():
    """Outline points (on the zero level set, from a fine polyline of each piece's boundary),
    inside points and outside points (from a grid, by the distance function)."""
    half = ARM / 2
    candidates = []
    for t in np.linspace(0.0, LENGTH - half, 40):  # the arms' straight sides
        candidates += [[t, 0.0], [t, ARM], [0.0, t], [ARM, t]]
    for end in ([LENGTH - half, half], [half, LENGTH - half]):  # the rounded ends
        for angle in np.linspace(0.0, 2 * np.pi, 48, endpoint=False):
            candidates.append([end[0] + half * np.cos(angle), end[1] + half * np.sin(angle)])
    candidates = np.array(candidates)
    outline = candidates[np.abs(bracket_distance(candidates)) < 1e-9]
    # Every third, so that the outline is sampled about every 0.1.
    outline = outline[np.argsort(np.arctan2(outline[:, 1] - 0.8, outline[:, 0] - 0.8))][::3]
    grid = np.array([[x, y] for x in np.linspace(-0.3, 2.3, 27) for y in np.linspace(-0.3, 2.3, 27)])
    distance = bracket_distance(grid)
    inner = grid[distance < -0.05]
    outer = grid[(distance > OUTSIDE_GAP) & (distance < 0.2)]
    return outline, inner, outer


class Model:
    """Two capsules and a padded rectangle in the plane, each with a planar pose (x, y, angle)."""

    def __init__(self):
        def tensor(values):
            return torch.tensor(values, dtype=DTYPE, requires_grad=True)

        # A rough first guess: a short fat stick along each arm, askew, and a small square.
        self.capsules = [
            {"length": tensor(1.2), "log_radius": tensor(math.log(0.15)), "pose": tensor([1.0, 0.4, 0.2])},
            {"length": tensor(1.2), "log_radius": tensor(math.log(0.15)), "pose": tensor([0.4, 1.0, 1.3])},
        ]
        self.rectangle = {
            "log_d": tensor([math.log(0.15)] * 4),
            "log_radius": tensor(math.log(0.05)),
            "pose": tensor([0.3, 0.3, 0.3]),
        }
        self.C = torch.tensor([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]], dtype=DTYPE)

    def parameters(self):
        out = [self.rectangle["log_d"], self.rectangle["log_radius"], self.rectangle["pose"]]
        for capsule in self.capsules:
            out += [capsule["length"], capsule["log_radius"], capsule["pose"]]
        return out

    @staticmethod
    def planar_pose(pose):
        x, y, angle = pose[0], pose[1], pose[2]
        r = torch.stack([x, y, torch.zeros((), dtype=DTYPE)])
        zero = torch.zeros((), dtype=DTYPE)
        q = torch.stack([torch.cos(angle / 2), zero, zero, torch.sin(angle / 2)])
        return r, q

    def shapes(self):
        """(shape dict, r, q) of each primitive, differentiable in the model's parameters."""
        out = []
        for capsule in self.capsules:
            shape = {"length": torch.nn.functional.softplus(capsule["length"], beta=20.0), "radius": capsule["log_radius"].exp()}
            out.append((shape, *self.planar_pose(capsule["pose"])))
        shape = {"C": self.C, "d": self.rectangle["log_d"].exp(), "radius": self.rectangle["log_radius"].exp()}
        out.append((shape, *self.planar_pose(self.rectangle["pose"])))
        return out

    def distance(self, points):
        """The signed distance of each point (N, 2) to the union of the primitives: the smallest."""
        point = {"length": torch.zeros((), dtype=DTYPE), "radius": torch.zeros((), dtype=DTYPE)}
        r = torch.cat([points, torch.zeros(len(points), 1, dtype=DTYPE)], dim=1)
        identity = torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=DTYPE)
        per_shape = [
            diffpills.torch.shape_signed_distance(shape, r_s, q_s, point, r, identity)
            for shape, r_s, q_s in self.shapes()
        ]
        return torch.stack(per_shape).min(dim=0).values


def loss(model, outline, inner, outer):
    terms = (
        model.distance(outline).pow(2).mean(),
        torch.relu(model.distance(inner)).pow(2).mean(),
        torch.relu(OUTSIDE_GAP - model.distance(outer)).pow(2).mean(),
    )
    return sum(terms)


def svg_shapes(model, colour, opacity):
    scale, out = 200.0, []

    def point(x, y):
        return f"{40 + scale * x:.2f},{460 - scale * y:.2f}"

    with torch.no_grad():
        for shape, r, q in model.shapes():
            angle = 2 * math.atan2(float(q[3]), float(q[0]))
            rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
            centre = r[:2].numpy()
            width = 2 * scale * float(shape["radius"])
            if "length" in shape:
                half = 0.5 * float(shape["length"])
                a, b = centre + rotation @ [-half, 0], centre + rotation @ [half, 0]
                out.append(
                    f"<line x1='{point(*a).split(',')[0]}' y1='{point(*a).split(',')[1]}' "
                    f"x2='{point(*b).split(',')[0]}' y2='{point(*b).split(',')[1]}' stroke='{colour}' "
                    f"stroke-opacity='{opacity}' stroke-width='{width:.2f}' stroke-linecap='round'/>"
                )
            else:
                d = shape["d"].numpy()
                corners = [(d[0], d[1]), (-d[2], d[1]), (-d[2], -d[3]), (d[0], -d[3])]
                points = " ".join(point(*(centre + rotation @ c)) for c in corners)
                out.append(
                    f"<polygon points='{points}' fill='{colour}' fill-opacity='{opacity}' "
                    f"stroke='{colour}' stroke-opacity='{opacity}' stroke-width='{width:.2f}' "
                    f"stroke-linejoin='round'/>"
                )
    return out, point


def write_svg(path, before, model, outline, inner, outer):
    after, point = svg_shapes(model, "#1f77b4", 0.55)
    parts = [
        "<svg xmlns='http://www.w3.org/2000/svg' width='520' height='520' viewBox='0 0 520 520'>",
        "<rect width='520' height='520' fill='white'/>",
        *before,
        *after,
    ]
    for points, colour in ((outline, "black"), (inner, "#2ca02c"), (outer, "#d62728")):
        for p in points:
            x, y = point(*p).split(",")
            parts.append(f"<circle cx='{x}' cy='{y}' r='2' fill='{colour}'/>")
    parts.append(
        "<text x='10' y='510' font-family='sans-serif' font-size='12'>grey: first guess; blue: "
        "fitted; black: outline samples; green: inside; red: outside</text>"
    )
    parts.append("</svg>")
    path.write_text("\n".join(parts) + "\n")


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out")
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 300
    out.mkdir(parents=True, exist_ok=True)
    outline, inner, outer = (torch.tensor(a, dtype=DTYPE) for a in samples())
    model = Model()
    before, _ = svg_shapes(model, "#999999", 0.35)
    optimizer = torch.optim.Adam(model.parameters(), lr=0.02)
    first = float(loss(model, outline, inner, outer))
    for _ in range(steps):
        optimizer.zero_grad()
        value = loss(model, outline, inner, outer)
        value.backward()
        optimizer.step()
    with torch.no_grad():
        final = float(loss(model, outline, inner, outer))
        worst = float(model.distance(outline).abs().max())
    write_svg(out / "fit.svg", before, model, outline.numpy(), inner.numpy(), outer.numpy())
    print(
        f"fit_bracket: loss {first:.3g} -> {final:.3g} in {steps} steps; outline points within "
        f"{worst:.3f} of the model (tolerance {TOLERANCE}); wrote {out / 'fit.svg'}"
    )
    return 0 if worst <= TOLERANCE else 1


if __name__ == "__main__":
    sys.exit(main())
