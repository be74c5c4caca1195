#include "rcm/calib/target_detector.h"

#include <glog/logging.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace rcm::calib {
namespace {

// Images smaller than this along a side hold no target worth detecting.
constexpr int kMinImageSide = 16;
// Kalibr's tags: a 2-bit black border around the 6 x 6 data bits.
constexpr int kAprilTagBorderBits = 2;
// ArUco's adaptive threshold offsets tried in turn for Kalibr's tags: a
// corner square joined to a tag at one threshold is apart at another (on
// renders, one pass finds ~85% of the tags, these two all).
constexpr double kAprilThresholdConstants[] = {7.0, 14.0};
constexpr double kAprilMinMarkerDistanceRate = 0.001;
constexpr double kAprilIgnoredMargin = 0.3;
constexpr int kAprilTagBits = 10;
// Half window of the tag corners' cornerSubPix as a fraction of the
// X-junction's reach: on renders 0.55-0.7 converge (measured), smaller
// windows miss contour corners that start 2-3 px off, larger ones reach
// the data bits.
constexpr double kAprilHalfWindowFraction = 0.6;
// The classic detector's corner refinement: half window [px] and stop
// criteria (as OpenCV's calibration sample).
constexpr int kClassicHalfWindow = 5;
// findChessboardCornersSB's corners refined again by cornerSubPix on each
// corner's own X-junction. SB's sub-pixel estimate is pulled towards the
// board's white margin at the pattern's border: on renders (rcm simulate,
// dataset rig, 40 mm squares, seed 1) the outer rows and columns came out
// 0.05-0.09 px outward (away from the pattern's centre) with the board at
// 0.6-0.9 m and 1.6-2 m, the interior corners unbiased (+-0.01 px). A board
// spread at its border looks like extra refraction: that seed's n came out
// 2.35e-3 high (1.05e-3 of it from its one view at 0.78 m). The window
// reaches this fraction of the corner's shortest edge to a grid neighbour,
// so it sees only the four squares of the junction (the outer squares of
// the pattern are whole squares: the margin beyond them is never reached),
// clamped to [2, 10] px; measured on those renders, 0.45-0.6 leave the
// border within 0.02 px, 0.75 reaches the next junctions on foreshortened
// boards and fails.
constexpr double kSbRefineHalfWindowFraction = 0.5;
constexpr int kSbRefineMinHalfWindow = 2;
constexpr int kSbRefineMaxHalfWindow = 10;
// cornerSubPix runs on the image smoothed by a Gaussian of this sigma [px]
// (symmetric about every corner, so it moves none): on the renders' sharp
// edges (a pixel box) cornerSubPix locks to the pixel grid, 0.09 px RMS
// against the truth without noise; smoothed by 1 px, 0.058 px (SB's own
// 0.035 px).
constexpr double kSbRefineSmoothingSigma = 1.0;
// Which refined corner is kept. A refinement that stays within
// kSbRefineMaxMovePx [px] of SB's corner is kept (as OpenCV's calibration
// sample trusts cornerSubPix). One that moves farther is checked by a
// second refinement from SB's corner with a window of half the size (at
// least 2 px): when the two land within kSbRefineAgreementPx of each other
// the corner is a fixed point of its X-junction and the refinement is kept
// (if it moved less than kSbRefineMaxJumpPx); else the smaller window's
// corner is kept if it stays within kSbRefineMaxMovePx of SB's; else the
// corner is dropped, as neither estimate can be trusted.
//  - Renders (Alphasense rig, boards at 0.3-0.55 m tilted up to 40
//    degrees, squares of 10-25 px; BoardWarpOnRenders): SB is off by
//    0.5-1.3 px on ~5 % of the corners, where both windows agree on the
//    junction. Keeping SB's corner there (the former rule) left the
//    corners at 0.13 px RMS against the truth (0.05 px without them), and
//    they read as a bowl of +0.050 +- 0.025 mm on a flat board; with this
//    rule +0.001 +- 0.011 mm.
//  - OpenCV's sample pairs (left01.jpg ...): 110 of 1404 corners move
//    0.5-4 px, all on the pattern's border, where the paper's edge cuts
//    the outer squares. 60 are fixed points and kept, 13 take the smaller
//    window's corner, 37 are dropped; the stereo RMS went from 0.2665 to
//    0.1894 px (OpenCvSampleStereo.*).
constexpr double kSbRefineMaxMovePx = 0.5;
constexpr double kSbRefineAgreementPx = 0.1;
constexpr double kSbRefineMaxJumpPx = 3.0;
// cornerSubPix on a ChArUco corner: the chessboard X-junction reaches
// (square - marker) / 2 from the corner (to the markers); the half window
// is this fraction of it in pixels, clamped to [2, 10].
constexpr double kCharucoHalfWindowFraction = 0.6;

using Corners = std::vector<cv::Point2f>;

// A detected chessboard: every corner of the cols x rows grid (row-major),
// and the ones the refinement dropped (kSbRefineMaxMovePx), which are left
// out of the observation.
struct Chessboard {
  Corners corners;
  std::vector<bool> dropped;
};

// cornerSubPix on every corner of a cols x rows grid (row-major), each with
// a window from its shortest edge to a grid neighbour (see
// kSbRefineHalfWindowFraction), kept, or dropped (NaN), by the rule of
// kSbRefineMaxMovePx; a dropped corner keeps SB's position (for the grid's
// ordering) and is marked in `dropped`.
void RefineOnJunctions(const cv::Mat& gray, const cv::Size& pattern,
                       Corners* corners, std::vector<bool>* dropped) {
  const int cols = pattern.width, rows = pattern.height;
  const Corners start = *corners;
  const cv::TermCriteria stop(cv::TermCriteria::EPS + cv::TermCriteria::COUNT,
                              40, 0.001);
  const auto refine = [&](const cv::Point2f& from, int half_window) {
    Corners corner = {from};
    cv::cornerSubPix(gray, corner, cv::Size(half_window, half_window),
                     cv::Size(-1, -1), stop);
    return corner[0];
  };
  const auto finite = [](const cv::Point2f& p) {
    return std::isfinite(p.x) && std::isfinite(p.y);
  };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int k = r * cols + c;
      double edge = std::numeric_limits<double>::infinity();
      const auto neighbour = [&](int r2, int c2) {
        if (r2 < 0 || r2 >= rows || c2 < 0 || c2 >= cols) return;
        edge = std::min(edge, static_cast<double>(
                                  cv::norm(start[k] - start[r2 * cols + c2])));
      };
      neighbour(r, c - 1);
      neighbour(r, c + 1);
      neighbour(r - 1, c);
      neighbour(r + 1, c);
      if (!std::isfinite(edge)) continue;
      const int half_window = std::clamp(
          static_cast<int>(std::lround(kSbRefineHalfWindowFraction * edge)),
          kSbRefineMinHalfWindow, kSbRefineMaxHalfWindow);
      const cv::Point2f refined = refine(start[k], half_window);
      if (!finite(refined)) continue;  // SB's corner
      const double move = cv::norm(refined - start[k]);
      if (move <= kSbRefineMaxMovePx) {
        (*corners)[k] = refined;
        continue;
      }
      const cv::Point2f check =
          refine(start[k], std::max(kSbRefineMinHalfWindow, half_window / 2));
      const bool fixed_point =
          finite(check) && cv::norm(check - refined) <= kSbRefineAgreementPx;
      if (fixed_point && move <= kSbRefineMaxJumpPx) {
        (*corners)[k] = refined;
      } else if (finite(check) &&
                 cv::norm(check - start[k]) <= kSbRefineMaxMovePx) {
        (*corners)[k] = check;
      } else {
        (*dropped)[k] = true;
      }
    }
  }
}

