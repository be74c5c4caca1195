#include "rcm/sim/sequence_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/scene_intersection.h"
#include "support/test_rigs.h"

namespace rcm::sequence_simulator_test {
namespace {

// Poses and matches only, no images: fast.
SequenceOptions MatchesOnly(std::vector<MediaSegment> media,
                            int matches_per_frame = 300) {
  SequenceOptions options;
  options.media = std::move(media);
  options.render_images = false;
  options.matches_per_frame = matches_per_frame;
  return options;
}

// Small, quick images: one ray per pixel.
SequenceOptions WithImages(int frames) {
  SequenceOptions options;
  options.media = {MediaSegment{1.333, frames}};
  options.render.supersampling = 1;
  options.matches_per_frame = 100;
  return options;
}

TEST(SequenceSimulator, ThinPortMatchesGiveEachFramesIndexExactly) {
  // Thin port: the scene matches obey the paper's model, so the refinement
  // returns each frame's medium to 1e-9 (air, water, a denser liquid).
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig,
                                MatchesOnly({{1.0, 1}, {1.333, 1}, {1.6, 1}}))
          .value();
  ASSERT_EQ(simulator->num_frames(), 3);
  for (int i = 0; i < 3; ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    EXPECT_EQ(frame.matches.size(), 300u);
    EXPECT_TRUE(frame.left.empty());
    for (const StereoCorrespondence& match : frame.matches) {
      EXPECT_EQ(match.frame, i);
      EXPECT_EQ(match.timestamp.value(), frame.t);
      EXPECT_TRUE(rig.left().InImage(match.left_pixel));
      EXPECT_TRUE(rig.right().InImage(match.right_pixel));
    }
    const RefinementSummary summary =
        RefineRefractiveIndex(rig, frame.matches, RefinementOptions()).value();
    EXPECT_NEAR(summary.n, frame.n, 1e-9) << "frame " << i;
  }
}

TEST(SequenceSimulator, ScenePointsAreInTheTank) {
  // The matches come from a pool seen 16 degrees down from 1.2 m: depths
  // are bounded by the tank's size (12 x 8 x 3 m).
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(AlphasenseFrontRectifiedRig(),
                                MatchesOnly({{1.333, 2}}))
          .value();
  const TankScene& scene = simulator->scene();
  for (const TimedPose& pose : simulator->poses()) {
    EXPECT_TRUE(scene.Contains(pose.world_from_cam0.translation, 0.5));
  }
  const double diagonal =
      std::hypot(scene.length(), scene.width(), scene.depth());
  EXPECT_LT(diagonal, 15.0);
}

TEST(SequenceSimulator, NoiseAndOutliersAreApplied) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  SequenceOptions exact_options = MatchesOnly({{1.333, 1}}, 400);
  SequenceOptions noisy_options = exact_options;
  noisy_options.match_noise_px = 0.5;
  noisy_options.outlier_fraction = 0.25;
  const SequenceFrame exact =
      SequenceSimulator::Create(rig, exact_options).value()->Frame(0).value();
  const SequenceFrame noisy =
      SequenceSimulator::Create(rig, noisy_options).value()->Frame(0).value();
  ASSERT_EQ(exact.matches.size(), noisy.matches.size());
  EXPECT_EQ(noisy.outlier_indices.size(), 100u);
  // The left pixels differ by the noise alone: its RMS per coordinate is
  // 0.5 px within 4 standard errors (0.5 / sqrt(2 * 800) * 4 = 0.05).
  double sum_squares = 0.0;
  for (size_t i = 0; i < exact.matches.size(); ++i) {
    sum_squares += (noisy.matches[i].left_pixel - exact.matches[i].left_pixel)
                       .squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(sum_squares / (2.0 * exact.matches.size())), 0.5, 0.05);
}

TEST(SequenceSimulator, SameSeedSameFrames) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  SequenceOptions options = WithImages(1);
  options.seed = 7;
  const SequenceFrame a =
      SequenceSimulator::Create(rig, options).value()->Frame(0).value();
  const SequenceFrame b =
      SequenceSimulator::Create(rig, options).value()->Frame(0).value();
  ASSERT_EQ(a.left.size(), cv::Size(720, 540));
  ASSERT_EQ(a.left.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);
  ASSERT_EQ(a.matches.size(), b.matches.size());
  for (size_t i = 0; i < a.matches.size(); ++i) {
    EXPECT_EQ(a.matches[i].left_pixel, b.matches[i].left_pixel);
    EXPECT_EQ(a.matches[i].right_pixel, b.matches[i].right_pixel);
  }
  options.seed = 8;
  const SequenceFrame c =
      SequenceSimulator::Create(rig, options).value()->Frame(0).value();
  EXPECT_GT(cv::norm(a.left, c.left, cv::NORM_L1), 0.0);
}

