// `diffpills scene` (DESIGN.md section 3c): answers equal the C++ API's, bad scene files end the
// command with status 2 and a message naming the field, bad lines get an error line and the next
// lines are answered.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "json_io.hpp"
#include "scene_command.hpp"

namespace diffpills::app {
namespace {

using nlohmann::json;

const char* kScene = R"({"bodies": [
  {"name": "link1", "shapes": [{"type": "capsule", "length": 0.3, "radius": 0.05,
                                 "r": [0, 0, 0.15], "q": [1, 0, 0, 0]}]},
  {"name": "table", "shapes": [{"type": "polygon", "C": [[1,0],[0,1],[-1,0],[0,-1]],
                                 "d": [1,1,1,1], "radius": 0.01, "r": [0, 0, 0], "q": [1, 0, 0, 0]}],
   "category": 2, "mask": 1},
  {"name": "link2", "shapes": [{"type": "capsule", "length": 0.3, "radius": 0.05,
                                 "r": [0, 0, 0.15], "q": [0.9, 0, 0.3, 0]},
                                {"type": "capsule", "length": 0, "radius": 0.1,
                                 "r": [0.2, 0, 0], "q": [1, 0, 0, 0]}]}],
 "exclude": [["link2", "link1"]]})";

const char* kPoses = R"({"poses": {"link1": {"r": [0, 0, 0], "q": [1, 0, 0, 0]},
  "table": {"r": [0, 0, 0.1], "q": [1, 0, 0, 0]},
  "link2": {"r": [0.1, 0.2, 0.25], "q": [0.7, 0.1, 0, 0.7]}}, "margin": 0.2})";

std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n') c = ' ';
  }
  return text;
}

struct CommandRun {
  int status = 0;
  std::string out, diagnostics;
};

CommandRun run(const std::vector<std::string>& arguments, const std::string& input) {
  std::istringstream in(input);
  std::ostringstream out, diagnostics;
  CommandRun result;
  result.status = run_scene_command(arguments, in, out, diagnostics);
  result.out = out.str();
  result.diagnostics = diagnostics.str();
  return result;
}

