#include "car_bus_ipopt.hpp"

#include <IpTNLP.hpp>
#include <algorithm>
#include <cmath>
#include <vector>

#include "ipopt/knot_hessian.hpp"
#include "ipopt/timed_solve.hpp"

namespace diffpills::examples {
namespace {

using Ipopt::Index;
using Ipopt::Number;

constexpr int kState = 5;
constexpr int kControl = 2;
constexpr double kInfinity = 1e19;  // Ipopt's default nlp_upper_bound_inf

// Index bookkeeping for z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}].
struct Layout {
  int knots;
  std::ptrdiff_t state(int k) const { return std::ptrdiff_t{kState} * k; }
  std::ptrdiff_t control(int k) const {
    return std::ptrdiff_t{kState} * knots + std::ptrdiff_t{kControl} * k;
  }
  int variables() const { return kState * knots + kControl * (knots - 1); }
  int defects() const { return kState * (knots - 1); }
  int constraints() const { return defects() + knots; }  // dynamics, then phi per knot
};

class CarBusNlp : public Ipopt::TNLP {
 public:
  CarBusNlp(const CarBusProblem& problem, std::vector<Eigen::VectorXd> guess_states,
            std::vector<Eigen::VectorXd> guess_controls)
      : problem_(problem),
        view_(problem),
        layout_{problem.knots()},
        guess_states_(std::move(guess_states)),
        guess_controls_(std::move(guess_controls)),
        hessian_(kState, kControl, layout_.knots) {}

  IpoptRun run;

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_hess,
                    IndexStyleEnum& style) override {
    n = layout_.variables();
    m = layout_.constraints();
    // Per defect block: I on x_{k+1}, -A on x_k, -B on u_k; per phi row: px, py, theta.
    nnz_jac =
        (layout_.knots - 1) * (kState + kState * kState + kState * kControl) + 3 * layout_.knots;
    nnz_hess = hessian_.nonzeros();
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    const CarBusScenario& s = problem_.scenario();
    std::fill(x_l, x_l + n, -kInfinity);
    std::fill(x_u, x_u + n, kInfinity);
    for (int i = 0; i < kState; ++i) x_l[i] = x_u[i] = s.x0(i);  // x_0 fixed
    const int last = layout_.state(layout_.knots - 1);
    for (int i = 0; i < 3; ++i) x_l[last + i] = x_u[last + i] = s.goal(i);  // position, heading
    for (int k = 0; k + 1 < layout_.knots; ++k) {
      for (int i = 0; i < kControl; ++i) {
        x_l[layout_.control(k) + i] = -s.control_limit(i);
        x_u[layout_.control(k) + i] = s.control_limit(i);
      }
    }
    std::fill(g_l, g_l + m, 0.0);
    std::fill(g_u, g_u + layout_.defects(), 0.0);            // dynamics: equalities
    std::fill(g_u + layout_.defects(), g_u + m, kInfinity);  // phi >= 0
    return true;
  }

