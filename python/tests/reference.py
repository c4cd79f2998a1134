"""Brute-force distance between two cores given as world vertices: one point, a segment (two) or
a convex planar polygon (three or more, in order). It enumerates feature pairs (vertex-core,
edge-edge interiors, an edge crossing a face), enough for convex polytopes: some closest pair
always lies on such features. Written for the tests, apart from the library."""

import itertools

import numpy as np


def _point_segment(p, a, b):
    ab = b - a
    t = 0.0 if ab @ ab == 0 else np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t * ab)), a + t * ab


def _inside_polygon(p, vertices, normal):
    n = len(vertices)
    signs = [np.cross(vertices[(i + 1) % n] - vertices[i], p - vertices[i]) @ normal for i in range(n)]
    return all(s >= -1e-12 for s in signs) or all(s <= 1e-12 for s in signs)


def _edges(vertices):
    if len(vertices) == 1:
        return []
    if len(vertices) == 2:
        return [(vertices[0], vertices[1])]
    return [(vertices[i], vertices[(i + 1) % len(vertices)]) for i in range(len(vertices))]


def _normal(vertices):
    n = np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0])
    return n / np.linalg.norm(n)


def point_to_core(p, vertices):
    """Distance and closest point from point p to the core."""
    if len(vertices) == 1:
        return np.linalg.norm(p - vertices[0]), vertices[0]
    best = min((_point_segment(p, a, b) for a, b in _edges(vertices)), key=lambda t: t[0])
    if len(vertices) >= 3:
        n = _normal(vertices)
        foot = p - ((p - vertices[0]) @ n) * n
        if _inside_polygon(foot, vertices, n):
            best = min(best, (np.linalg.norm(p - foot), foot), key=lambda t: t[0])
    return best


def core_distance(A, B):
    """Smallest distance between cores A and B (lists of world vertices)."""
    A, B = [np.asarray(v, float) for v in A], [np.asarray(v, float) for v in B]
    best = min(point_to_core(p, B)[0] for p in A)
    best = min(best, min(point_to_core(p, A)[0] for p in B))
    for (a0, a1), (b0, b1) in itertools.product(_edges(A), _edges(B)):
        u, v, w = a1 - a0, b1 - b0, a0 - b0
        M = np.array([[u @ u, -(u @ v)], [-(u @ v), v @ v]])
        if abs(np.linalg.det(M)) > 1e-14 * (u @ u) * (v @ v):
            s, t = np.linalg.solve(M, [-(u @ w), v @ w])
            if 0 <= s <= 1 and 0 <= t <= 1:
                best = min(best, np.linalg.norm(a0 + s * u - b0 - t * v))
    for X, Y in ((A, B), (B, A)):
        if len(Y) < 3:
            continue
        n = _normal(Y)
        for a0, a1 in _edges(X):
            h0, h1 = (a0 - Y[0]) @ n, (a1 - Y[0]) @ n
            if h0 * h1 < 0:
                crossing = a0 + h0 / (h0 - h1) * (a1 - a0)
                if _inside_polygon(crossing, Y, n):
                    best = 0.0
    return best
