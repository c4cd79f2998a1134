// `make demo`'s files parse and carry what the motion-planning issue promises: runs the demo
// program (its path is the first argument) into a fresh folder and reads everything back, then
// checks that each CSV row follows from the previous one by RK4 of the documented model, with the
// parameters the JSON files state.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string demo_program;

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// Runs the demo once into a fresh folder; both tests read it.
const std::filesystem::path& demo_folder() {
  static const std::filesystem::path out = [] {
    const std::filesystem::path folder =
        std::filesystem::temp_directory_path() / "diffpills_demo_test";
    std::filesystem::remove_all(folder);
    const int status = std::system((demo_program + " " + folder.string() + " > /dev/null").c_str());
    EXPECT_EQ(status, 0);
    return folder;
  }();
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
    rows.push_back(
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
