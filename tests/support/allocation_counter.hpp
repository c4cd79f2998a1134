// Counting a test binary's heap allocations. allocation_counter.cpp defines malloc and its
// relatives over glibc's own, which Eigen's matrices and operator new both reach; since the
// definitions apply to everything linked in, it goes into binaries of their own (the *_allocations
// tests). Under AddressSanitizer, which defines malloc itself, nothing is defined or counted:
// kCountingAllocations is false and such tests skip (and are labelled no_sanitize).
#pragma once

namespace diffpills::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kCountingAllocations = false;
#else
inline constexpr bool kCountingAllocations = true;
#endif

// The calls of malloc, calloc, realloc and aligned_alloc so far.
long heap_allocations();

}  // namespace diffpills::testing
