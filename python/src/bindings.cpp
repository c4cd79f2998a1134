// The Python module diffpills._core: the shapes, poses and queries of the C++ library, NumPy arrays
// in and out. Inputs are checked here for their types (TypeError naming the argument) and shapes
// (ValueError naming the argument), and by the library for their values (std::invalid_argument,
// which pybind11 turns into ValueError with the library's message). The package diffpills
// (python/diffpills/__init__.py) re-exports everything.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "diffpills/diffpills.hpp"

namespace py = pybind11;

namespace diffpills::python {

// False for an object made by T.__new__ without __init__ (or __setstate__): pybind11 2.10 then
// hands out freshly allocated, uninitialised memory as the C++ value (type_caster_generic::
// load_value), so reading it returns garbage or crashes. The test is pybind11's own for a Python
// subclass that forgets to call __init__ (pybind11_meta_call). object must be a bound class's
// instance.
inline bool constructed(const py::handle& object) {
  for (const auto& value_and_holder :
       py::detail::values_and_holders(reinterpret_cast<py::detail::instance*>(object.ptr()))) {
    if (!value_and_holder.holder_constructed()) return false;
  }
  return true;
}

inline std::string not_constructed(const py::handle& object) {
  const std::string type = py::str(py::type::of(object).attr("__name__"));
  return "this diffpills." + type + " was made by __new__ without __init__ and holds no value; " +
         (py::isinstance<Proximity>(object)
              ? "results come from diffpills.proximity, proximity_jacobian, proximity_hessian, "
                "proximity_with_hessian and proximity_shape_gradient"
          : py::isinstance<SignedDistance>(object)
              ? "results come from diffpills.signed_distance, signed_distance_jacobian, "
                "signed_distance_hessian and signed_distance_shape_gradient"
              : "create it as diffpills." + type + "(...)");
}

// The caster of every bound class: pybind11's, refusing unconstructed objects with TypeError
// wherever one is passed (as self of a method or property, __repr__, pickling, or an argument).
template <class T>
class ConstructedCaster : public py::detail::type_caster_base<T> {
 public:
  bool load(py::handle source, bool convert) {
    if (py::isinstance<T>(source) && !constructed(source)) {
      throw py::type_error(not_constructed(source));
    }
    return py::detail::type_caster_base<T>::load(source, convert);
  }
};

}  // namespace diffpills::python

namespace pybind11::detail {
template <>
class type_caster<diffpills::Capsule>
    : public diffpills::python::ConstructedCaster<diffpills::Capsule> {};
template <>
class type_caster<diffpills::PaddedPolygon>
    : public diffpills::python::ConstructedCaster<diffpills::PaddedPolygon> {};
template <>
class type_caster<diffpills::Pose> : public diffpills::python::ConstructedCaster<diffpills::Pose> {
};
template <>
class type_caster<diffpills::Proximity>
    : public diffpills::python::ConstructedCaster<diffpills::Proximity> {};
template <>
class type_caster<diffpills::ProximityJacobian>
    : public diffpills::python::ConstructedCaster<diffpills::ProximityJacobian> {};
template <>
class type_caster<diffpills::SignedDistance>
    : public diffpills::python::ConstructedCaster<diffpills::SignedDistance> {};
template <>
class type_caster<diffpills::SignedDistanceJacobian>
    : public diffpills::python::ConstructedCaster<diffpills::SignedDistanceJacobian> {};
template <>
class type_caster<diffpills::ProximityHessian>
    : public diffpills::python::ConstructedCaster<diffpills::ProximityHessian> {};
template <>
class type_caster<diffpills::ProximityWithHessian>
    : public diffpills::python::ConstructedCaster<diffpills::ProximityWithHessian> {};
template <>
class type_caster<diffpills::SignedDistanceHessian>
    : public diffpills::python::ConstructedCaster<diffpills::SignedDistanceHessian> {};
template <>
class type_caster<diffpills::ProximityShapeGradient>
    : public diffpills::python::ConstructedCaster<diffpills::ProximityShapeGradient> {};
template <>
class type_caster<diffpills::SignedDistanceShapeGradient>
    : public diffpills::python::ConstructedCaster<diffpills::SignedDistanceShapeGradient> {};
template <>
class type_caster<diffpills::Body> : public diffpills::python::ConstructedCaster<diffpills::Body> {
};
template <>
class type_caster<diffpills::Scene>
    : public diffpills::python::ConstructedCaster<diffpills::Scene> {};
}  // namespace pybind11::detail

