// NumPy <-> library conversions shared by the binding files: coordinate
// arrays (converted once, in C++), correspondences, paths, images.
//
// Coordinates: any array-like of real numbers (float64, float32, integer;
// non-contiguous arrays and lists are converted); bool, complex, object and
// string arrays, a wrong shape, an empty array and NaN/inf entries are
// refused with one-line ValueErrors (TypeError for a non-numeric dtype).
#ifndef RCM_PYTHON_SRC_CONVERSIONS_H_
#define RCM_PYTHON_SRC_CONVERSIONS_H_

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/geometry/rigid3d.h"
#include "rcm/geometry/stereo_correspondence.h"

namespace rcm::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style>;

// What the bindings return for a value that does not exist (NaN).
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A C-contiguous float64 copy (or view) of `object` of shape (N, cols), or
// (cols,) when `allow_single` (then `single` is set and the caller returns
// one row as a 1-D array). Errors name `name`: "pixels must have shape
// (N, 2), got (5, 3)". `allow_empty`: N = 0 accepted. `finite`: NaN/inf
// refused.
struct Rows {
  DoubleArray array;
  int64_t rows = 0;
  bool single = false;
  const double* data() const { return array.data(); }
};
Rows RowsFromPython(const py::handle& object, const std::string& name, int cols,
                    bool allow_single = true, bool allow_empty = false,
                    bool finite = true);

// A 1-D array-like of finite numbers of any length (a list, a tuple).
std::vector<double> VectorFromPython(const py::handle& object,
                                     const std::string& name);
// A fixed-size vector or matrix of finite numbers from an array-like.
Eigen::Vector3d Vector3FromPython(const py::handle& object,
                                  const std::string& name);
Eigen::Matrix4d Matrix4FromPython(const py::handle& object,
                                  const std::string& name);
// A seed: an int in [0, 2^64) (TypeError for another type, ValueError out
// of range).
uint64_t SeedFromPython(const py::handle& object, const std::string& name);
// An int (not a bool) in the range of int.
int IntFromPython(const py::handle& object, const std::string& name);
// One finite number (ValueError for NaN/inf, TypeError for a non-number).
double FiniteDouble(const py::handle& object, const std::string& name);

// A pose as a TUM row [tx, ty, tz, qx, qy, qz, qw] (+ 0.0: no "-0").
void TumRow(const Rigid3d& pose, double row[7]);

// A new float64 array of shape (rows, cols), or (cols,) when `single`.
DoubleArray NewArray(int64_t rows, int cols, bool single = false);
// A copy of an Eigen value: a 1-D array for a compile-time column vector,
// else 2-D (rows, cols), C order.
template <typename Derived>
DoubleArray ToNumpy(const Eigen::MatrixBase<Derived>& value) {
  const Eigen::MatrixXd matrix = value.template cast<double>();
  const bool vector = Derived::ColsAtCompileTime == 1;
  DoubleArray array =
      vector
          ? DoubleArray(std::vector<py::ssize_t>{matrix.rows()})
          : DoubleArray(std::vector<py::ssize_t>{matrix.rows(), matrix.cols()});
  double* data = array.mutable_data();
  for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) {
      data[r * matrix.cols() + c] = matrix(r, c);
    }
  }
  return array;
}

// rcm.Correspondences: the library's correspondences, held in C++ so that
// an estimator takes them without a conversion.
struct Correspondences {
  std::vector<StereoCorrespondence> matches;
};

// The correspondences of anything the estimators accept:
//   an rcm.Correspondences;
//   a mapping with arrays xl, yl, xr, yr (and optionally frame, t), e.g.
//     the dict of rcm.Correspondences.to_dict();
//   an (N, 4) array [xl, yl, xr, yr] (all frame 0) or an (N, 5) array
//     [frame, xl, yl, xr, yr].
// Frames must be non-negative integers, non-decreasing (as in a
// correspondence file); coordinates finite; N >= 1 unless allow_empty.
std::vector<StereoCorrespondence> MatchesFromPython(const py::handle& object,
                                                    const std::string& name,
                                                    bool allow_empty = false);

// os.fspath(object) as UTF-8: str, bytes or any os.PathLike.
std::string PathFromPython(const py::handle& object);

// An 8-bit image (H, W), (H, W, 1), (H, W, 3) or (H, W, 4) as a cv::Mat
// viewing the array's memory (kept alive by `keep`: hold it while the Mat
// is used). Any other dtype or shape: ValueError naming `name`.
cv::Mat ImageFromPython(const py::handle& object, const std::string& name,
                        py::object* keep);
// A copy of an 8-bit (1 or 3 channel) or float32 image as a NumPy array.
py::array ImageToNumpy(const cv::Mat& image);

}  // namespace rcm::python

#endif  // RCM_PYTHON_SRC_CONVERSIONS_H_
