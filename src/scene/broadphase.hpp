// The broadphase of a scene query (scene.hpp): every primitive's world box (its body-frame points,
// scene_outlines.hpp, moved by its body's pose and grown by its radius), and the primitive pairs
// of checked bodies whose boxes overlap (box_tree.hpp).
#pragma once

#include <vector>

#include "box_tree.hpp"
#include "diffpills/scene.hpp"
#include "scene_outlines.hpp"
#include "unit_quaternion.hpp"

namespace diffpills::detail {

// Pairs of indices into outlines.primitives whose boxes overlap, of two checked bodies (filtered
// during the walk, box_tree.hpp), the earlier body's primitive first, in no particular order.
// `attitudes` is emptied, then holds each body's attitude normalized (one per body, in order),
// for the narrowphase's world poses and chain rule: each body's quaternion is normalized once
// per query. Throws std::invalid_argument as Scene::contacts documents (pose count, margin, a
// primitive's world position beyond kMaxMagnitude).
std::vector<std::pair<int, int>> broadphase(const Scene& scene, const SceneOutlines& outlines,
                                            const std::vector<Pose>& body_poses, double margin,
                                            std::vector<UnitQuaternion>& attitudes);

}  // namespace diffpills::detail
