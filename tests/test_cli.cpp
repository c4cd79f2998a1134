// `diffpills query` (DESIGN.md section 3): answers equal the C++ API's, and every bad input of the
// core issue gets an error line naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <ios>
#include <nlohmann/json.hpp>
#include <sstream>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "json_io.hpp"
#include "json_line.hpp"
#include "query.hpp"

namespace diffpills::app {
namespace {

using nlohmann::json;

const char* kCapsule =
    R"({"type": "capsule", "length": 2.0, "radius": 0.2, "r": [0, 0, 0], "q": [1, 0, 0, 0]})";
const char* kPolygon =
    R"({"type": "polygon", "C": [[1,0],[0,1],[-1,0],[0,-1]], "d": [1,1,1,1], "radius": 0.1, )"
    R"("r": [0.3, 0.1, 1], "q": [0.9, 0.1, 0.2, 0]})";

// Parses an answer strictly: nlohmann::json::parse throws on bytes that are not UTF-8.
json answer(const std::string& line, bool expect_ok = true) {
  bool ok = false;
  const std::string out = answer_query_line(line, ok);
  EXPECT_EQ(ok, expect_ok) << out;
  EXPECT_EQ(out.find('\n'), std::string::npos);  // one line per answer
  return json::parse(out);
}

std::string error_of(const std::string& line) {
  const json out = answer(line, false);
  EXPECT_EQ(out.size(), 1u) << out;
  return out.value("error", std::string());
}

bool mentions_nan(const std::string& message) { return message.find("NaN") != std::string::npos; }

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

// "signed_distance": true adds the signed distance (DESIGN.md section 3b), as the library gives it.
TEST(Cli, SignedDistanceMatchesTheLibrary) {
  // The capsule through the square (penetrating) and far above it (apart).
  for (const char* height : {"0.1", "3"}) {
    const std::string upright =
        std::string(R"({"type": "capsule", "length": 2.0, "radius": 0.2, "r": [0.2, 0, )") +
        height + R"(], "q": [0.7071067811865476, 0, -0.7071067811865476, 0]})";
    const json out =
        answer(query_with(kPolygon, upright, R"(, "signed_distance": true, "jacobian": true)"));
    Eigen::MatrixX2d C(4, 2);
    C << 1, 0, 0, 1, -1, 0, 0, -1;
    const PaddedPolygon polygon(C, Eigen::Vector4d(1, 1, 1, 1), 0.1);
    const SignedDistanceJacobian expected = signed_distance_jacobian(
        polygon, Pose({0.3, 0.1, 1}, {0.9, 0.1, 0.2, 0}), Capsule(2.0, 0.2),
        Pose({0.2, 0, std::stod(height)}, {0.7071067811865476, 0, -0.7071067811865476, 0}));
    const json& sd = out["signed_distance"];
    EXPECT_EQ(sd["distance"].get<double>(), expected.distance);
    EXPECT_EQ(sd["penetrating"].get<bool>(), expected.penetrating);
    EXPECT_EQ(sd["penetrating"].get<bool>(), std::string(height) == "0.1");
    for (int i = 0; i < 2; ++i) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(sd["points"][i][k].get<double>(), expected.points[i](k));
        EXPECT_EQ(sd["core_points"][i][k].get<double>(), expected.core_points[i](k));
      }
    }
    for (int k = 0; k < 3; ++k) EXPECT_EQ(sd["normal"][k].get<double>(), expected.normal(k));
    for (int k = 0; k < 14; ++k) EXPECT_EQ(sd["gradient"][k].get<double>(), expected.gradient(k));
    ASSERT_EQ(sd["jacobian"].size(), 6u);
    EXPECT_EQ(sd["jacobian"][5][13].get<double>(), expected.points_jacobian(5, 13));
    EXPECT_EQ(sd["core_points_jacobian"][0][4].get<double>(), expected.core_points_jacobian(0, 4));
    EXPECT_TRUE(out.contains("phi"));  // the proximity's answer is still there
  }
  const json plain = answer(query_with(kCapsule, kPolygon, R"(, "signed_distance": true)"));
  EXPECT_FALSE(plain["signed_distance"].contains("jacobian"));
  EXPECT_FALSE(answer(query_with(kCapsule, kPolygon, R"(, "signed_distance": false)"))
                   .contains("signed_distance"));
  expect_error(query_with(kCapsule, kPolygon, R"(, "signed_distance": 1)"), "signed_distance");
}

