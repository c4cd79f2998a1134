// `make demo`: solves the paper's car-bus problem, the quadrotor-window problem and the arm-shelf
// problem with the ALTRO-style optimizer and writes, in the output folder (default out/),
// car_bus.{csv,json,svg}, quadrotor_window.{csv,json,svg}, arm_shelf.{csv,json,svg} and scene.svg
// (the paper's Fig. 1: a capsule beside a padded polygon, closest points and normal). Each problem
// is cross-checked with Ipopt from the same guess, with its limited-memory and its exact Hessian,
// every solver timed the same way (solver_runs.hpp). Prints a summary table.
//
// Usage: diffpills_demo [output folder] [--quick] [--ipopt-cpu-seconds S]. --quick (the tests')
// runs each solver once and Ipopt on the car-bus problem only: the quadrotor's and the arm's Ipopt
// runs take minutes under the sanitizers. --ipopt-cpu-seconds stops each Ipopt run after S > 0
// seconds of CPU time (default 120; DemoSettings).
#include <Eigen/Geometry>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <utility>

#include "arm_shelf_outputs.hpp"
#include "car_bus/car_bus.hpp"
#include "car_bus/car_bus_ipopt.hpp"
#include "demo_json.hpp"
#include "demo_scene.hpp"
#include "json_io.hpp"
#include "quadrotor_window_outputs.hpp"
#include "solver_runs.hpp"
#include "svg.hpp"