TEST(SequenceSimulator, MatchesLandOnTheSameTextureInBothImages) {
  // The matches are consistent with the rendered images: 11x11 patches
  // around the two pixels of a match correlate (thick tilted port, so the
  // renderer's and the sampler's ports must agree exactly).
  SequenceOptions options = WithImages(1);
  options.left_port.air_gap = 0.01;
  options.left_port.glass_thickness = 0.006;
  options.right_port = options.left_port;
  const SequenceFrame frame =
      SequenceSimulator::Create(AlphasenseFrontUnrectifiedRig(), options)
          .value()
          ->Frame(0)
          .value();
  std::vector<double> correlations;
  constexpr int kHalf = 5;
  for (const StereoCorrespondence& match : frame.matches) {
    const cv::Point l(std::lround(match.left_pixel.x()),
                      std::lround(match.left_pixel.y()));
    const cv::Point r(std::lround(match.right_pixel.x()),
                      std::lround(match.right_pixel.y()));
    const cv::Rect inner(kHalf, kHalf, 720 - 2 * kHalf, 540 - 2 * kHalf);
    if (!inner.contains(l) || !inner.contains(r)) continue;
    cv::Mat result;
    cv::matchTemplate(frame.left(cv::Rect(l.x - kHalf, l.y - kHalf,
                                          2 * kHalf + 1, 2 * kHalf + 1)),
                      frame.right(cv::Rect(r.x - kHalf, r.y - kHalf,
                                           2 * kHalf + 1, 2 * kHalf + 1)),
                      result, cv::TM_CCOEFF_NORMED);
    correlations.push_back(result.at<float>(0, 0));
  }
  ASSERT_GT(correlations.size(), 50u);
  std::sort(correlations.begin(), correlations.end());
  // Median well above what unrelated patches give (~0).
  EXPECT_GT(correlations[correlations.size() / 2], 0.8);
}

TEST(SequenceSimulator, DepthRangeMatchesAreAtTheRequestedDepths) {
  // Through a thick port the two rays of a match meet (to ~1e-11 m, the
  // lens round trip) at a point whose depth Z lies in the range.
  constexpr double kRayDistanceTolerance = 1e-9;  // meters
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  SequenceOptions options = MatchesOnly({{1.333, 1}, {1.0, 1}}, 100);
  options.left_port.air_gap = 0.01;
  options.left_port.glass_thickness = 0.005;
  options.right_port = options.left_port;
  options.match_min_depth = 0.4;
  options.match_max_depth = 1.2;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  for (int i = 0; i < 2; ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    ASSERT_EQ(frame.matches.size(), 100u);
    const FlatPortCamera left =
        FlatPortCamera::Create(rig.left(), options.left_port, frame.n).value();
    const FlatPortCamera right =
        FlatPortCamera::Create(rig.right(), options.right_port, frame.n)
            .value();
    const Rigid3d left_from_right = rig.right_from_left().Inverse();
    for (const StereoCorrespondence& match : frame.matches) {
      EXPECT_EQ(match.frame, i);
      const RayInMedium l = left.RayFromImage(match.left_pixel).value();
      const RayInMedium r = right.RayFromImage(match.right_pixel).value();
      const Eigen::Vector3d r_origin = left_from_right * r.origin;
      const Eigen::Vector3d r_direction =
          left_from_right.rotation * r.direction;
      // Closest points of the two lines.
      const Eigen::Vector3d w = l.origin - r_origin;
      const double b = l.direction.dot(r_direction);
      const double d = l.direction.dot(w);
      const double e = r_direction.dot(w);
      const double s = (b * e - d) / (1.0 - b * b);
      const double t = (e - b * d) / (1.0 - b * b);
      const Eigen::Vector3d on_left = l.origin + s * l.direction;
      const Eigen::Vector3d on_right = r_origin + t * r_direction;
      EXPECT_LT((on_left - on_right).norm(), kRayDistanceTolerance);
      EXPECT_GE(on_left.z(), 0.4 - 1e-9);
      EXPECT_LE(on_left.z(), 1.2 + 1e-9);
    }
  }
  options.render_images = true;
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
  options.render_images = false;
  options.match_max_depth = 0.2;
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
}

