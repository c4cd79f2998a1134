#include "contact_normal.hpp"

#include <Eigen/Geometry>

#include "penetration.hpp"
#include "unit_quaternion.hpp"

namespace diffpills::detail {

NormalSource points_normal_source(const PosedCore& a, const ClosestFeature& side_a,
                                  const PosedCore& b, const ClosestFeature& side_b,
                                  const Eigen::Vector3d& d, double unit) {
  NormalSource source;
  const double length = d.norm();
  // A feature's normal must agree with d / |d| to d's own uncertainty (a few ulps of the scene,
  // `unit` here, over |d|; 250 times that), or the features do not hold the points as their
  // labels say: a segment of zero length in the frame (a polygon 1e-300 of a scene of 1e70, found
  // by fuzz_proximity) or a point labelled inside an edge by rounding at its end. (With the
  // scene's size taken as 1 in a subnormal scene's frame, where it is 2^-52, any normal agreed:
  // fuzz_proximity found two capsules 1e-317 apart along x given the normal z.)
  const auto agrees = [&](const Eigen::Vector3d& normal) {
    return (normal - d / length).norm() <= 1e-12 * (1.0 + unit / length);
  };
  for (int core = 0; core < 2; ++core) {
    const ClosestFeature& side = core == 0 ? side_a : side_b;
    if (side.free_dimensions == 2) {
      const Eigen::Vector3d axis = (core == 0 ? a : b).attitude.matrix().col(2);
      const double sign = axis.dot(d) >= 0.0 ? 1.0 : -1.0;
      if (!agrees(sign * axis)) continue;
      source.kind = NormalSource::Kind::kFace;
      source.face_core = core;
      source.sign = sign;
      return source;
    }
  }
  if (side_a.free_dimensions == 1 && side_b.free_dimensions == 1) {
    const Eigen::Vector3d e = a.attitude.matrix() * side_a.free_directions.col(0);
    const Eigen::Vector3d f = b.attitude.matrix() * side_b.free_directions.col(0);
    const Eigen::Vector3d c = stable_cross(e, f);
    const double sine = c.norm();
    const double sign = c.dot(d) >= 0.0 ? 1.0 : -1.0;
    if (sine * unit >= length && agrees(sign * c / sine)) {
      source.kind = NormalSource::Kind::kEdges;
      source.sign = sign;
      source.edge_directions = {side_a.free_directions.col(0), side_b.free_directions.col(0)};
    }
  }
  return source;
}

Eigen::Vector3d source_normal(const NormalSource& source, const PosedCore& a, const PosedCore& b,
                              const Eigen::Vector3d& d) {
  switch (source.kind) {
    case NormalSource::Kind::kFace:
      return source.sign * (source.face_core == 0 ? a : b).attitude.matrix().col(2);
    case NormalSource::Kind::kEdges:
      return source.sign * stable_cross(a.attitude.matrix() * source.edge_directions[0],
                                        b.attitude.matrix() * source.edge_directions[1])
                               .normalized();
    default:
      return d * (1.0 / d.norm());
  }
}

// d(sign * unit(a x b)) with a = Q1 u, b = Q2 v: d(a x b) = da x b + a x db = -[b]x da + [a]x db.
Matrix3x14 source_normal_motion(const NormalSource& source, const PosedCore& a, const PosedCore& b,
                                const Eigen::Vector3d& d, const PointMotion& motion) {
  Matrix3x14 dnormal = Matrix3x14::Zero();
  switch (source.kind) {
    case NormalSource::Kind::kClosestPoints:
      dnormal = unit_vector_motion(d, motion.dp2 - motion.dp1);
      break;
    case NormalSource::Kind::kFace: {
      const PosedCore& face = source.face_core == 0 ? a : b;
      dnormal.middleCols<4>(source.face_core == 0 ? 3 : 10) =
          source.sign * face.attitude.rotate_jacobian(Eigen::Vector3d::UnitZ());
      break;
    }
    case NormalSource::Kind::kEdges: {
      const Eigen::Vector3d edge_a = a.attitude.matrix() * source.edge_directions[0];
      const Eigen::Vector3d edge_b = b.attitude.matrix() * source.edge_directions[1];
      Matrix3x14 d_cross = Matrix3x14::Zero();
      d_cross.middleCols<4>(3) =
          -skew(edge_b) * a.attitude.rotate_jacobian(source.edge_directions[0]);
      d_cross.middleCols<4>(10) =
          skew(edge_a) * b.attitude.rotate_jacobian(source.edge_directions[1]);
      dnormal = source.sign * unit_vector_motion(stable_cross(edge_a, edge_b), d_cross);
      break;
    }
    case NormalSource::Kind::kFixed:
      break;
  }
  return dnormal;
}

}  // namespace diffpills::detail
