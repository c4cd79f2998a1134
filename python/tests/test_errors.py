"""Bad input raises ValueError carrying the library's message, which names the field; wrong types
raise TypeError. Nothing crashes or returns NaN."""

import copy
import fractions
import pickle

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
        (lambda: diffpills.Pose(np.zeros((3, 1)), [1.0, 0.0, 0.0, 0.0]), "r"),
        (lambda: diffpills.Pose(np.array(1.0), [1.0, 0.0, 0.0, 0.0]), "r"),  # 0-d
        (lambda: diffpills.Pose([1.0, [2.0, 3.0]], [1.0, 0.0, 0.0, 0.0]), "r"),  # ragged
        (lambda: diffpills.Capsule([1.0], 0.1), "length"),
        (lambda: diffpills.Capsule(1.0, 10**400), "radius"),  # no float holds it
        (lambda: diffpills.PaddedPolygon(np.ones((4, 2, 1)), [1.0] * 4, 0.1), "C"),
        (lambda: diffpills.PaddedPolygon(SQUARE_C, [1.0] * 4, [0.1, 0.1]), "radius"),
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
    with pytest.raises(ValueError, match=r"r_a: expected shape \(N, 3\) or \(3,\), got \(5, 3, 1\)"):
        diffpills.proximity_batch(capsule, r[:, :, None], q, capsule, r, q)
    with pytest.raises(ValueError, match=r"^q_b: has 4 rows, r_a has 5$"):
        diffpills.proximity_batch(capsule, r, q, capsule, r, q[:4])
    inf_q = q.copy()
    inf_q[4, 2] = np.inf
    with pytest.raises(ValueError, match=r"q_a\[4\]"):
        diffpills.proximity_batch(capsule, r, inf_q, capsule, r, q)


def _pybind11_dump(error):
    return "Invoked with" in str(error) or "incompatible function arguments" in str(error)


@pytest.mark.parametrize(
    "threads, error",
    [(-1, ValueError), (2**40, ValueError), (-(2**70), ValueError), (None, TypeError), (2.0, TypeError),
     ("2", TypeError), (True, TypeError), (np.array([2]), TypeError)],
)
def test_bad_thread_counts_name_threads(threads, error):
    capsule = diffpills.Capsule(1.0, 0.1)
    r, q = np.zeros((5, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (5, 1))
    with pytest.raises(error, match="^threads: ") as raised:
        diffpills.proximity_batch(capsule, r, q, capsule, r, q, threads=threads)
    assert not _pybind11_dump(raised.value)


def test_any_int_thread_count_works():
    # Counts above the hardware's are capped, not refused: NumPy ints, 10**6 and the largest int.
    capsule = diffpills.Capsule(1.0, 0.1)
    r, q = np.zeros((5, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (5, 1))
    expected, _ = diffpills.proximity_batch(capsule, r, q, capsule, r + 0.5, q, threads=1)
    for threads in (np.int64(3), np.uint8(2), 10**6, 2**31 - 1):
        phi, _ = diffpills.proximity_batch(capsule, r, q, capsule, r + 0.5, q, threads=threads)
        np.testing.assert_array_equal(phi, expected)


@pytest.mark.parametrize(
    "method, error",
    [(None, TypeError), (b"default", TypeError), (1, TypeError), ("Default", ValueError), ("\ud800", ValueError)],
)
def test_bad_methods_name_method(method, error):
    capsule, pose = diffpills.Capsule(1.0, 0.1), diffpills.Pose()
    r, q = np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1))
    for call in (
        lambda: diffpills.proximity(capsule, pose, capsule, pose, method=method),
        lambda: diffpills.proximity_jacobian(capsule, pose, capsule, pose, method=method),
        lambda: diffpills.proximity_batch(capsule, r, q, capsule, r, q, method=method),
    ):
        with pytest.raises(error, match="^method: ") as raised:
            call()
        assert not _pybind11_dump(raised.value)


NOT_REAL = {
    "complex": np.array([1.0 + 2.0j, 0.0, 0.0, 0.0]),
    "complex, zero imaginary part": np.array([1.0, 0.0, 0.0, 0.0], dtype=complex),
    "bool": np.array([True, False, False, False]),
    "str": np.array(["1", "0", "0", "0"]),
    "bytes": np.array([b"1", b"0", b"0", b"0"]),
    "object holding None": np.array([1.0, None, 0.0, 0.0], dtype=object),  # NumPy reads None as NaN
    "object holding a complex": np.array([1.0, 2j, 0.0, 0.0], dtype=object),
}


