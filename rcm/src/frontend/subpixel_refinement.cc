#include "rcm/frontend/subpixel_refinement.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

// Parameters of the affine warp W(w) = x_r + t + (I + D) w: t (2) and D
// row-major (4).
constexpr int kNumParameters = 6;
// Translation steps below this start the affine iterations.
constexpr double kAffineFromStepPx = 0.1;
using Vector6 = Eigen::Matrix<double, kNumParameters, 1>;
using Matrix6 = Eigen::Matrix<double, kNumParameters, kNumParameters>;

// Bilinear interpolation of a CV_32F image; (x, y) must lie at least one
// pixel inside the last row and column (so that they are positive, and
// truncation is their floor).
inline float Bilinear(const cv::Mat& image, float x, float y) {
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const float ax = x - x0;
  const float ay = y - y0;
  const float* row0 = image.ptr<float>(y0) + x0;
  const float* row1 = image.ptr<float>(y0 + 1) + x0;
  return (1.0f - ay) * ((1.0f - ax) * row0[0] + ax * row0[1]) +
         ay * ((1.0f - ax) * row1[0] + ax * row1[1]);
}

inline bool Inside(const cv::Mat& image, double x, double y) {
  return x >= 1.0 && y >= 1.0 && x < image.cols - 2 && y < image.rows - 2;
}

// Per thread: the template window, its gradients and the warped patch,
// and the window's offsets and the warped samples' positions and corners
// (WarpPatch); sized by Resize, which allocates only when the window grows.
struct Buffers {
  std::vector<float> patch;
  std::vector<float> dx;
  std::vector<float> dy;
  std::vector<float> warped;
  std::vector<double> u;
  std::vector<double> v;
  std::vector<float> x;
  std::vector<float> y;
  std::vector<int> x0;
  std::vector<int> y0;
  std::vector<float> top_left, top_right, bottom_left, bottom_right;

  // For a window of (2 half + 1)^2 pixels, in row-major order.
  void Resize(int half) {
    const int side = 2 * half + 1;
    const size_t size = static_cast<size_t>(side) * side;
    for (std::vector<float>* values :
         {&patch, &dx, &dy, &warped, &x, &y, &top_left, &top_right,
          &bottom_left, &bottom_right}) {
      values->resize(size);
    }
    x0.resize(size);
    y0.resize(size);
    if (u.size() == size) return;  // the offsets of this window already
    u.resize(size);
    v.resize(size);
    for (int row = -half, k = 0; row <= half; ++row) {
      for (int column = -half; column <= half; ++column, ++k) {
        u[k] = column;
        v[k] = row;
      }
    }
  }
};

// buffers->warped[k] = Bilinear(image, W (u_k, v_k)) for the window's
// offsets (u_k, v_k) under the affine warp W, row by row of the window in
// the template's order: the same arithmetic as Bilinear per sample, in
// passes over arrays that the compiler vectorizes (only the four pixel
// reads of each sample stay scalar). The warp must keep every sample at
// least one pixel inside the image (positive coordinates).
void WarpPatch(const cv::Mat& image, const Eigen::Matrix3d& warp, int size,
               Buffers* buffers) {
  const double w00 = warp(0, 0), w01 = warp(0, 1), w02 = warp(0, 2);
  const double w10 = warp(1, 0), w11 = warp(1, 1), w12 = warp(1, 2);
  const double* u = buffers->u.data();
  const double* v = buffers->v.data();
  float* x = buffers->x.data();
  float* y = buffers->y.data();
  for (int k = 0; k < size; ++k) {
    x[k] = static_cast<float>(w00 * u[k] + w01 * v[k] + w02);
    y[k] = static_cast<float>(w10 * u[k] + w11 * v[k] + w12);
  }
  int* x0 = buffers->x0.data();
  int* y0 = buffers->y0.data();
  for (int k = 0; k < size; ++k) {
    x0[k] = static_cast<int>(x[k]);
    y0[k] = static_cast<int>(y[k]);
  }
  float* a = buffers->top_left.data();
  float* b = buffers->top_right.data();
  float* c = buffers->bottom_left.data();
  float* d = buffers->bottom_right.data();
  for (int k = 0; k < size; ++k) {
    const float* row0 = image.ptr<float>(y0[k]) + x0[k];
    const float* row1 = image.ptr<float>(y0[k] + 1) + x0[k];
    a[k] = row0[0];
    b[k] = row0[1];
    c[k] = row1[0];
    d[k] = row1[1];
  }
  float* warped = buffers->warped.data();
  for (int k = 0; k < size; ++k) {
    const float ax = x[k] - x0[k];
    const float ay = y[k] - y0[k];
    warped[k] = (1.0f - ay) * ((1.0f - ax) * a[k] + ax * b[k]) +
                ay * ((1.0f - ax) * c[k] + ax * d[k]);
  }
}