namespace {

using namespace diffpills;
using json = nlohmann::ordered_json;
using examples::altro_summary;
using examples::ipopt_summary;
using examples::json_list;

struct CarBusRun {
  trajopt::AltroResult result;
  examples::IpoptRuns ipopt;
  double guess_min_phi = 0.0;
  double solve_ms = 0.0;
  int runs = 1;  // per solver
};

// ALTRO and Ipopt (both Hessians), each the fastest of settings.runs(false) solves.
CarBusRun solve_car_bus(const examples::CarBusProblem& problem,
                        const examples::DemoSettings& settings) {
  const examples::CarBusScenario& s = problem.scenario();
  const std::vector<Eigen::VectorXd> guess = problem.straight_line_controls();
  CarBusRun run;
  Eigen::VectorXd x = s.x0;
  run.guess_min_phi = examples::car_bus_phi(s, x);
  for (const Eigen::VectorXd& u : guess) {
    examples::CarBusProblem::State next;
    examples::CarBusProblem::StateMatrix A;
    examples::CarBusProblem::ControlMatrix B;
    problem.dynamics(x, u, next, A, B);
    x = next;
    run.guess_min_phi = std::min(run.guess_min_phi, examples::car_bus_phi(s, x));
  }
  run.runs = settings.runs(false);
  examples::AltroRun altro =
      examples::fastest_altro(run.runs, [&] { return trajopt::solve(problem, s.x0, guess); });
  run.result = std::move(altro.result);
  run.solve_ms = altro.solve_ms;
  run.ipopt = examples::fastest_ipopt(run.runs, [&](examples::IpoptHessian hessian) {
    return examples::solve_with_ipopt(problem, guess, hessian, settings.ipopt_cpu_seconds);
  });
  return run;
}

void write_car_bus_csv(const examples::CarBusProblem& problem, const CarBusRun& run,
                       const std::filesystem::path& path) {
  std::ostringstream out;
  out << std::setprecision(17) << "k,t,px,py,theta,v,gamma,u1,u2\n";
  const auto& states = run.result.states;
  for (std::size_t k = 0; k < states.size(); ++k) {
    out << k << "," << static_cast<double>(k) * problem.scenario().dt;
    for (int i = 0; i < 5; ++i) out << "," << states[k](i);
    if (k < run.result.controls.size()) {
      out << "," << run.result.controls[k](0) << "," << run.result.controls[k](1) << "\n";
    } else {
      out << ",,\n";
    }
  }
  examples::write_file(path, out.str());
}

void write_car_bus_json(const examples::CarBusProblem& problem, const CarBusRun& run,
                        const std::filesystem::path& path) {
  const examples::CarBusScenario& s = problem.scenario();
  json bus = app::to_json(Shape(s.bus), s.bus_pose);
  bus.erase("type");
  json out = {{"dt", s.dt},
              {"N", s.knots},
              {"wheelbase", s.car_model.wheelbase},
              {"car", {{"length", s.car.length()}, {"radius", s.car.radius()}}},
              {"bus", bus},
              {"x0", json_list(s.x0)},
              {"goal", json_list(s.goal)},
              {"control_limit", json_list(s.control_limit)},
              {"initial_guess_min_phi", run.guess_min_phi},
              {"solver", altro_summary(run.result, run.solve_ms)}};
  examples::add_ipopt_comparison(out, run.ipopt, run.result, run.solve_ms, run.runs);
  examples::write_file(path, out.dump(2) + "\n");
}

// Top view: the bus, the car's capsule every fifth knot, its path, start and goal.
void write_car_bus_svg(const examples::CarBusProblem& problem, const CarBusRun& run,
                       const std::filesystem::path& path) {
  const examples::CarBusScenario& s = problem.scenario();
  examples::Svg svg({-3.0, -7.0}, {24.0, 3.5}, 32.0);
  const auto capsule_ends = [](const Capsule& c, const Pose& pose) {
    const Eigen::Vector3d axis = rotation_matrix(pose.q()).col(0) * 0.5 * c.length();
    return std::pair<Eigen::Vector2d, Eigen::Vector2d>((pose.r() - axis).head<2>(),
                                                       (pose.r() + axis).head<2>());
  };
  const auto [bus_a, bus_b] = capsule_ends(s.bus, s.bus_pose);
  svg.segment(bus_a, bus_b, s.bus.radius(), "#f2b705");
  svg.text(s.bus_pose.r().head<2>() + Eigen::Vector2d(-0.6, -0.2), "bus");
  const auto& states = run.result.states;
  for (std::size_t k = 0; k < states.size(); k += 5) {
    const auto [a, b] = capsule_ends(s.car, examples::car_pose(states[k]));
    svg.segment(a, b, s.car.radius(), "#1f77b4", 0.25);
  }
  for (std::size_t k = 0; k + 1 < states.size(); ++k) {
    svg.segment(states[k].head<2>(), states[k + 1].head<2>(), 0.0, "#1f77b4");
  }
  svg.circle(s.x0.head<2>(), 5, "#2ca02c");
  svg.text(s.x0.head<2>() + Eigen::Vector2d(-0.5, 1.4), "start");
  svg.circle(s.goal.head<2>(), 5, "#d62728");
  svg.text(s.goal.head<2>() + Eigen::Vector2d(-0.5, -1.6), "goal");
  svg.text({-2.5, 3.0}, "car-bus: ALTRO, phi(car, bus) >= 0 at every knot", 16);
  examples::write_file(path, svg.str());
}

// The paper's Fig. 1 in an orthographic view: the silhouettes of both padded shapes are exactly
// their projected cores stroked at width 2R.
void write_scene_svg(const std::filesystem::path& path) {
  const app::Fig1Scene scene = app::fig1_scene();
  const Proximity p =
      proximity(scene.capsule, scene.capsule_pose, scene.polygon, scene.polygon_pose);
  const Eigen::Vector3d view = Eigen::Vector3d(1.0, -1.6, 0.9).normalized();
  const Eigen::Vector3d right = view.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = right.cross(view);
  const auto project = [&](const Eigen::Vector3d& x) {
    return Eigen::Vector2d(x.dot(right), x.dot(up));
  };
  examples::Svg svg({-1.1, -1.0}, {1.4, 1.75}, 200.0);
  std::vector<Eigen::Vector2d> outline;
  const Eigen::Matrix3d R = rotation_matrix(scene.polygon_pose.q());
  for (Eigen::Index i = 0; i < scene.polygon.vertices().rows(); ++i) {
    const Eigen::Vector3d v(scene.polygon.vertices()(i, 0), scene.polygon.vertices()(i, 1), 0.0);
    outline.push_back(project(scene.polygon_pose.r() + R * v));
  }
  svg.polygon(outline, scene.polygon.radius(), "#aec7e8");
  svg.outline(outline, "#1f77b4");  // the core inside its padding
  const Eigen::Vector3d axis =
      rotation_matrix(scene.capsule_pose.q()).col(0) * 0.5 * scene.capsule.length();
  const Eigen::Vector2d a = project(scene.capsule_pose.r() - axis);
  const Eigen::Vector2d b = project(scene.capsule_pose.r() + axis);
  svg.segment(a, b, scene.capsule.radius(), "#ffbb78");
  svg.segment(a, b, 0.0, "#ff7f0e");
  svg.segment(project(p.core_points[0]), project(p.core_points[1]), 0.0, "#555555");
  svg.circle(project(p.points[0]), 5, "#d62728");
  svg.circle(project(p.points[1]), 5, "#d62728");
  svg.arrow(project(p.points[0]), project(p.points[0] + 0.35 * p.normal), "#2ca02c");
  std::ostringstream label;
  label << std::setprecision(4) << "phi = " << p.phi
        << " (apart); red: closest points, green: normal";
  svg.text({-1.05, 1.65}, label.str(), 15);
  examples::write_file(path, svg.str());
}

// The quadrotor behind a thin wall (panels and body padded by 0.025 m each): the same problem
// with phi and with the signed distance as the clearance, ALTRO alone.
examples::AltroRun solve_thin_wall(examples::Clearance clearance,
                                   const examples::DemoSettings& settings) {
  examples::QuadrotorWindowScenario scenario;
  scenario.wall_radius = 0.025;
  scenario.body_radius = 0.025;
  scenario.clearance = clearance;
  scenario.build();
  const examples::QuadrotorWindowProblem problem{scenario};
  return examples::fastest_altro(settings.runs(false), [&] {
    return trajopt::solve(problem, scenario.x0, problem.hover_controls());
  });
}

// A run's milliseconds with one decimal, fixed: a minute is 64195.3, not 6.42e+04.
std::string fixed_ms(double ms) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << ms;
  return text.str();
}

