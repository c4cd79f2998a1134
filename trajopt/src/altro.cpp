#include "diffpills/trajopt/altro.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace diffpills::trajopt {

KnotConstraints Problem::constraints(int /*k*/, const Eigen::VectorXd& x,
                                     const Eigen::VectorXd& u) const {
  KnotConstraints none;
  none.value.resize(0);
  none.dx.resize(0, x.size());
  none.du.resize(0, u.size());
  return none;
}

void require_size(const Eigen::VectorXd& v, Eigen::Index size, const char* name) {
  if (v.size() != size) {
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(size) +
                                " entries, got " + std::to_string(v.size()));
  }
}

Eigen::MatrixXd Problem::dynamics_hessian(const Eigen::VectorXd&, const Eigen::VectorXd&,
                                          const Eigen::VectorXd&) const {
  throw std::logic_error("dynamics_hessian: this problem supplies no second derivatives");
}

Eigen::MatrixXd Problem::constraint_hessian(int, const Eigen::VectorXd&, const Eigen::VectorXd&,
                                            const Eigen::VectorXd&) const {
  throw std::logic_error("constraint_hessian: this problem supplies no second derivatives");
}

const char* to_string(AltroStatus status) {
  switch (status) {
    case AltroStatus::kSolved:
      return "solved";
    case AltroStatus::kMaxIterations:
      return "max_iterations";
    case AltroStatus::kRegularizationFailure:
      return "regularization_failure";
  }
  return "unknown";
}

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct Rollout {
  std::vector<VectorXd> x, u;
  std::vector<MatrixXd> A, B;  // dynamics Jacobians along the rollout
};

// The augmented Lagrangian's multipliers and penalty (one scalar penalty, as Altro.jl's default
// of a uniform initial penalty scaled together).
struct Multipliers {
  std::vector<VectorXd> lambda;  // per knot, one entry per constraint row
  double mu = 1.0;
};

// I_mu for one row: the penalty acts on equalities always, and on inequalities that are violated
// or already carry a multiplier; a satisfied inequality with lambda = 0 contributes nothing.
double penalty_weight(const KnotConstraints& c, Eigen::Index row, double lambda, double mu) {
  return (row < c.equalities || c.value(row) > 0.0 || lambda > 0.0) ? mu : 0.0;
}

Eigen::VectorXd penalty_weights(const KnotConstraints& c, const VectorXd& lambda, double mu) {
  VectorXd w(c.value.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) w(i) = penalty_weight(c, i, lambda(i), mu);
  return w;
}

double violation(const KnotConstraints& c) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < c.value.size(); ++i) {
    worst = std::max(worst, i < c.equalities ? std::abs(c.value(i)) : c.value(i));
  }
  return worst;
}

class Solver {
 public:
  Solver(const Problem& problem, const AltroSettings& settings)
      : problem_(problem),
        settings_(settings),
        n_(problem.knots()),
        rho_(settings.regularization_initial) {}

  AltroResult run(const VectorXd& x0, const std::vector<VectorXd>& controls);

 private:
  const VectorXd& control(const Rollout& r, int k) const { return k < n_ - 1 ? r.u[k] : empty_; }
  void rollout(const VectorXd& x0, Rollout& r) const;
  double problem_cost(const Rollout& r) const;
  double augmented_cost(const Rollout& r) const;
  double max_violation(const Rollout& r) const;
  bool backward_pass(const Rollout& r);
  bool forward_pass(const VectorXd& x0, Rollout& r, double& cost);
  void update_multipliers(const Rollout& r);
  double total_violation(const VectorXd& x0, const Rollout& r) const;
  int polish(const VectorXd& x0, Rollout& r) const;
  // rho <- rho * growth after a failed factorization or line search; false once past the cap.
  bool grow_regularization() {
    rho_ = std::max(rho_ * settings_.regularization_growth, settings_.regularization_min);
    return rho_ <= settings_.regularization_max;
  }

