#include "box_tree.hpp"

#include <algorithm>
#include <array>
#include <numeric>

namespace diffpills::detail {
namespace {

// A leaf's boxes are paired with each other directly: below a handful, that is cheaper than more
// levels of the tree.
constexpr int kLeafBoxes = 2;

// 10 bits per axis: the centres' bounding box cut into 1024^3 cells.
constexpr int kBitsPerAxis = 10;

// Below this many items a comparison sort beats the radix sort's three passes over 1024 buckets.
constexpr std::size_t kRadixSortFrom = 512;

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

// Sorts by code, stably: a radix sort (10 bits a pass, O(n)) for many items.
void sort_by_code(std::vector<Keyed>& items) {
  if (items.size() < kRadixSortFrom) {
    std::stable_sort(items.begin(), items.end(),
                     [](const Keyed& a, const Keyed& b) { return a.code < b.code; });
    return;
  }
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
  int first = 0, end = 0;  // its boxes: order[first, end)
  int children[2] = {-1, -1};
  int group = -1;                           // the group all its boxes share, or -1
  std::uint32_t categories = 0, masks = 0;  // unions over its boxes
  bool is_leaf() const { return children[0] < 0; }
};

class BoxTree {
 public:
  BoxTree(const std::vector<Box>& boxes, const std::vector<BoxFilter>& filters,
          const std::function<bool(int, int)>& groups_checked)
      : boxes_(boxes), filters_(filters), groups_checked_(groups_checked) {
    const int count = static_cast<int>(boxes.size());
    if (count == 0) return;
    order_.resize(boxes.size());
    std::iota(order_.begin(), order_.end(), 0);
    codes_.resize(boxes.size());
    rekey(0, count);
    nodes_.reserve(4 * boxes.size() / kLeafBoxes + 4);
    build(0, count);
    // The walk reads boxes and filters in the tree's order, from contiguous memory.
    sorted_.reserve(boxes.size());
    sorted_filters_.reserve(boxes.size());
    for (const int i : order_) {
      sorted_.push_back(boxes[static_cast<std::size_t>(i)]);
      sorted_filters_.push_back(filters[static_cast<std::size_t>(i)]);
    }
  }

  std::vector<std::pair<int, int>> self_pairs() {
    if (!nodes_.empty()) within(0);
    return std::move(pairs_);
  }

