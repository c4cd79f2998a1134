// A fixed-capacity array on the stack for up to 32 entries, on the heap beyond: the fast paths
// allocate nothing for polygons of common size.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace diffpills::detail {

template <class T, Eigen::Index kInline = 32>
class SmallBuffer {
 public:
  explicit SmallBuffer(Eigen::Index size) : size_(size) {
    if (size_ > kInline) heap_.resize(static_cast<std::size_t>(size_));
  }
  Eigen::Index size() const { return size_; }
  T* data() { return size_ > kInline ? heap_.data() : inline_.data(); }
  const T* data() const { return size_ > kInline ? heap_.data() : inline_.data(); }
  T& operator[](Eigen::Index i) { return data()[i]; }
  const T& operator[](Eigen::Index i) const { return data()[i]; }

 private:
  Eigen::Index size_;
  // Default-initialized, not zeroed: every user writes an entry before reading it, and zeroing
  // (a memset of up to 32 x 56 bytes per buffer) was a tenth of a hexagon pair's enumeration.
  std::array<T, static_cast<std::size_t>(kInline)> inline_;
  std::vector<T> heap_;
};

}  // namespace diffpills::detail
