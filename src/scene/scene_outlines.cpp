#include "scene_outlines.hpp"

#include <variant>

#include "diffpills/rotation.hpp"

namespace diffpills::detail {

SceneOutlines make_outlines(const std::vector<Body>& bodies) {
  SceneOutlines out;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::vector<BodyShape>& shapes = bodies[i].shapes();
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      const Pose& local = shapes[k].pose;
      const Eigen::Matrix3d R = rotation_matrix(local.q());
      SceneOutlines::Primitive primitive;
      primitive.body = static_cast<int>(i);
      primitive.shape = static_cast<int>(k);
      primitive.first_point = static_cast<int>(out.points.size());
      if (const auto* capsule = std::get_if<Capsule>(&shapes[k].shape)) {
        const Eigen::Vector3d half = 0.5 * capsule->length() * R.col(0);
        out.points.emplace_back(local.r() - half);
        if (capsule->length() > 0.0) out.points.emplace_back(local.r() + half);
        primitive.radius = capsule->radius();
      } else {
        const auto& polygon = std::get<PaddedPolygon>(shapes[k].shape);
        for (Eigen::Index v = 0; v < polygon.vertices().rows(); ++v) {
          out.points.emplace_back(local.r() +
                                  R.leftCols<2>() * polygon.vertices().row(v).transpose());
        }
        primitive.radius = polygon.radius();
      }
      primitive.point_count = static_cast<int>(out.points.size()) - primitive.first_point;
      out.primitives.push_back(primitive);
    }
  }
  return out;
}

}  // namespace diffpills::detail
