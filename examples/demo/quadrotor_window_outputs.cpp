#include "quadrotor_window_outputs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "demo_json.hpp"
#include "ipopt/problem_nlp.hpp"
#include "json_io.hpp"
#include "svg.hpp"

namespace diffpills::examples {

namespace {

using json = nlohmann::ordered_json;

// The angle between body z and world z: cos = R(q)_zz = 1 - 2 (qx^2 + qy^2).
double tilt_deg(const Eigen::VectorXd& x) {
  const double cosine = 1.0 - 2.0 * (x(4) * x(4) + x(5) * x(5));
  return std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / M_PI;
}

double level_straight_line_min_phi(const QuadrotorWindowScenario& s) {
  double smallest = INFINITY;
  const int steps = 200;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    smallest = std::min(smallest, quadrotor_min_phi(s, (1.0 - t) * s.x0 + t * s.goal));
  }
  return smallest;
}

}  // namespace

QuadrotorWindowRun solve_quadrotor_window(const QuadrotorWindowProblem& problem,
                                          const DemoSettings& settings) {
  const QuadrotorWindowScenario& s = problem.scenario();
  QuadrotorWindowRun run;
  run.level_straight_line_min_phi = level_straight_line_min_phi(s);
  run.runs = settings.runs(false);
  const std::vector<Eigen::VectorXd> guess = problem.hover_controls();
  AltroRun altro = fastest_altro(run.runs, [&] { return trajopt::solve(problem, s.x0, guess); });
  run.result = std::move(altro.result);
  run.solve_ms = altro.solve_ms;
  if (!settings.quick) {
    run.ipopt = fastest_ipopt(run.runs, [&](IpoptHessian hessian) {
      return solve_problem_with_ipopt(problem, s.x0, guess, hessian, settings.ipopt_cpu_seconds);
    });
  }
  run.min_phi = INFINITY;
  for (const Eigen::VectorXd& x : run.result.states) {
    run.min_phi = std::min(run.min_phi, quadrotor_min_phi(s, x));
    run.largest_tilt_deg = std::max(run.largest_tilt_deg, tilt_deg(x));
  }
  return run;
}

void write_quadrotor_window_csv(const QuadrotorWindowProblem& problem,
                                const QuadrotorWindowRun& run, const std::filesystem::path& path) {
  std::ostringstream out;
  out << std::setprecision(17) << "k,t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,u1,u2,u3,u4\n";
  const auto& states = run.result.states;
  for (std::size_t k = 0; k < states.size(); ++k) {
    out << k << "," << static_cast<double>(k) * problem.scenario().dt;
    for (int i = 0; i < 13; ++i) out << "," << states[k](i);
    for (int i = 0; i < 4; ++i) {
      out << ",";
      if (k < run.result.controls.size()) out << run.result.controls[k](i);
    }
    out << "\n";
  }
  write_file(path, out.str());
}

void write_quadrotor_window_json(const QuadrotorWindowProblem& problem,
                                 const QuadrotorWindowRun& run, const std::filesystem::path& path) {
  const QuadrotorWindowScenario& s = problem.scenario();
  json body = app::to_json(Shape(s.body), Pose());
  body.erase("r");
  body.erase("q");
  json wall = json::array(), poles = json::array();
  for (const PosedPolygon& panel : s.wall)
    wall.push_back(app::to_json(Shape(panel.shape), panel.pose));
  for (const PosedCapsule& pole : s.poles)
    poles.push_back(app::to_json(Shape(pole.shape), pole.pose));
  json out = {{"dt", s.dt},
              {"N", s.knots},
              {"quadrotor",
               {{"mass", s.model.mass},
                {"inertia", json_list(s.model.inertia)},
                {"arm", s.model.arm},
                {"torque_per_thrust", s.model.torque_per_thrust},
                {"gravity", s.model.gravity},
                {"thrust_max", s.thrust_max},
                {"body", body}}},
              {"window",
               {{"centre", json_list(s.window_centre)},
                {"width", s.window_width},
                {"height", s.window_height},
                {"tilt", s.window_tilt}}},
              {"wall", wall},
              {"poles", poles},
              {"x0", json_list(s.x0)},
              {"goal", json_list(s.goal)},
              {"initial_guess", "hover thrust at every step"},
              {"level_straight_line_min_phi", run.level_straight_line_min_phi},
              {"min_phi", run.min_phi},
              {"largest_tilt_deg", run.largest_tilt_deg},
              {"solver", altro_summary(run.result, run.solve_ms)}};
  add_ipopt_comparison(out, run.ipopt, run.result, run.solve_ms, run.runs);
  write_file(path, out.dump(2) + "\n");
}

