// The diffpills command: `diffpills query` (JSON Lines) and `diffpills demo`.
#include <cerrno>
#include <csignal>
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
  Optional: "jacobian" (false by default), "method": "default" | "interior_point",
  "signed_distance" (false by default).
  Quaternions are [w, x, y, z]; a capsule's core lies along its body x axis; a polygon is
  {y : C y <= d} in its body x-y plane with d > 0.

An answer:
  {"phi": ..., "core_points": [p1, p2], "points": [p~1, p~2], "normal": [...],
   "gradient": [14 numbers: dphi/d(r1, q1, r2, q2)], "cores_intersect": false,
   "jacobian": {"core_points": 6x14 rows, "points": 6x14 rows},   (jacobian only if asked)
   "signed_distance": {"distance": ..., "points": [x~1, x~2], "normal": [...],
     "gradient": [14 numbers: d distance/d(r1, q1, r2, q2)], "core_points": [x1, x2],
     "penetrating": false, "jacobian": 6x14 rows of the points,
     "core_points_jacobian": 6x14 rows}}   (signed_distance only if asked, its Jacobians
                                            only with "jacobian")
  The signed distance is the gap between the padded shapes, or minus their penetration depth.
  A line that is not a valid query is answered {"error": "<field>: <what is wrong>"}
  and the following lines are still answered.

  Each line is answered as soon as it is read, whatever bytes it holds: a line that is not
  UTF-8, is nested deeper than 64 arrays and objects, repeats a key in one object or is longer
  than 64 MiB is answered with an error too. A UTF-8 byte order mark and a CR before the line
  end are ignored.

exit status:
  0  every line was answered with a result
  1  some line was answered with an error
  2  the command was misused (unknown command, extra arguments)
  3  reading standard input or writing standard output failed (full disk, closed pipe, ...);
     a message on standard error says which, and the command stops there
)";

// Ends a command that wrote to standard output: a write that failed (full disk, closed pipe) is
// reported and ends the command with kInputOutputFailed.
int finish_output(int status) {
  return diffpills::app::flush_standard_output(std::cout, std::cerr)
             ? status
             : diffpills::app::kInputOutputFailed;
}

int misuse(const std::string& problem) {
  std::cerr << "diffpills: " << problem << "\n\n" << kHelp;
  return diffpills::app::kMisuse;
}

}  // namespace

int main(int argc, char** argv) {
  // A reader that goes away (`diffpills query | head -n 1`) makes writes fail with EPIPE, reported
  // like any failed write, instead of killing the command silently with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  if (argc < 2) return misuse("missing command");
  const std::string command = argv[1];
  if (argc > 2) {
    return misuse("unexpected argument '" + std::string(argv[2]) + "' after '" + command + "'" +
                  (command == "query" ? " (queries are read from standard input)" : ""));
  }
  errno = 0;  // so that a failed write's reason is its own
  if (command == "--help" || command == "-h") {
    std::cout << kHelp;
    return finish_output(0);
  }
  if (command == "--version") {
    std::cout << "diffpills " << diffpills::kVersion << "\n";
    return finish_output(0);
  }
  if (command == "query") {
    std::ios::sync_with_stdio(false);
    return diffpills::app::run_query(std::cin, std::cout);
  }
  if (command == "demo") {
    return finish_output(diffpills::app::run_scene_demo(std::cout));
  }
  return misuse("unknown command '" + command + "'");
}