// The two Ipopt runs in the table's order, each with its name below the table and the width of
// its column ("Ipopt L-M ms", "Ipopt exact ms").
struct LabeledIpoptRun {
  const examples::IpoptRun* run;
  const char* label;
  int column_width;
};
std::array<LabeledIpoptRun, 2> labeled_runs(const examples::IpoptRuns& ipopt) {
  return {{{&ipopt.limited_memory, "L-M", 14}, {&ipopt.exact, "exact", 16}}};
}

// One row of the summary table: ALTRO's run, then each Ipopt run's time and cost ("failed" for
// one that did not solve), and ALTRO's speed-up over the faster solved one, marked * where that
// Ipopt run found another local minimum ("-" without Ipopt).
void print_row(const std::string& name, const trajopt::AltroResult& result, double solve_ms,
               const std::optional<examples::IpoptRuns>& ipopt) {
  std::cout << std::left << std::setw(18) << name << std::right << std::setw(8)
            << (result.status == trajopt::AltroStatus::kSolved ? "solved" : "FAILED")
            << std::setw(12) << result.iterations << std::setw(15) << std::setprecision(3)
            << result.max_violation << std::setw(12) << std::setprecision(6) << result.cost
            << std::setw(10) << std::setprecision(3) << solve_ms;
  if (!ipopt) {
    std::cout << std::setw(14) << "-" << std::setw(12) << "-" << std::setw(16) << "-"
              << std::setw(12) << "-" << std::setw(10) << "-\n";
    return;
  }
  for (const auto& [run, label, width] : labeled_runs(*ipopt)) {
    if (run->solved) {
      std::cout << std::setw(width) << fixed_ms(run->solve_ms) << std::setw(12)
                << std::setprecision(6) << run->cost;
    } else {
      std::cout << std::setw(width) << "failed" << std::setw(12) << "-";
    }
  }
  const examples::IpoptRun* faster = ipopt->faster_solved();
  if (faster == nullptr) {
    std::cout << std::setw(10) << "-\n";
    return;
  }
  std::ostringstream ratio;
  ratio << std::setprecision(3) << faster->solve_ms / solve_ms << "x"
        << (examples::same_minimum(faster->cost, result.cost) ? "" : "*");
  std::cout << std::setw(10) << ratio.str() << "\n";
}

