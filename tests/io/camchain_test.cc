#include "rcm/io/camchain.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "rcm/io/atomic_file.h"
#include "rcm/sim/reference_rigs.h"
#include "support/reader_inputs.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::camchain_test {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// The front pair of the paper's dataset (docs/design.md, "The reference rig")
// as Kalibr writes it: Python's yaml.dump(..., default_flow_style=None) of the
// camchain dictionary produced exactly these bytes, including the wrapped
// distortion_coeffs lines. T_cn_cnm1 is the rotation of angle-axis
// (0.0021, -0.0113, 0.0016) rad with a 0.11 m baseline.
constexpr char kAlphasense[] =
    R"(cam0:
  T_cam_imu:
  - [0.009190539179784296, -0.9999574394434022, -0.0008082644242889958, 0.0057]
  - [0.01747295221941203, 0.0009687677355780799, -0.9998468669900471, -0.0412]
  - [0.9998050959713713, 0.009175009039190274, 0.01748111205867031, -0.0291]
  - [0.0, 0.0, 0.0, 1.0]
  cam_overlaps: [1]
  camera_model: pinhole
  distortion_coeffs: [-0.037934508908317364, -0.0009855550912794707, -0.0009622185860956224,
    2.365797666527927e-05]
  distortion_model: equidistant
  intrinsics: [346.68681661781403, 346.7780959214622, 360.53325988648163, 271.0179819820658]
  resolution: [720, 540]
  rostopic: /alphasense_driver_ros/cam0
  timeshift_cam_imu: 0.0012847
cam1:
  T_cam_imu:
  - [0.011389227497007659, -0.9999303934359439, -0.0030811978287598185, -0.1044]
  - [0.0030811978287598185, 0.0031164776298818198, -0.9999903968474511, -0.0405]
  - [0.9999303934359439, 0.011379624344458661, 0.0031164776298818198, -0.0298]
  - [0.0, 0.0, 0.0, 1.0]
  T_cn_cnm1:
  - [0.9999348757308079, -0.001611828957763957, -0.011298066410893199, -0.11018]
  - [0.0015880992240529304, 0.9999965150391074, -0.0021089927678739134, 0.00041]
  - [0.011301426373188565, 0.00209091297076075, 0.9999339507411878, -0.00023]
  - [0.0, 0.0, 0.0, 1.0]
  cam_overlaps: [0]
  camera_model: pinhole
  distortion_coeffs: [-0.03970881800919102, 0.0016107591002609727, -0.002331667784337188,
    0.00035009066006595556]
  distortion_model: equidistant
  intrinsics: [344.3933991977547, 344.2292927278568, 358.725925185576, 262.02195974034373]
  resolution: [720, 540]
  rostopic: /alphasense_driver_ros/cam1
  timeshift_cam_imu: 1.0e-05
)";

// A small valid camchain for the malformed-input tests; each test breaks
// one line of it. Line numbers are given for reference.
constexpr char kMinimal[] =
    R"(cam0:
  cam_overlaps: [1]
  camera_model: pinhole
  distortion_coeffs: [-0.0379, -0.00098, -0.00096, 2.36e-05]
  distortion_model: equidistant
  intrinsics: [346.7, 346.8, 360.5, 271.0]
  resolution: [720, 540]
cam1:
  T_cn_cnm1:
  - [0.9999348757308079, -0.001611828957763957, -0.011298066410893199, -0.11018]
  - [0.0015880992240529304, 0.9999965150391074, -0.0021089927678739134, 0.00041]
  - [0.011301426373188565, 0.00209091297076075, 0.9999339507411878, -0.00023]
  - [0.0, 0.0, 0.0, 1.0]
  cam_overlaps: [0]
  camera_model: pinhole
  distortion_coeffs: [-0.0397, 0.00161, -0.00233, 0.00035]
  distortion_model: equidistant
  intrinsics: [344.4, 344.2, 358.7, 262.0]
  resolution: [720, 540]
)";
//  1 cam0:                     10   - [0.99993..., row 1
//  4   distortion_coeffs       12   - [0.0113..., row 3
//  5   distortion_model        13   - [0.0, 0.0, 0.0, 1.0]
//  6   intrinsics              15   camera_model (cam1)
//  7   resolution              18   intrinsics (cam1)
//  8 cam1:                     19   resolution (cam1)
//  9   T_cn_cnm1:

using test::ReplaceOnce;

// The error message of parsing `text` as "rig.yaml" (empty if it parsed).
std::string ParseError(const std::string& text) {
  return test::ErrorMessage(ParseCamchain(text, "rig.yaml"));
}

