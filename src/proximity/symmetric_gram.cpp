// Compiled once per instruction set by Highway's foreach_target (this file includes itself through
// HWY_TARGET_INCLUDE); the code outside HWY_NAMESPACE is compiled once (HWY_ONCE).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "proximity/symmetric_gram.cpp"
#include "symmetric_gram.hpp"

// The kernel keeps the rows in arrays of vectors whose number it knows at compile time: not
// compiled for Highway's scalable targets, whose vectors are sizeless and of run-time length.
#include <hwy/detect_targets.h>
#undef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)

#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <cstddef>

HWY_BEFORE_NAMESPACE();
namespace diffpills::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Column j of H is 2 (sum_k plus_k[j] plus_k - sum_k minus_k[j] minus_k), its 14 rows in
// vectors of kLanes lanes (1, 2, 4 or 8: 14 rows are 7 x 2, 3 x 4 + 2 or 8 + 6), the rows held in
// registers across the columns. Lane i of column j multiplies the same two numbers as lane j of
// column i and accumulates in the same order (plus_0, plus_1, plus_2, then the minus rows; a fused
// multiply-add's product is exact, so it is the same either way round): H(i, j) == H(j, i)
// exactly. Columns 7-9 are columns 0-2 negated, exactly (entries 7-9 of every row are entries 0-2
// negated: the capsule Hessian's r_b = -r_a, capsule_proximity.cpp), so they are not computed
// again; a zero there may be -0 where its mirror image, computed, is +0. A vector reaching past
// row 13 is stored with a mask.
template <int kMinus>
HWY_INLINE void Gram(const GramRows& rows, double* HWY_RESTRICT out) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  constexpr std::size_t kLanes = HWY_LANES(double);
  constexpr std::size_t kVectors = (14 + kLanes - 1) / kLanes;
  constexpr int kMinusRows = std::max(kMinus, 1);  // arrays of zero length are not C++
  V plus[3][kVectors];
  V minus[kMinusRows][kVectors];
  for (std::size_t v = 0; v < kVectors; ++v) {
    for (int k = 0; k < 3; ++k) plus[k][v] = hn::Load(d, rows.plus[k] + v * kLanes);
    for (int k = 0; k < kMinus; ++k) minus[k][v] = hn::Load(d, rows.minus[k] + v * kLanes);
  }
  const V two = hn::Set(d, 2.0);
  const auto store = [&d](const V& entries, double* at, std::size_t first_row) {
    if (first_row + kLanes <= 14) {
      hn::StoreU(entries, d, at);
    } else {
      hn::BlendedStore(entries, hn::FirstN(d, 14 - first_row), d, at);
    }
  };
  for (std::size_t j = 0; j < 14; ++j) {
    if (j >= 7 && j < 10) continue;
    const V p0 = hn::Set(d, rows.plus[0][j]), p1 = hn::Set(d, rows.plus[1][j]),
            p2 = hn::Set(d, rows.plus[2][j]);
    V m[kMinusRows];
    for (int k = 0; k < kMinus; ++k) m[k] = hn::Set(d, rows.minus[k][j]);
    for (std::size_t v = 0; v < kVectors; ++v) {
      V sum = hn::MulAdd(p2, plus[2][v], hn::MulAdd(p1, plus[1][v], hn::Mul(p0, plus[0][v])));
      if (kMinus > 0) {
        V less = hn::Mul(m[0], minus[0][v]);
        for (int k = 1; k < kMinus; ++k) less = hn::MulAdd(m[k], minus[k][v], less);
        sum = hn::Sub(sum, less);
      }
      const V entries = hn::Mul(two, sum);
      const std::size_t first_row = v * kLanes;
      store(entries, out + 14 * j + first_row, first_row);
      if (j < 3) store(hn::Neg(entries), out + 14 * (j + 7) + first_row, first_row);
    }
  }
}

void SymmetricGram(const GramRows& rows, double* HWY_RESTRICT out) {
  switch (rows.minus_count) {
    case 0:
      return Gram<0>(rows, out);
    case 1:
      return Gram<1>(rows, out);
    default:
      return Gram<2>(rows, out);
  }
}

const char* SymmetricGramTarget() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace diffpills::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace diffpills::detail {

HWY_EXPORT(SymmetricGram);
HWY_EXPORT(SymmetricGramTarget);

void symmetric_gram(const GramRows& rows, double* out) {
  HWY_DYNAMIC_DISPATCH(SymmetricGram)(rows, out);
}

const char* symmetric_gram_target() { return HWY_DYNAMIC_DISPATCH(SymmetricGramTarget)(); }

}  // namespace diffpills::detail
#endif  // HWY_ONCE
