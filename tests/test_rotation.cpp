// Rotation utilities against Eigen's quaternions and central differences.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "diffpills/rotation.hpp"
#include "unit_quaternion.hpp"

namespace diffpills {
namespace {

using Rng = std::mt19937_64;

Eigen::Vector4d random_quaternion(Rng& rng) {
  std::normal_distribution<double> normal;
  Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q * std::uniform_real_distribution<double>(0.3, 3.0)(rng) / q.norm();  // not unit
}

Eigen::Vector3d random_vector(Rng& rng) {
  std::normal_distribution<double> normal;
  return {normal(rng), normal(rng), normal(rng)};
}

template <class Function>
Eigen::Matrix<double, 3, 4> differences(const Function& f, const Eigen::Vector4d& q) {
  Eigen::Matrix<double, 3, 4> out;
  for (int j = 0; j < 4; ++j) {
    const double step = 1e-6;
    Eigen::Vector4d plus = q, minus = q;
    plus(j) += step;
    minus(j) -= step;
    out.col(j) = (f(plus) - f(minus)) / (2 * step);
  }
  return out;
}

TEST(Rotation, MatchesEigenQuaternionForNonUnitInput) {
  Rng rng(1);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector4d q = random_quaternion(rng);
    const Eigen::Quaterniond eigen(q(0), q(1), q(2), q(3));
    const Eigen::Matrix3d R = rotation_matrix(q);
    EXPECT_LE((R - eigen.normalized().toRotationMatrix()).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  }
}

TEST(Rotation, JacobiansMatchCentralDifferences) {
  Rng rng(2);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector4d q = random_quaternion(rng);
    const Eigen::Vector3d v = random_vector(rng);
    const auto rotate = [&](const Eigen::Vector4d& p) {
      return Eigen::Vector3d(rotation_matrix(p) * v);
    };
    const auto rotate_back = [&](const Eigen::Vector4d& p) {
      return Eigen::Vector3d(rotation_matrix(p).transpose() * v);
    };
    EXPECT_LE((rotate_jacobian(q, v) - differences(rotate, q)).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_LE((rotate_transpose_jacobian(q, v) - differences(rotate_back, q)).cwiseAbs().maxCoeff(),
              1e-8);
    // Normalization is built in: no sensitivity along q itself.
    EXPECT_LE((rotate_jacobian(q, v) * q).norm(), 1e-12 * v.norm());
    // The gradient of w . Q v is w' times the Jacobian, formed without it.
    const Eigen::Vector3d w = random_vector(rng);
    EXPECT_LE((rotate_gradient(q, v, w) - rotate_jacobian(q, v).transpose() * w).norm(),
              1e-12 * (1 + v.norm() * w.norm()) / q.norm());
  }
}

// The Hessian of w . Q(q / |q|) v: central differences of its gradient (computed with Eigen's
// quaternion here, not rotate_gradient), symmetric, and with q itself in its null space's
// complement (G is of degree 0: hess q = -grad, by Euler's theorem for the gradient).
TEST(Rotation, HessianMatchesCentralDifferencesOfTheGradient) {
  Rng rng(5);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector4d q = random_quaternion(rng);
    const Eigen::Vector3d v = random_vector(rng), w = random_vector(rng);
    const auto value = [&](const Eigen::Vector4d& p) {
      const Eigen::Quaterniond eigen(p(0), p(1), p(2), p(3));
      return w.dot(eigen.normalized() * v);
    };
    const auto gradient = [&](const Eigen::Vector4d& p) {
      Eigen::Vector4d out;
      for (int j = 0; j < 4; ++j) {
        const double step = 1e-5;
        Eigen::Vector4d plus = p, minus = p;
        plus(j) += step;
        minus(j) -= step;
        out(j) = (value(plus) - value(minus)) / (2 * step);
      }
      return out;
    };
    const Eigen::Matrix4d H = rotate_hessian(q, v, w);
    Eigen::Matrix4d numeric;
    for (int j = 0; j < 4; ++j) {
      const double step = 1e-4;
      Eigen::Vector4d plus = q, minus = q;
      plus(j) += step;
      minus(j) -= step;
      numeric.col(j) = (gradient(plus) - gradient(minus)) / (2 * step);
    }
    const double size = v.norm() * w.norm() / q.squaredNorm();
    EXPECT_LE((H - numeric).cwiseAbs().maxCoeff(), 1e-5 * (1 + size)) << i;
    EXPECT_LE((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-13 * size);
    EXPECT_LE((H * q + rotate_gradient(q, v, w)).norm(), 1e-12 * (1 + size * q.norm()));
  }
}

// The product three ways (left and right multiplication matrices, quaternion_product) against
// Eigen's product; quaternion_product as a composition of rotations, Q(q (x) p) = Q(q) Q(p) (the
// scene composes a primitive's attitude on its body's so); and the attitude Jacobian.
TEST(Rotation, QuaternionProductsAndAttitudeJacobian) {
  Rng rng(3);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector4d q = random_quaternion(rng);
    const Eigen::Vector4d p = random_quaternion(rng);
    const Eigen::Quaterniond product =
        Eigen::Quaterniond(q(0), q(1), q(2), q(3)) * Eigen::Quaterniond(p(0), p(1), p(2), p(3));
    const Eigen::Vector4d expected(product.w(), product.x(), product.y(), product.z());
    EXPECT_LE((left_multiply_matrix(q) * p - expected).norm(), 1e-13);
    EXPECT_LE((right_multiply_matrix(p) * q - expected).norm(), 1e-13);  // Eigen's product
    const Eigen::Vector4d qp = quaternion_product(q, p);
    EXPECT_LE((qp - expected).norm(), 1e-13 * q.norm() * p.norm());
    EXPECT_LE((rotation_matrix(qp) - rotation_matrix(q) * rotation_matrix(p)).cwiseAbs().maxCoeff(),
              1e-14);
    // R(p)' q = q (x) p*, which the scene's chain rule takes through a composed attitude.
    const Eigen::Vector4d conjugate(p(0), -p(1), -p(2), -p(3));
    EXPECT_LE((quaternion_product(q, conjugate) - right_multiply_matrix(p).transpose() * q).norm(),
              1e-13 * q.norm() * p.norm());
    // rotation_matrix builds the matrix alone, with the same bits as the attitude the scene and
    // the pairs keep (their broadphase boxes and world poses must agree exactly).
    EXPECT_EQ(rotation_matrix(q), detail::UnitQuaternion(q).matrix());
    // dq/dtheta of q (x) [1, theta/2] is 1/2 G(q).
    const Eigen::Matrix<double, 4, 3> G = attitude_jacobian(q);
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector4d bump = Eigen::Vector4d::UnitX();  // [1, 0, 0, 0]
      bump(1 + j) = 0.5 * 1e-6;
      Eigen::Vector4d back = Eigen::Vector4d::UnitX();
      back(1 + j) = -0.5 * 1e-6;
      const Eigen::Vector4d fd =
          (left_multiply_matrix(q) * bump - left_multiply_matrix(q) * back) / 2e-6;
      EXPECT_LE((0.5 * G.col(j) - fd).norm(), 1e-9);
    }
  }
}