std::string write_file(const std::string& name, const std::string& text) {
  std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

// Sends each case's query line to `diffpills scene path`, each followed by `good` if given, and
// checks that the command ends with status 1, that every query is answered by an error holding
// its expected text, and that every `good` line is answered with contacts.
void expect_error_answers(const std::string& path,
                          const std::vector<std::pair<std::string, std::string>>& cases,
                          const std::string& good = "") {
  std::string input;
  for (const auto& [line, _] : cases) input += line + "\n" + (good.empty() ? "" : good + "\n");
  const CommandRun result = run({path}, input);
  EXPECT_EQ(result.status, 1);
  std::istringstream answers(result.out);
  std::string line;
  for (const auto& [query, expected] : cases) {
    ASSERT_TRUE(std::getline(answers, line));
    const json error = json::parse(line);
    ASSERT_TRUE(error.contains("error")) << query;
    EXPECT_NE(error["error"].get<std::string>().find(expected), std::string::npos)
        << query << " -> " << error["error"];
    if (good.empty()) continue;
    ASSERT_TRUE(std::getline(answers, line));
    EXPECT_TRUE(json::parse(line).contains("contacts")) << line;
  }
}

TEST(SceneCli, AnswerMatchesTheLibrary) {
  const Scene scene = parse_scene(json::parse(kScene));
  const json query = json::parse(kPoses);
  std::vector<Pose> poses;
  for (const char* name : {"link1", "table", "link2"}) {
    poses.push_back(parse_pose(query["poses"][name], name));
  }
  const std::vector<Contact> expected = scene.contacts(poses, 0.2);
  // The filter: link1 (category 1, mask all) and the table (category 2, mask 1) check each other,
  // the table and link2 too; link1 and link2 are excluded. link1 sinks 0.01 into the table, link2's
  // two shapes hover 0.166 and 0.068 above it.
  ASSERT_EQ(expected.size(), 3u);

  const std::string path = write_file("scene.json", kScene);
  const CommandRun result = run({path}, one_line(kPoses) + "\n");
  ASSERT_EQ(result.status, 0) << result.diagnostics;
  const json answer = json::parse(result.out);
  ASSERT_EQ(answer["contacts"].size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const json& c = answer["contacts"][k];
    EXPECT_EQ(c["bodies"][0], scene.body(expected[k].bodies[0]).name());
    EXPECT_EQ(c["bodies"][1], scene.body(expected[k].bodies[1]).name());
    EXPECT_EQ(c["shapes"][1], expected[k].shapes[1]);
    EXPECT_EQ(c["distance"].get<double>(), expected[k].distance);
    EXPECT_EQ(c["phi"].get<double>(), expected[k].phi);
    for (int i = 0; i < 14; ++i) {
      EXPECT_EQ(c["gradient"][static_cast<std::size_t>(i)].get<double>(), expected[k].gradient(i));
      EXPECT_EQ(c["phi_gradient"][static_cast<std::size_t>(i)].get<double>(),
                expected[k].phi_gradient(i));
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(c["points"][1][static_cast<std::size_t>(i)].get<double>(),
                expected[k].points[1](i));
      EXPECT_EQ(c["normal"][static_cast<std::size_t>(i)].get<double>(), expected[k].normal(i));
    }
  }
  // --margin is the default; a line's own margin overrides it.
  std::string no_margin = one_line(kPoses);
  no_margin.replace(no_margin.find(", \"margin\": 0.2"), 15, "");
  const json none = json::parse(run({path}, no_margin + "\n").out);
  const json wide = json::parse(run({path, "--margin", "0.2"}, no_margin + "\n").out);
  EXPECT_EQ(none["contacts"].size(), 1u);
  EXPECT_EQ(wide["contacts"].size(), 3u);
}

TEST(SceneCli, BadLinesGetAnErrorAndTheNextLinesAreAnswered) {
  const std::string path = write_file("scene_lines.json", kScene);
  const std::string good = one_line(kPoses);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not json", "malformed JSON"},
      {"[1, 2]", "query: must be a JSON object"},
      {R"({"margin": 0.1})", "poses: missing"},
      {R"({"poses": {}, "extra": 1})", "extra: unknown field"},
      {R"({"poses": []})", "poses: must be an object"},
      {R"({"poses": {"link1": {"r": [0,0,0], "q": [1,0,0,0]}}})",
       "poses: body 'table' has no pose"},
      {R"({"poses": {"nobody": {"r": [0,0,0], "q": [1,0,0,0]}}})",
       "poses.nobody: no body is named 'nobody'"},
      {R"({"poses": {"link1": {"r": [0,0], "q": [1,0,0,0]}}})", "poses.link1.r: must be an array"},
      {R"({"poses": {"link1": {"r": [0,0,0], "q": [0,0,0,0]}}})", "poses.link1.q: quaternion"},
      {R"({"poses": {"link1": {"r": [0,0,0], "q": [1,0,0,0], "w": 1}}})",
       "poses.link1.w: unknown field"},
  };
  expect_error_answers(path, cases, good);
  // A margin that is not a number, or not finite (1e400 is beyond a double).
  EXPECT_NE(run({path}, R"({"poses": {}, "margin": "x"})"
                        "\n")
                .out.find("margin: must be a number"),
            std::string::npos);
  // A blank line is answered as this command's line, not a query's.
  const json blank = json::parse(run({path}, " \n").out);
  EXPECT_EQ(blank["error"], "query: empty line; expected a JSON object with a field \"poses\"");
}

