#include "rcm/estimation/calibration_propagation.h"

#include <ceres/jet.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "rcm/estimation/generalized_epipolar_error.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/util/parallel_for.h"

namespace rcm {

const char* RotationModeName(RotationMode mode) {
  switch (mode) {
    case RotationMode::kHeld:
      return "held";
    case RotationMode::kPrior:
      return "self-calibrated";
    case RotationMode::kFree:
      return "free";
  }
  return "held";
}

namespace {

// Central-difference steps (see the header).
constexpr double kRotationStep = 1e-6;     // radians
constexpr double kTranslationStep = 1e-6;  // meters
constexpr double kLensStepScale = 1e-6;    // times (1 + |p|)
constexpr double kPortStep = 1e-6;         // meters (air gap), tilt
// The least systematic field detected, pixels: far below any matcher's
// (0.03 px for rcm's front end), far above rounding.
constexpr double kMinSystematicPx = 1e-6;
// The rows summed together before their sums are added (see
// AccumulateLocusNormalEquations): a 12000-match sequence in 24 chunks
// that two threads share evenly.
constexpr int64_t kRowsPerChunk = 512;

// The camera with parameter `index` of params() moved by `step`; nullopt
// when the moved camera is invalid (a parameter at the edge of its range).
std::optional<Camera> MovedCamera(const Camera& camera, int index,
                                  double step) {
  std::vector<double> params(camera.params(),
                             camera.params() + camera.num_params());
  params[index] += step;
  StatusOr<Camera> moved = camera.WithParams(params.data());
  if (!moved.ok()) return std::nullopt;
  return *moved;
}

// One finite-difference column: one camera's lens (side 0: left, 1:
// right) moved both ways, and the step.
struct Difference {
  int side = 0;
  std::optional<Camera> plus;
  std::optional<Camera> minus;
  double step = 0.0;
};

std::vector<Difference> LensDifferences(
    const StereoRig& rig, const CalibrationParameterLayout& layout) {
  std::vector<Difference> differences;
  for (int c = 0; c < 2; ++c) {
    const Camera& camera = c == 0 ? rig.left() : rig.right();
    const int count = c == 0 ? layout.num_left_lens : layout.num_right_lens;
    for (int j = 0; j < count; ++j) {
      Difference difference;
      difference.side = c;
      difference.step = kLensStepScale * (1.0 + std::abs(camera.params()[j]));
      difference.plus = MovedCamera(camera, j, difference.step);
      difference.minus = MovedCamera(camera, j, -difference.step);
      differences.push_back(std::move(difference));
    }
  }
  return differences;
}

// The port of a rig side with parameter k of q = [d, a, b] moved by
// `step`; nullopt when the moved port is invalid (a gap below its least).
std::optional<FlatPort> MovedPort(const FlatPort& port, int k, double step) {
  FlatPort moved = port;
  if (k == 0) {
    moved.air_gap += step;
  } else {
    Eigen::Vector2d tilt(port.normal.x() / port.normal.z(),
                         port.normal.y() / port.normal.z());
    tilt[k - 1] += step;
    moved.normal = Eigen::Vector3d(tilt.x(), tilt.y(), 1.0).normalized();
  }
  if (!moved.Check().ok()) return std::nullopt;
  return moved;
}

}  // namespace

CalibrationParameterLayout CalibrationParameterLayout::Of(
    const StereoRig& rig, double systematic_px, bool estimate_focal,
    bool detect_systematic) {
  CalibrationParameterLayout layout;
  layout.systematic_px = systematic_px;
  layout.detect_systematic = detect_systematic;
  if (const std::optional<CalibrationUncertainty>& uncertainty =
          rig.calibration_uncertainty()) {
    if (uncertainty->left_lens_covariance.size() > 0) {
      layout.num_left_lens = rig.left().num_params();
    }
    if (uncertainty->right_lens_covariance.size() > 0) {
      layout.num_right_lens = rig.right().num_params();
    }
    if (uncertainty->port_covariance.size() > 0 && rig.HasThickPort()) {
      layout.num_ports = kNumPorts;
      for (int k = 0; k < kNumPorts; ++k) {
        layout.port_varies[k] = uncertainty->port_covariance(k, k) > 0.0;
      }
    }
    layout.focal = estimate_focal && uncertainty->focal_drift_sigma > 0.0 &&
                   layout.num_left_lens > 0 && layout.num_right_lens > 0;
  }
  for (int k = 0; k < 2; ++k) {
    layout.left_focal[k] = rig.left().params()[k];
    layout.right_focal[k] = rig.right().params()[k];
  }
  return layout;
}

void LocusNormalEquations::Add(const LocusNormalEquations& other) {
  information += other.information;
  gradient += other.gradient;
  gradient_intercept += other.gradient_intercept;
  intercept_squares += other.intercept_squares;
  squared_residuals += other.squared_residuals;
  count += other.count;
}

void LocusNormalEquations::AddRow(const Vector& row, double r, double a) {
  information.selfadjointView<Eigen::Lower>().rankUpdate(row);
  gradient += r * row;
  gradient_intercept += a * row;
  intercept_squares += a * a;
  squared_residuals += r * r;
  ++count;
}

namespace {

// The locus residual of a prepared match for extrinsics `cam1_from_cam0`
// and its derivative in n: the Sampson coplanarity residual of the thin
// port, or the generalized epipolar residual of the rig's thick ports.
class LocusResidualModel {
 public:
  LocusResidualModel(const StereoRig& rig, const Rigid3d& cam1_from_cam0)
      : thick_(rig.HasThickPort()) {
    if (thick_) {
      stereo_.left_port = rig.ports()->left;
      stereo_.right_port = rig.ports()->right;
      stereo_.cam1_from_cam0 = cam1_from_cam0;
    } else {
      essential_ = EssentialMatrix(cam1_from_cam0);
    }
  }

