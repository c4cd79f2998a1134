// Bodies, scenes and the scene query (scene.hpp): validation, then the broadphase's pairs
// (broadphase.hpp) through the narrowphase (signed_distance.hpp) and the chain rule from primitive
// poses to body poses.
#include "diffpills/scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <variant>

#include "broadphase.hpp"
#include "diffpills/rotation.hpp"
#include "diffpills/signed_distance.hpp"
#include "scene_outlines.hpp"
#include "unit_quaternion.hpp"
#include "validation.hpp"

namespace diffpills {
namespace {

// A primitive's world pose (world_pose in scene.hpp) from its body's attitude normalized once per
// query by the broadphase.
Pose posed(const Pose& body_pose, const detail::UnitQuaternion& attitude, const Pose& local) {
  return Pose(body_pose.r() + attitude.matrix() * local.r(),
              quaternion_product(attitude.unit(), local.q() / local.q().norm()));
}

// The body's [dr, dq] from its primitive's [dr_p, dq_p] (scene.hpp, "Chain rule"), dq_p taken at
// the unit quaternion of world_pose: a function of the attitude alone does not change when its
// quaternion is scaled, so its gradient scales by the inverse, and at q (x) q_l it is
// dq_p / (|q| |q_l|). Through the product, d(q (x) q_l)/dq = R(q_l) (rotation.hpp), and
// R(q_l)' = R(q_l*) (q_l* the conjugate: R's vector part changes sign under the transpose), so
// R(q_l)' dq_p = dq_p (x) q_l*.
Eigen::Matrix<double, 7, 1> body_gradient(const detail::UnitQuaternion& attitude, const Pose& local,
                                          const Eigen::Matrix<double, 7, 1>& primitive) {
  const Eigen::Vector4d& q_l = local.q();
  const Eigen::Vector4d conjugate(q_l(0), -q_l(1), -q_l(2), -q_l(3));
  Eigen::Matrix<double, 7, 1> out;
  out.head<3>() = primitive.head<3>();
  out.tail<4>() =
      attitude.rotate_gradient(local.r(), primitive.head<3>()) +
      quaternion_product(primitive.tail<4>(), conjugate) * (attitude.inverse_norm() / q_l.norm());
  return out;
}

// 256 contacts, ~86 KB: below glibc's 128 KiB threshold for mapping an allocation of its own, so
// the reserve comes from the heap and is not page-faulted in on every query.
constexpr std::size_t kContactsReserved = 256;

double radius_of(const Shape& shape) {
  return std::visit([](const auto& s) { return s.radius(); }, shape);
}

}  // namespace

// r + Q(q) r_l and q^ (x) q_l / |q_l|, q^ = q / |q|: q (x) q_l itself is as good an attitude, but
// its entries could exceed 1e100 (or its norm fall below 1e-40) where q's and q_l's do not, and
// the unit one is always a valid Pose. (The broadphase checked r + Q(q) r_l for the scene's
// primitives; a caller's is checked by Pose.)
Pose world_pose(const Pose& body, const Pose& local) {
  return posed(body, detail::UnitQuaternion(body.q()), local);
}

BodyPoseError::BodyPoseError(int body, const std::string& body_name, int shape, std::string reason)
    : std::invalid_argument("body_poses[" + std::to_string(body) + "] (body '" +
                            detail::printable(body_name) + "'), shape " + std::to_string(shape) +
                            ": " + reason),
      body_(body),
      shape_(shape),
      reason_(std::move(reason)) {}

Body::Body(std::string name, std::vector<BodyShape> shapes, CollisionFilter filter)
    : name_(std::move(name)), shapes_(std::move(shapes)), filter_(filter) {
  if (name_.empty()) throw std::invalid_argument("body.name: must not be empty");
}

namespace {

// The outlines of the empty scene, one for every empty scene: a moved-from scene takes them
// without allocating, so the moves cannot throw.
const std::shared_ptr<const detail::SceneOutlines>& empty_outlines() {
  static const std::shared_ptr<const detail::SceneOutlines> empty =
      std::make_shared<detail::SceneOutlines>();
  return empty;
}

}  // namespace

Scene::Scene() : outlines_(empty_outlines()) {}

Scene::Scene(Scene&& other) noexcept
    : bodies_(std::move(other.bodies_)),
      excluded_(std::move(other.excluded_)),
      names_(std::move(other.names_)),
      outlines_(std::exchange(other.outlines_, empty_outlines())) {
  other.bodies_.clear();
  other.excluded_.clear();
  other.names_.clear();
}

Scene& Scene::operator=(Scene&& other) noexcept {
  if (this == &other) return *this;
  bodies_ = std::move(other.bodies_);
  excluded_ = std::move(other.excluded_);
  names_ = std::move(other.names_);
  outlines_ = std::exchange(other.outlines_, empty_outlines());
  other.bodies_.clear();
  other.excluded_.clear();
  other.names_.clear();
  return *this;
}

Scene::Scene(std::vector<Body> bodies,
             const std::vector<std::pair<std::string, std::string>>& exclude)
    : bodies_(std::move(bodies)),
      outlines_(std::make_shared<detail::SceneOutlines>(detail::make_outlines(bodies_))) {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    names_.emplace_back(bodies_[i].name(), static_cast<int>(i));
  }
  std::sort(names_.begin(), names_.end());
  for (std::size_t k = 1; k < names_.size(); ++k) {
    if (names_[k].first == names_[k - 1].first) {
      const int first = std::min(names_[k].second, names_[k - 1].second);
      const int second = std::max(names_[k].second, names_[k - 1].second);
      throw std::invalid_argument("bodies[" + std::to_string(second) + "].name: '" +
                                  detail::printable(names_[k].first) +
                                  "' is also the name of bodies[" + std::to_string(first) + "]");
    }
  }
  for (std::size_t k = 0; k < exclude.size(); ++k) {
    const std::string field = "exclude[" + std::to_string(k) + "]";
    const int i = index_of(exclude[k].first), j = index_of(exclude[k].second);
    for (const auto& [index, name] : {std::pair{i, &exclude[k].first}, {j, &exclude[k].second}}) {
      if (index < 0) {
        throw std::invalid_argument(field + ": no body is named '" + detail::printable(*name) +
                                    "'");
      }
    }
    if (i == j)
      throw std::invalid_argument(field + ": names body '" + detail::printable(exclude[k].first) +
                                  "' twice");
    excluded_.emplace_back(std::min(i, j), std::max(i, j));
  }
  std::sort(excluded_.begin(), excluded_.end());
  excluded_.erase(std::unique(excluded_.begin(), excluded_.end()), excluded_.end());
}