// A body named with "\u0000" (a NUL once decoded) is named with it written out in every error:
// the message is read back through what(), a C string, and a raw NUL ended it ("poses: body 'a").
TEST(SceneCli, NamesWithANulAreWrittenInFull) {
  const std::string path = write_file("scene_nul.json", R"({"bodies": [
      {"name": "a\u0000b", "shapes": [{"type": "capsule", "length": 0.5, "radius": 0.1,
                                        "r": [1e100, 0, 0], "q": [1, 0, 0, 0]}]},
      {"name": "c", "shapes": []}]})");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"poses": {"c": {"r": [0,0,0], "q": [1,0,0,0]}}})",
       R"(poses: body 'a\u0000b' has no pose)"},
      {R"({"poses": {"a\u0000b": {"r": [1e100,0,0], "q": [1,0,0,0]}, "c": {"r": [0,0,0], "q": [1,0,0,0]}}})",
       R"(poses.a\u0000b, shape 0: its world position is beyond 1e100)"},
      {R"({"poses": {"z\u0000": {"r": [0,0,0], "q": [1,0,0,0]}}})",
       R"(poses.z\u0000: no body is named 'z\u0000')"},
      {R"({"poses": {}, "m\u0000": 1})", R"(m\u0000: unknown field)"},
  };
  expect_error_answers(path, cases);
}

// A pose that puts a primitive beyond 1e100 is named as the line names it: poses.<body>.
TEST(SceneCli, APrimitiveBeyondTheLimitIsNamedByTheLinesField) {
  const std::string path = write_file("far_scene.json", R"({"bodies": [
    {"name": "near", "shapes": []},
    {"name": "far", "shapes": [{"type": "capsule", "length": 1, "radius": 0.1,
                                "r": [1e100, 0, 0], "q": [1, 0, 0, 0]}]}]})");
  const CommandRun result =
      run({path}, one_line(R"({"poses": {"near": {"r": [0, 0, 0], "q": [1, 0, 0, 0]},
                                         "far": {"r": [1e100, 0, 0], "q": [1, 0, 0, 0]}}})") +
                      "\n");
  EXPECT_EQ(result.status, 1);
  EXPECT_EQ(json::parse(result.out)["error"],
            "poses.far, shape 0: its world position is beyond 1e100 in magnitude");
}

