"""Bad input raises ValueError carrying the library's message, which names the field; wrong types
raise TypeError. Nothing crashes or returns NaN."""

import numpy as np
import pytest

import diffpills

SQUARE_C = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: diffpills.Capsule(-1.0, 0.1), "capsule.length"),
        (lambda: diffpills.Capsule(1.0, float("nan")), "capsule.radius"),
        (lambda: diffpills.Capsule(float("inf"), 0.1), "capsule.length"),
        (lambda: diffpills.PaddedPolygon(SQUARE_C, [1.0, 1.0, 1.0, 1.0], -0.5), "polygon.radius"),
        (lambda: diffpills.PaddedPolygon(SQUARE_C, [1.0, 1.0, 1.0, -1.0], 0.1), "polygon.d"),
        (lambda: diffpills.PaddedPolygon(SQUARE_C[:3], [1.0, 1.0, 1.0], 0.1), "polygon"),  # unbounded
        (lambda: diffpills.PaddedPolygon(SQUARE_C, [1.0, 1.0, 1.0], 0.1), "polygon"),  # sizes differ
        (lambda: diffpills.PaddedPolygon(np.ones((4, 3)), [1.0] * 4, 0.1), "C"),
        (lambda: diffpills.Pose([0.0, np.nan, 0.0], [1.0, 0.0, 0.0, 0.0]), "pose.r"),
        (lambda: diffpills.Pose([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]), "pose.q"),
        (lambda: diffpills.Pose([0.0, 0.0, 0.0], [1.0, np.inf, 0.0, 0.0]), "pose.q"),
        (lambda: diffpills.Pose([0.0, 0.0], [1.0, 0.0, 0.0, 0.0]), "r"),
        (lambda: diffpills.Pose("abc", [1.0, 0.0, 0.0, 0.0]), "r"),
    ],
)
def test_bad_values_raise_value_error_naming_the_field(make, field):
    with pytest.raises(ValueError, match=field):
        make()


def test_bad_batches_name_the_argument_and_row():
    capsule = diffpills.Capsule(1.0, 0.1)
    r, q = np.zeros((5, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (5, 1))
    bad_q = q.copy()
    bad_q[3] = 0.0
    with pytest.raises(ValueError, match=r"q_b\[3\]"):
        diffpills.proximity_batch(capsule, r, q, capsule, r, bad_q)
    bad_r = r.copy()
    bad_r[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"r_a\[2\]"):
        diffpills.proximity_batch(capsule, bad_r, q, capsule, r, q)
    with pytest.raises(ValueError, match="q_a"):
        diffpills.proximity_batch(capsule, r, q[:4], capsule, r, q)
    with pytest.raises(ValueError, match="r_b"):
        diffpills.proximity_batch(capsule, r, q, capsule, np.zeros((5, 2)), q)
    with pytest.raises(ValueError, match="threads"):
        diffpills.proximity_batch(capsule, r, q, capsule, r, q, threads=-1)
    with pytest.raises(ValueError, match="method"):
        diffpills.proximity_batch(capsule, r, q, capsule, r, q, method="gjk")


def test_wrong_types_raise_type_error():
    capsule = diffpills.Capsule(1.0, 0.1)
    with pytest.raises(TypeError, match="a: expected"):
        diffpills.proximity("capsule", diffpills.Pose(), capsule, diffpills.Pose())
    with pytest.raises(TypeError, match="pose_b"):
        diffpills.proximity(capsule, diffpills.Pose(), capsule, [0.0, 0.0, 0.0])


def test_extreme_but_valid_input_gives_finite_results():
    capsule = diffpills.Capsule(1e-9, 1e-9)
    polygon = diffpills.PaddedPolygon(SQUARE_C * 1e6, [1e6] * 4, 0.0)
    for r in ([1e8, 0.0, 0.0], [0.0, 0.0, 1e-12], [0.0, 0.0, 0.0]):
        result = diffpills.proximity(capsule, diffpills.Pose(r, [1e-100, 0.0, 1e-100, 0.0]), polygon, diffpills.Pose())
        assert np.isfinite(result.phi) and np.all(np.isfinite(result.gradient))