  bool Residual(const PreparedCorrespondence& match, double n, double* r,
                double* dr_dn) const {
    if (dr_dn == nullptr) {
      const bool ok = thick_ ? GeneralizedEpipolarResidual<double>(
                                   stereo_, match, n, 0.0, r)
                             : SampsonCoplanarityResidual<double>(
                                   essential_, match, n, nullptr, r);
      return ok && std::isfinite(*r);
    }
    using Jet = ceres::Jet<double, 1>;
    Jet residual;
    const bool ok = thick_
                        ? GeneralizedEpipolarResidual<Jet>(
                              stereo_, match, Jet(n, 0), Jet(0.0), &residual)
                        : SampsonCoplanarityResidual<Jet>(
                              essential_, match, Jet(n, 0), nullptr, &residual);
    if (!ok || !ceres::isfinite(residual)) return false;
    *r = residual.a;
    if (dr_dn != nullptr) *dr_dn = residual.v[0];
    return true;
  }

 private:
  bool thick_;
  Eigen::Matrix3d essential_ = Eigen::Matrix3d::Zero();
  ThickPortStereo stereo_;
};

}  // namespace

void AccumulateLocusNormalEquations(
    const StereoRig& rig, const CalibrationParameterLayout& layout,
    const std::vector<StereoCorrespondence>& raw,
    const std::vector<PreparedCorrespondence>& matches,
    const std::vector<int64_t>& indices, double n,
    const Eigen::Vector3d& rotation, const Eigen::Vector2d& focal_scale,
    LocusNormalEquations* equations,
    std::vector<LocusNormalEquations>* per_frame, int num_threads) {
  const int size = layout.Size();
  // Pixels to [-1, 1] over the left image, for the systematic field.
  const double half_width = 0.5 * std::max(1, rig.left().width() - 1);
  const double half_height = 0.5 * std::max(1, rig.left().height() - 1);
  CHECK_EQ(equations->information.rows(), size);
  // The rig at the solution, and moved both ways along each of w and dt.
  const StatusOr<StereoRig> at = rig.WithCam1Moved(rotation);
  if (!at.ok()) return;
  const LocusResidualModel model(*at, at->right_from_left());
  std::array<std::optional<LocusResidualModel>, 12> moved;
  for (int k = 0; k < 6; ++k) {
    for (int s = 0; s < 2; ++s) {
      Eigen::Vector3d w = rotation;
      Eigen::Vector3d dt = Eigen::Vector3d::Zero();
      const double step =
          (s == 0 ? 1.0 : -1.0) * (k < 3 ? kRotationStep : kTranslationStep);
      (k < 3 ? w[k] : dt[k - 3]) += step;
      const StatusOr<StereoRig> shifted = rig.WithCam1Moved(w, dt);
      if (shifted.ok()) {
        moved[2 * k + s].emplace(*shifted, shifted->right_from_left());
      }
    }
  }
  const std::vector<Difference> lens = LensDifferences(*at, layout);
  // The ports' columns: each parameter that varies moved both ways (an air
  // gap within a step of 0 forward only: minus is the rig itself).
  struct PortDifference {
    int column = 0;
    std::optional<LocusResidualModel> plus;
    std::optional<LocusResidualModel> minus;  // nullopt: the rig at hand
    double span = 0.0;                        // between plus and minus
  };
  std::vector<PortDifference> ports;
  for (int k = 0; k < layout.num_ports; ++k) {
    if (!layout.port_varies[k]) continue;
    const int side = k / 3;
    const int parameter = k % 3;
    const FlatPort& port = side == 0 ? at->ports()->left : at->ports()->right;
    const bool forward =
        parameter == 0 &&
        port.air_gap < 2.0 * kPortStep + FlatPort::kMinLayerThickness;
    PortDifference difference;
    difference.column = layout.Ports() + k;
    difference.span = forward ? kPortStep : 2.0 * kPortStep;
    for (int s = 0; s < (forward ? 1 : 2); ++s) {
      const std::optional<FlatPort> moved =
          MovedPort(port, parameter, s == 0 ? kPortStep : -kPortStep);
      if (!moved) continue;
      const StatusOr<StereoRig> shifted =
          side == 0 ? at->WithPorts(*moved, at->ports()->right)
                    : at->WithPorts(at->ports()->left, *moved);
      if (!shifted.ok()) continue;
      (s == 0 ? difference.plus : difference.minus)
          .emplace(*shifted, shifted->right_from_left());
    }
    // A side that could not be moved leaves the column undefined.
    if (!difference.plus || (!forward && !difference.minus)) {
      difference.plus.reset();
    }
    ports.push_back(std::move(difference));
  }

  // rankUpdate fills the lower triangle only.
  const auto symmetrize = [](LocusNormalEquations::Matrix* matrix) {
    *matrix = matrix->selfadjointView<Eigen::Lower>();
  };
  // The rows in chunks of kRowsPerChunk indices, each chunk summed on its
  // own (on up to `num_threads` threads), then the chunks in order: the
  // sums do not depend on the number of threads.
  struct Chunk {
    LocusNormalEquations total;
    // The chunk's frames in order of first appearance.
    std::vector<std::pair<int64_t, LocusNormalEquations>> frames;
  };
  const int64_t num_chunks =
      (static_cast<int64_t>(indices.size()) + kRowsPerChunk - 1) /
      kRowsPerChunk;
  std::vector<Chunk> chunks(num_chunks, Chunk{LocusNormalEquations(size), {}});
  const auto accumulate = [&](int64_t chunk_index) {
    Chunk& chunk = chunks[chunk_index];
    LocusNormalEquations::Vector row(size);
    const size_t first = static_cast<size_t>(chunk_index * kRowsPerChunk);
    const size_t last =
        std::min(indices.size(), first + static_cast<size_t>(kRowsPerChunk));
    for (size_t index = first; index < last; ++index) {
      const int64_t i = indices[index];
      const PreparedCorrespondence& match = matches[i];
      double r = 0.0;
      if (!model.Residual(match, n, &r, &row[0])) continue;
      bool defined = true;
      for (int k = 0; k < 6 && defined; ++k) {
        double values[2];
        for (int s = 0; s < 2 && defined; ++s) {
          defined = moved[2 * k + s].has_value() &&
                    moved[2 * k + s]->Residual(match, n, &values[s], nullptr);
        }
        if (defined) {
          row[1 + k] = (values[0] - values[1]) /
                       (2.0 * (k < 3 ? kRotationStep : kTranslationStep));
        }
      }
      for (size_t j = 0; j < lens.size() && defined; ++j) {
        // The match with the moved camera's half prepared again (the other
        // camera's is the match's own).
        double values[2];
        for (int s = 0; s < 2 && defined; ++s) {
          const std::optional<Camera>& moved_camera =
              s == 0 ? lens[j].plus : lens[j].minus;
          PreparedCorrespondence prepared = match;
          defined =
              moved_camera.has_value() &&
              PrepareCorrespondenceSideNear(
                  *moved_camera,
                  lens[j].side == 0 ? raw[i].left_pixel : raw[i].right_pixel,
                  lens[j].side, &prepared) &&
              model.Residual(prepared, n, &values[s], nullptr);
        }
        if (defined) {
          row[layout.LeftLens() + static_cast<int>(j)] =
              (values[0] - values[1]) / (2.0 * lens[j].step);
        }
      }
      for (size_t j = 0; j < ports.size() && defined; ++j) {
        const PortDifference& port = ports[j];
        double plus = 0.0;
        double minus = r;
        defined =
            port.plus.has_value() &&
            port.plus->Residual(match, n, &plus, nullptr) &&
            (!port.minus || port.minus->Residual(match, n, &minus, nullptr));
        if (defined) row[port.column] = (plus - minus) / port.span;
      }
      if (layout.focal && defined) {
        // d r / d e = g^T d r / d lens (d params / d e = g of the
        // calibration's lenses, whatever the scale of the rig at hand).
        for (int c = 0; c < 2; ++c) {
          const int lens_column =
              c == 0 ? layout.LeftLens() : layout.RightLens();
          const double* focal = c == 0 ? layout.left_focal : layout.right_focal;
          row[layout.Focal() + c] =
              focal[0] * row[lens_column] + focal[1] * row[lens_column + 1];
        }
      }
      if (layout.NumSystematic() > 0) {
        const double x = raw[i].left_pixel.x() / half_width - 1.0;
        const double y = raw[i].left_pixel.y() / half_height - 1.0;
        const double phi[CalibrationParameterLayout::kNumSystematic] = {
            1.0, x, y, x * x, x * y, y * y};
        for (int k = 0; k < CalibrationParameterLayout::kNumSystematic; ++k) {
          row[layout.Systematic() + k] = phi[k];
        }
      }
      if (!defined || !row.allFinite()) continue;
      double a = r - n * row[0] - rotation.dot(row.segment<3>(1));
      if (layout.focal) a -= focal_scale.dot(row.segment<2>(layout.Focal()));
      chunk.total.AddRow(row, r, a);
      if (per_frame != nullptr) {
        auto slot = std::find_if(
            chunk.frames.rbegin(), chunk.frames.rend(),
            [&](const auto& entry) { return entry.first == raw[i].frame; });
        if (slot == chunk.frames.rend()) {
          chunk.frames.emplace_back(raw[i].frame, LocusNormalEquations(size));
          slot = chunk.frames.rbegin();
        }
        slot->second.AddRow(row, r, a);
      }
    }
  };
  ParallelFor(num_chunks, num_threads, 1, [&](int64_t begin, int64_t end) {
    for (int64_t c = begin; c < end; ++c) accumulate(c);
  });
  std::map<int64_t, size_t> frame_slot;
  for (Chunk& chunk : chunks) {
    symmetrize(&chunk.total.information);
    equations->Add(chunk.total);
    if (per_frame == nullptr) continue;
    for (auto& [frame_id, frame] : chunk.frames) {
      symmetrize(&frame.information);
      const auto [slot, inserted] =
          frame_slot.emplace(frame_id, per_frame->size());
      if (inserted) {
        per_frame->push_back(std::move(frame));
      } else {
        (*per_frame)[slot->second].Add(frame);
      }
    }
  }
}

QuadraticSelfCalibration SelfCalibrateQuadratic(
    const LocusNormalEquations& equations,
    const CalibrationParameterLayout& layout,
    const Eigen::Matrix3d& rotation_covariance, double focal_sigma,
    double sigma_px) {
  // x = (n, w[, e]): its columns in the layout, and its prior.
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  int columns[6] = {0, 1, 2, 3, 0, 0};
  int size = 4;
  if (layout.focal) {
    columns[size++] = layout.Focal();
    columns[size++] = layout.Focal() + 1;
  }
  Matrix m(size, size);
  Vector intercept(size);
  for (int r = 0; r < size; ++r) {
    intercept[r] = equations.gradient_intercept[columns[r]];
    for (int c = 0; c < size; ++c) {
      m(r, c) = equations.information(columns[r], columns[c]);
    }
  }
  Matrix prior = Matrix::Zero(size, size);
  prior.block<3, 3>(1, 1) =
      rotation_covariance.ldlt().solve(Eigen::Matrix3d::Identity());
  if (layout.focal) {
    prior.block<2, 2>(4, 4) =
        Eigen::Matrix2d::Identity() / (focal_sigma * focal_sigma);
  }
  const double dof =
      static_cast<double>(std::max<int64_t>(equations.count - size, 1));
  constexpr int kMaxPasses = 6;
  constexpr double kVarianceTolerance = 1e-3;  // relative
  QuadraticSelfCalibration result;
  double variance = sigma_px * sigma_px;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    const Matrix h = m + variance * prior;
    Vector x = -h.ldlt().solve(intercept);
    if (!(x[0] >= 1.0 && x[0] <= 2.0)) {
      // n on its bound, the rest solved there.
      x[0] = std::clamp(x[0], 1.0, 2.0);
      x.tail(size - 1) = -h.bottomRightCorner(size - 1, size - 1)
                              .ldlt()
                              .solve(intercept.tail(size - 1) +
                                     m.block(1, 0, size - 1, 1) * x[0]);
    }
    const double data =
        std::max(0.0, equations.intercept_squares + 2.0 * intercept.dot(x) +
                          x.dot(m * x));
    const double updated = data / dof;
    result.n = x[0];
    result.rotation = x.segment<3>(1);
    if (layout.focal) result.focal_scale = x.segment<2>(4);
    const bool settled =
        std::abs(updated - variance) <= kVarianceTolerance * updated;
    variance = updated;
    if (settled) break;
  }
  result.sigma_px = std::sqrt(variance);
  return result;
}

