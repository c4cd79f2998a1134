// Tests that run code in a child process whose address space may grow by only so much
// (RLIMIT_AS): the process's current address space, and whether a sanitizer is in the build
// (address-space limits do not mix with the sanitizers' shadow memory; such tests skip).
#pragma once

#include <sys/resource.h>

#include <fstream>
#include <string>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define DIFFPILLS_TEST_SANITIZED
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define DIFFPILLS_TEST_SANITIZED
#endif

namespace diffpills::testing {

#ifdef DIFFPILLS_TEST_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

// The process's address space (VmSize of /proc/self/status), in bytes.
inline rlim_t address_space() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmSize:", 0) == 0) return std::stoull(line.substr(7)) * 1024;
  }
  return 0;
}

// Limits this process's address space to what it holds now plus `headroom` bytes.
inline void limit_address_space(rlim_t headroom) {
  rlimit limit{};
  getrlimit(RLIMIT_AS, &limit);
  limit.rlim_cur = address_space() + headroom;
  setrlimit(RLIMIT_AS, &limit);
}

}  // namespace diffpills::testing