namespace diffpills::python {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string type_name(const py::handle& value) {
  return py::str(py::type::of(value).attr("__name__"));
}

// numpy.asarray(value, dtype) (dtype null: NumPy's choice), with flags; an object NumPy cannot
// read raises TypeError or ValueError naming the argument, with NumPy's (or the object's) reason.
// MemoryError (a huge copy) and exceptions that are not errors (KeyboardInterrupt) pass as they
// are.
py::array numpy_array(const py::handle& value, py::dtype dtype, int flags,
                      const std::string& name) {
  PyObject* array = py::detail::npy_api::get().PyArray_FromAny_(
      value.ptr(), dtype ? dtype.release().ptr() : nullptr, 0, 0,
      flags | py::detail::npy_api::NPY_ARRAY_ENSUREARRAY_, nullptr);
  if (array != nullptr) return py::reinterpret_steal<py::array>(array);
  py::error_already_set error;
  if (error.matches(PyExc_MemoryError) || !error.matches(PyExc_Exception)) throw error;
  // A torch tensor that requires grad refuses to become an array (torch's RuntimeError names no
  // argument). Detaching it here would silently cut it from its graph: the caller should decide.
  if (py::hasattr(value, "requires_grad") && py::hasattr(value, "detach") &&
      value.attr("requires_grad").ptr() == Py_True) {
    throw py::type_error(name + ": a tensor that requires grad; pass " + name +
                         ".detach() (diffpills.Pose and proximity_batch take plain numbers, "
                         "outside autograd; diffpills.torch.proximity differentiates with respect "
                         "to poses)");
  }
  const std::string message =
      name + ": expected numbers (" + std::string(py::str(error.value())) + ")";
  if (error.matches(PyExc_ValueError) || error.matches(PyExc_ArithmeticError)) {
    throw py::value_error(message);
  }
  throw py::type_error(message);
}

// The first entry of an object array that is not a real number (numbers.Real, not a bool), or
// null if all are: ints beyond 64 bits, Fractions and mixes of them with floats, which NumPy keeps
// as objects, are numbers; None (which NumPy would read as NaN), str or complex are not.
py::object first_non_real(const py::array& objects) {
  const py::object real = py::module_::import("numbers").attr("Real");
  for (const py::handle entry : objects.attr("flat")) {
    if (!py::isinstance(entry, real) || py::isinstance<py::bool_>(entry)) {
      return py::reinterpret_borrow<py::object>(entry);
    }
  }
  return {};
}

// Any array-like of real numbers as a C-contiguous float64 array (the data itself if it is one
// already, else a copy, so any strides are fine), or TypeError naming the argument. Floats of any
// width, integers and object arrays of real numbers are values; complex numbers (whose imaginary
// part a cast would drop), bools and strings are refused rather than guessed at.
Array as_array(const py::handle& value, const std::string& name) {
  // A subclass of ndarray is read as its data, which for a masked array would include the values
  // its mask hides: refused (a hostile review).
  const auto* ndarray = reinterpret_cast<PyTypeObject*>(py::detail::npy_api::get().PyArray_Type_);
  if (Py_TYPE(value.ptr()) != ndarray && py::isinstance<py::array>(value) &&
      py::hasattr(value, "mask")) {
    throw py::type_error(name + ": a masked array; pass " + name +
                         ".filled(...) or its unmasked values");
  }
  // The common case first, at no cost: float64 C-contiguous, used as it is.
  if (Array::check_(value)) return py::reinterpret_borrow<Array>(value);
  // A list or tuple is read as objects first: NumPy would turn [True, 0, 0] into integers and a
  // bool in it would pass for a number (a hostile review).
  const bool sequence = PyList_Check(value.ptr()) || PyTuple_Check(value.ptr());
  const py::array any = py::isinstance<py::array>(value)
                            ? py::reinterpret_borrow<py::array>(value)
                            : numpy_array(value, sequence ? py::dtype("O") : py::dtype(), 0, name);
  const char kind = any.dtype().kind();
  if (kind == 'O') {
    if (const py::object entry = first_non_real(any)) {
      if (sequence && py::isinstance<py::sequence>(entry) && !py::isinstance<py::str>(entry)) {
        throw py::value_error(name +
                              ": expected a rectangular array, got nested sequences of "
                              "different lengths");
      }
      throw py::type_error(name + ": expected real numbers, got " +
                           (any.ndim() == 0 ? "" : "an array holding ") + type_name(entry));
    }
  } else if (kind != 'f' && kind != 'i' && kind != 'u') {
    const bool text = kind == 'U' || kind == 'S';
    throw py::type_error(
        name + ": expected real numbers, got " +
        (any.ndim() == 0
             ? type_name(value)
             : "an array of " + (text ? "strings" : std::string(py::str(any.dtype())))));
  }
  if (Array::check_(any)) return py::reinterpret_borrow<Array>(any);
  return py::reinterpret_borrow<Array>(numpy_array(
      any, py::dtype::of<double>(),
      py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_FORCECAST_,
      name));
}

std::string shape_of(const Array& array) {
  std::ostringstream out;
  out << "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) out << (i ? ", " : "") << array.shape(i);
  out << (array.ndim() == 1 ? ",)" : ")");
  return out.str();
}

template <int N>
Eigen::Matrix<double, N, 1> fixed_vector(const py::handle& value, const std::string& name) {
  const Array array = as_array(value, name);
  if (array.ndim() != 1 || array.shape(0) != N) {
    throw py::value_error(name + ": expected shape (" + std::to_string(N) + ",), got " +
                          shape_of(array));
  }
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(array.data());
}

// A number given as a Python or NumPy scalar (or a 0-d array), read like the arrays: a complex,
// bool or str is refused with TypeError naming the argument.
double real_number(const py::handle& value, const std::string& name) {
  // Python floats (NumPy's float64 is one) and ints skip NumPy, five times faster.
  if (PyFloat_Check(value.ptr())) return PyFloat_AS_DOUBLE(value.ptr());
  if (PyLong_CheckExact(value.ptr())) {
    const double number = PyLong_AsDouble(value.ptr());
    if (number != -1.0 || !PyErr_Occurred()) return number;
    PyErr_Clear();  // beyond a double's range: refused below, naming the argument
  }
  const Array array = as_array(value, name);
  if (array.ndim() != 0) {
    throw py::value_error(name + ": expected a number, got shape " + shape_of(array));
  }
  return *array.data();
}

template <int R, int C>
Eigen::Matrix<double, R, C> fixed_matrix(const py::handle& value, const std::string& name) {
  const Array array = as_array(value, name);
  if (array.ndim() != 2 || array.shape(0) != R || array.shape(1) != C) {
    throw py::value_error(name + ": expected shape (" + std::to_string(R) + ", " +
                          std::to_string(C) + "), got " + shape_of(array));
  }
  return Eigen::Map<const Eigen::Matrix<double, R, C, Eigen::RowMajor>>(array.data());
}

Method to_method(const py::handle& value) {
  const std::string expected = "method: expected \"default\" or \"interior_point\", got ";
  if (!py::isinstance<py::str>(value)) throw py::type_error(expected + type_name(value));
  // Compared as Python strings: a str with a lone surrogate has no UTF-8 std::string.
  if (PyUnicode_CompareWithASCIIString(value.ptr(), "default") == 0) return Method::kDefault;
  if (PyUnicode_CompareWithASCIIString(value.ptr(), "interior_point") == 0) {
    return Method::kInteriorPoint;
  }
  throw py::value_error(expected + std::string(py::repr(value)));
}

// threads as an int of BatchOptions: a Python or NumPy integer from 0 to INT_MAX (counts above
// the hardware threads are capped by the library). A bool or a float is a mistake, not a count.
int thread_count(const py::handle& value) {
  if (py::isinstance<py::bool_>(value) || !PyIndex_Check(value.ptr())) {
    throw py::type_error("threads: expected an int, got " + type_name(value));
  }
  const auto number = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!number) {  // e.g. a NumPy array of one element, whose __index__ refuses
    PyErr_Clear();
    throw py::type_error("threads: expected an int, got " + type_name(value));
  }
  int overflow = 0;
  const long long count = PyLong_AsLongLongAndOverflow(number.ptr(), &overflow);
  if (overflow != 0 || count < 0 || count > INT_MAX) {
    throw py::value_error("threads: must be from 0 (every hardware thread) to " +
                          std::to_string(INT_MAX) + ", got " + std::string(py::str(number)));
  }
  return static_cast<int>(count);
}

// The C++ value of an argument of a bound class, or TypeError naming the argument if it was
// never constructed.
template <class T>
const T& value_of(const py::handle& object, const std::string& name) {
  if (!constructed(object)) throw py::type_error(name + ": " + not_constructed(object));
  // pybind11's own caster: ConstructedCaster would repeat the checks, a third of a call's time.
  py::detail::type_caster_base<T> caster;
  if (!caster.load(object, /*convert=*/false)) {
    throw py::type_error(name + ": expected " + py::type_id<T>());
  }
  return *static_cast<const T*>(caster.value);
}

// Calls f with the shape behind a Python object (a Capsule or a PaddedPolygon, by reference).
template <class F>
decltype(auto) with_shape(const py::handle& object, const std::string& name, F&& f) {
  if (py::isinstance<Capsule>(object)) return f(value_of<Capsule>(object, name));
  if (py::isinstance<PaddedPolygon>(object)) return f(value_of<PaddedPolygon>(object, name));
  throw py::type_error(name + ": expected diffpills.Capsule or diffpills.PaddedPolygon, got " +
                       type_name(object));
}

Shape to_shape(const py::handle& object, const std::string& name) {
  return with_shape(object, name, [](const auto& shape) { return Shape(shape); });
}

const Pose& to_pose(const py::handle& object, const std::string& name) {
  if (!py::isinstance<Pose>(object)) {
    throw py::type_error(name + ": expected diffpills.Pose, got " + type_name(object));
  }
  return value_of<Pose>(object, name);
}

// The state a __getstate__ below made: a tuple of `size` entries, or an error naming the fields.
py::tuple pickled_state(const py::handle& state, std::size_t size, const std::string& fields) {
  if (!py::isinstance<py::tuple>(state)) {
    throw py::type_error("__setstate__: expected a tuple " + fields + ", got " + type_name(state));
  }
  if (py::len(state) != size) {
    throw py::value_error("__setstate__: expected a tuple " + fields + ", got " +
                          std::to_string(py::len(state)) + " entries");
  }
  return py::reinterpret_borrow<py::tuple>(state);
}

py::array_t<double> points_array(const std::array<Eigen::Vector3d, 2>& points) {
  py::array_t<double> out({2, 3});
  auto view = out.mutable_unchecked<2>();
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) view(i, j) = points[i](j);
  }
  return out;
}

std::array<Eigen::Vector3d, 2> points_from(const py::handle& value, const std::string& name) {
  const Eigen::Matrix<double, 2, 3> points = fixed_matrix<2, 3>(value, name);
  return {points.row(0).transpose(), points.row(1).transpose()};
}

template <int Width>
using Rows = Eigen::Matrix<double, Eigen::Dynamic, Width, Eigen::RowMajor>;

// One of a batch's pose arrays: (N, Width), or a single pose ((Width,) or one row) repeated over
// the other arrays' N rows. A float64 C-contiguous NumPy array is used in place, without a copy
// (copying 10^5 poses per call measurably slowed the batch).
template <int Width>
class BatchInput {
 public:
  BatchInput(const py::handle& value, const std::string& name)
      : array_(as_array(value, name)), name_(name) {
    const bool one = array_.ndim() == 1 && array_.shape(0) == Width;
    if (!one && (array_.ndim() != 2 || array_.shape(1) != Width)) {
      throw py::value_error(name + ": expected shape (N, " + std::to_string(Width) + ") or (" +
                            std::to_string(Width) + ",), got " + shape_of(array_));
    }
    rows_ = one ? 1 : array_.shape(0);
  }

  Eigen::Index rows() const { return rows_; }
  const std::string& name() const { return name_; }
  const Array& array() const { return array_; }

  // The N x Width rows: the NumPy data itself, or the single pose repeated N times.
  Eigen::Map<const Rows<Width>> view(Eigen::Index n) {
    if (rows_ == n) return {array_.data(), n, Width};
    repeated_ = Eigen::Map<const Rows<Width>>(array_.data(), 1, Width).replicate(n, 1);
    return {repeated_.data(), n, Width};
  }

 private:
  Array array_;
  std::string name_;
  Eigen::Index rows_ = 0;
  Rows<Width> repeated_;
};

