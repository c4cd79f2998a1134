// The diffpills command: `diffpills query` (JSON Lines) and `diffpills demo`.
#include <cstring>
#include <iostream>
#include <string>

#include "demo_scene.hpp"
#include "diffpills/version.hpp"
#include "query.hpp"

namespace {

constexpr const char* kHelp = R"(usage: diffpills <command>

Differentiable collision detection for capsules and padded polygons.

commands:
  query      Read one JSON query per line on standard input and write one JSON answer per
             line on standard output, in the same order.
  demo       Print phi, closest points, normal and gradient for the paper's Fig. 1 scene.
  --help     Show this text.   --version   Show the version.

A query:
  {"a": {"type": "capsule", "length": 2.0, "radius": 0.2, "r": [0,0,0], "q": [1,0,0,0]},
   "b": {"type": "polygon", "C": [[1,0],[0,1],[-1,0],[0,-1]], "d": [1,1,1,1],
         "radius": 0.1, "r": [0,0,1], "q": [1,0,0,0]},
   "jacobian": true}
  Optional: "jacobian" (false by default), "method": "default" | "interior_point".
  Quaternions are [w, x, y, z]; a capsule's core lies along its body x axis; a polygon is
  {y : C y <= d} in its body x-y plane with d > 0.

An answer:
  {"phi": ..., "core_points": [p1, p2], "points": [p~1, p~2], "normal": [...],
   "gradient": [14 numbers: dphi/d(r1, q1, r2, q2)], "cores_intersect": false,
   "jacobian": {"core_points": 6x14 rows, "points": 6x14 rows}}   (jacobian only if asked)
  A line that is not a valid query is answered {"error": "<field>: <what is wrong>"}
  and the following lines are still answered.

exit status: 0 every line answered, 1 some line was an error, 2 the command was misused.
)";

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::cout << kHelp;
    return 0;
  }
  if (argc == 2 && std::strcmp(argv[1], "--version") == 0) {
    std::cout << "diffpills " << diffpills::kVersion << "\n";
    return 0;
  }
  if (argc == 2 && std::strcmp(argv[1], "query") == 0) {
    std::ios::sync_with_stdio(false);
    return diffpills::app::run_query(std::cin, std::cout);
  }
  if (argc == 2 && std::strcmp(argv[1], "demo") == 0) {
    return diffpills::app::run_scene_demo(std::cout);
  }
  std::cerr << "diffpills: " << (argc < 2 ? "missing command" : "unknown arguments") << "\n\n"
            << kHelp;
  return 2;
}
