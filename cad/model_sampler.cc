#include "cad/model_sampler.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "core/vector_math.h"

namespace sfc::cad {
namespace {

// The model's density on one face, zero outside its trimmed region. Face
// surfaces take the face's unit square, so point.u, point.v are the face's.
class TrimmedDensity final : public Density {
 public:
  TrimmedDensity(const Face* face, std::shared_ptr<const Density> inner)
      : face_(face), inner_(std::move(inner)) {}
  bool NeedsCurvature() const override { return inner_->NeedsCurvature(); }
  double Value(const SurfacePoint& point) const override {
    if (face_->trimmed() && !face_->Contains(point.u, point.v)) return 0;
    return inner_->Value(point);
  }
  // The trim is a step of this density that leaves need not follow below the
  // trim grid's cells (Face::Contains): a sample outside the trim moves to
  // the nearest inside point (KeepInTrim), and following the trim down to
  // issue 33's rough floor asked the CAD kernel about every point within
  // ~1/2048 of it (the STEP box with a hole: 197 588 leaves and 60 s for
  // 10^6 samples, against 0.23 s before).
  double StepResolution() const override { return face_->trimmed() ? Face::TrimGridCell() : 0; }
  // The inner density's answer on a cell the trim keeps whole.
  bool IsUniformOn(double u0, double u1, double v0, double v1) const override {
    return inner_->IsUniformOn(u0, u1, v0, v1) &&
           (!face_->trimmed() || face_->KeepsWhole(u0, u1, v0, v1));
  }
  // The inner density's bound (an expression's reads x, y, z from the face's
  // Surface::Bound) on a cell inside the trim, 0 on one outside it (every
  // value there is 0), and none (+infinity: the hidden-mass check counts
  // nothing) on a cell the trim may cross. There the nodes outside the trim
  // see 0, so any mass inside would look hidden: the trim itself, a step
  // the tree need not follow (StepResolution), would split the cells along
  // it (the STEP box's smooth densities gained 400 leaves, the cylinder's
  // 600). So a feature within such a cell of a trim curve is not checked.
  bool Bounds() const override { return inner_->Bounds(); }
  double UpperBound(const Surface& surface, double u0, double u1, double v0,
                    double v1) const override {
    if (face_->trimmed()) {
      switch (face_->Classify(u0, u1, v0, v1)) {
        case CellState::kOutside:
          return 0;
        case CellState::kStraddles:
          return INFINITY;
        case CellState::kInside:
          break;
      }
    }
    return inner_->UpperBound(surface, u0, u1, v0, v1);
  }

 private:
  const Face* face_;  // owned by the model, which the tree keeps alive
  std::shared_ptr<const Density> inner_;
};

// The paper's tolerance a for the whole model when the options leave it
// automatic (0): core's automatic share of the diagonal of the box of every
// face with area, each measured on core's grid (WidenByGridPoints). a is a
// length in model units, and the model is one surface made of faces: 1% of
// each face's own diagonal split every face, however small or flat, to
// stage 1's base depth (4096 leaves a face: 32 768 of the STEP box's 46 064).
// 0 when no face gives a finite box; each face's build then resolves its own.
// `control.check` is asked between faces (a face without a closed form is
// evaluated by the CAD kernel).
absl::StatusOr<double> ModelTolerance(const Model& model, const BuildControl& control) {
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const Face& face : model.faces()) {
    if (control.check) RETURN_IF_ERROR(control.check());
    if (!(face.area() > 0)) continue;
    double u, v;
    WidenByGridPoints(face.surface(), &lo, &hi, &u, &v);  // a face's own build reports it
  }
  const double diagonal = Norm(hi - lo);
  return std::isfinite(diagonal) && diagonal > 0 ? kAutomaticToleranceShare * diagonal : 0.0;
}

// A face the core tree cannot sample because it has nothing to sample: no
// area (a degenerate face), or no density mass inside its trim.
bool HasNothingToSample(const absl::Status& status) {
  return status.code() == absl::StatusCode::kInvalidArgument &&
         !CurveTree::IsMassOverflow(status) &&
         (absl::StrContains(status.message(), "zero area") ||
          absl::StrContains(status.message(), "integrates to") ||
          absl::StrContains(status.message(), "to one point"));
}

}  // namespace