TEST(SequenceSimulator, RejectsInvalidOptions) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  SequenceOptions options = MatchesOnly({{2.5, 3}});
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
  options = MatchesOnly({{1.333, 3}});
  options.matches_per_frame = -1;
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
  options = MatchesOnly({{1.333, 3}});
  options.outlier_fraction = 1.5;
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
  options = MatchesOnly({{1.333, 3}});
  options.left_port.air_gap = -0.01;
  const StatusOr<std::unique_ptr<SequenceSimulator>> bad_port =
      SequenceSimulator::Create(rig, options);
  ASSERT_FALSE(bad_port.ok());
  EXPECT_NE(bad_port.status().message().find("left port"), std::string::npos);
}

TEST(SequenceSimulator, DriftMovesTheRigThatMakesTheDataOnly) {
  // The housing drifted by 0.5 degrees: the data are those of the moved
  // rig (thin port, exact: it returns n to 1e-9), while rig() stays the
  // calibration, on which the same matches give a confidently wrong n
  // (docs/design.md, "Rigs that drift"; 1.77 for the true 1.34).
  const StereoRig rig = NarrowFieldRig();
  SequenceOptions options = MatchesOnly({{1.34, 20}});
  options.cam1_drift.rotation = Eigen::Vector3d(0.0, 0.5, 0.0) * M_PI / 180.0;
  options.cam1_drift.translation = Eigen::Vector3d(0.5e-3, 0.0, 0.0);
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  const StereoRig moved = rig.WithCam1Moved(options.cam1_drift.rotation,
                                            options.cam1_drift.translation)
                              .value();
  EXPECT_EQ(simulator->rig().right_from_left().ToMatrix(),
            rig.right_from_left().ToMatrix());
  EXPECT_EQ(simulator->true_rig().right_from_left().ToMatrix(),
            moved.right_from_left().ToMatrix());
  std::vector<StereoCorrespondence> matches;
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    matches.insert(matches.end(), frame.matches.begin(), frame.matches.end());
  }
  ASSERT_EQ(matches.size(), 6000u);
  EXPECT_NEAR(
      RefineRefractiveIndex(moved, matches, RefinementOptions()).value().n,
      1.34, 1e-9);
  const RefinementSummary calibrated =
      RefineRefractiveIndex(rig, matches, RefinementOptions()).value();
  EXPECT_GT(calibrated.n - 1.34, 0.2);
  EXPECT_LT(calibrated.sigma_n, 0.05);
  // No drift: the rig as given, bit for bit.
  const std::unique_ptr<SequenceSimulator> still =
      SequenceSimulator::Create(rig, MatchesOnly({{1.34, 1}})).value();
  EXPECT_EQ(still->true_rig().right_from_left().ToMatrix(),
            rig.right_from_left().ToMatrix());
  // Too much drift is refused.
  options.cam1_drift.rotation = Eigen::Vector3d(0.0, 11.0, 0.0) * M_PI / 180.0;
  const Status refused = SequenceSimulator::Create(rig, options).status();
  EXPECT_NE(refused.message().find("above 10 deg"), std::string::npos)
      << refused.message();
  options.cam1_drift.rotation = Eigen::Vector3d(0.0, NAN, 0.0);
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
}

// Lenses that changed since the air calibration: the data are those of
// the changed focal lengths (exact: the changed rig returns n to 1e-9), the
// calibration's stay; and on it a 0.5 % longer focal length in both
// cameras moves n by about as much (a flat port scales the paraxial focal
// length by n).
// Cameras not triggered together (exposure_delay.h): on the tank's
// surfaces too the right pixels see the scene moved during the delay and
// the left ones are the synchronized run's (but for points whose moved
// right pixel left the image); the frames then disagree beyond their
// noise, which the refinement's consistency test measures. The sampler's
// test checks the motion itself to 1e-9 (exposure_delay_test.cc).
// 10 ms between the exposures of a rig turning at 20 deg/s and moving at
// 0.2 m/s: the right pixels move by pixels.
ExposureDelay FastHandHeld() {
  ExposureDelay delay;
  delay.delay = 0.010;
  delay.angular_speed_sd = 20.0 * M_PI / 180.0;
  delay.speed_sd = 0.2;
  return delay;
}

