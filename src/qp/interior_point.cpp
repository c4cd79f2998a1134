#include "diffpills/qp/interior_point.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace diffpills::qp {
namespace {

double inf_norm(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>();
}

void require_finite(const Eigen::MatrixXd& m, const char* name) {
  if (!m.allFinite()) {
    throw std::invalid_argument(std::string("qp.") + name + ": must be finite");
  }
}

}  // namespace

const char* to_string(Status status) {
  switch (status) {
    case Status::kSolved:
      return "solved";
    case Status::kMaxIterations:
      return "max_iterations";
    case Status::kNumericalFailure:
      return "numerical_failure";
  }
  return "unknown";
}

InteriorPointSolver::InteriorPointSolver(const InteriorPointSettings& settings)
    : settings_(settings) {}

// Factor K = P + G'WG. If rounding makes K lose definiteness (W spans ~1e12 near convergence),
// a diagonal shift relative to K's size is added, growing tenfold up to 1e-6: small enough to
// leave the Newton direction a descent direction, large enough to restore a factorization.
bool InteriorPointSolver::factor(const Eigen::MatrixXd& P) {
  kkt_ = P;
  kkt_.noalias() += G_.transpose() * w_.asDiagonal() * G_;
  llt_.compute(kkt_);
  const double size = 1.0 + kkt_.diagonal().cwiseAbs().maxCoeff();
  for (double shift = 1e-14; llt_.info() != Eigen::Success && shift <= 1e-6; shift *= 10.0) {
    Eigen::MatrixXd shifted = kkt_;
    shifted.diagonal().array() += shift * size;
    llt_.compute(shifted);
  }
  return llt_.info() == Eigen::Success;
}

// Appendix B, derived for the right-hand side (v1, v2, v3) of
//   P dx + G' dl = v1,   lambda o ds + s o dl = v2,   G dx + ds = v3.
// The third row gives ds = v3 - G dx, the second dl = (v2 - lambda o ds) / s, and substituting
// both in the first leaves one positive definite system:
//   (P + G'WG) dx = v1 + G'W (v3 - v2 / lambda),   W = D(lambda / s).
void InteriorPointSolver::solve_newton(const Eigen::VectorXd& v1, const Eigen::VectorXd& v2,
                                       const Eigen::VectorXd& v3, Direction& out) const {
  const Eigen::VectorXd rhs =
      v1 + G_.transpose() * (w_.array() * (v3.array() - v2.array() / lambda_.array())).matrix();
  out.x = llt_.solve(rhs);
  out.s = v3 - G_ * out.x;
  out.lambda = ((v2.array() - lambda_.array() * out.s.array()) / s_.array()).matrix();
}

// The largest alpha in [0, 1] keeping s + alpha ds >= 0 and lambda + alpha dl >= 0.
double InteriorPointSolver::step_to_boundary(const Direction& direction) const {
  double alpha = 1.0;
  for (Eigen::Index i = 0; i < s_.size(); ++i) {
    if (direction.s(i) < 0.0) {
      alpha = std::min(alpha, -s_(i) / direction.s(i));
    }
    if (direction.lambda(i) < 0.0) {
      alpha = std::min(alpha, -lambda_(i) / direction.lambda(i));
    }
  }
  return alpha;
}

void InteriorPointSolver::update_residuals(const Eigen::MatrixXd& P, const Eigen::VectorXd& c,
                                           const Eigen::VectorXd& h) {
  r_dual_ = P * x_ + c + G_.transpose() * lambda_;
  r_primal_ = G_ * x_ + s_ - h;
}