absl::StatusOr<std::shared_ptr<const ModelTree>> ModelTree::Build(
    std::shared_ptr<const Model> model, std::shared_ptr<const Density> density,
    const CurveTreeOptions& given, uint64_t count, const BuildControl& control) {
  CurveTreeOptions options = given;
  if (options.tolerance == 0) {
    ASSIGN_OR_RETURN(options.tolerance, ModelTolerance(*model, control));
  }
  auto tree = std::shared_ptr<ModelTree>(new ModelTree());
  tree->model_ = model;
  uint64_t leaves = 0, bytes = 0;  // of the faces' trees so far
  // The caller's control, told the bytes of the faces' trees built before.
  auto control_after = [&](uint64_t bytes_before) {
    BuildControl c = control;
    if (control.charge) {
      c.charge = [charge = control.charge, bytes_before](uint64_t b) {
        return charge(bytes_before + b);
      };
    }
    return c;
  };
  auto over_budget = [&] {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "the model \"%s\" needs more than %d leaves (max_tree_leaves) over its %d faces; ask "
        "for fewer samples or a coarser tree",
        model->name(), options.max_leaves, model->faces().size()));
  };
  auto on_face = [&](int f, const absl::Status& status) {
    return absl::Status(status.code(), absl::StrFormat("face %d of \"%s\": %s", f, model->name(),
                                                       status.message()));
  };
  // Builds face f's tree at `grade` into a new piece, or counts the face as
  // skipped; false when the face has nothing to sample.
  auto build_face = [&](int f, int grade, bool refuse_hidden = true) -> absl::StatusOr<bool> {
    const Face& face = model->faces()[f];
    Piece piece;
    piece.face = f;
    piece.surface = face.shared_surface();
    // An untrimmed face's TrimmedDensity would answer as `density` does.
    piece.density = face.trimmed() ? std::make_shared<TrimmedDensity>(&face, density) : density;
    if (leaves >= options.max_leaves) return over_budget();
    CurveTreeOptions o = options;
    o.max_leaves = options.max_leaves - leaves;  // what the faces before left
    BuildControl face_control = control_after(bytes);
    face_control.refuse_hidden = refuse_hidden;
    auto built = CurveTree::Build(*piece.surface, *piece.density, o, grade, face_control);
    if (!built.ok()) {
      if (HasNothingToSample(built.status())) {
        ++tree->skipped_faces_;
        return false;
      }
      return on_face(f, built.status());
    }
    piece.tree = *std::move(built);
    leaves += piece.tree->leaf_count();
    bytes += piece.tree->bytes();
    tree->pieces_.push_back(std::move(piece));
    return true;
  };
  // The grade for the samples a face's share of the mass brings.
  auto grade_for = [count](double share) {
    const uint64_t samples = static_cast<uint64_t>(std::ceil(static_cast<double>(count) * share));
    return CurveTree::GradeFor(std::max<uint64_t>(1, samples));
  };
  auto total_mass = [&] {
    double total = 0;
    for (const Piece& piece : tree->pieces_) total += piece.tree->total_mass();
    return total;
  };
  // The faces' masses may each be finite and their sum not.
  auto check_total = [&](double total) {
    return CurveTree::CheckMassIsFinite(total, absl::StrFormat("model \"%s\"", model->name()));
  };
  auto nothing_to_sample = [&] {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the model \"%s\" has no face to sample: its %d faces have no area or no density mass",
        model->name(), model->faces().size()));
  };
  if (density->IsUniform()) {
    // A face's mass is its trimmed area (Face::area, the kernel's surface
    // integral), so its share is known before any tree: each face's tree is
    // built once, at its grade (a tree built at grade g is, bit for bit, the
    // grade-0 tree refined to g: core/curve_tree.h).
    double area = 0;  // of the faces with area
    for (const Face& face : model->faces()) area += face.area() > 0 ? face.area() : 0;
    for (int f : model->curve_order()) {
      const Face& face = model->faces()[f];
      if (!(face.area() > 0)) {  // at rounding level (cad/model.h): no samples
        ++tree->skipped_faces_;
        continue;
      }
      RETURN_IF_ERROR(build_face(f, grade_for(face.area() / area)).status());
      if (leaves > options.max_leaves) return over_budget();
    }
    if (tree->pieces_.empty() || !(total_mass() > 0)) return nothing_to_sample();
  } else {
    // Stage one: every face's coarse tree (grade 0), for its mass. A feature
    // its leaves may hide is followed by the refinement, which refuses what
    // it cannot resolve (and a face kept at grade 0 is checked below).
    for (int f : model->curve_order()) {
      if (!(model->faces()[f].area() > 0)) {
        ++tree->skipped_faces_;
        continue;
      }
      RETURN_IF_ERROR(build_face(f, 0, /*refuse_hidden=*/false).status());
    }
    const double coarse_total = total_mass();
    RETURN_IF_ERROR(check_total(coarse_total));
    if (tree->pieces_.empty() || !(coarse_total > 0)) return nothing_to_sample();
    // Stage two: each face's tree refined for the samples its coarse share
    // brings. Each refinement is bounded by the budget its coarse build was
    // given; the sum is checked as they go.
    leaves = 0, bytes = 0;
    for (Piece& piece : tree->pieces_) {
      const int grade = grade_for(piece.tree->total_mass() / coarse_total);
      // Refining to the same grade re-examines its hidden features and
      // refuses them as a fresh build would.
      if (grade > 0 || piece.tree->precision().hidden_share > CurveTree::kHiddenShare) {
        auto refined =
            piece.tree->Refined(*piece.surface, *piece.density, grade, control_after(bytes));
        if (!refined.ok()) return on_face(piece.face, refined.status());
        piece.tree = *std::move(refined);
      }
      leaves += piece.tree->leaf_count();
      bytes += piece.tree->bytes();
      if (leaves > options.max_leaves) return over_budget();
    }
  }
  // The windows, from the refined masses; one double per boundary, so
  // neighbouring windows split the samples exactly.
  const double total = total_mass();
  RETURN_IF_ERROR(check_total(total));
  double running = 0;
  for (size_t i = 0; i < tree->pieces_.size(); ++i) {
    Piece& piece = tree->pieces_[i];
    piece.lo = i == 0 ? 0.0 : tree->pieces_[i - 1].hi;
    running += piece.tree->total_mass();
    piece.hi = i + 1 == tree->pieces_.size() ? 1.0 : running / total;
  }
  tree->leaves_ = leaves;
  tree->bytes_ = bytes;
  tree->total_mass_ = total;
  return std::shared_ptr<const ModelTree>(std::move(tree));
}

