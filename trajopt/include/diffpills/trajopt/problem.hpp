// A discrete-time trajectory optimization problem for diffpills::trajopt:
//
//   minimize    sum_{k<N-1} l_k(x_k, u_k) + l_N(x_{N-1})
//   subject to  x_{k+1} = f(x_k, u_k),  x_0 given,
//               c_k(x_k, u_k) <= 0 and e_k(x_k, u_k) = 0 at every knot (u absent at the last)
//
// with N knots, states x in R^n and controls u in R^m. A problem supplies its dynamics, costs and
// constraints with their first derivatives (and the costs' second derivatives); the solver never
// differentiates numerically. A problem may also supply the second derivatives of its dynamics and
// constraints, for solvers that use the exact Hessian of the Lagrangian (the examples' Ipopt
// cross-check); ALTRO does not use them. Implementations must be pure: the same inputs give the
// same outputs.
//
// Sizes. ProblemOf<Nx, Nu> fixes n and m at compile time: states, controls, their Jacobians and
// the cost expansions are then Eigen fixed-size types on the stack, and the solver's inner loops
// (altro_solver.hpp) allocate nothing for them. Problem = ProblemOf<Eigen::Dynamic,
// Eigen::Dynamic> takes its sizes at run time (VectorXd, MatrixXd). A knot's constraint rows are
// a run-time count in both. DynamicProblem<Nx, Nu> (dynamic_problem.hpp) shows a fixed-size problem
// as a dynamic one, for code written against Problem (the examples' Ipopt cross-check).
//
// The last knot has no control. A dynamic problem gets an empty u there and returns du with zero
// columns; a fixed-size problem gets u = 0 there and its du, if it fills one, is ignored. Either
// way the constraints and their Hessian must not depend on u at the last knot.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <type_traits>

namespace diffpills::trajopt {

// Value and derivatives of one knot's constraints: rows [0, equalities) are equalities e = 0,
// the rest inequalities c <= 0.
template <int Nx, int Nu>
struct KnotConstraintsOf {
  Eigen::VectorXd value;
  Eigen::Matrix<double, Eigen::Dynamic, Nx> dx;
  Eigen::Matrix<double, Eigen::Dynamic, Nu> du;
  int equalities = 0;
};

// A cost term's value with its gradient and Hessian (Gauss-Newton or exact). The terminal cost
// fills value, x and xx only.
template <int Nx, int Nu>
struct CostExpansionOf {
  double value = 0.0;
  Eigen::Matrix<double, Nx, 1> x;  // gradients
  Eigen::Matrix<double, Nu, 1> u;
  Eigen::Matrix<double, Nx, Nx> xx;  // Hessians
  Eigen::Matrix<double, Nu, Nu> uu;
  Eigen::Matrix<double, Nu, Nx> ux;  // mixed, m x n
};

template <int Nx, int Nu>
class ProblemOf {
 public:
  using State = Eigen::Matrix<double, Nx, 1>;
  using Control = Eigen::Matrix<double, Nu, 1>;
  using StateMatrix = Eigen::Matrix<double, Nx, Nx>;    // A = df/dx
  using ControlMatrix = Eigen::Matrix<double, Nx, Nu>;  // B = df/du
  using Constraints = KnotConstraintsOf<Nx, Nu>;
  using Cost = CostExpansionOf<Nx, Nu>;

  virtual ~ProblemOf() = default;

  virtual int state_size() const = 0;  // Nx when fixed
  virtual int control_size() const = 0;
  virtual int knots() const = 0;  // N: states x_0..x_{N-1}, controls u_0..u_{N-2}

  // next = f(x, u) with A = df/dx (n x n), B = df/du (n x m).
  virtual void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                        ControlMatrix& B) const = 0;

  // l_k(x, u) for k < N - 1 and l_N(x) for the last knot (expansion.u and friends unused there).
  virtual Cost stage_cost(int k, const State& x, const Control& u) const = 0;
  virtual Cost terminal_cost(const State& x) const = 0;

  // Constraints at knot k (k = N - 1: terminal, see above for u). A knot's row count is fixed by
  // the first call and must stay the same in every later call, here and in constraint_values;
  // dx and du have one row per value, and 0 <= equalities <= rows. The solver checks this at
  // every call and throws std::invalid_argument naming the knot. The default has none.
  virtual Constraints constraints(int /*k*/, const State& x, const Control& u) const {
    Constraints none;
    none.value.resize(0);
    none.dx.resize(0, x.size());
    none.du.resize(0, u.size());
    return none;
  }

