"""Seeded random shapes and poses for the Python tests, with each core's body-frame vertices
computed here from C and d (not by the library), so that the brute-force reference stays
independent of the code under test."""

import numpy as np

import diffpills


def random_capsule(rng, scale=1.0):
    length = rng.uniform(0.2, 2.0) * scale
    radius = rng.uniform(0.0, 0.3) * scale
    body = np.array([[-0.5 * length, 0.0, 0.0], [0.5 * length, 0.0, 0.0]])
    return diffpills.Capsule(length, radius), body


def polygon_vertices(C, d):
    """Vertices of {y : C y <= d} by brute force: every pair of rows' intersection point that
    satisfies all rows, ordered counterclockwise around their mean."""
    points = []
    for i in range(len(d)):
        for j in range(i + 1, len(d)):
            A = np.array([C[i], C[j]])
            if abs(np.linalg.det(A)) < 1e-12:
                continue
            y = np.linalg.solve(A, [d[i], d[j]])
            if np.all(C @ y <= d + 1e-9):
                points.append(y)
    size = max(np.linalg.norm(p) for p in points)
    unique = []
    for p in points:  # three rows through one vertex give it twice
        if all(np.linalg.norm(p - q) > 1e-9 * size for q in unique):
            unique.append(p)
    points = np.array(unique)
    centre = points.mean(axis=0)
    order = np.argsort(np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0]))
    return points[order]


def random_polygon(rng, scale=1.0):
    k = rng.integers(3, 8)
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, k))
    corners = np.stack([np.cos(angles), np.sin(angles)], axis=1) * rng.uniform(0.3, 1.0) * scale
    corners -= corners.mean(axis=0)  # the centroid of the corners is inside: the body origin
    C, d = [], []
    for i in range(k):
        edge = corners[(i + 1) % k] - corners[i]
        normal = np.array([edge[1], -edge[0]])
        normal /= np.linalg.norm(normal)
        C.append(normal)
        d.append(normal @ corners[i])
    C, d = np.array(C), np.array(d)
    radius = rng.uniform(0.0, 0.3) * scale
    vertices = polygon_vertices(C, d)  # two corners closer than 1e-9 x size count as one
    body = np.column_stack([vertices, np.zeros(len(vertices))])
    return diffpills.PaddedPolygon(C, d, radius), body


def random_shape(rng, scale=1.0):
    return random_capsule(rng, scale) if rng.random() < 0.5 else random_polygon(rng, scale)


def random_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q) * rng.uniform(0.5, 2.0)


def random_poses(rng, n, spread=1.5):
    """n positions (n, 3) and quaternions (n, 4) as NumPy arrays."""
    return rng.uniform(-spread, spread, (n, 3)), np.array([random_quaternion(rng) for _ in range(n)])


def random_pose(rng, spread=1.5):
    return diffpills.Pose(rng.uniform(-spread, spread, 3), random_quaternion(rng))


def rotation(q):
    w, x, y, z = np.asarray(q) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def to_world(body, pose):
    return pose.r + body @ rotation(pose.q).T