  const Problem& problem_;
  const AltroSettings& settings_;
  const int n_;
  const VectorXd empty_;
  Multipliers multipliers_;
  double rho_;
  std::vector<MatrixXd> K_;
  std::vector<VectorXd> d_;
  Rollout candidate_;  // the line search's trial, kept to reuse its storage across iterations
  double expected_linear_ = 0.0, expected_quadratic_ = 0.0;
  int iterations_ = 0;
};

void Solver::rollout(const VectorXd& x0, Rollout& r) const {
  r.x[0] = x0;
  for (int k = 0; k + 1 < n_; ++k) {
    problem_.dynamics(r.x[k], r.u[k], r.x[k + 1], r.A[k], r.B[k]);
  }
}

double Solver::problem_cost(const Rollout& r) const {
  double cost = problem_.terminal_cost_value(r.x[n_ - 1]);
  for (int k = 0; k + 1 < n_; ++k) cost += problem_.stage_cost_value(k, r.x[k], r.u[k]);
  return cost;
}

// J + sum_k lambda_k' c_k + 1/2 c_k' I_mu c_k.
double Solver::augmented_cost(const Rollout& r) const {
  double cost = problem_cost(r);
  for (int k = 0; k < n_; ++k) {
    const KnotConstraints c = problem_.constraint_values(k, r.x[k], control(r, k));
    const VectorXd w = penalty_weights(c, multipliers_.lambda[k], multipliers_.mu);
    cost += multipliers_.lambda[k].dot(c.value) + 0.5 * c.value.dot(w.cwiseProduct(c.value));
  }
  return cost;
}

double Solver::max_violation(const Rollout& r) const {
  double worst = 0.0;
  for (int k = 0; k < n_; ++k) {
    worst = std::max(worst, violation(problem_.constraint_values(k, r.x[k], control(r, k))));
  }
  return worst;
}

// iLQR backward pass on the augmented Lagrangian, Gauss-Newton in the constraints: with
// g = lambda + I_mu c the constraint terms add C'g to the gradients and C' I_mu C to the Hessians.
//   Qx = lx + A'Vx + Cx'g        Qxx = lxx + A'Vxx A + Cx' I Cx
//   Qu = lu + B'Vx + Cu'g        Quu = luu + B'Vxx B + Cu' I Cu
//   Qux = lux + B'Vxx A + Cu' I Cx
// K = -(Quu + rho I)^-1 Qux, d = -(Quu + rho I)^-1 Qu, and the value function
//   Vx = Qx + K'Quu d + K'Qu + Qux'd,   Vxx = Qxx + K'Quu K + K'Qux + Qux'K.
// The expected change for a step alpha d is alpha sum d'Qu + alpha^2 / 2 sum d'Quu d.
bool Solver::backward_pass(const Rollout& r) {
  const CostExpansion terminal = problem_.terminal_cost(r.x[n_ - 1]);
  const KnotConstraints last = problem_.constraints(n_ - 1, r.x[n_ - 1], empty_);
  const VectorXd last_w = penalty_weights(last, multipliers_.lambda[n_ - 1], multipliers_.mu);
  VectorXd Vx = terminal.x + last.dx.transpose() *
                                 (multipliers_.lambda[n_ - 1] + last_w.cwiseProduct(last.value));
  MatrixXd Vxx = terminal.xx + last.dx.transpose() * last_w.asDiagonal() * last.dx;
  expected_linear_ = expected_quadratic_ = 0.0;
  for (int k = n_ - 2; k >= 0; --k) {
    const CostExpansion l = problem_.stage_cost(k, r.x[k], r.u[k]);
    const KnotConstraints c = problem_.constraints(k, r.x[k], r.u[k]);
    const VectorXd w = penalty_weights(c, multipliers_.lambda[k], multipliers_.mu);
    const VectorXd g = multipliers_.lambda[k] + w.cwiseProduct(c.value);
    const MatrixXd& A = r.A[k];
    const MatrixXd& B = r.B[k];
    const VectorXd Qx = l.x + A.transpose() * Vx + c.dx.transpose() * g;
    const VectorXd Qu = l.u + B.transpose() * Vx + c.du.transpose() * g;
    const MatrixXd VxxA = Vxx * A;
    const MatrixXd Qxx = l.xx + A.transpose() * VxxA + c.dx.transpose() * w.asDiagonal() * c.dx;
    const MatrixXd Quu = l.uu + B.transpose() * Vxx * B + c.du.transpose() * w.asDiagonal() * c.du;
    const MatrixXd Qux = l.ux + B.transpose() * VxxA + c.du.transpose() * w.asDiagonal() * c.dx;
    MatrixXd regularized = Quu;
    regularized.diagonal().array() += rho_;
    const Eigen::LLT<MatrixXd> llt(regularized);
    if (llt.info() != Eigen::Success) return false;
    K_[k] = -llt.solve(Qux);
    d_[k] = -llt.solve(Qu);
    const MatrixXd& K = K_[k];
    const VectorXd& d = d_[k];
    Vx = Qx + K.transpose() * (Quu * d) + K.transpose() * Qu + Qux.transpose() * d;
    Vxx = Qxx + K.transpose() * Quu * K + K.transpose() * Qux + Qux.transpose() * K;
    Vxx = 0.5 * (Vxx + Vxx.transpose());
    expected_linear_ += d.dot(Qu);
    expected_quadratic_ += 0.5 * d.dot(Quu * d);
  }
  return true;
}