// `image` as 8-bit gray, or nullopt for an empty, tiny or non-8-bit image.
std::optional<cv::Mat> ToGray(const cv::Mat& image) {
  if (image.empty() || image.dims != 2 || image.depth() != CV_8U ||
      image.cols < kMinImageSide || image.rows < kMinImageSide) {
    return std::nullopt;
  }
  switch (image.channels()) {
    case 1:
      return image;
    case 3: {
      cv::Mat gray;
      cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
      return gray;
    }
    case 4: {
      cv::Mat gray;
      cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
      return gray;
    }
    default:
      return std::nullopt;
  }
}

// ---------------------------------------------------------------------------
// Checkerboard.

enum class ChessDetector { kSb, kClassic };

const char* DetectorName(ChessDetector detector) {
  return detector == ChessDetector::kSb ? "chessboard-sb"
                                        : "chessboard-classic";
}

// The detector's corners (row-major over patternSize (cols, rows)).
std::optional<Chessboard> FindChessboard(const cv::Mat& gray,
                                         const CalibrationTarget& target,
                                         ChessDetector detector) {
  const cv::Size pattern(target.cols, target.rows);
  Corners corners;
  std::vector<bool> dropped;
  try {
    if (detector == ChessDetector::kSb) {
      // SB's search is not monotone in its flags: on OpenCV's sample
      // left05.jpg EXHAUSTIVE | ACCURACY fails where ACCURACY alone
      // succeeds (and on left01.jpg EXHAUSTIVE alone fails). NORMALIZE_IMAGE
      // finds more boards but its corners are worse (the renders'
      // calibration went from 2e-4 to 2e-3 in f, OpenCV's sample pairs from
      // 0.2553 to 0.2707 px RMS), so it is the last resort. ACCURACY alone
      // goes first: it found all 26 boards of the sample pairs, at 0.25 s
      // per 640x480 image on one thread against 0.32 s for EXHAUSTIVE |
      // ACCURACY (which found 25), and the refined corners of the sample
      // came out bit-identical to those of the former order.
      bool found = false;
      for (const int flags :
           {static_cast<int>(cv::CALIB_CB_ACCURACY),
            cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY,
            cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE |
                cv::CALIB_CB_ACCURACY}) {
        if (cv::findChessboardCornersSB(gray, pattern, corners, flags)) {
          found = true;
          break;
        }
      }
      if (!found) {
        return std::nullopt;
      }
      if (static_cast<int>(corners.size()) == target.cols * target.rows) {
        cv::Mat smoothed;
        cv::GaussianBlur(gray, smoothed, cv::Size(0, 0),
                         kSbRefineSmoothingSigma);
        dropped.assign(corners.size(), false);
        RefineOnJunctions(smoothed, pattern, &corners, &dropped);
      }
    } else {
      if (!cv::findChessboardCorners(
              gray, pattern, corners,
              cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
        return std::nullopt;
      }
      cv::cornerSubPix(
          gray, corners, cv::Size(kClassicHalfWindow, kClassicHalfWindow),
          cv::Size(-1, -1),
          cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30,
                           0.01));
    }
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (static_cast<int>(corners.size()) != target.cols * target.rows) {
    return std::nullopt;
  }
  dropped.resize(corners.size(), false);
  return Chessboard{std::move(corners), std::move(dropped)};
}

// A relabelling of a cols x rows grid: label k takes the corner at
// source[k].
using GridOrder = std::vector<int>;

// The relabellings of the grid that keep its shape: the rotations (by 180
// degrees; by 90 too when square) and, when `mirrors`, the reflections.
std::vector<GridOrder> GridOrders(int cols, int rows, bool mirrors) {
  // Each maps the new label (r, c) to the old (r', c').
  using Map = std::pair<int, int> (*)(int r, int c, int cols, int rows);
  std::vector<Map> maps = {
      [](int r, int c, int, int) { return std::make_pair(r, c); },
      [](int r, int c, int cols, int rows) {
        return std::make_pair(rows - 1 - r, cols - 1 - c);
      }};
  if (cols == rows) {
    maps.push_back([](int r, int c, int cols, int) {
      return std::make_pair(c, cols - 1 - r);
    });
    maps.push_back([](int r, int c, int cols, int) {
      return std::make_pair(cols - 1 - c, r);
    });
  }
  if (mirrors) {
    maps.push_back([](int r, int c, int cols, int) {
      return std::make_pair(r, cols - 1 - c);
    });
    maps.push_back([](int r, int c, int, int rows) {
      return std::make_pair(rows - 1 - r, c);
    });
    if (cols == rows) {
      maps.push_back(
          [](int r, int c, int, int) { return std::make_pair(c, r); });
      maps.push_back([](int r, int c, int cols, int) {
        return std::make_pair(cols - 1 - c, cols - 1 - r);
      });
    }
  }
  std::vector<GridOrder> orders;
  for (const Map map : maps) {
    GridOrder order(static_cast<size_t>(cols) * rows);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const auto [old_r, old_c] = map(r, c, cols, rows);
        order[r * cols + c] = old_r * cols + old_c;
      }
    }
    orders.push_back(std::move(order));
  }
  return orders;
}

