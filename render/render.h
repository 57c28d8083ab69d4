// Pictures of samples and curves (the paper's Figs. 9-14), drawn with cairo
// into PNG files: samples on the surface, shaded and seen from a chosen
// direction; the adaptive curve mapped onto the surface; and both in the
// parameter square. Thread-compatible.
#ifndef SFCSAMPLER_RENDER_RENDER_H_
#define SFCSAMPLER_RENDER_RENDER_H_

#include <string>

#include "absl/status/status.h"
#include "core/curve_tree.h"
#include "core/surface.h"
#include "core/types/sample_batch.h"

namespace sfc {

struct View {
  int width = 900, height = 900;  // pixels
  double azimuth_degrees = 35;    // around z, from the x axis
  double elevation_degrees = 25;  // above the xy plane
  double point_radius = 0;        // pixels; 0 = from the sample count
  std::string title;              // drawn in the top-left corner
};

// Samples as shaded discs on the surface, drawn back to front.
// REQUIRES: `samples` has normals.
absl::Status RenderSamples(const SampleBatch& samples, const View& view,
                           const std::string& png_path);

// The tree's curve (its leaves' centres in curve order) mapped through f,
// coloured from blue to red along the curve.
absl::Status RenderCurve(const CurveTree& tree, const Surface& surface, const View& view,
                         const std::string& png_path);

// The same in the parameter square: samples as dots, or the curve.
absl::Status RenderParameterSamples(const SampleBatch& samples, const View& view,
                                    const std::string& png_path);
absl::Status RenderParameterCurve(const CurveTree& tree, const View& view,
                                  const std::string& png_path);

}  // namespace sfc

#endif  // SFCSAMPLER_RENDER_RENDER_H_