// "shape_gradient": true adds the shapes' parameter gradients of phi (DESIGN.md section 3b), and
// of the distance inside "signed_distance" when both are asked, as the library gives them.
TEST(Cli, ShapeGradientMatchesTheLibrary) {
  const json out = answer(
      query_with(kCapsule, kPolygon, R"(, "shape_gradient": true, "signed_distance": true)"));
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  const Shape capsule = Capsule(2.0, 0.2);
  const Shape polygon = PaddedPolygon(C, Eigen::Vector4d(1, 1, 1, 1), 0.1);
  const Pose polygon_pose({0.3, 0.1, 1}, {0.9, 0.1, 0.2, 0});
  const auto phi = proximity_shape_gradient(capsule, Pose(), polygon, polygon_pose);
  const auto distance = signed_distance_shape_gradient(capsule, Pose(), polygon, polygon_pose);
  const auto check = [](const json& got, const std::array<ShapeGradient, 2>& expected) {
    const auto& a = std::get<CapsuleShapeGradient>(expected[0]);
    EXPECT_EQ(got["a"]["length"].get<double>(), a.length);
    EXPECT_EQ(got["a"]["radius"].get<double>(), a.radius);
    const auto& b = std::get<PolygonShapeGradient>(expected[1]);
    ASSERT_EQ(got["b"]["C"].size(), 4u);
    ASSERT_EQ(got["b"]["d"].size(), 4u);
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(got["b"]["d"][i].get<double>(), b.d(i));
      for (int j = 0; j < 2; ++j) EXPECT_EQ(got["b"]["C"][i][j].get<double>(), b.C(i, j));
    }
    EXPECT_EQ(got["b"]["radius"].get<double>(), b.radius);
  };
  check(out["shape_gradient"], phi.shape_gradient);
  check(out["signed_distance"]["shape_gradient"], distance.shape_gradient);
  EXPECT_FALSE(answer(query_with(kCapsule, kPolygon, R"(, "signed_distance": true)"))
                   .at("signed_distance")
                   .contains("shape_gradient"));
  expect_error(query_with(kCapsule, kPolygon, R"(, "shape_gradient": "yes")"), "shape_gradient");
}

// "hessian": true adds the 14x14 Hessian of phi, and of the distance inside "signed_distance"
// when both are asked (DESIGN.md section 3b), as the library gives them.
TEST(Cli, HessianMatchesTheLibrary) {
  const json out =
      answer(query_with(kCapsule, kPolygon, R"(, "hessian": true, "signed_distance": true)"));
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  const Shape capsule = Capsule(2.0, 0.2);
  const Shape polygon = PaddedPolygon(C, Eigen::Vector4d(1, 1, 1, 1), 0.1);
  const Pose polygon_pose({0.3, 0.1, 1}, {0.9, 0.1, 0.2, 0});
  const auto phi = proximity_hessian(capsule, Pose(), polygon, polygon_pose).hessian;
  const auto distance = signed_distance_hessian(capsule, Pose(), polygon, polygon_pose).hessian;
  ASSERT_EQ(out["hessian"].size(), 14u);
  ASSERT_EQ(out["signed_distance"]["hessian"].size(), 14u);
  for (int i = 0; i < 14; ++i) {
    ASSERT_EQ(out["hessian"][i].size(), 14u);
    for (int j = 0; j < 14; ++j) {
      EXPECT_EQ(out["hessian"][i][j].get<double>(), phi(i, j));
      EXPECT_EQ(out["signed_distance"]["hessian"][i][j].get<double>(), distance(i, j));
    }
  }
  EXPECT_FALSE(answer(query_with(kCapsule, kPolygon)).contains("hessian"));
  expect_error(query_with(kCapsule, kPolygon, R"(, "hessian": null)"), "hessian");
}

