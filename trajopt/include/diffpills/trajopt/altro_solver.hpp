// The ALTRO-style solver of altro.hpp, a template over the problem's state and control sizes
// (problem.hpp). With fixed sizes every state, control, Jacobian, gain and cost expansion is an
// Eigen fixed-size object: the backward pass, the rollouts and the line search allocate nothing
// but the constraint rows the problem returns (a run-time count; none once they are sized, for a
// problem that writes them in place through write_constraints), and Eigen unrolls the small
// products. With Eigen::Dynamic the same code runs on VectorXd and MatrixXd.
//
// Included by altro.hpp; use trajopt::solve, not this class.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/problem.hpp"

namespace diffpills::trajopt::detail {

// I_mu for one row: the penalty acts on equalities always, and on inequalities that are violated
// or already carry a multiplier; a satisfied inequality with lambda = 0 contributes nothing. With
// mu > 0 (check_settings), w = 0 exactly for those rows, and every sum over rows skips them: their
// value need not even be finite (c = -inf is a satisfied inequality; 0 * c would be NaN). A NaN
// value is weighted, so that it reaches the cost and the solve ends as kNonFinite.
inline double penalty_weight(const Eigen::VectorXd& value, int equalities, Eigen::Index row,
                             double lambda, double mu) {
  return (row < equalities || !(value(row) <= 0.0) || lambda > 0.0) ? mu : 0.0;  // NaN: weighted
}

// max(a, b), but NaN if either is: std::max(0.0, NaN) is 0, which would let a problem that
// returned NaN look satisfied.
inline double max_or_nan(double a, double b) { return (a > b || std::isnan(a)) ? a : b; }

// The largest |e| of the equalities and positive c of the inequalities; NaN if any value is.
inline double violation(const Eigen::VectorXd& value, int equalities) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < value.size(); ++i) {
    worst = max_or_nan(worst, i < equalities ? std::abs(value(i)) : value(i));
  }
  return worst;
}

// The largest |v_i|, NaN if any entry is.
template <class Vector>
double largest_magnitude(const Vector& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().template maxCoeff<Eigen::PropagateNaN>();
}

// Throws std::invalid_argument naming the first setting that is NaN, or out of its range: the
// penalties and regularizations finite and positive (a zero penalty would drop the multiplier
// terms with the penalty's), their growth factors at least 1, the tolerances not negative, the
// line search's bounds ordered. Iteration caps below 1 just stop the loops they cap.
void check_settings(const AltroSettings& settings);

template <int Nx, int Nu>
class AltroSolver {
 public:
  using Problem = ProblemOf<Nx, Nu>;
  using State = typename Problem::State;
  using Control = typename Problem::Control;
  using StateMatrix = typename Problem::StateMatrix;
  using ControlMatrix = typename Problem::ControlMatrix;
  using Constraints = typename Problem::Constraints;
  using Cost = typename Problem::Cost;
  using Gain = Eigen::Matrix<double, Nu, Nx>;
  using ControlSquare = Eigen::Matrix<double, Nu, Nu>;

  AltroSolver(const Problem& problem, const AltroSettings& settings);

  AltroResult run(const Eigen::VectorXd& x0, const std::vector<Eigen::VectorXd>& controls);

 private:
  // What a rollout holds of the problem's constraints at its knots.
  enum class Evaluated { kNothing, kValues, kDerivatives };
  struct Rollout {
    std::vector<State> x;
    std::vector<Control> u;
    std::vector<StateMatrix> A;  // dynamics Jacobians along the rollout
    std::vector<ControlMatrix> B;
    // The constraints at (x_k, u_k), kept until x or u change (whoever changes them sets
    // evaluated to kNothing): see constraints_at.
    std::vector<Constraints> c;
    Evaluated evaluated = Evaluated::kNothing;
  };