// Backtracking from alpha = 1: u = ubar + K (x - xbar) + alpha d, accepted when the actual over
// the expected decrease of the augmented cost lies in [line_search_lower, line_search_upper].
bool Solver::forward_pass(const VectorXd& x0, Rollout& r, double& cost) {
  Rollout& candidate = candidate_;
  double alpha = 1.0;
  for (int step = 0; step < settings_.line_search_steps; ++step, alpha *= 0.5) {
    candidate.x[0] = x0;
    for (int k = 0; k + 1 < n_; ++k) {
      candidate.u[k] = r.u[k] + K_[k] * (candidate.x[k] - r.x[k]) + alpha * d_[k];
      problem_.dynamics(candidate.x[k], candidate.u[k], candidate.x[k + 1], candidate.A[k],
                        candidate.B[k]);
    }
    const double new_cost = augmented_cost(candidate);
    const double expected = -(alpha * expected_linear_ + alpha * alpha * expected_quadratic_);
    const double ratio = (cost - new_cost) / expected;
    if (std::isfinite(new_cost) && expected > 0.0 && ratio >= settings_.line_search_lower &&
        ratio <= settings_.line_search_upper) {
      std::swap(r, candidate);  // the old rollout's storage becomes the next trial's
      cost = new_cost;
      return true;
    }
  }
  return false;
}

// lambda <- max(0, lambda + mu c) on inequalities, lambda + mu c on equalities; mu <- 10 mu.
void Solver::update_multipliers(const Rollout& r) {
  for (int k = 0; k < n_; ++k) {
    const KnotConstraints c = problem_.constraint_values(k, r.x[k], control(r, k));
    VectorXd& lambda = multipliers_.lambda[k];
    for (Eigen::Index i = 0; i < lambda.size(); ++i) {
      lambda(i) += multipliers_.mu * c.value(i);
      if (i >= c.equalities) lambda(i) = std::max(0.0, lambda(i));
    }
  }
  multipliers_.mu = std::min(multipliers_.mu * settings_.penalty_scaling, settings_.penalty_max);
}

// The largest violation of anything the solution must satisfy: the problem's constraints, the
// initial state and the dynamics (exact after a rollout, not after a polish).
double Solver::total_violation(const VectorXd& x0, const Rollout& r) const {
  double worst = std::max(max_violation(r), (r.x[0] - x0).lpNorm<Eigen::Infinity>());
  for (int k = 0; k + 1 < n_; ++k) {
    VectorXd next;
    MatrixXd A, B;
    problem_.dynamics(r.x[k], r.u[k], next, A, B);
    worst = std::max(worst, (r.x[k + 1] - next).lpNorm<Eigen::Infinity>());
  }
  return worst;
}

