#include "conversions.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "errors.h"

namespace rcm::python {
namespace {

std::string ShapeText(const py::array& array) {
  std::ostringstream text;
  text << "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) {
    if (i > 0) text << ", ";
    text << array.shape(i);
  }
  if (array.ndim() == 1) text << ",";
  text << ")";
  return text.str();
}

// A number as the shortest text that reads back to it ("1e+300", "nan").
std::string NumberText(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

std::string DtypeText(const py::array& array) {
  return py::str(array.dtype()).cast<std::string>();
}

// np.asarray(object), refusing what is not an array of real numbers.
py::array NumericArray(const py::handle& object, const std::string& name) {
  py::array array;
  try {
    array = py::array::ensure(object);
  } catch (const py::error_already_set&) {
    array = py::array();
  }
  if (!array) {
    PyErr_Clear();
    ThrowTypeError(name + " must be an array of numbers, got " +
                   py::str(py::type::of(object)).cast<std::string>());
  }
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    ThrowTypeError(name + " must be an array of real numbers, got dtype " +
                   DtypeText(array));
  }
  return array;
}

DoubleArray AsDoubleArray(const py::array& array) {
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
      array);
}

}  // namespace

Rows RowsFromPython(const py::handle& object, const std::string& name, int cols,
                    bool allow_single, bool allow_empty, bool finite) {
  const py::array array = NumericArray(object, name);
  Rows rows;
  const std::string expected = "(N, " + std::to_string(cols) + ")";
  if (array.ndim() == 1 && allow_single && array.shape(0) == cols) {
    rows.single = true;
  } else if (array.ndim() != 2 || array.shape(1) != cols) {
    ThrowValueError(
        name + " must have shape " + expected +
        (allow_single ? " or (" + std::to_string(cols) + ",)" : std::string()) +
        ", got " + ShapeText(array));
  }
  rows.rows = rows.single ? 1 : array.shape(0);
  if (rows.rows == 0 && !allow_empty) {
    ThrowValueError(name + " is empty (shape " + ShapeText(array) + ")");
  }
  rows.array = AsDoubleArray(array);
  if (finite) {
    const double* data = rows.array.data();
    const int64_t size = rows.rows * cols;
    for (int64_t i = 0; i < size; ++i) {
      if (!std::isfinite(data[i])) {
        ThrowValueError(name + " has a non-finite value (" +
                        NumberText(data[i]) + ") in row " +
                        std::to_string(i / cols));
      }
    }
  }
  return rows;
}

std::vector<double> VectorFromPython(const py::handle& object,
                                     const std::string& name) {
  const py::array array = NumericArray(object, name);
  if (array.ndim() != 1) {
    ThrowValueError(name + " must be one-dimensional, got shape " +
                    ShapeText(array));
  }
  const DoubleArray values = AsDoubleArray(array);
  std::vector<double> result(values.data(), values.data() + values.size());
  for (const double value : result) {
    if (!std::isfinite(value)) {
      ThrowValueError(name + " has a non-finite value");
    }
  }
  return result;
}

uint64_t SeedFromPython(const py::handle& object, const std::string& name) {
  if (PyBool_Check(object.ptr()) || !PyIndex_Check(object.ptr())) {
    ThrowTypeError(name + " must be a non-negative int");
  }
  const py::int_ number = py::reinterpret_borrow<py::object>(object);
  if (number < py::int_(0) || number > py::int_(UINT64_MAX)) {
    ThrowValueError(name + " must be an int in [0, 2^64)");
  }
  return number.cast<uint64_t>();
}

int IntFromPython(const py::handle& object, const std::string& name) {
  if (PyBool_Check(object.ptr()) || !PyIndex_Check(object.ptr())) {
    ThrowTypeError(name + " must be an int, got " +
                   py::str(py::type::of(object)).cast<std::string>());
  }
  const py::int_ number = py::reinterpret_borrow<py::object>(object);
  if (number < py::int_(INT32_MIN) || number > py::int_(INT32_MAX)) {
    ThrowValueError(name + " is out of range");
  }
  return number.cast<int>();
}

double FiniteDouble(const py::handle& object, const std::string& name) {
  if (PyBool_Check(object.ptr()) || !PyNumber_Check(object.ptr()) ||
      PyComplex_Check(object.ptr())) {
    ThrowTypeError(name + " must be a number, got " +
                   py::str(py::type::of(object)).cast<std::string>());
  }
  const double value = PyFloat_AsDouble(object.ptr());
  if (PyErr_Occurred()) throw py::error_already_set();
  if (!std::isfinite(value)) {
    ThrowValueError(name + " must be finite, got " + NumberText(value));
  }
  return value;
}

Eigen::Vector3d Vector3FromPython(const py::handle& object,
                                  const std::string& name) {
  const Rows rows = RowsFromPython(object, name, 3, /*allow_single=*/true);
  if (!rows.single) {
    ThrowValueError(name + " must have shape (3,)");
  }
  return Eigen::Vector3d(rows.data()[0], rows.data()[1], rows.data()[2]);
}

