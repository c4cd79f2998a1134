#include "problem_nlp.hpp"

#include <IpTNLP.hpp>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "knot_hessian.hpp"
#include "timed_solve.hpp"

namespace diffpills::examples {
namespace {

using Ipopt::Index;
using Ipopt::Number;

constexpr double kInfinity = 1e19;  // Ipopt's default nlp_upper_bound_inf

class ProblemNlp : public Ipopt::TNLP {
 public:
  ProblemNlp(const trajopt::Problem& problem, Eigen::VectorXd x0,
             std::vector<Eigen::VectorXd> guess_states, std::vector<Eigen::VectorXd> guess_controls)
      : problem_(problem),
        n_(problem.state_size()),
        m_(problem.control_size()),
        knots_(problem.knots()),
        x0_(std::move(x0)),
        guess_states_(std::move(guess_states)),
        guess_controls_(std::move(guess_controls)),
        hessian_(n_, m_, knots_) {
    // Each knot's rows (fixed between calls, problem.hpp), from the guess.
    Index offset = n_ * (knots_ - 1);
    for (int k = 0; k < knots_; ++k) {
      const trajopt::KnotConstraints c = problem_.constraint_values(
          k, guess_states_[static_cast<std::size_t>(k)], control_or_empty(k, guess_controls_));
      row_start_.push_back(offset);
      rows_.push_back(static_cast<Index>(c.value.size()));
      equalities_.push_back(c.equalities);
      offset += static_cast<Index>(c.value.size());
    }
    constraints_ = offset;
  }

  IpoptRun run;

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_hess,
                    IndexStyleEnum& style) override {
    n = variables();
    m = constraints_;
    nnz_jac = (knots_ - 1) * (n_ + n_ * n_ + n_ * m_);
    for (int k = 0; k < knots_; ++k)
      nnz_jac += rows_[static_cast<std::size_t>(k)] * (n_ + (k + 1 < knots_ ? m_ : 0));
    nnz_hess = hessian_.nonzeros();
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index, Number* g_l,
                       Number* g_u) override {
    std::fill(x_l, x_l + n, -kInfinity);
    std::fill(x_u, x_u + n, kInfinity);
    for (int i = 0; i < n_; ++i) x_l[i] = x_u[i] = x0_(i);  // x_0 fixed
    std::fill(g_l, g_l + defects(), 0.0);                   // dynamics
    std::fill(g_u, g_u + defects(), 0.0);
    for (int k = 0; k < knots_; ++k) {
      const auto s = static_cast<std::size_t>(k);
      for (Index r = 0; r < rows_[s]; ++r) {
        g_l[row_start_[s] + r] = r < equalities_[s] ? 0.0 : -kInfinity;
        g_u[row_start_[s] + r] = 0.0;
      }
    }
    return true;
  }

  bool get_starting_point(Index, bool init_x, Number* z, bool init_z, Number*, Number*, Index,
                          bool init_lambda, Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    for (int k = 0; k < knots_; ++k) {
      Eigen::Map<Eigen::VectorXd>(z + state_index(k), n_) =
          guess_states_[static_cast<std::size_t>(k)];
      if (k + 1 < knots_) {
        Eigen::Map<Eigen::VectorXd>(z + control_index(k), m_) =
            guess_controls_[static_cast<std::size_t>(k)];
      }
    }
    return true;
  }

  bool eval_f(Index, const Number* z, bool, Number& value) override {
    value = cost(z, nullptr);
    return true;
  }

  bool eval_grad_f(Index n, const Number* z, bool, Number* gradient) override {
    Eigen::Map<Eigen::VectorXd> g(gradient, n);
    cost(z, &g);
    return true;
  }

  bool eval_g(Index, const Number* z, bool, Index, Number* g) override {
    for (int k = 0; k + 1 < knots_; ++k) {
      Eigen::VectorXd next;
      Eigen::MatrixXd A, B;
      problem_.dynamics(state(z, k), control(z, k), next, A, B);
      Eigen::Map<Eigen::VectorXd>(g + std::ptrdiff_t{n_} * k, n_) = state(z, k + 1) - next;
    }
    for (int k = 0; k < knots_; ++k) {
      const trajopt::KnotConstraints c =
          problem_.constraint_values(k, state(z, k), control_or_empty(k, z));
      const auto s = static_cast<std::size_t>(k);
      Eigen::Map<Eigen::VectorXd>(g + row_start_[s], rows_[s]) = c.value;
    }
    return true;
  }

  bool eval_jac_g(Index, const Number* z, bool, Index, Index, Index* rows, Index* cols,
                  Number* values) override {
    Index entry = 0;
    for (int k = 0; k + 1 < knots_; ++k) {
      Eigen::VectorXd next;
      Eigen::MatrixXd A, B;
      if (values != nullptr) problem_.dynamics(state(z, k), control(z, k), next, A, B);
      for (int i = 0; i < n_; ++i) {
        const Index row = n_ * k + i;
        add(rows, cols, values, entry, row, state_index(k + 1) + i, 1.0);
        for (int j = 0; j < n_; ++j) {
          add(rows, cols, values, entry, row, state_index(k) + j, values ? -A(i, j) : 0.0);
        }
        for (int j = 0; j < m_; ++j) {
          add(rows, cols, values, entry, row, control_index(k) + j, values ? -B(i, j) : 0.0);
        }
      }
    }
    for (int k = 0; k < knots_; ++k) {
      const auto s = static_cast<std::size_t>(k);
      trajopt::KnotConstraints c;
      if (values != nullptr) c = problem_.constraints(k, state(z, k), control_or_empty(k, z));
      for (Index r = 0; r < rows_[s]; ++r) {
        for (int j = 0; j < n_; ++j) {
          add(rows, cols, values, entry, row_start_[s] + r, state_index(k) + j,
              values ? c.dx(r, j) : 0.0);
        }
        if (k + 1 == knots_) continue;
        for (int j = 0; j < m_; ++j) {
          add(rows, cols, values, entry, row_start_[s] + r, control_index(k) + j,
              values ? c.du(r, j) : 0.0);
        }
      }
    }
    return true;
  }