PaddedPolygon polygon_from(const py::handle& C, const py::handle& d, const py::handle& radius) {
  const Array c_array = as_array(C, "C");
  if (c_array.ndim() != 2 || c_array.shape(1) != 2) {
    throw py::value_error("C: expected shape (m, 2), got " + shape_of(c_array));
  }
  const Array d_array = as_array(d, "d");
  if (d_array.ndim() != 1) {
    throw py::value_error("d: expected shape (m,), got " + shape_of(d_array));
  }
  const Eigen::MatrixX2d c_matrix =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(
          c_array.data(), c_array.shape(0), 2);
  const Eigen::VectorXd d_vector =
      Eigen::Map<const Eigen::VectorXd>(d_array.data(), d_array.shape(0));
  return PaddedPolygon(c_matrix, d_vector, real_number(radius, "radius"));
}

void bind_shapes(py::module_& m) {
  py::class_<Capsule>(m, "Capsule",
                      R"(A capsule: a segment of the given length along the body x axis,
from [-length/2, 0, 0] to [length/2, 0, 0], padded by radius. length 0 is a sphere.

Raises ValueError for negative or non-finite sizes, TypeError for a size that is not a real
number.)")
      .def(py::init([](const py::handle& length, const py::handle& radius) {
             return Capsule(real_number(length, "length"), real_number(radius, "radius"));
           }),
           py::arg("length"), py::arg("radius"))
      .def_property_readonly("length", &Capsule::length, "Length of the core segment.")
      .def_property_readonly("radius", &Capsule::radius, "Padding radius.")
      .def("__repr__",
           [](const Capsule& c) {
             std::ostringstream out;
             out << "diffpills.Capsule(length=" << c.length() << ", radius=" << c.radius() << ")";
             return out.str();
           })
      // Pickles: the getters return py::object, the type the setters take (pybind11 wants them
      // alike), so that a setter can refuse a state that is not a tuple with its own message.
      .def(py::pickle(
          [](const Capsule& c) -> py::object { return py::make_tuple(c.length(), c.radius()); },
          [](const py::object& state) {
            const py::tuple fields = pickled_state(state, 2, "(length, radius)");
            return Capsule(real_number(fields[0], "length"), real_number(fields[1], "radius"));
          }));

  py::class_<PaddedPolygon>(m, "PaddedPolygon",
                            R"(A padded polygon: the convex polygon {y : C y <= d}
in the body x-y plane, padded by radius.

C is (m, 2) and d is (m,), m >= 3, with d > 0 (the body origin strictly inside) and the polygon
bounded. Redundant rows are allowed and dropped. Raises ValueError naming the violated field.)")
      .def(py::init(&polygon_from), py::arg("C"), py::arg("d"), py::arg("radius"))
      .def_property_readonly("C", &PaddedPolygon::constraint_matrix, "The rows as given, (m, 2).")
      .def_property_readonly("d", &PaddedPolygon::constraint_offsets, "The offsets as given, (m,).")
      .def_property_readonly("radius", &PaddedPolygon::radius, "Padding radius.")
      .def_property_readonly("vertices", &PaddedPolygon::vertices,
                             "The polygon's vertices in the body x-y plane, counterclockwise, "
                             "(k, 2).")
      .def("__repr__",
           [](const PaddedPolygon& p) {
             std::ostringstream out;
             out << "diffpills.PaddedPolygon(" << p.vertices().rows()
                 << " vertices, radius=" << p.radius() << ")";
             return out.str();
           })
      .def(py::pickle(
          [](const PaddedPolygon& p) -> py::object {
            return py::make_tuple(p.constraint_matrix(), p.constraint_offsets(), p.radius());
          },
          [](const py::object& state) {
            const py::tuple fields = pickled_state(state, 3, "(C, d, radius)");
            return polygon_from(fields[0], fields[1], fields[2]);
          }));

  py::class_<Pose>(m, "Pose", R"(A rigid-body pose: x_world = r + R(q) x_body.

r is a position (3,), q a quaternion [w, x, y, z] (4,), scalar first. q need not be unit: it is
normalized wherever it is used, and gradients include that normalization. Pose() is the identity.
Raises ValueError for non-finite entries, a zero quaternion or a wrong shape, TypeError for entries
that are not real numbers (complex, bool, str) and for a torch tensor that requires grad: a Pose
holds plain numbers, outside autograd, so pass r.detach() (diffpills.torch.proximity differentiates
with respect to poses).)")
      .def(py::init<>())
      .def(py::init([](const py::handle& r, const py::handle& q) {
             return Pose(fixed_vector<3>(r, "r"), fixed_vector<4>(q, "q"));
           }),
           py::arg("r"), py::arg("q"))
      .def_property_readonly("r", &Pose::r, "Position (3,).")
      .def_property_readonly("q", &Pose::q, "Quaternion [w, x, y, z] (4,), as given.")
      .def("__repr__",
           [](const Pose& p) {
             std::ostringstream out;
             out << "diffpills.Pose(r=[" << p.r().transpose() << "], q=[" << p.q().transpose()
                 << "])";
             return out.str();
           })
      .def(py::pickle([](const Pose& p) -> py::object { return py::make_tuple(p.r(), p.q()); },
                      [](const py::object& state) {
                        const py::tuple fields = pickled_state(state, 2, "(r, q)");
                        return Pose(fixed_vector<3>(fields[0], "r"),
                                    fixed_vector<4>(fields[1], "q"));
                      }));
}

py::object proximity_state(const Proximity& p) {
  return py::make_tuple(p.phi, points_array(p.core_points), points_array(p.points), p.normal,
                        p.cores_intersect, p.gradient);
}

constexpr const char* kProximityFields =
    "(phi, core_points, points, normal, cores_intersect, gradient)";

void restore_proximity(Proximity& p, const py::handle& state) {
  const py::tuple fields = pickled_state(state, 6, kProximityFields);
  p.phi = real_number(fields[0], "phi");
  p.core_points = points_from(fields[1], "core_points");
  p.points = points_from(fields[2], "points");
  p.normal = fixed_vector<3>(fields[3], "normal");
  // True or False (or NumPy's), not any object's truth value.
  py::detail::make_caster<bool> cores_intersect;
  if (!cores_intersect.load(fields[4], /*convert=*/false)) {
    throw py::type_error("cores_intersect: expected a bool, got " + type_name(fields[4]));
  }
  p.cores_intersect = static_cast<bool>(cores_intersect);
  p.gradient = fixed_vector<14>(fields[5], "gradient");
}

py::object signed_distance_state(const SignedDistance& s) {
  return py::make_tuple(s.distance, points_array(s.core_points), points_array(s.points), s.normal,
                        s.penetrating, s.gradient);
}

constexpr const char* kSignedDistanceFields =
    "(distance, core_points, points, normal, penetrating, gradient)";

void restore_signed_distance(SignedDistance& s, const py::handle& state) {
  const py::tuple fields = pickled_state(state, 6, kSignedDistanceFields);
  s.distance = real_number(fields[0], "distance");
  s.core_points = points_from(fields[1], "core_points");
  s.points = points_from(fields[2], "points");
  s.normal = fixed_vector<3>(fields[3], "normal");
  py::detail::make_caster<bool> penetrating;
  if (!penetrating.load(fields[4], /*convert=*/false)) {
    throw py::type_error("penetrating: expected a bool, got " + type_name(fields[4]));
  }
  s.penetrating = static_cast<bool>(penetrating);
  s.gradient = fixed_vector<14>(fields[5], "gradient");
}

