#include "render/render.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Orthographic camera looking along -view_dir, fitted to a set of points.
struct Camera {
  Vec3 right, up, toward;  // toward: from the scene to the eye
  double scale = 1, cx = 0, cy = 0, width = 0, height = 0;

  Camera(const View& v) : width(v.width), height(v.height) {
    const double az = v.azimuth_degrees * kPi / 180, el = v.elevation_degrees * kPi / 180;
    toward = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    right = Cross(Vec3{0, 0, 1}, toward);
    right = right * (1 / Norm(right));
    up = Cross(toward, right);
  }
  void Fit(const std::vector<Vec3>& pts) {
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (const Vec3& p : pts) {
      const double x = Dot(p, right), y = Dot(p, up);
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    scale = 0.9 * std::min(width / std::max(x1 - x0, 1e-12), height / std::max(y1 - y0, 1e-12));
    cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  }
  double X(const Vec3& p) const { return width / 2 + (Dot(p, right) - cx) * scale; }
  double Y(const Vec3& p) const { return height / 2 - (Dot(p, up) - cy) * scale; }
  double Depth(const Vec3& p) const { return Dot(p, toward); }
};

struct Canvas {
  cairo_surface_t* surface;
  cairo_t* cr;
  explicit Canvas(const View& v) {
    surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, v.width, v.height);
    cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
  }
  absl::Status Save(const View& v, const std::string& path) {
    if (!v.title.empty()) {
      cairo_set_source_rgb(cr, 0, 0, 0);
      cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
      cairo_set_font_size(cr, 16);
      cairo_move_to(cr, 12, 24);
      cairo_show_text(cr, v.title.c_str());
    }
    cairo_destroy(cr);
    const cairo_status_t status = cairo_surface_write_to_png(surface, path.c_str());
    cairo_surface_destroy(surface);
    if (status != CAIRO_STATUS_SUCCESS) return absl::UnavailableError("cannot write " + path);
    return absl::OkStatus();
  }
};

double AutoRadius(const View& v, size_t n) {
  if (v.point_radius > 0) return v.point_radius;
  return std::clamp(0.22 * v.width / std::sqrt(static_cast<double>(std::max<size_t>(n, 1))), 0.5,
                    4.0);
}

// Blue (t = 0) to red (t = 1) through green.
void Hue(cairo_t* cr, double t) {
  const double r = std::clamp(2 * t - 0.5, 0.0, 1.0), g = 1 - std::fabs(2 * t - 1),
               b = std::clamp(1.5 - 2 * t, 0.0, 1.0);
  cairo_set_source_rgb(cr, 0.85 * r, 0.75 * g, 0.9 * b);
}

std::vector<Vec3> LeafCentres(const CurveTree& tree, const Surface* surface) {
  std::vector<Vec3> pts(tree.leaf_count());
  for (size_t l = 0; l < tree.leaf_count(); ++l) {
    const CurveTree::Cell c = tree.LeafCell(l);
    const double u = c.u0 + c.size / 2, v = c.v0 + c.size / 2;
    pts[l] = surface ? surface->Point(u, v) : Vec3{u, v, 0};
  }
  return pts;
}

}  // namespace

absl::Status RenderSamples(const SampleBatch& s, const View& view, const std::string& path) {
  if (s.nx.size() != s.size()) return absl::InvalidArgumentError("RenderSamples needs normals");
  Camera cam(view);
  std::vector<Vec3> pts(s.size());
  for (size_t i = 0; i < s.size(); ++i) pts[i] = {s.x[i], s.y[i], s.z[i]};
  cam.Fit(pts);
  std::vector<size_t> order(pts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return cam.Depth(pts[a]) < cam.Depth(pts[b]); });
  const Vec3 light = (cam.toward * 0.8 + cam.up * 0.5 + cam.right * 0.3) *
                     (1 / Norm(cam.toward * 0.8 + cam.up * 0.5 + cam.right * 0.3));
  Canvas canvas(view);
  const double r = AutoRadius(view, pts.size());
  for (size_t i : order) {
    const double shade = 0.25 + 0.75 * std::fabs(Dot(Vec3{s.nx[i], s.ny[i], s.nz[i]}, light));
    cairo_set_source_rgb(canvas.cr, 0.15 * shade, 0.35 * shade, 0.8 * shade);
    cairo_arc(canvas.cr, cam.X(pts[i]), cam.Y(pts[i]), r, 0, 2 * kPi);
    cairo_fill(canvas.cr);
  }
  return canvas.Save(view, path);
}

absl::Status RenderCurve(const CurveTree& tree, const Surface& surface, const View& view,
                         const std::string& path) {
  Camera cam(view);
  const std::vector<Vec3> pts = LeafCentres(tree, &surface);
  cam.Fit(pts);
  Canvas canvas(view);
  cairo_set_line_width(canvas.cr,
                       std::clamp(600.0 / std::sqrt(static_cast<double>(pts.size())), 0.4, 2.0));
  for (size_t l = 1; l < pts.size(); ++l) {
    Hue(canvas.cr, static_cast<double>(l) / pts.size());
    cairo_move_to(canvas.cr, cam.X(pts[l - 1]), cam.Y(pts[l - 1]));
    cairo_line_to(canvas.cr, cam.X(pts[l]), cam.Y(pts[l]));
    cairo_stroke(canvas.cr);
  }
  return canvas.Save(view, path);
}

absl::Status RenderParameterSamples(const SampleBatch& s, const View& view,
                                    const std::string& path) {
  Canvas canvas(view);
  const double m = 0.05 * view.width, side = view.width - 2 * m;
  cairo_set_source_rgb(canvas.cr, 0, 0, 0);
  cairo_rectangle(canvas.cr, m, m, side, side);
  cairo_stroke(canvas.cr);
  const double r = AutoRadius(view, s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    cairo_arc(canvas.cr, m + s.u[i] * side, m + (1 - s.v[i]) * side, r, 0, 2 * kPi);
    cairo_fill(canvas.cr);
  }
  return canvas.Save(view, path);
}

absl::Status RenderParameterCurve(const CurveTree& tree, const View& view,
                                  const std::string& path) {
  Canvas canvas(view);
  const double m = 0.05 * view.width, side = view.width - 2 * m;
  const std::vector<Vec3> pts = LeafCentres(tree, nullptr);
  cairo_set_line_width(canvas.cr,
                       std::clamp(600.0 / std::sqrt(static_cast<double>(pts.size())), 0.4, 2.0));
  for (size_t l = 1; l < pts.size(); ++l) {
    Hue(canvas.cr, static_cast<double>(l) / pts.size());
    cairo_move_to(canvas.cr, m + pts[l - 1].x * side, m + (1 - pts[l - 1].y) * side);
    cairo_line_to(canvas.cr, m + pts[l].x * side, m + (1 - pts[l].y) * side);
    cairo_stroke(canvas.cr);
  }
  return canvas.Save(view, path);
}

}  // namespace sfc