  // The Lagrangian obj_factor l(z) + lambda' g(z): per knot, the costs' Hessian, the defect's
  // -f(x_k, u_k) weighted by its multipliers, and the knot's constraints weighted by theirs.
  bool eval_h(Index, const Number* z, bool, Number obj_factor, Index, const Number* lambda, bool,
              Index, Index* rows, Index* cols, Number* values) override {
    return hessian_.eval_h(
        problem_, z, obj_factor, lambda,
        [&](int k, const Eigen::VectorXd& x, const Eigen::VectorXd& u) -> Eigen::MatrixXd {
          const auto s = static_cast<std::size_t>(k);
          if (rows_[s] == 0) return Eigen::MatrixXd::Zero(n_ + u.size(), n_ + u.size());
          return problem_.constraint_hessian(
              k, x, u, Eigen::Map<const Eigen::VectorXd>(lambda + row_start_[s], rows_[s]));
        },
        rows, cols, values);
  }

  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* z, const Number*,
                         const Number*, Index m, const Number*, const Number*, Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    run.solved = status == Ipopt::SUCCESS;
    const PointValues point = evaluate_point(*this, n, z, m);
    const std::vector<Number>& g = point.constraints;
    run.cost = point.cost;
    run.max_violation = 0.0;
    for (Index i = 0; i < n_ * (knots_ - 1); ++i) {
      run.max_violation = std::max(run.max_violation, std::abs(g[i]));
    }
    for (int k = 0; k < knots_; ++k) {
      const auto s = static_cast<std::size_t>(k);
      for (Index r = 0; r < rows_[s]; ++r) {
        const double value = g[row_start_[s] + r];
        run.max_violation =
            std::max(run.max_violation, r < equalities_[s] ? std::abs(value) : value);
      }
      run.states.push_back(state(z, k));
      if (k + 1 < knots_) run.controls.push_back(control(z, k));
    }
  }

 private:
  Index variables() const { return n_ * knots_ + m_ * (knots_ - 1); }
  std::ptrdiff_t defects() const { return std::ptrdiff_t{n_} * (knots_ - 1); }
  Index state_index(int k) const { return n_ * k; }
  Index control_index(int k) const { return n_ * knots_ + m_ * k; }
  Eigen::VectorXd state(const Number* z, int k) const {
    return Eigen::Map<const Eigen::VectorXd>(z + state_index(k), n_);
  }
  Eigen::VectorXd control(const Number* z, int k) const {
    return Eigen::Map<const Eigen::VectorXd>(z + control_index(k), m_);
  }
  Eigen::VectorXd control_or_empty(int k, const Number* z) const {
    return k + 1 < knots_ ? control(z, k) : Eigen::VectorXd();
  }
  Eigen::VectorXd control_or_empty(int k, const std::vector<Eigen::VectorXd>& controls) const {
    return k + 1 < knots_ ? controls[static_cast<std::size_t>(k)] : Eigen::VectorXd();
  }

  // The problem's costs summed over the knots, the gradient scattered into z's layout.
  double cost(const Number* z, Eigen::Map<Eigen::VectorXd>* gradient) const {
    double total = 0.0;
    if (gradient != nullptr) gradient->setZero();
    for (int k = 0; k + 1 < knots_; ++k) {
      const trajopt::CostExpansion l = problem_.stage_cost(k, state(z, k), control(z, k));
      total += l.value;
      if (gradient != nullptr) {
        gradient->segment(state_index(k), n_) += l.x;
        gradient->segment(control_index(k), m_) += l.u;
      }
    }
    const trajopt::CostExpansion terminal = problem_.terminal_cost(state(z, knots_ - 1));
    total += terminal.value;
    if (gradient != nullptr) gradient->segment(state_index(knots_ - 1), n_) += terminal.x;
    return total;
  }

  static void add(Index* rows, Index* cols, Number* values, Index& entry, Index row, Index col,
                  double value) {
    if (values == nullptr) {
      rows[entry] = row;
      cols[entry] = col;
    } else {
      values[entry] = value;
    }
    ++entry;
  }

  const trajopt::Problem& problem_;
  int n_, m_, knots_;
  Eigen::VectorXd x0_;
  std::vector<Eigen::VectorXd> guess_states_, guess_controls_;
  std::vector<Index> row_start_, rows_;
  std::vector<int> equalities_;
  Index constraints_ = 0;
  KnotHessian hessian_;
};

}  // namespace

IpoptRun solve_problem_with_ipopt(const trajopt::Problem& problem, const Eigen::VectorXd& x0,
                                  const std::vector<Eigen::VectorXd>& initial_controls,
                                  IpoptHessian hessian, double max_cpu_seconds) {
  if (hessian == IpoptHessian::kExact && !problem.has_second_derivatives()) {
    throw std::invalid_argument("hessian: the problem supplies no second derivatives");
  }
  const std::vector<Eigen::VectorXd> states = rollout(problem, x0, initial_controls);
  Ipopt::SmartPtr<ProblemNlp> nlp = new ProblemNlp(problem, x0, states, initial_controls);
  return solve_timed(nlp, nlp->run, hessian, max_cpu_seconds);
}

}  // namespace diffpills::examples