TEST(SceneCli, BadSceneFilesAndArgumentsEndWithStatus2) {
  const auto failure = [](const std::vector<std::string>& arguments) {
    const CommandRun result = run(arguments, "");
    EXPECT_EQ(result.status, 2) << result.diagnostics;
    EXPECT_TRUE(result.out.empty());
    return result.diagnostics;
  };
  const auto file_failure = [&](const std::string& text) {
    return failure({write_file("bad_scene.json", text)});
  };
  const auto mentions = [](const std::string& message, const std::string& part) {
    return message.find(part) != std::string::npos;
  };
  EXPECT_TRUE(mentions(failure({}), "missing the scene file"));
  EXPECT_TRUE(mentions(failure({"/nonexistent/scene.json"}), "cannot open the scene file"));
  const std::string path = write_file("good_scene.json", kScene);
  EXPECT_TRUE(mentions(failure({path, "--margin"}), "--margin needs"));
  EXPECT_TRUE(mentions(failure({path, "--margin", "inf"}), "--margin needs"));
  EXPECT_TRUE(mentions(failure({path, "--margin", "0.1x"}), "--margin needs"));
  // JSON's number grammar, the whole argument: no hex, no spaces, no leading '+' or '.'.
  for (const char* margin :
       {"0x1p-3", " 0.1", "0.1 ", "+0.1", ".5", "1.", "01", "", "nan", "1e101"}) {
    EXPECT_TRUE(mentions(failure({path, "--margin", margin}), "--margin needs")) << margin;
  }
  EXPECT_TRUE(
      mentions(failure({path, "--margin", "0.1", "--margin", "0.2"}), "--margin given twice"));
  EXPECT_EQ(run({path, "--margin", "-0.5e-1"}, "").status, 0);
  EXPECT_EQ(run({path, "--margin", "1E+2"}, "").status, 0);
  EXPECT_TRUE(mentions(failure({path, "other.json"}), "unexpected argument 'other.json'"));
  EXPECT_TRUE(mentions(failure({path, "--verbose"}), "unexpected argument '--verbose'"));
  EXPECT_TRUE(mentions(file_failure("{"), "malformed JSON"));
  // Two byte order marks: the message quotes bytes of the second, cut mid-character; it is still
  // valid UTF-8 (nlohmann's strict dump throws on anything else).
  const std::string two_marks = file_failure("\xEF\xBB\xBF\xEF\xBB\xBF{}");
  EXPECT_TRUE(mentions(two_marks, "malformed JSON")) << two_marks;
  EXPECT_NO_THROW(static_cast<void>(json(two_marks).dump())) << two_marks;
  EXPECT_TRUE(mentions(file_failure(" \n"),
                       ": empty file; expected a JSON object with a field \"bodies\""));
  EXPECT_TRUE(mentions(file_failure("[]"), "scene: must be an object"));
  EXPECT_TRUE(mentions(file_failure(R"({"exclude": []})"), "scene.bodies: missing"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": {}})"), "bodies: must be an array"));
  EXPECT_TRUE(
      mentions(file_failure(R"({"bodies": [], "colour": 1})"), "scene.colour: unknown field"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"shapes": []}]})"), "bodies[0].name: missing"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "", "shapes": []}]})"),
                       "bodies[0].name: must be a non-empty string"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "a", "shapes": []},
                                                   {"name": "a", "shapes": []}]})"),
                       "bodies[1].name: 'a' is also the name of bodies[0]"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "a", "shapes": [{"type": "capsule",
                       "length": 1, "radius": -1, "r": [0,0,0], "q": [1,0,0,0]}]}]})"),
                       "bodies[0].shapes[0].radius: must be >= 0"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "a", "shapes": [], "category": -1}]})"),
                       "bodies[0].category: must be an integer from 0 to 4294967295"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "a", "shapes": [], "mask": 1.5}]})"),
                       "bodies[0].mask: must be an integer"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "a", "shapes": []}],
                                       "exclude": [["a", "b"]]})"),
                       "exclude[0]: no body is named 'b'"));
  EXPECT_TRUE(mentions(file_failure(R"({"bodies": [{"name": "a", "shapes": []}],
                                       "exclude": [["a"]]})"),
                       "exclude[0]: must be a pair of body names"));
  // Nested past the limit: named where the parser stopped, with the limit only (it once added
  // "(a query needs 4)", which a scene file is not: it needs 7). The message is read after the
  // file's path, which may hold any word.
  const std::string deep_path = write_file(
      "deep_scene.json", "{\"bodies\": " + std::string(70, '[') + std::string(70, ']') + "}");
  const std::string deep = failure({deep_path});
  ASSERT_TRUE(mentions(deep, deep_path)) << deep;
  const std::string deep_message = deep.substr(deep.find(deep_path) + deep_path.size());
  EXPECT_TRUE(mentions(deep_message, "bodies[0][0][0]")) << deep;
  EXPECT_TRUE(mentions(deep_message, "nested deeper than 64 levels")) << deep;
  EXPECT_FALSE(mentions(deep_message, "query")) << deep;
}

TEST(SceneCli, EmptySceneAndRoundTrip) {
  const std::string empty = write_file("empty_scene.json", R"({"bodies": []})");
  const CommandRun result = run({empty}, R"({"poses": {}})"
                                         "\n");
  EXPECT_EQ(result.status, 0);
  EXPECT_EQ(result.out, "{\"contacts\":[]}\n");
  // A scene written by to_json reads back to the same contacts.
  const Scene scene = parse_scene(json::parse(kScene));
  const Scene again = parse_scene(json::parse(to_json(scene).dump()));
  const std::vector<Pose> poses(3, Pose(Eigen::Vector3d(0, 0, 0.1), Eigen::Vector4d(1, 0, 0, 0)));
  const std::vector<Contact> a = scene.contacts(poses, 0.3), b = again.contacts(poses, 0.3);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k].distance, b[k].distance);
  EXPECT_EQ(again.excluded(), scene.excluded());
  EXPECT_EQ(again.body(1).filter().category, 2u);
}

}  // namespace
}  // namespace diffpills::app
