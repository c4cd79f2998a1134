// The Python module diffpills._core: the shapes, poses and queries of the C++ library, NumPy arrays
// in and out. Inputs are checked here for their shapes (ValueError naming the argument) and by the
// library for their values (std::invalid_argument, which pybind11 turns into ValueError with the
// library's message). The package diffpills (python/diffpills/__init__.py) re-exports everything.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "diffpills/diffpills.hpp"

namespace py = pybind11;

namespace diffpills::python {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Any array-like as a C-contiguous float64 array, or ValueError naming the argument.
Array as_array(const py::handle& value, const std::string& name) {
  Array array = Array::ensure(value);
  if (!array) throw py::value_error(name + ": expected an array of numbers");
  return array;
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

Method to_method(const std::string& name) {
  if (name == "default") return Method::kDefault;
  if (name == "interior_point") return Method::kInteriorPoint;
  throw py::value_error("method: expected \"default\" or \"interior_point\", got \"" + name + "\"");
}

// Calls f with the shape behind a Python object (a Capsule or a PaddedPolygon, by reference).
template <class F>
decltype(auto) with_shape(const py::handle& object, const std::string& name, F&& f) {
  if (py::isinstance<Capsule>(object)) return f(object.cast<const Capsule&>());
  if (py::isinstance<PaddedPolygon>(object)) return f(object.cast<const PaddedPolygon&>());
  throw py::type_error(name + ": expected diffpills.Capsule or diffpills.PaddedPolygon, got " +
                       std::string(py::str(py::type::of(object).attr("__name__"))));
}

Shape to_shape(const py::handle& object, const std::string& name) {
  return with_shape(object, name, [](const auto& shape) { return Shape(shape); });
}

const Pose& to_pose(const py::handle& object, const std::string& name) {
  if (!py::isinstance<Pose>(object)) {
    throw py::type_error(name + ": expected diffpills.Pose, got " +
                         std::string(py::str(py::type::of(object).attr("__name__"))));
  }
  return object.cast<const Pose&>();
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
  const Array array = as_array(value, name);
  if (array.ndim() != 2 || array.shape(0) != 2 || array.shape(1) != 3) {
    throw py::value_error(name + ": expected shape (2, 3), got " + shape_of(array));
  }
  return {Eigen::Vector3d(array.data(0, 0)), Eigen::Vector3d(array.data(1, 0))};
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

void bind_shapes(py::module_& m) {
  py::class_<Capsule>(m, "Capsule",
                      R"(A capsule: a segment of the given length along the body x axis,
from [-length/2, 0, 0] to [length/2, 0, 0], padded by radius. length 0 is a sphere.

Raises ValueError for negative or non-finite sizes.)")
      .def(py::init<double, double>(), py::arg("length"), py::arg("radius"))
      .def_property_readonly("length", &Capsule::length, "Length of the core segment.")
      .def_property_readonly("radius", &Capsule::radius, "Padding radius.")
      .def("__repr__",
           [](const Capsule& c) {
             std::ostringstream out;
             out << "diffpills.Capsule(length=" << c.length() << ", radius=" << c.radius() << ")";
             return out.str();
           })
      .def(py::pickle([](const Capsule& c) { return py::make_tuple(c.length(), c.radius()); },
                      [](const py::tuple& state) {
                        return Capsule(state[0].cast<double>(), state[1].cast<double>());
                      }));

  py::class_<PaddedPolygon>(m, "PaddedPolygon",
                            R"(A padded polygon: the convex polygon {y : C y <= d}
in the body x-y plane, padded by radius.

C is (m, 2) and d is (m,), m >= 3, with d > 0 (the body origin strictly inside) and the polygon
bounded. Redundant rows are allowed and dropped. Raises ValueError naming the violated field.)")
      .def(py::init([](const py::handle& C, const py::handle& d, double radius) {
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
             return PaddedPolygon(c_matrix, d_vector, radius);
           }),
           py::arg("C"), py::arg("d"), py::arg("radius"))
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
          [](const PaddedPolygon& p) {
            return py::make_tuple(p.constraint_matrix(), p.constraint_offsets(), p.radius());
          },
          [](const py::tuple& state) {
            return PaddedPolygon(state[0].cast<Eigen::MatrixX2d>(),
                                 state[1].cast<Eigen::VectorXd>(), state[2].cast<double>());
          }));

  py::class_<Pose>(m, "Pose", R"(A rigid-body pose: x_world = r + R(q) x_body.

r is a position (3,), q a quaternion [w, x, y, z] (4,), scalar first. q need not be unit: it is
normalized wherever it is used, and gradients include that normalization. Pose() is the identity.
Raises ValueError for non-finite entries or a zero quaternion.)")
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
      .def(py::pickle([](const Pose& p) { return py::make_tuple(p.r(), p.q()); },
                      [](const py::tuple& state) {
                        return Pose(state[0].cast<Eigen::Vector3d>(),
                                    state[1].cast<Eigen::Vector4d>());
                      }));
}

py::tuple proximity_state(const Proximity& p) {
  return py::make_tuple(p.phi, points_array(p.core_points), points_array(p.points), p.normal,
                        p.cores_intersect, p.gradient);
}

void restore_proximity(Proximity& p, const py::tuple& state) {
  p.phi = state[0].cast<double>();
  p.core_points = points_from(state[1], "core_points");
  p.points = points_from(state[2], "points");
  p.normal = fixed_vector<3>(state[3], "normal");
  p.cores_intersect = state[4].cast<bool>();
  p.gradient = fixed_vector<14>(state[5], "gradient");
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
           [](const Proximity& p) {
             std::ostringstream out;
             out << "diffpills.Proximity(phi=" << p.phi << ", normal=[" << p.normal.transpose()
                 << "], cores_intersect=" << (p.cores_intersect ? "True" : "False") << ")";
             return out.str();
           })
      .def(py::pickle(&proximity_state, [](const py::tuple& state) {
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
          [](const ProximityJacobian& p) {
            return py::make_tuple(proximity_state(p), p.core_points_jacobian, p.points_jacobian);
          },
          [](const py::tuple& state) {
            ProximityJacobian p;
            restore_proximity(p, state[0].cast<py::tuple>());
            p.core_points_jacobian = state[1].cast<Eigen::Matrix<double, 6, 14>>();
            p.points_jacobian = state[2].cast<Eigen::Matrix<double, 6, 14>>();
            return p;
          }));
}

// proximity / proximity_jacobian on two shapes of any type.
template <class Result, class Query>
Result query(const py::handle& a, const py::handle& pose_a, const py::handle& b,
             const py::handle& pose_b, const std::string& method, const Query& call) {
  const ProximityOptions options{to_method(method)};
  const Pose& first = to_pose(pose_a, "pose_a");
  const Pose& second = to_pose(pose_b, "pose_b");
  return with_shape(a, "a", [&](const auto& shape_a) -> Result {
    return with_shape(b, "b", [&](const auto& shape_b) -> Result {
      return call(shape_a, first, shape_b, second, options);
    });
  });
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

py::tuple batch(const py::handle& a, const py::handle& r_a, const py::handle& q_a,
                const py::handle& b, const py::handle& r_b, const py::handle& q_b, int threads,
                const std::string& method, const py::object& out) {
  if (threads < 0) throw py::value_error("threads: must be >= 0 (0 = every core)");
  const Shape shape_a = to_shape(a, "a"), shape_b = to_shape(b, "b");
  BatchInput<3> r_first(r_a, "r_a"), r_second(r_b, "r_b");
  BatchInput<4> q_first(q_a, "q_a"), q_second(q_b, "q_b");
  const Eigen::Index n =
      std::max({r_first.rows(), q_first.rows(), r_second.rows(), q_second.rows()});
  for (auto [rows, name] : {std::pair{r_first.rows(), &r_first.name()},
                            {q_first.rows(), &q_first.name()},
                            {r_second.rows(), &r_second.name()},
                            {q_second.rows(), &q_second.name()}}) {
    if (rows != 1 && rows != n) {
      throw py::value_error(*name + ": has " + std::to_string(rows) + " rows, the others " +
                            std::to_string(n));
    }
  }
  const auto ra = r_first.view(n), rb = r_second.view(n);
  const auto qa = q_first.view(n), qb = q_second.view(n);
  py::array_t<double> phi, gradient;
  if (out.is_none()) {
    phi = py::array_t<double>(n);
    gradient = py::array_t<double>({n, static_cast<Eigen::Index>(14)});
  } else {
    if (!py::isinstance<py::tuple>(out) || py::len(out) != 2) {
      throw py::value_error("out: expected a tuple (phi, gradient)");
    }
    phi = output_array(out[py::int_(0)], "out[0]", {n});
    gradient = output_array(out[py::int_(1)], "out[1]", {n, 14});
  }
  Eigen::Map<Eigen::VectorXd> phi_view(phi.mutable_data(), n);
  Eigen::Map<GradientArray> gradient_view(gradient.mutable_data(), n, 14);
  {
    py::gil_scoped_release release;
    proximity_batch(shape_a, ra, qa, shape_b, rb, qb, phi_view, gradient_view,
                    BatchOptions{threads, to_method(method)});
  }
  return py::make_tuple(phi, gradient);
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

phi = ||p1 - p2||^2 - (R1 + R2)^2 is negative exactly when the shapes overlap. The gradient layout
is [r_a (3), q_a (4), r_b (3), q_b (4)]. method="interior_point" selects the paper's solver
instead of the exact fast paths (same answers, slower). Bad input raises ValueError naming the
field; import diffpills.torch for a PyTorch autograd function over batches.)";
  m.attr("__version__") = kVersion;
  py::register_exception<SolverError>(m, "SolverError", PyExc_RuntimeError).attr("__doc__") =
      "Raised when the QP solver does not converge (never seen for valid shapes in the tests); "
      "the library never returns an unverified answer.";
  bind_shapes(m);
  bind_results(m);

  m.def(
      "proximity",
      [](const py::handle& a, const py::handle& pose_a, const py::handle& b,
         const py::handle& pose_b, const std::string& method) {
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
         const py::handle& pose_b, const std::string& method) {
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
row equal to proximity(a, Pose(r_a[i], q_a[i]), b, Pose(r_b[i], q_b[i])). threads: worker
threads, 0 = every core; the GIL is released while they run. A bad row raises ValueError naming
it, e.g. "q_b[17]: ...".

out: optionally (phi, gradient), float64 C-contiguous arrays of shapes (N,) and (N, 14) to write
into and return, for loops that call the batch repeatedly (fresh outputs cost page faults, which
the kernel serializes across threads: measured 1.5x slower with 2 threads for 10^5 capsules).)");
}