  // The control passed at knot k: none at the last knot (problem.hpp: empty or zero).
  const Control& control(const Rollout& r, int k) const {
    return k < n_ - 1 ? r.u[k] : no_control_;
  }
  static Control make_no_control() {
    if constexpr (Nu == Eigen::Dynamic) {
      return Control();
    } else {
      return Control::Zero();
    }
  }
  // Every read of a knot's constraints checks them first (problem.hpp): as many rows as the
  // knot's multipliers (the first call's count), 0 <= equalities <= rows, and when `derivatives`
  // a rows x n dx and, before the last knot, a rows x m du. A problem that broke this would
  // otherwise have the solver read past its matrices or its multipliers.
  void check_rows(const Constraints& c, int k, bool derivatives) const;
  // Every knot's constraints at r, with their derivatives if asked, from r's store when it holds
  // them. One rollout meets several sweeps: the line search's augmented cost, the backward pass,
  // the violation at a convergence, the multiplier update, the next outer iteration's cost and
  // backward pass, a retry with a larger rho. Each evaluated them anew before (a collision query
  // per obstacle and knot); with forward_pass's derivatives the arm's solve went from 349 to 203
  // ms (BENCHMARKS.md).
  const std::vector<Constraints>& constraints_at(Rollout& r, bool derivatives) const;
  void rollout(Rollout& r) const;
  static bool finite_states(const Rollout& r);
  double problem_cost(const Rollout& r) const;
  double augmented_cost(Rollout& r) const;
  double max_violation(Rollout& r) const;
  template <class Gradient, class Hessian>
  void add_terminal_constraints(const Constraints& c, Gradient& Vx, Hessian& Vxx) const;
  enum class Pass { kDone, kIndefinite, kNonFinite };
  Pass backward_pass(Rollout& r);
  bool forward_pass(Rollout& r, double& cost, int steps);
  void update_multipliers(Rollout& r);
  double total_violation(Rollout& r) const;
  int polish(Rollout& r) const;
  // rho <- rho * growth after a failed factorization or line search; false once past the cap.
  bool grow_regularization();

  const Problem& problem_;
  const AltroSettings& settings_;
  const int n_;
  const Control no_control_ = make_no_control();
  State x0_;
  // The augmented Lagrangian's multipliers and penalty (one scalar penalty, as Altro.jl's
  // default of a uniform initial penalty scaled together).
  std::vector<Eigen::VectorXd> lambda_;  // per knot, one entry per constraint row
  double mu_ = 1.0;
  double rho_;
  std::vector<Gain> K_;
  std::vector<Control> d_;
  Rollout candidate_;  // the line search's trial, kept to reuse its storage across iterations
  double expected_linear_ = 0.0, expected_quadratic_ = 0.0;
  int iterations_ = 0;
};

template <int Nx, int Nu>
AltroSolver<Nx, Nu>::AltroSolver(const Problem& problem, const AltroSettings& settings)
    : problem_(problem),
      settings_(settings),
      n_(problem.knots()),
      rho_(settings.regularization_initial) {}

template <int Nx, int Nu>
bool AltroSolver<Nx, Nu>::grow_regularization() {
  rho_ = std::max(rho_ * settings_.regularization_growth, settings_.regularization_min);
  return rho_ <= settings_.regularization_max;
}

