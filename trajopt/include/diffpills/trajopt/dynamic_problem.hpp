// DynamicProblem<Nx, Nu>: a fixed-size problem (problem.hpp) seen through the run-time-sized
// interface, for code written once against trajopt::Problem (the examples' Ipopt cross-check).
// Every call copies its arguments into the fixed-size types and the answers back out; vectors of
// the wrong size throw std::invalid_argument (require_size) instead of reaching the fixed-size
// code. constraint_hessian's multipliers go to the problem as given, for it to check: their count
// is its constraint rows, which only it knows. At the last knot the empty control becomes the zero
// control and du gets zero columns, as problem.hpp's convention for each side says. The view holds
// a reference: the problem must outlive it.
#pragma once

#include <Eigen/Core>

#include "diffpills/trajopt/problem.hpp"

namespace diffpills::trajopt {

template <int Nx, int Nu>
class DynamicProblem final : public Problem {
  static_assert(Nx != Eigen::Dynamic && Nu != Eigen::Dynamic,
                "a dynamic problem needs no view: use it as a Problem");

 public:
  using Fixed = ProblemOf<Nx, Nu>;

  explicit DynamicProblem(const Fixed& fixed) : fixed_(fixed) {}

  int state_size() const override { return Nx; }
  int control_size() const override { return Nu; }
  int knots() const override { return fixed_.knots(); }

  void dynamics(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& next,
                Eigen::MatrixXd& A, Eigen::MatrixXd& B) const override {
    typename Fixed::State fixed_next;
    typename Fixed::StateMatrix fixed_A;
    typename Fixed::ControlMatrix fixed_B;
    fixed_.dynamics(state(x, "x"), control(u, "u"), fixed_next, fixed_A, fixed_B);
    next = fixed_next;
    A = fixed_A;
    B = fixed_B;
  }
  CostExpansion stage_cost(int k, const Eigen::VectorXd& x,
                           const Eigen::VectorXd& u) const override {
    const typename Fixed::Cost l = fixed_.stage_cost(k, state(x, "x"), control(u, "u"));
    return {l.value, l.x, l.u, l.xx, l.uu, l.ux};
  }
  CostExpansion terminal_cost(const Eigen::VectorXd& x) const override {
    const typename Fixed::Cost l = fixed_.terminal_cost(state(x, "x"));
    return {l.value, l.x, Eigen::VectorXd(), l.xx, Eigen::MatrixXd(), Eigen::MatrixXd()};
  }
  KnotConstraints constraints(int k, const Eigen::VectorXd& x,
                              const Eigen::VectorXd& u) const override {
    return widen(k, fixed_.constraints(k, state(x, "x"), knot_control(k, u)));
  }
  double stage_cost_value(int k, const Eigen::VectorXd& x,
                          const Eigen::VectorXd& u) const override {
    return fixed_.stage_cost_value(k, state(x, "x"), control(u, "u"));
  }
  double terminal_cost_value(const Eigen::VectorXd& x) const override {
    return fixed_.terminal_cost_value(state(x, "x"));
  }
  KnotConstraints constraint_values(int k, const Eigen::VectorXd& x,
                                    const Eigen::VectorXd& u) const override {
    return widen(k, fixed_.constraint_values(k, state(x, "x"), knot_control(k, u)));
  }
  bool has_second_derivatives() const override { return fixed_.has_second_derivatives(); }
  Eigen::MatrixXd dynamics_hessian(const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                   const Eigen::VectorXd& lambda) const override {
    return fixed_.dynamics_hessian(state(x, "x"), control(u, "u"), state(lambda, "lambda"));
  }
  Eigen::MatrixXd constraint_hessian(int k, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                     const Eigen::VectorXd& mu) const override {
    return fixed_.constraint_hessian(k, state(x, "x"), knot_control(k, u), mu);
  }

 private:
  bool last(int k) const { return k == fixed_.knots() - 1; }
  static typename Fixed::State state(const Eigen::VectorXd& x, const char* name) {
    require_size(x, Nx, name);
    return x;
  }
  static typename Fixed::Control control(const Eigen::VectorXd& u, const char* name) {
    require_size(u, Nu, name);
    return u;
  }
  // The control at knot k: none at the last knot (the fixed-size side gets zero there).
  typename Fixed::Control knot_control(int k, const Eigen::VectorXd& u) const {
    if (!last(k)) return control(u, "u");
    require_size(u, 0, "u");
    return Fixed::Control::Zero();
  }
  KnotConstraints widen(int k, const typename Fixed::Constraints& c) const {
    KnotConstraints out;
    out.value = c.value;
    out.dx = c.dx;
    if (last(k)) {
      out.du.resize(c.dx.rows(), 0);
    } else {
      out.du = c.du;
    }
    out.equalities = c.equalities;
    return out;
  }

  const Fixed& fixed_;
};

}  // namespace diffpills::trajopt
