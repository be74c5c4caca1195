// rcm.Correspondences, rcm.read_correspondences, rcm.write_correspondences.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "rcm/io/correspondence_csv.h"

namespace rcm::python {
namespace {

py::array_t<int64_t> Frames(const Correspondences& c) {
  py::array_t<int64_t> a(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(c.matches.size())});
  for (size_t i = 0; i < c.matches.size(); ++i) {
    a.mutable_data()[i] = c.matches[i].frame;
  }
  return a;
}

// Coordinate k of every match: 0 xl, 1 yl, 2 xr, 3 yr.
DoubleArray Coordinate(const Correspondences& c, int k) {
  DoubleArray a(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(c.matches.size())});
  for (size_t i = 0; i < c.matches.size(); ++i) {
    const StereoCorrespondence& m = c.matches[i];
    a.mutable_data()[i] = k < 2 ? m.left_pixel[k] : m.right_pixel[k - 2];
  }
  return a;
}

bool HasTimestamps(const Correspondences& c) {
  for (const StereoCorrespondence& m : c.matches) {
    if (!m.timestamp) return false;
  }
  return !c.matches.empty();
}

py::object Timestamps(const Correspondences& c) {
  bool any = false;
  for (const StereoCorrespondence& m : c.matches) any = any || m.timestamp;
  if (!any) return py::none();
  DoubleArray a(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(c.matches.size())});
  for (size_t i = 0; i < c.matches.size(); ++i) {
    a.mutable_data()[i] = c.matches[i].timestamp.value_or(
        std::numeric_limits<double>::quiet_NaN());
  }
  return std::move(a);
}

DoubleArray Pixels(const Correspondences& c, bool with_frame) {
  const int cols = with_frame ? 5 : 4;
  DoubleArray a = NewArray(static_cast<int64_t>(c.matches.size()), cols);
  double* out = a.mutable_data();
  for (size_t i = 0; i < c.matches.size(); ++i) {
    const StereoCorrespondence& m = c.matches[i];
    double* row = out + cols * i;
    if (with_frame) *row++ = static_cast<double>(m.frame);
    row[0] = m.left_pixel.x();
    row[1] = m.left_pixel.y();
    row[2] = m.right_pixel.x();
    row[3] = m.right_pixel.y();
  }
  return a;
}

Correspondences Select(const Correspondences& c, const py::object& selection) {
  const py::array array = py::array::ensure(selection);
  if (!array) ThrowTypeError("selection must be a bool mask or an index array");
  Correspondences result;
  const int64_t size = static_cast<int64_t>(c.matches.size());
  if (array.dtype().kind() == 'b') {
    const auto mask =
        py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(
            array);
    if (mask.ndim() != 1 || mask.shape(0) != size) {
      ThrowValueError("mask must have one entry per correspondence (" +
                      std::to_string(size) + ")");
    }
    for (int64_t i = 0; i < size; ++i) {
      if (mask.data()[i]) result.matches.push_back(c.matches[i]);
    }
    return result;
  }
  if (array.dtype().kind() != 'i' && array.dtype().kind() != 'u') {
    ThrowTypeError("selection must be a bool mask or an integer index array");
  }
  const auto indices =
      py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(
          array);
  if (indices.ndim() != 1) ThrowValueError("indices must be one-dimensional");
  for (py::ssize_t k = 0; k < indices.shape(0); ++k) {
    int64_t i = indices.data()[k];
    if (i < 0) i += size;
    if (i < 0 || i >= size) {
      throw py::index_error("index " + std::to_string(indices.data()[k]) +
                            " out of range for " + std::to_string(size) +
                            " correspondences");
    }
    result.matches.push_back(c.matches[i]);
  }
  for (size_t i = 1; i < result.matches.size(); ++i) {
    if (result.matches[i].frame < result.matches[i - 1].frame) {
      ThrowValueError("indices must keep the frames in order");
    }
  }
  return result;
}

}  // namespace