TEST(SequenceSimulator, ExposureDelayMovesTheRightPixelsOfTheScene) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  SequenceOptions options = MatchesOnly({{1.333, 6}}, 150);
  std::unique_ptr<SequenceSimulator> synchronized =
      SequenceSimulator::Create(rig, options).value();
  options.exposure_delay = FastHandHeld();
  std::unique_ptr<SequenceSimulator> delayed =
      SequenceSimulator::Create(rig, options).value();
  std::vector<StereoCorrespondence> all;
  int shared = 0;
  int total = 0;
  for (int f = 0; f < 6; ++f) {
    const SequenceFrame a = synchronized->Frame(f).value();
    const SequenceFrame b = delayed->Frame(f).value();
    for (const StereoCorrespondence& match : b.matches) {
      ++total;
      for (const StereoCorrespondence& other : a.matches) {
        if (other.left_pixel == match.left_pixel) {
          ++shared;
          EXPECT_NE(other.right_pixel, match.right_pixel);
          break;
        }
      }
    }
    all.insert(all.end(), b.matches.begin(), b.matches.end());
  }
  EXPECT_GE(shared, 0.9 * total);
  const RefinementSummary summary =
      RefineRefractiveIndex(rig, all, RefinementOptions()).value();
  ASSERT_TRUE(summary.consistency.has_value());
  EXPECT_GT(summary.consistency->inflation, 1.0);
}

// The images under an exposure delay: the left image is the synchronized
// run's, byte for byte; the right image is, byte for byte, that of a
// synchronized run on the rig whose cam1 is where the delay put it for
// that frame (RightFromLeftOfFrame), and differs from the synchronized
// right image.
TEST(SequenceSimulator, ExposureDelayRendersTheRightImageWhereCam1Was) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  SequenceOptions options = WithImages(2);
  options.matches_per_frame = 0;
  std::unique_ptr<SequenceSimulator> synchronized =
      SequenceSimulator::Create(rig, options).value();
  options.exposure_delay = FastHandHeld();
  std::unique_ptr<SequenceSimulator> delayed =
      SequenceSimulator::Create(rig, options).value();
  const auto same = [](const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() &&
           cv::countNonZero(a != b) == 0;
  };
  for (int f = 0; f < 2; ++f) {
    SCOPED_TRACE(f);
    const SequenceFrame a = synchronized->Frame(f).value();
    const SequenceFrame b = delayed->Frame(f).value();
    EXPECT_TRUE(same(a.left, b.left));
    EXPECT_FALSE(same(a.right, b.right));
    SequenceOptions moved_options = options;
    moved_options.exposure_delay = ExposureDelay();
    const StereoRig moved = StereoRig::Create(rig.left(), rig.right(),
                                              delayed->RightFromLeftOfFrame(f))
                                .value();
    std::unique_ptr<SequenceSimulator> at_exposure =
        SequenceSimulator::Create(moved, moved_options).value();
    EXPECT_TRUE(same(at_exposure->Frame(f).value().right, b.right));
  }
  EXPECT_EQ(synchronized->RightFromLeftOfFrame(1).ToMatrix(),
            rig.right_from_left().ToMatrix());
}