absl::StatusOr<std::unique_ptr<ModelSampleCursor>> ModelSampleCursor::Create(
    std::shared_ptr<const ModelTree> tree, Sequence sequence, uint64_t begin, uint64_t end,
    const Region& region, const SampleFields& fields, int threads) {
  if (begin > end || end > sequence.count()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the index range [%d, %d) is not inside the set of %d samples; it needs begin <= end <= "
        "count",
        begin, end, sequence.count()));
  }
  RETURN_IF_ERROR(region.Validate());
  if (region.kind == Region::Kind::kParameterRect) {
    return absl::InvalidArgumentError(
        "a CAD model has one parameter square per face, so a uv: region is ambiguous; use a 3D "
        "box (box:X0,Y0,Z0,X1,Y1,Z1)");
  }
  auto cursor = std::unique_ptr<ModelSampleCursor>(
      new ModelSampleCursor(std::move(tree), sequence, region, fields, std::max(1, threads)));
  cursor->begin_ = begin;
  cursor->end_ = end;
  if (sequence.two_dimensional()) {
    // [begin, end) are positions of the whole set in curve order: each
    // piece's samples are found, in one pass over the set, so a piece takes
    // its part of the range and its cursor warps its own samples alone.
    const auto& pieces = cursor->tree_->pieces();
    cursor->piece_members_.assign(pieces.size(), {});
    std::vector<double> his(pieces.size());
    for (size_t p = 0; p < pieces.size(); ++p) {
      his[p] = pieces[p].hi;
      // A net puts its window's share of the points in it, to a few points:
      // the lists hold 4 bytes a sample, not twice that from growing.
      const double share = std::max(0.0, pieces[p].hi - pieces[p].lo);
      cursor->piece_members_[p].reserve(
          static_cast<size_t>(share * static_cast<double>(sequence.count())) + 64);
    }
    // Windows [lo, hi) meet end to end, and q_k = 1 is the last piece's
    // (Sequence::InWindow's choice).
    for (uint64_t k = 0; k < sequence.count(); ++k) {
      const size_t p = std::upper_bound(his.begin(), his.end(), sequence.At(k)) - his.begin();
      cursor->piece_members_[std::min(p, pieces.size() - 1)].push_back(static_cast<uint32_t>(k));
    }
    cursor->piece_counts_.resize(pieces.size());
    for (size_t p = 0; p < pieces.size(); ++p) {
      cursor->piece_counts_[p] = cursor->piece_members_[p].size();
    }
  }
  return cursor;
}

