// symmetric_gram (src/proximity/symmetric_gram.hpp), the vector kernel of two capsules' Hessian,
// on every instruction set Highway compiled it for that this CPU runs: against the same Gram
// matrix formed by Eigen from the rows (a computation that shares none of its code), exactly
// symmetric, and its three negated columns exactly the negation of the first three.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "proximity/symmetric_gram.hpp"

namespace diffpills::testing {
namespace {

using Matrix14 = Eigen::Matrix<double, 14, 14>;
using Row14 = Eigen::Matrix<double, 1, 14>;

// A row as the capsule Hessian lays it out: entries 7-9 are entries 0-2 negated.
Row14 random_row(std::mt19937_64& rng, double size) {
  std::normal_distribution<double> normal(0.0, size);
  Row14 row;
  for (int i = 0; i < 14; ++i) row(i) = normal(rng);
  row.segment<3>(7) = -row.head<3>();
  return row;
}

void set(double* padded, const Row14& row) {
  for (int i = 0; i < 14; ++i) padded[i] = row(i);
  padded[14] = padded[15] = 0.0;
}

template <class Check>
void on_every_target(const Check& check) {
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target));
    ASSERT_STREQ(detail::symmetric_gram_target(), hwy::TargetName(target));
    check();
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(SymmetricGram, MatchesEigensGramOnEveryInstructionSet) {
  on_every_target([] {
    std::mt19937_64 rng(1201);
    for (int trial = 0; trial < 300; ++trial) {
      const double size = std::ldexp(1.0, trial % 40 - 20);
      detail::GramRows rows;
      rows.minus_count = trial % 3;
      Eigen::Matrix<double, 3, 14> plus;
      Eigen::Matrix<double, 2, 14> minus = Eigen::Matrix<double, 2, 14>::Zero();
      for (int k = 0; k < 3; ++k) {
        plus.row(k) = random_row(rng, size);
        set(rows.plus[k], plus.row(k));
      }
      for (int k = 0; k < rows.minus_count; ++k) {
        minus.row(k) = random_row(rng, size);
        set(rows.minus[k], minus.row(k));
      }
      // Rows beyond minus_count hold garbage the kernel must not read.
      for (int k = rows.minus_count; k < 2; ++k) {
        for (double& entry : rows.minus[k]) entry = std::nan("");
      }
      Matrix14 H;
      H.setConstant(std::nan(""));
      detail::symmetric_gram(rows, H.data());
      const Matrix14 expected = 2.0 * (plus.transpose() * plus - minus.transpose() * minus);
      const double entry_size = (plus.cwiseAbs2().colwise().sum().maxCoeff() +
                                 minus.cwiseAbs2().colwise().sum().maxCoeff());
      for (int j = 0; j < 14; ++j) {
        for (int i = 0; i < 14; ++i) {
          ASSERT_NEAR(H(i, j), expected(i, j), 1e-14 * entry_size) << i << ", " << j;
          ASSERT_EQ(H(i, j), H(j, i)) << i << ", " << j;
        }
      }
      const Eigen::Matrix<double, 14, 3> negated = -H.leftCols<3>();
      ASSERT_EQ(H.middleCols<3>(7), negated);
    }
  });
}

// Exactly 0 where every row is 0 (no stale lanes), and no write outside the 196 entries.
TEST(SymmetricGram, WritesExactlyTheMatrix) {
  on_every_target([] {
    detail::GramRows rows{};
    rows.minus_count = 2;
    double out[196 + 16];
    for (double& entry : out) entry = 7.0;
    detail::symmetric_gram(rows, out);
    for (int i = 0; i < 196; ++i) ASSERT_EQ(out[i], 0.0) << i;
    for (int i = 196; i < 196 + 16; ++i) ASSERT_EQ(out[i], 7.0) << i;
  });
}

}  // namespace
}  // namespace diffpills::testing
