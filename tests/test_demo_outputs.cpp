// `make demo`'s files parse and carry what the motion-planning issues promise: runs the demo
// program (its path is the first argument) into a fresh folder and reads everything back, then
// checks that each CSV row follows from the previous one by RK4 of the documented model, with the
// parameters the JSON files state; and the arm's motion from the JSON's own description alone
// (its DH parameters, links, exclusions and shelf): limits, start, goal and the signed distances;
// and the Ipopt comparison's blocks. The demo runs with --quick (each solver once, Ipopt on the
// car-bus problem only: the other Ipopt runs take minutes under the sanitizers), and once more
// with its Ipopt runs stopped at once by --ipopt-cpu-seconds.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "demo_json.hpp"
#include "diffpills/diffpills.hpp"
#include "json_io.hpp"
#include "solver_runs.hpp"

namespace {

std::string demo_program;

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// Runs the demo with --quick and the extra arguments into a fresh folder named name, its
// standard output into stdout.txt there.
std::filesystem::path run_demo(const std::string& name, const std::string& arguments) {
  std::filesystem::path folder = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string command = demo_program + " " + folder.string() + " --quick " + arguments +
                              " > " + (folder / "stdout.txt").string();
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return folder;
}

// Runs the demo once into a fresh folder; every test reads it.
const std::filesystem::path& demo_folder() {
  static const std::filesystem::path out = run_demo("diffpills_demo_test", "");
  return out;
}

// The CSV's numeric rows (k, t, state..., controls...), the last without controls.
std::vector<Eigen::VectorXd> csv_rows(const std::filesystem::path& path) {
  std::istringstream csv(read(path));
  std::string line;
  std::getline(csv, line);  // header
  std::vector<Eigen::VectorXd> rows;
  while (std::getline(csv, line)) {
    std::vector<double> values;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) {
      if (!cell.empty()) values.push_back(std::stod(cell));
    }
    rows.emplace_back(
        Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size())));
  }
  return rows;
}

template <class Rate>
Eigen::VectorXd rk4(const Rate& rate, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                    double h) {
  const Eigen::VectorXd k1 = rate(x, u), k2 = rate(x + 0.5 * h * k1, u),
                        k3 = rate(x + 0.5 * h * k2, u), k4 = rate(x + h * k3, u);
  return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

TEST(DemoOutputs, CsvRowsFollowRk4OfTheDocumentedModels) {
  const std::filesystem::path& out = demo_folder();
  {  // the kinematic bicycle of README / trajopt/car.hpp
    const nlohmann::json scenario = nlohmann::json::parse(read(out / "car_bus.json"));
    const double dt = scenario["dt"], l = scenario["wheelbase"];
    const auto rate = [l](const Eigen::VectorXd& x, const Eigen::VectorXd& u) {
      Eigen::VectorXd xdot(5);
      xdot << x(3) * std::cos(x(2)), x(3) * std::sin(x(2)), x(3) * std::tan(x(4)) / l, u(0), u(1);
      return xdot;
    };
    const std::vector<Eigen::VectorXd> rows = csv_rows(out / "car_bus.csv");
    for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
      const Eigen::VectorXd next = rk4(rate, rows[k].segment(2, 5), rows[k].segment(7, 2), dt);
      EXPECT_LE((next - rows[k + 1].segment(2, 5)).norm(), 1e-9) << "car_bus row " << k;
    }
  }
  {  // the quadrotor of trajopt/quadrotor.hpp: RK4, then q normalized
    const nlohmann::json scenario = nlohmann::json::parse(read(out / "quadrotor_window.json"));
    const nlohmann::json& model = scenario["quadrotor"];
    const double dt = scenario["dt"], m = model["mass"], arm = model["arm"],
                 km = model["torque_per_thrust"], g = model["gravity"];
    const Eigen::Vector3d J(model["inertia"][0], model["inertia"][1], model["inertia"][2]);
    const auto rate = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& u) {
      const Eigen::Quaterniond q(x(3), x(4), x(5), x(6));
      const Eigen::Vector3d w = x.segment<3>(10);
      const Eigen::Quaterniond spin = q * Eigen::Quaterniond(0.0, w(0), w(1), w(2));
      const Eigen::Vector3d tau(arm * (u(1) - u(3)), arm * (u(2) - u(0)),
                                km * (u(0) - u(1) + u(2) - u(3)));
      Eigen::VectorXd xdot(13);
      xdot.head<3>() = x.segment<3>(7);
      xdot.segment<4>(3) << 0.5 * spin.w(), 0.5 * spin.x(), 0.5 * spin.y(), 0.5 * spin.z();
      xdot.segment<3>(7) = q.toRotationMatrix().col(2) * u.sum() / m - Eigen::Vector3d(0, 0, g);
      xdot.segment<3>(10) = (tau - w.cross(J.asDiagonal() * w)).cwiseQuotient(J);
      return xdot;
    };
    const std::vector<Eigen::VectorXd> rows = csv_rows(out / "quadrotor_window.csv");
    for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
      Eigen::VectorXd next = rk4(rate, rows[k].segment(2, 13), rows[k].segment(15, 4), dt);
      next.segment<4>(3).normalize();
      EXPECT_LE((next - rows[k + 1].segment(2, 13)).norm(), 1e-9) << "quadrotor row " << k;
    }
  }
}

