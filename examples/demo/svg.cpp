#include "svg.hpp"

namespace diffpills::examples {

Svg::Svg(const Eigen::Vector2d& min, const Eigen::Vector2d& max, double scale)
    : min_(min), max_(max), scale_(scale) {}

Eigen::Vector2d Svg::pixel(const Eigen::Vector2d& p) const {
  return {margin_ + (p.x() - min_.x()) * scale_, margin_ + (max_.y() - p.y()) * scale_};
}

void Svg::segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius,
                  const std::string& color, double opacity) {
  const Eigen::Vector2d pa = pixel(a), pb = pixel(b);
  body_ << "<line x1='" << pa.x() << "' y1='" << pa.y() << "' x2='" << pb.x() << "' y2='" << pb.y()
        << "' stroke='" << color << "' stroke-opacity='" << opacity << "' stroke-width='"
        << std::max(1.0, 2.0 * radius * scale_) << "' stroke-linecap='round'/>\n";
}

void Svg::polygon(const std::vector<Eigen::Vector2d>& vertices, double radius,
                  const std::string& color, double opacity) {
  body_ << "<polygon points='";
  for (const Eigen::Vector2d& v : vertices) {
    const Eigen::Vector2d p = pixel(v);
    body_ << p.x() << "," << p.y() << " ";
  }
  body_ << "' fill='" << color << "' fill-opacity='" << opacity << "' stroke='" << color
        << "' stroke-opacity='" << opacity << "' stroke-width='" << 2.0 * radius * scale_
        << "' stroke-linejoin='round'/>\n";
}

void Svg::outline(const std::vector<Eigen::Vector2d>& vertices, const std::string& color) {
  body_ << "<polygon points='";
  for (const Eigen::Vector2d& v : vertices) {
    const Eigen::Vector2d p = pixel(v);
    body_ << p.x() << "," << p.y() << " ";
  }
  body_ << "' fill='none' stroke='" << color << "' stroke-width='1.5'/>\n";
}

void Svg::circle(const Eigen::Vector2d& centre, double pixels, const std::string& color) {
  const Eigen::Vector2d p = pixel(centre);
  body_ << "<circle cx='" << p.x() << "' cy='" << p.y() << "' r='" << pixels << "' fill='" << color
        << "'/>\n";
}

void Svg::arrow(const Eigen::Vector2d& from, const Eigen::Vector2d& to, const std::string& color) {
  const Eigen::Vector2d a = pixel(from), b = pixel(to);
  const Eigen::Vector2d d = (b - a).normalized();
  const Eigen::Vector2d side(-d.y(), d.x());
  const Eigen::Vector2d h1 = b - 10.0 * d + 5.0 * side, h2 = b - 10.0 * d - 5.0 * side;
  body_ << "<line x1='" << a.x() << "' y1='" << a.y() << "' x2='" << b.x() << "' y2='" << b.y()
        << "' stroke='" << color << "' stroke-width='2'/>\n"
        << "<polygon points='" << b.x() << "," << b.y() << " " << h1.x() << "," << h1.y() << " "
        << h2.x() << "," << h2.y() << "' fill='" << color << "'/>\n";
}

void Svg::text(const Eigen::Vector2d& at, const std::string& words, int size) {
  const Eigen::Vector2d p = pixel(at);
  body_ << "<text x='" << p.x() << "' y='" << p.y() << "' font-family='sans-serif' font-size='"
        << size << "'>" << words << "</text>\n";
}

std::string Svg::str() const {
  const Eigen::Vector2d size = (max_ - min_) * scale_ + Eigen::Vector2d::Constant(2 * margin_);
  std::ostringstream out;
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << size.x() << "' height='" << size.y()
      << "' viewBox='0 0 " << size.x() << " " << size.y() << "'>\n"
      << "<rect width='100%' height='100%' fill='white'/>\n"
      << body_.str() << "</svg>\n";
  return out.str();
}

}  // namespace diffpills::examples