// Mean and standard deviation of a patch.
void MeanAndDeviation(const std::vector<float>& values, double* mean,
                      double* deviation) {
  double sum = 0.0;
  double sum_squares = 0.0;
  for (const float value : values) {
    sum += value;
    sum_squares += static_cast<double>(value) * value;
  }
  *mean = sum / values.size();
  *deviation =
      std::sqrt(std::max(0.0, sum_squares / values.size() - *mean * *mean));
}

// Inverse compositional Gauss-Newton (Baker and Matthews 2004) for the
// affine warp: the template's steepest-descent images and Hessian are
// computed once; each iteration samples the right image under the current
// warp, normalizes it to the template's mean and contrast (gain and bias,
// solved in closed form), and composes the warp with the inverse of the
// step. False when the fit fails (see the header).
// The left image and its gradients (central differences, the derivative
// of the bilinear interpolant at the pixel centers), as float.
struct LeftImage {
  cv::Mat image;
  cv::Mat dx;
  cv::Mat dy;
};

bool RefineOne(const LeftImage& left_image, const cv::Mat& right,
               const cv::Point2f& left_pixel, cv::Point2f* right_pixel,
               const SubpixelOptions& options, Buffers* buffers) {
  const cv::Mat& left = left_image.image;
  const int half = options.window / 2;
  const int size = options.window * options.window;
  if (!Inside(left, left_pixel.x - half - 1, left_pixel.y - half - 1) ||
      !Inside(left, left_pixel.x + half + 1, left_pixel.y + half + 1)) {
    return false;
  }
  buffers->Resize(half);
  Matrix6 hessian = Matrix6::Zero();
  for (int v = -half, k = 0; v <= half; ++v) {
    for (int u = -half; u <= half; ++u, ++k) {
      const float x = left_pixel.x + u;
      const float y = left_pixel.y + v;
      buffers->patch[k] = Bilinear(left, x, y);
      buffers->dx[k] = Bilinear(left_image.dx, x, y);
      buffers->dy[k] = Bilinear(left_image.dy, x, y);
      // H += d d^T on the upper triangle, written out (Eigen's rankUpdate
      // of a 6-vector goes through its general product kernel).
      const double descent[kNumParameters] = {
          buffers->dx[k],     buffers->dy[k],     buffers->dx[k] * u,
          buffers->dx[k] * v, buffers->dy[k] * u, buffers->dy[k] * v};
      for (int j = 0; j < kNumParameters; ++j) {
        for (int i = 0; i <= j; ++i) hessian(i, j) += descent[j] * descent[i];
      }
    }
  }
  double template_mean = 0.0;
  double template_deviation = 0.0;
  if (options.normalize_exposure) {
    MeanAndDeviation(buffers->patch, &template_mean, &template_deviation);
  }
  // Texture: the weaker eigenvalue of the translation block (Shi-Tomasi),
  // per pixel of the window.
  const Eigen::Matrix2d translation_block =
      hessian.topLeftCorner<2, 2>().selfadjointView<Eigen::Upper>();
  const double weakest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                             translation_block, Eigen::EigenvaluesOnly)
                             .eigenvalues()[0] /
                         size;
  if (!(weakest >= options.min_texture)) return false;
  const Eigen::LDLT<Matrix6> solver(hessian.selfadjointView<Eigen::Upper>());
  const Eigen::LDLT<Eigen::Matrix2d> translation_solver(translation_block);
  if (solver.info() != Eigen::Success || !solver.isPositive()) return false;
  // Warp as a 2x3 matrix [I + D | x_r + t].
  Eigen::Matrix3d warp = Eigen::Matrix3d::Identity();
  warp(0, 2) = right_pixel->x;
  warp(1, 2) = right_pixel->y;
  bool converged = false;
  bool affine = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    for (const int su : {-half, half}) {
      for (const int sv : {-half, half}) {
        const Eigen::Vector3d corner = warp * Eigen::Vector3d(su, sv, 1.0);
        if (!Inside(right, corner.x(), corner.y())) return false;
      }
    }
    WarpPatch(right, warp, size, buffers);
    // Exposure: error = gain * warped + offset - template, the identity
    // unless normalize_exposure matches mean and contrast.
    double gain = 1.0;
    double offset = 0.0;
    if (options.normalize_exposure) {
      double mean = 0.0;
      double deviation = 0.0;
      MeanAndDeviation(buffers->warped, &mean, &deviation);
      if (!(deviation > 0.0)) return false;
      gain = template_deviation / deviation;
      offset = template_mean - gain * mean;
    }
    // The translation's two sums alone until the warp is fitted.
    Vector6 gradient = Vector6::Zero();
    if (affine) {
      for (int v = -half, k = 0; v <= half; ++v) {
        for (int u = -half; u <= half; ++u, ++k) {
          const double error =
              gain * buffers->warped[k] + offset - buffers->patch[k];
          const double ex = buffers->dx[k] * error;
          const double ey = buffers->dy[k] * error;
          gradient[0] += ex;
          gradient[1] += ey;
          gradient[2] += ex * u;
          gradient[3] += ex * v;
          gradient[4] += ey * u;
          gradient[5] += ey * v;
        }
      }
    } else {
      double gx = 0.0;
      double gy = 0.0;
      for (int k = 0; k < size; ++k) {
        const double error =
            gain * buffers->warped[k] + offset - buffers->patch[k];
        gx += buffers->dx[k] * error;
        gy += buffers->dy[k] * error;
      }
      gradient[0] = gx;
      gradient[1] = gy;
    }
    // Translation alone until it is within a tenth of a pixel (the affine
    // terms are poorly determined far from the optimum), then the warp.
    Vector6 step = Vector6::Zero();
    if (!affine) {
      step.head<2>() = translation_solver.solve(gradient.head<2>());
      if (std::hypot(step[0], step[1]) < kAffineFromStepPx) {
        affine = options.affine;
        if (!affine && std::hypot(step[0], step[1]) < options.min_step_px) {
          converged = true;
          break;
        }
      }
    } else {
      step = solver.solve(gradient);
    }
    if (!step.allFinite()) return false;
    Eigen::Matrix3d step_warp = Eigen::Matrix3d::Identity();
    step_warp(0, 0) += step[2];
    step_warp(0, 1) = step[3];
    step_warp(1, 0) = step[4];
    step_warp(1, 1) += step[5];
    step_warp(0, 2) = step[0];
    step_warp(1, 2) = step[1];
    warp = warp * step_warp.inverse();
    if (affine && std::hypot(step[0], step[1]) < options.min_step_px) {
      converged = true;
      break;
    }
  }
  if (!converged) return false;
  const double shift_x = warp(0, 2) - right_pixel->x;
  const double shift_y = warp(1, 2) - right_pixel->y;
  if (!(std::hypot(shift_x, shift_y) <= options.max_shift_px)) return false;
  if (!(std::abs(warp(0, 0) - 1.0) <= options.max_warp &&
        std::abs(warp(1, 1) - 1.0) <= options.max_warp &&
        std::abs(warp(0, 1)) <= options.max_warp &&
        std::abs(warp(1, 0)) <= options.max_warp)) {
    return false;
  }
  right_pixel->x = static_cast<float>(warp(0, 2));
  right_pixel->y = static_cast<float>(warp(1, 2));
  return true;
}

}  // namespace

