// The order in which one space-filling curve visits the faces of a model.
//
// Faces are sorted by the 3D Hilbert index of their centroids (quantised to
// 2^10 cells per axis of the centroids' bounding box; Skilling's transpose
// form, "Programming the Hilbert curve", AIP Conf. Proc. 707, 2004), so faces
// consecutive in the order are close in space and the curve's jumps between
// faces stay short. Ties keep the file's order. Pure function; thread-safe.
#ifndef SFCSAMPLER_CAD_FACE_ORDER_H_
#define SFCSAMPLER_CAD_FACE_ORDER_H_

#include <cstdint>
#include <vector>

#include "core/types/vec3.h"

namespace sfc::cad {


// A permutation of 0..points.size()-1: the points in 3D Hilbert order.
std::vector<int> HilbertOrder(const std::vector<Vec3>& points);

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_FACE_ORDER_H_
