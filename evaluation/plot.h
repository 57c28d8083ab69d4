// Log-log plots of discrepancy against N, like the paper's Figs. 5-8, drawn
// with cairo as SVG and PNG. Thread-compatible.
#ifndef SFCSAMPLER_EVALUATION_PLOT_H_
#define SFCSAMPLER_EVALUATION_PLOT_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "evaluation/protocol.h"

namespace sfc {

// Writes `path_stem`.svg and `path_stem`.png for one domain and measure
// ("rectangular", "circular", "triangular", "spherical" or "density"), one
// line per method.
absl::Status PlotDiscrepancy(const std::vector<ProtocolRow>& rows, const std::string& domain,
                             const std::string& measure, const std::string& path_stem);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_PLOT_H_