TEST(Cli, BadInputGetsAnErrorNamingTheField) {
  expect_error("{\"a\": ", "a: malformed JSON");  // the value of "a" is missing
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
  expect_error(query_with(capsule("1e999", "0.1"), kPolygon), "a.length: malformed");  // > double
  expect_error(query_with(capsule("NaN", "0.1"), kPolygon), "a.length: malformed");    // not JSON
  expect_error(query_with(capsule("1e300", "0.1"), kPolygon), "a.length");             // > 1e100
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

// A key holding "\u0000" (a NUL once decoded) is named with it written out: the message is read
// back through what(), a C string, and a raw NUL ended it ({"a\u0000": 1} was answered
// {"error":"a"}, the field misnamed and the problem lost).
TEST(Cli, KeysWithANulAreNamedInFull) {
  expect_error(R"({"a\u0000": 1})", R"(a\u0000: unknown field)");
  expect_error(query_with(kCapsule, kPolygon, R"(, "x\u0000y": 1)"), R"(x\u0000y: unknown field)");
  expect_error(query_with(R"({"type": "capsule", "length": 1, "radius": 0.1, "r": [0,0,0],
      "q": [1,0,0,0], "l\u0000": 2})",
                          kPolygon),
               R"(a.l\u0000: unknown field)");
  expect_error(R"({"a\u0000": [1, )", R"(a\u0000[1]: malformed JSON)");
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

// Whatever bytes a line holds, its answer is one line of valid UTF-8 JSON: an error naming the
// field where there is one. Before, bytes that are not UTF-8 made nlohmann's dump() throw while
// the error answer was built, and the command died in std::terminate.
TEST(Cli, AnyBytesGetOneValidJsonErrorLine) {
  std::string every_byte_but_newline;
  for (int byte = 0; byte < 256; ++byte) {
    if (byte != '\n') every_byte_but_newline += static_cast<char>(byte);
  }
  const std::vector<std::pair<std::string, std::string>> lines_and_fields = {
      {"{\"a\": \"\xff\"}", "a"},                                  // not UTF-8, in a string
      {query_with(kCapsule, "\"\xe2\x82\"") + " ", "b"},           // a truncated sequence
      {"{\"\xc3\x28\": 1}", "query"},                              // not UTF-8, in a key
      {"\xfe\xff{}", "query"},                                     // not UTF-8, outside strings
      {"{\"a\": \"\\ud800\"}", "a"},                               // a lone surrogate escape
      {std::string("{\"a\": 1}\0{\"b\": 2}", 17), "query"},        // a NUL byte
      {std::string("{\"a\": \"\0\"}", 10), "query"},               // a NUL byte in a string
      {every_byte_but_newline, "query"},                           // binary garbage
      {"{\"a\": \"" + std::string(1000000, 'x') + "\xff\"}", "a"}  // a long token quoted
  };
  for (const auto& [line, field] : lines_and_fields) {
    const std::string error = error_of(line);
    EXPECT_EQ(error.rfind(field + ": ", 0), 0u) << error;
    EXPECT_LT(error.size(), 2000u);  // an error does not echo a megabyte of query
  }
  // The replacement character stands for the bytes that are not UTF-8.
  EXPECT_NE(error_of("{\"a\": \"\xff\"}").find("\xef\xbf\xbd"), std::string::npos);
}

// A byte order mark at the start of a line, and CR LF line ends, are whitespace: the query is
// answered. A line of nothing but whitespace is an error that says the line is empty.
TEST(Cli, ByteOrderMarkAndCarriageReturnAreIgnored) {
  const json with_bom = answer("\xef\xbb\xbf" + query_with(kCapsule, kPolygon));
  const json with_cr = answer(query_with(kCapsule, kPolygon) + "\r");
  const json plain = answer(query_with(kCapsule, kPolygon));
  EXPECT_EQ(with_bom, plain);
  EXPECT_EQ(with_cr, plain);
  for (const std::string blank : {"", "   ", "\t \r", "\xef\xbb\xbf"}) {
    const std::string error = error_of(blank);
    EXPECT_EQ(error.rfind("query: empty line", 0), 0u) << error;
  }
  EXPECT_EQ(error_of("\xef\xbb").rfind("query: malformed JSON", 0), 0u);  // half a BOM
}

