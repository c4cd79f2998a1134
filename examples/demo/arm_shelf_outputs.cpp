#include "arm_shelf_outputs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <variant>

#include "demo_json.hpp"
#include "ipopt/problem_nlp.hpp"
#include "json_io.hpp"
#include "svg.hpp"

namespace diffpills::examples {
namespace {

using json = nlohmann::ordered_json;

json list_of(const std::vector<double>& values) { return json(values); }

// An orthographic view: world points to the canvas (right, up), placed at `at`.
struct View {
  Eigen::Vector3d right, up;
  Eigen::Vector2d at;
  Eigen::Vector2d operator()(const Eigen::Vector3d& x) const {
    return Eigen::Vector2d(x.dot(right), x.dot(up)) + at;
  }
};

// Draws a posed shape's silhouette (exact for an orthographic view: the projected core stroked at
// width 2 R).
void draw(Svg& svg, const View& view, const Shape& shape, const Pose& pose,
          const std::string& color, double opacity) {
  const Eigen::Matrix3d R = rotation_matrix(pose.q());
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    const Eigen::Vector3d half = 0.5 * capsule->length() * R.col(0);
    svg.segment(view(pose.r() - half), view(pose.r() + half), capsule->radius(), color, opacity);
    return;
  }
  const auto& polygon = std::get<PaddedPolygon>(shape);
  std::vector<Eigen::Vector2d> outline;
  for (Eigen::Index i = 0; i < polygon.vertices().rows(); ++i) {
    outline.push_back(view(pose.r() + R.leftCols<2>() * polygon.vertices().row(i).transpose()));
  }
  svg.polygon(outline, polygon.radius(), color, opacity);
}

}  // namespace

ArmShelfRun solve_arm_shelf(const ArmShelfProblem& problem, const DemoSettings& settings) {
  const ArmShelfScenario& s = problem.scenario();
  ArmShelfRun run;
  std::vector<Eigen::VectorXd> line{s.start};
  for (const Eigen::VectorXd& u : problem.straight_line_controls()) {
    line.emplace_back(line.back() + s.dt * u);
  }
  run.straight_line_min_distance = arm_shelf_path_min_distance(problem, line, 1);
  const std::vector<Eigen::VectorXd> guess = problem.retreat_controls();
  run.runs = settings.runs(true);
  AltroRun altro = fastest_altro(run.runs, [&] {
    return trajopt::solve(problem, s.start, guess, ArmShelfProblem::settings());
  });
  run.result = std::move(altro.result);
  run.solve_ms = altro.solve_ms;
  run.min_distance = arm_shelf_path_min_distance(problem, run.result.states, 1);
  run.path_min_distance = arm_shelf_path_min_distance(problem, run.result.states, 20);
  if (!settings.quick) {
    run.ipopt = fastest_ipopt(run.runs, [&](IpoptHessian hessian) {
      return solve_problem_with_ipopt(problem, s.start, guess, hessian, settings.ipopt_cpu_seconds);
    });
  }
  return run;
}

void write_arm_shelf_csv(const ArmShelfProblem& problem, const ArmShelfRun& run,
                         const std::filesystem::path& path) {
  std::ostringstream out;
  out << std::setprecision(17) << "t,q1,q2,q3,q4,q5,q6,q7\n";
  const auto& states = run.result.states;
  for (std::size_t k = 0; k < states.size(); ++k) {
    out << static_cast<double>(k) * problem.scenario().dt;
    for (int i = 0; i < 7; ++i) out << "," << states[k](i);
    out << "\n";
  }
  write_file(path, out.str());
}

