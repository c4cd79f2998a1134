// `diffpills query` (DESIGN.md section 3): answers equal the C++ API's, and every bad input of the
// core issue gets an error line naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "json_io.hpp"
#include "query.hpp"

namespace diffpills::app {
namespace {

using nlohmann::json;

const char* kCapsule =
    R"({"type": "capsule", "length": 2.0, "radius": 0.2, "r": [0, 0, 0], "q": [1, 0, 0, 0]})";
const char* kPolygon =
    R"({"type": "polygon", "C": [[1,0],[0,1],[-1,0],[0,-1]], "d": [1,1,1,1], "radius": 0.1, )"
    R"("r": [0.3, 0.1, 1], "q": [0.9, 0.1, 0.2, 0]})";

json answer(const std::string& line, bool expect_ok = true) {
  bool ok = false;
  const std::string out = answer_query_line(line, ok);
  EXPECT_EQ(ok, expect_ok) << out;
  EXPECT_EQ(out.find('\n'), std::string::npos);  // one line per answer
  return json::parse(out);
}

// The error must name `field` at the start of its message.
void expect_error(const std::string& line, const std::string& field) {
  const json out = answer(line, false);
  ASSERT_TRUE(out.contains("error")) << out;
  EXPECT_EQ(out.size(), 1u);
  EXPECT_EQ(out["error"].get<std::string>().rfind(field, 0), 0u) << out["error"];
}

std::string query_with(const std::string& a, const std::string& b, const std::string& extra = "") {
  return R"({"a": )" + a + R"(, "b": )" + b + extra + "}";
}

TEST(Cli, AnswerMatchesTheLibrary) {
  const json out = answer(query_with(kCapsule, kPolygon, R"(, "jacobian": true)"));
  const Capsule capsule(2.0, 0.2);
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  const PaddedPolygon polygon(C, Eigen::Vector4d(1, 1, 1, 1), 0.1);
  const ProximityJacobian expected =
      proximity_jacobian(capsule, Pose(), polygon, Pose({0.3, 0.1, 1}, {0.9, 0.1, 0.2, 0}));
  EXPECT_EQ(out["phi"].get<double>(), expected.phi);  // full precision round trip
  for (int i = 0; i < 2; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(out["core_points"][i][k].get<double>(), expected.core_points[i](k));
      EXPECT_EQ(out["points"][i][k].get<double>(), expected.points[i](k));
    }
  }
  for (int k = 0; k < 3; ++k) EXPECT_EQ(out["normal"][k].get<double>(), expected.normal(k));
  ASSERT_EQ(out["gradient"].size(), 14u);
  for (int k = 0; k < 14; ++k) EXPECT_EQ(out["gradient"][k].get<double>(), expected.gradient(k));
  EXPECT_EQ(out["cores_intersect"].get<bool>(), expected.cores_intersect);
  ASSERT_EQ(out["jacobian"]["core_points"].size(), 6u);
  ASSERT_EQ(out["jacobian"]["points"][5].size(), 14u);
  EXPECT_EQ(out["jacobian"]["points"][4][9].get<double>(), expected.points_jacobian(4, 9));
  EXPECT_EQ(out["jacobian"]["core_points"][2][3].get<double>(),
            expected.core_points_jacobian(2, 3));
  // Without "jacobian", no jacobian field; the interior-point method answers the same phi.
  const json plain = answer(query_with(kCapsule, kPolygon, R"(, "method": "interior_point")"));
  EXPECT_FALSE(plain.contains("jacobian"));
  EXPECT_NEAR(plain["phi"].get<double>(), expected.phi, 1e-12);
}

TEST(Cli, BadInputGetsAnErrorNamingTheField) {
  expect_error("{\"a\": ", "malformed JSON");
  expect_error("[1, 2]", "query");
  expect_error(R"({"a": {}})", "b");
  expect_error(query_with(R"({"type": "cube"})", kPolygon), "a.type");
  expect_error(query_with(R"({"length": 1})", kPolygon), "a.type");
  expect_error(query_with(kCapsule, kPolygon, R"(, "jacobain": true)"), "jacobain");
  expect_error(query_with(kCapsule, kPolygon, R"(, "jacobian": 1)"), "jacobian");
  expect_error(query_with(kCapsule, kPolygon, R"(, "method": "fast")"), "method");
  const auto capsule = [](const std::string& length, const std::string& radius,
                          const std::string& r = "[0,0,0]", const std::string& q = "[1,0,0,0]") {
    return R"({"type": "capsule", "length": )" + length + R"(, "radius": )" + radius +
           R"(, "r": )" + r + R"(, "q": )" + q + "}";
  };
  expect_error(query_with(capsule("-1", "0.1"), kPolygon), "a.length");
  expect_error(query_with(kPolygon, capsule("1", "-0.1")), "b.radius");
  expect_error(query_with(capsule("1e999", "0.1"), kPolygon), "malformed JSON");  // not a double
  expect_error(query_with(capsule("NaN", "0.1"), kPolygon), "malformed JSON");    // not JSON
  expect_error(query_with(capsule("1e300", "0.1"), kPolygon), "a.length");        // > 1e100
  expect_error(query_with(capsule("\"1\"", "0.1"), kPolygon), "a.length");
  expect_error(query_with(capsule("1", "0.1", "[0,0]"), kPolygon), "a.r");
  expect_error(query_with(capsule("1", "0.1", "[0,1e101,0]"), kPolygon), "a.r[1]");
  expect_error(query_with(capsule("1", "0.1", "[0,0,0]", "[0,0,0,0]"), kPolygon), "a.q");
  expect_error(query_with(kCapsule, capsule("1", "0.1", "[0,0,0]", "[0,-1e101,0,0]")), "b.q[1]");
  expect_error(query_with(kCapsule, capsule("1", "0.1", "[0,0,0]", "[1,0,0]")), "b.q");
  const auto polygon = [](const std::string& C, const std::string& d) {
    return R"({"type": "polygon", "C": )" + C + R"(, "d": )" + d +
           R"(, "radius": 0.1, "r": [0,0,0], "q": [1,0,0,0]})";
  };
  expect_error(query_with(kCapsule, polygon("[[1,0],[0,1]]", "[1,1]")), "b.C");
  expect_error(query_with(kCapsule, polygon("[[1,0],[0,1],[-1,-1]]", "[1,1]")), "b.d");
  expect_error(query_with(kCapsule, polygon("[[1,0],[0,1],[-1,-1]]", "[1,0,1]")), "b.d[1]");
  expect_error(query_with(kCapsule, polygon("[[1,0],[1,1],[1,-1]]", "[1,1,1]")), "b.C");
  expect_error(query_with(kCapsule, polygon("[[1,0],[0,1],[-1]]", "[1,1,1]")), "b.C[2]");
  expect_error(query_with(kCapsule, polygon("[[1,0],[0,1],[-1,-1]]", "{}")), "b.d");
  expect_error(query_with(kCapsule, R"({"type": "polygon", "C": [[1,0],[0,1],[-1,-1]],
      "d": [1,1,1], "r": [0,0,0], "q": [1,0,0,0]})"),
               "b.radius");
}