bool BitwiseEqual(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

::testing::AssertionResult CamerasBitwiseEqual(const Camera& a,
                                               const Camera& b) {
  if (a.model() != b.model() || a.width() != b.width() ||
      a.height() != b.height() || a.num_params() != b.num_params()) {
    return ::testing::AssertionFailure() << "model or size differ";
  }
  for (int i = 0; i < a.num_params(); ++i) {
    if (!BitwiseEqual(a.params()[i], b.params()[i])) {
      return ::testing::AssertionFailure()
             << "param " << i << ": " << a.params()[i] << " vs "
             << b.params()[i];
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult TransformsBitwiseEqual(const Rigid3d& a,
                                                  const Rigid3d& b) {
  const Eigen::Matrix4d ma = a.ToMatrix();
  const Eigen::Matrix4d mb = b.ToMatrix();
  for (int i = 0; i < 16; ++i) {
    if (!BitwiseEqual(ma(i), mb(i))) {
      return ::testing::AssertionFailure()
             << "entry " << i << ": " << ma(i) << " vs " << mb(i);
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult OptionalTransformsBitwiseEqual(
    const std::optional<Rigid3d>& a, const std::optional<Rigid3d>& b) {
  if (a.has_value() != b.has_value()) {
    return ::testing::AssertionFailure() << "presence differs";
  }
  if (!a.has_value()) return ::testing::AssertionSuccess();
  return TransformsBitwiseEqual(*a, *b);
}

void ExpectCamchainsBitwiseEqual(const Camchain& a, const Camchain& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t i = 0; i < a.cameras.size(); ++i) {
    SCOPED_TRACE("cam" + std::to_string(i));
    const CamchainCamera& ca = a.cameras[i];
    const CamchainCamera& cb = b.cameras[i];
    EXPECT_TRUE(CamerasBitwiseEqual(ca.camera, cb.camera));
    EXPECT_TRUE(OptionalTransformsBitwiseEqual(ca.cam_from_previous,
                                               cb.cam_from_previous));
    EXPECT_TRUE(
        OptionalTransformsBitwiseEqual(ca.cam_from_imu, cb.cam_from_imu));
    ASSERT_EQ(ca.timeshift_cam_imu.has_value(),
              cb.timeshift_cam_imu.has_value());
    if (ca.timeshift_cam_imu.has_value()) {
      EXPECT_TRUE(BitwiseEqual(*ca.timeshift_cam_imu, *cb.timeshift_cam_imu));
    }
    EXPECT_EQ(ca.cam_overlaps, cb.cam_overlaps);
    EXPECT_EQ(ca.rostopic, cb.rostopic);
    ASSERT_EQ(ca.port.has_value(), cb.port.has_value());
    if (ca.port.has_value()) {
      EXPECT_TRUE(BitwiseEqual(ca.port->air_gap, cb.port->air_gap));
      EXPECT_TRUE(
          BitwiseEqual(ca.port->glass_thickness, cb.port->glass_thickness));
      EXPECT_TRUE(BitwiseEqual(ca.port->glass_index, cb.port->glass_index));
      for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(BitwiseEqual(ca.port->normal[k], cb.port->normal[k]));
      }
    }
    ASSERT_EQ(ca.dome.has_value(), cb.dome.has_value());
    if (ca.dome.has_value()) {
      EXPECT_TRUE(BitwiseEqual(ca.dome->inner_radius, cb.dome->inner_radius));
      EXPECT_TRUE(BitwiseEqual(ca.dome->thickness, cb.dome->thickness));
      EXPECT_TRUE(BitwiseEqual(ca.dome->glass_index, cb.dome->glass_index));
      for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(
            BitwiseEqual(ca.dome->decentering[k], cb.dome->decentering[k]));
      }
    }
  }
}

Camera MakeCamera(LensModelId model, double fx,
                  const std::vector<double>& distortion) {
  return Camera::Create(model, 720, 540, {fx, fx + 0.25, 360.5, 271.0},
                        distortion)
      .value();
}

Rigid3d MakeTransform(const Eigen::Vector3d& angle_axis,
                      const Eigen::Vector3d& translation) {
  Rigid3d transform;
  transform.rotation =
      Eigen::AngleAxisd(angle_axis.norm(), angle_axis.normalized())
          .toRotationMatrix();
  transform.translation = translation;
  return transform;
}

CamchainCamera MakeEntry(const Camera& camera,
                         std::optional<Rigid3d> cam_from_previous) {
  return CamchainCamera{
      camera, cam_from_previous, std::nullopt, std::nullopt, {}, ""};
}

// --- Reading a Kalibr file --------------------------------------------------

TEST(Camchain, ParsesKalibrFile) {
  const StatusOr<Camchain> camchain = ParseCamchain(kAlphasense, "rig.yaml");
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  ASSERT_EQ(camchain->cameras.size(), 2u);

  const CamchainCamera& cam0 = camchain->cameras[0];
  EXPECT_EQ(cam0.camera.model(), LensModelId::kEquidistant);
  EXPECT_EQ(cam0.camera.width(), 720);
  EXPECT_EQ(cam0.camera.height(), 540);
  EXPECT_EQ(cam0.camera.fx(), 346.68681661781403);
  EXPECT_EQ(cam0.camera.fy(), 346.7780959214622);
  EXPECT_EQ(cam0.camera.cx(), 360.53325988648163);
  EXPECT_EQ(cam0.camera.cy(), 271.0179819820658);
  EXPECT_EQ(
      cam0.camera.Distortion(),
      (std::vector<double>{-0.037934508908317364, -0.0009855550912794707,
                           -0.0009622185860956224, 2.365797666527927e-05}));
  EXPECT_FALSE(cam0.cam_from_previous.has_value());
  ASSERT_TRUE(cam0.cam_from_imu.has_value());
  EXPECT_EQ(cam0.cam_from_imu->translation,
            Eigen::Vector3d(0.0057, -0.0412, -0.0291));
  EXPECT_EQ(cam0.timeshift_cam_imu, 0.0012847);
  EXPECT_EQ(cam0.cam_overlaps, std::vector<int>{1});
  EXPECT_EQ(cam0.rostopic, "/alphasense_driver_ros/cam0");

  const CamchainCamera& cam1 = camchain->cameras[1];
  EXPECT_EQ(cam1.camera.fx(), 344.3933991977547);
  EXPECT_EQ(cam1.timeshift_cam_imu, 1e-05);
  ASSERT_TRUE(cam1.cam_from_previous.has_value());
  EXPECT_EQ(cam1.cam_from_previous->rotation(0, 0), 0.9999348757308079);
  EXPECT_EQ(cam1.cam_from_previous->rotation(2, 1), 0.00209091297076075);
  EXPECT_EQ(cam1.cam_from_previous->translation,
            Eigen::Vector3d(-0.11018, 0.00041, -0.00023));
  EXPECT_NEAR(cam1.cam_from_previous->RotationAngle(),
              Eigen::Vector3d(0.0021, -0.0113, 0.0016).norm(), 1e-15);
}

TEST(Camchain, FormatReproducesKalibrFileByteForByte) {
  const StatusOr<Camchain> camchain = ParseCamchain(kAlphasense, "rig.yaml");
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  EXPECT_EQ(FormatCamchain(*camchain), kAlphasense);
}

TEST(Camchain, WrapsLongListsLikePyYaml) {
  // yaml.dump breaks a flow list after the first comma past column 80.
  CamchainCamera entry =
      MakeEntry(MakeCamera(LensModelId::kPinhole, 300.0, {}), std::nullopt);
  for (int i = 0; i < 16; ++i) entry.cam_overlaps.push_back(10000 + i);
  Camchain camchain;
  camchain.cameras.push_back(entry);
  EXPECT_EQ(FormatCamchain(camchain),
            "cam0:\n"
            "  cam_overlaps: [10000, 10001, 10002, 10003, 10004, 10005, 10006, "
            "10007, 10008, 10009,\n"
            "    10010, 10011, 10012, 10013, 10014, 10015]\n"
            "  camera_model: pinhole\n"
            "  distortion_coeffs: []\n"
            "  distortion_model: none\n"
            "  intrinsics: [300.0, 300.25, 360.5, 271.0]\n"
            "  resolution: [720, 540]\n");
}

TEST(Camchain, WritesCamerasInPythonKeyOrder) {
  Camchain camchain;
  camchain.cameras.push_back(
      MakeEntry(MakeCamera(LensModelId::kPinhole, 300.0, {}), std::nullopt));
  for (int i = 1; i <= 11; ++i) {
    camchain.cameras.push_back(
        MakeEntry(MakeCamera(LensModelId::kPinhole, 300.0 + i, {}),
                  MakeTransform(Eigen::Vector3d(0.0, 0.01 * i, 0.0),
                                Eigen::Vector3d(-0.1, 0.0, 0.0))));
  }
  const std::string text = FormatCamchain(camchain);
  // Python sorts the keys as strings: cam1 < cam10 < cam11 < cam2.
  const size_t cam1 = text.find("\ncam1:\n");
  const size_t cam10 = text.find("\ncam10:\n");
  const size_t cam11 = text.find("\ncam11:\n");
  const size_t cam2 = text.find("\ncam2:\n");
  ASSERT_NE(cam2, std::string::npos);
  EXPECT_LT(cam1, cam10);
  EXPECT_LT(cam10, cam11);
  EXPECT_LT(cam11, cam2);
  // Reading restores the numeric order.
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
}

TEST(Camchain, IgnoresUnknownKeys) {
  const std::string text =
      ReplaceOnce(kMinimal, "cam1:\n",
                  "calibration_note: taken in air\ncam1:\n  color: red\n");
  const StatusOr<Camchain> camchain = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  EXPECT_EQ(camchain->cameras.size(), 2u);
}

// --- Round trips ------------------------------------------------------------

TEST(Camchain, RoundTripIsByteStable) {
  // Values that exercise every number layout: long mantissas, exponents on
  // both sides of the fixed/scientific switch, -0.0, integral values
  // (those that no camera has go into the IMU transform and time shifts).
  Camchain camchain;
  CamchainCamera cam0 = MakeEntry(
      Camera::Create(LensModelId::kEquidistant, 1440, 1080,
                     {1234.5678901234567, 999999.9999999999, -0.0, 123456.0},
                     {1e-05, -2.365797666527927e-05, 0.1, 5e-324})
          .value(),
      std::nullopt);
  cam0.cam_from_imu =
      MakeTransform(Eigen::Vector3d(1.2, -1.2, 1.2),
                    Eigen::Vector3d(1e16, 1e-17, 9999999999999998.0));
  cam0.timeshift_cam_imu = -0.0001;
  cam0.cam_overlaps = {1, 2};
  cam0.rostopic = "/rig/left/image_raw";
  CamchainCamera cam1 =
      MakeEntry(Camera::Create(LensModelId::kRadTan, 640, 480,
                               {100.0 / 3.0, 1000.0 / 3.0, 320.0, 240.0},
                               {-0.28, 0.07, 1.9e-4, -3.1e-5})
                    .value(),
                MakeTransform(Eigen::Vector3d(0.003, -0.02, 0.001),
                              Eigen::Vector3d(-0.12, 1e-4, 2.5e-3)));
  cam1.cam_overlaps = {0};
  cam1.timeshift_cam_imu = 0.1 + 0.2;
  CamchainCamera cam2 =
      MakeEntry(MakeCamera(LensModelId::kPinhole, 500.0, {}),
                MakeTransform(Eigen::Vector3d(0.5, 0.25, -0.125),
                              Eigen::Vector3d(0.3, -0.2, 0.1)));
  cam2.rostopic = "123";  // needs quotes to stay a string
  camchain.cameras = {cam0, cam1, cam2};

  const std::string first = FormatCamchain(camchain);
  const StatusOr<Camchain> parsed = ParseCamchain(first, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message() << "\n" << first;
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
  EXPECT_EQ(FormatCamchain(*parsed), first);
}

TEST(Camchain, RadTanRoundTrips) {
  Camchain camchain;
  camchain.cameras.push_back(MakeEntry(
      MakeCamera(LensModelId::kRadTan, 458.654,
                 {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}),
      std::nullopt));
  camchain.cameras.push_back(MakeEntry(
      MakeCamera(LensModelId::kRadTan, 457.587,
                 {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05}),
      MakeTransform(Eigen::Vector3d(0.002, 0.0003, -0.0004),
                    Eigen::Vector3d(-0.110073808127187, 0.000399121547014,
                                    -0.000853702503357))));
  const std::string text = FormatCamchain(camchain);
  EXPECT_THAT(text, HasSubstr("  distortion_model: radtan\n"));
  EXPECT_THAT(text, HasSubstr("  distortion_coeffs: [-0.28340811, 0.07395907, "
                              "0.00019359, 1.76187114e-05]\n"));
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
  EXPECT_EQ(FormatCamchain(*parsed), text);
}

TEST(Camchain, NoneModelRoundTrips) {
  Camchain camchain;
  camchain.cameras.push_back(
      MakeEntry(MakeCamera(LensModelId::kPinhole, 400.0, {}), std::nullopt));
  const std::string text = FormatCamchain(camchain);
  EXPECT_EQ(text,
            "cam0:\n"
            "  cam_overlaps: []\n"
            "  camera_model: pinhole\n"
            "  distortion_coeffs: []\n"
            "  distortion_model: none\n"
            "  intrinsics: [400.0, 400.25, 360.5, 271.0]\n"
            "  resolution: [720, 540]\n");
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
}

// The models of issue 21. ds and eucm as Kalibr writes them (the camera
// model, its two parameters before fu, fv, pu, pv, distortion_model none);
// rational as rcm's extension (a pinhole with 8 distortion_coeffs).
TEST(Camchain, DoubleSphereIsWrittenAsKalibrDoes) {
  Camchain camchain;
  camchain.cameras.push_back(
      MakeEntry(test::DoubleSphereCamera(), std::nullopt));
  const std::string text = FormatCamchain(camchain);
  EXPECT_EQ(text,
            "cam0:\n"
            "  cam_overlaps: []\n"
            "  camera_model: ds\n"
            "  distortion_coeffs: []\n"
            "  distortion_model: none\n"
            "  intrinsics: [-0.18, 0.59, 300.2, 299.7, 318.4, 241.9]\n"
            "  resolution: [640, 480]\n");
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
  EXPECT_EQ(FormatCamchain(*parsed), text);
}

TEST(Camchain, NewModelsRoundTripBitExactly) {
  Camchain camchain;
  camchain.cameras.push_back(MakeEntry(test::RationalCamera(), std::nullopt));
  camchain.cameras.push_back(
      MakeEntry(test::EucmCamera(),
                MakeTransform(Eigen::Vector3d(0.002, 0.0003, -0.0004),
                              Eigen::Vector3d(-0.11, 0.0004, -0.0009))));
  camchain.cameras.push_back(
      MakeEntry(test::DoubleSphereCamera(),
                MakeTransform(Eigen::Vector3d(-0.001, 0.0002, 0.0001),
                              Eigen::Vector3d(-0.09, 0.0001, 0.0002))));
  const std::string text = FormatCamchain(camchain);
  EXPECT_THAT(text, HasSubstr("  camera_model: pinhole\n  distortion_coeffs: "
                              "[0.5, 0.1, 0.0009, -0.0006, 0.001, 0.75, "
                              "0.2, 0.001]\n  distortion_model: rational\n"));
  EXPECT_THAT(text, HasSubstr("  camera_model: eucm\n  distortion_coeffs: []\n"
                              "  distortion_model: none\n  intrinsics: [0.63, "
                              "1.04, 320.4, 319.8, 321.1, 238.6]\n"));
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
  EXPECT_EQ(FormatCamchain(*parsed), text);
  // Through a file too.
  const std::string path = test::TempFilePath("new_models.yaml");
  ASSERT_TRUE(WriteCamchain(path, camchain).ok());
  const StatusOr<Camchain> read = ReadCamchain(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ExpectCamchainsBitwiseEqual(*read, camchain);
}

// A Kalibr ds camchain as Kalibr's own files have it, without the
// (empty) distortion_coeffs.
constexpr char kKalibrDs[] =
    "cam0:\n"
    "  camera_model: ds\n"
    "  distortion_model: none\n"
    "  intrinsics: [-0.2, 0.58, 190.5, 190.4, 254.9, 256.8]\n"
    "  resolution: [512, 512]\n";

TEST(Camchain, ReadsKalibrDoubleSphere) {
  const StatusOr<Camchain> parsed = ParseCamchain(kKalibrDs, "ds.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  const Camera& camera = parsed->cameras[0].camera;
  EXPECT_EQ(camera.model(), LensModelId::kDoubleSphere);
  EXPECT_EQ(camera.Distortion(), (std::vector<double>{-0.2, 0.58}));
  EXPECT_EQ(camera.fx(), 190.5);
  EXPECT_EQ(camera.cy(), 256.8);
}

TEST(Camchain, RejectsBadNewModelEntries) {
  const auto error = [](const std::string& text) {
    const StatusOr<Camchain> parsed = ParseCamchain(text, "ds.yaml");
    return parsed.ok() ? std::string() : parsed.status().message();
  };
  EXPECT_EQ(error(ReplaceOnce(kKalibrDs, "[-0.2, 0.58, ", "[1.2, 0.58, ")),
            "ds.yaml:4: cam0.intrinsics: ds xi = 1.2 is outside (-1, 1]");
  EXPECT_EQ(error(ReplaceOnce(kKalibrDs, "[-0.2, 0.58, ", "[-0.2, 1.5, ")),
            "ds.yaml:4: cam0.intrinsics: ds alpha = 1.5 is outside [0, 1]");
  EXPECT_EQ(error(ReplaceOnce(ReplaceOnce(kKalibrDs, "ds\n", "eucm\n"),
                              "[-0.2, 0.58, ", "[0.6, -1, ")),
            "ds.yaml:4: cam0.intrinsics: eucm beta = -1 is outside (0, 1000]");
  EXPECT_THAT(error(ReplaceOnce(kKalibrDs, "[-0.2, 0.58, ", "[")),
              HasSubstr("cam0.intrinsics: expected 6"));
  EXPECT_EQ(error(ReplaceOnce(kKalibrDs, "model: none", "model: radtan")),
            "ds.yaml:3: cam0.distortion_model: camera_model 'ds' takes "
            "distortion_model 'none', got 'radtan'");
  EXPECT_THAT(
      error(ReplaceOnce(ReplaceOnce(kKalibrDs, "model: ds", "model: pinhole"),
                        "model: none", "model: ds")),
      HasSubstr("unknown model 'ds' (supported: none, radtan, "
                "equidistant, rational; 'ds' is a camera_model, "
                "with distortion_model 'none')"));
  EXPECT_EQ(error(ReplaceOnce(kKalibrDs, "  distortion_model",
                              "  distortion_coeffs: [0.1]\n  "
                              "distortion_model")),
            "ds.yaml:3: cam0.distortion_coeffs: expected 0 numbers for "
            "camera_model 'ds', got 1");
  // A rational camera needs its 8 coefficients.
  EXPECT_THAT(
      error("cam0:\n  camera_model: pinhole\n  distortion_coeffs: [0.1, 0.0, "
            "0.0, 0.0]\n  distortion_model: rational\n  intrinsics: [300, "
            "300, 320, 240]\n  resolution: [640, 480]\n"),
      HasSubstr("expected 8 numbers for distortion_model 'rational', got 4"));
}

TEST(Camchain, PortBlockRoundTrips) {
  Camchain camchain;
  camchain.cameras.push_back(
      MakeEntry(MakeCamera(LensModelId::kPinhole, 400.0, {}), std::nullopt));
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  port.glass_index = 1.517;
  port.normal = TiltedPortNormal(0.02, 0.3);
  camchain.cameras[0].port = port;
  const std::string text = FormatCamchain(camchain);
  EXPECT_NE(text.find("  port:\n"
                      "    air_gap: 0.008\n"
                      "    glass_index: 1.517\n"
                      "    glass_thickness: 0.006\n"
                      "    normal: ["),
            std::string::npos)
      << text;
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
}

TEST(Camchain, PortDefaultsToAcrylicAlongTheOpticalAxis) {
  const std::string text = ReplaceOnce(
      kMinimal, "  resolution: [720, 540]\ncam1:\n",
      "  resolution: [720, 540]\n  port: {air_gap: 0.01, glass_thickness: "
      "0.005}\ncam1:\n");
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_TRUE(parsed->cameras[0].port.has_value());
  EXPECT_FALSE(parsed->cameras[1].port.has_value());
  const FlatPort& port = *parsed->cameras[0].port;
  EXPECT_EQ(port.air_gap, 0.01);
  EXPECT_EQ(port.glass_thickness, 0.005);
  EXPECT_EQ(port.glass_index, 1.49);
  EXPECT_EQ(port.normal, Eigen::Vector3d::UnitZ());
}

TEST(Camchain, PortNormalIsNormalized) {
  const std::string text = ReplaceOnce(
      kMinimal, "  resolution: [720, 540]\ncam1:\n",
      "  resolution: [720, 540]\n  port: {air_gap: 0.01, glass_thickness: "
      "0.0, normal: [0, 0, 2]}\ncam1:\n");
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->cameras[0].port->normal, Eigen::Vector3d::UnitZ());
}

TEST(Camchain, RejectsBadPortBlocks) {
  const auto with_port = [](const std::string& port) {
    return ParseError(
        ReplaceOnce(kMinimal, "  resolution: [720, 540]\ncam1:\n",
                    "  resolution: [720, 540]\n  port: " + port + "\ncam1:\n"));
  };
  EXPECT_THAT(with_port("3"), HasSubstr("cam0.port: expected a map"));
  EXPECT_THAT(with_port("{glass_thickness: 0.005}"),
              HasSubstr("cam0.port: missing key 'air_gap'"));
  EXPECT_THAT(with_port("{air_gap: 0.01, glass_thickness: 0.0, gap_mm: 8}"),
              HasSubstr("cam0.port.gap_mm: unknown key"));
  // A key with a line break and a NUL (a double-quoted YAML key; found by
  // fuzz_calibration_yaml) is named escaped, on one line.
  const std::string control = with_port(
      "{air_gap: 0.01, glass_thickness: 0.0, \"glass\\nthi\\0ckness\": 1}");
  EXPECT_THAT(control,
              HasSubstr("cam0.port.glass\\x0athi\\x00ckness: unknown key"));
  EXPECT_EQ(control.find('\n'), std::string::npos) << control;
  EXPECT_THAT(with_port("{air_gap: -0.01, glass_thickness: 0.0}"),
              HasSubstr("port air_gap = -0.01 m is outside [0, 0.5]"));
  EXPECT_THAT(with_port("{air_gap: 8, glass_thickness: 0.0}"),
              HasSubstr("outside [0, 0.5]"));
  EXPECT_THAT(with_port("{air_gap: .nan, glass_thickness: 0.0}"),
              HasSubstr("cam0.port.air_gap"));
  EXPECT_THAT(
      with_port("{air_gap: 0.01, glass_thickness: 0.0, normal: [0, 1]}"),
      HasSubstr("cam0.port.normal"));
  EXPECT_THAT(
      with_port("{air_gap: 0.01, glass_thickness: 0.0, normal: [0, 1, 0]}"),
      HasSubstr("tilted 90 degrees"));
  EXPECT_THAT(
      with_port("{air_gap: 0.01, glass_thickness: 0.0, glass_index: 3}"),
      HasSubstr("glass_index = 3 is outside [1, 2]"));
}

TEST(Camchain, DomePortBlockRoundTrips) {
  Camchain camchain;
  camchain.cameras.push_back(
      MakeEntry(MakeCamera(LensModelId::kPinhole, 400.0, {}), std::nullopt));
  DomePort dome;
  dome.inner_radius = 0.04355;
  dome.thickness = 0.00375;
  dome.glass_index = 1.495;
  dome.decentering = Eigen::Vector3d(0.0001, -0.00005, 0.0072);
  camchain.cameras[0].dome = dome;
  const std::string text = FormatCamchain(camchain);
  EXPECT_NE(text.find("  port:\n"
                      "    decentering: [0.0001, -5.0e-05, 0.0072]\n"
                      "    glass_index: 1.495\n"
                      "    inner_radius: 0.04355\n"
                      "    thickness: 0.00375\n"
                      "    type: dome\n"),
            std::string::npos)
      << text;
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectCamchainsBitwiseEqual(*parsed, camchain);
  EXPECT_FALSE(parsed->cameras[0].port.has_value());
}

TEST(Camchain, DomeGivenByItsRadii) {
  const std::string text = ReplaceOnce(
      kMinimal, "  resolution: [720, 540]\ncam1:\n",
      "  resolution: [720, 540]\n  port: {type: dome, inner_radius: 0.04355, "
      "outer_radius: 0.0473}\ncam1:\n");
  const StatusOr<Camchain> parsed = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_TRUE(parsed->cameras[0].dome.has_value());
  EXPECT_NEAR(parsed->cameras[0].dome->thickness, 0.00375, 1e-15);
  EXPECT_EQ(parsed->cameras[0].dome->glass_index, 1.49);
  EXPECT_TRUE(parsed->cameras[0].dome->IsCentred());
}

TEST(Camchain, RejectsBadDomeBlocks) {
  const auto with_port = [](const std::string& port) {
    return ParseError(
        ReplaceOnce(kMinimal, "  resolution: [720, 540]\ncam1:\n",
                    "  resolution: [720, 540]\n  port: " + port + "\ncam1:\n"));
  };
  EXPECT_THAT(with_port("{type: globe, inner_radius: 0.05}"),
              HasSubstr("cam0.port.type: unknown port type 'globe'"));
  EXPECT_THAT(with_port("{type: dome, thickness: 0.005}"),
              HasSubstr("cam0.port: missing key 'inner_radius'"));
  EXPECT_THAT(with_port("{type: dome, inner_radius: 0.05}"),
              HasSubstr("cam0.port: missing key 'thickness'"));
  EXPECT_THAT(with_port("{type: dome, inner_radius: 0.05, thickness: 0.005, "
                        "air_gap: 0.01}"),
              HasSubstr("cam0.port.air_gap: unknown key (a dome port has"));
  EXPECT_THAT(
      with_port("{type: dome, inner_radius: 0.04355, outer_radius: 0.0473, "
                "thickness: 0.005}"),
      HasSubstr("not the 0.005 m given"));
  EXPECT_THAT(with_port("{type: dome, inner_radius: 0.04355, thickness: "
                        "0.00375, decentering: [0, 0, 0.05]}"),
              HasSubstr("outside the inner sphere"));
  EXPECT_THAT(with_port("{type: dome, inner_radius: 43.55, thickness: 3.75}"),
              HasSubstr("millimetres given as metres"));
}

TEST(Camchain, DomeCameraIsRefusedByTheStereoRig) {
  Camchain camchain = CamchainFromStereoRig(test::AlphasenseRealisticRig());
  camchain.cameras[1].dome = DomePort();
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain, 0, 1);
  ASSERT_FALSE(rig.ok());
  EXPECT_THAT(rig.status().message(),
              HasSubstr("cam1 looks through a dome port"));
}

TEST(Camchain, NoneModelMayOmitCoefficients) {
  const StatusOr<Camchain> camchain = ParseCamchain(
      "cam0:\n"
      "  camera_model: pinhole\n"
      "  distortion_model: none\n"
      "  intrinsics: [400.0, 400.0, 360.0, 270.0]\n"
      "  resolution: [720, 540]\n",
      "rig.yaml");
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  EXPECT_EQ(camchain->cameras[0].camera.model(), LensModelId::kPinhole);
  EXPECT_TRUE(camchain->cameras[0].cam_overlaps.empty());
  EXPECT_TRUE(camchain->cameras[0].rostopic.empty());
}

TEST(Camchain, WriteAndReadRoundTripThroughFile) {
  const StatusOr<Camchain> camchain = ParseCamchain(kAlphasense, "rig.yaml");
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  const std::string path = test::TempFilePath("write_read.yaml");
  ASSERT_TRUE(WriteCamchain(path, *camchain).ok());
  const StatusOr<std::string> bytes = ReadFileToString(path);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  EXPECT_EQ(*bytes, kAlphasense);
  const StatusOr<Camchain> read = ReadCamchain(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ExpectCamchainsBitwiseEqual(*read, *camchain);
}

TEST(Camchain, WriteRejectsMissingTcnCnm1) {
  Camchain camchain;
  camchain.cameras.push_back(
      MakeEntry(MakeCamera(LensModelId::kPinhole, 400.0, {}), std::nullopt));
  camchain.cameras.push_back(
      MakeEntry(MakeCamera(LensModelId::kPinhole, 400.0, {}), std::nullopt));
  const std::string path = test::TempFilePath("missing_t.yaml");
  const Status status = WriteCamchain(path, camchain);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), path + ": cannot write: cam1 has no T_cn_cnm1");
  EXPECT_FALSE(ReadFileToString(path).ok());
}

// --- Stereo pairs
// -------------------------------------------------------------

class CamchainStereo : public ::testing::Test {
 protected:
  void SetUp() override {
    cam1_from_cam0_ = MakeTransform(Eigen::Vector3d(0.002, -0.011, 0.0015),
                                    Eigen::Vector3d(-0.11, 0.0004, -0.0002));
    cam2_from_cam1_ = MakeTransform(Eigen::Vector3d(-0.01, 0.03, 0.002),
                                    Eigen::Vector3d(-0.09, 0.002, 0.001));
    camchain_.cameras.push_back(MakeEntry(
        MakeCamera(LensModelId::kEquidistant, 346.0, {-0.03, 0.0, 0.0, 0.0}),
        std::nullopt));
    camchain_.cameras.push_back(
        MakeEntry(MakeCamera(LensModelId::kRadTan, 344.0, {0.1, 0.0, 0.0, 0.0}),
                  cam1_from_cam0_));
    camchain_.cameras.push_back(MakeEntry(
        MakeCamera(LensModelId::kPinhole, 500.0, {}), cam2_from_cam1_));
  }

  Camchain camchain_;
  Rigid3d cam1_from_cam0_;
  Rigid3d cam2_from_cam1_;
};

TEST_F(CamchainStereo, AdjacentPairUsesTcnCnm1) {
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain_, 0, 1);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_TRUE(TransformsBitwiseEqual(rig->right_from_left(), cam1_from_cam0_));
  EXPECT_TRUE(CamerasBitwiseEqual(rig->left(), camchain_.cameras[0].camera));
  EXPECT_TRUE(CamerasBitwiseEqual(rig->right(), camchain_.cameras[1].camera));
}

TEST_F(CamchainStereo, ChainsTransformsAcrossCameras) {
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain_, 0, 2);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  const Rigid3d expected = cam2_from_cam1_ * cam1_from_cam0_;
  EXPECT_TRUE(
      rig->right_from_left().rotation.isApprox(expected.rotation, 1e-12));
  EXPECT_LT((rig->right_from_left().translation - expected.translation)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_TRUE(CamerasBitwiseEqual(rig->right(), camchain_.cameras[2].camera));
}

TEST_F(CamchainStereo, ReversedPairIsTheInverse) {
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain_, 2, 0);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  const Rigid3d expected = (cam2_from_cam1_ * cam1_from_cam0_).Inverse();
  EXPECT_LT((rig->right_from_left().rotation - expected.rotation)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_LT((rig->right_from_left().translation - expected.translation)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_TRUE(CamerasBitwiseEqual(rig->left(), camchain_.cameras[2].camera));
  EXPECT_TRUE(CamerasBitwiseEqual(rig->right(), camchain_.cameras[0].camera));
}

TEST_F(CamchainStereo, RejectsIndexOutOfRange) {
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain_, 0, 3);
  ASSERT_FALSE(rig.ok());
  EXPECT_EQ(rig.status().message(),
            "camera index 3 is out of range (the camchain has cam0..cam2)");
}

TEST_F(CamchainStereo, RejectsNegativeIndex) {
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain_, -1, 0);
  ASSERT_FALSE(rig.ok());
  EXPECT_THAT(rig.status().message(), StartsWith("camera index -1 is out"));
}

TEST_F(CamchainStereo, RejectsSameCamera) {
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(camchain_, 1, 1);
  ASSERT_FALSE(rig.ok());
  EXPECT_EQ(rig.status().message(),
            "left and right are the same camera (cam1)");
}

TEST(Camchain, StereoRigRejectsZeroBaseline) {
  const std::string text =
      ReplaceOnce(ReplaceOnce(ReplaceOnce(kMinimal, "-0.11018]", "0.0]"),
                              "0.00041]", "0.0]"),
                  "-0.00023]", "0.0]");
  const StatusOr<Camchain> camchain = ParseCamchain(text, "rig.yaml");
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  const StatusOr<StereoRig> rig = StereoRigFromCamchain(*camchain, 0, 1);
  ASSERT_FALSE(rig.ok());
  EXPECT_THAT(rig.status().message(),
              StartsWith("cam1_from_cam0: zero baseline (|t| = 0 m)"));
}

// --- Malformed input
// ----------------------------------------------------------

TEST(Camchain, MinimalFixtureIsValid) { EXPECT_EQ(ParseError(kMinimal), ""); }

TEST(Camchain, RejectsMissingKey) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal,
                                   "  intrinsics: [344.4, 344.2, 358.7, "
                                   "262.0]\n",
                                   "")),
            "rig.yaml: cam1: missing key 'intrinsics'");
}