void bind_signed_distance_results(py::module_& m) {
  py::class_<SignedDistance>(m, "SignedDistance", R"(The result of diffpills.signed_distance.

distance     the gap between the padded surfaces (> 0), or minus their penetration depth (< 0)
core_points  (2, 3): witness points on the two cores, world frame
points       (2, 3): witness points on the two surfaces; points[1] - points[0] = distance * normal
normal       (3,): unit, from shape a to shape b; moving b by -distance * normal makes them touch
penetrating  True when the cores intersect
gradient     (14,): d distance / d[r_a, q_a, r_b, q_b])")
      .def_readonly("distance", &SignedDistance::distance)
      .def_property_readonly("core_points",
                             [](const SignedDistance& s) { return points_array(s.core_points); })
      .def_property_readonly("points",
                             [](const SignedDistance& s) { return points_array(s.points); })
      .def_readonly("normal", &SignedDistance::normal)
      .def_readonly("penetrating", &SignedDistance::penetrating)
      .def_readonly("gradient", &SignedDistance::gradient)
      .def("__repr__",
           [](const py::object& self) {
             // The class's own name: a SignedDistanceJacobian shares this repr.
             const auto& s = self.cast<const SignedDistance&>();
             std::ostringstream out;
             out << "diffpills." << py::type::of(self).attr("__name__").cast<std::string>()
                 << "(distance=" << s.distance << ", normal=[" << s.normal.transpose()
                 << "], penetrating=" << (s.penetrating ? "True" : "False") << ")";
             return out.str();
           })
      .def(py::pickle(&signed_distance_state, [](const py::object& state) {
        SignedDistance s;
        restore_signed_distance(s, state);
        return s;
      }));

  py::class_<SignedDistanceJacobian, SignedDistance>(
      m, "SignedDistanceJacobian", R"(The result of diffpills.signed_distance_jacobian: everything
of SignedDistance, plus

core_points_jacobian  (6, 14): d[core point a; core point b] / d[r_a, q_a, r_b, q_b]
points_jacobian       (6, 14): d[surface point a; surface point b] / d[r_a, q_a, r_b, q_b])")
      .def_readonly("core_points_jacobian", &SignedDistanceJacobian::core_points_jacobian)
      .def_readonly("points_jacobian", &SignedDistanceJacobian::points_jacobian)
      .def(py::pickle(
          [](const SignedDistanceJacobian& s) -> py::object {
            return py::make_tuple(signed_distance_state(s), s.core_points_jacobian,
                                  s.points_jacobian);
          },
          [](const py::object& state) {
            const py::tuple fields =
                pickled_state(state, 3,
                              std::string("(") + kSignedDistanceFields +
                                  ", core_points_jacobian, " + "points_jacobian)");
            SignedDistanceJacobian s;
            restore_signed_distance(s, fields[0]);
            s.core_points_jacobian = fixed_matrix<6, 14>(fields[1], "core_points_jacobian");
            s.points_jacobian = fixed_matrix<6, 14>(fields[2], "points_jacobian");
            return s;
          }));
}

// A shape's parameter gradient as Python sees it: {"length", "radius"} for a capsule, {"C" (m, 2),
// "d" (m,), "radius"} for a polygon.
py::dict shape_gradient_dict(const ShapeGradient& gradient) {
  py::dict out;
  if (const auto* capsule = std::get_if<CapsuleShapeGradient>(&gradient)) {
    out["length"] = capsule->length;
    out["radius"] = capsule->radius;
    return out;
  }
  const auto& polygon = std::get<PolygonShapeGradient>(gradient);
  out["C"] = py::cast(Eigen::MatrixX2d(polygon.C));
  out["d"] = py::cast(Eigen::VectorXd(polygon.d));
  out["radius"] = polygon.radius;
  return out;
}

py::tuple shape_gradient_pair(const std::array<ShapeGradient, 2>& gradients) {
  return py::make_tuple(shape_gradient_dict(gradients[0]), shape_gradient_dict(gradients[1]));
}

// The dict back, for unpickling, with the checks of any argument.
ShapeGradient shape_gradient_from(const py::handle& value, const std::string& name) {
  if (!py::isinstance<py::dict>(value)) {
    throw py::type_error(name + ": expected a dict, got " + type_name(value));
  }
  const py::dict dict = py::reinterpret_borrow<py::dict>(value);
  const auto field = [&](const char* key) {
    if (!dict.contains(key)) throw py::value_error(name + "." + key + ": missing");
    return dict[key];
  };
  if (dict.contains("length")) {
    if (py::len(dict) != 2) throw py::value_error(name + ": expected the keys length, radius");
    return CapsuleShapeGradient{real_number(field("length"), name + ".length"),
                                real_number(field("radius"), name + ".radius")};
  }
  if (py::len(dict) != 3) throw py::value_error(name + ": expected the keys C, d, radius");
  const Array C = as_array(field("C"), name + ".C"), d = as_array(field("d"), name + ".d");
  if (C.ndim() != 2 || C.shape(1) != 2 || d.ndim() != 1 || d.shape(0) != C.shape(0)) {
    throw py::value_error(name + ": expected C of shape (m, 2) and d of shape (m,), got " +
                          shape_of(C) + " and " + shape_of(d));
  }
  PolygonShapeGradient out{Eigen::MatrixX2d(C.shape(0), 2), Eigen::VectorXd(d.shape(0)),
                           real_number(field("radius"), name + ".radius")};
  for (py::ssize_t i = 0; i < C.shape(0); ++i) {
    out.C(i, 0) = C.at(i, 0);
    out.C(i, 1) = C.at(i, 1);
    out.d(i) = d.at(i);
  }
  return out;
}

constexpr const char* kShapeGradientHelp = R"(
shape_gradient  (a's, b's): for a capsule {"length": ..., "radius": ...}, for a polygon
                {"C": (m, 2), "d": (m,), "radius": ...}, the derivatives with respect to the
                shape's own parameters, rows as given (a redundant row gets 0))";

void bind_shape_gradient_results(py::module_& m) {
  py::class_<ProximityShapeGradient, Proximity>(
      m, "ProximityShapeGradient",
      (std::string("The result of diffpills.proximity_shape_gradient: everything of Proximity, "
                   "plus\n") +
       kShapeGradientHelp + " (of phi).")
          .c_str())
      .def_property_readonly(
          "shape_gradient",
          [](const ProximityShapeGradient& p) { return shape_gradient_pair(p.shape_gradient); })
      .def(py::pickle(
          [](const ProximityShapeGradient& p) -> py::object {
            return py::make_tuple(proximity_state(p), shape_gradient_pair(p.shape_gradient));
          },
          [](const py::object& state) {
            const py::tuple fields =
                pickled_state(state, 2, std::string("(") + kProximityFields + ", shape_gradient)");
            ProximityShapeGradient p;
            restore_proximity(p, fields[0]);
            const py::tuple pair = pickled_state(fields[1], 2, "(a's, b's)");
            p.shape_gradient = {shape_gradient_from(pair[0], "shape_gradient[0]"),
                                shape_gradient_from(pair[1], "shape_gradient[1]")};
            return p;
          }));
  py::class_<SignedDistanceShapeGradient, SignedDistance>(
      m, "SignedDistanceShapeGradient",
      (std::string("The result of diffpills.signed_distance_shape_gradient: everything of "
                   "SignedDistance, plus\n") +
       kShapeGradientHelp + " (of the distance).")
          .c_str())
      .def_property_readonly("shape_gradient",
                             [](const SignedDistanceShapeGradient& s) {
                               return shape_gradient_pair(s.shape_gradient);
                             })
      .def(py::pickle(
          [](const SignedDistanceShapeGradient& s) -> py::object {
            return py::make_tuple(signed_distance_state(s), shape_gradient_pair(s.shape_gradient));
          },
          [](const py::object& state) {
            const py::tuple fields = pickled_state(
                state, 2, std::string("(") + kSignedDistanceFields + ", shape_gradient)");
            SignedDistanceShapeGradient s;
            restore_signed_distance(s, fields[0]);
            const py::tuple pair = pickled_state(fields[1], 2, "(a's, b's)");
            s.shape_gradient = {shape_gradient_from(pair[0], "shape_gradient[0]"),
                                shape_gradient_from(pair[1], "shape_gradient[1]")};
            return s;
          }));
}

