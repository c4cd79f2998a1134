#include "box_tree.hpp"

#include <algorithm>
#include <array>
#include <numeric>

namespace diffpills::detail {
namespace {

// A leaf's boxes are paired with each other directly: below a handful, that is cheaper than more
// levels of the tree.
constexpr int kLeafBoxes = 2;

// 10 bits per axis: a range's centres' bounding box cut into 1024^3 cells.
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
  int item;
};

// Sorts by code, stably: a radix sort (10 bits a pass, O(n)) for many items.
void sort_by_code(std::vector<Keyed>& items, std::vector<Keyed>& buffer) {
  if (items.size() < kRadixSortFrom) {
    std::stable_sort(items.begin(), items.end(),
                     [](const Keyed& a, const Keyed& b) { return a.code < b.code; });
    return;
  }
  buffer.resize(items.size());
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
  int first = 0, end = 0;  // its items: positions [first, end) of the hierarchy's order
  int children[2] = {-1, -1};
  bool is_leaf() const { return children[0] < 0; }
};

// A linear BVH over each of several ranges of items (a forest), items being indices into a list
// of boxes. Each range's centres get Morton codes in their own bounding box and are sorted by
// them, and each range of codes is split where its first and last codes first differ: the nodes
// are the cells of an octree over the centres, down to leaves of at most kLeafBoxes items. A range
// whose codes are all equal but whose centres are not (a cluster far smaller than the whole,
// beside one far-away box) gets new codes in its own centres' bounding box and is sorted again,
// so a cluster is split as finely as the rest; a range of identical centres is split in the
// middle. Bounds come from below, O(n).
class Hierarchy {
 public:
  // range_starts: the first position of each range in `items`, ascending, then items.size();
  // every range holds at least one item.
  Hierarchy(const std::vector<Box>& boxes, std::vector<int> items,
            const std::vector<int>& range_starts)
      : boxes_(boxes), order_(std::move(items)) {
    codes_.resize(order_.size());
    nodes_.reserve(2 * order_.size());
    for (std::size_t r = 0; r + 1 < range_starts.size(); ++r) {
      const int first = range_starts[r], end = range_starts[r + 1];
      if (end - first > kLeafBoxes) rekey(first, end);
      roots_.push_back(build(first, end));
    }
    sorted_.reserve(order_.size());
    for (const int i : order_) sorted_.push_back(boxes[static_cast<std::size_t>(i)]);
  }

  int root(int range) const { return roots_[static_cast<std::size_t>(range)]; }
  int node_count() const { return static_cast<int>(nodes_.size()); }
  const Node& node(int index) const { return nodes_[static_cast<std::size_t>(index)]; }
  // The item at a position of the tree's order, and its box (read from contiguous memory).
  int item(int position) const { return order_[static_cast<std::size_t>(position)]; }
  const Box& box_at(int position) const { return sorted_[static_cast<std::size_t>(position)]; }

 private:
  Eigen::Vector3d twice_centre(int position) const {
    const Box& b = boxes_[static_cast<std::size_t>(item(position))];
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
    keyed_.resize(static_cast<std::size_t>(end - first));
    for (int i = first; i < end; ++i) {
      const Eigen::Vector3d centre = twice_centre(i);
      std::uint32_t code = 0;
      for (int axis = 0; axis < 3; ++axis) {
        const double t = extent(axis) > 0.0 ? (centre(axis) - low(axis)) / extent(axis) : 0.0;
        const auto cell = static_cast<std::uint32_t>(std::clamp(t * cells, 0.0, cells));
        code |= spread_bits(cell) << (2 - axis);
      }
      keyed_[static_cast<std::size_t>(i - first)] = {code, item(i)};
    }
    sort_by_code(keyed_, sort_buffer_);
    for (int i = first; i < end; ++i) {
      const Keyed& keyed = keyed_[static_cast<std::size_t>(i - first)];
      codes_[static_cast<std::size_t>(i)] = keyed.code;
      order_[static_cast<std::size_t>(i)] = keyed.item;
    }
    return true;
  }

  // Splits a range of sorted codes where its first and last codes first differ; a range of equal
  // codes is keyed again in its own bounding box, or split in the middle if its centres coincide.
  int build(int first, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].end = end;
    if (end - first <= kLeafBoxes) {
      Box box = boxes_[static_cast<std::size_t>(item(first))];
      for (int i = first + 1; i < end; ++i)
        box = merged(box, boxes_[static_cast<std::size_t>(item(i))]);
      nodes_[static_cast<std::size_t>(index)].box = box;
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
    node.children[0] = left;
    node.children[1] = right;
    node.box = merged(nodes_[static_cast<std::size_t>(left)].box,
                      nodes_[static_cast<std::size_t>(right)].box);
    return index;
  }