TEST(Camchain, RejectsWrongIntrinsicsLength) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[344.4, 344.2, 358.7, 262.0]",
                                   "[344.4, 344.2, 358.7]")),
            "rig.yaml:18: cam1.intrinsics: expected 4 numbers, got 3");
}

TEST(Camchain, RejectsIntrinsicsThatAreNotAList) {
  EXPECT_EQ(ParseError(
                ReplaceOnce(kMinimal, "[344.4, 344.2, 358.7, 262.0]", "344.4")),
            "rig.yaml:18: cam1.intrinsics: expected 4 numbers, got '344.4'");
}

TEST(Camchain, RejectsWrongCoefficientCount) {
  EXPECT_EQ(ParseError(
                ReplaceOnce(kMinimal, "[-0.0379, -0.00098, -0.00096, 2.36e-05]",
                            "[-0.0379, -0.00098, -0.00096, 2.36e-05, 0.0]")),
            "rig.yaml:4: cam0.distortion_coeffs: expected 4 numbers for "
            "distortion_model 'equidistant', got 5");
}

TEST(Camchain, RejectsCoefficientsForNoneModel) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal,
                                   "  distortion_model: equidistant\n  "
                                   "intrinsics: [346.7",
                                   "  distortion_model: none\n  intrinsics: "
                                   "[346.7")),
            "rig.yaml:4: cam0.distortion_coeffs: expected 0 numbers for "
            "distortion_model 'none', got 4");
}