// Projected Newton on z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}]: with c(z) the stacked active
// constraints (x_0 - x0, x_{k+1} - f(x_k, u_k), equalities, inequalities that carry a multiplier
// or are violated) and D = dc/dz, the minimum-norm Gauss-Newton step to c + D dz = 0 is
//   dz = -D'(D D')^-1 c.
// D D' is banded (each dynamics row touches two knots); Eigen's sparse LDLT factors it, with a
// diagonal shift of 1e-12 of its size in case active rows are dependent. A step is taken whole or
// halved up to five times, and only if it lowers total_violation. Returns the accepted steps.
int Solver::polish(const VectorXd& x0, Rollout& r) const {
  const int nx = problem_.state_size();
  const int nu = problem_.control_size();
  const auto x_index = [&](int k) { return static_cast<Eigen::Index>(k) * nx; };
  const auto u_index = [&](int k) {
    return static_cast<Eigen::Index>(n_) * nx + static_cast<Eigen::Index>(k) * nu;
  };
  const Eigen::Index variables = u_index(n_ - 1);
  int accepted = 0;
  for (int iteration = 0; iteration < settings_.polish_iterations; ++iteration) {
    const double current = total_violation(x0, r);
    if (current <= settings_.polish_tolerance) break;
    std::vector<Eigen::Triplet<double>> entries;
    std::vector<double> values;
    const auto add_row = [&](double value) {
      values.push_back(value);
      return static_cast<Eigen::Index>(values.size()) - 1;
    };
    for (int i = 0; i < nx; ++i) {
      entries.emplace_back(add_row(r.x[0](i) - x0(i)), x_index(0) + i, 1.0);
    }
    for (int k = 0; k + 1 < n_; ++k) {
      VectorXd next;
      MatrixXd A, B;
      problem_.dynamics(r.x[k], r.u[k], next, A, B);
      for (int i = 0; i < nx; ++i) {
        const Eigen::Index row = add_row(r.x[k + 1](i) - next(i));
        entries.emplace_back(row, x_index(k + 1) + i, 1.0);
        for (int j = 0; j < nx; ++j) entries.emplace_back(row, x_index(k) + j, -A(i, j));
        for (int j = 0; j < nu; ++j) entries.emplace_back(row, u_index(k) + j, -B(i, j));
      }
    }
    for (int k = 0; k < n_; ++k) {
      const KnotConstraints c = problem_.constraints(k, r.x[k], control(r, k));
      for (Eigen::Index i = 0; i < c.value.size(); ++i) {
        if (i >= c.equalities && c.value(i) <= 0.0 && multipliers_.lambda[k](i) <= 0.0) continue;
        const Eigen::Index row = add_row(c.value(i));
        for (int j = 0; j < nx; ++j) entries.emplace_back(row, x_index(k) + j, c.dx(i, j));
        for (Eigen::Index j = 0; j < c.du.cols(); ++j) {
          entries.emplace_back(row, u_index(k) + j, c.du(i, j));
        }
      }
    }
    const auto rows = static_cast<Eigen::Index>(values.size());
    Eigen::SparseMatrix<double> D(rows, variables);
    D.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseMatrix<double> normal = D * D.transpose();
    double size = 0.0;
    for (Eigen::Index i = 0; i < rows; ++i) size = std::max(size, normal.coeff(i, i));
    for (Eigen::Index i = 0; i < rows; ++i) normal.coeffRef(i, i) += 1e-12 * (1.0 + size);
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
    if (ldlt.info() != Eigen::Success) break;
    const VectorXd step =
        -(D.transpose() * ldlt.solve(Eigen::Map<const VectorXd>(values.data(), rows))).eval();
    bool improved = false;
    for (double fraction = 1.0; fraction > 0.03 && !improved; fraction *= 0.5) {
      Rollout trial = r;
      for (int k = 0; k < n_; ++k) trial.x[k] += fraction * step.segment(x_index(k), nx);
      for (int k = 0; k + 1 < n_; ++k) trial.u[k] += fraction * step.segment(u_index(k), nu);
      if (total_violation(x0, trial) < current) {
        r = std::move(trial);
        improved = true;
      }
    }
    if (!improved) break;
    ++accepted;
  }
  return accepted;
}

