#include "calibration_input.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "image_input_flags.h"
#include "number_list_flag.h"
#include "rcm/calib/corners_file.h"
#include "rcm/calib/target_detector.h"
#include "rcm/io/image_file.h"

DEFINE_string(corners, "",
              "calibrate from these corners (mrcal's corners.vnl format) "
              "instead of detecting the target; --left/--right give each "
              "camera's images as a folder or a pattern with one '*' "
              "('left*.jpg'), and pair them by what '*' matched");
DEFINE_string(corners_out, "",
              "write the corners the calibration uses to this file in "
              "mrcal's corners.vnl format (mrcal-calibrate-cameras "
              "--corners-cache FILE reads it)");
DEFINE_string(image_size, "",
              "with --corners: the images' size W,H when the images named "
              "in the file cannot be read");

namespace rcm::cli {

extern const char kCalibrationInputFlagsSource[] = __FILE__;

namespace {

namespace fs = std::filesystem;
using calib::CornersFileImage;
using calib::StereoView;

// A --left/--right pattern: the text before and after its one '*'.
struct NamePattern {
  std::string prefix;
  std::string suffix;

  // The text '*' matches in `name`, nullopt when it does not match.
  std::optional<std::string> Match(const std::string& name) const {
    const std::string normal = fs::path(name).lexically_normal().string();
    if (normal.size() < prefix.size() + suffix.size() ||
        normal.compare(0, prefix.size(), prefix) != 0 ||
        normal.compare(normal.size() - suffix.size(), suffix.size(), suffix) !=
            0) {
      return std::nullopt;
    }
    return normal.substr(prefix.size(),
                         normal.size() - prefix.size() - suffix.size());
  }
};

StatusOr<NamePattern> PatternFromFlag(const std::string& flag,
                                      const std::string& value) {
  if (value.find_first_of("?[") != std::string::npos) {
    return Status::Error(flag + " " + value +
                         ": with --corners a pattern has one '*' and no '?' "
                         "or '['");
  }
  std::string pattern = value;
  const size_t star = pattern.find('*');
  if (star == std::string::npos) {
    // A folder: every file in it.
    pattern = (fs::path(value) / "*").lexically_normal().string();
  } else if (pattern.find('*', star + 1) != std::string::npos) {
    return Status::Error(flag + " " + value +
                         ": with --corners a pattern has one '*', not more");
  } else {
    pattern = fs::path(pattern).lexically_normal().string();
  }
  const size_t at = pattern.find('*');
  return NamePattern{pattern.substr(0, at), pattern.substr(at + 1)};
}

StatusOr<calib::ImageSize> ImageSizeFromFlag(const std::string& value) {
  const StatusOr<std::vector<double>> numbers = ParseNumberList(value);
  const auto side = [](double value) {
    return value >= 1.0 && value <= Camera::kMaxImageSide &&
           value == std::floor(value);
  };
  if (!numbers.ok() || numbers->size() != 2 || !side((*numbers)[0]) ||
      !side((*numbers)[1])) {
    return Status::Error("--image-size " + value +
                         ": expected W,H in pixels, e.g. 640,480 (each in "
                         "[1, " +
                         std::to_string(Camera::kMaxImageSide) + "])");
  }
  return calib::ImageSize{static_cast<int>((*numbers)[0]),
                          static_cast<int>((*numbers)[1])};
}

// The size of the first image of `names` that can be read, as it is named
// or relative to the corners file's folder (mrcal reads both).
std::optional<calib::ImageSize> SizeOfFirstReadable(
    const std::vector<std::string>& names, const fs::path& corners_folder) {
  for (const std::string& name : names) {
    for (const fs::path& path : {fs::path(name), corners_folder / name}) {
      std::error_code error;
      if (!fs::is_regular_file(path, error)) continue;
      const StatusOr<cv::Mat> image = ReadImageAsStored(path.string());
      if (image.ok()) return calib::ImageSize{image->cols, image->rows};
    }
  }
  return std::nullopt;
}

std::string Count(int n, const std::string& what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

}  // namespace

StatusOr<CalibrationInput> ReadCornersInput(
    const calib::CalibrationTarget& target, bool allow_left_only,
    const CornersSource& source) {
  if (source.left.empty() || (source.right.empty() && !allow_left_only)) {
    return Status::Error(
        source.flags.file + " needs " + source.flags.left + " and " +
        source.flags.right +
        ": each camera's images as named in "
        "the file, a folder or a pattern with one '*' (e.g. --left "
        "'data/left*.jpg' --right 'data/right*.jpg')");
  }
  StatusOr<std::vector<CornersFileImage>> images =
      calib::ReadCornersFile(source.file, calib::NumTargetPoints(target));
  if (!images.ok()) return images.status();
  StatusOr<NamePattern> patterns[2] = {
      PatternFromFlag(source.flags.left, source.left), NamePattern{}};
  const bool two_cameras = !source.right.empty();
  if (two_cameras)
    patterns[1] = PatternFromFlag(source.flags.right, source.right);
  for (const StatusOr<NamePattern>& pattern : patterns) {
    if (!pattern.ok()) return pattern.status();
  }

  CalibrationInput input;
  Detections& detections = input.detections;
  std::map<std::string, size_t> view_of_key;
  std::vector<std::string> names[2];
  int unmatched = 0;
  std::string first_unmatched;
  for (CornersFileImage& image : *images) {
    int camera = -1;
    std::optional<std::string> key;
    for (int c = 0; c < (two_cameras ? 2 : 1) && camera < 0; ++c) {
      key = patterns[c]->Match(image.filename);
      if (key) camera = c;
    }
    if (camera < 0) {
      if (unmatched++ == 0) first_unmatched = image.filename;
      continue;
    }
    auto [it, inserted] = view_of_key.emplace(*key, detections.views.size());
    if (inserted) detections.views.emplace_back();
    StereoView& view = detections.views[it->second];
    std::string& name = camera == 0 ? view.left_name : view.right_name;
    if (!name.empty()) {
      return Status::Error(source.file + ": " + name + " and " +
                           image.filename + " both pair as '" + *key +
                           "' for the " + (camera == 0 ? "left" : "right") +
                           " camera: give " + source.flags.left + "/" +
                           source.flags.right +
                           " patterns that tell "
                           "the images apart");
    }
    name = image.filename;
    names[camera].push_back(image.filename);
    (camera == 0 ? view.left : view.right) = std::move(image.observation);
  }
  if (detections.views.empty()) {
    return Status::Error(
        source.file + ": none of its " +
        Count(static_cast<int>(images->size()), "image") + " matches " +
        source.flags.left + " " + source.left +
        (two_cameras ? " or " + source.flags.right + " " + source.right : "") +
        " (the first is " + first_unmatched + ")");
  }
  if (unmatched > 0) {
    detections.warnings.push_back(
        source.file + ": " + Count(unmatched, "image") + " match neither " +
        source.flags.left + " nor " + source.flags.right +
        " and are not used (the first is " + first_unmatched + ")");
  }
  for (StereoView& view : detections.views) {
    if (!two_cameras) {
      if (!view.left) view.note = "no target found";
      continue;
    }
    if (view.left_name.empty()) {
      view.note = "no left image pairs with it";
    } else if (view.right_name.empty()) {
      view.note = "no right image pairs with it";
    } else {
      calib::NoteMissingTargets(&view);
    }
    if (!view.note.empty()) {
      detections.warnings.push_back(
          (view.left_name.empty() ? view.right_name
           : view.right_name.empty()
               ? view.left_name
               : view.left_name + " and " + view.right_name) +
          ": " + view.note);
    }
  }
  CountViews(&detections);

  std::optional<calib::ImageSize> given;
  if (!source.image_size.empty()) {
    StatusOr<calib::ImageSize> size = ImageSizeFromFlag(source.image_size);
    if (!size.ok()) return size.status();
    given = *size;
  }
  const fs::path folder = fs::path(source.file).parent_path();
  for (int c = 0; c < (two_cameras ? 2 : 1); ++c) {
    if (names[c].empty()) continue;
    detections.sizes[c] = given ? given : SizeOfFirstReadable(names[c], folder);
    if (!detections.sizes[c]) {
      return Status::Error(
          source.file + ": none of the " + (c == 0 ? "left" : "right") +
          " images it names can be read for their size (the first is " +
          names[c].front() + "): give --image-size W,H");
    }
  }
  input.description =
      "corners file " + source.file + ": " +
      Count(static_cast<int>(images->size()) - unmatched, "image") +
      (two_cameras ? ", " + Count(detections.stereo, "pair") +
                         " with the target in both"
                   : "");
  return input;
}

namespace {

// A name the corners file can hold: a bag's "topic @ stamp" without blanks.
std::string CornersFileName(std::string name) {
  const std::string at = " @ ";
  for (size_t i = name.find(at); i != std::string::npos; i = name.find(at)) {
    name.replace(i, at.size(), "@");
  }
  for (char& c : name) {
    if (c == ' ' || c == '\t') c = '_';
  }
  return name;
}

Status WriteCornersOut(const Detections& detections, int num_points) {
  std::vector<CornersFileImage> images;
  for (const StereoView& view : detections.views) {
    if (!view.left_name.empty()) {
      images.push_back({CornersFileName(view.left_name), view.left});
    }
    if (!view.right_name.empty()) {
      images.push_back({CornersFileName(view.right_name), view.right});
    }
  }
  return calib::WriteCornersFile(FLAGS_corners_out, images, num_points)
      .WithContext("--corners-out");
}

// --corners-out can be written, checked before a detection pass that it
// would otherwise waste: not a folder, in a folder that exists.
Status CheckCornersOut() {
  if (FLAGS_corners_out.empty()) return Status::Ok();
  std::error_code error;
  const fs::path path(FLAGS_corners_out);
  if (fs::is_directory(path, error)) {
    return Status::Error("--corners-out " + FLAGS_corners_out +
                         ": is a folder, expected the file to write");
  }
  const fs::path folder =
      path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(folder, error)) {
    return Status::Error("--corners-out " + FLAGS_corners_out + ": folder " +
                         folder.string() + " does not exist");
  }
  return Status::Ok();
}

}  // namespace

bool CornersInputGiven() { return !FLAGS_corners.empty(); }

StatusOr<CalibrationInput> ReadCalibrationInput(
    const calib::CalibrationTarget& target, bool allow_left_only,
    const CalibrationOutputPaths& paths,
    const std::function<void(const std::string&)>& started) {
  RCM_RETURN_IF_ERROR(CheckCornersOut());
  CalibrationInput input;
  if (CornersInputGiven()) {
    if (!FLAGS_pairs.empty() || !FLAGS_bag.empty()) {
      return Status::Error(
          "--corners takes --left and --right (the images' names in the "
          "file), not --pairs or --bag");
    }
    StatusOr<CalibrationInput> read = ReadCornersInput(
        target, allow_left_only,
        {FLAGS_corners, FLAGS_left, FLAGS_right, FLAGS_image_size, {}});
    if (!read.ok()) return read.status();
    input = std::move(read).value();
    RCM_RETURN_IF_ERROR(CheckCalibrationOutputPaths(paths));
    started(input.description);
  } else {
    if (!FLAGS_image_size.empty()) {
      return Status::Error("--image-size goes with --corners");
    }
    StatusOr<std::unique_ptr<StereoImageSource>> source =
        OpenImageInputFromFlags(allow_left_only);
    if (!source.ok()) return source.status();
    if ((*source)->NumPairs() == 0) {
      return Status::Error((*source)->Describe() + ": no image pairs");
    }
    RCM_RETURN_IF_ERROR(CheckCalibrationOutputPaths(paths));
    input.description = (*source)->Describe();
    started(input.description);
    StatusOr<Detections> detections = DetectTargets(source->get(), target);
    if (!detections.ok()) return detections.status();
    input.detections = std::move(detections).value();
  }
  if (!FLAGS_corners_out.empty()) {
    RCM_RETURN_IF_ERROR(
        WriteCornersOut(input.detections, calib::NumTargetPoints(target)));
  }
  return input;
}

}  // namespace rcm::cli
