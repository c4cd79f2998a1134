// A minimal SVG writer for the demo figures: world coordinates in, y up, scaled to a canvas.
#pragma once

#include <Eigen/Core>
#include <sstream>
#include <string>
#include <vector>

namespace diffpills::examples {

class Svg {
 public:
  // The canvas shows [min, max] (world units) at `scale` pixels per unit, with a margin.
  Svg(const Eigen::Vector2d& min, const Eigen::Vector2d& max, double scale);

  // A padded segment seen from above or in any orthographic view: a stroke of width 2 radius
  // with round caps is exactly its silhouette. radius 0 draws a thin line.
  void segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius,
               const std::string& color, double opacity = 1.0);
  // A padded polygon's silhouette: the polygon filled and stroked at width 2 radius, round joins.
  void polygon(const std::vector<Eigen::Vector2d>& vertices, double radius,
               const std::string& color, double opacity = 1.0);
  // A closed outline, unfilled.
  void outline(const std::vector<Eigen::Vector2d>& vertices, const std::string& color);
  void circle(const Eigen::Vector2d& centre, double pixels, const std::string& color);
  void arrow(const Eigen::Vector2d& from, const Eigen::Vector2d& to, const std::string& color);
  void text(const Eigen::Vector2d& at, const std::string& words, int size = 14);

  std::string str() const;

 private:
  Eigen::Vector2d pixel(const Eigen::Vector2d& p) const;

  Eigen::Vector2d min_, max_;
  double scale_;
  double margin_ = 30.0;
  std::ostringstream body_;
};

}  // namespace diffpills::examples
