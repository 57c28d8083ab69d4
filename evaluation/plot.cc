#include "evaluation/plot.h"

#include <cairo-svg.h>
#include <cairo.h>

#include <cmath>
#include <map>

#include "absl/strings/str_format.h"

namespace sfc {
namespace {

struct Series {
  std::vector<std::pair<double, double>> points;  // (log10 N, log10 D)
};

void Draw(cairo_t* cr, double width, double height, const std::map<std::string, Series>& series,
          const std::string& title) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& [name, s] : series) {
    for (auto [x, y] : s.points) {
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  x0 = std::floor(x0), x1 = std::ceil(x1), y0 = std::floor(y0), y1 = std::ceil(y1);
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  const double left = 70, right = 200, top = 40, bottom = 50;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * (width - left - right); };
  auto py = [&](double y) {
    return height - bottom - (y - y0) / (y1 - y0) * (height - top - bottom);
  };

  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 12);
  cairo_set_line_width(cr, 1);
  for (double x = x0; x <= x1; ++x) {
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, px(x), py(y0));
    cairo_line_to(cr, px(x), py(y1));
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, px(x) - 14, height - bottom + 18);
    cairo_show_text(cr, absl::StrFormat("1e%d", static_cast<int>(x)).c_str());
  }
  for (double y = y0; y <= y1; ++y) {
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, px(x0), py(y));
    cairo_line_to(cr, px(x1), py(y));
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, 20, py(y) + 4);
    cairo_show_text(cr, absl::StrFormat("1e%d", static_cast<int>(y)).c_str());
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, px(x0), py(y1), px(x1) - px(x0), py(y0) - py(y1));
  cairo_stroke(cr);
  cairo_set_font_size(cr, 14);
  cairo_move_to(cr, left, 24);
  cairo_show_text(cr, title.c_str());
  cairo_set_font_size(cr, 12);
  cairo_move_to(cr, (px(x0) + px(x1)) / 2 - 30, height - 12);
  cairo_show_text(cr, "points N");

  static const double kColours[][3] = {{0.85, 0.1, 0.1}, {0.1, 0.45, 0.85}, {0.1, 0.6, 0.2},
                                       {0.6, 0.2, 0.7},  {0.9, 0.55, 0.0},  {0.0, 0.0, 0.0},
                                       {0.5, 0.5, 0.5},  {0.0, 0.6, 0.6}};
  int i = 0;
  for (const auto& [name, s] : series) {
    const double* c = kColours[i % 8];
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    cairo_set_line_width(cr, name.rfind("hilbert", 0) == 0 ? 2.2 : 1.2);
    for (size_t k = 0; k < s.points.size(); ++k) {
      const double x = px(s.points[k].first), y = py(s.points[k].second);
      k == 0 ? cairo_move_to(cr, x, y) : cairo_line_to(cr, x, y);
    }
    cairo_stroke(cr);
    const double ly = top + 20 + 20 * i;
    cairo_move_to(cr, width - right + 15, ly);
    cairo_line_to(cr, width - right + 40, ly);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, width - right + 45, ly + 4);
    cairo_show_text(cr, name.c_str());
    ++i;
  }
}

}  // namespace

absl::Status PlotDiscrepancy(const std::vector<ProtocolRow>& rows, const std::string& domain,
                             const std::string& measure, const std::string& path_stem) {
  std::map<std::string, Series> series;
  for (const ProtocolRow& r : rows) {
    if (r.domain != domain) continue;
    const std::optional<double>& d = measure == "rectangular" ? r.rectangular
                                     : measure == "circular"  ? r.circular
                                     : measure == "triangular" ? r.triangular
                                     : measure == "density"    ? r.density
                                                               : r.spherical;
    if (d && *d > 0)
      series[r.method].points.push_back({std::log10(static_cast<double>(r.n)), std::log10(*d)});
  }
  if (series.empty())
    return absl::InvalidArgumentError("nothing to plot for " + domain + " " + measure);
  for (auto& [name, s] : series) std::sort(s.points.begin(), s.points.end());
  const double width = 800, height = 560;
  const std::string title = absl::StrFormat("%s discrepancy (%s)", measure, domain);

  cairo_surface_t* svg = cairo_svg_surface_create((path_stem + ".svg").c_str(), width, height);
  cairo_t* cr = cairo_create(svg);
  Draw(cr, width, height, series, title);
  cairo_destroy(cr);
  cairo_surface_finish(svg);
  const cairo_status_t svg_status = cairo_surface_status(svg);
  cairo_surface_destroy(svg);

  cairo_surface_t* png = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
  cr = cairo_create(png);
  Draw(cr, width, height, series, title);
  cairo_destroy(cr);
  const cairo_status_t png_status = cairo_surface_write_to_png(png, (path_stem + ".png").c_str());
  cairo_surface_destroy(png);
  if (svg_status != CAIRO_STATUS_SUCCESS || png_status != CAIRO_STATUS_SUCCESS) {
    return absl::UnavailableError("cannot write " + path_stem + ".svg/.png");
  }
  return absl::OkStatus();
}

}  // namespace sfc