Eigen::Matrix4d Matrix4FromPython(const py::handle& object,
                                  const std::string& name) {
  const py::array array = NumericArray(object, name);
  if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
    ThrowValueError(name + " must have shape (4, 4), got " + ShapeText(array));
  }
  const Rows rows = RowsFromPython(array, name, 4, /*allow_single=*/false);
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) matrix(r, c) = rows.data()[4 * r + c];
  }
  return matrix;
}

void TumRow(const Rigid3d& pose, double row[7]) {
  const Eigen::Quaterniond q(pose.rotation);
  const Eigen::Vector3d t = pose.translation + Eigen::Vector3d::Zero();
  const double values[7] = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
  std::copy(values, values + 7, row);
}

DoubleArray NewArray(int64_t rows, int cols, bool single) {
  if (single) return DoubleArray(std::vector<py::ssize_t>{cols});
  return DoubleArray(std::vector<py::ssize_t>{rows, cols});
}

namespace {

// Frames: non-negative integers, non-decreasing.
void CheckFrames(const std::vector<StereoCorrespondence>& matches,
                 const std::string& name) {
  for (size_t i = 1; i < matches.size(); ++i) {
    if (matches[i].frame < matches[i - 1].frame) {
      ThrowValueError(name + ": frame " + std::to_string(matches[i].frame) +
                      " in row " + std::to_string(i) + " after frame " +
                      std::to_string(matches[i - 1].frame) +
                      ": frames must not decrease");
    }
  }
}

int64_t FrameFromDouble(double value, const std::string& name, int64_t row) {
  if (!(value >= 0.0) || value != std::floor(value) || value > 9.0e15) {
    ThrowValueError(name + ": frame in row " + std::to_string(row) +
                    " must be a non-negative integer, got " +
                    NumberText(value));
  }
  return static_cast<int64_t>(value);
}

// One column of a mapping, as N doubles.
Rows Column(const py::handle& mapping, const char* key, const std::string& name,
            bool finite) {
  const py::object column = mapping[py::str(key)];
  const py::array array = NumericArray(column, name + "['" + key + "']");
  if (array.ndim() != 1) {
    ThrowValueError(name + "['" + key +
                    "'] must be one-dimensional, got shape " +
                    ShapeText(array));
  }
  Rows rows;
  rows.rows = array.shape(0);
  rows.array = AsDoubleArray(array);
  if (finite) {
    for (int64_t i = 0; i < rows.rows; ++i) {
      if (!std::isfinite(rows.data()[i])) {
        ThrowValueError(name + "['" + key +
                        "'] has a non-finite value in row " +
                        std::to_string(i));
      }
    }
  }
  return rows;
}

std::vector<StereoCorrespondence> MatchesFromMapping(const py::handle& mapping,
                                                     const std::string& name) {
  for (const char* key : {"xl", "yl", "xr", "yr"}) {
    if (!mapping.contains(py::str(key))) {
      ThrowValueError(name + " lacks the key '" + key +
                      "' (expected xl, yl, xr, yr, optionally frame and t)");
    }
  }
  const Rows xl = Column(mapping, "xl", name, true);
  const Rows yl = Column(mapping, "yl", name, true);
  const Rows xr = Column(mapping, "xr", name, true);
  const Rows yr = Column(mapping, "yr", name, true);
  std::optional<Rows> frame;
  std::optional<Rows> t;
  if (mapping.contains(py::str("frame")) &&
      !mapping[py::str("frame")].is_none()) {
    frame = Column(mapping, "frame", name, false);
  }
  if (mapping.contains(py::str("t")) && !mapping[py::str("t")].is_none()) {
    t = Column(mapping, "t", name, false);
  }
  const int64_t size = xl.rows;
  for (const Rows* column : {&yl, &xr, &yr}) {
    if (column->rows != size) {
      ThrowValueError(name + ": columns xl, yl, xr, yr differ in length");
    }
  }
  if ((frame && frame->rows != size) || (t && t->rows != size)) {
    ThrowValueError(name + ": columns frame and t must have the length of xl");
  }
  std::vector<StereoCorrespondence> matches(size);
  for (int64_t i = 0; i < size; ++i) {
    StereoCorrespondence& match = matches[i];
    match.left_pixel = {xl.data()[i], yl.data()[i]};
    match.right_pixel = {xr.data()[i], yr.data()[i]};
    if (frame) match.frame = FrameFromDouble(frame->data()[i], name, i);
    // NaN timestamps (to_dict's "none") stay unset; inf is refused.
    if (t && !std::isnan(t->data()[i])) {
      if (!std::isfinite(t->data()[i])) {
        ThrowValueError(name + "['t'] has a non-finite value in row " +
                        std::to_string(i));
      }
      match.timestamp = t->data()[i];
    }
  }
  return matches;
}

}  // namespace