template <int Nx, int Nu>
void AltroSolver<Nx, Nu>::check_rows(const Constraints& c, int k, bool derivatives) const {
  const Eigen::Index rows = c.value.size();
  const bool has_control = k + 1 < n_;  // the last knot's du is ignored
  const Eigen::Index nx = problem_.state_size(), nu = problem_.control_size();
  const auto shape = [](Eigen::Index r, Eigen::Index c) {
    return std::to_string(r) + " x " + std::to_string(c);
  };
  std::string broken;
  if (rows != lambda_[k].size()) {
    broken = "the knot has " + std::to_string(lambda_[k].size()) + " rows, its first call's count";
  } else if (c.equalities < 0 || c.equalities > rows) {
    broken = "equalities must lie in [0, rows]";
  } else if (derivatives && (c.dx.rows() != rows || c.dx.cols() != nx)) {
    broken = "dx must be " + shape(rows, nx);
  } else if (derivatives && has_control && (c.du.rows() != rows || c.du.cols() != nu)) {
    broken = "du must be " + shape(rows, nu);
  } else {
    return;
  }
  std::string what =
      "trajopt: " + std::string(derivatives ? "constraints(" : "constraint_values(") +
      std::to_string(k) + ") returned " + std::to_string(rows) + " values (" +
      std::to_string(c.equalities) + " equalities)";
  if (derivatives) {
    what += " with a " + shape(c.dx.rows(), c.dx.cols()) + " dx and a " +
            shape(c.du.rows(), c.du.cols()) + " du";
  }
  throw std::invalid_argument(what + ": " + broken);
}

template <int Nx, int Nu>
const std::vector<typename AltroSolver<Nx, Nu>::Constraints>& AltroSolver<Nx, Nu>::constraints_at(
    Rollout& r, bool derivatives) const {
  if (r.evaluated == Evaluated::kDerivatives ||
      (r.evaluated == Evaluated::kValues && !derivatives)) {
    return r.c;
  }
  r.c.resize(n_);
  for (int k = 0; k < n_; ++k) {
    problem_.write_constraints(k, r.x[k], control(r, k), derivatives, r.c[k]);
    check_rows(r.c[k], k, derivatives);
  }
  r.evaluated = derivatives ? Evaluated::kDerivatives : Evaluated::kValues;
  return r.c;
}

template <int Nx, int Nu>
void AltroSolver<Nx, Nu>::rollout(Rollout& r) const {
  r.evaluated = Evaluated::kNothing;
  r.x[0] = x0_;
  for (int k = 0; k + 1 < n_; ++k) {
    problem_.dynamics(r.x[k], r.u[k], r.x[k + 1], r.A[k], r.B[k]);
  }
}

template <int Nx, int Nu>
bool AltroSolver<Nx, Nu>::finite_states(const Rollout& r) {
  return std::all_of(r.x.begin(), r.x.end(), [](const State& x) { return x.allFinite(); });
}

template <int Nx, int Nu>
double AltroSolver<Nx, Nu>::problem_cost(const Rollout& r) const {
  double cost = problem_.terminal_cost_value(r.x[n_ - 1]);
  for (int k = 0; k + 1 < n_; ++k) cost += problem_.stage_cost_value(k, r.x[k], r.u[k]);
  return cost;
}

// J + sum_k lambda_k' c_k + 1/2 c_k' I_mu c_k.
template <int Nx, int Nu>
double AltroSolver<Nx, Nu>::augmented_cost(Rollout& r) const {
  double cost = problem_cost(r);
  const std::vector<Constraints>& constraints = constraints_at(r, false);
  for (int k = 0; k < n_; ++k) {
    const Constraints& c = constraints[k];
    const Eigen::VectorXd& lambda = lambda_[k];
    for (Eigen::Index i = 0; i < c.value.size(); ++i) {
      const double w = penalty_weight(c.value, c.equalities, i, lambda(i), mu_);
      if (w != 0.0) cost += (lambda(i) + 0.5 * w * c.value(i)) * c.value(i);
    }
  }
  return cost;
}

template <int Nx, int Nu>
double AltroSolver<Nx, Nu>::max_violation(Rollout& r) const {
  double worst = 0.0;
  for (const Constraints& c : constraints_at(r, false)) {
    worst = max_or_nan(worst, violation(c.value, c.equalities));
  }
  return worst;
}