Status SubpixelOptions::Check() const {
  if (window < 5 || window % 2 == 0) {
    return Status::Error("subpixel window must be odd and at least 5, got " +
                         std::to_string(window));
  }
  if (max_iterations < 1) {
    return Status::Error("subpixel refinement needs at least 1 iteration");
  }
  if (!(min_step_px > 0.0) || !(max_shift_px > 0.0) || !(max_warp > 0.0)) {
    return Status::Error(
        "subpixel step, shift and warp limits must be positive");
  }
  if (!(min_texture >= 0.0)) {
    return Status::Error("subpixel minimum texture must be >= 0");
  }
  if (num_threads < 1) {
    return Status::Error("threads must be at least 1, got " +
                         std::to_string(num_threads));
  }
  return Status::Ok();
}

void RefineRightPixels(const cv::Mat& left_gray, const cv::Mat& right_gray,
                       const std::vector<cv::Point2f>& left,
                       std::vector<cv::Point2f>* right,
                       std::vector<unsigned char>* kept,
                       const SubpixelOptions& options) {
  CHECK_EQ(left.size(), right->size());
  CHECK(options.Check().ok()) << options.Check().message();
  CHECK_EQ(left_gray.type(), CV_8UC1);
  CHECK_EQ(right_gray.type(), CV_8UC1);
  kept->assign(left.size(), 1);
  if (!options.enabled || left.empty()) return;
  LeftImage left_image;
  cv::Mat right_float;
  left_gray.convertTo(left_image.image, CV_32F);
  right_gray.convertTo(right_float, CV_32F);
  cv::Sobel(left_image.image, left_image.dx, CV_32F, 1, 0, 1, 0.5, 0.0,
            cv::BORDER_REPLICATE);
  cv::Sobel(left_image.image, left_image.dy, CV_32F, 0, 1, 1, 0.5, 0.0,
            cv::BORDER_REPLICATE);
  // About 20 us per match: below ~100 matches one thread is faster. The
  // matches go in chunks of 32 to whichever thread is free (the decoder of
  // the next pair shares the cores).
  constexpr int64_t kMinMatchesPerThread = 64;
  constexpr int64_t kMatchesPerChunk = 32;
  const int64_t count = static_cast<int64_t>(left.size());
  ParallelForChunks(count,
                    count >= 2 * kMinMatchesPerThread ? options.num_threads : 1,
                    kMatchesPerChunk, [&](int64_t begin, int64_t end) {
                      // Per thread, not per chunk: sized once.
                      thread_local Buffers buffers;
                      for (int64_t i = begin; i < end; ++i) {
                        cv::Point2f refined = (*right)[i];
                        if (RefineOne(left_image, right_float, left[i],
                                      &refined, options, &buffers)) {
                          (*right)[i] = refined;
                        } else {
                          (*kept)[i] = 0;
                        }
                      }
                    });
}

}  // namespace rcm
