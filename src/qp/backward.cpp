#include "diffpills/qp/backward.hpp"

#include <stdexcept>

namespace diffpills::qp {

// With a = (P + G'WG)^-1 dl/dx and nu = W G a (see the header for the derivation):
//   d_x = -a,  D(lambda) d_lambda = -nu,
//   dl/dP = -1/2 (a x' + x a'),  dl/dc = -a,  dl/dG = -(nu x' + lambda a'),  dl/dh = nu.
QpGradient backward(const InteriorPointSolver& solver, const Eigen::VectorXd& dl_dx) {
  const InteriorPointResult& result = solver.result();
  if (result.status != Status::kSolved) {
    throw std::logic_error("qp::backward: the last solve did not succeed");
  }
  if (dl_dx.size() != result.x.size()) {
    throw std::invalid_argument("qp::backward: dl_dx must have one entry per variable");
  }
  const Eigen::VectorXd a = solver.factorization().solve(dl_dx);
  const Eigen::VectorXd nu = (solver.weights().array() * (solver.G() * a).array()).matrix();
  QpGradient gradient;
  gradient.P = -0.5 * (a * result.x.transpose() + result.x * a.transpose());
  gradient.c = -a;
  gradient.G = -(nu * result.x.transpose() + result.lambda * a.transpose());
  gradient.h = nu;
  return gradient;
}

}  // namespace diffpills::qp