  const std::vector<Box>& boxes_;
  std::vector<int> order_;            // items in the tree's order
  std::vector<std::uint32_t> codes_;  // order_'s codes, sorted within each keyed range
  std::vector<Keyed> keyed_, sort_buffer_;
  std::vector<Box> sorted_;  // the boxes in the tree's order
  std::vector<Node> nodes_;
  std::vector<int> roots_;
};

// The pairs of overlapping boxes of a hierarchy: within one node (its children's own pairs and the
// pairs across them), or across two nodes whose boxes overlap (the node with more items is split,
// the other if it is a leaf). may_pair(node_a, node_b) prunes node pairs that can hold no wanted
// pair; visit(position_a, position_b) receives every overlapping pair of leaf items not pruned.
// At a fixed density of boxes the walk visits about O(n log n) node pairs plus the pairs found.
template <class MayPair, class Visit>
class Walk {
 public:
  Walk(const Hierarchy& tree, MayPair may_pair, Visit visit)
      : tree_(tree), may_pair_(std::move(may_pair)), visit_(std::move(visit)) {}

  void within(int index) {
    const Node& n = tree_.node(index);
    if (n.is_leaf()) {
      for (int i = n.first; i < n.end; ++i) {
        for (int j = i + 1; j < n.end; ++j) test(i, j);
      }
      return;
    }
    within(n.children[0]);
    within(n.children[1]);
    visit_across(n.children[0], n.children[1]);
  }

  // The pairs across two nodes, if their boxes overlap and they may pair.
  void visit_across(int index_a, int index_b) {
    if (overlap(tree_.node(index_a).box, tree_.node(index_b).box) && may_pair_(index_a, index_b)) {
      across(index_a, index_b);
    }
  }

 private:
  void test(int i, int j) {
    if (overlap(tree_.box_at(i), tree_.box_at(j))) visit_(i, j);
  }

  void across(int index_a, int index_b) {
    const Node& a = tree_.node(index_a);
    const Node& b = tree_.node(index_b);
    if (a.is_leaf() && b.is_leaf()) {
      for (int i = a.first; i < a.end; ++i) {
        for (int j = b.first; j < b.end; ++j) test(i, j);
      }
      return;
    }
    if (b.is_leaf() || (!a.is_leaf() && a.end - a.first >= b.end - b.first)) {
      for (const int child : a.children) visit_across(child, index_b);
    } else {
      for (const int child : b.children) visit_across(index_a, child);
    }
  }

  const Hierarchy& tree_;
  MayPair may_pair_;
  Visit visit_;
};

template <class MayPair, class Visit>
Walk<MayPair, Visit> make_walk(const Hierarchy& tree, MayPair may_pair, Visit visit) {
  return Walk<MayPair, Visit>(tree, std::move(may_pair), std::move(visit));
}

// What a node of the groups' hierarchy holds: the group all its groups are (a leaf of one group),
// or -1, and the unions of its groups' categories and masks.
struct GroupSummary {
  int group = -1;
  std::uint32_t categories = 0, masks = 0;
};

}  // namespace

Box merged(const Box& a, const Box& b) { return {a.low.cwiseMin(b.low), a.high.cwiseMax(b.high)}; }