// Three orthographic views on one canvas: top (x, y) above, side (x, z) below, and on the right
// the view through the window along +x (-y, z), which shows the roll. Padded shapes are drawn as
// their projected cores stroked at 2R, their exact silhouettes.
void write_quadrotor_window_svg(const QuadrotorWindowProblem& problem,
                                const QuadrotorWindowRun& run, const std::filesystem::path& path) {
  const QuadrotorWindowScenario& s = problem.scenario();
  struct View {
    Eigen::Matrix<double, 2, 3> axes;
    Eigen::Vector2d offset;
  };
  View top{}, side{}, front{};
  top.axes << 1, 0, 0, 0, 1, 0;
  top.offset << 0.0, 0.0;
  side.axes << 1, 0, 0, 0, 0, 1;
  side.offset << 0.0, -6.5;
  front.axes << 0, -1, 0, 0, 0, 1;
  front.offset << 10.0, -4.5;
  const View views[3] = {top, side, front};
  Svg svg({-0.8, -7.3}, {12.4, 2.6}, 60.0);
  const auto project = [](const View& v, const Eigen::Vector3d& p) -> Eigen::Vector2d {
    return v.axes * p + v.offset;
  };
  const auto draw_polygon = [&](const View& v, const PaddedPolygon& shape, const Pose& pose,
                                const std::string& color, double opacity) {
    const Eigen::Matrix3d R = rotation_matrix(pose.q());
    std::vector<Eigen::Vector2d> outline;
    for (Eigen::Index i = 0; i < shape.vertices().rows(); ++i) {
      const Eigen::Vector3d vertex(shape.vertices()(i, 0), shape.vertices()(i, 1), 0.0);
      outline.push_back(project(v, pose.r() + R * vertex));
    }
    svg.polygon(outline, shape.radius(), color, opacity);
  };
  const auto near_window = [&](const Eigen::VectorXd& x) {
    return std::abs(x(0) - s.window_centre(0)) < 0.45;
  };
  const auto& states = run.result.states;
  for (const View& v : views) {
    for (const PosedPolygon& panel : s.wall)
      draw_polygon(v, panel.shape, panel.pose, "#999999", 0.45);
    const bool is_front = &v == &views[2];
    // The poles would hide the window in the view along +x.
    for (const PosedCapsule& pole : is_front ? std::vector<PosedCapsule>() : s.poles) {
      const Eigen::Vector3d axis =
          rotation_matrix(pole.pose.q()).col(0) * 0.5 * pole.shape.length();
      svg.segment(project(v, pole.pose.r() - axis), project(v, pole.pose.r() + axis),
                  pole.shape.radius(), "#f2b705", 0.8);
    }
    for (std::size_t k = 0; k < states.size(); ++k) {
      if (is_front ? near_window(states[k]) : k % 5 == 0 || near_window(states[k])) {
        draw_polygon(v, s.body, quadrotor_pose(states[k]), "#1f77b4", 0.3);
      }
    }
    for (std::size_t k = 0; k + 1 < states.size(); ++k) {
      svg.segment(project(v, states[k].head<3>()), project(v, states[k + 1].head<3>()), 0.0,
                  "#1f77b4");
    }
    svg.circle(project(v, s.x0.head<3>()), 5, "#2ca02c");
    svg.circle(project(v, s.goal.head<3>()), 5, "#d62728");
  }
  svg.text({-0.6, 2.3}, "top view (x, y): quadrotor through a tilted window, ALTRO", 16);
  svg.text({-0.6, -2.4}, "side view (x, z)", 16);
  svg.text({7.6, 2.3}, "view along +x, through the window", 16);
  std::ostringstream label;
  label << std::setprecision(3) << "largest tilt " << run.largest_tilt_deg << " deg";
  svg.text({7.6, 1.9}, label.str(), 14);
  write_file(path, svg.str());
}

}  // namespace diffpills::examples
