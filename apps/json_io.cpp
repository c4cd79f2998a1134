#include "json_io.hpp"

#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>

#include "json_line.hpp"

namespace diffpills::app {
namespace {

// Queries are read into std::map based objects (see json_line.hpp); answers keep their keys in
// the documented order.
using Input = nlohmann::json;
using Output = nlohmann::ordered_json;

[[noreturn]] void fail(const std::string& field, const std::string& problem) {
  throw std::invalid_argument(field + ": " + problem);
}

const Input& member(const Input& object, const std::string& key, const std::string& name) {
  const auto it = object.find(key);
  if (it == object.end()) {
    fail(name + "." + key, "missing");
  }
  return *it;
}

double number(const Input& value, const std::string& field) {
  if (!value.is_number()) {
    fail(field, "must be a number");
  }
  return value.get<double>();
}

template <int N>
Eigen::Matrix<double, N, 1> vector(const Input& value, const std::string& field) {
  if (!value.is_array() || value.size() != N) {
    fail(field, "must be an array of " + std::to_string(N) + " numbers");
  }
  Eigen::Matrix<double, N, 1> out;
  for (int i = 0; i < N; ++i) {
    out(i) = number(value[static_cast<std::size_t>(i)], field + "[" + std::to_string(i) + "]");
  }
  return out;
}

void reject_unknown_fields(const Input& object, const std::set<std::string>& allowed,
                           const std::string& name) {
  for (const auto& item : object.items()) {
    if (allowed.count(item.key()) == 0) {
      fail(name + "." + key_text(item.key()), "unknown field");
    }
  }
}

// Library messages start with a generic owner ("capsule.", "polygon.", "pose."); replace it with
// the shape's own name so the field is unambiguous in a query with two shapes.
std::string rename_field(const std::string& message, const std::string& owner,
                         const std::string& name) {
  return message.rfind(owner, 0) == 0 ? name + "." + message.substr(owner.size()) : message;
}

Shape parse_shape(const Input& value, const std::string& name, const std::string& type) {
  if (type == "capsule") {
    reject_unknown_fields(value, {"type", "length", "radius", "r", "q"}, name);
    try {
      return Capsule(number(member(value, "length", name), name + ".length"),
                     number(member(value, "radius", name), name + ".radius"));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(rename_field(error.what(), "capsule.", name));
    }
  }
  if (type == "polygon") {
    reject_unknown_fields(value, {"type", "C", "d", "radius", "r", "q"}, name);
    const Input& rows = member(value, "C", name);
    const Input& offsets = member(value, "d", name);
    if (!rows.is_array()) fail(name + ".C", "must be an array of [c1, c2] rows");
    if (!offsets.is_array()) fail(name + ".d", "must be an array of numbers");
    Eigen::MatrixX2d C(static_cast<Eigen::Index>(rows.size()), 2);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Eigen::Vector2d row = vector<2>(rows[i], name + ".C[" + std::to_string(i) + "]");
      C.row(static_cast<Eigen::Index>(i)) = row.transpose();
    }
    Eigen::VectorXd d(static_cast<Eigen::Index>(offsets.size()));
    for (std::size_t i = 0; i < offsets.size(); ++i) {
      d(static_cast<Eigen::Index>(i)) = number(offsets[i], name + ".d[" + std::to_string(i) + "]");
    }
    const double radius = number(member(value, "radius", name), name + ".radius");
    try {
      return PaddedPolygon(C, d, radius);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(rename_field(error.what(), "polygon.", name));
    }
  }
  fail(name + ".type", "must be \"capsule\" or \"polygon\"");
}

Output rows(const Eigen::MatrixXd& matrix) {
  Output out = Output::array();
  for (Eigen::Index i = 0; i < matrix.rows(); ++i) {
    Output row = Output::array();
    for (Eigen::Index j = 0; j < matrix.cols(); ++j) row.push_back(matrix(i, j));
    out.push_back(row);
  }
  return out;
}

Output list(const Eigen::VectorXd& v) {
  return Output(std::vector<double>(v.data(), v.data() + v.size()));
}

}  // namespace