  // Values only, where no derivatives are needed: the cost's values in the line search, the
  // constraint values in the polish's trial steps and in the Ipopt bridge's constraint function.
  // The defaults call the full evaluations; a problem overrides them when that saves work. An
  // override must return what the full evaluation would (constraint_values: the same value and
  // equalities as constraints): the solvers take either at a point, and the row rules above are
  // checked where each is called, so a constraint_values that disagrees is seen only in the
  // polish. (The line search evaluates constraints() with derivatives, which ALTRO keeps for the
  // backward pass at the rollout it accepts: see AltroSolver::constraints_at.)
  virtual double stage_cost_value(int k, const State& x, const Control& u) const {
    return stage_cost(k, x, u).value;
  }
  virtual double terminal_cost_value(const State& x) const { return terminal_cost(x).value; }
  // value and equalities filled; dx and du may be left empty.
  virtual Constraints constraint_values(int k, const State& x, const Control& u) const {
    return constraints(k, x, u);
  }

  // What ALTRO calls: constraints (derivatives true) or constraint_values (false) at knot k,
  // written into `out`, which is empty or holds what an earlier write_constraints of this problem
  // left there (at any knot, with or without derivatives). The default assigns the function's
  // result. A problem with many rows overrides it to write them into out's storage, which then
  // lives as long as the solve: the arm's ~375 rows of value, dx and du were allocated and freed
  // at every knot of every sweep. An override must write what the function would; with
  // derivatives false, dx and du are not read and may hold anything. ALTRO then calls only the
  // override: a class derived from such a problem that changes constraints() or
  // constraint_values() must override write_constraints too. Conversely, where constraints() and
  // constraint_values() call their class's write_constraints by name (rows_written_by below; the
  // demo's problems do, so that a derived class may take the default back without recursing), a
  // derived class that overrides write_constraints alone changes what ALTRO reads but not what
  // those two return (the Ipopt bridge reads them): override the three together. Rows of the
  // wrong shape are reported (std::invalid_argument) under the name of the function the default
  // would call, "constraints(k)" with derivatives and "constraint_values(k)" without, an
  // override's too.
  virtual void write_constraints(int k, const State& x, const Control& u, bool derivatives,
                                 Constraints& out) const {
    out = derivatives ? constraints(k, x, u) : constraint_values(k, x, u);
  }

  // Second derivatives. A problem that returns true here implements the two functions below, and
  // its cost expansions' Hessians are exact (not Gauss-Newton); the defaults have none and throw
  // std::logic_error.
  virtual bool has_second_derivatives() const { return false; }
  // The Hessian of lambda' f(x, u) with respect to [x; u], (n + m) x (n + m), for lambda in R^n.
  // A dynamic problem throws std::invalid_argument for vectors of the wrong size (require_size
  // below).
  virtual Eigen::MatrixXd dynamics_hessian(const State& /*x*/, const Control& /*u*/,
                                           const State& /*lambda*/) const {
    throw std::logic_error("dynamics_hessian: this problem supplies no second derivatives");
  }
  // The Hessian of mu' [e_k; c_k](x, u) with respect to [x; u] (x alone at the last knot), for one
  // multiplier per row of constraints(k, x, u).
  virtual Eigen::MatrixXd constraint_hessian(int /*k*/, const State& /*x*/, const Control& /*u*/,
                                             const Eigen::VectorXd& /*mu*/) const {
    throw std::logic_error("constraint_hessian: this problem supplies no second derivatives");
  }

 protected:
  // constraints() (derivatives true) or constraint_values() (false) of a problem that writes its
  // rows in place: what Class::write_constraints writes into fresh storage. Class's own is called
  // by name, not virtually, so that a class derived from it may take the default
  // write_constraints back (which calls constraints() and constraint_values()) without recursing.
  //   Constraints constraints(int k, const State& x, const Control& u) const override {
  //     return rows_written_by<MyProblem>(*this, k, x, u, true);
  //   }
  // Class must declare write_constraints itself or inherit another class's override of it (the
  // default would call back here without end: refused at compile time), and make it public. In a
  // class template, whose base depends on its parameters, write
  // `this->template rows_written_by<MyProblem>(...)`.
  template <class Class>
  static Constraints rows_written_by(const Class& problem, int k, const State& x, const Control& u,
                                     bool derivatives) {
    static_assert(!std::is_same_v<decltype(&Class::write_constraints),
                                  decltype(&ProblemOf::write_constraints)>,
                  "rows_written_by<Class>: Class must override write_constraints");
    Constraints rows;
    problem.Class::write_constraints(k, x, u, derivatives, rows);
    return rows;
  }
};

// Sizes chosen at run time.
using Problem = ProblemOf<Eigen::Dynamic, Eigen::Dynamic>;
using KnotConstraints = KnotConstraintsOf<Eigen::Dynamic, Eigen::Dynamic>;
using CostExpansion = CostExpansionOf<Eigen::Dynamic, Eigen::Dynamic>;

// Throws std::invalid_argument("<name>: expected <size> entries, got <v.size()>") unless v has size
// entries: for the second-derivative functions, whose fixed-size models would otherwise read past
// a short vector.
void require_size(const Eigen::VectorXd& v, Eigen::Index size, const char* name);

}  // namespace diffpills::trajopt