void bind_hessian_results(py::module_& m) {
  py::class_<ProximityHessian, ProximityJacobian>(m, "ProximityHessian",
                                                  R"(The result of diffpills.proximity_hessian:
everything of ProximityJacobian, plus

hessian  (14, 14): d^2 phi / d[r_a, q_a, r_b, q_b]^2, symmetric (0 where the cores intersect))")
      .def_readonly("hessian", &ProximityHessian::hessian)
      .def(py::pickle(
          [](const ProximityHessian& p) -> py::object {
            return py::make_tuple(proximity_state(p), p.core_points_jacobian, p.points_jacobian,
                                  p.hessian);
          },
          [](const py::object& state) {
            const py::tuple fields =
                pickled_state(state, 4,
                              std::string("(") + kProximityFields +
                                  ", core_points_jacobian, points_jacobian, hessian)");
            ProximityHessian p;
            restore_proximity(p, fields[0]);
            p.core_points_jacobian = fixed_matrix<6, 14>(fields[1], "core_points_jacobian");
            p.points_jacobian = fixed_matrix<6, 14>(fields[2], "points_jacobian");
            p.hessian = fixed_matrix<14, 14>(fields[3], "hessian");
            return p;
          }));
  py::class_<ProximityWithHessian, Proximity>(m, "ProximityWithHessian",
                                              R"(The result of diffpills.proximity_with_hessian:
everything of Proximity, plus

hessian  (14, 14): d^2 phi / d[r_a, q_a, r_b, q_b]^2, symmetric (0 where the cores intersect),
         the same as proximity_hessian's)")
      .def_readonly("hessian", &ProximityWithHessian::hessian)
      .def(py::pickle(
          [](const ProximityWithHessian& p) -> py::object {
            return py::make_tuple(proximity_state(p), p.hessian);
          },
          [](const py::object& state) {
            const py::tuple fields =
                pickled_state(state, 2, std::string("(") + kProximityFields + ", hessian)");
            ProximityWithHessian p;
            restore_proximity(p, fields[0]);
            p.hessian = fixed_matrix<14, 14>(fields[1], "hessian");
            return p;
          }));
  py::class_<SignedDistanceHessian, SignedDistanceJacobian>(
      m, "SignedDistanceHessian", R"(The result of diffpills.signed_distance_hessian: everything
of SignedDistanceJacobian, plus

normal_jacobian  (3, 14): d normal / d[r_a, q_a, r_b, q_b]
hessian          (14, 14): d^2 distance / d[r_a, q_a, r_b, q_b]^2, symmetric)")
      .def_readonly("normal_jacobian", &SignedDistanceHessian::normal_jacobian)
      .def_readonly("hessian", &SignedDistanceHessian::hessian)
      .def(py::pickle(
          [](const SignedDistanceHessian& s) -> py::object {
            return py::make_tuple(signed_distance_state(s), s.core_points_jacobian,
                                  s.points_jacobian, s.normal_jacobian, s.hessian);
          },
          [](const py::object& state) {
            const py::tuple fields = pickled_state(
                state, 5,
                std::string("(") + kSignedDistanceFields +
                    ", core_points_jacobian, points_jacobian, normal_jacobian, hessian)");
            SignedDistanceHessian s;
            restore_signed_distance(s, fields[0]);
            s.core_points_jacobian = fixed_matrix<6, 14>(fields[1], "core_points_jacobian");
            s.points_jacobian = fixed_matrix<6, 14>(fields[2], "points_jacobian");
            s.normal_jacobian = fixed_matrix<3, 14>(fields[3], "normal_jacobian");
            s.hessian = fixed_matrix<14, 14>(fields[4], "hessian");
            return s;
          }));
}

void bind_results(py::module_& m) {
  py::class_<Proximity>(m, "Proximity", R"(The result of diffpills.proximity.

phi              ||p1 - p2||^2 - (R1 + R2)^2: negative when the shapes overlap
core_points      (2, 3): the closest points p1, p2 of the two cores, world frame
points           (2, 3): the surface points p1 + R1 n and p2 - R2 n
normal           (3,): unit, from shape a to shape b
cores_intersect  True when p1 = p2 (the normal is then a documented fallback)
gradient         (14,): d phi / d[r_a, q_a, r_b, q_b])")
      .def_readonly("phi", &Proximity::phi)
      .def_property_readonly("core_points",
                             [](const Proximity& p) { return points_array(p.core_points); })
      .def_property_readonly("points", [](const Proximity& p) { return points_array(p.points); })
      .def_readonly("normal", &Proximity::normal)
      .def_readonly("cores_intersect", &Proximity::cores_intersect)
      .def_readonly("gradient", &Proximity::gradient)
      .def("__repr__",
           [](const py::object& self) {
             // The class's own name: a ProximityJacobian shares this repr.
             const auto& p = self.cast<const Proximity&>();
             std::ostringstream out;
             out << "diffpills." << py::type::of(self).attr("__name__").cast<std::string>()
                 << "(phi=" << p.phi << ", normal=[" << p.normal.transpose()
                 << "], cores_intersect=" << (p.cores_intersect ? "True" : "False") << ")";
             return out.str();
           })
      .def(py::pickle(&proximity_state, [](const py::object& state) {
        Proximity p;
        restore_proximity(p, state);
        return p;
      }));

  py::class_<ProximityJacobian, Proximity>(m, "ProximityJacobian",
                                           R"(The result of diffpills.proximity_jacobian: everything
of Proximity, plus

core_points_jacobian  (6, 14): d[p1; p2] / d[r_a, q_a, r_b, q_b]
points_jacobian       (6, 14): d[surface point a; surface point b] / d[r_a, q_a, r_b, q_b])")
      .def_readonly("core_points_jacobian", &ProximityJacobian::core_points_jacobian)
      .def_readonly("points_jacobian", &ProximityJacobian::points_jacobian)
      .def(py::pickle(
          [](const ProximityJacobian& p) -> py::object {
            return py::make_tuple(proximity_state(p), p.core_points_jacobian, p.points_jacobian);
          },
          [](const py::object& state) {
            const py::tuple fields =
                pickled_state(state, 3,
                              std::string("(") + kProximityFields + ", core_points_jacobian, " +
                                  "points_jacobian)");
            ProximityJacobian p;
            restore_proximity(p, fields[0]);
            p.core_points_jacobian = fixed_matrix<6, 14>(fields[1], "core_points_jacobian");
            p.points_jacobian = fixed_matrix<6, 14>(fields[2], "points_jacobian");
            return p;
          }));
  bind_signed_distance_results(m);
  bind_shape_gradient_results(m);
  bind_hessian_results(m);
}

// A query of two shapes of any type: call(shape_a, pose_a, shape_b, pose_b).
template <class Result, class Query>
Result pair_query(const py::handle& a, const py::handle& pose_a, const py::handle& b,
                  const py::handle& pose_b, const Query& call) {
  const Pose& first = to_pose(pose_a, "pose_a");
  const Pose& second = to_pose(pose_b, "pose_b");
  return with_shape(a, "a", [&](const auto& shape_a) -> Result {
    return with_shape(b, "b", [&](const auto& shape_b) -> Result {
      return call(shape_a, first, shape_b, second);
    });
  });
}

// proximity / proximity_jacobian, with the method.
template <class Result, class Query>
Result query(const py::handle& a, const py::handle& pose_a, const py::handle& b,
             const py::handle& pose_b, const py::handle& method, const Query& call) {
  const ProximityOptions options{to_method(method)};
  return pair_query<Result>(a, pose_a, b, pose_b,
                            [&](const auto&... args) { return call(args..., options); });
}

// A caller-owned output array: float64, C-contiguous, writable, of the given shape (no silent
// copy, which would leave the caller's array unwritten).
py::array_t<double> output_array(const py::handle& value, const std::string& name,
                                 const std::vector<py::ssize_t>& shape) {
  using Exact = py::array_t<double, py::array::c_style>;
  if (!py::isinstance<Exact>(value)) {
    throw py::value_error(name + ": expected a C-contiguous float64 numpy array");
  }
  auto array = value.cast<Exact>();
  if (!array.writeable()) throw py::value_error(name + ": array is read-only");
  const bool same = array.ndim() == static_cast<py::ssize_t>(shape.size()) &&
                    std::equal(shape.begin(), shape.end(), array.shape());
  if (!same) {
    std::string expected = "(" + std::to_string(shape[0]) + (shape.size() == 1 ? ",)" : ", 14)");
    throw py::value_error(name + ": expected shape " + expected + ", got " + shape_of(array));
  }
  return array;
}

// Whether two C-contiguous arrays share bytes. The threads write the outputs while reading the
// inputs, so an output laid over an input (or over the other output) would give results that
// depend on the thread timing, and two threads writing one double is a data race.
bool overlap(const py::array& x, const py::array& y) {
  const auto* x_begin = static_cast<const char*>(x.data());
  const auto* y_begin = static_cast<const char*>(y.data());
  return x.nbytes() > 0 && y.nbytes() > 0 && x_begin < y_begin + y.nbytes() &&
         y_begin < x_begin + x.nbytes();
}

// The batch of either query (value = phi or distance): run(shape_a, r_a, q_a, shape_b, r_b, q_b,
// value, gradient) fills the outputs, without the GIL.
template <class Run>
py::tuple batch_of(const char* value_name, const py::handle& a, const py::handle& r_a,
                   const py::handle& q_a, const py::handle& b, const py::handle& r_b,
                   const py::handle& q_b, const py::handle& out, const Run& run) {
  const Shape shape_a = to_shape(a, "a"), shape_b = to_shape(b, "b");
  BatchInput<3> r_first(r_a, "r_a"), r_second(r_b, "r_b");
  BatchInput<4> q_first(q_a, "q_a"), q_second(q_b, "q_b");
  // N is the row count of the arrays that are not a single pose (1 if all are). Taking the
  // largest row count instead made a 0-row batch with a single pose fail (0 rows against 1).
  Eigen::Index n = 1;
  const std::string* n_from = nullptr;
  for (auto [rows, name] : {std::pair{r_first.rows(), &r_first.name()},
                            {q_first.rows(), &q_first.name()},
                            {r_second.rows(), &r_second.name()},
                            {q_second.rows(), &q_second.name()}}) {
    if (rows == 1) continue;
    if (n_from == nullptr) {
      n = rows;
      n_from = name;
    } else if (rows != n) {
      throw py::value_error(*name + ": has " + std::to_string(rows) + " rows, " + *n_from +
                            " has " + std::to_string(n));
    }
  }
  const auto ra = r_first.view(n), rb = r_second.view(n);
  const auto qa = q_first.view(n), qb = q_second.view(n);
  py::array_t<double> phi, gradient;
  if (out.is_none()) {
    phi = py::array_t<double>(n);
    gradient = py::array_t<double>({n, static_cast<Eigen::Index>(14)});
  } else {
    if (!py::isinstance<py::tuple>(out)) {
      throw py::type_error("out: expected a tuple (" + std::string(value_name) +
                           ", gradient), got " + type_name(out));
    }
    if (py::len(out) != 2) {
      throw py::value_error("out: expected a tuple (" + std::string(value_name) + ", gradient)");
    }
    phi = output_array(out[py::int_(0)], "out[0]", {n});
    gradient = output_array(out[py::int_(1)], "out[1]", {n, 14});
    if (overlap(phi, gradient)) {
      throw py::value_error("out: " + std::string(value_name) + " and gradient share memory");
    }
    for (const auto* input :
         {&r_first.array(), &q_first.array(), &r_second.array(), &q_second.array()}) {
      for (auto [output, name] : {std::pair{&phi, "out[0]"}, {&gradient, "out[1]"}}) {
        if (overlap(*output, *input)) {
          throw py::value_error(std::string(name) + ": shares memory with an input array");
        }
      }
    }
  }
  Eigen::Map<Eigen::VectorXd> phi_view(phi.mutable_data(), n);
  Eigen::Map<GradientArray> gradient_view(gradient.mutable_data(), n, 14);
  {
    py::gil_scoped_release release;
    run(shape_a, ra, qa, shape_b, rb, qb, phi_view, gradient_view);
  }
  return py::make_tuple(phi, gradient);
}

py::tuple batch(const py::handle& a, const py::handle& r_a, const py::handle& q_a,
                const py::handle& b, const py::handle& r_b, const py::handle& q_b,
                const py::handle& threads, const py::handle& method, const py::handle& out) {
  const BatchOptions options{thread_count(threads), to_method(method)};
  return batch_of("phi", a, r_a, q_a, b, r_b, q_b, out,
                  [&](const auto&... args) { proximity_batch(args..., options); });
}

py::tuple signed_distance_batch_of(const py::handle& a, const py::handle& r_a,
                                   const py::handle& q_a, const py::handle& b,
                                   const py::handle& r_b, const py::handle& q_b,
                                   const py::handle& threads, const py::handle& out) {
  const BatchOptions options{thread_count(threads)};
  return batch_of("distance", a, r_a, q_a, b, r_b, q_b, out,
                  [&](const auto&... args) { signed_distance_batch(args..., options); });
}

// A Python int as a 32-bit filter mask (Box2D's category and mask), or an error naming it.
std::uint32_t filter_bits(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || !PyIndex_Check(value.ptr())) {
    throw py::type_error(name + ": expected an int, got " + type_name(value));
  }
  const auto number = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!number) {
    PyErr_Clear();
    throw py::type_error(name + ": expected an int, got " + type_name(value));
  }
  int overflow = 0;
  const long long bits = PyLong_AsLongLongAndOverflow(number.ptr(), &overflow);
  if (overflow != 0 || bits < 0 || bits > 0xFFFFFFFFLL) {
    throw py::value_error(name + ": must be from 0 to 4294967295, got " +
                          std::string(py::str(number)));
  }
  return static_cast<std::uint32_t>(bits);
}