Pose parse_pose(const Input& value, const std::string& name) {
  if (!value.is_object()) fail(name, "must be an object with fields \"r\" and \"q\"");
  reject_unknown_fields(value, {"r", "q"}, name);
  const Eigen::Vector3d r = vector<3>(member(value, "r", name), name + ".r");
  const Eigen::Vector4d q = vector<4>(member(value, "q", name), name + ".q");
  try {
    return Pose(r, q);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(rename_field(error.what(), "pose.", name));
  }
}

namespace {

std::uint32_t filter_bits(const Input& body, const char* key, std::uint32_t fallback,
                          const std::string& name) {
  const auto it = body.find(key);
  if (it == body.end()) return fallback;
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > 0xFFFFFFFFu) {
    fail(name + "." + key, "must be an integer from 0 to 4294967295");
  }
  return static_cast<std::uint32_t>(it->get<std::uint64_t>());
}

}  // namespace

Scene parse_scene(const Input& value) {
  if (!value.is_object()) fail("scene", "must be an object with fields \"bodies\" and \"exclude\"");
  reject_unknown_fields(value, {"bodies", "exclude"}, "scene");
  const Input& bodies = member(value, "bodies", "scene");
  if (!bodies.is_array()) fail("bodies", "must be an array of bodies");
  std::vector<Body> list;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::string name = "bodies[" + std::to_string(i) + "]";
    const Input& body = bodies[i];
    if (!body.is_object()) fail(name, "must be an object with fields \"name\" and \"shapes\"");
    reject_unknown_fields(body, {"name", "shapes", "category", "mask"}, name);
    const Input& body_name = member(body, "name", name);
    if (!body_name.is_string() || body_name.get<std::string>().empty()) {
      fail(name + ".name", "must be a non-empty string");
    }
    const Input& shapes = member(body, "shapes", name);
    if (!shapes.is_array()) fail(name + ".shapes", "must be an array of shapes");
    std::vector<BodyShape> posed;
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      PosedShape shape = parse_posed_shape(shapes[k], name + ".shapes[" + std::to_string(k) + "]");
      posed.push_back({std::move(shape.shape), shape.pose});
    }
    const CollisionFilter defaults;
    list.emplace_back(body_name.get<std::string>(), std::move(posed),
                      CollisionFilter{filter_bits(body, "category", defaults.category, name),
                                      filter_bits(body, "mask", defaults.mask, name)});
  }
  std::vector<std::pair<std::string, std::string>> exclude;
  if (value.contains("exclude")) {
    const Input& pairs = value["exclude"];
    if (!pairs.is_array()) fail("exclude", "must be an array of [name, name] pairs");
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const Input& pair = pairs[k];
      if (!pair.is_array() || pair.size() != 2 || !pair[0].is_string() || !pair[1].is_string()) {
        fail("exclude[" + std::to_string(k) + "]", "must be a pair of body names");
      }
      exclude.emplace_back(pair[0].get<std::string>(), pair[1].get<std::string>());
    }
  }
  return Scene(std::move(list), exclude);
}

PosedShape parse_posed_shape(const Input& value, const std::string& name) {
  if (!value.is_object()) {
    fail(name, "must be an object");
  }
  const Input& type = member(value, "type", name);
  if (!type.is_string()) {
    fail(name + ".type", "must be \"capsule\" or \"polygon\"");
  }
  Shape shape = parse_shape(value, name, type.get<std::string>());
  const Eigen::Vector3d r = vector<3>(member(value, "r", name), name + ".r");
  const Eigen::Vector4d q = vector<4>(member(value, "q", name), name + ".q");
  try {
    return {std::move(shape), Pose(r, q)};
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(rename_field(error.what(), "pose.", name));
  }
}

Output to_json(const Shape& shape, const Pose& pose) {
  Output out;
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    out = {{"type", "capsule"}, {"length", capsule->length()}, {"radius", capsule->radius()}};
  } else {
    const auto& polygon = std::get<PaddedPolygon>(shape);
    out = {{"type", "polygon"},
           {"C", rows(polygon.constraint_matrix())},
           {"d", list(polygon.constraint_offsets())},
           {"radius", polygon.radius()}};
  }
  out["r"] = list(pose.r());
  out["q"] = list(pose.q());
  return out;
}