Chessboard Reorder(const Chessboard& board, const GridOrder& order) {
  Chessboard out{Corners(order.size()), std::vector<bool>(order.size())};
  for (size_t k = 0; k < order.size(); ++k) {
    out.corners[k] = board.corners[order[k]];
    out.dropped[k] = board.dropped[order[k]];
  }
  return out;
}

// The rotation of the grid whose corner 0 has the smallest x + y.
Chessboard Canonical(const Chessboard& board, const CalibrationTarget& target) {
  const Corners& corners = board.corners;
  const std::vector<GridOrder> orders =
      GridOrders(target.cols, target.rows, /*mirrors=*/false);
  const GridOrder* best = nullptr;
  float best_sum = std::numeric_limits<float>::infinity();
  for (const GridOrder& order : orders) {
    const cv::Point2f& first = corners[order[0]];
    if (first.x + first.y < best_sum) {
      best_sum = first.x + first.y;
      best = &order;
    }
  }
  return Reorder(board, *best);
}

TargetObservation ChessboardObservation(const Chessboard& board,
                                        ChessDetector detector) {
  const Corners& corners = board.corners;
  TargetObservation observation;
  observation.detector = DetectorName(detector);
  for (size_t k = 0; k < corners.size(); ++k) {
    if (board.dropped[k]) continue;
    observation.point_ids.push_back(static_cast<int>(k));
    observation.pixels.emplace_back(corners[k].x, corners[k].y);
  }
  return observation;
}