// Two levels. The boxes are sorted by group and each group gets its own tree (a forest); a second
// tree is built over the groups' bounding boxes, and walked against itself with node pairs pruned
// by the filters (a node knows the unions of its groups' categories and masks) and by
// groups_checked at its leaves. Only for two groups that may pair and whose bounds overlap are
// their own trees walked against each other, each box pair then filtered exactly. So the boxes of
// one group, or of groups that are never checked against each other (an excluded pair of bodies,
// categories that never meet), cost nothing beyond their trees, however much they overlap.
namespace {

// Up to this many boxes every pair is tested directly, the filters first: sorting, two levels of
// trees and their walk cost more than n (n - 1) / 2 box tests. Measured on random boxes in groups
// of two, 8 to 128 boxes: 3-10x faster where most boxes overlap (43 ns against 439 at 8 boxes,
// 8.9 us against 31 at 128), 3-16x where few do (6.1 us against 17.5 at 128). The trees win from a
// few hundred boxes on; bench_scene's smallest scene (100 bodies, ~200 boxes) keeps them.
constexpr std::size_t kDirectUpTo = 128;

std::vector<std::pair<int, int>> every_pair_tested(
    const std::vector<Box>& boxes, const std::vector<BoxFilter>& filters,
    const std::function<bool(int, int)>& groups_checked) {
  std::vector<std::pair<int, int>> pairs;
  const int n = static_cast<int>(boxes.size());
  for (int i = 0; i < n; ++i) {
    const BoxFilter& f = filters[static_cast<std::size_t>(i)];
    const Box& a = boxes[static_cast<std::size_t>(i)];
    for (int j = i + 1; j < n; ++j) {
      const BoxFilter& g = filters[static_cast<std::size_t>(j)];
      if (f.group == g.group || (f.category & g.mask) == 0 || (g.category & f.mask) == 0 ||
          !overlap(a, boxes[static_cast<std::size_t>(j)]) || !groups_checked(f.group, g.group)) {
        continue;
      }
      pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

}  // namespace

std::vector<std::pair<int, int>> overlapping_pairs(
    const std::vector<Box>& boxes, const std::vector<BoxFilter>& filters,
    const std::function<bool(int, int)>& groups_checked) {
  if (boxes.size() <= kDirectUpTo) return every_pair_tested(boxes, filters, groups_checked);
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> by_group(boxes.size());
  std::iota(by_group.begin(), by_group.end(), 0);
  const auto group_of = [&](int i) { return filters[static_cast<std::size_t>(i)].group; };
  std::stable_sort(by_group.begin(), by_group.end(),
                   [&](int a, int b) { return group_of(a) < group_of(b); });
  std::vector<int> group_starts;
  std::vector<GroupSummary> groups;
  for (std::size_t p = 0; p < by_group.size(); ++p) {
    const BoxFilter& filter = filters[static_cast<std::size_t>(by_group[p])];
    if (p == 0 || filter.group != groups.back().group) {
      group_starts.push_back(static_cast<int>(p));
      groups.push_back({filter.group, 0u, 0u});
    }
    groups.back().categories |= filter.category;
    groups.back().masks |= filter.mask;
  }
  group_starts.push_back(static_cast<int>(by_group.size()));
  const Hierarchy members(boxes, std::move(by_group), group_starts);

  const int group_count = static_cast<int>(groups.size());
  std::vector<Box> group_boxes;
  group_boxes.reserve(groups.size());
  for (int g = 0; g < group_count; ++g) group_boxes.push_back(members.node(members.root(g)).box);
  std::vector<int> all_groups(groups.size());
  std::iota(all_groups.begin(), all_groups.end(), 0);
  const Hierarchy tree(group_boxes, std::move(all_groups), {0, group_count});

  // The groups' nodes' summaries, children before parents (they come after them in the nodes).
  std::vector<GroupSummary> summary(static_cast<std::size_t>(tree.node_count()));
  for (int index = tree.node_count() - 1; index >= 0; --index) {
    const Node& n = tree.node(index);
    GroupSummary& s = summary[static_cast<std::size_t>(index)];
    if (n.is_leaf()) {
      for (int i = n.first; i < n.end; ++i) {
        const GroupSummary& g = groups[static_cast<std::size_t>(tree.item(i))];
        s.group = n.end - n.first == 1 ? g.group : -1;
        s.categories |= g.categories;
        s.masks |= g.masks;
      }
    } else {
      const GroupSummary& l = summary[static_cast<std::size_t>(n.children[0])];
      const GroupSummary& r = summary[static_cast<std::size_t>(n.children[1])];
      s = {-1, l.categories | r.categories, l.masks | r.masks};
    }
  }
  const auto filters_meet = [](const GroupSummary& a, const GroupSummary& b) {
    return (a.categories & b.masks) != 0 && (b.categories & a.masks) != 0;
  };
  const auto may_pair_nodes = [&](int a, int b) {
    const GroupSummary& x = summary[static_cast<std::size_t>(a)];
    const GroupSummary& y = summary[static_cast<std::size_t>(b)];
    return filters_meet(x, y) && (x.group < 0 || y.group < 0 || groups_checked(x.group, y.group));
  };
  const auto visit_box_pair = [&](int p, int q) {
    const int a = members.item(p), b = members.item(q);
    const BoxFilter& f = filters[static_cast<std::size_t>(a)];
    const BoxFilter& g = filters[static_cast<std::size_t>(b)];
    if ((f.category & g.mask) != 0 && (g.category & f.mask) != 0) {
      pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
  };
  auto member_walk = make_walk(
      members, [](int, int) { return true; }, visit_box_pair);
  const auto visit_group_pair = [&](int p, int q) {
    const int g = tree.item(p), h = tree.item(q);
    const GroupSummary& x = groups[static_cast<std::size_t>(g)];
    const GroupSummary& y = groups[static_cast<std::size_t>(h)];
    if (filters_meet(x, y) && groups_checked(x.group, y.group)) {
      member_walk.visit_across(members.root(g), members.root(h));
    }
  };
  make_walk(tree, may_pair_nodes, visit_group_pair).within(tree.root(0));
  return pairs;
}

std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box>& boxes) {
  std::vector<BoxFilter> filters(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) filters[i].group = static_cast<int>(i);
  return overlapping_pairs(boxes, filters, [](int, int) { return true; });
}

}  // namespace diffpills::detail
