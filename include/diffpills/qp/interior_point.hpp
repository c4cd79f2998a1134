// A primal-dual interior-point method with Mehrotra predictor-corrector for small dense QPs
//
//     minimize 1/2 x'Px + c'x   subject to  Gx <= h                          (paper eq. qp)
//
// with P symmetric positive semidefinite (n x n) and G (m x n, m >= 1) of full column rank, so that
// P + G'WG is positive definite for every positive diagonal W (true of every QP diffpills builds:
// a bounded polygon's C has rank 2, a segment's bounds have rank 1).
//
// The method is the paper's section II-B (after Mattingley and Boyd's CVXGEN): slack s >= 0 with
// Gx + s = h, affine (predictor) and centering-corrector Newton directions from the same linear
// system, whose matrix is reduced to P + G'WG, W = D(lambda / s), and factored once per iteration
// by Cholesky; the corrector reuses the factorization (Appendix B). Settings, workspace and
// results are kept apart (proxsuite style): one solver object can be reused across problems of the
// same size without reallocating.
//
// Polish: interior-point iterates only approach the solution. Once the residuals are small the
// solver guesses the active set {i : lambda_i > s_i}, solves the equality-constrained KKT system
// for the point closest to the iterate, and accepts it if it satisfies every KKT condition to the
// polish tolerance; otherwise it keeps iterating. A polished solution is exact up to rounding.
// Where the minimizer is not unique the polished point is the optimal point nearest the iterate,
// which tends to the analytic centre of the optimal set (the limit of the central path).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace diffpills::qp {

enum class Status {
  kSolved,            // every KKT residual is within tolerance
  kMaxIterations,     // the iteration cap was reached first
  kNumericalFailure,  // a Newton system could not be factored even after regularization
};

const char* to_string(Status status);

struct InteriorPointSettings {
  int max_iterations = 60;
  // Relative tolerance on the primal residual (against 1 + |h|inf), the dual residual (against
  // 1 + |c|inf) and the mean complementarity s'lambda / m (against 1 + |objective|).
  double tolerance = 1e-12;
  bool polish = true;
  // Polishing is attempted once every residual is below this (relative) level. Waiting longer
  // buys nothing and can hurt: at a vertex fixed by n active rows, W = lambda / s grows past
  // 1e20 and rounding in the reduced system makes the dual residual grow again.
  double polish_threshold = 1e-9;
  // A polished point is accepted when every constraint holds and every active multiplier is
  // nonnegative to this relative level (a right active set gives residuals near rounding).
  double polish_tolerance = 1e-11;
};

struct InteriorPointResult {
  Eigen::VectorXd x;       // primal solution
  Eigen::VectorXd s;       // slack h - Gx (>= 0)
  Eigen::VectorXd lambda;  // multipliers of Gx <= h (>= 0)
  Status status = Status::kMaxIterations;
  int iterations = 0;
  bool polished = false;
  double primal_residual = 0.0;  // |Gx + s - h|inf
  double dual_residual = 0.0;    // |Px + c + G'lambda|inf
  double complementarity = 0.0;  // s'lambda / m
};

class InteriorPointSolver {
 public:
  explicit InteriorPointSolver(const InteriorPointSettings& settings = {});

  // Solves the QP. Throws std::invalid_argument on inconsistent sizes or non-finite data; a
  // problem that does not converge within the cap is reported through result().status.
  const InteriorPointResult& solve(const Eigen::MatrixXd& P, const Eigen::VectorXd& c,
                                   const Eigen::MatrixXd& G, const Eigen::VectorXd& h);

  const InteriorPointResult& result() const { return result_; }
  const InteriorPointSettings& settings() const { return settings_; }

  // The last problem and a factorization of P + G'WG for the backward pass (qp/backward.hpp).
  // It is taken at the returned solution with slacks floored at delta = 3e-10 and multipliers at
  // delta^2 (both relative to 1 + |h|inf): W = lambda_i / delta on active rows, delta^2 / s_i on
  // inactive ones. The backward pass then errs by about delta / lambda_i (W finite on active
  // rows), eps * W (forming P + G'WG rounds P at that level) and delta^2 / s_i (inactive rows
  // leak in), amplified by the conditioning of the active rows. Measured worst relative errors:
  // random QPs of up to 4 variables 6e-5 / 6e-6 / 1.9e-6 / 4e-6 for delta = 1e-8 / 1e-9 / 3e-10 /
  // 1e-10; proximity QPs 8e-8 / 8e-9 / 2e-9 / 1e-9. Flooring multipliers at delta instead of
  // delta^2 let an inactive row with slack 0.08 leak an error of 1e-5; the unfloored final iterate
  // of an unpolished solve (W ~ 1e14) gave 2e-2.
  const Eigen::MatrixXd& G() const { return G_; }
  const Eigen::VectorXd& weights() const { return w_; }
  const Eigen::LLT<Eigen::MatrixXd>& factorization() const { return llt_; }

 private:
  struct Direction {
    Eigen::VectorXd x, s, lambda;
  };

  bool factor(const Eigen::MatrixXd& P);
  void solve_newton(const Eigen::VectorXd& v1, const Eigen::VectorXd& v2, const Eigen::VectorXd& v3,
                    Direction& out) const;
  double step_to_boundary(const Direction& direction) const;
  bool try_polish(const Eigen::MatrixXd& P, const Eigen::VectorXd& c, const Eigen::VectorXd& h);
  void update_residuals(const Eigen::MatrixXd& P, const Eigen::VectorXd& c,
                        const Eigen::VectorXd& h);

  InteriorPointSettings settings_;
  InteriorPointResult result_;
  // Interior iterate (kept separate from result_ so that a polish never disturbs it).
  Eigen::VectorXd x_, s_, lambda_;
  Eigen::MatrixXd G_;
  Eigen::VectorXd w_;
  Eigen::MatrixXd kkt_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd r_dual_, r_primal_;
  Direction affine_, corrector_;
};

}  // namespace diffpills::qp