TEST(Camchain, RejectsMissingCoefficientsForEquidistant) {
  EXPECT_EQ(ParseError(
                ReplaceOnce(kMinimal,
                            "  distortion_coeffs: [-0.0397, 0.00161, -0.00233, "
                            "0.00035]\n",
                            "")),
            "rig.yaml: cam1: missing key 'distortion_coeffs'");
}

TEST(Camchain, RejectsUnknownCameraModel) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal,
                                   "camera_model: pinhole\n  distortion_coeffs:"
                                   " [-0.0379",
                                   "camera_model: omni\n  distortion_coeffs: "
                                   "[-0.0379")),
            "rig.yaml:3: cam0.camera_model: unknown model 'omni' (supported: "
            "pinhole, ds, eucm)");
}

TEST(Camchain, RejectsUnknownDistortionModel) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal,
                                   "  distortion_model: equidistant\n  "
                                   "intrinsics: [346.7",
                                   "  distortion_model: fov\n  intrinsics: "
                                   "[346.7")),
            "rig.yaml:5: cam0.distortion_model: unknown model 'fov' "
            "(supported: none, radtan, equidistant, rational)");
}

TEST(Camchain, RejectsNonOrthonormalRotation) {
  EXPECT_THAT(
      ParseError(ReplaceOnce(kMinimal, "[0.9999348757308079,", "[0.99,")),
      StartsWith("rig.yaml:10: cam1.T_cn_cnm1: not a rigid transform: "
                 "rotation is not orthonormal (max |R^T R - I| = "));
}

