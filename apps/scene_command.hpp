// `diffpills scene SCENE.json [--margin M]` (DESIGN.md section 3c): loads a scene file, then
// answers one line of body poses with one line of contacts, in order.
#pragma once

#include <iostream>
#include <string>
#include <vector>

#include "diffpills/scene.hpp"
#include "json_lines.hpp"

namespace diffpills::app {

// Answers one query line for `scene`: {"contacts": [...]}, or {"error": "..."} naming the field
// ("poses.arm.q[2]: ...", "poses: body 'arm' has no pose"). A query is {"poses": {"<body name>":
// {"r": [3], "q": [4]}, ...}, "margin": M} with every body posed and "margin" optional
// (default_margin when absent). Sets ok to false for an error answer. Never throws.
std::string answer_scene_line(const Scene& scene, double default_margin, const std::string& line,
                              bool& ok);

// The command, given the arguments after "scene": reads the scene file (a bad file or argument
// is reported on `diagnostics` and returns kMisuse), then answers every line of `in` as
// run_lines does.
int run_scene_command(const std::vector<std::string>& arguments, std::istream& in,
                      std::ostream& out, std::ostream& diagnostics = std::cerr);

}  // namespace diffpills::app
