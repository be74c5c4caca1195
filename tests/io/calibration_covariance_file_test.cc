#include "rcm/io/calibration_covariance_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "rcm/io/camchain.h"
#include "rcm/io/stereo_rig_file.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::calibration_covariance_file_test {
namespace {

using ::testing::HasSubstr;

constexpr double kDegree = M_PI / 180.0;

// A positive-definite n x n matrix with entries that do not print short.
Eigen::MatrixXd Covariance(int size, double scale, int seed) {
  Eigen::MatrixXd a(size, size);
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      a(r, c) = std::sin(1.7 * (r + 1) * (c + 2) + seed) / 3.0;
    }
  }
  return scale *
         (a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(size, size));
}

CalibrationCovarianceFile SampleFile() {
  CalibrationCovarianceFile file;
  file.medium = "water";
  file.drift_rotation_sigma = 0.05 * kDegree;
  file.drift_translation_sigma = 2e-4;
  file.cameras.resize(2);
  file.cameras[0].intrinsics_covariance = Covariance(8, 0.3, 1);
  file.cameras[1].intrinsics_covariance = Covariance(8, 0.2, 2);
  file.cameras[1].from_previous_covariance = Covariance(6, 1e-8, 3);
  return file;
}

// Camera::params() of an 8-parameter lens ([fx, fy, cx, cy, d...]).
Eigen::VectorXd Params(double fx) {
  Eigen::VectorXd params(8);
  params << fx, fx + 1.0, 320.0, 240.0, 0.1, -0.02, 1e-3, 2e-4;
  return params;
}

// PairCalibrationUncertainty for two 8-parameter lenses.
StatusOr<CalibrationUncertainty> Pair(
    const CalibrationCovarianceFile& file, int left, int right,
    std::optional<std::pair<double, double>> drift = std::nullopt,
    std::optional<double> focal = std::nullopt) {
  return PairCalibrationUncertainty(file, left, right, "c.yaml", Params(500.0),
                                    Params(490.0), drift, focal);
}

TEST(CalibrationCovarianceFile, SidecarPathIsNextToTheCamchain) {
  EXPECT_EQ(CovarianceSidecarPath("out/camchain.yaml"),
            "out/camchain-covariance.yaml");
  EXPECT_EQ(CovarianceSidecarPath("rig.yml"), "rig-covariance.yaml");
}

TEST(CalibrationCovarianceFile, RoundTripIsBitExact) {
  const CalibrationCovarianceFile file = SampleFile();
  const std::string text = FormatCalibrationCovariance(file);
  const CalibrationCovarianceFile read =
      ParseCalibrationCovariance(text, "c.yaml").value();
  EXPECT_EQ(read.medium, "water");
  EXPECT_EQ(read.drift_rotation_sigma, file.drift_rotation_sigma);
  EXPECT_EQ(read.drift_translation_sigma, file.drift_translation_sigma);
  ASSERT_EQ(read.cameras.size(), 2u);
  EXPECT_EQ(read.cameras[0].intrinsics_covariance,
            file.cameras[0].intrinsics_covariance);
  EXPECT_FALSE(read.cameras[0].from_previous_covariance.has_value());
  EXPECT_EQ(read.cameras[1].intrinsics_covariance,
            file.cameras[1].intrinsics_covariance);
  ASSERT_TRUE(read.cameras[1].from_previous_covariance.has_value());
  EXPECT_EQ(*read.cameras[1].from_previous_covariance,
            *file.cameras[1].from_previous_covariance);
  EXPECT_EQ(FormatCalibrationCovariance(read), text);
}