// The points centred on their centroid and scaled to unit RMS radius.
std::vector<Eigen::Vector2d> NormalizedLayout(const Corners& corners) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const cv::Point2f& p : corners) centroid += Eigen::Vector2d(p.x, p.y);
  centroid /= static_cast<double>(corners.size());
  std::vector<Eigen::Vector2d> layout;
  double sum_squares = 0.0;
  for (const cv::Point2f& p : corners) {
    layout.push_back(Eigen::Vector2d(p.x, p.y) - centroid);
    sum_squares += layout.back().squaredNorm();
  }
  const double rms = std::sqrt(sum_squares / corners.size());
  if (rms > 0.0) {
    for (Eigen::Vector2d& point : layout) point /= rms;
  }
  return layout;
}

double Mismatch(const std::vector<Eigen::Vector2d>& a,
                const std::vector<Eigen::Vector2d>& b) {
  double sum = 0.0;
  for (size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]).squaredNorm();
  return sum / static_cast<double>(a.size());
}

// ---------------------------------------------------------------------------
// ArUco based targets.

// cornerSubPix on the four corners of a Kalibr tag, each an X-junction of
// the tag's 2-bit border and a corner square, reaching min(2 bits, gap)
// from the corner; the window must stay inside it.
void RefineTagCorners(const cv::Mat& gray, const CalibrationTarget& target,
                      Corners* corners) {
  // Twice: the contour's corners can be a few pixels inside the tag, which
  // makes it look smaller than it is; the second pass sizes its window from
  // the first pass's corners.
  for (int pass = 0; pass < 2; ++pass) {
    double edge = 0.0;  // mean edge [px]
    for (int k = 0; k < 4; ++k) {
      edge += 0.25 * cv::norm((*corners)[k] - (*corners)[(k + 1) % 4]);
    }
    const double junction =
        std::min(static_cast<double>(kAprilTagBorderBits) / kAprilTagBits,
                 target.tag_spacing) *
        edge;
    const int half_window = std::clamp(
        static_cast<int>(std::lround(kAprilHalfWindowFraction * junction)), 2,
        10);
    cv::cornerSubPix(
        gray, *corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
        cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40,
                         0.01));
  }
}

