// JSON <-> diffpills types for the command line (DESIGN.md section 3). Parsing errors throw
// std::invalid_argument whose message starts with the field's path, e.g. "a.q[2]: ...".
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "diffpills/diffpills.hpp"

namespace diffpills::app {

// A shape with its pose: {"type": "capsule", "length", "radius", "r", "q"} or
// {"type": "polygon", "C", "d", "radius", "r", "q"}; `name` prefixes error messages.
struct PosedShape {
  Shape shape;
  Pose pose;
};
PosedShape parse_posed_shape(const nlohmann::json& value, const std::string& name);

// The same schema back, for output files of the demos.
nlohmann::ordered_json to_json(const Shape& shape, const Pose& pose);

// A pose alone: {"r": [3], "q": [4]}.
Pose parse_pose(const nlohmann::json& value, const std::string& name);

// A scene file (DESIGN.md section 3c): {"bodies": [{"name": "...", "shapes": [posed shapes, in
// the body's frame], "category": n, "mask": n}], "exclude": [["a", "b"], ...]}, with "category"
// and "mask" (Box2D's collision filter, integers in [0, 2^32)) and "exclude" optional. Errors
// name the field ("bodies[2].shapes[0].radius: ...").
Scene parse_scene(const nlohmann::json& value);
// The same schema back (the filter only where it is not the default).
nlohmann::ordered_json to_json(const Scene& scene);
// A contact of a scene query, bodies by name (DESIGN.md section 3c).
nlohmann::ordered_json to_json(const Contact& contact, const Scene& scene);

nlohmann::ordered_json to_json(const Proximity& result);
nlohmann::ordered_json to_json(const ProximityJacobian& result);
// DESIGN.md section 3b: distance, points, normal, gradient (and core_points, penetrating); with
// the Jacobian, "jacobian" is that of the surface points (6 rows of 14) and "core_points_jacobian"
// that of the core points.
nlohmann::ordered_json to_json(const SignedDistance& result);
nlohmann::ordered_json to_json(const SignedDistanceJacobian& result);
// A matrix as JSON rows ("hessian": [14 rows of 14]).
nlohmann::ordered_json matrix_rows(const Eigen::MatrixXd& matrix);
// DESIGN.md section 3b: {"a": S, "b": S}, S = {"length", "radius"} for a capsule, {"C": [m rows of
// 2], "d": [m], "radius"} for a polygon.
nlohmann::ordered_json to_json(const std::array<ShapeGradient, 2>& shape_gradient);

}  // namespace diffpills::app