// A Python str as a std::string (a str with a lone surrogate has no UTF-8 form: refused).
std::string text(const py::handle& value, const std::string& name) {
  if (!py::isinstance<py::str>(value)) {
    throw py::type_error(name + ": expected a str, got " + type_name(value));
  }
  Py_ssize_t size = 0;
  const char* data = PyUnicode_AsUTF8AndSize(value.ptr(), &size);
  if (data == nullptr) {
    PyErr_Clear();
    throw py::value_error(name + ": not valid as UTF-8 (a lone surrogate?)");
  }
  return std::string(data, static_cast<std::size_t>(size));
}

Body body_from(const py::handle& name, const py::handle& shapes, const py::handle& category,
               const py::handle& mask) {
  if (!py::isinstance<py::sequence>(shapes) || py::isinstance<py::str>(shapes)) {
    throw py::type_error("shapes: expected a list of (shape, pose) pairs, got " +
                         type_name(shapes));
  }
  std::vector<BodyShape> posed;
  const auto list = py::reinterpret_borrow<py::sequence>(shapes);
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string field = "shapes[" + std::to_string(k) + "]";
    const py::object item = list[k];
    if (!py::isinstance<py::tuple>(item) || py::len(item) != 2) {
      throw py::type_error(field + ": expected a (shape, pose) pair, got " + type_name(item));
    }
    posed.push_back(
        {to_shape(item[py::int_(0)], field + "[0]"), to_pose(item[py::int_(1)], field + "[1]")});
  }
  return Body(text(name, "name"), std::move(posed),
              CollisionFilter{filter_bits(category, "category"), filter_bits(mask, "mask")});
}

py::list body_shapes(const Body& body) {
  py::list out;
  for (const BodyShape& shape : body.shapes()) {
    out.append(py::make_tuple(std::visit([](const auto& s) { return py::cast(s); }, shape.shape),
                              shape.pose));
  }
  return out;
}

Scene scene_from(const py::handle& bodies, const py::handle& exclude) {
  if (!py::isinstance<py::sequence>(bodies) || py::isinstance<py::str>(bodies)) {
    throw py::type_error("bodies: expected a list of diffpills.Body, got " + type_name(bodies));
  }
  std::vector<Body> list;
  const auto items = py::reinterpret_borrow<py::sequence>(bodies);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string field = "bodies[" + std::to_string(i) + "]";
    const py::object item = items[i];
    if (!py::isinstance<Body>(item)) {
      throw py::type_error(field + ": expected diffpills.Body, got " + type_name(item));
    }
    list.push_back(value_of<Body>(item, field));
  }
  std::vector<std::pair<std::string, std::string>> pairs;
  if (!exclude.is_none()) {
    if (!py::isinstance<py::sequence>(exclude) || py::isinstance<py::str>(exclude)) {
      throw py::type_error("exclude: expected a list of (name, name) pairs, got " +
                           type_name(exclude));
    }
    const auto excluded = py::reinterpret_borrow<py::sequence>(exclude);
    for (std::size_t k = 0; k < excluded.size(); ++k) {
      const std::string field = "exclude[" + std::to_string(k) + "]";
      const py::object pair = excluded[k];
      if (!py::isinstance<py::sequence>(pair) || py::isinstance<py::str>(pair) ||
          py::len(pair) != 2) {
        throw py::type_error(field + ": expected a (name, name) pair, got " + type_name(pair));
      }
      pairs.emplace_back(text(pair[py::int_(0)], field + "[0]"),
                         text(pair[py::int_(1)], field + "[1]"));
    }
  }
  return Scene(std::move(list), pairs);
}

py::list body_list(const Scene& scene) {
  py::list out;
  for (const Body& body : scene.bodies()) out.append(py::cast(body));
  return out;
}

py::list excluded_names(const Scene& scene) {
  py::list out;
  for (const auto& [i, j] : scene.excluded()) {
    out.append(py::make_tuple(scene.body(i).name(), scene.body(j).name()));
  }
  return out;
}