std::optional<TargetObservation> DetectAprilGrid(
    const cv::Mat& gray, const CalibrationTarget& target,
    const TargetDetectorOptions& options) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  const int num_tags = target.cols * target.rows;
  TargetObservation observation;
  observation.detector = "aprilgrid";
  std::vector<bool> seen(num_tags, false);
  for (const double threshold_constant : kAprilThresholdConstants) {
    const cv::Ptr<cv::aruco::DetectorParameters> parameters =
        cv::aruco::DetectorParameters::create();
    parameters->markerBorderBits = kAprilTagBorderBits;
    parameters->adaptiveThreshConstant = threshold_constant;
    // Keep a tag's inner and outer contours both as candidates: the outer
    // one may be spoilt by a corner square joined to it.
    parameters->minMarkerDistanceRate = kAprilMinMarkerDistanceRate;
    parameters->perspectiveRemoveIgnoredMarginPerCell = kAprilIgnoredMargin;
    // Refined below, per tag.
    parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
    std::vector<Corners> markers;
    std::vector<int> ids;
    cv::aruco::detectMarkers(gray, dictionary, markers, ids, parameters);
    for (size_t m = 0; m < ids.size(); ++m) {
      const int id = ids[m];
      if (id < 0 || id >= num_tags || seen[id]) continue;
      seen[id] = true;
      RefineTagCorners(gray, target, &markers[m]);
      for (int k = 0; k < 4; ++k) {
        observation.point_ids.push_back(4 * id + (k ^ 1));
        observation.pixels.emplace_back(markers[m][k].x, markers[m][k].y);
      }
    }
  }
  if (observation.size() < 4 * options.min_aprilgrid_tags) return std::nullopt;
  return observation;
}

std::optional<TargetObservation> DetectCharuco(
    const cv::Mat& gray, const CalibrationTarget& target,
    const TargetDetectorOptions& options) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(
          FindArucoDictionary(target.dictionary)->opencv_id);
  const cv::Ptr<cv::aruco::CharucoBoard> board =
      cv::aruco::CharucoBoard::create(
          target.cols, target.rows, static_cast<float>(target.square_size),
          static_cast<float>(target.marker_size), dictionary);
  std::vector<Corners> markers;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dictionary, markers, ids,
                           cv::aruco::DetectorParameters::create());
  // Markers of the dictionary that are not on the board.
  const int num_markers = NumCharucoMarkers(target);
  std::vector<Corners> board_markers;
  std::vector<int> board_ids;
  for (size_t m = 0; m < ids.size(); ++m) {
    if (ids[m] < 0 || ids[m] >= num_markers) continue;
    board_markers.push_back(markers[m]);
    board_ids.push_back(ids[m]);
  }
  if (board_ids.empty()) return std::nullopt;
  Corners corners;
  std::vector<int> corner_ids;
  cv::aruco::interpolateCornersCharuco(board_markers, board_ids, gray, board,
                                       corners, corner_ids);
  if (static_cast<int>(corner_ids.size()) < options.min_charuco_corners) {
    return std::nullopt;
  }
  // OpenCV 4.6 leaves the interpolated corners ~0.5 px off on renders (its
  // refinement window is sized from the marker corners); refine them again
  // on their X-junctions, the window sized from the markers' edges.
  std::vector<double> edges;
  for (const Corners& marker : board_markers) {
    for (int k = 0; k < 4; ++k) {
      edges.push_back(cv::norm(marker[k] - marker[(k + 1) % 4]));
    }
  }
  std::nth_element(edges.begin(), edges.begin() + edges.size() / 2,
                   edges.end());
  const double square_px =
      edges[edges.size() / 2] * target.square_size / target.marker_size;
  const double junction_px = 0.5 * (target.square_size - target.marker_size) /
                             target.square_size * square_px;
  const int half_window = std::clamp(
      static_cast<int>(kCharucoHalfWindowFraction * junction_px), 2, 10);
  cv::cornerSubPix(
      gray, corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40,
                       0.001));
  TargetObservation observation;
  observation.detector = "charuco";
  for (size_t k = 0; k < corner_ids.size(); ++k) {
    observation.point_ids.push_back(corner_ids[k]);
    observation.pixels.emplace_back(corners[k].x, corners[k].y);
  }
  return observation;
}