TEST(Cli, EveryLineIsAnsweredInOrder) {
  std::istringstream in(query_with(kCapsule, kPolygon) + "\nnot json\n\n" +
                        query_with(kPolygon, kCapsule) + "\n");
  std::ostringstream out;
  EXPECT_EQ(run_query(in, out), 1);
  std::istringstream lines(out.str());
  std::string line;
  std::vector<json> answers;
  while (std::getline(lines, line)) answers.push_back(json::parse(line));
  ASSERT_EQ(answers.size(), 4u);
  EXPECT_TRUE(answers[0].contains("phi"));
  EXPECT_TRUE(answers[1].contains("error"));
  EXPECT_TRUE(answers[2].contains("error"));  // an empty line is not a query
  EXPECT_TRUE(answers[3].contains("phi"));
  EXPECT_NEAR(answers[0]["phi"].get<double>(), answers[3]["phi"].get<double>(), 1e-12);

  std::istringstream good(query_with(kCapsule, kCapsule) + "\n");
  std::ostringstream good_out;
  EXPECT_EQ(run_query(good, good_out), 0);
}

// The degenerate configurations of the core issue, through the command: each answer must be the
// C++ API's, bit for bit, and finite.
TEST(Cli, DegenerateCasesMatchTheLibrary) {
  const auto capsule = [](double length, double radius, const Pose& pose) {
    return std::make_pair(Shape(Capsule(length, radius)), pose);
  };
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  const auto square = [&](double half, double radius, const Pose& pose) {
    return std::make_pair(Shape(PaddedPolygon(C, Eigen::VectorXd::Constant(4, half), radius)),
                          pose);
  };
  const Eigen::Vector4d I(1, 0, 0, 0);
  const Eigen::Vector4d quarter_z(std::cos(M_PI / 4), 0, 0, std::sin(M_PI / 4));
  const Eigen::Vector4d half_z(0, 0, 0, 1);
  const std::vector<std::pair<std::pair<Shape, Pose>, std::pair<Shape, Pose>>> cases = {
      {capsule(2, 0.1, Pose({0, 0, 0}, I)), capsule(2, 0.1, Pose({0.5, 0, 1}, I))},  // parallel
      {capsule(2, 0.1, Pose({0, 0, 0}, I)),
       capsule(2, 0.1, Pose({0.5, 0, 1}, half_z))},                                // anti-parallel
      {capsule(2, 0.1, Pose({0, 0, 0}, I)), capsule(2, 0.2, Pose({3, 0, 0}, I))},  // collinear
      {capsule(0, 0.3, Pose({0, 0, 0}, I)), capsule(0, 0.2, Pose({1, 2, 2}, I))},  // spheres
      {capsule(2, 0.1, Pose({0.3, 0, 0}, I)),
       capsule(2, 0.2, Pose({0, 0.2, 0}, quarter_z))},                               // crossing
      {square(0.5, 0.1, Pose({1, 2, 3}, I)), square(0.5, 0.1, Pose({1, 2, 3}, I))},  // identical
      {square(1, 0.1, Pose()), square(0.5, 0.2, Pose({0.7, -0.2, 1}, I))},           // stacked
      {square(1, 0.1, Pose()), square(1, 0.1, Pose({3, 0.5, 0}, I))},                // coplanar
      {capsule(4, 0.1, Pose({0.2, 0.4, 1.5}, I)), square(1, 0.2, Pose())},  // parallel to plane
      {capsule(1e-3, 1e-4, Pose({500, -200, 3}, 7.0 * quarter_z)),
       square(1e3, 1, Pose())},  // scales, non-unit q
  };
  for (const auto& [a, b] : cases) {
    json query;
    query["a"] = to_json(a.first, a.second);
    query["b"] = to_json(b.first, b.second);
    query["jacobian"] = true;
    const json out = answer(query.dump());
    const ProximityJacobian expected = proximity_jacobian(a.first, a.second, b.first, b.second);
    ASSERT_TRUE(std::isfinite(expected.phi));
    EXPECT_EQ(out["phi"].get<double>(), expected.phi);
    EXPECT_EQ(out["cores_intersect"].get<bool>(), expected.cores_intersect);
    for (int k = 0; k < 14; ++k) EXPECT_EQ(out["gradient"][k].get<double>(), expected.gradient(k));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(out["normal"][k].get<double>(), expected.normal(k));
    for (int row = 0; row < 6; ++row) {
      for (int col = 0; col < 14; ++col) {
        EXPECT_EQ(out["jacobian"]["points"][row][col].get<double>(),
                  expected.points_jacobian(row, col));
      }
    }
  }
}

}  // namespace
}  // namespace diffpills::app