// The last knot's constraint terms of the value function: Vx += Cx'g, Vxx += Cx' I_mu Cx, one
// row at a time (rank-one updates of the rows that carry a weight: most rows of a problem with
// many constraints are satisfied inequalities without a multiplier, and contribute nothing).
template <int Nx, int Nu>
template <class Gradient, class Hessian>
void AltroSolver<Nx, Nu>::add_terminal_constraints(const Constraints& c, Gradient& Vx,
                                                   Hessian& Vxx) const {
  const Eigen::VectorXd& lambda = lambda_[n_ - 1];
  for (Eigen::Index i = 0; i < c.value.size(); ++i) {
    const double w = penalty_weight(c.value, c.equalities, i, lambda(i), mu_);
    if (w == 0.0) continue;
    const double g = lambda(i) + w * c.value(i);
    Vx.noalias() += g * c.dx.row(i).transpose();
    Vxx.noalias() += w * c.dx.row(i).transpose() * c.dx.row(i);
  }
}

// iLQR backward pass on the augmented Lagrangian, Gauss-Newton in the constraints: with
// g = lambda + I_mu c the constraint terms add C'g to the gradients and C' I_mu C to the Hessians.
//   Qx = lx + A'Vx + Cx'g        Qxx = lxx + A'Vxx A + Cx' I Cx
//   Qu = lu + B'Vx + Cu'g        Quu = luu + B'Vxx B + Cu' I Cu
//   Qux = lux + B'Vxx A + Cu' I Cx
// K = -(Quu + rho I)^-1 Qux, d = -(Quu + rho I)^-1 Qu, and the value function
//   Vx = Qx + K'Quu d + K'Qu + Qux'd,   Vxx = Qxx + K'Quu K + K'Qux + Qux'K.
// The expected change for a step alpha d is alpha sum d'Qu + alpha^2 / 2 sum d'Quu d.
// The constraint terms are summed row by row over the rows with a nonzero g or weight (see
// add_terminal_constraints).
// kIndefinite when Quu + rho I has no Cholesky factor (grow rho and retry). kNonFinite when Quu,
// Qu, Qux or a gain is NaN or infinite: the problem returned one along the rollout (a NaN in V
// reaches every earlier knot's Quu and Qu, and Eigen's LLT passes NaN through without failing),
// and no rho repairs that.
template <int Nx, int Nu>
typename AltroSolver<Nx, Nu>::Pass AltroSolver<Nx, Nu>::backward_pass(Rollout& r) {
  const std::vector<Constraints>& constraints = constraints_at(r, true);
  const Cost terminal = problem_.terminal_cost(r.x[n_ - 1]);
  State Vx = terminal.x;
  StateMatrix Vxx = terminal.xx;
  add_terminal_constraints(constraints[n_ - 1], Vx, Vxx);
  expected_linear_ = expected_quadratic_ = 0.0;
  for (int k = n_ - 2; k >= 0; --k) {
    const Cost l = problem_.stage_cost(k, r.x[k], r.u[k]);
    const Constraints& c = constraints[k];
    const StateMatrix& A = r.A[k];
    const ControlMatrix& B = r.B[k];
    State Qx = l.x;
    Qx.noalias() += A.transpose() * Vx;
    Control Qu = l.u;
    Qu.noalias() += B.transpose() * Vx;
    StateMatrix VxxA;
    VxxA.noalias() = Vxx * A;
    StateMatrix Qxx = l.xx;
    Qxx.noalias() += A.transpose() * VxxA;
    ControlMatrix VxxB;
    VxxB.noalias() = Vxx * B;
    ControlSquare Quu = l.uu;
    Quu.noalias() += B.transpose() * VxxB;
    Gain Qux = l.ux;
    Qux.noalias() += B.transpose() * VxxA;
    const Eigen::VectorXd& lambda = lambda_[k];
    for (Eigen::Index i = 0; i < c.value.size(); ++i) {
      const double w = penalty_weight(c.value, c.equalities, i, lambda(i), mu_);
      if (w == 0.0) continue;
      const double g = lambda(i) + w * c.value(i);
      Qx.noalias() += g * c.dx.row(i).transpose();
      Qu.noalias() += g * c.du.row(i).transpose();
      Qxx.noalias() += w * c.dx.row(i).transpose() * c.dx.row(i);
      Quu.noalias() += w * c.du.row(i).transpose() * c.du.row(i);
      Qux.noalias() += w * c.du.row(i).transpose() * c.dx.row(i);
    }
    // An infinite entry would make the factorization fail and rho grow to its cap for nothing.
    if (!Quu.allFinite() || !Qu.allFinite() || !Qux.allFinite()) return Pass::kNonFinite;
    ControlSquare regularized = Quu;
    regularized.diagonal().array() += rho_;
    const Eigen::LLT<ControlSquare> llt(regularized);
    if (llt.info() != Eigen::Success) return Pass::kIndefinite;
    Gain& K = K_[k];
    Control& d = d_[k];
    K = -llt.solve(Qux);
    d = -llt.solve(Qu);
    if (!K.allFinite() || !d.allFinite()) return Pass::kNonFinite;
    const Control Quu_d = Quu * d;
    Vx = Qx;
    Vx.noalias() += K.transpose() * (Quu_d + Qu);
    Vx.noalias() += Qux.transpose() * d;
    const Gain Quu_K = Quu * K;
    Vxx = Qxx;
    Vxx.noalias() += K.transpose() * (Quu_K + Qux);
    Vxx.noalias() += Qux.transpose() * K;
    Vxx = (0.5 * (Vxx + Vxx.transpose())).eval();
    expected_linear_ += d.dot(Qu);
    expected_quadratic_ += 0.5 * d.dot(Quu_d);
  }
  return Pass::kDone;
}