 private:
  Eigen::Vector3d twice_centre(int i) const {
    const Box& b = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])];
    return b.low + b.high;
  }

  // Morton codes of the centres of order[first, end) in their own bounding box, and the range
  // sorted by them. False if the centres coincide (no code can tell them apart).
  bool rekey(int first, int end) {
    Eigen::Vector3d low = twice_centre(first), high = low;
    for (int i = first + 1; i < end; ++i) {
      low = low.cwiseMin(twice_centre(i));
      high = high.cwiseMax(twice_centre(i));
    }
    const Eigen::Vector3d extent = high - low;
    if (!(extent.maxCoeff() > 0.0)) return false;
    const double cells = (1 << kBitsPerAxis) - 1;
    std::vector<Keyed> keyed(static_cast<std::size_t>(end - first));
    for (int i = first; i < end; ++i) {
      const Eigen::Vector3d centre = twice_centre(i);
      std::uint32_t code = 0;
      for (int axis = 0; axis < 3; ++axis) {
        const double t = extent(axis) > 0.0 ? (centre(axis) - low(axis)) / extent(axis) : 0.0;
        const auto cell = static_cast<std::uint32_t>(std::clamp(t * cells, 0.0, cells));
        code |= spread_bits(cell) << (2 - axis);
      }
      keyed[static_cast<std::size_t>(i - first)] = {code, order_[static_cast<std::size_t>(i)]};
    }
    sort_by_code(keyed);
    for (int i = first; i < end; ++i) {
      const Keyed& item = keyed[static_cast<std::size_t>(i - first)];
      codes_[static_cast<std::size_t>(i)] = item.code;
      order_[static_cast<std::size_t>(i)] = item.box;
    }
    return true;
  }

  // Splits a range of sorted codes where its first and last codes first differ (the cells of an
  // octree over the centres); a range of equal codes is keyed again in its own bounding box, or
  // split in the middle if its centres coincide. Bounds and filter summaries come from below.
  int build(int first, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].end = end;
    if (end - first <= kLeafBoxes) {
      Node& leaf = nodes_[static_cast<std::size_t>(index)];
      const auto input = [&](int i) { return static_cast<std::size_t>(order_[i]); };
      leaf.box = boxes_[input(first)];
      leaf.group = filters_[input(first)].group;
      for (int i = first; i < end; ++i) {
        const BoxFilter& filter = filters_[input(i)];
        leaf.box = merged(leaf.box, boxes_[input(i)]);
        if (filter.group != leaf.group) leaf.group = -1;
        leaf.categories |= filter.category;
        leaf.masks |= filter.mask;
      }
      return index;
    }
    const auto code = [&](int i) { return codes_[static_cast<std::size_t>(i)]; };
    int split = first + (end - first) / 2;
    if (code(first) != code(end - 1) || rekey(first, end)) {
      // The highest bit where the range's ends differ: codes with it set come second.
      const std::uint32_t a = code(first), b = code(end - 1);
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
    const Node& l = nodes_[static_cast<std::size_t>(left)];
    const Node& r = nodes_[static_cast<std::size_t>(right)];
    node.children[0] = left;
    node.children[1] = right;
    node.box = merged(l.box, r.box);
    node.group = l.group == r.group ? l.group : -1;
    node.categories = l.categories | r.categories;
    node.masks = l.masks | r.masks;
    return index;
  }

  const Node& node(int index) const { return nodes_[static_cast<std::size_t>(index)]; }

  // Can the two nodes hold an allowed pair across them?
  bool may_pair(const Node& a, const Node& b) const {
    if (a.group >= 0 && a.group == b.group) return false;
    if ((a.categories & b.masks) == 0 || (b.categories & a.masks) == 0) return false;
    return a.group < 0 || b.group < 0 || groups_checked_(a.group, b.group);
  }

  void test(int i, int j) {
    const BoxFilter& f = sorted_filters_[static_cast<std::size_t>(i)];
    const BoxFilter& g = sorted_filters_[static_cast<std::size_t>(j)];
    if (f.group == g.group || (f.category & g.mask) == 0 || (g.category & f.mask) == 0) return;
    if (!overlap(sorted_[static_cast<std::size_t>(i)], sorted_[static_cast<std::size_t>(j)])) {
      return;
    }
    if (!groups_checked_(f.group, g.group)) return;
    const int a = order_[static_cast<std::size_t>(i)];
    const int b = order_[static_cast<std::size_t>(j)];
    pairs_.emplace_back(std::min(a, b), std::max(a, b));
  }

  // The pairs among a node's own boxes: its children's own pairs and the pairs across them. A
  // node of one group holds none.
  void within(int index) {
    const Node& n = node(index);
    if (n.group >= 0) return;
    if (n.is_leaf()) {
      for (int i = n.first; i < n.end; ++i) {
        for (int j = i + 1; j < n.end; ++j) test(i, j);
      }
      return;
    }
    within(n.children[0]);
    within(n.children[1]);
    const Node& left = node(n.children[0]);
    const Node& right = node(n.children[1]);
    if (overlap(left.box, right.box) && may_pair(left, right)) {
      across(n.children[0], n.children[1]);
    }
  }

  // The pairs with one box in each of two nodes whose boxes overlap. The node with more boxes is
  // split (the other, if it is a leaf), and only children whose boxes overlap the other node's,
  // and that may pair with it, are visited.
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
        if (overlap(node(child).box, b.box) && may_pair(node(child), b)) across(child, index_b);
      }
    } else {
      for (const int child : b.children) {
        if (overlap(a.box, node(child).box) && may_pair(a, node(child))) across(index_a, child);
      }
    }
  }

  const std::vector<Box>& boxes_;
  const std::vector<BoxFilter>& filters_;
  const std::function<bool(int, int)>& groups_checked_;
  std::vector<int> order_;            // input indices in the tree's order
  std::vector<std::uint32_t> codes_;  // order_'s codes, sorted within each keyed range
  std::vector<Box> sorted_;           // the boxes in the tree's order
  std::vector<BoxFilter> sorted_filters_;
  std::vector<Node> nodes_;
  std::vector<std::pair<int, int>> pairs_;
};

}  // namespace

Box merged(const Box& a, const Box& b) { return {a.low.cwiseMin(b.low), a.high.cwiseMax(b.high)}; }

std::vector<std::pair<int, int>> overlapping_pairs(
    const std::vector<Box>& boxes, const std::vector<BoxFilter>& filters,
    const std::function<bool(int, int)>& groups_checked) {
  return BoxTree(boxes, filters, groups_checked).self_pairs();
}

std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box>& boxes) {
  std::vector<BoxFilter> filters(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) filters[i].group = static_cast<int>(i);
  return overlapping_pairs(boxes, filters, [](int, int) { return true; });
}

}  // namespace diffpills::detail