// attitude_gradient is built on the product matrices of q as given, yet it is the gradient along
// the body-frame rotation q (x) exp(theta) for a non-unit q too, and the same for every scaling
// of q: a dphi/dq that includes the normalization scales as 1 / |q| (rotation.hpp).
TEST(Rotation, AttitudeGradientOfANonUnitQuaternion) {
  Rng rng(5);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector4d q = random_quaternion(rng);
    const Eigen::Vector3d v = random_vector(rng), w = random_vector(rng);
    const Eigen::Vector3d reduced = attitude_gradient(q, rotate_gradient(q, v, w));
    for (const double factor : {1e-3, 0.37, 3.1, 1e3}) {
      const Eigen::Vector4d scaled = factor * q;
      const Eigen::Vector3d of_scaled = attitude_gradient(scaled, rotate_gradient(scaled, v, w));
      EXPECT_LE((of_scaled - reduced).norm(), 1e-13 * (1 + reduced.norm())) << i << " " << factor;
    }
    // Central differences of w . Q(q (x) exp(theta)) v over theta, q (x) exp(theta) not unit.
    const auto phi = [&](int axis, double angle) {
      const Eigen::Quaterniond turned =
          Eigen::Quaterniond(q(0), q(1), q(2), q(3)) *
          Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis)));
      return w.dot(
          rotation_matrix(Eigen::Vector4d(turned.w(), turned.x(), turned.y(), turned.z())) * v);
    };
    for (int j = 0; j < 3; ++j) {
      const double step = 1e-6;
      const double numeric = (phi(j, step) - phi(j, -step)) / (2 * step);
      EXPECT_NEAR(reduced(j), numeric, 1e-8 * (1 + v.norm() * w.norm())) << i << " " << j;
    }
  }
}

TEST(Rotation, ModifiedRodriguesParametersRoundTrip) {
  Rng rng(4);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector4d q = random_quaternion(rng);
    const Eigen::Vector3d p = quaternion_to_mrp(q);
    EXPECT_LE(p.norm(), 1.0 + 1e-15);  // shadow set chosen
    const Eigen::Vector4d back = mrp_to_quaternion(p);
    EXPECT_NEAR(back.norm(), 1.0, 1e-14);
    // Same attitude: q and back agree up to sign.
    const Eigen::Vector4d unit = q.normalized();
    EXPECT_LE(std::min((back - unit).norm(), (back + unit).norm()), 1e-13);
    EXPECT_LE((rotation_matrix(back) - rotation_matrix(q)).cwiseAbs().maxCoeff(), 1e-13);
    // Jacobian of the conversion.
    Eigen::Matrix<double, 4, 3> fd;
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector3d plus = p, minus = p;
      plus(j) += 1e-6;
      minus(j) -= 1e-6;
      fd.col(j) = (mrp_to_quaternion(plus) - mrp_to_quaternion(minus)) / 2e-6;
    }
    EXPECT_LE((mrp_to_quaternion_jacobian(p) - fd).cwiseAbs().maxCoeff(), 1e-8);
  }
  EXPECT_EQ(quaternion_to_mrp(Eigen::Vector4d(1, 0, 0, 0)), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace diffpills