// Backtracking from alpha = 1 over at most `steps` trials: u = ubar + K (x - xbar) + alpha d,
// accepted when the actual over the expected decrease of the augmented cost lies in
// [line_search_lower, line_search_upper].
template <int Nx, int Nu>
bool AltroSolver<Nx, Nu>::forward_pass(Rollout& r, double& cost, int steps) {
  Rollout& candidate = candidate_;
  double alpha = 1.0;
  for (int step = 0; step < steps; ++step, alpha *= 0.5) {
    candidate.evaluated = Evaluated::kNothing;
    candidate.x[0] = x0_;
    for (int k = 0; k + 1 < n_; ++k) {
      candidate.u[k] = r.u[k] + alpha * d_[k];
      candidate.u[k].noalias() += K_[k] * (candidate.x[k] - r.x[k]);
      problem_.dynamics(candidate.x[k], candidate.u[k], candidate.x[k + 1], candidate.A[k],
                        candidate.B[k]);
    }
    // With derivatives, although only the values decide: the trial taken is the rollout of the
    // next backward pass, which then finds them kept, and most trials are taken (the quadrotor:
    // 173 of 200). A value sweep per trial, then a derivative sweep for the backward pass, cost
    // more on all three examples; derivatives on the first trial only and values on shorter
    // steps cost more on the arm (224 ms against 209 in one paired run: its derivatives cost
    // little more than its scene queries).
    constraints_at(candidate, true);
    const double new_cost = augmented_cost(candidate);
    const double expected = -(alpha * expected_linear_ + alpha * alpha * expected_quadratic_);
    const double ratio = (cost - new_cost) / expected;
    if (std::isfinite(new_cost) && expected > 0.0 && ratio >= settings_.line_search_lower &&
        ratio <= settings_.line_search_upper && finite_states(candidate)) {
      std::swap(r, candidate);  // the old rollout's storage becomes the next trial's
      cost = new_cost;
      return true;
    }
  }
  return false;
}

// lambda <- max(0, lambda + mu c) on inequalities, lambda + mu c on equalities; mu <- 10 mu.
template <int Nx, int Nu>
void AltroSolver<Nx, Nu>::update_multipliers(Rollout& r) {
  const std::vector<Constraints>& constraints = constraints_at(r, false);
  for (int k = 0; k < n_; ++k) {
    const Constraints& c = constraints[k];
    Eigen::VectorXd& lambda = lambda_[k];
    for (Eigen::Index i = 0; i < lambda.size(); ++i) {
      lambda(i) += mu_ * c.value(i);
      if (i >= c.equalities) lambda(i) = std::max(0.0, lambda(i));
    }
  }
  mu_ = std::min(mu_ * settings_.penalty_scaling, settings_.penalty_max);
}

