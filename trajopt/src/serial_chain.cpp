#include "diffpills/trajopt/serial_chain.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "diffpills/rotation.hpp"

namespace diffpills::trajopt {
namespace {

Eigen::Vector4d about_x(double angle) {
  return {std::cos(0.5 * angle), std::sin(0.5 * angle), 0.0, 0.0};
}
Eigen::Vector4d about_z(double angle) {
  return {std::cos(0.5 * angle), 0.0, 0.0, std::sin(0.5 * angle)};
}

}  // namespace

ChainFrames forward_kinematics(const SerialChain& chain, const Eigen::Ref<const Eigen::VectorXd>& q,
                               bool derivatives) {
  ChainFrames frames;
  forward_kinematics(chain, q, derivatives, frames);
  return frames;
}

void forward_kinematics(const SerialChain& chain, const Eigen::Ref<const Eigen::VectorXd>& q,
                        bool derivatives, ChainFrames& out) {
  const int n = chain.joints();
  if (static_cast<int>(chain.d.size()) != n || static_cast<int>(chain.alpha.size()) != n) {
    throw std::invalid_argument("chain: a, d and alpha must have one entry per joint");
  }
  if (q.size() != n) {
    throw std::invalid_argument("q: expected " + std::to_string(n) + " joint angles, got " +
                                std::to_string(q.size()));
  }
  const auto frames = static_cast<std::size_t>(n) + 2;
  out.origin.assign(frames, Eigen::Vector3d::Zero());
  out.attitude.assign(frames, Eigen::Vector4d(1, 0, 0, 0));
  std::vector<Eigen::Vector3d>& axis = out.axis;
  axis.assign(frames - 1, Eigen::Vector3d::Zero());
  for (int i = 1; i <= n + 1; ++i) {
    const auto f = static_cast<std::size_t>(i);
    const Eigen::Matrix3d previous = rotation_matrix(out.attitude[f - 1]);
    if (i <= n) {
      const auto j = static_cast<std::size_t>(i - 1);
      const Eigen::Vector4d tilted =
          quaternion_product(out.attitude[f - 1], about_x(chain.alpha[j]));
      out.attitude[f] = quaternion_product(tilted, about_z(q(i - 1)));
      axis[f] = rotation_matrix(tilted).col(2);  // RotZ(q_i) leaves the z axis where it is
      out.origin[f] = out.origin[f - 1] + chain.a[j] * previous.col(0) + chain.d[j] * axis[f];
    } else {
      out.attitude[f] = out.attitude[f - 1];
      out.origin[f] = out.origin[f - 1] + chain.flange_d * previous.col(2);
    }
  }
  if (!derivatives) {
    // An earlier call's derivatives are kept for their storage, but not another chain's, whose
    // sizes a reader would take for this one's.
    const bool fits = out.d_origin.size() == frames && out.d_attitude.size() == frames &&
                      out.d_origin[0].cols() == n;  // frames >= 2: the base and the flange
    if (!fits) {
      out.d_origin.clear();
      out.d_attitude.clear();
    }
    return;
  }
  // resize and setZero, not assign(count, Zero(3, n)): that builds its argument on the heap.
  out.d_origin.resize(frames);
  out.d_attitude.resize(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    out.d_origin[f].setZero(3, n);
    out.d_attitude[f].setZero(4, n);
  }
  for (int f = 1; f <= n + 1; ++f) {
    const auto frame = static_cast<std::size_t>(f);
    for (int j = 1; j <= std::min(f, n); ++j) {
      const Eigen::Vector3d& z = axis[static_cast<std::size_t>(j)];
      out.d_origin[frame].col(j - 1) =
          z.cross(out.origin[frame] - out.origin[static_cast<std::size_t>(j)]);
      out.d_attitude[frame].col(j - 1) =
          0.5 * quaternion_product(Eigen::Vector4d(0.0, z.x(), z.y(), z.z()), out.attitude[frame]);
    }
  }
}

AttachedPoseDerivatives attached_pose_derivatives(const ChainFrames& frames, int frame,
                                                  const Eigen::Vector3d& position,
                                                  const Eigen::Vector4d& attitude,
                                                  const Eigen::Matrix<double, 7, 1>& gradient) {
  const int n = static_cast<int>(frames.axis.size()) - 1;
  const auto pure = [](const Eigen::Vector3d& v) {
    return Eigen::Vector4d(0.0, v.x(), v.y(), v.z());
  };
  AttachedPoseDerivatives out;
  out.jacobian = Eigen::Matrix<double, 7, Eigen::Dynamic>::Zero(7, n);
  out.curvature = Eigen::MatrixXd::Zero(n, n);
  const int moving = std::min(frame, n);  // joints 1 .. moving turn the frame
  for (int j = 1; j <= moving; ++j) {
    const Eigen::Vector3d& z_j = frames.axis[static_cast<std::size_t>(j)];
    const Eigen::Vector3d lever = position - frames.origin[static_cast<std::size_t>(j)];
    const Eigen::Vector4d turned = quaternion_product(pure(z_j), attitude);
    out.jacobian.col(j - 1) << z_j.cross(lever), 0.5 * turned;
    for (int i = 1; i <= j; ++i) {
      const Eigen::Vector3d& z_i = frames.axis[static_cast<std::size_t>(i)];
      const double value = gradient.head<3>().dot(z_i.cross(z_j.cross(lever))) +
                           0.25 * gradient.tail<4>().dot(quaternion_product(pure(z_i), turned));
      out.curvature(i - 1, j - 1) = out.curvature(j - 1, i - 1) = value;
    }
  }
  return out;
}

}  // namespace diffpills::trajopt