// DetectTarget without the argument checks, for a gray image.
std::optional<TargetObservation> DetectInGray(
    const cv::Mat& gray, const CalibrationTarget& target,
    const TargetDetectorOptions& options) {
  try {
    switch (target.type) {
      case TargetType::kCheckerboard: {
        for (const ChessDetector detector :
             {ChessDetector::kSb, ChessDetector::kClassic}) {
          if (detector == ChessDetector::kClassic &&
              !options.chessboard_fallback) {
            break;
          }
          const std::optional<Chessboard> corners =
              FindChessboard(gray, target, detector);
          if (corners) {
            return ChessboardObservation(Canonical(*corners, target), detector);
          }
        }
        return std::nullopt;
      }
      case TargetType::kAprilGrid:
        return DetectAprilGrid(gray, target, options);
      case TargetType::kCharuco:
        return DetectCharuco(gray, target, options);
    }
  } catch (const std::exception&) {
    // cv::Exception from OpenCV on an input it does not handle.
  }
  return std::nullopt;
}

// Runs first() and second(), at once when num_threads >= 2.
template <typename First, typename Second>
void RunBoth(int num_threads, const First& first, const Second& second) {
  if (num_threads < 2) {
    first();
    second();
    return;
  }
  std::thread thread(second);
  first();
  thread.join();
}

// The pair's checkerboards; see the header.
void DetectChessboardPair(const std::optional<cv::Mat>& left,
                          const std::optional<cv::Mat>& right,
                          const CalibrationTarget& target,
                          const TargetDetectorOptions& options,
                          StereoView* view) {
  std::optional<Chessboard> corners[2];
  const std::optional<cv::Mat>* images[2] = {&left, &right};
  const auto run = [&](ChessDetector detector, std::optional<Chessboard>* out) {
    RunBoth(
        options.num_threads,
        [&] {
          if (*images[0])
            out[0] = FindChessboard(**images[0], target, detector);
        },
        [&] {
          if (*images[1])
            out[1] = FindChessboard(**images[1], target, detector);
        });
  };
  run(ChessDetector::kSb, corners);
  ChessDetector detector = ChessDetector::kSb;
  const auto count = [](const std::optional<Chessboard>* pair) {
    return static_cast<int>(pair[0].has_value()) +
           static_cast<int>(pair[1].has_value());
  };
  if (count(corners) < 2 && options.chessboard_fallback) {
    std::optional<Chessboard> classic[2];
    run(ChessDetector::kClassic, classic);
    if (count(classic) > count(corners)) {
      corners[0] = std::move(classic[0]);
      corners[1] = std::move(classic[1]);
      detector = ChessDetector::kClassic;
    }
  }
  if (corners[0]) {
    corners[0] = Canonical(*corners[0], target);
    view->left = ChessboardObservation(*corners[0], detector);
  }
  if (!corners[1]) return;
  if (!corners[0]) {
    view->right =
        ChessboardObservation(Canonical(*corners[1], target), detector);
    return;
  }
  // The right ordering whose layout best matches the left's.
  const std::vector<Eigen::Vector2d> left_layout =
      NormalizedLayout(corners[0]->corners);
  double best = std::numeric_limits<double>::infinity();
  double second = std::numeric_limits<double>::infinity();
  Chessboard best_corners;
  for (const GridOrder& order :
       GridOrders(target.cols, target.rows, /*mirrors=*/true)) {
    Chessboard candidate = Reorder(*corners[1], order);
    const double mismatch =
        Mismatch(left_layout, NormalizedLayout(candidate.corners));
    if (mismatch < best) {
      second = best;
      best = mismatch;
      best_corners = std::move(candidate);
    } else if (mismatch < second) {
      second = mismatch;
    }
  }
  if (best > options.chessboard_pair_max_mismatch ||
      best >= options.chessboard_pair_max_ratio * second) {
    std::ostringstream note;
    note.precision(3);
    note << "right chessboard order ambiguous (layout mismatch " << best
         << ", next " << second << "); right view dropped";
    view->note = note.str();
    return;
  }
  view->right = ChessboardObservation(best_corners, detector);
}

}  // namespace