// The largest violation of anything the solution must satisfy: the problem's constraints, the
// initial state and the dynamics (exact after a rollout, not after a polish).
template <int Nx, int Nu>
double AltroSolver<Nx, Nu>::total_violation(Rollout& r) const {
  double worst = max_or_nan(max_violation(r), largest_magnitude(r.x[0] - x0_));
  State next;
  StateMatrix A;
  ControlMatrix B;
  for (int k = 0; k + 1 < n_; ++k) {
    problem_.dynamics(r.x[k], r.u[k], next, A, B);
    worst = max_or_nan(worst, largest_magnitude(r.x[k + 1] - next));
  }
  return worst;
}

// Projected Newton on z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}]: with c(z) the stacked active
// constraints (x_0 - x0, x_{k+1} - f(x_k, u_k), equalities, inequalities that carry a multiplier
// or are violated) and D = dc/dz, the minimum-norm Gauss-Newton step to c + D dz = 0 is
//   dz = -D'(D D')^-1 c.
// D D' is banded (each dynamics row touches two knots, each constraint row one), with the rows in
// knot order; Eigen's sparse LDLT factors it in that order (a fill-reducing ordering finds nothing
// better for a band and cost ~1/5 of the polish), with a diagonal shift of 1e-12 of its size in
// case active rows are dependent. A step is taken whole or
// halved up to five times, and only if it lowers total_violation. Returns the accepted steps.
template <int Nx, int Nu>
int AltroSolver<Nx, Nu>::polish(Rollout& r) const {
  const int nx = problem_.state_size();
  const int nu = problem_.control_size();
  const auto x_index = [&](int k) { return static_cast<Eigen::Index>(k) * nx; };
  const auto u_index = [&](int k) {
    return static_cast<Eigen::Index>(n_) * nx + static_cast<Eigen::Index>(k) * nu;
  };
  const Eigen::Index variables = u_index(n_ - 1);
  int accepted = 0;
  State next;
  StateMatrix A;
  ControlMatrix B;
  for (int iteration = 0; iteration < settings_.polish_iterations; ++iteration) {
    const double current = total_violation(r);
    if (current <= settings_.polish_tolerance) break;
    std::vector<Eigen::Triplet<double>> entries;
    std::vector<double> values;
    // The initial state's and the dynamics' entries; the active constraints' come on top.
    entries.reserve(static_cast<std::size_t>(n_) * nx * (1 + nx + nu));
    const auto add_row = [&](double value) {
      values.push_back(value);
      return static_cast<Eigen::Index>(values.size()) - 1;
    };
    for (int i = 0; i < nx; ++i) {
      entries.emplace_back(add_row(r.x[0](i) - x0_(i)), x_index(0) + i, 1.0);
    }
    // Rows in the order of the knots, each knot's constraints before the dynamics that leave it,
    // so that D D' is banded in its natural order (no row couples knots more than one apart).
    const std::vector<Constraints>& constraints = constraints_at(r, true);
    for (int k = 0; k < n_; ++k) {
      const Constraints& c = constraints[k];
      const bool has_control = k + 1 < n_;  // the last knot's du is ignored (problem.hpp)
      for (Eigen::Index i = 0; i < c.value.size(); ++i) {
        if (i >= c.equalities && c.value(i) <= 0.0 && lambda_[k](i) <= 0.0) continue;
        const Eigen::Index row = add_row(c.value(i));
        for (int j = 0; j < nx; ++j) entries.emplace_back(row, x_index(k) + j, c.dx(i, j));
        for (int j = 0; has_control && j < nu; ++j) {
          entries.emplace_back(row, u_index(k) + j, c.du(i, j));
        }
      }
      if (!has_control) break;
      problem_.dynamics(r.x[k], r.u[k], next, A, B);
      for (int i = 0; i < nx; ++i) {
        const Eigen::Index row = add_row(r.x[k + 1](i) - next(i));
        entries.emplace_back(row, x_index(k + 1) + i, 1.0);
        for (int j = 0; j < nx; ++j) entries.emplace_back(row, x_index(k) + j, -A(i, j));
        for (int j = 0; j < nu; ++j) entries.emplace_back(row, u_index(k) + j, -B(i, j));
      }
    }
    const auto rows = static_cast<Eigen::Index>(values.size());
    Eigen::SparseMatrix<double> D(rows, variables);
    D.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseMatrix<double> normal = D * D.transpose();
    double size = 0.0;
    for (Eigen::Index i = 0; i < rows; ++i) size = std::max(size, normal.coeff(i, i));
    for (Eigen::Index i = 0; i < rows; ++i) normal.coeffRef(i, i) += 1e-12 * (1.0 + size);
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower,
                                Eigen::NaturalOrdering<int>>
        ldlt(normal);
    if (ldlt.info() != Eigen::Success) break;
    const Eigen::VectorXd step =
        -(D.transpose() * ldlt.solve(Eigen::Map<const Eigen::VectorXd>(values.data(), rows)))
             .eval();
    bool improved = false;
    for (double fraction = 1.0; fraction > 0.03 && !improved; fraction *= 0.5) {
      Rollout trial = r;
      trial.evaluated = Evaluated::kNothing;
      for (int k = 0; k < n_; ++k) trial.x[k] += fraction * step.segment(x_index(k), nx);
      for (int k = 0; k + 1 < n_; ++k) trial.u[k] += fraction * step.segment(u_index(k), nu);
      if (total_violation(trial) < current) {
        r = std::move(trial);
        improved = true;
      }
    }
    if (!improved) break;
    ++accepted;
  }
  return accepted;
}