void BindCorrespondences(py::module_& module) {
  py::class_<Correspondences>(module, "Correspondences", R"doc(
Stereo correspondences in raw (lens-distorted) pixels, held in C++ so that
every estimator takes them without a conversion.

Correspondences(matches) accepts what the estimators accept: another
Correspondences, a mapping with arrays xl, yl, xr, yr (optionally frame,
t), an (N, 4) array [xl, yl, xr, yr] (all frame 0) or an (N, 5) array
[frame, xl, yl, xr, yr]. Frames are non-negative integers that do not
decrease. Arrays: frame (int64), xl, yl, xr, yr (float64, pixels), t
(float64 seconds, NaN where a match has none; None when none has one).
)doc")
      .def(
          py::init([](const py::object& matches) {
            return Correspondences{MatchesFromPython(matches, "matches", true)};
          }),
          py::arg("matches"))
      .def("__len__", [](const Correspondences& c) { return c.matches.size(); })
      .def_property_readonly("frame", &Frames, "Frame of each match (int64).")
      .def_property_readonly(
          "xl", [](const Correspondences& c) { return Coordinate(c, 0); })
      .def_property_readonly(
          "yl", [](const Correspondences& c) { return Coordinate(c, 1); })
      .def_property_readonly(
          "xr", [](const Correspondences& c) { return Coordinate(c, 2); })
      .def_property_readonly(
          "yr", [](const Correspondences& c) { return Coordinate(c, 3); })
      .def_property_readonly(
          "t", &Timestamps,
          "Timestamps in seconds (NaN where absent), or None.")
      .def_property_readonly("has_timestamps", &HasTimestamps)
      .def_property_readonly(
          "pixels", [](const Correspondences& c) { return Pixels(c, false); },
          "(N, 4) float64 [xl, yl, xr, yr], pixels.")
      .def(
          "to_array", [](const Correspondences& c) { return Pixels(c, true); },
          "(N, 5) float64 [frame, xl, yl, xr, yr].")
      .def(
          "to_dict",
          [](const Correspondences& c) {
            py::dict d;
            d["frame"] = Frames(c);
            d["xl"] = Coordinate(c, 0);
            d["yl"] = Coordinate(c, 1);
            d["xr"] = Coordinate(c, 2);
            d["yr"] = Coordinate(c, 3);
            d["t"] = Timestamps(c);
            return d;
          },
          "dict of NumPy arrays frame, xl, yl, xr, yr, t (t None without "
          "timestamps).")
      .def_property_readonly(
          "frame_ids",
          [](const Correspondences& c) {
            std::vector<int64_t> ids;
            for (const StereoCorrespondence& m : c.matches) {
              if (ids.empty() || ids.back() != m.frame) ids.push_back(m.frame);
            }
            return ids;
          },
          "The distinct frames, in order.")
      .def(
          "split_frames",
          [](const Correspondences& c) {
            std::vector<Correspondences> frames;
            for (size_t i = 0; i < c.matches.size(); ++i) {
              if (i == 0 || c.matches[i].frame != c.matches[i - 1].frame) {
                frames.emplace_back();
              }
              frames.back().matches.push_back(c.matches[i]);
            }
            return frames;
          },
          "One Correspondences per frame, in order.")
      .def("select", &Select, py::arg("selection"),
           "The matches where a bool mask is True, or at integer indices (e.g. "
           "result.inliers).")
      .def("__repr__", [](const Correspondences& c) {
        size_t frames = 0;
        for (size_t i = 0; i < c.matches.size(); ++i) {
          if (i == 0 || c.matches[i].frame != c.matches[i - 1].frame) ++frames;
        }
        return "Correspondences(" + std::to_string(c.matches.size()) +
               " matches, " + std::to_string(frames) + " frames)";
      });

  module.def(
      "read_correspondences",
      [](const py::object& path) {
        const std::string file = PathFromPython(path);
        StatusOr<std::vector<StereoCorrespondence>> matches =
            Status::Error("not read");
        {
          py::gil_scoped_release release;
          matches = ReadCorrespondenceCsv(file);
        }
        return Correspondences{ReadOrThrow(file, std::move(matches))};
      },
      py::arg("path"), R"doc(
Reads a correspondence CSV (header with xl, yl, xr, yr, optional frame and t;
raw pixels) into an rcm.Correspondences (use .to_dict() for a dict of NumPy
arrays frame, xl, yl, xr, yr, t). OSError (FileNotFoundError, ...) when the
file cannot be read, ValueError for bad contents ("m.csv:7: expected 5
fields, got 4").
)doc");
  module.def(
      "write_correspondences",
      [](const py::object& path, const py::object& matches) {
        const std::string file = PathFromPython(path);
        const std::vector<StereoCorrespondence> list =
            MatchesFromPython(matches, "matches");
        size_t with_time = 0;
        for (const StereoCorrespondence& m : list)
          with_time += m.timestamp ? 1 : 0;
        if (with_time != 0 && with_time != list.size()) {
          ThrowValueError("matches: either all or none need a timestamp");
        }
        const Status status = WriteCorrespondenceCsv(file, list);
        if (!status.ok()) ThrowWriteError(status.message());
      },
      py::arg("path"), py::arg("matches"),
      "Writes correspondences as CSV (frame,xl,yl,xr,yr[,t]), numbers in "
      "their shortest round-trip form, atomically. OSError on failure.");
}

}  // namespace rcm::python