// Below the table, what stopped each Ipopt run that did not solve (the table says "failed"):
// "quadrotor_window, Ipopt exact: locally infeasible (2) after 375 iterations, 3266.1 ms, cost
// 255.547 at max violation 0.0625" (or "no point handed back").
void print_unsolved(const std::string& name, const std::optional<examples::IpoptRuns>& ipopt) {
  if (!ipopt) return;
  for (const auto& [run, label, width] : labeled_runs(*ipopt)) {
    if (run->solved) continue;
    std::cout << name << ", Ipopt " << label << ": " << run->status << " after " << run->iterations
              << " iterations, " << fixed_ms(run->solve_ms) << " ms, ";
    if (run->has_point()) {
      std::cout << "cost " << std::setprecision(6) << run->cost << " at max violation "
                << std::setprecision(3) << run->max_violation << "\n";
    } else {
      std::cout << "no point handed back\n";
    }
  }
}

// text as a number of seconds, all of it read ("120", "1e-9"), in double's normal range
// [2.2e-308, 1.8e308] and > 0, or nothing. Not text with leading white space (strtod skips it;
// trailing space is not read either), nor a number strtod cannot hold: it turns 1e-400 into 0,
// 1e400 into infinity, and 1e-310 into a subnormal that has lost digits, all refused by their
// values. (Not by errno: glibc also sets ERANGE for text just below 2^-1022 that rounds up to
// it, a normal number.)
std::optional<double> seconds_limit(const char* text) {
  if (std::isspace(static_cast<unsigned char>(text[0])) != 0) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  const bool normal = std::isfinite(value) && value >= std::numeric_limits<double>::min();
  if (end == text || *end != '\0' || !normal) return std::nullopt;
  return value;
}