TEST(CalibrationCovarianceFile, PairUncertaintyAddsTheDriftPrior) {
  const CalibrationCovarianceFile file = SampleFile();
  const CalibrationUncertainty uncertainty = Pair(file, 0, 1).value();
  Eigen::Matrix<double, 6, 6> expected =
      *file.cameras[1].from_previous_covariance;
  for (int k = 0; k < 3; ++k) {
    expected(k, k) += std::pow(file.drift_rotation_sigma, 2);
    expected(3 + k, 3 + k) += std::pow(file.drift_translation_sigma, 2);
  }
  EXPECT_LT((uncertainty.extrinsics_covariance - expected).norm(),
            1e-15 * expected.norm());
  EXPECT_EQ(uncertainty.left_lens_covariance,
            file.cameras[0].intrinsics_covariance);
  EXPECT_THAT(uncertainty.source, HasSubstr("c.yaml (water calibration)"));
  EXPECT_THAT(uncertainty.source, HasSubstr("drift prior 0.05 deg, 0.2 mm"));
  // An override replaces the file's drift prior.
  const CalibrationUncertainty overridden =
      Pair(file, 0, 1, std::pair<double, double>{0.0, 0.0}).value();
  EXPECT_EQ(overridden.extrinsics_covariance,
            *file.cameras[1].from_previous_covariance);
  // Reversed or non-adjacent pairs have no measured extrinsics.
  const CalibrationUncertainty reversed = Pair(file, 1, 0).value();
  EXPECT_TRUE((reversed.extrinsics_covariance.topRightCorner<3, 3>().isZero()));
  EXPECT_NEAR(reversed.extrinsics_covariance(0, 0),
              std::pow(file.drift_rotation_sigma, 2), 1e-24);
  EXPECT_FALSE(Pair(file, 0, 2).ok());
}