TEST(DemoOutputs, FilesParseAndCarryTheScenario) {
  const std::filesystem::path& out = demo_folder();

  const nlohmann::json scenario = nlohmann::json::parse(read(out / "car_bus.json"));
  for (const char* key :
       {"dt", "N", "wheelbase", "car", "bus", "x0", "goal", "initial_guess_min_phi", "solver"}) {
    EXPECT_TRUE(scenario.contains(key)) << key;
  }
  for (const char* key : {"iterations", "max_violation", "cost", "solve_ms"}) {
    EXPECT_TRUE(scenario["solver"].contains(key)) << key;
  }
  for (const char* key : {"length", "radius", "r", "q"}) {
    EXPECT_TRUE(scenario["bus"].contains(key)) << key;
  }
  EXPECT_LT(scenario["initial_guess_min_phi"].get<double>(), 0.0);
  EXPECT_LE(scenario["solver"]["max_violation"].get<double>(), 1e-6);

  std::istringstream csv(read(out / "car_bus.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "k,t,px,py,theta,v,gamma,u1,u2");
  int rows = 0;
  std::string last;
  while (std::getline(csv, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, scenario["N"].get<int>());
  EXPECT_EQ(last.substr(last.size() - 2), ",,");  // the last knot has no controls

  const nlohmann::json flight = nlohmann::json::parse(read(out / "quadrotor_window.json"));
  for (const char* key : {"dt", "N", "quadrotor", "window", "wall", "poles", "x0", "goal",
                          "level_straight_line_min_phi", "min_phi", "largest_tilt_deg", "solver"}) {
    EXPECT_TRUE(flight.contains(key)) << key;
  }
  EXPECT_EQ(flight["wall"].size(), 4u);
  for (const auto& panel : flight["wall"]) {
    EXPECT_EQ(panel["type"], "polygon");
    for (const char* key : {"C", "d", "radius", "r", "q"}) EXPECT_TRUE(panel.contains(key)) << key;
  }
  for (const auto& pole : flight["poles"]) EXPECT_EQ(pole["type"], "capsule");
  EXPECT_LT(flight["level_straight_line_min_phi"].get<double>(), 0.0);
  EXPECT_GE(flight["min_phi"].get<double>(), -1e-6);
  EXPECT_LE(flight["solver"]["max_violation"].get<double>(), 1e-6);

  std::istringstream flight_csv(read(out / "quadrotor_window.csv"));
  std::getline(flight_csv, line);
  EXPECT_EQ(line, "k,t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,u1,u2,u3,u4");
  rows = 0;
  while (std::getline(flight_csv, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, flight["N"].get<int>());
  EXPECT_EQ(last.substr(last.size() - 4), ",,,,");

  for (const char* figure : {"car_bus.svg", "quadrotor_window.svg", "scene.svg"}) {
    const std::string svg = read(out / figure);
    EXPECT_EQ(svg.rfind("<svg", 0), 0u) << figure;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << figure;
  }
}

// The arm: every row of arm_shelf.csv posed by the modified-DH product of the JSON's parameters,
// T_i = RotX(alpha_i) TransX(a_i) RotZ(q_i) TransZ(d_i), its links' shapes placed by it, and every
// pair of non-excluded links and of a moving link and a board measured with signed_distance().
TEST(DemoOutputs, ArmShelfFromItsOwnDescription) {
  const std::filesystem::path& out = demo_folder();
  const nlohmann::json arm = nlohmann::json::parse(read(out / "arm_shelf.json"));
  EXPECT_EQ(read(out / "arm_shelf.csv").substr(0, 23), "t,q1,q2,q3,q4,q5,q6,q7\n");
  const std::vector<Eigen::VectorXd> rows = csv_rows(out / "arm_shelf.csv");
  ASSERT_EQ(rows.size(), arm["knots"].get<std::size_t>());
  EXPECT_EQ(arm["status"], "solved");
  EXPECT_GT(arm["iterations"].get<int>(), 0);
  EXPECT_GT(arm["ms"].get<double>(), 0.0);
  for (const char* key : {"a", "d", "alpha"}) ASSERT_EQ(arm["dh"][key].size(), 7u) << key;
  ASSERT_EQ(arm["joint_limits"].size(), 7u);
  ASSERT_EQ(arm["links"].size(), 9u);
  ASSERT_EQ(arm["start"].size(), 7u);
  ASSERT_EQ(arm["goal"].size(), 7u);

  struct Placed {
    int frame;
    diffpills::Shape shape;
    diffpills::Pose local;
  };
  std::vector<Placed> links;
  for (const auto& link : arm["links"]) {
    for (const auto& shape : link["shapes"]) {
      const diffpills::app::PosedShape posed = diffpills::app::parse_posed_shape(shape, "shape");
      links.push_back({link["frame"].get<int>(), posed.shape, posed.pose});
    }
  }
  std::vector<diffpills::app::PosedShape> boards;
  for (const auto& body : arm["shelf"]["bodies"]) {
    for (const auto& shape : body["shapes"]) {
      boards.push_back(diffpills::app::parse_posed_shape(shape, "board"));
    }
  }
  const auto excluded = [&](int f, int g) {
    for (const auto& pair : arm["excluded_link_pairs"]) {
      if ((pair[0] == f && pair[1] == g) || (pair[0] == g && pair[1] == f)) return true;
    }
    return f == g;
  };
  const double dt = arm["dt"].get<double>();
  double smallest = INFINITY;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Eigen::VectorXd& row = rows[k];
    EXPECT_NEAR(row(0), dt * static_cast<double>(k), 1e-12);
    const Eigen::VectorXd q = row.tail(7);
    for (int i = 0; i < 7; ++i) {
      EXPECT_GE(q(i), arm["joint_limits"][i][0].get<double>() - 1e-6);
      EXPECT_LE(q(i), arm["joint_limits"][i][1].get<double>() + 1e-6);
      if (k == 0) EXPECT_NEAR(q(i), arm["start"][i].get<double>(), 1e-9);
      if (k + 1 == rows.size()) EXPECT_NEAR(q(i), arm["goal"][i].get<double>(), 1e-6);
    }
    std::vector<Eigen::Isometry3d> frames{Eigen::Isometry3d::Identity()};
    for (int i = 0; i < 7; ++i) {
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      step.rotate(Eigen::AngleAxisd(arm["dh"]["alpha"][i].get<double>(), Eigen::Vector3d::UnitX()));
      step.translate(Eigen::Vector3d(arm["dh"]["a"][i].get<double>(), 0, 0));
      step.rotate(Eigen::AngleAxisd(q(i), Eigen::Vector3d::UnitZ()));
      step.translate(Eigen::Vector3d(0, 0, arm["dh"]["d"][i].get<double>()));
      frames.push_back(frames.back() * step);
    }
    frames.push_back(frames.back() * Eigen::Translation3d(0, 0, arm["flange_d"].get<double>()));
    std::vector<diffpills::Pose> world;
    for (const Placed& link : links) {
      const Eigen::Isometry3d& T = frames[static_cast<std::size_t>(link.frame)];
      const Eigen::Quaterniond q_world = Eigen::Quaterniond(T.rotation()) *
                                         Eigen::Quaterniond(link.local.q()(0), link.local.q()(1),
                                                            link.local.q()(2), link.local.q()(3));
      world.emplace_back(T * link.local.r(),
                         Eigen::Vector4d(q_world.w(), q_world.x(), q_world.y(), q_world.z()));
    }
    for (std::size_t i = 0; i < links.size(); ++i) {
      for (std::size_t j = i + 1; j < links.size(); ++j) {
        if (excluded(links[i].frame, links[j].frame)) continue;
        smallest = std::min(
            smallest, diffpills::signed_distance(links[i].shape, world[i], links[j].shape, world[j])
                          .distance);
      }
      if (links[i].frame == 0) continue;  // the base never moves
      for (const auto& board : boards) {
        smallest = std::min(
            smallest,
            diffpills::signed_distance(links[i].shape, world[i], board.shape, board.pose).distance);
      }
    }
  }
  EXPECT_GE(smallest, arm["clearance"].get<double>() - 1e-6);
  EXPECT_NEAR(smallest, arm["min_distance"].get<double>(), 1e-9);
  EXPECT_LT(arm["straight_line_min_distance"].get<double>(), 0.0);
  EXPECT_EQ(read(out / "arm_shelf.svg").rfind("<svg", 0), 0u);
}

// Both Ipopt runs of the car-bus problem are there, name their Hessian, solve, agree with ALTRO's
// cost, and the speed-up is the faster one's time over ALTRO's. (Without --quick the quadrotor and
// the arm carry the same blocks.)
TEST(DemoOutputs, IpoptComparison) {
  const std::filesystem::path& out = demo_folder();
  const nlohmann::json car_bus = nlohmann::json::parse(read(out / "car_bus.json"));
  const double altro_ms = car_bus["solver"]["solve_ms"], altro_cost = car_bus["solver"]["cost"];
  double faster = INFINITY;
  std::string faster_name;
  for (const auto& [key, hessian] :
       {std::pair{"ipopt", "limited-memory"}, std::pair{"ipopt_exact", "exact"}}) {
    const nlohmann::json& run = car_bus.at(key);
    EXPECT_EQ(run["hessian"], hessian);
    EXPECT_EQ(run["status"], "solved");
    EXPECT_EQ(run["max_cpu_seconds"], 120.0);  // the default limit
    EXPECT_LE(run["max_violation"].get<double>(), 1e-6);
    EXPECT_NEAR(run["cost"].get<double>(), altro_cost, 1e-3 * altro_cost) << key;
    if (run["solve_ms"].get<double>() < faster) {
      faster = run["solve_ms"];
      faster_name = hessian;
    }
  }
  EXPECT_EQ(car_bus["altro_speedup"]["over"], faster_name);
  EXPECT_DOUBLE_EQ(car_bus["altro_speedup"]["ratio"].get<double>(), faster / altro_ms);
  EXPECT_EQ(car_bus["altro_speedup"]["runs"], 1);
  EXPECT_EQ(car_bus["altro_speedup"]["same_minimum"], true);  // the costs agree (above)
  for (const char* quick_only : {"quadrotor_window.json", "arm_shelf.json"}) {
    EXPECT_FALSE(nlohmann::json::parse(read(out / quick_only)).contains("ipopt")) << quick_only;
  }
}

// --ipopt-cpu-seconds reaches the car-bus runs: stopped before they solve, both say
// "time limit (-4)" in the JSON (with the cost and violation of the point handed back, evaluated:
// Ipopt's own values there are zeros) and below the table, the table says "failed", and no
// speed-up is claimed.
TEST(DemoOutputs, IpoptCpuLimitStopsTheRunsAndIsReported) {
  const std::filesystem::path out =
      run_demo("diffpills_demo_limit_test", "--ipopt-cpu-seconds 1e-9");
  const nlohmann::json car_bus = nlohmann::json::parse(read(out / "car_bus.json"));
  const std::string printed = read(out / "stdout.txt");
  for (const auto& [key, label] : {std::pair{"ipopt", "L-M"}, std::pair{"ipopt_exact", "exact"}}) {
    const nlohmann::json& run = car_bus.at(key);
    EXPECT_EQ(run["status"], "time limit (-4)") << key;
    const int iterations = run["iterations"];
    EXPECT_LT(iterations, 10) << key;  // 0 here: checked before the first step
    // Near the straight-line guess, which drives through the bus (phi -0.84).
    EXPECT_GT(run["cost"].get<double>(), 0.0) << key;
    EXPECT_GT(run["max_violation"].get<double>(), 0.1) << key;
    const std::string footnote = std::string("car_bus, Ipopt ") + label +
                                 ": time limit (-4) after " + std::to_string(iterations) +
                                 " iterations, ";
    EXPECT_NE(printed.find(footnote), std::string::npos) << footnote << "\n" << printed;
  }
  EXPECT_TRUE(car_bus["altro_speedup"].is_null());
  const std::size_t row = printed.find("\ncar_bus ");
  ASSERT_NE(row, std::string::npos) << printed;
  const std::string row_text = printed.substr(row + 1, printed.find('\n', row + 1) - row - 1);
  EXPECT_EQ(row_text.find("solved"), row_text.rfind("solved")) << row_text;  // ALTRO's only
  EXPECT_NE(row_text.find("failed"), row_text.rfind("failed")) << row_text;  // both Ipopt runs
  EXPECT_NE(printed.find("each run limited to 1e-09 s of CPU time"), std::string::npos);
  EXPECT_EQ(car_bus["ipopt"]["max_cpu_seconds"], 1e-9);
}

// An Ipopt block writes null for the cost and the violation of a run that handed back no point
// (Ipopt skips finalize_solution for errors before it starts; the demo's runs do not reach that,
// so the block is checked here), and the numbers of one that did.
TEST(DemoOutputs, IpoptBlockWithoutAPointHasNullCostAndViolation) {
  diffpills::examples::IpoptRun run;
  run.hessian = diffpills::examples::IpoptHessian::kExact;
  run.status = "stopped (-12)";
  run.cost = 3.5;
  run.max_violation = 0.25;
  const nlohmann::ordered_json without_point = diffpills::examples::ipopt_summary(run);
  EXPECT_EQ(without_point["hessian"], "exact");
  EXPECT_EQ(without_point["status"], "stopped (-12)");
  EXPECT_TRUE(without_point["cost"].is_null());
  EXPECT_TRUE(without_point["max_violation"].is_null());
  run.states.emplace_back(Eigen::VectorXd::Zero(2));
  const nlohmann::ordered_json with_point = diffpills::examples::ipopt_summary(run);
  EXPECT_EQ(with_point["cost"], 3.5);
  EXPECT_EQ(with_point["max_violation"], 0.25);
}

// Of each Hessian's runs the demo keeps the fastest that solved, not a faster one stopped by the
// CPU limit (its wall time can be shorter), and the fastest of all when none solved.
TEST(DemoOutputs, FastestIpoptKeepsTheFastestSolvedRun) {
  using diffpills::examples::IpoptHessian;
  using diffpills::examples::IpoptRun;
  const auto run = [](bool solved, double ms) {
    IpoptRun r;
    r.solved = solved;
    r.solve_ms = ms;
    return r;
  };
  // Limited-memory: stopped at 100 ms, solved at 130 and 120; exact: stopped at 90 and 80.
  const std::vector<IpoptRun> limited = {run(false, 100), run(true, 130), run(true, 120)};
  const std::vector<IpoptRun> exact = {run(false, 90), run(false, 80), run(false, 95)};
  std::size_t next_limited = 0, next_exact = 0;
  const diffpills::examples::IpoptRuns kept =
      diffpills::examples::fastest_ipopt(3, [&](IpoptHessian hessian) {
        IpoptRun r =
            hessian == IpoptHessian::kExact ? exact.at(next_exact++) : limited.at(next_limited++);
        r.hessian = hessian;
        return r;
      });
  EXPECT_TRUE(kept.limited_memory.solved);
  EXPECT_EQ(kept.limited_memory.solve_ms, 120.0);
  EXPECT_FALSE(kept.exact.solved);
  EXPECT_EQ(kept.exact.solve_ms, 80.0);
  EXPECT_EQ(kept.faster_solved(), &kept.limited_memory);
}

// The demo's command line: --help, a stray or second argument, and a folder it cannot write
// (an existing one: /proc) end with the documented statuses, not a silent success; so does an
// --ipopt-cpu-seconds without a finite positive number of seconds.
TEST(DemoOutputs, CommandLine) {
  const auto status = [](const std::string& arguments) {
    const int raw = std::system((demo_program + " " + arguments + " > /dev/null 2>&1").c_str());
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  };
  EXPECT_EQ(status("--help"), 0);
  EXPECT_EQ(status("--bogus"), 2);
  EXPECT_EQ(status("-q"), 2);
  EXPECT_EQ(status("one two --quick"), 2);
  EXPECT_EQ(status("/proc --quick"), 1);
  EXPECT_EQ(status("--quick --ipopt-cpu-seconds"), 2);  // no value
  for (const char* limit : {"''", "0", "-0", "-1", "nan", "inf", "1e999", "1e-400", "1e-310", "abc",
                            "5s", "' 5'", "'5 '", "--quick"}) {
    EXPECT_EQ(status(std::string("--quick --ipopt-cpu-seconds ") + limit), 2) << limit;
  }
  // A limit is read before --help ends the program: the smallest normal double is accepted, also
  // written just below it (strtod rounds it up, and glibc sets ERANGE for it all the same).
  for (const char* limit : {"2.2250738585072014e-308", "2.2250738585072012e-308", "1.7e308"}) {
    EXPECT_EQ(status(std::string("--ipopt-cpu-seconds ") + limit + " --help"), 0) << limit;
  }
  EXPECT_EQ(status("--ipopt-cpu-seconds 2.2250738585072011e-308 --help"), 2);  // a subnormal
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (argc < 2) {
    std::fprintf(stderr, "usage: test_demo_outputs <path to diffpills_demo>\n");
    return 2;
  }
  demo_program = argv[1];
  return RUN_ALL_TESTS();
}