int Scene::index_of(const std::string& name) const {
  const auto found = std::lower_bound(names_.begin(), names_.end(), std::pair{name, -1});
  return found != names_.end() && found->first == name ? found->second : -1;
}

bool Scene::checked(int i, int j) const {
  if (i == j) return false;
  const CollisionFilter& a = body(i).filter();
  const CollisionFilter& b = body(j).filter();
  if ((a.category & b.mask) == 0 || (b.category & a.mask) == 0) return false;
  return !std::binary_search(excluded_.begin(), excluded_.end(),
                             std::pair{std::min(i, j), std::max(i, j)});
}

std::vector<Contact> Scene::contacts(const std::vector<Pose>& body_poses, double margin) const {
  std::vector<detail::UnitQuaternion> attitudes;
  const std::vector<std::pair<int, int>> pairs =
      detail::broadphase(*this, *outlines_, body_poses, margin, attitudes);
  // A primitive in several pairs (a robot's link beside every board of a shelf) is posed once per
  // query: posed normalizes the local quaternion, composes and checks the result.
  std::vector<std::optional<Pose>> world(outlines_->primitives.size());
  const auto world_of = [&](int primitive) -> const Pose& {
    std::optional<Pose>& pose = world[static_cast<std::size_t>(primitive)];
    if (!pose) {
      const detail::SceneOutlines::Primitive& p =
          outlines_->primitives[static_cast<std::size_t>(primitive)];
      const auto owner = static_cast<std::size_t>(p.body);
      pose = posed(body_poses[owner], attitudes[owner],
                   body(p.body).shapes()[static_cast<std::size_t>(p.shape)].pose);
    }
    return *pose;
  };
  // Reserved for the pairs, up to kContactsReserved only: boxes of long thin shapes overlap by the
  // N^2 without a contact (a hostile review: 3000 parallel sticks, 1.4 GB of address space
  // reserved for none), while a robot's query (tens of pairs) then grows the vector no more.
  std::vector<Contact> found;
  found.reserve(std::min(pairs.size(), kContactsReserved));
  for (const auto& [u, v] : pairs) {
    const detail::SceneOutlines::Primitive& first =
        outlines_->primitives[static_cast<std::size_t>(u)];
    const detail::SceneOutlines::Primitive& second =
        outlines_->primitives[static_cast<std::size_t>(v)];
    const BodyShape& a = body(first.body).shapes()[static_cast<std::size_t>(first.shape)];
    const BodyShape& b = body(second.body).shapes()[static_cast<std::size_t>(second.shape)];
    const SignedDistance sd = signed_distance(a.shape, world_of(u), b.shape, world_of(v));
    if (!(sd.distance <= margin)) continue;

    Contact& contact = found.emplace_back();
    contact.bodies = {first.body, second.body};
    contact.shapes = {first.shape, second.shape};
    contact.distance = sd.distance;
    contact.points = sd.points;
    contact.normal = sd.normal;
    contact.gradient << body_gradient(attitudes[static_cast<std::size_t>(first.body)], a.pose,
                                      sd.gradient.head<7>()),
        body_gradient(attitudes[static_cast<std::size_t>(second.body)], b.pose,
                      sd.gradient.tail<7>());
    const double radii = radius_of(a.shape) + radius_of(b.shape);
    if (sd.penetrating) {
      contact.phi = -radii * radii;  // the cores intersect: flat (proximity.hpp)
    } else {
      contact.phi = sd.distance * (sd.distance + 2.0 * radii);
      contact.phi_gradient = 2.0 * (sd.distance + radii) * contact.gradient;
    }
  }
  std::sort(found.begin(), found.end(), [](const Contact& x, const Contact& y) {
    return std::tie(x.bodies[0], x.bodies[1], x.shapes[0], x.shapes[1]) <
           std::tie(y.bodies[0], y.bodies[1], y.shapes[0], y.shapes[1]);
  });
  return found;
}

}  // namespace diffpills