TEST(Camchain, RejectsReflection) {
  EXPECT_EQ(
      ParseError(ReplaceOnce(kMinimal,
                             "[0.011301426373188565, 0.00209091297076075, "
                             "0.9999339507411878,",
                             "[-0.011301426373188565, -0.00209091297076075, "
                             "-0.9999339507411878,")),
      "rig.yaml:10: cam1.T_cn_cnm1: not a rigid transform: rotation has "
      "determinant -1 (a reflection)");
}

TEST(Camchain, RejectsBadLastRow) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[0.0, 0.0, 0.0, 1.0]",
                                   "[0.0, 0.0, 0.1, 1.0]")),
            "rig.yaml:10: cam1.T_cn_cnm1: not a rigid transform: last row is "
            "[  0   0 0.1   1], expected [0 0 0 1]");
}

TEST(Camchain, RejectsShortMatrixRow) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[0.0, 0.0, 0.0, 1.0]",
                                   "[0.0, 0.0, 1.0]")),
            "rig.yaml:13: cam1.T_cn_cnm1 row 4: expected 4 numbers, got 3");
}

TEST(Camchain, RejectsMatrixWithThreeRows) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "  - [0.0, 0.0, 0.0, 1.0]\n", "")),
            "rig.yaml:10: cam1.T_cn_cnm1: expected a 4x4 matrix (4 rows of 4 "
            "numbers), got 3 rows");
}