@pytest.mark.parametrize("kind", NOT_REAL)
def test_arrays_of_non_real_numbers_are_refused_naming_the_argument(kind):
    # A cast to float64 would drop imaginary parts (silently, with only a warning) and turn None into
    # NaN or True into 1: every such array is refused, wherever it is passed.
    bad = NOT_REAL[kind]
    capsule = diffpills.Capsule(1.0, 0.1)
    square = diffpills.PaddedPolygon(SQUARE_C, [1.0] * 4, 0.1)
    r, q = np.zeros((4, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (4, 1))
    calls = {
        "r": lambda: diffpills.Pose(bad[:3], q[0]),
        "q": lambda: diffpills.Pose(r[0], bad),
        "C": lambda: diffpills.PaddedPolygon(np.stack([bad, bad], axis=1), [1.0] * 4, 0.1),
        "d": lambda: diffpills.PaddedPolygon(SQUARE_C, bad, 0.1),
        "length": lambda: diffpills.Capsule(bad[0], 0.1),
        "radius": lambda: diffpills.PaddedPolygon(SQUARE_C, [1.0] * 4, bad[0]),
        "r_a": lambda: diffpills.proximity_batch(capsule, np.tile(bad[:3], (4, 1)), q, square, r, q),
        "q_a": lambda: diffpills.proximity_batch(capsule, r, np.tile(bad, (4, 1)), square, r, q),
        "r_b": lambda: diffpills.proximity_batch(capsule, r, q, square, bad[:3], q),
        "q_b": lambda: diffpills.proximity_batch(capsule, r, q, square, r, bad),
    }
    for name, call in calls.items():
        if kind.startswith("object") and name in ("length", "radius"):
            continue  # bad[0] is the float 1.0 there
        with pytest.raises(TypeError, match=f"^{name}: expected real numbers") as raised:
            call()
        assert not _pybind11_dump(raised.value)


def test_bools_in_lists_and_masked_arrays_are_refused():
    # NumPy reads [True, 0, 0] as integers and a masked array as its data, hidden values included
    # (a hostile review); both are refused with TypeError naming the argument.
    q, r = [1.0, 0.0, 0.0, 0.0], np.zeros((2, 3))
    capsule = diffpills.Capsule(1.0, 0.1)
    masked = np.ma.masked_array([0.0, 5.0, 0.0], mask=[0, 1, 0])
    calls = {
        "r": [lambda: diffpills.Pose([True, 0, 0], q), lambda: diffpills.Pose((0, 0, False), q),
              lambda: diffpills.Pose(masked, q)],
        "q": [lambda: diffpills.Pose([0, 0, 0], [True, 0, 0, 0])],
        "d": [lambda: diffpills.PaddedPolygon(SQUARE_C, [1, 1, True, 1], 0.1)],
        "C": [lambda: diffpills.PaddedPolygon([[1, 0], [0, 1], [-1, 0], [0, True]], [1] * 4, 0.1)],
        "r_a": [lambda: diffpills.proximity_batch(capsule, [[0, 0, 0], [0, True, 0]],
                                                  np.tile(q, (2, 1)), capsule, r, q)],
    }
    for name, bad_calls in calls.items():
        for call in bad_calls:
            with pytest.raises(TypeError, match=f"^{name}: ") as raised:
                call()
            assert not _pybind11_dump(raised.value)
    # Lists and tuples of ints, floats and big ints are still numbers.
    assert list(diffpills.Pose((1, 2.5, 10**30), [1, 0, 0, 0]).r) == [1.0, 2.5, 1e30]


@pytest.mark.parametrize(
    "value", [1j, np.complex128(1.0), True, np.bool_(True), "1", None, diffpills.Pose()]
)
def test_scalars_that_are_not_real_numbers_are_refused(value):
    with pytest.raises(TypeError, match="^length: expected real numbers"):
        diffpills.Capsule(value, 0.1)
    with pytest.raises(TypeError, match="^r: expected real numbers"):
        diffpills.Pose(value, [1.0, 0.0, 0.0, 0.0])


def test_real_numbers_of_any_type_and_layout_are_read_exactly():
    # float16/float32 widen exactly, ints and NumPy's object arrays of Python numbers (ints beyond 64
    # bits, Fractions) convert like float(); views of any strides are copied, never misread.
    capsule = diffpills.Capsule(1.0, 0.1)
    square = diffpills.PaddedPolygon(SQUARE_C, [1.0] * 4, 0.1)
    q = np.array([2.0, 1.0, 0.0, 1.0])
    for r in (np.array([1, -2, 3], dtype=np.int8), np.array([1, 2**64, 3], dtype=object),
              [fractions.Fraction(1, 3), 2, np.float16(0.5)], np.arange(7.0)[5::-2],
              np.float32([0.1, 0.2, 0.3])):
        expected = np.array([float(x) for x in r])
        np.testing.assert_array_equal(diffpills.Pose(r, q).r, expected)
    assert diffpills.Capsule(np.float16(0.5), 2**70).radius == 2.0**70
    assert diffpills.Capsule(np.array(0.5), fractions.Fraction(1, 4)).radius == 0.25

    rng = np.random.default_rng(3)
    r_a, q_a = rng.uniform(-1, 1, (6, 3)), rng.normal(size=(6, 4))
    inputs = {
        "Fortran order": (np.asfortranarray(r_a), np.asfortranarray(q_a)),
        "every other column": (np.repeat(r_a, 2, axis=1)[:, ::2], np.repeat(q_a, 2, axis=1)[:, ::2]),
        "negative strides": (r_a[::-1].copy()[::-1], q_a[::-1].copy()[::-1]),
        "float32, float16": (r_a.astype(np.float32), q_a.astype(np.float16)),
        "int32, uint8": (rng.integers(-3, 4, (6, 3)).astype(np.int32), rng.integers(1, 4, (6, 4)).astype(np.uint8)),
    }
    for name, (r_in, q_in) in inputs.items():
        as_float64 = [np.ascontiguousarray(x, dtype=np.float64) for x in (r_in, q_in)]
        phi, gradient = diffpills.proximity_batch(capsule, r_in, q_in, square, [0, 0, 0], [1, 0, 0, 0])
        expected = diffpills.proximity_batch(capsule, *as_float64, square, [0, 0, 0], [1, 0, 0, 0])
        np.testing.assert_array_equal(phi, expected[0], err_msg=name)
        np.testing.assert_array_equal(gradient, expected[1], err_msg=name)


def test_polygon_offsets_are_reported_at_full_precision():
    with pytest.raises(ValueError, match=r"polygon\.d\[3\].*-1e-10") as raised:
        diffpills.PaddedPolygon(SQUARE_C, [1.0, 1.0, 1.0, -1e-10], 0.1)
    assert "-0.000000" not in str(raised.value)


def test_wrong_types_raise_type_error():
    capsule = diffpills.Capsule(1.0, 0.1)
    with pytest.raises(TypeError, match="a: expected"):
        diffpills.proximity("capsule", diffpills.Pose(), capsule, diffpills.Pose())
    with pytest.raises(TypeError, match="pose_b"):
        diffpills.proximity(capsule, diffpills.Pose(), capsule, [0.0, 0.0, 0.0])


def _uninitialised():
    """One object of each class made by __new__ alone (as pickle does before __setstate__), and of a
    Python subclass."""

    class Subclass(diffpills.Capsule):
        pass

    classes = [diffpills.Capsule, diffpills.PaddedPolygon, diffpills.Pose, diffpills.Proximity,
               diffpills.ProximityJacobian, diffpills.ProximityWithHessian, Subclass]
    return {cls.__name__: cls.__new__(cls) for cls in classes}


def test_objects_made_by_new_without_init_are_refused():
    # They once handed uninitialised memory to C++: garbage phi or a segmentation fault.
    capsule, pose = diffpills.Capsule(1.0, 0.1), diffpills.Pose()
    r, q = np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1))
    for kind, empty in _uninitialised().items():
        uses = [lambda: repr(empty), lambda: pickle.dumps(empty), lambda: copy.copy(empty),
                lambda: copy.deepcopy(empty)]
        uses += [lambda name=name: getattr(empty, name) for name in dir(type(empty))
                 if isinstance(getattr(type(empty), name), property)]
        if isinstance(empty, diffpills.Pose):
            for query in (diffpills.proximity, diffpills.proximity_jacobian):
                uses.append(lambda query=query: query(capsule, empty, capsule, pose))
                uses.append(lambda query=query: query(capsule, pose, capsule, empty))
        if isinstance(empty, (diffpills.Capsule, diffpills.PaddedPolygon)):
            for query in (diffpills.proximity, diffpills.proximity_jacobian):
                uses.append(lambda query=query: query(empty, pose, capsule, pose))
                uses.append(lambda query=query: query(capsule, pose, empty, pose))
            uses.append(lambda: diffpills.proximity_batch(empty, r, q, capsule, r, q))
            uses.append(lambda: diffpills.proximity_batch(capsule, r, q, empty, r, q))
        assert len(uses) > 4, kind
        for use in uses:
            with pytest.raises(TypeError, match="__new__ without __init__"):
                use()
    with pytest.raises(TypeError, match="^pose_b: this diffpills.Pose was made by __new__"):
        diffpills.proximity(capsule, pose, capsule, diffpills.Pose.__new__(diffpills.Pose))
    with pytest.raises(TypeError, match="^b: this diffpills.PaddedPolygon was made by __new__"):
        diffpills.proximity_batch(capsule, r, q, diffpills.PaddedPolygon.__new__(diffpills.PaddedPolygon), r, q)


