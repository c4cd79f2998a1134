// diffpills: differentiable collision detection for capsules and padded polygons.
// The umbrella header; see each header for its part of the contract.
#pragma once

#include "diffpills/batch.hpp"
#include "diffpills/proximity.hpp"
#include "diffpills/qp/backward.hpp"
#include "diffpills/qp/box_active_set.hpp"
#include "diffpills/qp/interior_point.hpp"
#include "diffpills/rotation.hpp"
#include "diffpills/scene.hpp"
#include "diffpills/shape_gradient.hpp"
#include "diffpills/shapes.hpp"
#include "diffpills/signed_distance.hpp"
#include "diffpills/version.hpp"