Status TargetDetectorOptions::Check() const {
  std::ostringstream message;
  if (min_charuco_corners < 4) {
    message << "min_charuco_corners = " << min_charuco_corners
            << " must be >= 4";
  } else if (min_aprilgrid_tags < 1) {
    message << "min_aprilgrid_tags = " << min_aprilgrid_tags << " must be >= 1";
  } else if (!(chessboard_pair_max_ratio > 0.0 &&
               chessboard_pair_max_ratio < 1.0)) {
    message << "chessboard_pair_max_ratio = " << chessboard_pair_max_ratio
            << " must be in (0, 1)";
  } else if (!(chessboard_pair_max_mismatch > 0.0 &&
               std::isfinite(chessboard_pair_max_mismatch))) {
    message << "chessboard_pair_max_mismatch = " << chessboard_pair_max_mismatch
            << " must be positive and finite";
  } else if (num_threads < 1) {
    message << "num_threads = " << num_threads << " must be >= 1";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

std::optional<TargetObservation> DetectTarget(
    const cv::Mat& image, const CalibrationTarget& target,
    const TargetDetectorOptions& options) {
  const Status valid = options.Check();
  CHECK(valid.ok()) << "TargetDetectorOptions: " << valid.message();
  NumTargetPoints(target);  // CHECKs that the target is valid
  const std::optional<cv::Mat> gray = ToGray(image);
  if (!gray) return std::nullopt;
  return DetectInGray(*gray, target, options);
}

StereoView DetectTargetPair(const cv::Mat& left, const cv::Mat& right,
                            const CalibrationTarget& target,
                            const TargetDetectorOptions& options) {
  const Status valid = options.Check();
  CHECK(valid.ok()) << "TargetDetectorOptions: " << valid.message();
  NumTargetPoints(target);  // CHECKs that the target is valid
  StereoView view;
  const std::optional<cv::Mat> left_gray = ToGray(left);
  const std::optional<cv::Mat> right_gray = ToGray(right);
  if (target.type == TargetType::kCheckerboard) {
    DetectChessboardPair(left_gray, right_gray, target, options, &view);
  } else {
    RunBoth(
        options.num_threads,
        [&] {
          if (left_gray) view.left = DetectInGray(*left_gray, target, options);
        },
        [&] {
          if (right_gray) {
            view.right = DetectInGray(*right_gray, target, options);
          }
        });
  }
  NoteMissingTargets(&view);
  return view;
}

void NoteMissingTargets(StereoView* view) {
  if (!view->note.empty()) return;
  if (!view->left && !view->right) {
    view->note = "board found in neither image";
  } else if (!view->right) {
    view->note = "board found in the left image only";
  } else if (!view->left) {
    view->note = "board found in the right image only";
  }
}

}  // namespace rcm::calib