def _new(cls):
    return cls.__new__(cls)


class _Garbage:
    """Pickles as a diffpills object with the given state: pickle.loads makes it by __new__ alone,
    then calls its __setstate__(state), as for a genuine pickle."""

    def __init__(self, cls, state):
        self.cls, self.state = cls, state

    def __reduce__(self):
        return _new, (self.cls,), self.state


def _proximity_state(**change):
    fields = dict(phi=1.0, core_points=np.zeros((2, 3)), points=np.zeros((2, 3)), normal=np.array([0.0, 0.0, 1.0]),
                  cores_intersect=False, gradient=np.zeros(14))
    fields.update(change)
    return tuple(fields.values())


@pytest.mark.parametrize(
    "cls, state, error, match",
    [
        (diffpills.Capsule, "garbage", TypeError, "expected a tuple"),
        (diffpills.Capsule, [1.0, 0.1], TypeError, "expected a tuple"),
        (diffpills.Capsule, (1.0,), ValueError, "expected a tuple"),
        (diffpills.Capsule, ("1", 0.1), TypeError, "^length"),
        (diffpills.Capsule, (1.0, -0.1), ValueError, "capsule.radius"),
        (diffpills.Capsule, (1.0, 0.1 + 1j), TypeError, "^radius"),
        (diffpills.PaddedPolygon, (SQUARE_C, [1.0] * 4), ValueError, "expected a tuple"),
        (diffpills.PaddedPolygon, (SQUARE_C.astype(complex), [1.0] * 4, 0.1), TypeError, "^C"),
        (diffpills.PaddedPolygon, (SQUARE_C, [1.0, 1.0, 1.0, 0.0], 0.1), ValueError, r"polygon\.d"),
        (diffpills.Pose, ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 1j]), TypeError, "^q"),
        (diffpills.Pose, ([0.0, 0.0, np.nan], [1.0, 0.0, 0.0, 0.0]), ValueError, r"pose\.r"),
        (diffpills.Pose, ({}, [1.0, 0.0, 0.0, 0.0]), TypeError, "^r"),
        (diffpills.Proximity, _proximity_state(cores_intersect="yes"), TypeError, "^cores_intersect"),
        (diffpills.Proximity, _proximity_state(gradient=np.zeros(13)), ValueError, "^gradient"),
        (diffpills.Proximity, _proximity_state(points=np.zeros((3, 2))), ValueError, "^points"),
        (diffpills.Proximity, _proximity_state(phi=1j), TypeError, "^phi"),
        (diffpills.ProximityJacobian, (_proximity_state(), np.zeros((6, 14))), ValueError, "expected a tuple"),
        (diffpills.ProximityJacobian, (_proximity_state(), np.zeros((6, 14)), np.zeros((14, 6))), ValueError,
         "^points_jacobian"),
        (diffpills.ProximityJacobian, ("x", np.zeros((6, 14)), np.zeros((6, 14))), TypeError, "expected a tuple"),
    ],
)
def test_unpickling_garbage_raises_naming_the_field(cls, state, error, match):
    data = pickle.dumps(_Garbage(cls, state))
    with pytest.raises(error, match=match):
        pickle.loads(data)


def test_extreme_but_valid_input_gives_finite_results():
    capsule = diffpills.Capsule(1e-9, 1e-9)
    polygon = diffpills.PaddedPolygon(SQUARE_C * 1e6, [1e6] * 4, 0.0)
    for r in ([1e8, 0.0, 0.0], [0.0, 0.0, 1e-12], [0.0, 0.0, 0.0]):
        result = diffpills.proximity(capsule, diffpills.Pose(r, [1e-40, 0.0, 1e-40, 0.0]), polygon, diffpills.Pose())
        assert np.isfinite(result.phi) and np.all(np.isfinite(result.gradient))
    # Below a norm of 1e-40 the gradient's 1 / |q| could overflow: refused.
    with pytest.raises(ValueError, match="pose.q"):
        diffpills.Pose([0.0, 0.0, 0.0], [1e-100, 0.0, 1e-100, 0.0])