AltroResult Solver::run(const VectorXd& x0, const std::vector<VectorXd>& controls) {
  const int nx = problem_.state_size();
  const int nu = problem_.control_size();
  if (n_ < 2 || x0.size() != nx || static_cast<int>(controls.size()) != n_ - 1) {
    throw std::invalid_argument("trajopt: need x0 of size " + std::to_string(nx) + " and " +
                                std::to_string(n_ - 1) + " initial controls");
  }
  for (const VectorXd& u : controls) {
    if (u.size() != nu || !u.allFinite()) {
      throw std::invalid_argument("trajopt: every initial control must have " + std::to_string(nu) +
                                  " finite entries");
    }
  }
  Rollout r{std::vector<VectorXd>(n_), controls, std::vector<MatrixXd>(n_ - 1),
            std::vector<MatrixXd>(n_ - 1)};
  rollout(x0, r);
  candidate_ = r;
  K_.assign(n_ - 1, MatrixXd());
  d_.assign(n_ - 1, VectorXd());
  multipliers_.mu = settings_.penalty_initial;
  multipliers_.lambda.resize(n_);
  for (int k = 0; k < n_; ++k) {
    multipliers_.lambda[k] =
        VectorXd::Zero(problem_.constraints(k, r.x[k], control(r, k)).value.size());
  }

  AltroResult result;
  result.status = AltroStatus::kMaxIterations;
  for (int outer = 0; outer < settings_.max_outer_iterations; ++outer) {
    result.outer_iterations = outer + 1;
    double cost = augmented_cost(r);
    bool converged = false;
    for (int inner = 0;
         inner < settings_.max_inner_iterations && iterations_ < settings_.max_total_iterations;
         ++inner) {
      ++iterations_;
      if (!backward_pass(r)) {
        if (!grow_regularization()) {
          result.status = AltroStatus::kRegularizationFailure;
          break;
        }
        continue;
      }
      // Converged when the predicted decrease, or the largest feedforward step, is negligible.
      double step = 0.0;
      for (int k = 0; k + 1 < n_; ++k) {
        step = std::max(step,
                        d_[k].lpNorm<Eigen::Infinity>() / (1.0 + r.u[k].lpNorm<Eigen::Infinity>()));
      }
      if (-expected_linear_ < settings_.cost_tolerance * (1.0 + std::abs(cost)) ||
          step < settings_.gradient_tolerance) {
        converged = true;
        break;
      }
      const double before = cost;
      if (!forward_pass(x0, r, cost)) {
        if (!grow_regularization()) {
          result.status = AltroStatus::kRegularizationFailure;
          break;
        }
        continue;
      }
      rho_ = std::max(rho_ / settings_.regularization_growth, settings_.regularization_min);
      if (before - cost < settings_.cost_tolerance * (1.0 + std::abs(before))) {
        converged = true;
        break;
      }
    }
    if (result.status == AltroStatus::kRegularizationFailure) break;
    result.max_violation = max_violation(r);
    if (converged && result.max_violation <= settings_.constraint_tolerance) {
      result.status = AltroStatus::kSolved;
      break;
    }
    if (iterations_ >= settings_.max_total_iterations) break;
    update_multipliers(r);
  }
  if (settings_.polish && result.status == AltroStatus::kSolved) {
    result.polish_iterations = polish(x0, r);
  }
  result.states = r.x;
  result.controls = r.u;
  result.cost = problem_cost(r);
  result.max_violation = total_violation(x0, r);
  result.iterations = iterations_;
  return result;
}

}  // namespace

AltroResult solve(const Problem& problem, const Eigen::VectorXd& x0,
                  const std::vector<Eigen::VectorXd>& initial_controls,
                  const AltroSettings& settings) {
  return Solver(problem, settings).run(x0, initial_controls);
}

}  // namespace diffpills::trajopt