// Active-set polish (see the header): with A = {i : lambda_i > s_i}, solve
//   [ P    G_A' ] [ dx       ]   [ -(P x + c)  ]
//   [ G_A  0    ] [ lambda_A ] = [ h_A - G_A x ]
// by a complete orthogonal decomposition, which returns the minimum-norm solution when the
// minimizer is not unique or active rows are dependent, and accept x + dx if it is a KKT point.
// At a degenerate vertex (more active rows than variables) the multipliers are not unique and
// the minimum-norm ones may have a negative entry although nonnegative ones exist; the row with
// the most negative multiplier is then dropped and the system solved again, as an active-set
// method would, up to once per guessed row.
bool InteriorPointSolver::try_polish(const Eigen::MatrixXd& P, const Eigen::VectorXd& c,
                                     const Eigen::VectorXd& h) {
  const Eigen::Index n = x_.size();
  std::vector<Eigen::Index> active;
  for (Eigen::Index i = 0; i < s_.size(); ++i) {
    if (lambda_(i) > s_(i)) {
      active.push_back(i);
    }
  }
  const double tolerance = settings_.polish_tolerance;
  while (true) {
    const auto k = static_cast<Eigen::Index>(active.size());
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(n + k, n + k);
    Eigen::VectorXd rhs(n + k);
    kkt.topLeftCorner(n, n) = P;
    rhs.head(n) = -(P * x_ + c);
    for (Eigen::Index j = 0; j < k; ++j) {
      const Eigen::Index row = active[static_cast<std::size_t>(j)];
      kkt.block(n + j, 0, 1, n) = G_.row(row);
      kkt.block(0, n + j, n, 1) = G_.row(row).transpose();
      rhs(n + j) = h(row) - G_.row(row).dot(x_);
    }
    const Eigen::VectorXd solution = kkt.completeOrthogonalDecomposition().solve(rhs);
    if (!solution.allFinite() ||
        inf_norm(kkt * solution - rhs) > tolerance * (1.0 + inf_norm(rhs) + inf_norm(c))) {
      return false;  // the guessed active set admits no KKT point
    }
    const Eigen::VectorXd x = x_ + solution.head(n);
    const Eigen::VectorXd slack = h - G_ * x;
    if (slack.minCoeff() < -tolerance * (1.0 + inf_norm(h))) {
      return false;  // a constraint left out of the guess is violated
    }
    Eigen::Index most_negative = -1;
    for (Eigen::Index j = 0; j < k; ++j) {
      if (solution(n + j) < -tolerance * (1.0 + inf_norm(c)) &&
          (most_negative < 0 || solution(n + j) < solution(n + most_negative))) {
        most_negative = j;
      }
    }
    if (most_negative >= 0) {
      active.erase(active.begin() + most_negative);  // a row in the guess pushes the wrong way
      continue;
    }
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(s_.size());
    for (Eigen::Index j = 0; j < k; ++j) {
      lambda(active[static_cast<std::size_t>(j)]) = std::max(solution(n + j), 0.0);
    }
    result_.x = x;
    result_.s = slack.cwiseMax(0.0);
    result_.lambda = lambda;
    result_.polished = true;
    result_.primal_residual = inf_norm(G_ * x + result_.s - h);
    result_.dual_residual = inf_norm(P * x + c + G_.transpose() * lambda);
    result_.complementarity = result_.s.dot(lambda) / static_cast<double>(s_.size());
    return true;
  }
}