double ChiSquaredUpperTail(double chi_squared, int dof) {
  CHECK_GE(dof, 1);
  if (!(chi_squared > 0.0)) return 1.0;
  const double k = static_cast<double>(dof);
  const double scale = 2.0 / (9.0 * k);
  const double z =
      (std::cbrt(chi_squared / k) - (1.0 - scale)) / std::sqrt(scale);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

namespace {

// p-value and inflation of a consistency with chi_squared and frames set.
std::optional<FrameConsistency> Finish(FrameConsistency consistency,
                                       double sigma_px) {
  if (consistency.frames < 2 || !(sigma_px > 0.0) ||
      !std::isfinite(consistency.chi_squared)) {
    return std::nullopt;
  }
  consistency.dof = consistency.frames - 1;
  consistency.p_value =
      ChiSquaredUpperTail(consistency.chi_squared, consistency.dof);
  if (consistency.p_value < FrameConsistency::kInflationP &&
      consistency.chi_squared > consistency.dof) {
    consistency.inflation =
        std::sqrt(consistency.chi_squared / consistency.dof);
  }
  return consistency;
}

}  // namespace

std::optional<FrameConsistency> FrameConsistencyOf(
    const std::vector<LocusNormalEquations>& per_frame, double sigma_px) {
  FrameConsistency consistency;
  for (const LocusNormalEquations& frame : per_frame) {
    const double information = frame.information(0, 0);
    if (!(information > 0.0)) continue;
    const double score = frame.gradient[0];
    consistency.chi_squared +=
        score * score / (sigma_px * sigma_px * information);
    ++consistency.frames;
  }
  return Finish(consistency, sigma_px);
}

void FrameEstimateSums::Add(double n_f, double information,
                            const SelfCalibrationVector& coupling) {
  s0 += information;
  s1 += information * n_f;
  s2 += information * n_f * n_f;
  b += coupling;
  bn += coupling * n_f;
  if (information > 0.0) {
    bb += coupling * coupling.transpose() / information;
  }
  ++frames;
}

double FrameEstimateSums::WeightedSquares(
    double n, const SelfCalibrationVector& x) const {
  // sum G_f (n_f - n)^2 - 2 (n_f - n) b_f . x + (b_f . x)^2 / G_f.
  return s2 - 2.0 * n * s1 + n * n * s0 - 2.0 * (bn - n * b).dot(x) +
         x.dot(bb * x);
}

std::optional<FrameConsistency> FrameConsistencyOf(
    const FrameEstimateSums& sums, double n, double sigma_px,
    const SelfCalibrationVector& x) {
  FrameConsistency consistency;
  consistency.frames = sums.frames;
  // Rounding can take the difference of large sums a little below zero.
  consistency.chi_squared =
      std::max(0.0, sums.WeightedSquares(n, x)) / (sigma_px * sigma_px);
  return Finish(consistency, sigma_px);
}

StatusOr<CalibrationPropagation> PropagateCalibration(
    const LocusNormalEquations& equations,
    const CalibrationParameterLayout& layout,
    const CalibrationUncertainty& uncertainty, RotationMode mode,
    double sigma_px, double noise_inflation, double n_prior_sigma) {
  const int size = layout.Size();
  CHECK_EQ(equations.information.rows(), size);
  CHECK(sigma_px >= 0.0 && noise_inflation >= 1.0);
  const Eigen::MatrixXd m = equations.information;
  CalibrationPropagation result;
  result.mode = mode;
  result.source = uncertainty.source;

  // The calibration's covariance in the layout's columns (n's is 0). With
  // the focal scales estimated under the focal drift prior, the held lenses
  // carry what the calibration measured only, and the prior is the focal
  // columns' (P below).
  Eigen::MatrixXd calibration = Eigen::MatrixXd::Zero(size, size);
  calibration.block<6, 6>(1, 1) = uncertainty.extrinsics_covariance;
  if (layout.num_left_lens > 0) {
    calibration.block(layout.LeftLens(), layout.LeftLens(),
                      layout.num_left_lens, layout.num_left_lens) =
        uncertainty.left_lens_covariance;
  }
  if (layout.num_right_lens > 0) {
    calibration.block(layout.RightLens(), layout.RightLens(),
                      layout.num_right_lens, layout.num_right_lens) =
        uncertainty.right_lens_covariance;
  }
  // The extrinsics' correlation with the lenses (an underwater
  // calibration's), when both lenses have columns.
  const int num_lens = layout.num_left_lens + layout.num_right_lens;
  if (layout.num_left_lens > 0 && layout.num_right_lens > 0 &&
      uncertainty.extrinsics_lens_covariance.rows() == 6 &&
      uncertainty.extrinsics_lens_covariance.cols() == num_lens) {
    calibration.block(1, layout.LeftLens(), 6, num_lens) =
        uncertainty.extrinsics_lens_covariance;
    calibration.block(layout.LeftLens(), 1, num_lens, 6) =
        uncertainty.extrinsics_lens_covariance.transpose();
  }
  // The lenses' correlation with each other (a joint calibration's).
  if (uncertainty.lens_cross_covariance.rows() == layout.num_left_lens &&
      uncertainty.lens_cross_covariance.cols() == layout.num_right_lens &&
      layout.num_left_lens > 0 && layout.num_right_lens > 0) {
    calibration.block(layout.LeftLens(), layout.RightLens(),
                      layout.num_left_lens, layout.num_right_lens) =
        uncertainty.lens_cross_covariance;
    calibration.block(layout.RightLens(), layout.LeftLens(),
                      layout.num_right_lens, layout.num_left_lens) =
        uncertainty.lens_cross_covariance.transpose();
  }
  // The ports' covariance, and theirs with the extrinsics and the lenses
  // (the cross rows are [w; dt], then the lenses the uncertainty has, which
  // are the layout's lens columns).
  if (layout.num_ports > 0) {
    const int ports = layout.Ports();
    calibration.block(ports, ports, layout.num_ports, layout.num_ports) =
        uncertainty.port_covariance;
    const Eigen::MatrixXd& cross = uncertainty.port_cross_covariance;
    if (cross.rows() == 6 + num_lens && cross.cols() == layout.num_ports) {
      calibration.block(1, ports, 6 + num_lens, layout.num_ports) = cross;
      calibration.block(ports, 1, layout.num_ports, 6 + num_lens) =
          cross.transpose();
    }
  }
  double systematic_variance = layout.systematic_px * layout.systematic_px;
  if (layout.detect_systematic && sigma_px > 0.0) {
    // The field the residuals show: with x the estimated columns and c the
    // field's, u = g_c - M_cx M_xx^-1 g_x (the residuals projected off what
    // the fit absorbed) has Cov(u) = tau^2 A A + sigma^2 A for c ~ N(0,
    // tau^2 I), A = M_cc - M_cx M_xx^-1 M_xc, so that u^T A^+ u / sigma^2
    // is chi^2 of rank A degrees of freedom without a field and
    //   tau^2 = (u^T A^+ u - sigma^2 rank A) / trace A.
    std::vector<int> x = {0};
    if (mode != RotationMode::kHeld) x.insert(x.end(), {1, 2, 3});
    if (layout.focal) x.insert(x.end(), {layout.Focal(), layout.Focal() + 1});
    const int nx = static_cast<int>(x.size());
    const int nc = layout.NumSystematic();
    Eigen::MatrixXd m_xx(nx, nx), m_xc(nx, nc);
    Eigen::VectorXd g_x(nx);
    for (int r = 0; r < nx; ++r) {
      g_x[r] = equations.gradient[x[r]];
      for (int c = 0; c < nx; ++c) m_xx(r, c) = m(x[r], x[c]);
      for (int c = 0; c < nc; ++c)
        m_xc(r, c) = m(x[r], layout.Systematic() + c);
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu_xx(m_xx);
    if (lu_xx.isInvertible()) {
      const Eigen::MatrixXd m_cc =
          m.block(layout.Systematic(), layout.Systematic(), nc, nc);
      const Eigen::MatrixXd a_cc = m_cc - m_xc.transpose() * lu_xx.solve(m_xc);
      const Eigen::VectorXd u =
          equations.gradient.segment(layout.Systematic(), nc) -
          m_xc.transpose() * lu_xx.solve(g_x);
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a_cc);
      const double largest = eigen.eigenvalues().maxCoeff();
      double statistic = 0.0;
      int rank = 0;
      for (int k = 0; k < nc; ++k) {
        const double value = eigen.eigenvalues()[k];
        if (!(value > 1e-12 * largest)) continue;
        const double projection = eigen.eigenvectors().col(k).dot(u);
        statistic += projection * projection / value;
        ++rank;
      }
      const double variance_px = sigma_px * sigma_px;
      if (rank > 0) {
        result.systematic_chi_squared = statistic / variance_px;
        result.systematic_dof = rank;
        result.systematic_p_value =
            ChiSquaredUpperTail(result.systematic_chi_squared, rank);
        // (Exact data leave residuals of rounding, 1e-14 px, whose pattern
        // is no field: below kMinSystematicPx nothing is detected.)
        const double tau2 =
            std::max(0.0, (statistic - variance_px * rank) / a_cc.trace());
        if (result.systematic_p_value < FrameConsistency::kInflationP &&
            tau2 > kMinSystematicPx * kMinSystematicPx) {
          result.systematic_detected_px = std::sqrt(tau2);
          systematic_variance = std::max(systematic_variance, tau2);
        }
      }
    }
  }
  for (int k = 0; k < layout.NumSystematic(); ++k) {
    calibration(layout.Systematic() + k, layout.Systematic() + k) =
        systematic_variance;
  }
  const double focal_variance =
      uncertainty.focal_drift_sigma * uncertainty.focal_drift_sigma;
  if (layout.focal) {
    // (CalibrationUncertainty::WithoutFocalDrift, in the layout's columns.)
    for (int c = 0; c < 2; ++c) {
      const int column = c == 0 ? layout.LeftLens() : layout.RightLens();
      const Eigen::Vector2d g =
          Eigen::Vector2d::Map(c == 0 ? layout.left_focal : layout.right_focal);
      calibration.block<2, 2>(column, column) -=
          focal_variance * g * g.transpose();
    }
  }

  const double m_nn = m(0, 0);
  if (!(m_nn > 0.0)) {
    return Status::Error("the correspondences carry no information on n");
  }
  for (int k = 0; k < 3; ++k) {
    result.dn_drotation[k] = -m(0, 1 + k) / m_nn;
    result.dn_dtranslation[k] = -m(0, 4 + k) / m_nn;
  }
  // Observability of w from the data alone.
  {
    const Eigen::Matrix4d joint = m.topLeftCorner<4, 4>();
    const Eigen::FullPivLU<Eigen::Matrix4d> lu(joint);
    if (lu.isInvertible()) {
      const double joint_nn = lu.inverse()(0, 0);
      const double ratio = 1.0 / (m_nn * joint_nn);  // 1 - R^2
      result.rotation_multiple_correlation =
          std::sqrt(std::clamp(1.0 - ratio, 0.0, 1.0));
      result.rotation_sigma_inflation =
          ratio > 0.0 ? 1.0 / std::sqrt(ratio) : INFINITY;
    } else {
      result.rotation_multiple_correlation = 1.0;
      result.rotation_sigma_inflation = INFINITY;
    }
  }

  // Estimated and held columns: x = (n, w when estimated, e when the
  // layout has the focal columns).
  std::vector<int> estimated = {0};
  std::vector<int> held;
  const bool rotation_estimated = mode != RotationMode::kHeld;
  for (int k = 1; k < size; ++k) {
    const bool estimated_column =
        (rotation_estimated && k <= 3) || (layout.focal && k >= layout.Focal());
    (estimated_column ? estimated : held).push_back(k);
  }
  const int focal_x =
      layout.focal ? static_cast<int>(estimated.size()) - 2 : -1;
  const int nx = static_cast<int>(estimated.size());
  const int np = static_cast<int>(held.size());
  const double variance = sigma_px * sigma_px;
  Eigen::MatrixXd a(nx, nx), b(nx, np), sigma_p(np, np);
  for (int r = 0; r < nx; ++r) {
    for (int c = 0; c < nx; ++c) a(r, c) = m(estimated[r], estimated[c]);
    for (int c = 0; c < np; ++c) b(r, c) = m(estimated[r], held[c]);
  }
  for (int r = 0; r < np; ++r) {
    for (int c = 0; c < np; ++c) sigma_p(r, c) = calibration(held[r], held[c]);
  }
  // With the rotation estimated under its prior, the prior's deviation
  // and the held parameters are jointly distributed: Sigma_pw, the held
  // columns' covariance with w (zero unless the extrinsics are correlated
  // with the lenses).
  Eigen::MatrixXd sigma_pw = Eigen::MatrixXd::Zero(np, 3);
  if (rotation_estimated) {
    for (int r = 0; r < np; ++r) {
      for (int k = 0; k < 3; ++k) sigma_pw(r, k) = calibration(held[r], 1 + k);
    }
  }
  // The rotation's prior P_w is its covariance given the held columns
  // (CalibrationUncertainty::RotationPriorCovariance); the rotation's
  // deviation from it has the marginal covariance Sigma_ww, so its share is
  // sigma^4 H'^-1 P_w Sigma_ww P_w H'^-1 (H'^-1 P_w H'^-1 when w is
  // uncorrelated with the held columns and the two are equal).
  Eigen::MatrixXd prior = Eigen::MatrixXd::Zero(nx, nx);
  Eigen::MatrixXd prior_spread = Eigen::MatrixXd::Zero(nx, nx);
  if (mode == RotationMode::kPrior) {
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(
        uncertainty.RotationPriorCovariance());
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) {
      return Status::Error(
          "the rotation prior is singular: give every axis a drift sigma > 0");
    }
    const Eigen::Matrix3d precision = ldlt.solve(Eigen::Matrix3d::Identity());
    prior.block<3, 3>(1, 1) = precision;
    prior_spread.block<3, 3>(1, 1) =
        precision * uncertainty.RotationCovariance() * precision;
  }
  Eigen::MatrixXd n_prior = Eigen::MatrixXd::Zero(nx, nx);
  if (n_prior_sigma > 0.0)
    n_prior(0, 0) = 1.0 / (n_prior_sigma * n_prior_sigma);
  prior += n_prior;
  prior_spread += n_prior;
  Eigen::MatrixXd focal_prior = Eigen::MatrixXd::Zero(nx, nx);
  if (layout.focal) {
    if (!(focal_variance > 0.0)) {
      return Status::Error("the focal scales need a focal drift prior > 0");
    }
    focal_prior.block<2, 2>(focal_x, focal_x) =
        Eigen::Matrix2d::Identity() / focal_variance;
  }
  prior += focal_prior;
  prior_spread += focal_prior;
  // In the sigma^2-scaled form, stable down to exact data (sigma = 0):
  // H' = sigma^2 H = A + sigma^2 P, S = H'^-1 B.
  const Eigen::MatrixXd h = a + variance * prior;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(h);
  if (!lu.isInvertible()) {
    return Status::Error(
        "the rotation correction cannot be separated from n with these "
        "correspondences (singular information); estimate n alone");
  }
  const Eigen::MatrixXd h_inverse = lu.inverse();
  const Eigen::MatrixXd noise = variance * h_inverse * a * h_inverse;
  const Eigen::MatrixXd from_prior =
      variance * variance * h_inverse * prior_spread * h_inverse;
  const Eigen::MatrixXd from_n_prior =
      variance * variance * h_inverse * n_prior * h_inverse;
  const Eigen::MatrixXd from_focal_prior =
      variance * variance * h_inverse * focal_prior * h_inverse;
  const Eigen::MatrixXd s = h_inverse * b;
  // The estimate's error is H'^-1 (B dp - sigma^2 P_w dw) for held
  // parameters off by dp and a rotation off its prior by dw (P_w the
  // rotation prior's rows of x), so beside the two independent shares
  //   from_held  = S Sigma_p S^T,
  //   from_prior = sigma^4 H'^-1 P_w Sigma_ww P_w^T H'^-1,
  // their correlation adds
  //   cross = -sigma^2 (S Sigma_pw P_w^T H'^-1 + its transpose).
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(nx, nx);
  if (mode == RotationMode::kPrior && !sigma_pw.isZero(0.0)) {
    const Eigen::MatrixXd p_w = prior.middleCols(1, 3);  // x = (n, w, ...)
    const Eigen::MatrixXd half =
        -variance * s * sigma_pw * p_w.transpose() * h_inverse;
    cross = half + half.transpose();
  }
  const Eigen::MatrixXd from_held = s * sigma_p * s.transpose() + cross;

  // The held parameters' share, split by kind for the report: rotation
  // (when held), translation, lenses, ports; cross-covariances between
  // kinds (a measured covariance of rotation with translation) go with the
  // translation, except the lenses' with the extrinsics, which go with the
  // lenses, and the ports' with the extrinsics and the lenses, which go with
  // the ports (so that a share is what its kind adds with its correlation,
  // negative when what was fitted with it cancels more than it adds).
  const int ports_column = layout.Ports();
  const int systematic = layout.Systematic();
  enum Group {
    kRotationGroup,
    kTranslationGroup,
    kLensGroup,
    kPortGroup,
    kSystematicGroup,
    kNumGroups
  };
  const auto group_of = [ports_column, systematic](int column) {
    return column <= 3             ? kRotationGroup
           : column <= 6           ? kTranslationGroup
           : column < ports_column ? kLensGroup
           : column < systematic   ? kPortGroup
                                   : kSystematicGroup;
  };
  double shares[kNumGroups] = {};
  for (int g = 0; g < kNumGroups; ++g) {
    Eigen::MatrixXd part = Eigen::MatrixXd::Zero(np, np);
    for (int r = 0; r < np; ++r) {
      for (int c = 0; c < np; ++c) {
        const int gr = group_of(held[r]);
        const int gc = group_of(held[c]);
        // The kind a cross term goes with: the later of lens and port.
        const int owner = std::max(gr, gc);
        const bool mine =
            (gr == g && gc == g) ||
            (gr != gc && owner == g && (g == kLensGroup || g == kPortGroup) &&
             owner < kSystematicGroup);
        if (mine) part(r, c) = sigma_p(r, c);
      }
    }
    shares[g] = (s.row(0) * part * s.row(0).transpose())(0, 0);
  }
  // The rotation prior's correlation with the held columns, by the kind of
  // the held column (the translation's by difference below).
  if (mode == RotationMode::kPrior && !sigma_pw.isZero(0.0)) {
    const Eigen::MatrixXd p_w = prior.middleCols(1, 3);
    for (const int g : {kLensGroup, kPortGroup}) {
      Eigen::MatrixXd part = Eigen::MatrixXd::Zero(np, 3);
      for (int r = 0; r < np; ++r) {
        if (group_of(held[r]) == g) part.row(r) = sigma_pw.row(r);
      }
      shares[g] += -2.0 * variance *
                   (s.row(0) * part * p_w.transpose() * h_inverse.col(0))(0, 0);
    }
  }
  result.variance_rotation = shares[kRotationGroup];
  result.variance_lenses = shares[kLensGroup];
  result.variance_ports = shares[kPortGroup];
  result.variance_systematic = shares[kSystematicGroup];
  result.variance_translation = from_held(0, 0) - shares[kRotationGroup] -
                                shares[kLensGroup] - shares[kPortGroup] -
                                shares[kSystematicGroup];
  result.variance_medium = from_n_prior(0, 0);
  result.variance_lenses += from_focal_prior(0, 0);
  result.variance_rotation +=
      from_prior(0, 0) - from_n_prior(0, 0) - from_focal_prior(0, 0);

  const double noise_variance = noise(0, 0) * noise_inflation * noise_inflation;
  const double calibration_variance = std::max(
      0.0, from_prior(0, 0) + from_held(0, 0) - result.variance_systematic);
  result.sigma_n_noise = std::sqrt(std::max(0.0, noise_variance));
  result.sigma_n_calibration = std::sqrt(calibration_variance);
  result.sigma_n_systematic =
      std::sqrt(std::max(0.0, result.variance_systematic));
  result.sigma_n =
      std::sqrt(std::max(0.0, noise_variance) + calibration_variance +
                std::max(0.0, result.variance_systematic));

  const Eigen::MatrixXd total =
      noise * noise_inflation * noise_inflation + from_prior + from_held;
  const auto correlation_with_n = [&total](int k) {
    const double denominator = std::sqrt(total(0, 0) * total(k, k));
    return denominator > 0.0 ? total(0, k) / denominator : 0.0;
  };
  if (rotation_estimated) {
    result.rotation_covariance = total.block<3, 3>(1, 1);
    for (int k = 0; k < 3; ++k) {
      result.rotation_correlation_with_n[k] = correlation_with_n(1 + k);
    }
  }
  if (layout.focal) {
    result.focal_estimated = true;
    result.focal_scale_covariance = total.block<2, 2>(focal_x, focal_x);
    for (int k = 0; k < 2; ++k) {
      result.focal_scale_correlation_with_n[k] =
          correlation_with_n(focal_x + k);
    }
  }
  return result;
}

}  // namespace rcm