absl::Status ModelSampleCursor::OpenPiece() {
  const ModelTree::Piece& piece = tree_->pieces()[piece_];
  const Sequence window = sequence_.Window(piece.lo, piece.hi);
  uint64_t kb = begin_, ke = end_;
  if (sequence_.monotone()) {
    // The piece's samples are one index range: those with q_k in its window.
    const size_t last = tree_->pieces().size() - 1;
    auto first_reaching = [&](double q) {
      return FirstIndexWhere(sequence_.count(), [&](uint64_t k) { return sequence_.At(k) >= q; });
    };
    kb = std::max(begin_, piece_ == 0 ? 0 : first_reaching(piece.lo));
    ke = std::min(end_, piece_ == last ? sequence_.count() : first_reaching(piece.hi));
    ke = std::max(kb, ke);
  } else if (sequence_.two_dimensional()) {
    uint64_t before = 0;
    for (size_t p = 0; p < piece_; ++p) before += piece_counts_[p];
    const uint64_t here = piece_counts_[piece_];
    kb = std::min(here, begin_ - std::min(begin_, before));
    ke = std::max(kb, std::min(here, end_ - std::min(end_, before)));
  }
  auto sampler = std::make_shared<const Sampler>(piece.tree, piece.surface, piece.density, window);
  SampleFields core_fields = fields_;
  core_fields.face = core_fields.triangle = false;
  const std::vector<uint32_t>* members =
      sequence_.two_dimensional() ? &piece_members_[piece_] : nullptr;
  ASSIGN_OR_RETURN(cursor_, SampleCursor::Create(sampler, kb, ke, Region{}, core_fields, threads_,
                                                 members));
  if (members != nullptr) std::vector<uint32_t>().swap(piece_members_[piece_]);  // spent
  return absl::OkStatus();
}

void ModelSampleCursor::KeepInTrim(const ModelTree::Piece& piece, size_t begin, size_t end,
                                   SampleBatch* b) {
  const Face& face = tree_->model().faces()[piece.face];
  if (!face.trimmed() || end <= begin) return;
  inside_.resize(end - begin);
  face.ContainsMany(b->u.data() + begin, b->v.data() + begin, end - begin, inside_.data());
  for (size_t i = begin; i < end; ++i) {
    if (!inside_[i - begin]) MoveIntoTrim(piece, i, b);
  }
}