TEST(Camchain, RejectsNonPositiveFocalLength) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[346.7, 346.8, 360.5, 271.0]",
                                   "[-300, 346.8, 360.5, 271.0]")),
            "rig.yaml:6: cam0.intrinsics: focal length must be positive, got "
            "fx = -300");
}

TEST(Camchain, RejectsNonPositiveResolution) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "271.0]\n  resolution: [720, 540]",
                                   "271.0]\n  resolution: [0, 540]")),
            "rig.yaml:7: cam0.resolution: image size must be positive, got 0 "
            "x 540");
}

TEST(Camchain, RejectsNonIntegerResolution) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "271.0]\n  resolution: [720, 540]",
                                   "271.0]\n  resolution: [720.5, 540]")),
            "rig.yaml:7: cam0.resolution: '720.5' is not an integer");
}

TEST(Camchain, RejectsNonNumber) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[344.4, 344.2, 358.7, 262.0]",
                                   "[344.4, abc, 358.7, 262.0]")),
            "rig.yaml:18: cam1.intrinsics: 'abc' is not a number");
}

TEST(Camchain, RejectsNonFiniteNumber) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[344.4, 344.2, 358.7, 262.0]",
                                   "[344.4, nan, 358.7, 262.0]")),
            "rig.yaml:18: cam1.intrinsics: 'nan' is not a finite number");
}