TEST(SequenceSimulator, LensChangeScalesTheFocalLengthsOfTheDataOnly) {
  const StereoRig rig = NarrowFieldRig();
  SequenceOptions options = MatchesOnly({{1.34, 20}});
  options.lens_change.focal_scale = {0.005, 0.005};
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  for (const auto& [calibrated, changed] :
       {std::pair{&simulator->rig().left(), &simulator->true_rig().left()},
        std::pair{&simulator->rig().right(), &simulator->true_rig().right()}}) {
    EXPECT_EQ(changed->fx(), calibrated->fx() * 1.005);
    EXPECT_EQ(changed->fy(), calibrated->fy() * 1.005);
    EXPECT_EQ(changed->cx(), calibrated->cx());
  }
  std::vector<StereoCorrespondence> matches;
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    matches.insert(matches.end(), frame.matches.begin(), frame.matches.end());
  }
  EXPECT_NEAR(
      RefineRefractiveIndex(simulator->true_rig(), matches, RefinementOptions())
          .value()
          .n,
      1.34, 1e-9);
  const double stale =
      RefineRefractiveIndex(rig, matches, RefinementOptions()).value().n;
  std::printf("0.5 %% longer focal lengths: n %.5f for 1.34\n", stale);
  EXPECT_GT(std::abs(stale - 1.34), 0.002);
  // A change in one camera only breaks the pair's epipolar geometry: 0.2 %
  // in cam0 reads as a turn of cam1 and moves n by tenths (or to a bound).
  options.lens_change.focal_scale = {0.002, 0.0};
  simulator = SequenceSimulator::Create(rig, options).value();
  matches.clear();
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    matches.insert(matches.end(), frame.matches.begin(), frame.matches.end());
  }
  const StatusOr<RefinementSummary> one =
      RefineRefractiveIndex(rig, matches, RefinementOptions());
  if (one.ok()) {
    std::printf("0.2 %% longer in cam0 only: n %.5f for 1.34\n", one->n);
    EXPECT_GT(std::abs(one->n - 1.34), 0.05);
  }
  options.lens_change.focal_scale = {0.0, 0.06};
  const Status refused = SequenceSimulator::Create(rig, options).status();
  EXPECT_NE(refused.message().find("lens change of camera 1"),
            std::string::npos)
      << refused.message();
  options.lens_change.focal_scale = {NAN, 0.0};
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
}

TEST(SequenceSimulator, FramesCarryTheBoardsTruth) {
  SequenceOptions options = MatchesOnly({{1.34, 3}}, 50);
  options.board = SceneBoard();
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(NarrowFieldRig(), options).value();
  ASSERT_EQ(simulator->board_frames().size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    const BoardFrame& board = simulator->board_frames()[i];
    ASSERT_TRUE(frame.cam0_from_target.has_value());
    EXPECT_EQ(frame.cam0_from_target->ToMatrix(),
              board.cam0_from_target.ToMatrix());
    EXPECT_EQ(frame.board_fully_visible, board.fully_visible);
    EXPECT_TRUE(frame.board_fully_visible[0] && frame.board_fully_visible[1]);
  }
  const std::unique_ptr<SequenceSimulator> without =
      SequenceSimulator::Create(NarrowFieldRig(), MatchesOnly({{1.34, 1}}, 5))
          .value();
  EXPECT_TRUE(without->board_frames().empty());
  const SequenceFrame frame = without->Frame(0).value();
  EXPECT_FALSE(frame.cam0_from_target.has_value());
  EXPECT_FALSE(frame.board_fully_visible[0] || frame.board_fully_visible[1]);
  options.board->cols = 1;
  EXPECT_FALSE(SequenceSimulator::Create(NarrowFieldRig(), options).ok());
}

TEST(SequenceSimulator, MatchesOnTheBoardAreExactToo) {
  // The board close in front of the rig covers much of both images: many
  // matches land on it (the ray of the left pixel meets the board first),
  // and with a thin port all of them still give n to 1e-9.
  const StereoRig rig = NarrowFieldRig();
  SequenceOptions options = MatchesOnly({{1.34, 1}}, 400);
  options.board = SceneBoard();
  options.board_motion.min_distance = 0.6;
  options.board_motion.max_distance = 0.7;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  const SequenceFrame frame = simulator->Frame(0).value();
  ASSERT_EQ(frame.matches.size(), 400u);
  const PlacedBoard placed(*options.board,
                           frame.world_from_cam0 * *frame.cam0_from_target);
  const FlatPortCamera left =
      FlatPortCamera::Create(rig.left(), FlatPort(), 1.34).value();
  int on_board = 0;
  for (const StereoCorrespondence& match : frame.matches) {
    const RayInMedium ray = left.RayFromImage(match.left_pixel).value();
    on_board += IntersectScene(simulator->scene(), &placed,
                               frame.world_from_cam0 * ray.origin,
                               frame.world_from_cam0.rotation * ray.direction)
                    ->on_board;
  }
  EXPECT_GT(on_board, 40);
  EXPECT_LT(on_board, 400);
  EXPECT_NEAR(
      RefineRefractiveIndex(rig, frame.matches, RefinementOptions()).value().n,
      1.34, 1e-9);
}

