// `make demo`'s files parse and carry what the motion-planning issue promises: runs the demo
// program (its path is the first argument) into a fresh folder and reads everything back.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {

std::string demo_program;

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(DemoOutputs, FilesParseAndCarryTheScenario) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "diffpills_demo_test";
  std::filesystem::remove_all(out);
  ASSERT_EQ(std::system((demo_program + " " + out.string() + " > /dev/null").c_str()), 0);

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
  std::filesystem::remove_all(out);
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