void write_arm_shelf_json(const ArmShelfProblem& problem, const ArmShelfRun& run,
                          const std::filesystem::path& path) {
  const ArmShelfScenario& s = problem.scenario();
  const PandaArm& arm = s.arm;
  json links = json::array();
  for (std::size_t f = 0; f < arm.links.size(); ++f) {
    json shapes = json::array();
    for (const BodyShape& shape : arm.links[f])
      shapes.push_back(app::to_json(shape.shape, shape.pose));
    links.push_back({{"frame", f}, {"shapes", shapes}});
  }
  json excluded = json::array();
  for (const auto& [f, g] : arm.excluded_link_pairs) excluded.push_back({f, g});
  json limits = json::array();
  for (int i = 0; i < 7; ++i) limits.push_back({arm.joint_limits(i, 0), arm.joint_limits(i, 1)});
  json out = {{"dh",
               {{"a", list_of(arm.chain.a)},
                {"d", list_of(arm.chain.d)},
                {"alpha", list_of(arm.chain.alpha)}}},
              {"flange_d", arm.chain.flange_d},
              {"joint_limits", limits},
              {"velocity_limits", json_list(arm.velocity_limits)},
              {"links", links},
              {"excluded_link_pairs", excluded},
              {"shelf", app::to_json(Scene(s.shelf))},
              {"start", json_list(s.start)},
              {"goal", json_list(s.goal)},
              {"knots", s.knots},
              {"dt", s.dt},
              {"clearance", s.clearance},
              {"status", trajopt::to_string(run.result.status)},
              {"iterations", run.result.iterations},
              {"ms", run.solve_ms},
              {"cost", run.result.cost},
              {"max_violation", run.result.max_violation},
              {"min_distance", run.min_distance},
              {"path_min_distance", run.path_min_distance},
              {"straight_line_min_distance", run.straight_line_min_distance},
              {"solver", altro_summary(run.result, run.solve_ms)}};
  add_ipopt_comparison(out, run.ipopt, run.result, run.solve_ms, run.runs);
  write_file(path, out.dump(2) + "\n");
}

void write_arm_shelf_svg(const ArmShelfProblem& problem, const ArmShelfRun& run,
                         const std::filesystem::path& path) {
  const ArmShelfScenario& s = problem.scenario();
  // Two panels on one canvas: seen from behind the robot, along +x (world -y to the right, z up),
  // and from its right, along +y (x to the right, z up).
  const std::vector<View> views = {
      {-Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), Eigen::Vector2d(-0.75, 0.0)},
      {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ(), Eigen::Vector2d(0.45, 0.0)}};
  // The arm at five knots, start (green) to goal (red), and the hand's path.
  const auto& states = run.result.states;
  const std::size_t last = states.size() - 1;
  const std::vector<std::size_t> knots = {0, last / 4, last / 2, 3 * last / 4, last};
  const std::vector<std::string> colours = {"#2ca02c", "#1f77b4", "#9467bd", "#ff7f0e", "#d62728"};
  Svg svg({-1.3, -0.05}, {1.35, 1.25}, 360.0);
  for (const View& view : views) {
    for (const Body& board : s.shelf) {
      for (const BodyShape& shape : board.shapes()) {
        draw(svg, view, shape.shape, shape.pose, "#9a9a9a", 0.35);
      }
    }
    for (std::size_t i = 0; i < knots.size(); ++i) {
      const std::vector<Pose> poses = arm_shelf_poses(s, states[knots[i]]);
      for (std::size_t f = 0; f < s.arm.links.size(); ++f) {
        for (const BodyShape& shape : s.arm.links[f]) {
          draw(svg, view, shape.shape, world_pose(poses[f], shape.pose), colours[i], 0.3);
        }
      }
    }
    for (std::size_t k = 0; k < last; ++k) {
      const Eigen::Vector3d hand = arm_shelf_poses(s, states[k])[8].r();
      const Eigen::Vector3d next = arm_shelf_poses(s, states[k + 1])[8].r();
      svg.segment(view(hand), view(next), 0.0, "#202020");
    }
  }
  std::ostringstream title, distances;
  title << std::setprecision(3) << "arm_shelf: " << trajopt::to_string(run.result.status) << " in "
        << run.solve_ms << " ms; the joint-space straight line collides ("
        << run.straight_line_min_distance << " m)";
  distances << std::setprecision(3) << "smallest signed distance " << run.min_distance
            << " m at the knots, " << run.path_min_distance << " m between them";
  svg.text({-1.25, 1.22}, title.str(), 16);
  svg.text({-1.25, 1.16}, distances.str(), 14);
  svg.text({-1.25, 1.10}, "the arm at t = 0 (green), 1, 2, 3, 4 s (red); black: the flange's path",
           14);
  svg.text({-1.0, -0.03}, "from behind the robot (along +x)", 14);
  svg.text({0.5, -0.03}, "from the right (along +y)", 14);
  write_file(path, svg.str());
}

}  // namespace diffpills::examples