TEST(SequenceSimulator, SameSeedSameFramesWithABoard) {
  SequenceOptions options = WithImages(1);
  options.board = SceneBoard();
  options.seed = 3;
  const StereoRig rig = NarrowFieldRig();
  const SequenceFrame a =
      SequenceSimulator::Create(rig, options).value()->Frame(0).value();
  const SequenceFrame b =
      SequenceSimulator::Create(rig, options).value()->Frame(0).value();
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);
  EXPECT_EQ(a.cam0_from_target->ToMatrix(), b.cam0_from_target->ToMatrix());
  options.seed = 4;
  const SequenceFrame c =
      SequenceSimulator::Create(rig, options).value()->Frame(0).value();
  EXPECT_GT((a.cam0_from_target->translation - c.cam0_from_target->translation)
                .norm(),
            1e-3);
}

}  // namespace
}  // namespace rcm::sequence_simulator_test

namespace rcm::sequence_simulator_test {
namespace {

// The distance between two rays (origin, unit direction) at their closest.
double RayGap(const RayInMedium& a, const RayInMedium& b) {
  const Eigen::Vector3d normal = a.direction.cross(b.direction);
  return std::abs((b.origin - a.origin).dot(normal.normalized()));
}

// Through domes the board stays in view and the matches are exact: the
// left and right rays of every match (each traced through its own dome,
// DomePortCamera) meet, which the same pixels through flat thin ports do
// not.
TEST(SequenceSimulator, DomesMakeTheBoardAndTheMatches) {
  constexpr double kN = 1.34;
  const StereoRig rig = NarrowFieldRig();
  SequenceOptions options = MatchesOnly({{kN, 3}}, 200);
  options.board = SceneBoard();
  options.left_dome =
      rcm::test::AcrylicDome(Eigen::Vector3d(0.002, -0.001, 0.007));
  options.right_dome =
      rcm::test::AcrylicDome(Eigen::Vector3d(-0.0015, 0.0025, 0.009));
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  const DomePortCamera left =
      DomePortCamera::Create(rig.left(), *options.left_dome, kN).value();
  const DomePortCamera right =
      DomePortCamera::Create(rig.right(), *options.right_dome, kN).value();
  const FlatPortCamera flat_left =
      FlatPortCamera::Create(rig.left(), FlatPort(), kN).value();
  const FlatPortCamera flat_right =
      FlatPortCamera::Create(rig.right(), FlatPort(), kN).value();
  const Rigid3d left_from_right = rig.right_from_left().Inverse();
  const auto in_left = [&](const RayInMedium& ray) {
    return RayInMedium{left_from_right * ray.origin,
                       left_from_right.rotation * ray.direction};
  };
  double largest_gap = 0.0, largest_flat_gap = 0.0;
  for (int i = 0; i < 3; ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    EXPECT_TRUE(frame.board_fully_visible[0] && frame.board_fully_visible[1]);
    ASSERT_EQ(frame.matches.size(), 200u);
    for (const StereoCorrespondence& match : frame.matches) {
      largest_gap = std::max(
          largest_gap, RayGap(*left.RayFromImage(match.left_pixel),
                              in_left(*right.RayFromImage(match.right_pixel))));
      largest_flat_gap = std::max(
          largest_flat_gap,
          RayGap(*flat_left.RayFromImage(match.left_pixel),
                 in_left(*flat_right.RayFromImage(match.right_pixel))));
    }
  }
  EXPECT_LT(largest_gap, 1e-8);
  EXPECT_GT(largest_flat_gap, 1e-4);

  // Bad domes and depth-range matches through domes are refused.
  options.left_dome->decentering = Eigen::Vector3d(0.0, 0.0, 0.05);
  const StatusOr<std::unique_ptr<SequenceSimulator>> outside =
      SequenceSimulator::Create(rig, options);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.status().message().find("left"), std::string::npos);
  options = MatchesOnly({{kN, 1}}, 10);
  options.match_min_depth = 0.5;
  options.match_max_depth = 2.0;
  options.right_dome =
      rcm::test::AcrylicDome(Eigen::Vector3d(0.001, 0.0, 0.005));
  EXPECT_FALSE(SequenceSimulator::Create(rig, options).ok());
}

}  // namespace
}  // namespace rcm::sequence_simulator_test