std::vector<StereoCorrespondence> MatchesFromPython(const py::handle& object,
                                                    const std::string& name,
                                                    bool allow_empty) {
  std::vector<StereoCorrespondence> matches;
  if (py::isinstance<Correspondences>(object)) {
    matches = object.cast<const Correspondences&>().matches;
  } else if (PyDict_Check(object.ptr()) ||
             (!py::isinstance<py::array>(object) &&
              py::hasattr(object, "keys") &&
              py::hasattr(object, "__getitem__"))) {
    matches = MatchesFromMapping(object, name);
  } else {
    const py::array array = NumericArray(object, name);
    if (array.ndim() != 2 || (array.shape(1) != 4 && array.shape(1) != 5)) {
      ThrowValueError(name +
                      " must have shape (N, 4) [xl, yl, xr, yr] or (N, 5) "
                      "[frame, xl, yl, xr, yr], got " +
                      ShapeText(array));
    }
    const int cols = static_cast<int>(array.shape(1));
    const Rows rows = RowsFromPython(array, name, cols, /*allow_single=*/false,
                                     /*allow_empty=*/true, /*finite=*/true);
    matches.resize(rows.rows);
    const int offset = cols == 5 ? 1 : 0;
    for (int64_t i = 0; i < rows.rows; ++i) {
      const double* row = rows.data() + i * cols;
      if (cols == 5) matches[i].frame = FrameFromDouble(row[0], name, i);
      matches[i].left_pixel = {row[offset], row[offset + 1]};
      matches[i].right_pixel = {row[offset + 2], row[offset + 3]};
    }
  }
  if (matches.empty() && !allow_empty) {
    ThrowValueError(name + " is empty: at least one correspondence is needed");
  }
  CheckFrames(matches, name);
  return matches;
}

std::string PathFromPython(const py::handle& object) {
  const py::object os = py::module_::import("os");
  py::object path;
  try {
    path = os.attr("fsdecode")(os.attr("fspath")(object));
  } catch (const py::error_already_set&) {
    ThrowTypeError("expected a path (str or os.PathLike), got " +
                   py::str(py::type::of(object)).cast<std::string>());
  }
  return path.cast<std::string>();
}

cv::Mat ImageFromPython(const py::handle& object, const std::string& name,
                        py::object* keep) {
  if (!py::isinstance<py::array>(object)) {
    ThrowTypeError(name +
                   " must be a NumPy uint8 array (H, W) or (H, W, 3), got " +
                   py::str(py::type::of(object)).cast<std::string>());
  }
  const py::array array = py::reinterpret_borrow<py::array>(object);
  if (!array.dtype().is(py::dtype::of<uint8_t>())) {
    ThrowValueError(name +
                    " must be a uint8 image (H, W) or (H, W, 3), got dtype " +
                    DtypeText(array) +
                    " (convert with np.clip(image, 0, 255).astype(np.uint8))");
  }
  const bool gray = array.ndim() == 2;
  const bool color =
      array.ndim() == 3 &&
      (array.shape(2) == 1 || array.shape(2) == 3 || array.shape(2) == 4);
  if (!gray && !color) {
    ThrowValueError(name +
                    " must have shape (H, W), (H, W, 3) or (H, W, 4), got " +
                    ShapeText(array));
  }
  if (array.shape(0) == 0 || array.shape(1) == 0) {
    ThrowValueError(name + " is empty (shape " + ShapeText(array) + ")");
  }
  const auto contiguous =
      py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(
          array);
  *keep = contiguous;
  const int channels = gray ? 1 : static_cast<int>(array.shape(2));
  return cv::Mat(static_cast<int>(array.shape(0)),
                 static_cast<int>(array.shape(1)), CV_8UC(channels),
                 const_cast<uint8_t*>(contiguous.data()));
}

py::array ImageToNumpy(const cv::Mat& image) {
  if (image.empty())
    return py::array_t<uint8_t>(std::vector<py::ssize_t>{0, 0});
  const cv::Mat continuous = image.isContinuous() ? image : image.clone();
  std::vector<py::ssize_t> shape = {continuous.rows, continuous.cols};
  if (continuous.channels() > 1) shape.push_back(continuous.channels());
  if (continuous.depth() == CV_32F) {
    py::array_t<float> array(shape);
    std::memcpy(array.mutable_data(), continuous.data,
                continuous.total() * continuous.elemSize());
    return std::move(array);
  }
  if (continuous.depth() != CV_8U) {
    ThrowValueError("internal: unsupported image depth");
  }
  py::array_t<uint8_t> array(shape);
  std::memcpy(array.mutable_data(), continuous.data,
              continuous.total() * continuous.elemSize());
  return std::move(array);
}

}  // namespace rcm::python