TEST(Camchain, RejectsYamlInfinity) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[344.4, 344.2, 358.7, 262.0]",
                                   "[344.4, 344.2, -.inf, 262.0]")),
            "rig.yaml:18: cam1.intrinsics: '-.inf' is not a finite number");
}

TEST(Camchain, RejectsNumberOutOfRange) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[344.4, 344.2, 358.7, 262.0]",
                                   "[344.4, 1e999, 358.7, 262.0]")),
            "rig.yaml:18: cam1.intrinsics: '1e999' is out of range");
}

TEST(Camchain, RejectsYamlSyntaxError) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "[346.7, 346.8, 360.5, 271.0]",
                                   "[346.7, 346.8, 360.5, 271.0")),
            "rig.yaml:7: YAML syntax error: end of sequence flow not found");
}

// Found by fuzz_calibration_yaml: yaml-cpp's message quotes the offending
// character raw, here an escape byte (0x1b) after a backslash in a
// double-quoted string; the error must stay one line.
TEST(Camchain, YamlSyntaxErrorIsOneLineWhateverTheCharacter) {
  EXPECT_EQ(ParseError("cam0:\n  rostopic: \"a\\\x1b[31m\"\n"),
            "rig.yaml:2: YAML syntax error: unknown escape character: \\x1b");
}

TEST(Camchain, RejectsEmptyFile) {
  EXPECT_EQ(ParseError(""), "rig.yaml: empty file");
}

TEST(Camchain, RejectsCommentOnlyFile) {
  EXPECT_EQ(ParseError("# nothing here\n"), "rig.yaml: empty file");
}

TEST(Camchain, RejectsTopLevelList) {
  EXPECT_EQ(ParseError("- cam0\n- cam1\n"),
            "rig.yaml:1: top level is not a map (expected cam0, cam1, ...), "
            "got a list");
}

TEST(Camchain, RejectsMissingCam0) {
  EXPECT_EQ(ParseError("camera_model: pinhole\n"),
            "rig.yaml: no 'cam0' key: not a Kalibr camchain");
}

