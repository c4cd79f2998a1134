// The dense part of two capsules' Hessian of phi (capsule_proximity.cpp, issue 12): a 14 x 14
// matrix of rank at most five,
//
//   H = 2 (sum_k plus_k plus_k' - sum_k minus_k minus_k'),
//
// from three rows `plus` and at most two rows `minus` of 14 entries each, computed a column at a
// time in the widest vectors the CPU runs (Google Highway with run-time dispatch, as the capsule
// batches' kernel: AVX-512, AVX2, SSE4, SSSE3 or plain code; fixed-width vectors only, not
// Highway's SVE or RVV targets). Entry (i, j) is formed from the same products in the same order
// as entry (j, i), so H is exactly symmetric (==, a zero's sign aside) on every instruction set;
// the last bits of an entry may differ between instruction sets (fused multiply-adds).
#pragma once

namespace diffpills::detail {

// Rows padded to 16 entries (the last two zero), aligned for any vector width. Entries 7-9 of
// every row are entries 0-2 negated (symmetric_gram relies on it).
struct GramRows {
  alignas(64) double plus[3][16];
  alignas(64) double minus[2][16];
  int minus_count;  // 0, 1 or 2: the rows of `minus` used
};

// Writes H (above) to `out`, 196 doubles in column-major order.
void symmetric_gram(const GramRows& rows, double* out);

// The instruction set symmetric_gram runs on in this process (Highway's name), for tests.
const char* symmetric_gram_target();

}  // namespace diffpills::detail
