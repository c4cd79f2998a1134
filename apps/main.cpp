// The diffpills command: `diffpills query` and `diffpills scene` (JSON Lines), `diffpills demo`.
#include <cerrno>
#include <csignal>
#include <iostream>
#include <string>
#include <vector>

#include "demo_scene.hpp"
#include "diffpills/version.hpp"
#include "query.hpp"
#include "scene_command.hpp"

namespace {

constexpr const char* kHelp = R"(usage: diffpills <command>

Differentiable collision detection for capsules and padded polygons.

commands:
  query      Read one JSON query per line on standard input and write one JSON answer per
             line on standard output, in the same order.
  scene SCENE.json [--margin M]
             Load a scene of bodies (each a set of posed shapes), then read one line of body
             poses per query and answer every pair of shapes of two bodies within the margin.
  demo       Print phi, closest points, normal and gradient for the paper's Fig. 1 scene.
  --help     Show this text.   --version   Show the version.

A query:
  {"a": {"type": "capsule", "length": 2.0, "radius": 0.2, "r": [0,0,0], "q": [1,0,0,0]},
   "b": {"type": "polygon", "C": [[1,0],[0,1],[-1,0],[0,-1]], "d": [1,1,1,1],
         "radius": 0.1, "r": [0,0,1], "q": [1,0,0,0]},
   "jacobian": true}
  Optional: "jacobian" (false by default), "method": "default" | "interior_point",
  "signed_distance", "shape_gradient" and "hessian" (false by default).
  Quaternions are [w, x, y, z]; a capsule's core lies along its body x axis; a polygon is
  {y : C y <= d} in its body x-y plane with d > 0.

An answer:
  {"phi": ..., "core_points": [p1, p2], "points": [p~1, p~2], "normal": [...],
   "gradient": [14 numbers: dphi/d(r1, q1, r2, q2)], "cores_intersect": false,
   "jacobian": {"core_points": 6x14 rows, "points": 6x14 rows},   (jacobian only if asked)
   "signed_distance": {"distance": ..., "points": [x~1, x~2], "normal": [...],
     "gradient": [14 numbers: d distance/d(r1, q1, r2, q2)], "core_points": [x1, x2],
     "penetrating": false, "jacobian": 6x14 rows of the points,
     "core_points_jacobian": 6x14 rows, "hessian": ..., "shape_gradient": {...}},
                                           (signed_distance only if asked, its Jacobians
                                            only with "jacobian")
   "hessian": 14 rows of 14,             (only if asked; of phi, and of the distance inside
                                           signed_distance when both are asked)
   "shape_gradient": {"a": S, "b": S}}   (only if asked; of phi, and of the distance inside
                                           signed_distance: S = {"length", "radius"} for a
                                           capsule, {"C": m rows of 2, "d": [m], "radius"} for
                                           a polygon, rows as given, redundant rows 0; an
                                           error if beyond the double range: rows of C
                                           shorter than ~1e-308 of the shapes' gap)
  The signed distance is the gap between the padded shapes, or minus their penetration depth.
  A line that is not a valid query is answered {"error": "<field>: <what is wrong>"}
  and the following lines are still answered.

  Each line is answered as soon as it is read, whatever bytes it holds: a line that is not
  UTF-8, is nested deeper than 64 arrays and objects, repeats a key in one object or is longer
  than 64 MiB is answered with an error too. A UTF-8 byte order mark and a CR before the line
  end are ignored.

A scene file (`diffpills scene`):
  {"bodies": [{"name": "link1", "shapes": [<shape as in a query, r and q in the body's frame>],
               "category": 1, "mask": 4294967295},   (category and mask optional)
              ...],
   "exclude": [["link1", "link2"], ...]}              (optional)
  A scene query: {"poses": {"link1": {"r": [...], "q": [...]}, ...}, "margin": 0.1}
  (every body posed; margin optional, overriding --margin, default 0). Its answer:
  {"contacts": [{"bodies": ["link1", "table"], "shapes": [0, 0], "distance": ...,
     "phi": ..., "points": [x~1, x~2], "normal": [...], "gradient": [14 numbers:
     d distance/d(r_body1, q_body1, r_body2, q_body2)], "phi_gradient": [14 numbers]}]}
  every pair of shapes of two bodies not excluded (and whose categories and masks match)
  with signed distance <= margin, sorted by the bodies' order in the file, then the shapes.
  A bad scene file or argument ends the command with status 2 and a message naming the field.

exit status:
  0  every line was answered with a result
  1  some line was answered with an error
  2  the command was misused (unknown command, extra arguments, a bad scene file)
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
  if (command == "scene") {
    std::ios::sync_with_stdio(false);
    return diffpills::app::run_scene_command(std::vector<std::string>(argv + 2, argv + argc),
                                             std::cin, std::cout);
  }
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