int run(int argc, char** argv) {
  std::filesystem::path out_dir = "out";
  examples::DemoSettings settings;
  bool folder_given = false;
  constexpr const char* kUsage =
      "usage: diffpills_demo [output folder, default out] [--quick] [--ipopt-cpu-seconds S]\n";
  constexpr const char* kHelp =
      "  --quick                 each solver once, Ipopt on the car-bus problem only\n"
      "  --ipopt-cpu-seconds S   stop each Ipopt run after S seconds of CPU time (a finite\n"
      "                          number > 0 in double's normal range; default 120)\n"
      "exit status: 0 done, 1 a file not written or the car-bus, quadrotor or arm problem\n"
      "not solved by ALTRO (a solver's error too; the thin wall's phi run may fail),\n"
      "2 a bad argument\n";
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--quick") {
      settings.quick = true;
    } else if (argument == "--ipopt-cpu-seconds") {
      const std::optional<double> seconds = i + 1 < argc ? seconds_limit(argv[++i]) : std::nullopt;
      if (!seconds) {
        std::cerr << "diffpills_demo: --ipopt-cpu-seconds needs a finite number of seconds > 0 in "
                     "double's normal range\n"
                  << kUsage;
        return 2;
      }
      settings.ipopt_cpu_seconds = *seconds;
    } else if (argument == "--help" || argument == "-h") {
      std::cout << kUsage << kHelp;
      return 0;
    } else if (argument.empty() || argument[0] == '-' || folder_given) {
      std::cerr << "diffpills_demo: unexpected argument '" << argument << "'\n" << kUsage;
      return 2;
    } else {
      out_dir = argument;
      folder_given = true;
    }
  }
  std::filesystem::create_directories(out_dir);

  const examples::CarBusProblem car_bus{examples::CarBusScenario{}};
  const CarBusRun run = solve_car_bus(car_bus, settings);
  write_car_bus_csv(car_bus, run, out_dir / "car_bus.csv");
  write_car_bus_json(car_bus, run, out_dir / "car_bus.json");
  write_car_bus_svg(car_bus, run, out_dir / "car_bus.svg");
  write_scene_svg(out_dir / "scene.svg");

  const examples::QuadrotorWindowProblem quadrotor{examples::QuadrotorWindowScenario{}};
  const examples::QuadrotorWindowRun flight = examples::solve_quadrotor_window(quadrotor, settings);
  examples::write_quadrotor_window_csv(quadrotor, flight, out_dir / "quadrotor_window.csv");
  examples::write_quadrotor_window_json(quadrotor, flight, out_dir / "quadrotor_window.json");
  examples::write_quadrotor_window_svg(quadrotor, flight, out_dir / "quadrotor_window.svg");

  const examples::ArmShelfProblem arm{examples::ArmShelfScenario{}};
  const examples::ArmShelfRun reach = examples::solve_arm_shelf(arm, settings);
  examples::write_arm_shelf_csv(arm, reach, out_dir / "arm_shelf.csv");
  examples::write_arm_shelf_json(arm, reach, out_dir / "arm_shelf.json");
  examples::write_arm_shelf_svg(arm, reach, out_dir / "arm_shelf.svg");

  std::cout << std::left << std::setw(18) << "problem" << std::right << std::setw(8) << "status"
            << std::setw(12) << "iterations" << std::setw(15) << "max violation" << std::setw(12)
            << "cost" << std::setw(10) << "ms" << std::setw(14) << "Ipopt L-M ms" << std::setw(12)
            << "cost" << std::setw(16) << "Ipopt exact ms" << std::setw(12) << "cost"
            << std::setw(10) << "speed-up"
            << "\n";
  print_row("car_bus", run.result, run.solve_ms, run.ipopt);
  print_row("quadrotor_window", flight.result, flight.solve_ms, flight.ipopt);
  print_row("arm_shelf", reach.result, reach.solve_ms, reach.ipopt);
  const examples::AltroRun thin_phi = solve_thin_wall(examples::Clearance::kProximity, settings);
  const examples::AltroRun thin_distance =
      solve_thin_wall(examples::Clearance::kSignedDistance, settings);
  print_row("thin_wall (phi)", thin_phi.result, thin_phi.solve_ms, std::nullopt);
  print_row("thin_wall (sd)", thin_distance.result, thin_distance.solve_ms, std::nullopt);
  print_unsolved("car_bus", run.ipopt);
  print_unsolved("quadrotor_window", flight.ipopt);
  print_unsolved("arm_shelf", reach.ipopt);
  std::cout << "\nALTRO and Ipopt from the same guess; the fastest run of " << run.runs
            << " per solver (the arm: " << reach.runs
            << "); Ipopt with its limited-memory (L-M) and its exact Hessian, each run limited to "
            << settings.ipopt_cpu_seconds
            << " s of CPU time; speed-up: the faster solved Ipopt's time over ALTRO's (*: that "
               "Ipopt run stopped at another local minimum, its cost more than 1% from ALTRO's)\n";
  std::cout << std::setprecision(3)
            << "car_bus: straight-line initial guess collides, smallest phi " << run.guess_min_phi
            << "\nquadrotor_window: the level body slid straight through has "
            << "smallest phi " << flight.level_straight_line_min_phi
            << "; the solution tilts up to " << flight.largest_tilt_deg << " deg, smallest phi "
            << flight.min_phi
            << "\narm_shelf: a Panda arm moves its hand from the shelf's left compartment to the "
               "right one; the joint-space straight line collides (smallest signed distance "
            << reach.straight_line_min_distance << " m), the solution keeps " << reach.min_distance
            << " m at the knots and " << reach.path_min_distance << " m between them"
            << "\nthin_wall: the quadrotor problem with panels and body padded by 0.025 m; with "
               "phi the iterates that cross a core stay where phi is flat, with the signed "
               "distance (sd) they are led out"
            << "\nfigures and data in " << out_dir.string()
            << "/: car_bus.{svg,csv,json} quadrotor_window.{svg,csv,json} "
               "arm_shelf.{svg,csv,json} scene.svg\n";
  const bool solved = run.result.status == trajopt::AltroStatus::kSolved &&
                      flight.result.status == trajopt::AltroStatus::kSolved &&
                      reach.result.status == trajopt::AltroStatus::kSolved;
  return solved ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& error) {  // an unwritable folder, a solver that threw
    std::cerr << "diffpills_demo: " << error.what() << "\n";
    return 1;
  }
}