// nlohmann's parser builds arrays and objects without recursion, but copying a value is
// recursive: before, 10^5 arrays nested inside an object with a sibling key overflowed the stack
// (the ordered_json object copied its members when it grew). Lines nested deeper than
// kMaxNesting are now rejected while they are parsed, naming where.
TEST(Cli, DeepNestingIsRejectedNotACrash) {
  const std::size_t deep = 1000000;
  const std::string arrays = std::string(deep, '[') + std::string(deep, ']');
  std::string objects;
  for (std::size_t i = 0; i < deep; ++i) objects += "{\"a\":";
  objects += "1" + std::string(deep, '}');
  const std::string in_a_shape =
      R"({"a": {"type": "capsule", "length": )" + arrays + "}, " + R"("b": {"type": "capsule"}})";
  for (const std::string& line : {arrays, objects, in_a_shape, std::string(deep, '[')}) {
    const std::string error = error_of(line);
    EXPECT_NE(error.find("nested deeper than 64"), std::string::npos) << error.substr(0, 200);
  }
  EXPECT_EQ(error_of(in_a_shape).rfind("a.length[0][0]", 0), 0u);
  EXPECT_EQ(error_of(objects).rfind("a.a.a.a", 0), 0u);
  // Exactly kMaxNesting levels parse (and are then no query).
  const std::string deepest = std::string(kMaxNesting, '[') + std::string(kMaxNesting, ']');
  EXPECT_EQ(error_of(deepest).rfind("query: must be a JSON object", 0), 0u);
}

// A syntax error says what is wrong and where (nlohmann's reason, the byte), and mentions NaN and
// Infinity only when the line holds such a word or a number out of a double's range.
TEST(Cli, SyntaxErrorsSayWhatIsWrong) {
  const std::string trailing_comma = error_of(R"({"a": 1,})");
  EXPECT_EQ(trailing_comma.rfind("query: malformed JSON at byte 9: ", 0), 0u) << trailing_comma;
  EXPECT_NE(trailing_comma.find("expected string literal"), std::string::npos);
  EXPECT_FALSE(mentions_nan(trailing_comma));
  EXPECT_FALSE(mentions_nan(error_of("not json")));
  EXPECT_FALSE(mentions_nan(error_of(R"({"a": "nan", "inf": 1,})")));  // words inside strings
  EXPECT_FALSE(mentions_nan(error_of(query_with(kCapsule, kPolygon) + "}")));
  const auto capsule_r = [](const std::string& r) {
    return query_with(
        R"({"type": "capsule", "length": 1, "radius": 0.1, "q": [1,0,0,0], "r": )" + r + "}",
        kPolygon);
  };
  for (const std::string number : {"NaN", "nan", "-Infinity", "inf", "+inf", "1e999", "-1e400"}) {
    const std::string error = error_of(capsule_r("[0, " + number + ", 0]"));
    EXPECT_EQ(error.rfind("a.r[1]: malformed JSON at byte ", 0), 0u) << error;
    EXPECT_TRUE(mentions_nan(error)) << error;
  }
  const std::string big_integer = "1" + std::string(400, '0');  // JSON, but no double holds it
  EXPECT_EQ(error_of(capsule_r("[0, 0, " + big_integer + "]")).rfind("a.r[2]: malformed", 0), 0u);
  // Numbers a double holds are numbers, whatever their spelling.
  EXPECT_EQ(answer(capsule_r("[-0, 0.0, 1E-400]"))["phi"], answer(capsule_r("[0, 0, 0]"))["phi"]);
  EXPECT_EQ(answer(capsule_r("[0, 0, 12345678901234567890123]"))["cores_intersect"], false);
}