const InteriorPointResult& InteriorPointSolver::solve(const Eigen::MatrixXd& P,
                                                      const Eigen::VectorXd& c,
                                                      const Eigen::MatrixXd& G,
                                                      const Eigen::VectorXd& h) {
  const Eigen::Index n = P.rows();
  const Eigen::Index m = G.rows();
  if (P.cols() != n || c.size() != n || G.cols() != n || h.size() != m || n == 0 || m == 0) {
    throw std::invalid_argument("qp: sizes must be P n x n, c n, G m x n, h m with n, m >= 1");
  }
  require_finite(P, "P");
  require_finite(c, "c");
  require_finite(G, "G");
  require_finite(h, "h");

  result_ = InteriorPointResult{};
  G_ = G;
  const double h_scale = 1.0 + inf_norm(h);
  const double c_scale = 1.0 + inf_norm(c);

  // Start (CVXOPT's coneqp): x minimizes 1/2 x'Px + c'x + 1/2 |Gx - h|^2, then s = h - Gx and
  // lambda = Gx - h, each shifted by 1 + its most negative entry if not already positive.
  w_ = Eigen::VectorXd::Ones(m);
  if (!factor(P)) {
    result_.status = Status::kNumericalFailure;
    return result_;
  }
  x_ = llt_.solve(G.transpose() * h - c);
  s_ = h - G * x_;
  lambda_ = -s_;
  if (s_.minCoeff() <= 0.0) s_.array() += 1.0 - s_.minCoeff();
  if (lambda_.minCoeff() <= 0.0) lambda_.array() += 1.0 - lambda_.minCoeff();

  result_.status = Status::kMaxIterations;
  for (int iteration = 0; iteration <= settings_.max_iterations; ++iteration) {
    update_residuals(P, c, h);
    const double mu = s_.dot(lambda_) / static_cast<double>(m);
    const double objective = 0.5 * x_.dot(P * x_) + c.dot(x_);
    const double error = std::max({inf_norm(r_primal_) / h_scale, inf_norm(r_dual_) / c_scale,
                                   mu / (1.0 + std::abs(objective))});
    result_.iterations = iteration;
    if (settings_.polish && error <= settings_.polish_threshold && try_polish(P, c, h)) {
      result_.status = Status::kSolved;
      break;
    }
    if (error <= settings_.tolerance) {
      result_.status = Status::kSolved;
      break;
    }
    if (iteration == settings_.max_iterations) {
      break;
    }
    w_ = (lambda_.array() / s_.array()).matrix();
    if (!factor(P)) {
      result_.status = Status::kNumericalFailure;
      break;
    }
    // Predictor: the pure Newton (affine-scaling) direction, eq. (pdip:affine).
    solve_newton(-r_dual_, -(s_.array() * lambda_.array()).matrix(), -r_primal_, affine_);
    const double alpha_affine = step_to_boundary(affine_);
    const double mu_affine =
        (s_ + alpha_affine * affine_.s).dot(lambda_ + alpha_affine * affine_.lambda) /
        static_cast<double>(m);
    const double sigma = std::pow(mu_affine / mu, 3);  // Mehrotra's centering heuristic
    // Corrector: centering plus the second-order term, eq. (pdip:cc), same factorization.
    const Eigen::VectorXd centering =
        (sigma * mu - affine_.s.array() * affine_.lambda.array()).matrix();
    solve_newton(Eigen::VectorXd::Zero(n), centering, Eigen::VectorXd::Zero(m), corrector_);
    affine_.x += corrector_.x;
    affine_.s += corrector_.s;
    affine_.lambda += corrector_.lambda;
    // 0.99 of the way to the boundary keeps the iterate strictly interior.
    double alpha = std::min(1.0, 0.99 * step_to_boundary(affine_));
    // Safeguard. For a QP the step's second-order term ds'dl = dx'P dx is never negative, so a
    // long Mehrotra step can raise the mean complementarity, and the next step undo it: seen as
    // a two-cycle with mu frozen near 0.1 on a random 5-variable QP. Once the iterate is
    // feasible to 1e-6 (relative) and only mu is left to drive down, the step is halved until mu
    // decreases by at least 1% of the step, which breaks the cycle. Earlier, while the residuals
    // are still being removed, mu may legitimately rise and the step is left alone.
    if (std::max(inf_norm(r_primal_) / h_scale, inf_norm(r_dual_) / c_scale) <= 1e-6) {
      for (int halving = 0; halving < 30; ++halving) {
        const double mu_next =
            (s_ + alpha * affine_.s).dot(lambda_ + alpha * affine_.lambda) / static_cast<double>(m);
        if (mu_next <= (1.0 - 0.01 * alpha) * mu) break;
        alpha *= 0.5;
      }
    }
    x_ += alpha * affine_.x;
    s_ += alpha * affine_.s;
    lambda_ += alpha * affine_.lambda;
  }

  if (!result_.polished) {
    result_.x = x_;
    result_.s = s_;
    result_.lambda = lambda_;
    update_residuals(P, c, h);
    result_.primal_residual = inf_norm(r_primal_);
    result_.dual_residual = inf_norm(r_dual_);
    result_.complementarity = s_.dot(lambda_) / static_cast<double>(m);
  }
  // Leave a factorization for the backward pass (see the header for the choice of point).
  const double delta = 3e-10 * (1.0 + inf_norm(h));
  w_ = (result_.lambda.array().max(delta * delta) / result_.s.array().max(delta)).matrix();
  if (!factor(P) && result_.status == Status::kSolved) {
    result_.status = Status::kNumericalFailure;
  }
  return result_;
}

}  // namespace diffpills::qp