TEST(Camchain, RejectsCameraThatIsNotAMap) {
  EXPECT_EQ(ParseError("cam0: pinhole\n"),
            "rig.yaml:1: cam0: expected a map of camera parameters, got "
            "'pinhole'");
}

TEST(Camchain, RejectsDuplicateCamera) {
  const std::string text = kMinimal;
  const std::string cam1 = text.substr(text.find("cam1:"));
  EXPECT_EQ(ParseError(text + cam1), "rig.yaml:20: duplicate key 'cam1'");
}

TEST(Camchain, RejectsDuplicateKeyInCamera) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "cam1:\n",
                                   "  resolution: [640, 480]\ncam1:\n")),
            "rig.yaml:8: cam0: duplicate key 'resolution'");
}

TEST(Camchain, RejectsNonConsecutiveCameras) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "cam1:", "cam2:")),
            "rig.yaml:8: cameras must be numbered cam0, cam1, ... without "
            "gaps: found cam2 but no cam1");
}

TEST(Camchain, RejectsLeadingZeroCameraIndex) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "cam1:", "cam01:")),
            "rig.yaml:8: malformed camera key 'cam01' (expected cam0, cam1, "
            "...)");
}

TEST(Camchain, RejectsMissingTcnCnm1OnCam1) {
  const std::string text = kMinimal;
  const size_t start = text.find("  T_cn_cnm1:\n");
  const size_t end = text.find("  cam_overlaps: [0]");
  const std::string without = text.substr(0, start) + text.substr(end);
  EXPECT_EQ(ParseError(without), "rig.yaml: cam1: missing key 'T_cn_cnm1'");
}

TEST(Camchain, RejectsTcnCnm1OnCam0) {
  EXPECT_EQ(ParseError(ReplaceOnce(kMinimal, "cam0:\n",
                                   "cam0:\n  T_cn_cnm1: [[1, 0, 0, 0], [0, 1, "
                                   "0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n")),
            "rig.yaml:2: cam0.T_cn_cnm1: cam0 is the first camera and has no "
            "previous camera; T_cn_cnm1 belongs on cam1 and later");
}

TEST(Camchain, ErrorStaysOnOneLine) {
  // A multi-line scalar quoted in a message must not break the line.
  const std::string message = ParseError(ReplaceOnce(
      kMinimal, "camera_model: pinhole\n  distortion_coeffs: [-0.0379",
      "camera_model: \"pin\\nhole\"\n  distortion_coeffs: [-0.0379"));
  EXPECT_EQ(message,
            "rig.yaml:3: cam0.camera_model: unknown model 'pin\\x0ahole' "
            "(supported: pinhole, ds, eucm)");
}

TEST(Camchain, ReadRejectsMissingFile) {
  const std::string path = test::TempFilePath("does_not_exist.yaml");
  const StatusOr<Camchain> camchain = ReadCamchain(path);
  ASSERT_FALSE(camchain.ok());
  EXPECT_EQ(camchain.status().message(),
            path + ": cannot open: No such file or directory");
}

TEST(Camchain, ReadRejectsDirectory) {
  const std::string path = ::testing::TempDir();
  const StatusOr<Camchain> camchain = ReadCamchain(path);
  ASSERT_FALSE(camchain.ok());
  EXPECT_THAT(camchain.status().message(), HasSubstr(": is a directory"));
}

TEST(Camchain, ReadPrefixesErrorsWithThePath) {
  const std::string path = test::WriteTempFile(
      "bad_model.yaml", ReplaceOnce(kMinimal,
                                    "  distortion_model: equidistant\n"
                                    "  intrinsics: [346.7",
                                    "  distortion_model: fov\n"
                                    "  intrinsics: [346.7"));
  const StatusOr<Camchain> camchain = ReadCamchain(path);
  ASSERT_FALSE(camchain.ok());
  EXPECT_THAT(camchain.status().message(),
              StartsWith(path + ":5: cam0.distortion_model: unknown model"));
}

}  // namespace
}  // namespace rcm::camchain_test

namespace rcm::camchain_test {
namespace {

TEST(CamchainCameraIndex, ReadsCanonicalNamesOnly) {
  EXPECT_EQ(CamchainCameraIndex("cam0"), 0);
  EXPECT_EQ(CamchainCameraIndex("cam12"), 12);
  EXPECT_FALSE(CamchainCameraIndex("cam").has_value());
  EXPECT_FALSE(CamchainCameraIndex("cam01").has_value());
  EXPECT_FALSE(CamchainCameraIndex("cam-1").has_value());
  EXPECT_FALSE(CamchainCameraIndex("cam1x").has_value());
  EXPECT_FALSE(CamchainCameraIndex("camera").has_value());
  EXPECT_FALSE(CamchainCameraIndex("cam99999999999").has_value());
}

TEST(Camchain, FromStereoRigReadsBackAsTheSameRig) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const Camchain camchain = CamchainFromStereoRig(rig);
  const Camchain parsed =
      ParseCamchain(FormatCamchain(camchain), "rig.yaml").value();
  const StereoRig back = StereoRigFromCamchain(parsed, 0, 1).value();
  EXPECT_EQ(back.left(), rig.left());
  EXPECT_EQ(back.right(), rig.right());
  EXPECT_EQ(back.right_from_left().rotation, rig.right_from_left().rotation);
  EXPECT_EQ(back.right_from_left().translation,
            rig.right_from_left().translation);
  EXPECT_EQ(parsed.cameras[0].cam_overlaps, std::vector<int>{1});
}

}  // namespace
}  // namespace rcm::camchain_test

namespace rcm::camchain_test {
namespace {

TEST(Camchain, PortBlocksBecomeTheRigsPorts) {
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  StereoRig rig = test::AlphasenseRealisticRig();
  Camchain camchain = CamchainFromStereoRig(rig);
  camchain.cameras[1].port = port;
  const StatusOr<StereoRig> read = StereoRigFromCamchain(
      ParseCamchain(FormatCamchain(camchain), "rig.yaml").value(), 0, 1);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_TRUE(read->ports().has_value());
  EXPECT_TRUE(read->ports()->left.IsThin());  // no block: the thin port
  EXPECT_EQ(read->ports()->right, port);
  EXPECT_TRUE(read->HasThickPort());
  // And back: the rig's ports are written as port blocks.
  const Camchain written = CamchainFromStereoRig(*read);
  ASSERT_TRUE(written.cameras[1].port.has_value());
  EXPECT_EQ(*written.cameras[1].port, port);
  // A camchain without port blocks gives a rig without ports.
  EXPECT_FALSE(StereoRigFromCamchain(CamchainFromStereoRig(rig), 0, 1)
                   ->ports()
                   .has_value());
}

}  // namespace
}  // namespace rcm::camchain_test
