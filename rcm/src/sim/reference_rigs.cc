#include "rcm/sim/reference_rigs.h"

#include <Eigen/Geometry>
#include <cmath>

namespace rcm {

Camera AlphasenseFrontCam0() {
  return Camera::Create(LensModelId::kEquidistant, 720, 540,
                        {346.68681661781403, 346.7780959214622,
                         360.53325988648163, 271.0179819820658},
                        {-0.037934508908317364, -0.0009855550912794707,
                         -0.0009622185860956224, 2.365797666527927e-05})
      .value();
}

Camera AlphasenseFrontCam1() {
  return Camera::Create(LensModelId::kEquidistant, 720, 540,
                        {344.3933991977547, 344.2292927278568, 358.725925185576,
                         262.02195974034373},
                        {-0.03970881800919102, 0.0016107591002609727,
                         -0.002331667784337188, 0.00035009066006595556})
      .value();
}

Camera EurocCam0() {
  return Camera::Create(LensModelId::kRadTan, 752, 480,
                        {458.654, 457.296, 367.215, 248.375},
                        {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05})
      .value();
}

StereoRig AlphasenseFrontRectifiedRig() {
  Rigid3d right_from_left;
  right_from_left.translation = Eigen::Vector3d(-0.11, 0.0, 0.0);
  return StereoRig::Create(AlphasenseFrontCam0(), AlphasenseFrontCam1(),
                           right_from_left)
      .value();
}

StereoRig AlphasenseFrontUnrectifiedRig() {
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(0.5 * M_PI / 180.0,
                        Eigen::Vector3d(0.3, 1.0, -0.4).normalized())
          .toRotationMatrix();
  right_from_left.translation = Eigen::Vector3d(-0.11, 0.0015, -0.002);
  return StereoRig::Create(AlphasenseFrontCam0(), AlphasenseFrontCam1(),
                           right_from_left)
      .value();
}

Camera NarrowFieldCam0() {
  return Camera::Create(LensModelId::kRadTan, 640, 480,
                        {502.37, 501.84, 321.62, 238.41},
                        {-0.1183, 0.0521, 1.2e-4, -8.0e-5})
      .value();
}

Camera NarrowFieldCam1() {
  return Camera::Create(LensModelId::kRadTan, 640, 480,
                        {498.61, 498.93, 317.35, 242.87},
                        {-0.1231, 0.0478, -9.0e-5, 1.5e-4})
      .value();
}

StereoRig NarrowFieldRig() {
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(kNarrowFieldToeIn, Eigen::Vector3d::UnitY())
          .toRotationMatrix();
  right_from_left.translation =
      -(right_from_left.rotation *
        Eigen::Vector3d(kNarrowFieldBaseline, 0.0, 0.0));
  return StereoRig::Create(NarrowFieldCam0(), NarrowFieldCam1(),
                           right_from_left)
      .value();
}

}  // namespace rcm
