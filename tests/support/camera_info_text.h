// ROS camera_info YAML text for the tests, laid out as the ROS
// camera_calibration_parsers write it.
#ifndef RCM_TESTS_SUPPORT_CAMERA_INFO_TEXT_H_
#define RCM_TESTS_SUPPORT_CAMERA_INFO_TEXT_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rcm/util/number_format.h"

namespace rcm::test {

// "[a, b, c]" with the values as FormatDouble prints them.
inline std::string YamlFlowList(const double* values, int size) {
  std::string text = "[";
  for (int i = 0; i < size; ++i) {
    text += (i == 0 ? "" : ", ") + FormatDouble(values[i]);
  }
  return text + "]";
}

// The camera_info of one 720x540 camera. The lines that tests point at:
//   7 camera_matrix.data   8 distortion_model   12 distortion data
//  16 rectification data  20 projection data
inline std::string CameraInfoText(
    const std::string& name, const Eigen::Matrix3d& camera_matrix,
    const std::vector<double>& distortion, const Eigen::Matrix3d& rectification,
    const Eigen::Matrix<double, 3, 4>& projection) {
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> k = camera_matrix;
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = rectification;
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> p = projection;
  const int num_coefficients = static_cast<int>(distortion.size());
  return "image_width: 720\n"
         "image_height: 540\n"
         "camera_name: " +
         name +
         "\n"
         "camera_matrix:\n"
         "  rows: 3\n"
         "  cols: 3\n"
         "  data: " +
         YamlFlowList(k.data(), 9) +
         "\n"
         "distortion_model: plumb_bob\n"
         "distortion_coefficients:\n"
         "  rows: 1\n"
         "  cols: " +
         std::to_string(num_coefficients) +
         "\n"
         "  data: " +
         YamlFlowList(distortion.data(), num_coefficients) +
         "\n"
         "rectification_matrix:\n"
         "  rows: 3\n"
         "  cols: 3\n"
         "  data: " +
         YamlFlowList(r.data(), 9) +
         "\n"
         "projection_matrix:\n"
         "  rows: 3\n"
         "  cols: 4\n"
         "  data: " +
         YamlFlowList(p.data(), 12) + "\n";
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_CAMERA_INFO_TEXT_H_
