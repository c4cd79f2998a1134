#include "box_tree.hpp"

#include <algorithm>
#include <array>
#include <cstdint>

namespace diffpills::detail {
namespace {

// A leaf's boxes are paired with each other directly: below a handful, that is cheaper than more
// levels of the tree.
constexpr int kLeafBoxes = 2;

// 10 bits per axis: the centres' bounding box cut into 1024^3 cells.
constexpr int kBitsPerAxis = 10;

// The bits of v (< 2^10) spread to every third bit: b9 .. b0 -> b9 0 0 b8 0 0 ... b0.
std::uint32_t spread_bits(std::uint32_t v) {
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

struct Keyed {
  std::uint32_t code;
  int box;
};

// Radix sort by code, 10 bits a pass (stable, O(n)).
void sort_by_code(std::vector<Keyed>& items) {
  std::vector<Keyed> buffer(items.size());
  for (int shift = 0; shift < 3 * kBitsPerAxis; shift += kBitsPerAxis) {
    std::array<std::size_t, (1u << kBitsPerAxis) + 1> start{};
    for (const Keyed& item : items) ++start[((item.code >> shift) & 1023u) + 1];
    for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    for (const Keyed& item : items) buffer[start[(item.code >> shift) & 1023u]++] = item;
    items.swap(buffer);
  }
}

struct Node {
  Box box;
  int first = 0, end = 0;  // its boxes: sorted[first, end)
  int children[2] = {-1, -1};
  bool is_leaf() const { return children[0] < 0; }
};

class BoxTree {
 public:
  explicit BoxTree(const std::vector<Box>& boxes) {
    if (boxes.empty()) return;
    // Morton codes of the centres, in the centres' bounding box.
    Eigen::Vector3d low = boxes[0].low + boxes[0].high, high = low;  // twice the centres
    for (const Box& b : boxes) {
      low = low.cwiseMin(b.low + b.high);
      high = high.cwiseMax(b.low + b.high);
    }
    const Eigen::Vector3d extent = high - low;
    const double cells = (1 << kBitsPerAxis) - 1;
    std::vector<Keyed> keyed(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      std::uint32_t code = 0;
      for (int axis = 0; axis < 3; ++axis) {
        const double t =
            extent(axis) > 0.0
                ? ((boxes[i].low(axis) + boxes[i].high(axis)) - low(axis)) / extent(axis)
                : 0.0;
        const auto cell = static_cast<std::uint32_t>(std::clamp(t * cells, 0.0, cells));
        code |= spread_bits(cell) << (2 - axis);
      }
      keyed[i] = {code, static_cast<int>(i)};
    }
    sort_by_code(keyed);
    codes_.resize(keyed.size());
    sorted_.resize(keyed.size());
    input_index_.reserve(keyed.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) {
      codes_[i] = keyed[i].code;
      sorted_[i] = boxes[static_cast<std::size_t>(keyed[i].box)];
      input_index_.push_back(keyed[i].box);
    }
    nodes_.reserve(4 * boxes.size() / kLeafBoxes + 4);
    build(0, static_cast<int>(boxes.size()));
  }

  std::vector<std::pair<int, int>> self_pairs() {
    if (!nodes_.empty()) within(0);
    return std::move(pairs_);
  }

 private:
  // Splits a range of sorted codes where its first and last codes first differ (the cells of an
  // octree over the centres), or in the middle when they are equal; bounds come from below.
  int build(int first, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].end = end;
    if (end - first <= kLeafBoxes) {
      Box box = sorted_[static_cast<std::size_t>(first)];
      for (int i = first + 1; i < end; ++i) box = merged(box, sorted_[static_cast<std::size_t>(i)]);
      nodes_[static_cast<std::size_t>(index)].box = box;
      return index;
    }
    const std::uint32_t a = codes_[static_cast<std::size_t>(first)];
    const std::uint32_t b = codes_[static_cast<std::size_t>(end - 1)];
    int split = first + (end - first) / 2;
    if (a != b) {
      // The highest bit where they differ: codes in the range with it set come second.
      std::uint32_t bit = 1u << 31;
      while ((a & bit) == (b & bit)) bit >>= 1;
      const auto begin = codes_.begin();
      split =
          static_cast<int>(std::partition_point(begin + first, begin + end,
                                                [bit](std::uint32_t c) { return (c & bit) == 0; }) -
                           begin);
    }
    const int left = build(first, split);
    const int right = build(split, end);
    Node& node = nodes_[static_cast<std::size_t>(index)];
    node.children[0] = left;
    node.children[1] = right;
    node.box = merged(nodes_[static_cast<std::size_t>(left)].box,
                      nodes_[static_cast<std::size_t>(right)].box);
    return index;
  }

  const Node& node(int index) const { return nodes_[static_cast<std::size_t>(index)]; }
  void test(int i, int j) {
    if (!overlap(sorted_[static_cast<std::size_t>(i)], sorted_[static_cast<std::size_t>(j)])) {
      return;
    }
    const int a = input_index_[static_cast<std::size_t>(i)];
    const int b = input_index_[static_cast<std::size_t>(j)];
    pairs_.emplace_back(std::min(a, b), std::max(a, b));
  }

  // The pairs among a node's own boxes: its children's own pairs and the pairs across them.
  void within(int index) {
    const Node& n = node(index);
    if (n.is_leaf()) {
      for (int i = n.first; i < n.end; ++i) {
        for (int j = i + 1; j < n.end; ++j) test(i, j);
      }
      return;
    }
    within(n.children[0]);
    within(n.children[1]);
    if (overlap(node(n.children[0]).box, node(n.children[1]).box)) {
      across(n.children[0], n.children[1]);
    }
  }

  // The pairs with one box in each of two nodes whose boxes overlap. The node with more boxes is
  // split (the other, if it is a leaf), and only children whose boxes overlap the other node's are
  // visited.
  void across(int index_a, int index_b) {
    const Node& a = node(index_a);
    const Node& b = node(index_b);
    if (a.is_leaf() && b.is_leaf()) {
      for (int i = a.first; i < a.end; ++i) {
        for (int j = b.first; j < b.end; ++j) test(i, j);
      }
      return;
    }
    if (b.is_leaf() || (!a.is_leaf() && a.end - a.first >= b.end - b.first)) {
      for (const int child : a.children) {
        if (overlap(node(child).box, b.box)) across(child, index_b);
      }
    } else {
      for (const int child : b.children) {
        if (overlap(a.box, node(child).box)) across(index_a, child);
      }
    }
  }

  std::vector<std::uint32_t> codes_;  // sorted
  std::vector<Box> sorted_;           // the boxes in the codes' order
  std::vector<int> input_index_;      // the input index of each sorted box
  std::vector<Node> nodes_;
  std::vector<std::pair<int, int>> pairs_;
};

}  // namespace

Box merged(const Box& a, const Box& b) { return {a.low.cwiseMin(b.low), a.high.cwiseMax(b.high)}; }

std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box>& boxes) {
  return BoxTree(boxes).self_pairs();
}

}  // namespace diffpills::detail