// The focal drift prior: written and read back, the default of its medium
// when absent, added to each lens covariance as s^2 g g^T with g = [fx,
// fy, 0, ...] (an empty lens covariance becomes that alone), replaced by an
// override, and refused for a lens covariance of the wrong size.
TEST(CalibrationCovarianceFile, FocalDriftPriorReachesTheLenses) {
  CalibrationCovarianceFile file = SampleFile();
  file.medium = "air";
  file.drift_focal_sigma = 0.004;
  const std::string text = FormatCalibrationCovariance(file);
  EXPECT_THAT(text, HasSubstr("focal_percent: 0.4"));
  const CalibrationCovarianceFile read =
      ParseCalibrationCovariance(text, "c.yaml").value();
  EXPECT_EQ(read.drift_focal_sigma, 0.004);
  EXPECT_EQ(FormatCalibrationCovariance(read), text);
  for (const std::string medium : {"air", "water"}) {
    const CalibrationCovarianceFile absent =
        ParseCalibrationCovariance("medium: " + medium + "\ncam0: {}\n",
                                   "c.yaml")
            .value();
    EXPECT_EQ(absent.drift_focal_sigma,
              medium == "air"
                  ? 1e-2 * CalibrationUncertainty::kDefaultFocalDriftPercent
                  : 0.0)
        << medium;
  }

  const CalibrationUncertainty pair = Pair(read, 0, 1).value();
  Eigen::VectorXd g = Eigen::VectorXd::Zero(8);
  g.head(2) = Params(500.0).head(2);
  const Eigen::MatrixXd expected =
      file.cameras[0].intrinsics_covariance + 0.004 * 0.004 * g * g.transpose();
  EXPECT_LT((pair.left_lens_covariance - expected).cwiseAbs().maxCoeff(),
            1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_NEAR(pair.right_lens_covariance(0, 1) -
                  file.cameras[1].intrinsics_covariance(0, 1),
              0.004 * 0.004 * 490.0 * 491.0, 1e-9);
  EXPECT_EQ(pair.right_lens_covariance(2, 2),
            file.cameras[1].intrinsics_covariance(2, 2));
  EXPECT_THAT(pair.source, HasSubstr("focal drift prior 0.4 %"));
  EXPECT_TRUE(pair.Check(8, 8).ok());
  // Lenses taken as exact in the file get the prior alone.
  CalibrationCovarianceFile exact = read;
  exact.cameras[0].intrinsics_covariance.resize(0, 0);
  const CalibrationUncertainty prior_only = Pair(exact, 0, 1).value();
  EXPECT_NEAR(prior_only.left_lens_covariance(0, 0), std::pow(0.004 * 500.0, 2),
              1e-12);
  EXPECT_EQ(prior_only.left_lens_covariance(3, 3), 0.0);
  // An override of 0: the file's lenses as they are.
  EXPECT_EQ(Pair(read, 0, 1, std::nullopt, 0.0).value().left_lens_covariance,
            file.cameras[0].intrinsics_covariance);
  // A lens covariance that is not the camera's size.
  const StatusOr<CalibrationUncertainty> wrong = PairCalibrationUncertainty(
      read, 0, 1, "c.yaml", Params(500.0).head(5), Params(490.0));
  ASSERT_FALSE(wrong.ok());
  EXPECT_THAT(wrong.status().message(),
              HasSubstr("c.yaml: cam0: intrinsics_covariance has 8 rows, the "
                        "camera has 5 parameters"));
}

TEST(CalibrationCovarianceFile, BadFilesGiveOneLineErrors) {
  const std::string good = FormatCalibrationCovariance(SampleFile());
  const struct {
    std::string text;
    std::string message;
  } cases[] = {
      {"", "empty file"},
      {"cam0: {}\n", "missing key 'medium'"},
      {"medium: vacuum\n", "expected air or water"},
      {"medium: air\nfoo: 1\n", "unknown key"},
      {"medium: air\ndrift_prior: {rotation_deg: -1}\n", "must be >= 0"},
      {"medium: air\ncam1: {}\n", "cam0"},
      {"medium: air\ncam0:\n  intrinsics_covariance:\n  - [1, 2]\n  - [3, "
       "4]\n",
       "is not symmetric"},
      {"medium: air\ncam0:\n  intrinsics_covariance:\n  - [1, 0]\n  - [0, "
       "-1]\n",
       "is not positive semi-definite"},
      {"medium: air\ncam0:\n  intrinsics_covariance:\n  - [1, 0]\n  - [0]\n",
       "expected 2 numbers, got 1"},
      {"medium: air\ncam0:\n  intrinsics_covariance:\n  - [.nan]\n",
       "not a finite number"},
      {"medium: air\ncam0: {}\ncam1:\n  T_cn_cnm1_covariance:\n  - [1]\n",
       "expected 6 rows, got 1"},
      {"medium: air\ncam0:\n  T_cn_cnm1_covariance: []\n", "unknown key"},
  };
  for (const auto& c : cases) {
    const StatusOr<CalibrationCovarianceFile> read =
        ParseCalibrationCovariance(c.text, "side.yaml");
    ASSERT_FALSE(read.ok()) << c.text;
    EXPECT_THAT(read.status().message(), HasSubstr(c.message)) << c.text;
    EXPECT_THAT(read.status().message(), ::testing::StartsWith("side.yaml"));
    EXPECT_EQ(read.status().message().find('\n'), std::string::npos);
  }
  EXPECT_TRUE(ParseCalibrationCovariance(good, "side.yaml").ok());
}

// An underwater calibration's sidecar: the extrinsics' cross-covariance
// with both lenses reads back bit for bit and reaches the pair's
// uncertainty; one that cannot belong to a covariance is an error.
// The error of parsing `file` as written.
std::string ParseError(const CalibrationCovarianceFile& file) {
  return ParseCalibrationCovariance(FormatCalibrationCovariance(file),
                                    "side.yaml")
      .status()
      .message();
}

TEST(CalibrationCovarianceFile, ExtrinsicsLensCrossCovariance) {
  const Eigen::MatrixXd full = Covariance(22, 1e-3, 4);  // [w; dt; 8; 8]
  CalibrationCovarianceFile file = SampleFile();
  file.cameras[1].from_previous_covariance = full.topLeftCorner<6, 6>();
  file.cameras[0].intrinsics_covariance = full.block(6, 6, 8, 8);
  file.cameras[1].intrinsics_covariance = full.block(14, 14, 8, 8);
  // The lens-lens block is left out of the file: keep the rest positive
  // definite by a margin.
  file.cameras[0].intrinsics_covariance += Eigen::MatrixXd::Identity(8, 8);
  file.cameras[1].intrinsics_covariance += Eigen::MatrixXd::Identity(8, 8);
  file.cameras[1].from_previous_intrinsics_covariance = full.block(0, 6, 6, 16);
  const std::string text = FormatCalibrationCovariance(file);
  EXPECT_THAT(text, HasSubstr("T_cn_cnm1_intrinsics_covariance:"));
  const CalibrationCovarianceFile read =
      ParseCalibrationCovariance(text, "c.yaml").value();
  EXPECT_EQ(read.cameras[1].from_previous_intrinsics_covariance,
            file.cameras[1].from_previous_intrinsics_covariance);
  EXPECT_EQ(read.cameras[0].from_previous_intrinsics_covariance.size(), 0);
  EXPECT_EQ(FormatCalibrationCovariance(read), text);
  const CalibrationUncertainty pair = Pair(read, 0, 1).value();
  EXPECT_EQ(pair.extrinsics_lens_covariance,
            file.cameras[1].from_previous_intrinsics_covariance);
  EXPECT_TRUE(pair.Check(8, 8).ok());

  CalibrationCovarianceFile bad = file;
  bad.cameras[1].from_previous_intrinsics_covariance *= 1e4;
  EXPECT_THAT(ParseError(bad), HasSubstr("not positive semi-definite"));
  bad = file;
  bad.cameras[1].from_previous_intrinsics_covariance.conservativeResize(6, 15);
  EXPECT_THAT(ParseError(bad), HasSubstr("is 6x15, not 6x16"));
  bad = file;
  bad.cameras[0].intrinsics_covariance.resize(0, 0);
  EXPECT_THAT(ParseError(bad),
              HasSubstr("needs T_cn_cnm1_covariance and both"));
  const std::string rows =
      "medium: water\ncam0: {}\ncam1:\n  T_cn_cnm1_intrinsics_covariance:\n"
      "  - [1, 2]\n";
  EXPECT_THAT(ParseCalibrationCovariance(rows, "side.yaml").status().message(),
              HasSubstr("expected 6 rows"));
  const std::string ragged =
      "medium: water\ncam0: {}\ncam1:\n  T_cn_cnm1_intrinsics_covariance:\n"
      "  - [1, 2]\n  - [1]\n  - [1]\n  - [1]\n  - [1]\n  - [1]\n";
  EXPECT_THAT(
      ParseCalibrationCovariance(ragged, "side.yaml").status().message(),
      HasSubstr("expected 2 numbers, got 1"));
}

// The cam0-cam1 lens block of a joint calibration (intrinsics_cross_
// covariance on cam1): written, read back bit for bit, handed to the
// pair's uncertainty, and checked with the rest of the joint matrix.
TEST(CalibrationCovarianceFile, LensCrossCovariance) {
  const Eigen::MatrixXd full = Covariance(22, 1e-3, 4);  // [w; dt; 8; 8]
  CalibrationCovarianceFile file = SampleFile();
  file.cameras[1].from_previous_covariance = full.topLeftCorner<6, 6>();
  file.cameras[0].intrinsics_covariance = full.block(6, 6, 8, 8);
  file.cameras[1].intrinsics_covariance = full.block(14, 14, 8, 8);
  file.cameras[1].from_previous_intrinsics_covariance = full.block(0, 6, 6, 16);
  file.cameras[1].previous_intrinsics_covariance = full.block(6, 14, 8, 8);
  const std::string text = FormatCalibrationCovariance(file);
  EXPECT_THAT(text, HasSubstr("intrinsics_cross_covariance:"));
  const CalibrationCovarianceFile read =
      ParseCalibrationCovariance(text, "c.yaml").value();
  EXPECT_EQ(read.cameras[1].previous_intrinsics_covariance,
            file.cameras[1].previous_intrinsics_covariance);
  EXPECT_EQ(FormatCalibrationCovariance(read), text);
  const CalibrationUncertainty pair = Pair(read, 0, 1).value();
  EXPECT_EQ(pair.lens_cross_covariance,
            file.cameras[1].previous_intrinsics_covariance);
  EXPECT_TRUE(pair.Check(8, 8).ok());
  // The joint matrix's lens rows are the full one's (to the rounding of
  // a * a^T's symmetry; the extrinsics block has the file's drift prior
  // added).
  EXPECT_LT((pair.JointCovariance() - full).bottomRows(16).norm(),
            1e-14 * full.norm());

  CalibrationCovarianceFile bad = file;
  bad.cameras[1].previous_intrinsics_covariance *= 1e3;
  EXPECT_THAT(ParseError(bad), HasSubstr("not positive semi-definite"));
  bad = file;
  bad.cameras[1].previous_intrinsics_covariance.conservativeResize(8, 7);
  EXPECT_THAT(ParseError(bad), HasSubstr("is 8x7, not 8x8"));
  bad = file;
  bad.cameras[1].from_previous_intrinsics_covariance.resize(0, 0);
  bad.cameras[0].intrinsics_covariance.resize(0, 0);
  EXPECT_THAT(ParseError(bad), HasSubstr("needs both cameras' intrinsics"));
}

// The ports' block of an underwater calibration that estimated them:
// written, read back bit for bit, handed to the (cam0, cam1) pair's
// uncertainty (not to another pair), checked with the rest of the joint
// matrix; a focal drift prior on a camera without a lens covariance gives
// the cross-covariance that camera's zero rows.
TEST(CalibrationCovarianceFile, PortsCovariance) {
  const Eigen::MatrixXd full = Covariance(28, 1e-3, 6);  // [w; dt; 8; 8; q]
  CalibrationCovarianceFile file = SampleFile();
  file.cameras[1].from_previous_covariance = full.topLeftCorner<6, 6>();
  file.cameras[0].intrinsics_covariance = full.block(6, 6, 8, 8);
  file.cameras[1].intrinsics_covariance = full.block(14, 14, 8, 8);
  file.cameras[1].from_previous_intrinsics_covariance = full.block(0, 6, 6, 16);
  file.cameras[1].previous_intrinsics_covariance = full.block(6, 14, 8, 8);
  file.port_covariance = full.bottomRightCorner<6, 6>();
  file.port_cross_covariance = full.topRightCorner(22, 6);
  const std::string text = FormatCalibrationCovariance(file);
  EXPECT_THAT(text, HasSubstr("ports:\n  covariance:"));
  const CalibrationCovarianceFile read =
      ParseCalibrationCovariance(text, "c.yaml").value();
  EXPECT_EQ(read.port_cross_covariance, file.port_cross_covariance);
  EXPECT_EQ(FormatCalibrationCovariance(read), text);
  const CalibrationUncertainty pair = Pair(read, 0, 1).value();
  EXPECT_TRUE(pair.Check(8, 8).ok()) << pair.Check(8, 8).message();
  // The joint's port rows are the full one's (to the rounding of a * a^T's
  // symmetry).
  EXPECT_LT((pair.JointCovariance() - full).bottomRows(6).norm(),
            1e-14 * full.norm());
  EXPECT_EQ(Pair(read, 1, 0).value().port_covariance.size(), 0);

  CalibrationCovarianceFile bad = file;
  bad.port_cross_covariance *= 1e3;
  EXPECT_THAT(ParseError(bad), HasSubstr("not positive semi-definite"));
  bad = file;
  bad.port_cross_covariance.conservativeResize(21, 6);
  EXPECT_THAT(ParseError(bad), HasSubstr("is 21x6, not 22x6"));
  const std::string unknown =
      "medium: water\ncam0: {}\ncam1: {}\nports:\n  tilt: 1\n";
  EXPECT_THAT(
      ParseCalibrationCovariance(unknown, "side.yaml").status().message(),
      HasSubstr("ports.tilt: unknown key"));
  const std::string no_covariance =
      "medium: water\ncam0: {}\ncam1: {}\nports: {}\n";
  EXPECT_THAT(
      ParseCalibrationCovariance(no_covariance, "side.yaml").status().message(),
      HasSubstr("needs covariance"));

  // Ports without lens covariances: 6 cross rows; the focal drift prior
  // then adds each lens's zero rows.
  CalibrationCovarianceFile bare;
  bare.medium = "water";
  bare.cameras.resize(2);
  bare.cameras[1].from_previous_covariance = full.topLeftCorner<6, 6>();
  bare.port_covariance = full.bottomRightCorner<6, 6>();
  bare.port_cross_covariance = full.block(0, 22, 6, 6);
  const CalibrationUncertainty focal =
      Pair(bare, 0, 1, std::nullopt, 0.003).value();
  ASSERT_EQ(focal.port_cross_covariance.rows(), 22);
  EXPECT_EQ(focal.port_cross_covariance.topRows(6), bare.port_cross_covariance);
  EXPECT_TRUE(focal.port_cross_covariance.bottomRows(16).isZero(0.0));
  EXPECT_TRUE(focal.Check(8, 8).ok()) << focal.Check(8, 8).message();
}

// ReadStereoRig attaches the sidecar when there is one, and the default
// drift prior otherwise; a camera count that differs from the camchain's,
// or a lens covariance of the wrong size, is an error naming the sidecar.
TEST(CalibrationCovarianceFile, ReadStereoRigAttachesTheSidecar) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::string camchain = test::WriteTempFile(
      "rig.yaml", FormatCamchain(CamchainFromStereoRig(rig)));
  const std::string sidecar = CovarianceSidecarPath(camchain);
  std::remove(sidecar.c_str());  // an earlier run's
  const StereoRig without = ReadStereoRig(camchain).value();
  ASSERT_TRUE(without.calibration_uncertainty().has_value());
  EXPECT_THAT(without.calibration_uncertainty()->source,
              HasSubstr("default drift prior 0.1 deg, 0.1 mm per axis"));
  EXPECT_NEAR(without.calibration_uncertainty()->extrinsics_covariance(0, 0),
              std::pow(0.1 * kDegree, 2), 1e-20);
  // And the default focal drift prior of an air calibration on each lens.
  EXPECT_THAT(without.calibration_uncertainty()->source,
              HasSubstr("focal drift prior 0.3 %"));
  EXPECT_NEAR(without.calibration_uncertainty()->left_lens_covariance(0, 0),
              std::pow(0.003 * rig.left().fx(), 2), 1e-12);
  EXPECT_NEAR(without.calibration_uncertainty()->right_lens_covariance(1, 1),
              std::pow(0.003 * rig.right().fy(), 2), 1e-12);
  RigFileOptions exact_lenses;
  exact_lenses.focal_drift = 0.0;
  EXPECT_EQ(ReadStereoRig(camchain, "cam0", "cam1", exact_lenses)
                .value()
                .calibration_uncertainty()
                ->left_lens_covariance.size(),
            0);

  ASSERT_TRUE(WriteCalibrationCovariance(sidecar, SampleFile()).ok());
  const StereoRig with = ReadStereoRig(camchain).value();
  ASSERT_TRUE(with.calibration_uncertainty().has_value());
  EXPECT_EQ(with.calibration_uncertainty()->left_lens_covariance,
            SampleFile().cameras[0].intrinsics_covariance);
  EXPECT_THAT(with.calibration_uncertainty()->source, HasSubstr(sidecar));
  RigFileOptions no_drift;
  no_drift.drift_prior = std::pair<double, double>{0.0, 0.0};
  EXPECT_EQ(ReadStereoRig(camchain, "cam0", "cam1", no_drift)
                .value()
                .calibration_uncertainty()
                ->extrinsics_covariance,
            *SampleFile().cameras[1].from_previous_covariance);

  CalibrationCovarianceFile three = SampleFile();
  three.cameras.resize(3);
  ASSERT_TRUE(WriteCalibrationCovariance(sidecar, three).ok());
  const StatusOr<StereoRig> mismatch = ReadStereoRig(camchain);
  ASSERT_FALSE(mismatch.ok());
  EXPECT_THAT(mismatch.status().message(), HasSubstr("has 3 cameras"));

  CalibrationCovarianceFile small = SampleFile();
  small.cameras[0].intrinsics_covariance = Covariance(4, 1.0, 4);
  ASSERT_TRUE(WriteCalibrationCovariance(sidecar, small).ok());
  const StatusOr<StereoRig> wrong_size = ReadStereoRig(camchain);
  ASSERT_FALSE(wrong_size.ok());
  EXPECT_THAT(wrong_size.status().message(),
              HasSubstr("left lens covariance is 4x4, the camera has 8"));
  EXPECT_THAT(wrong_size.status().message(), HasSubstr(sidecar));
}

}  // namespace
}  // namespace rcm::calibration_covariance_file_test
