#include "diffpills/qp/box_active_set.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace diffpills::qp {
namespace {

// det P <= kSingular * P11 * P22 means the two columns of F (P = F'F) are parallel to within an
// angle of 1e-6 rad: sin^2 <= 1e-12. Treating such P as singular changes the optimal cost by at
// most ~1e-12 of P's scale (the cost varies by sin^2 * |F|^2 along the near-null direction).
constexpr double kSingular = 1e-12;

double cost(const Eigen::Matrix2d& P, const Eigen::Vector2d& c, const Eigen::Vector2d& x) {
  return 0.5 * x.dot(P * x) + c.dot(x);
}

// argmin over t in [0, 1] of 1/2 a t^2 + b t, a >= 0; the midpoint where the cost is flat.
double minimize_on_unit_interval(double a, double b, double scale) {
  if (a > 0.0) {
    return std::clamp(-b / a, 0.0, 1.0);
  }
  if (std::abs(b) <= 1e-15 * scale) {
    return 0.5;
  }
  return b > 0.0 ? 0.0 : 1.0;
}

}  // namespace

BoxQpResult solve_box_qp(const Eigen::Matrix2d& P, const Eigen::Vector2d& c) {
  if (!P.allFinite() || !c.allFinite()) {
    throw std::invalid_argument("box_qp: P and c must be finite");
  }
  const double scale = P.cwiseAbs().maxCoeff() + c.cwiseAbs().maxCoeff();
  const double det = P(0, 0) * P(1, 1) - P(0, 1) * P(1, 0);
  const bool invertible = det > kSingular * P(0, 0) * P(1, 1) && det > 0.0;

  BoxQpResult result;
  if (P.isZero(0.0)) {
    // A linear cost separates: each variable goes to the bound its slope favours, or to the
    // middle of [0, 1] where it does not matter.
    result.x << minimize_on_unit_interval(0.0, c(0), scale),
        minimize_on_unit_interval(0.0, c(1), scale);
    result.lambda = recover_box_duals(result.x, P, c);
    return result;
  }
  if (invertible) {
    // Algorithm 1, line 2, plus one step of iterative refinement: near the parallel threshold
    // det P = P11 P22 - P12^2 cancels to a relative accuracy of eps / (det / P11 P22), and the
    // resulting error in x lies along x itself, not along P's weak direction, so it shows in the
    // cost (measured: 4e-12 relative at an angle of 1e-5 rad). The residual -c - P x is computed
    // accurately, and one correction with the same inverse squares the relative error away.
    const Eigen::Matrix2d inverse = P.inverse();
    Eigen::Vector2d unconstrained = -inverse * c;
    unconstrained += inverse * (-c - P * unconstrained);
    if ((unconstrained.array() >= 0.0).all() && (unconstrained.array() <= 1.0).all()) {
      result.x = unconstrained;
      result.lambda.setZero();
      return result;
    }
  }

  // The four sides (x1 = 1, x1 = 0, x2 = 1, x2 = 0: the paper's candidates 1-4, each minimized in
  // closed form along its side and clamped to it) and the four corners (candidates 5-8).
  std::array<Eigen::Vector2d, 8> candidates;
  for (int fixed = 0; fixed < 2; ++fixed) {
    const int free = 1 - fixed;
    for (int side = 0; side < 2; ++side) {
      const double value = side == 0 ? 1.0 : 0.0;
      Eigen::Vector2d x;
      x(fixed) = value;
      x(free) = minimize_on_unit_interval(P(free, free), P(free, fixed) * value + c(free), scale);
      candidates[2 * static_cast<std::size_t>(fixed) + static_cast<std::size_t>(side)] = x;
    }
  }
  candidates[4] = {0.0, 0.0};
  candidates[5] = {0.0, 1.0};
  candidates[6] = {1.0, 0.0};
  candidates[7] = {1.0, 1.0};

  std::array<double, 8> costs{};
  std::size_t best = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    costs[i] = cost(P, c, candidates[i]);
    if (costs[i] < costs[best]) {
      best = i;
    }
  }
  result.x = candidates[best];

  if (!invertible) {
    // The optimal set is a segment along P's null direction (for P = F'F with parallel columns
    // f1, f2 it is n = [|f2|, -sign(P12) |f1|]), each end on a side or a corner, so both ends are
    // among the candidates whose cost ties the best. Return the middle of those ties along n.
    const Eigen::Vector2d null_direction(
        std::sqrt(std::max(P(1, 1), 0.0)),
        -std::copysign(std::sqrt(std::max(P(0, 0), 0.0)), P(0, 1)));
    const double tie = 1e-12 * (scale + std::abs(costs[best]));
    Eigen::Vector2d low = result.x;
    Eigen::Vector2d high = result.x;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (costs[i] <= costs[best] + tie) {
        const double along = null_direction.dot(candidates[i]);
        if (along < null_direction.dot(low)) low = candidates[i];
        if (along > null_direction.dot(high)) high = candidates[i];
      }
    }
    result.x = 0.5 * (low + high);
  }
  result.lambda = recover_box_duals(result.x, P, c);
  return result;
}

Eigen::Vector4d recover_box_duals(const Eigen::Vector2d& x, const Eigen::Matrix2d& P,
                                  const Eigen::Vector2d& c) {
  // Stationarity P x + c + lambda_upper - lambda_lower = 0, so y = -Px - c is the net push of the
  // bounds: positive pushes toward 1 (upper bound active), negative toward 0.
  const Eigen::Vector2d y = -P * x - c;
  const double eps = 1e-12 * (1.0 + P.cwiseAbs().maxCoeff() + c.cwiseAbs().maxCoeff());
  Eigen::Vector4d lambda = Eigen::Vector4d::Zero();
  for (int i = 0; i < 2; ++i) {
    if (y(i) >= eps && x(i) == 1.0) {
      lambda(i) = y(i);
    }
    if (y(i) <= -eps && x(i) == 0.0) {
      lambda(2 + i) = -y(i);
    }
  }
  return lambda;
}

}  // namespace diffpills::qp