template <int Nx, int Nu>
AltroResult AltroSolver<Nx, Nu>::run(const Eigen::VectorXd& x0,
                                     const std::vector<Eigen::VectorXd>& controls) {
  check_settings(settings_);
  const int nx = problem_.state_size();
  const int nu = problem_.control_size();
  if ((Nx != Eigen::Dynamic && nx != Nx) || (Nu != Eigen::Dynamic && nu != Nu)) {
    throw std::invalid_argument("trajopt: the problem's state_size() and control_size() (" +
                                std::to_string(nx) + ", " + std::to_string(nu) +
                                ") are not its compile-time sizes (" + std::to_string(Nx) + ", " +
                                std::to_string(Nu) + ")");
  }
  if (n_ < 2) {
    throw std::invalid_argument("trajopt: the problem has " + std::to_string(n_) +
                                " knots; it needs at least 2");
  }
  if (x0.size() != nx || !x0.allFinite() || static_cast<int>(controls.size()) != n_ - 1) {
    throw std::invalid_argument("trajopt: need x0 of " + std::to_string(nx) +
                                " finite entries and " + std::to_string(n_ - 1) +
                                " initial controls");
  }
  for (const Eigen::VectorXd& u : controls) {
    if (u.size() != nu || !u.allFinite()) {
      throw std::invalid_argument("trajopt: every initial control must have " + std::to_string(nu) +
                                  " finite entries");
    }
  }
  x0_ = x0;
  Rollout r;
  r.x.resize(n_);
  r.u.assign(controls.begin(), controls.end());
  r.A.resize(n_ - 1);
  r.B.resize(n_ - 1);
  rollout(r);
  K_.resize(n_ - 1);  // each filled by the first backward pass before any use
  d_.resize(n_ - 1);
  mu_ = settings_.penalty_initial;
  lambda_.resize(n_);
  r.c.resize(n_);
  for (int k = 0; k < n_; ++k) {  // the first call fixes each knot's row count
    problem_.write_constraints(k, r.x[k], control(r, k), true, r.c[k]);
    lambda_[k] = Eigen::VectorXd::Zero(r.c[k].value.size());
    check_rows(r.c[k], k, true);
  }
  r.evaluated = Evaluated::kDerivatives;
  candidate_ = r;

  AltroResult result;
  result.status = AltroStatus::kMaxIterations;
  for (int outer = 0; outer < settings_.max_outer_iterations; ++outer) {
    result.outer_iterations = outer + 1;
    double cost = augmented_cost(r);
    // Only the initial guess can be non-finite here: the line search accepts finite costs and
    // states only.
    if (!std::isfinite(cost) || !finite_states(r)) {
      result.status = AltroStatus::kNonFinite;
      break;
    }
    bool converged = false;
    for (int inner = 0;
         inner < settings_.max_inner_iterations && iterations_ < settings_.max_total_iterations;
         ++inner) {
      ++iterations_;
      const Pass pass = backward_pass(r);
      if (pass == Pass::kNonFinite) {
        result.status = AltroStatus::kNonFinite;
        break;
      }
      if (pass == Pass::kIndefinite) {
        if (!grow_regularization()) {
          result.status = AltroStatus::kRegularizationFailure;
          break;
        }
        continue;
      }
      // Converged when the predicted decrease, or the largest feedforward step, is negligible.
      // If the constraints are not yet met, the full step is still tried once: under a large
      // penalty the Newton step that removes a small violation can be below gradient_tolerance
      // relative to u, and skipping it left every multiplier update at the same point (an LQ
      // problem with coupled equalities stalled for 30 outer iterations at a violation of 1e-5;
      // test_trajopt). Not when they are met: a step that lowers the augmented cost may raise the
      // violation past the tolerance again. One trial only: near convergence the actual over the
      // predicted decrease is rounding noise, and backtracking would roll out up to
      // line_search_steps times for nothing.
      double step = 0.0;
      for (int k = 0; k + 1 < n_; ++k) {
        step = std::max(step, d_[k].template lpNorm<Eigen::Infinity>() /
                                  (1.0 + r.u[k].template lpNorm<Eigen::Infinity>()));  // finite
      }
      if (-expected_linear_ < settings_.cost_tolerance * (1.0 + std::abs(cost)) ||
          step < settings_.gradient_tolerance) {
        if (max_violation(r) > settings_.constraint_tolerance) {
          forward_pass(r, cost, 1);  // a rejected step leaves r as it was
        }
        converged = true;
        break;
      }
      const double before = cost;
      if (!forward_pass(r, cost, settings_.line_search_steps)) {
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
    if (result.status != AltroStatus::kMaxIterations) break;  // a failure ended the inner loop
    result.max_violation = max_violation(r);
    if (converged && result.max_violation <= settings_.constraint_tolerance) {
      result.status = AltroStatus::kSolved;
      break;
    }
    if (iterations_ >= settings_.max_total_iterations) break;
    update_multipliers(r);
  }
  if (settings_.polish && result.status == AltroStatus::kSolved) {
    result.polish_iterations = polish(r);
  }
  result.states.assign(r.x.begin(), r.x.end());
  result.controls.assign(r.u.begin(), r.u.end());
  result.cost = problem_cost(r);
  result.max_violation = total_violation(r);
  result.iterations = iterations_;
  return result;
}

extern template class AltroSolver<Eigen::Dynamic, Eigen::Dynamic>;

}  // namespace diffpills::trajopt::detail

namespace diffpills::trajopt {

template <int Nx, int Nu>
AltroResult solve(const ProblemOf<Nx, Nu>& problem, const Eigen::VectorXd& x0,
                  const std::vector<Eigen::VectorXd>& initial_controls,
                  const AltroSettings& settings) {
  return detail::AltroSolver<Nx, Nu>(problem, settings).run(x0, initial_controls);
}

}  // namespace diffpills::trajopt
