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

nlohmann::ordered_json to_json(const Proximity& result);
nlohmann::ordered_json to_json(const ProximityJacobian& result);
// DESIGN.md section 3b: distance, points, normal, gradient (and core_points, penetrating); with
// the Jacobian, "jacobian" is that of the surface points (6 rows of 14) and "core_points_jacobian"
// that of the core points.
nlohmann::ordered_json to_json(const SignedDistance& result);
nlohmann::ordered_json to_json(const SignedDistanceJacobian& result);

}  // namespace diffpills::app
