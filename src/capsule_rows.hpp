// The batches' kernel for two capsules (issue 13): several pose pairs per instruction.
//
// proximity_batch and signed_distance_batch of two capsules hand it each block of rows. It
// answers, in vectors of 2 to 8 doubles (Google Highway, the widest the CPU runs: AVX-512, AVX2,
// SSE4 or plain 64-bit code, chosen at run time), the rows whose closest points are the generic
// case, and leaves the others to the scalar path (`proximity`, `signed_distance`), which handles
// every case. The generic case is what random poses give almost always:
//   - every input finite, |r| components <= 2^40, 2^-60 <= |q|^2 <= 2^60 (the scalar path's pair
//     frame rescales anything; here the raw numbers neither overflow nor lose digits),
//   - the axes more than ~5.7 degrees apart (sin^2 > 1e-2). The formulas are the scalar path's
//     Ericson regime, but two correct computations of the closest points differ by ~eps / sin^2
//     (relative), the points' sensitivity to the rounding of the axes: at sin^2 = 1e-3 the
//     kernel's and the scalar path's gradients, both right to that level, differed by 1e-12 in
//     one row of 10^6. Nearer parallel the scalar path answers (under 1% of random rows),
//   - the cores apart by more than 1e-9 of the scene's size for phi (the scalar path decides
//     intersection there), and by more than 1e-2 of it for the signed distance, whose gradient
//     direction D / |D| the kernel's difference D (exact to a few eps S) gives only to
//     ~eps S / |D|; the scalar path answers nearer rows exactly (and penetration).
// An answered row equals the scalar path's to rounding, relative to the scene's size S (the
// largest of the lengths, the radii's sum and the distance between the middles): phi within
// 1e-12 S^2, the signed distance within 1e-12 S, their gradients within the same per length
// (position parts) and per unit of q (quaternion parts, which carry 1 / |q|); tested on every
// instruction set against the scalar path and a long-double brute force
// (tests/test_capsule_rows.cpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "diffpills/batch.hpp"

namespace diffpills::detail {

enum class CapsuleMeasure { kPhi, kSignedDistance };

// The two capsules and what to compute, for capsule_rows.
struct CapsulePair {
  double length_a, radius_a, length_b, radius_b;
  CapsuleMeasure measure;
};

// True if capsule_rows can answer rows of this pair at all: lengths in [2^-40, 2^40] and radii
// at most 2^40 (zero lengths, points, are the scalar path's).
bool capsule_rows_apply(const CapsulePair& pair);

// Rows [begin, end) of the batch: writes value(i) (phi or the signed distance) and gradient.row(i)
// of every row it answers and sets left[i - begin] = 1 for each row it leaves to the scalar path
// (0 for the others). end - begin <= kCapsuleRowsBlock. The outputs are views taken by const
// reference; the kernel writes through a copy of each Ref, which views the same numbers.
constexpr Eigen::Index kCapsuleRowsBlock = 512;
void capsule_rows(const CapsulePair& pair, const Eigen::Ref<const PositionArray>& r_a,
                  const Eigen::Ref<const QuaternionArray>& q_a,
                  const Eigen::Ref<const PositionArray>& r_b,
                  const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Index begin,
                  Eigen::Index end, const Eigen::Ref<Eigen::VectorXd>& value,
                  const Eigen::Ref<GradientArray>& gradient, std::uint8_t* left);

// The instruction set capsule_rows runs on in this process (Highway's name: "AVX3" for AVX-512,
// "AVX2", "SSE4", "SSSE3", "SCALAR" for plain code), for benchmarks and tests.
const char* capsule_rows_target();

}  // namespace diffpills::detail