Output to_json(const Scene& scene) {
  Output bodies = Output::array();
  const CollisionFilter defaults;
  for (const Body& body : scene.bodies()) {
    Output shapes = Output::array();
    for (const BodyShape& shape : body.shapes()) shapes.push_back(to_json(shape.shape, shape.pose));
    Output out = {{"name", body.name()}, {"shapes", shapes}};
    if (body.filter().category != defaults.category) out["category"] = body.filter().category;
    if (body.filter().mask != defaults.mask) out["mask"] = body.filter().mask;
    bodies.push_back(out);
  }
  Output exclude = Output::array();
  for (const auto& [i, j] : scene.excluded()) {
    exclude.push_back({scene.body(i).name(), scene.body(j).name()});
  }
  return {{"bodies", bodies}, {"exclude", exclude}};
}

Output to_json(const Contact& contact, const Scene& scene) {
  return {{"bodies", {scene.body(contact.bodies[0]).name(), scene.body(contact.bodies[1]).name()}},
          {"shapes", {contact.shapes[0], contact.shapes[1]}},
          {"distance", contact.distance},
          {"phi", contact.phi},
          {"points", {list(contact.points[0]), list(contact.points[1])}},
          {"normal", list(contact.normal)},
          {"gradient", list(contact.gradient)},
          {"phi_gradient", list(contact.phi_gradient)}};
}

Output to_json(const Proximity& result) {
  return {{"phi", result.phi},
          {"core_points", {list(result.core_points[0]), list(result.core_points[1])}},
          {"points", {list(result.points[0]), list(result.points[1])}},
          {"normal", list(result.normal)},
          {"gradient", list(result.gradient)},
          {"cores_intersect", result.cores_intersect}};
}

Output to_json(const ProximityJacobian& result) {
  Output out = to_json(static_cast<const Proximity&>(result));
  out["jacobian"] = {{"core_points", rows(result.core_points_jacobian)},
                     {"points", rows(result.points_jacobian)}};
  return out;
}

Output to_json(const SignedDistance& result) {
  return {{"distance", result.distance},
          {"points", {list(result.points[0]), list(result.points[1])}},
          {"normal", list(result.normal)},
          {"gradient", list(result.gradient)},
          {"core_points", {list(result.core_points[0]), list(result.core_points[1])}},
          {"penetrating", result.penetrating}};
}

Output to_json(const SignedDistanceJacobian& result) {
  Output out = to_json(static_cast<const SignedDistance&>(result));
  out["jacobian"] = rows(result.points_jacobian);
  out["core_points_jacobian"] = rows(result.core_points_jacobian);
  return out;
}

Output matrix_rows(const Eigen::MatrixXd& matrix) { return rows(matrix); }

// A polygon's d/dC and d/dd divide by the rows' lengths and are +-inf beyond the double range
// (shape_gradient.hpp: rows of subnormal length). JSON has no infinity, and a null would hide the
// sign and pass for an answer: the line is answered as an error naming the field instead.
Output to_json(const std::array<ShapeGradient, 2>& shape_gradient) {
  const auto one = [](const ShapeGradient& gradient, const char* shape) -> Output {
    if (const auto* capsule = std::get_if<CapsuleShapeGradient>(&gradient)) {
      return {{"length", capsule->length}, {"radius", capsule->radius}};
    }
    const auto& polygon = std::get<PolygonShapeGradient>(gradient);
    if (!polygon.C.allFinite() || !polygon.d.allFinite() || !std::isfinite(polygon.radius)) {
      throw std::invalid_argument(std::string("shape_gradient: ") + shape +
                                  "'s gradient is beyond the double range (rows of C "
                                  "shorter than ~1e-308 of the shapes' gap?); ask without "
                                  "\"shape_gradient\" or rescale the rows");
    }
    return {{"C", rows(polygon.C)}, {"d", list(polygon.d)}, {"radius", polygon.radius}};
  };
  return {{"a", one(shape_gradient[0], "a")}, {"b", one(shape_gradient[1], "b")}};
}

}  // namespace diffpills::app