// Scene.contacts: the poses as arrays (one row per body), the answer as NumPy arrays in a
// diffpills.Contacts named tuple.
py::object scene_contacts(const Scene& scene, const py::handle& r, const py::handle& q,
                          const py::handle& margin_value, const py::object& contacts_type) {
  const Array r_array = as_array(r, "r"), q_array = as_array(q, "q");
  const auto n = static_cast<py::ssize_t>(scene.size());
  if (r_array.ndim() != 2 || r_array.shape(0) != n || r_array.shape(1) != 3) {
    throw py::value_error("r: expected shape (" + std::to_string(n) +
                          ", 3), one row per body, got " + shape_of(r_array));
  }
  if (q_array.ndim() != 2 || q_array.shape(0) != n || q_array.shape(1) != 4) {
    throw py::value_error("q: expected shape (" + std::to_string(n) +
                          ", 4), one row per body, got " + shape_of(q_array));
  }
  const double margin = real_number(margin_value, "margin");
  std::vector<Pose> poses;
  poses.reserve(static_cast<std::size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    try {
      poses.emplace_back(Eigen::Map<const Eigen::Vector3d>(r_array.data() + 3 * i),
                         Eigen::Map<const Eigen::Vector4d>(q_array.data() + 4 * i));
    } catch (const std::invalid_argument& error) {
      // "pose.q: ..." as "q[3]: ..."
      const std::string message = error.what();
      const std::string field = message.rfind("pose.r", 0) == 0 ? "r" : "q";
      throw py::value_error(field + "[" + std::to_string(i) + "]" + message.substr(6));
    }
  }
  std::vector<Contact> found;
  try {
    py::gil_scoped_release release;
    found = scene.contacts(poses, margin);
  } catch (const diffpills::BodyPoseError& error) {
    // Named as the caller names the pose: rows of r and q.
    const std::string row = "[" + std::to_string(error.body()) + "]";
    throw py::value_error("r" + row + " and q" + row + " (body '" +
                          scene.body(error.body()).name() + "'), shape " +
                          std::to_string(error.shape()) + ": " + error.reason());
  }
  const auto k = static_cast<py::ssize_t>(found.size());
  py::array_t<int> bodies({k, py::ssize_t{2}}), shapes({k, py::ssize_t{2}});
  py::array_t<double> distance(k), phi(k), points({k, py::ssize_t{2}, py::ssize_t{3}}),
      normal({k, py::ssize_t{3}}), gradient({k, py::ssize_t{14}}),
      phi_gradient({k, py::ssize_t{14}});
  auto b = bodies.mutable_unchecked<2>();
  auto s = shapes.mutable_unchecked<2>();
  auto d = distance.mutable_unchecked<1>();
  auto f = phi.mutable_unchecked<1>();
  auto p = points.mutable_unchecked<3>();
  auto nv = normal.mutable_unchecked<2>();
  auto g = gradient.mutable_unchecked<2>();
  auto fg = phi_gradient.mutable_unchecked<2>();
  for (py::ssize_t c = 0; c < k; ++c) {
    const Contact& contact = found[static_cast<std::size_t>(c)];
    for (int j = 0; j < 2; ++j) {
      b(c, j) = contact.bodies[static_cast<std::size_t>(j)];
      s(c, j) = contact.shapes[static_cast<std::size_t>(j)];
      for (int i = 0; i < 3; ++i) p(c, j, i) = contact.points[static_cast<std::size_t>(j)](i);
    }
    d(c) = contact.distance;
    f(c) = contact.phi;
    for (int i = 0; i < 3; ++i) nv(c, i) = contact.normal(i);
    for (int i = 0; i < 14; ++i) {
      g(c, i) = contact.gradient(i);
      fg(c, i) = contact.phi_gradient(i);
    }
  }
  return contacts_type(bodies, shapes, distance, phi, points, normal, gradient, phi_gradient);
}