  bool get_starting_point(Index, bool init_x, Number* x, bool init_z, Number*, Number*, Index,
                          bool init_lambda, Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    for (int k = 0; k < layout_.knots; ++k) {
      Eigen::Map<Eigen::VectorXd>(x + layout_.state(k), kState) = guess_states_[k];
      if (k + 1 < layout_.knots) {
        Eigen::Map<Eigen::VectorXd>(x + layout_.control(k), kControl) = guess_controls_[k];
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
    for (int k = 0; k + 1 < layout_.knots; ++k) {
      Eigen::VectorXd next;
      Eigen::MatrixXd A, B;
      view_.dynamics(state(z, k), control(z, k), next, A, B);
      Eigen::Map<Eigen::VectorXd>(g + layout_.state(k), kState) = state(z, k + 1) - next;
    }
    for (int k = 0; k < layout_.knots; ++k) {
      g[layout_.defects() + k] = car_bus_phi(problem_.scenario(), state(z, k));
    }
    return true;
  }

  bool eval_jac_g(Index, const Number* z, bool, Index, Index, Index* rows, Index* cols,
                  Number* values) override {
    int entry = 0;
    for (int k = 0; k + 1 < layout_.knots; ++k) {
      Eigen::VectorXd next;
      Eigen::MatrixXd A, B;
      if (values != nullptr) view_.dynamics(state(z, k), control(z, k), next, A, B);
      for (int i = 0; i < kState; ++i) {
        const std::ptrdiff_t row = layout_.state(k) + i;
        add(rows, cols, values, entry, row, layout_.state(k + 1) + i, 1.0);
        for (int j = 0; j < kState; ++j) {
          add(rows, cols, values, entry, row, layout_.state(k) + j, values ? -A(i, j) : 0.0);
        }
        for (int j = 0; j < kControl; ++j) {
          add(rows, cols, values, entry, row, layout_.control(k) + j, values ? -B(i, j) : 0.0);
        }
      }
    }
    for (int k = 0; k < layout_.knots; ++k) {
      Eigen::VectorXd gradient = Eigen::VectorXd::Zero(kState);
      if (values != nullptr) car_bus_phi(problem_.scenario(), state(z, k), &gradient);
      for (int j = 0; j < 3; ++j) {
        add(rows, cols, values, entry, layout_.defects() + k, layout_.state(k) + j, gradient(j));
      }
    }
    return true;
  }

  // The Lagrangian obj_factor l(z) + lambda' g(z): per knot, the costs' Hessian, the defect's
  // -f(x_k, u_k) weighted by its multipliers, and phi(x_k) weighted by its multiplier.
  bool eval_h(Index, const Number* z, bool, Number obj_factor, Index, const Number* lambda, bool,
              Index, Index* rows, Index* cols, Number* values) override {
    return hessian_.eval_h(
        view_, z, obj_factor, lambda,
        [&](int k, const Eigen::VectorXd& x, const Eigen::VectorXd& u) -> Eigen::MatrixXd {
          Eigen::MatrixXd H = Eigen::MatrixXd::Zero(kState + u.size(), kState + u.size());
          H.topLeftCorner<kState, kState>() =
              lambda[layout_.defects() + k] * car_bus_phi_hessian(problem_.scenario(), x);
          return H;
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
    for (int i = 0; i < layout_.defects(); ++i)
      run.max_violation = std::max(run.max_violation, std::abs(g[i]));
    for (int k = 0; k < layout_.knots; ++k) {
      run.max_violation = std::max(run.max_violation, -g[layout_.defects() + k]);
      run.states.push_back(state(z, k));
      if (k + 1 < layout_.knots) run.controls.push_back(control(z, k));
    }
  }

 private:
  Eigen::VectorXd state(const Number* z, int k) const {
    return Eigen::Map<const Eigen::VectorXd>(z + layout_.state(k), kState);
  }
  Eigen::VectorXd control(const Number* z, int k) const {
    return Eigen::Map<const Eigen::VectorXd>(z + layout_.control(k), kControl);
  }

  // The problem's own costs, summed over the knots, with the gradient scattered into z's layout.
  double cost(const Number* z, Eigen::Map<Eigen::VectorXd>* gradient) const {
    double total = 0.0;
    if (gradient != nullptr) gradient->setZero();
    for (int k = 0; k + 1 < layout_.knots; ++k) {
      const trajopt::CostExpansion l = view_.stage_cost(k, state(z, k), control(z, k));
      total += l.value;
      if (gradient != nullptr) {
        gradient->segment(layout_.state(k), kState) += l.x;
        gradient->segment(layout_.control(k), kControl) += l.u;
      }
    }
    const trajopt::CostExpansion terminal = view_.terminal_cost(state(z, layout_.knots - 1));
    total += terminal.value;
    if (gradient != nullptr)
      gradient->segment(layout_.state(layout_.knots - 1), kState) += terminal.x;
    return total;
  }

  static void add(Index* rows, Index* cols, Number* values, int& entry, std::ptrdiff_t row,
                  std::ptrdiff_t col, double value) {
    if (values == nullptr) {
      rows[entry] = static_cast<Index>(row);
      cols[entry] = static_cast<Index>(col);
    } else {
      values[entry] = value;
    }
    ++entry;
  }

  const CarBusProblem& problem_;
  const trajopt::DynamicProblem<5, 2> view_;  // the problem in the run-time sizes of this NLP
  Layout layout_;
  std::vector<Eigen::VectorXd> guess_states_, guess_controls_;
  KnotHessian hessian_;
};

}  // namespace

IpoptRun solve_with_ipopt(const CarBusProblem& problem,
                          const std::vector<Eigen::VectorXd>& initial_controls,
                          IpoptHessian hessian, double max_cpu_seconds) {
  const std::vector<Eigen::VectorXd> states =
      rollout(problem, problem.scenario().x0, initial_controls);
  Ipopt::SmartPtr<CarBusNlp> nlp = new CarBusNlp(problem, states, initial_controls);
  return solve_timed(nlp, nlp->run, hessian, max_cpu_seconds);
}

}  // namespace diffpills::examples