// JSON that parses but is no query: each error names the field.
TEST(Cli, HostileButWellFormedQueries) {
  // nlohmann would keep the last of two equal keys; a query that says two things is an error.
  expect_error(R"({"a": 1, "b": 2, "a": 3})", "a: given twice");
  expect_error(query_with(R"({"type": "capsule", "length": 1, "radius": 0.1, "r": [0,0,0],
                              "q": [1,0,0,0], "r": [1,1,1]})",
                          kPolygon),
               "a.r: given twice");
  expect_error(query_with(kCapsule, kPolygon, R"(, "jacobian": true, "jacobian": false)"),
               "jacobian: given twice");
  // Sizes, types and values.
  const auto capsule = [](const std::string& fields) {
    return query_with(R"({"type": "capsule", )" + fields + "}", kPolygon);
  };
  expect_error(capsule(R"("length": 1, "radius": 0.1, "r": [0,0,0], "q": [1,0,0,0,0])"), "a.q");
  expect_error(capsule(R"("length": 1, "radius": "0.1", "r": [0,0,0], "q": [1,0,0,0])"),
               "a.radius");
  expect_error(capsule(R"("length": 1, "radius": 0.1, "r": [0,"0",0], "q": [1,0,0,0])"), "a.r[1]");
  expect_error(capsule(R"("length": 1, "radius": 0.1, "r": [0,null,0], "q": [1,0,0,0])"), "a.r[1]");
  expect_error(capsule(R"("length": [1], "radius": 0.1, "r": [0,0,0], "q": [1,0,0,0])"),
               "a.length");
  expect_error(query_with(kCapsule, kPolygon, R"(, "method": 1)"), "method");
  expect_error("{} {}", "query: malformed JSON");
  expect_error("\"a\"", "query: must be a JSON object");
  // A large polygon, given as JSON: answered, the same as through the library.
  const int vertices = 100000;
  Eigen::MatrixX2d C(vertices, 2);
  for (int k = 0; k < vertices; ++k) {
    C.row(k) << std::cos(2 * M_PI * k / vertices), std::sin(2 * M_PI * k / vertices);
  }
  const PaddedPolygon polygon(C, Eigen::VectorXd::Ones(vertices), 0.1);
  const Pose pose({0.2, 0.1, 1.5}, {0.9, 0.1, 0.2, 0});
  json query;
  query["a"] = to_json(Shape(polygon), Pose());
  query["b"] = to_json(Shape(polygon), pose);
  const json out = answer(query.dump());
  EXPECT_EQ(out["phi"].get<double>(), proximity(polygon, Pose(), polygon, pose).phi);
}

// Lines up to kMaxLineBytes are answered; a longer line is answered with an error without being
// kept whole, and the next line is answered.
TEST(Cli, OverlongLineIsAnErrorAndTheNextLineIsAnswered) {
  std::string longest = query_with(kCapsule, kPolygon);
  longest.resize(kMaxLineBytes, ' ');
  std::istringstream in(longest + "\n" + longest + " \n" + query_with(kCapsule, kCapsule));
  std::ostringstream out;
  EXPECT_EQ(run_query(in, out), 1);
  std::istringstream lines(out.str());
  std::vector<json> answers;
  for (std::string line; std::getline(lines, line);) answers.push_back(json::parse(line));
  ASSERT_EQ(answers.size(), 3u);
  EXPECT_TRUE(answers[0].contains("phi"));
  EXPECT_EQ(answers[1]["error"].get<std::string>().rfind("query: line longer than", 0), 0u);
  EXPECT_TRUE(answers[2].contains("phi"));
}

// An output whose every write fails, like a full disk or a closed pipe.
class FailingOutput : public std::streambuf {
 protected:
  int_type overflow(int_type /*c*/) override { return traits_type::eof(); }
};

// An input that serves `text`, then fails like libstdc++'s file buffers on a read error.
class FailingInput : public std::streambuf {
 public:
  explicit FailingInput(std::string text) : text_(std::move(text)) {
    setg(text_.data(), text_.data(), text_.data() + text_.size());
  }

 protected:
  int_type underflow() override { throw std::ios_base::failure("read error"); }

 private:
  std::string text_;
};

// Before, a failed write was ignored: the command answered nothing and exited 0.
TEST(Cli, FailedWriteEndsTheCommandWithStatus3) {
  std::istringstream in(query_with(kCapsule, kCapsule) + "\n" + query_with(kCapsule, kPolygon) +
                        "\n");
  FailingOutput failing;
  std::ostream out(&failing);
  std::ostringstream diagnostics;
  EXPECT_EQ(run_query(in, out, diagnostics), 3);
  EXPECT_EQ(diagnostics.str().rfind("diffpills: cannot write to standard output", 0), 0u)
      << diagnostics.str();
  // It stopped at the first failed answer: the second line was not read.
  std::string unread;
  EXPECT_TRUE(std::getline(in, unread));
  EXPECT_EQ(unread, query_with(kCapsule, kPolygon));
}

TEST(Cli, FailedReadEndsTheCommandWithStatus3) {
  FailingInput failing(query_with(kCapsule, kCapsule) + "\n");
  std::istream in(&failing);
  std::ostringstream out;
  std::ostringstream diagnostics;
  EXPECT_EQ(run_query(in, out, diagnostics), 3);
  EXPECT_NE(out.str().find("\"phi\""), std::string::npos);  // the line before was answered
  EXPECT_EQ(diagnostics.str().rfind("diffpills: cannot read standard input", 0), 0u)
      << diagnostics.str();
}

}  // namespace
}  // namespace diffpills::app
