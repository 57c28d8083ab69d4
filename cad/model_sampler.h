// Sampling a CAD model (issue 11): one curve tree per face, one curve and one
// equalisation through all faces (paper Fig. 1 line 8 over the whole model).
//
// The faces are visited in Model::curve_order(), the 3D Hilbert order of
// their centroids, so consecutive faces along the curve are close in space.
// Each face with area (and density mass) gets its own core CurveTree over its
// unit square, with the density made zero outside the face's trimmed region:
// the masses count only the trimmed part, and the error-controlled tree
// refines the cells the trim boundary crosses like any other place where the
// density changes fast. With M_f the faces' masses and S their sum, face f
// owns the mass window [S_{f-1}, S_f) of the model's curve, and sample k lands
// in the face whose window holds q_k S; inside it, q_k is rescaled to the
// face's own tree (Sequence::Window), so every sample is the core sampler's
// on that face and the faces' shares follow area x density exactly as along
// one curve. Each face's tree is built for the samples its share brings
// (grade of ceil(N M_f / S)), not for all N.
//
// Trims. The tree resolves a trim boundary down to leaves of a few samples,
// and a sample's place inside such a leaf follows the leaf's smooth model,
// which does not know the boundary; a sample that lands outside its face's
// trimmed region is moved to the nearest point inside (a deterministic search
// on growing circles in the face's unit square, from 1e-9 of the square), and
// its point, normal and density are evaluated there (Face::Contains answers
// from a grid classified once, so the kernel is asked only near a trim). No
// sample leaves its
// face; the few moved ones are counted (ModelSampleCursor::moved()).
//
// Columns: u, v are the face's own unit-square parameters; `face` is the
// face's index in the file's order; curve_position is (rank of the face
// along the curve + the position along the face's curve) / faces.
//
// Thread-safety: ModelTree is immutable and thread-safe; a cursor is used by
// one thread at a time.
#ifndef SFCSAMPLER_CAD_MODEL_SAMPLER_H_
#define SFCSAMPLER_CAD_MODEL_SAMPLER_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "cad/model.h"
#include "core/curve_tree.h"
#include "core/density.h"
#include "core/sampler.h"
#include "core/sequence.h"
#include "core/types/region.h"
#include "core/types/sample_batch.h"

namespace sfc::cad {

class ModelTree {
 public:
  // One face's part of the curve.
  struct Piece {
    int face = 0;  // index into Model::faces()
    std::shared_ptr<const Surface> surface;
    std::shared_ptr<const Density> density;  // the model's density, zero outside the trim
    std::shared_ptr<const CurveTree> tree;
    double lo = 0, hi = 1;  // the piece's window of q: [S_{f-1}/S, S_f/S)
  };

  // Trees for `count` samples of `density` on `model`; options.max_leaves
  // bounds all faces together. Faces without area or mass are left out
  // (skipped_faces()). Errors: INVALID_ARGUMENT when no face has mass (the
  // message names the model), the core build's errors otherwise
  // (RESOURCE_EXHAUSTED past the leaf budget, the control's status).
  static absl::StatusOr<std::shared_ptr<const ModelTree>> Build(
      std::shared_ptr<const Model> model, std::shared_ptr<const Density> density,
      const CurveTreeOptions& options, uint64_t count, const BuildControl& control = {});

  const Model& model() const { return *model_; }
  const std::vector<Piece>& pieces() const { return pieces_; }  // in curve order
  size_t skipped_faces() const { return skipped_faces_; }
  uint64_t leaf_count() const { return leaves_; }
  uint64_t bytes() const { return bytes_; }
  double total_mass() const { return total_mass_; }  // S: the faces' masses summed

 private:
  ModelTree() = default;
  std::shared_ptr<const Model> model_;
  std::vector<Piece> pieces_;
  size_t skipped_faces_ = 0;
  uint64_t leaves_ = 0, bytes_ = 0;
  double total_mass_ = 0;
};

class ModelSampleCursor {
 public:
  // Samples [begin, end) of `sequence` on `tree` inside `region`, in curve
  // order; for a two-dimensional sequence (sobol: split across the faces by
  // its first coordinate, then warped through the face's tree), positions
  // [begin, end) of the whole set in curve order. Errors (INVALID_ARGUMENT):
  // begin > end, end > count, an invalid region or a parameter rectangle (a
  // model has one parameter square per face: use a 3D box).
  static absl::StatusOr<std::unique_ptr<ModelSampleCursor>> Create(
      std::shared_ptr<const ModelTree> tree, Sequence sequence, uint64_t begin, uint64_t end,
      const Region& region, const SampleFields& fields, int threads = 1);

  // Appends up to `max` samples to `batch` (not cleared); 0 once exhausted.
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch);

  // Samples so far that were moved back into their face's trimmed region.
  uint64_t moved() const { return moved_; }

 private:
  ModelSampleCursor(std::shared_ptr<const ModelTree> tree, Sequence sequence, Region region,
                    SampleFields fields, int threads)
      : tree_(std::move(tree)), sequence_(sequence), region_(region), fields_(fields),
        threads_(threads) {}
  absl::Status OpenPiece();
  // Moves samples [begin, end) of `b` that lie outside the trim of `piece`
  // into it (MoveIntoTrim), one trim check for the batch.
  void KeepInTrim(const ModelTree::Piece& piece, size_t begin, size_t end, SampleBatch* b);
  // Moves sample i of `b`, outside the trim, to the nearest inside point.
  void MoveIntoTrim(const ModelTree::Piece& piece, size_t i, SampleBatch* b);

  const std::shared_ptr<const ModelTree> tree_;
  const Sequence sequence_;
  const Region region_;
  const SampleFields fields_;
  const int threads_;
  uint64_t begin_ = 0, end_ = 0;
  // Two-dimensional sequences (sobol): each piece's number of samples, whose
  // running sums turn [begin_, end_) into positions inside each piece, and
  // its samples' indices (increasing; freed once its cursor is made).
  std::vector<uint64_t> piece_counts_;
  std::vector<std::vector<uint32_t>> piece_members_;
  size_t piece_ = 0;                      // the piece being read
  std::unique_ptr<SampleCursor> cursor_;  // its cursor, null until opened
  SampleBatch scratch_;
  std::vector<uint8_t> inside_;  // KeepInTrim's answers, reused
  uint64_t moved_ = 0;
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_MODEL_SAMPLER_H_