void ModelSampleCursor::MoveIntoTrim(const ModelTree::Piece& piece, size_t i, SampleBatch* b) {
  const Face& face = tree_->model().faces()[piece.face];
  const double s = b->u[i], t = b->v[i];
  // The nearest inside point on growing circles (16 directions each, in a
  // fixed order), clamped to the square. A circle within the clearance holds
  // no inside point (a clamped probe is no farther than r from (s, t)), so it
  // is skipped without asking.
  constexpr int kDirections = 16;
  const double clear = face.Clearance(s, t);
  double best_s = s, best_t = t;
  bool found = false;
  for (double r = 1e-9; r <= 2 && !found; r *= 2) {
    if (r < clear) continue;
    for (int d = 0; d < kDirections && !found; ++d) {
      const math::SinCos a = math::SinCosPi(2.0 * d / kDirections);
      const double cs = std::clamp(s + r * a.cos, 0.0, 1.0);
      const double ct = std::clamp(t + r * a.sin, 0.0, 1.0);
      if (face.Contains(cs, ct)) best_s = cs, best_t = ct, found = true;
    }
  }
  if (!found) return;  // a face with mass has inside points; not reached
  ++moved_;
  b->u[i] = best_s, b->v[i] = best_t;
  const bool curvature = fields_.density && piece.density->NeedsCurvature();
  const SurfaceJet jet = piece.surface->Jet(best_s, best_t, curvature ? 2 : 1);
  b->x[i] = jet.p.x, b->y[i] = jet.p.y, b->z[i] = jet.p.z;
  if (fields_.normal || fields_.density) {
    const SurfaceGeometry geo = GeometryOf(jet);
    if (fields_.normal) b->nx[i] = geo.normal.x, b->ny[i] = geo.normal.y, b->nz[i] = geo.normal.z;
    if (fields_.density) {
      SurfacePoint point;
      point.u = best_s, point.v = best_t, point.p = jet.p, point.normal = geo.normal;
      point.gaussian_curvature = geo.gaussian_curvature;
      point.mean_curvature = geo.mean_curvature;
      b->density[i] = piece.density->Value(point);
    }
  }
}

absl::StatusOr<size_t> ModelSampleCursor::Next(size_t max, SampleBatch* batch) {
  size_t got = 0;
  const double pieces = static_cast<double>(tree_->pieces().size());
  while (got < max && piece_ < tree_->pieces().size()) {
    if (!cursor_) RETURN_IF_ERROR(OpenPiece());
    const ModelTree::Piece& piece = tree_->pieces()[piece_];
    if (region_.kind == Region::Kind::kAll) {
      // Every sample is kept: the face's samples go straight into `batch`
      // and are kept in the trim there (a copy of every column less).
      const size_t at = batch->size();
      ASSIGN_OR_RETURN(const size_t n, cursor_->Next(max - got, batch));
      if (n == 0) {
        cursor_.reset();
        ++piece_;
        continue;
      }
      KeepInTrim(piece, at, at + n, batch);
      if (fields_.curve_position) {
        for (size_t i = at; i < at + n; ++i) {
          batch->curve_position[i] = CurvePosition(piece_ + batch->curve_position[i], pieces);
        }
      }
      if (fields_.face) batch->face.insert(batch->face.end(), n, static_cast<uint32_t>(piece.face));
      got += n;
      continue;
    }
    scratch_.Clear();
    ASSIGN_OR_RETURN(const size_t n, cursor_->Next(max - got, &scratch_));
    if (n == 0) {
      cursor_.reset();
      ++piece_;
      continue;
    }
    KeepInTrim(piece, 0, n, &scratch_);
    if (fields_.curve_position) {
      for (double& c : scratch_.curve_position) c = (piece_ + c) / pieces;
    }
    // The samples inside the region, appended a run of consecutive ones at a time.
    for (size_t i = 0; i < n;) {
      size_t j = i;
      while (j < n && region_.Contains(scratch_.u[j], scratch_.v[j],
                                       Vec3{scratch_.x[j], scratch_.y[j], scratch_.z[j]})) {
        ++j;
      }
      if (j > i) {
        batch->AppendFrom(scratch_, i, j);
        if (fields_.face)
          batch->face.insert(batch->face.end(), j - i, static_cast<uint32_t>(piece.face));
        got += j - i;
      }
      i = j + 1;  // j is outside the region, or n
    }
  }
  return got;
}

}  // namespace sfc::cad