void bind_scene(py::module_& m) {
  m.attr("Contacts") =
      py::module_::import("collections")
          .attr("namedtuple")(
              "Contacts", py::make_tuple("bodies", "shapes", "distance", "phi", "points", "normal",
                                         "gradient", "phi_gradient"));
  m.attr("Contacts").attr("__module__") = "diffpills";
  m.attr("Contacts").attr("__doc__") =
      R"(The contacts of a scene query, K of them, as NumPy arrays: bodies (K, 2) and shapes (K, 2)
(ints: the two bodies' indices, the first earlier in the scene, and each one's shape index),
distance (K,) (signed distance), phi (K,), points (K, 2, 3) (witness points on the two surfaces),
normal (K, 3) (unit, from the first body's shape to the other), gradient (K, 14) (of distance) and
phi_gradient (K, 14), both with respect to [r, q] of the first body, then of the second.)";

  py::class_<Body>(m, "Body", R"(A rigid body made of primitives, each posed in the body's frame.

Body(name, shapes, category=1, mask=0xFFFFFFFF): shapes is a list of (shape, pose) pairs
(diffpills.Capsule or diffpills.PaddedPolygon, and diffpills.Pose in the body frame). category and
mask are Box2D's collision filter: two bodies are checked against each other only if each one's
category shares a bit with the other's mask.)")
      .def(py::init(&body_from), py::arg("name"), py::arg("shapes"), py::arg("category") = 1,
           py::arg("mask") = 0xFFFFFFFFu)
      .def_property_readonly("name", &Body::name)
      .def_property_readonly("shapes", &body_shapes, "The (shape, pose) pairs, as given.")
      .def_property_readonly("category", [](const Body& b) { return b.filter().category; })
      .def_property_readonly("mask", [](const Body& b) { return b.filter().mask; })
      .def("__repr__",
           [](const Body& b) {
             // The name as Python writes a str, quotes and control characters escaped.
             return "diffpills.Body(" + std::string(py::repr(py::str(b.name()))) + ", " +
                    std::to_string(b.shapes().size()) + " shapes)";
           })
      .def(py::pickle(
          [](const Body& b) -> py::object {
            return py::make_tuple(b.name(), body_shapes(b), b.filter().category, b.filter().mask);
          },
          [](const py::object& state) {
            const py::tuple fields = pickled_state(state, 4, "(name, shapes, category, mask)");
            return body_from(fields[0], fields[1], fields[2], fields[3]);
          }));

  py::class_<Scene>(m, "Scene", R"(Named bodies, some pairs of them excluded from each other.

Scene(bodies, exclude=None): bodies a list of diffpills.Body with distinct names, exclude a list of
(name, name) pairs never checked against each other (adjacent links of an arm). Immutable;
contacts() may run in several threads at once (it releases the GIL).

contacts(r, q, margin=0.0): r (n, 3) and q (n, 4), one pose per body in the scene's order; returns
a diffpills.Contacts of every pair of shapes of two checked bodies whose signed distance is at most
margin, sorted by the bodies' indices, then the shapes'. Gradients are with respect to the BODY
poses (chain rule through the shapes' local poses, quaternion normalization included).)")
      .def(py::init(&scene_from), py::arg("bodies"), py::arg("exclude") = py::none())
      .def("__len__", &Scene::size)
      .def_property_readonly("bodies", &body_list, "The bodies, in order.")
      .def_property_readonly("names",
                             [](const Scene& s) {
                               py::list out;
                               for (const Body& b : s.bodies()) out.append(b.name());
                               return out;
                             })
      .def_property_readonly("exclude", &excluded_names, "The excluded pairs, by name, sorted.")
      .def(
          "index_of",
          [](const Scene& s, const py::handle& name) { return s.index_of(text(name, "name")); },
          py::arg("name"), "The index of the body of that name, or -1.")
      .def(
          "contacts",
          [contacts_type = py::object(m.attr("Contacts"))](
              const Scene& s, const py::handle& r, const py::handle& q, const py::handle& margin) {
            return scene_contacts(s, r, q, margin, contacts_type);
          },
          py::arg("r"), py::arg("q"), py::arg("margin") = 0.0)
      .def("__repr__",
           [](const Scene& s) {
             return "diffpills.Scene(" + std::to_string(s.size()) + " bodies, " +
                    std::to_string(s.excluded().size()) + " excluded pairs)";
           })
      .def(py::pickle([](const Scene& s)
                          -> py::object { return py::make_tuple(body_list(s), excluded_names(s)); },
                      [](const py::object& state) {
                        const py::tuple fields = pickled_state(state, 2, "(bodies, exclude)");
                        return scene_from(fields[0], fields[1]);
                      }));
  m.def(
      "world_pose",
      [](const py::handle& body, const py::handle& local) {
        const Pose& body_pose = to_pose(body, "body");
        const Pose& local_pose = to_pose(local, "local");
        try {
          return world_pose(body_pose, local_pose);
        } catch (const std::invalid_argument& error) {  // the composed position beyond 1e100
          throw py::value_error(std::string("body, local: the world pose's ") + error.what());
        }
      },
      py::arg("body"), py::arg("local"),
      R"(The world pose of a shape fixed at pose `local` on a body at pose `body`: r + R(q) r_local
with the unit attitude q/|q| (x) q_local/|q_local|, bit for bit as Scene.contacts poses its
shapes, so that a contact's pair can be queried again at its own geometry.)");
}

}  // namespace
}  // namespace diffpills::python

PYBIND11_MODULE(_core, m) {
  using namespace diffpills;
  using namespace diffpills::python;
  m.doc() = R"(diffpills: differentiable collision detection for capsules and padded polygons.

Shapes: Capsule(length, radius) and PaddedPolygon(C, d, radius), each posed by Pose(r, q) with q a
quaternion [w, x, y, z]. For any pair:

  proximity(a, pose_a, b, pose_b)           phi, closest points, normal, d phi / d poses (14,)
  proximity_jacobian(a, pose_a, b, pose_b)  the same plus the points' Jacobians (6, 14)
  proximity_batch(a, r_a, q_a, b, r_b, q_b, threads=0)
                                            phi (N,) and gradients (N, 14) for arrays of poses,
                                            on all cores, without the GIL
  signed_distance(a, pose_a, b, pose_b)     the signed distance (negative in penetration), its
                                            witness points, normal and gradient (14,); also
                                            signed_distance_jacobian and signed_distance_batch

phi = ||p1 - p2||^2 - (R1 + R2)^2 is negative exactly when the shapes overlap. The gradient layout
is [r_a (3), q_a (4), r_b (3), q_b (4)]. method="interior_point" selects the paper's solver
instead of the exact fast paths (same answers, slower). Bad input raises ValueError (a bad value or
shape) or TypeError (a wrong type: a str, complex numbers, an object made by __new__ alone) naming
the field; import diffpills.torch for a PyTorch autograd function over batches.)";
  m.attr("__version__") = kVersion;
  py::register_exception<SolverError>(m, "SolverError", PyExc_RuntimeError).attr("__doc__") =
      "Raised when the interior-point method (method=\"interior_point\") does not converge, which "
      "it can fail to on badly scaled pairs; the default method never raises it, and the library "
      "never returns an unverified answer.";
  bind_shapes(m);
  bind_results(m);
  bind_scene(m);

  m.def(
      "proximity",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b, const py::handle& method) {
        return query<Proximity>(a, pose_a, b, pose_b, method,
                                [](const auto&... args) { return proximity(args...); });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("method") = "default",
      R"(Proximity of shape a at pose_a and shape b at pose_b (Capsule or PaddedPolygon each).

Returns a Proximity: phi, core_points (2, 3), points (2, 3), normal (3,), cores_intersect and
gradient (14,) = d phi / d[r_a, q_a, r_b, q_b]. method: "default" or "interior_point".)");
  m.def(
      "proximity_jacobian",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b, const py::handle& method) {
        return query<ProximityJacobian>(a, pose_a, b, pose_b, method, [](const auto&... args) {
          return proximity_jacobian(args...);
        });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("method") = "default",
      R"(As proximity, plus core_points_jacobian and points_jacobian (6, 14): the derivatives of
[p1; p2] and of the two surface points with respect to [r_a, q_a, r_b, q_b].)");
  m.def("proximity_batch", &batch, py::arg("a"), py::arg("r_a"), py::arg("q_a"), py::arg("b"),
        py::arg("r_b"), py::arg("q_b"), py::arg("threads") = 0, py::arg("method") = "default",
        py::arg("out") = py::none(),
        R"(phi and its gradient for N pose pairs of one shape pair.

r_a, r_b: (N, 3) positions; q_a, q_b: (N, 4) quaternions [w, x, y, z]. Any of them may be a single
pose ((3,) or (4,), or one row), used for every row. Returns (phi (N,), gradient (N, 14)), each
row equal to proximity(a, Pose(r_a[i], q_a[i]), b, Pose(r_b[i], q_b[i])) (two capsules: to rounding, 1e-12
of the scene's size, from a vector kernel; see the C++ header batch.hpp); N may be 0. Arrays of
floats or ints of any layout are read (a float64 C-contiguous one in place); complex, bool, str and
object arrays raise TypeError. threads: an int, 0 = every hardware thread; the calling thread works
too, beside worker threads started once per process and reused by every batch (never more than
the hardware's, nor than the blocks of rows). The GIL is released while they run. A bad row raises ValueError naming it, e.g. "q_b[17]: ...".

out: optionally (phi, gradient), writable float64 C-contiguous arrays of shapes (N,) and (N, 14),
sharing no memory with each other or the inputs, to write into and return, for loops that call the batch repeatedly (fresh outputs cost page faults, which
the kernel serializes across threads: measured 1.5x slower with 2 threads for 10^5 capsules).)");

  m.def(
      "signed_distance",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b) {
        return pair_query<SignedDistance>(
            a, pose_a, b, pose_b, [](const auto&... args) { return signed_distance(args...); });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      R"(Signed distance of shape a at pose_a and shape b at pose_b: the gap between the padded
surfaces, or minus their penetration depth, with its exact gradient on both sides.

Returns a SignedDistance: distance, core_points (2, 3), points (2, 3), normal (3,), penetrating and
gradient (14,) = d distance / d[r_a, q_a, r_b, q_b].)");
  m.def(
      "signed_distance_jacobian",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b) {
        return pair_query<SignedDistanceJacobian>(a, pose_a, b, pose_b, [](const auto&... args) {
          return signed_distance_jacobian(args...);
        });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      R"(As signed_distance, plus core_points_jacobian and points_jacobian (6, 14).)");
  m.def(
      "proximity_hessian",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b, const py::handle& method) {
        const ProximityOptions options{to_method(method)};
        return pair_query<ProximityHessian>(
            a, pose_a, b, pose_b,
            [&](const auto& x, const Pose& px, const auto& y, const Pose& py_) {
              return proximity_hessian(Shape(x), px, Shape(y), py_, options);
            });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("method") = "default",
      R"(As proximity_jacobian, plus hessian (14, 14): the second derivatives of phi with respect
to [r_a, q_a, r_b, q_b], quaternion normalization included.)");
  m.def(
      "proximity_with_hessian",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b, const py::handle& method) {
        const ProximityOptions options{to_method(method)};
        return pair_query<ProximityWithHessian>(
            a, pose_a, b, pose_b,
            [&](const auto& x, const Pose& px, const auto& y, const Pose& py_) {
              return proximity_with_hessian(Shape(x), px, Shape(y), py_, options);
            });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("method") = "default",
      R"(As proximity, plus hessian (14, 14), the same as proximity_hessian's, without the points'
Jacobians: what a Newton-type solver needs of a collision constraint, in less time.)");
  m.def(
      "signed_distance_hessian",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b) {
        return pair_query<SignedDistanceHessian>(
            a, pose_a, b, pose_b,
            [](const auto& x, const Pose& px, const auto& y, const Pose& py_) {
              return signed_distance_hessian(Shape(x), px, Shape(y), py_);
            });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      R"(As signed_distance_jacobian, plus normal_jacobian (3, 14) and hessian (14, 14): the
second derivatives of the distance with respect to [r_a, q_a, r_b, q_b].)");
  m.def(
      "proximity_shape_gradient",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b, const py::handle& method) {
        const ProximityOptions options{to_method(method)};
        return pair_query<ProximityShapeGradient>(
            a, pose_a, b, pose_b,
            [&](const auto& x, const Pose& px, const auto& y, const Pose& py_) {
              return proximity_shape_gradient(Shape(x), px, Shape(y), py_, options);
            });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("method") = "default",
      R"(As proximity, plus shape_gradient: the derivatives of phi with respect to each shape's own
parameters, ({"length", "radius"} of a capsule, {"C" (m, 2), "d" (m,), "radius"} of a polygon;
rows as given, a redundant row 0), by the envelope theorem. A row's entries scale as 1 / |C_i|
and are +-inf where that exceeds the double range (rows shorter than ~1e-308 of the shapes' gap),
never NaN.)");
  m.def(
      "signed_distance_shape_gradient",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b) {
        return pair_query<SignedDistanceShapeGradient>(
            a, pose_a, b, pose_b,
            [](const auto& x, const Pose& px, const auto& y, const Pose& py_) {
              return signed_distance_shape_gradient(Shape(x), px, Shape(y), py_);
            });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      R"(As signed_distance, plus shape_gradient: the derivatives of the distance with respect to
each shape's own parameters (as proximity_shape_gradient).)");
  m.def("signed_distance_batch", &signed_distance_batch_of, py::arg("a"), py::arg("r_a"),
        py::arg("q_a"), py::arg("b"), py::arg("r_b"), py::arg("q_b"), py::arg("threads") = 0,
        py::arg("out") = py::none(),
        R"(The signed distance and its gradient for N pose pairs of one shape pair: as
proximity_batch (arrays, single poses, threads, out=, errors), returning (distance (N,),
gradient (N, 14)), row i equal to signed_distance(a, Pose(r_a[i], q_a[i]), b, Pose(r_b[i], q_b[i])).)");
}
