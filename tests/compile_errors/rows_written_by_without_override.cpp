// Must not compile (tests/CMakeLists.txt, rows_written_by_refuses_the_default): a problem that
// answers constraints() with rows_written_by<itself> but does not override write_constraints would
// recurse without end through the default write_constraints (problem.hpp). With
// -DWITH_OVERRIDE it overrides it and must compile: the test's control.
#include "diffpills/trajopt/problem.hpp"

namespace {

class Bounded : public diffpills::trajopt::ProblemOf<1, 1> {
 public:
  int state_size() const override { return 1; }
  int control_size() const override { return 1; }
  int knots() const override { return 2; }
  void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                ControlMatrix& B) const override {
    next = x + u;
    A.setOnes();
    B.setOnes();
  }
  Cost stage_cost(int, const State&, const Control&) const override { return {}; }
  Cost terminal_cost(const State&) const override { return {}; }
  Constraints constraints(int k, const State& x, const Control& u) const override {
    return rows_written_by<Bounded>(*this, k, x, u, true);
  }
#ifdef WITH_OVERRIDE
  void write_constraints(int, const State& x, const Control&, bool,
                         Constraints& out) const override {
    out.value = x;
  }
#endif
};

}  // namespace

int main() {
  const Bounded problem;
  return static_cast<int>(
      problem.constraints(0, Bounded::State::Zero(), Bounded::Control::Zero()).value.size());
}
