// rcm undistort: refraction and lens corrected images (virtual pinholes in
// the water) and the calibration of the corrected cameras.
#include <gflags/gflags.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "command.h"
#include "image_input_flags.h"
#include "index_flag.h"
#include "progress.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"
#include "rcm/io/corrected_rig_files.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/stereo/virtual_pinhole_rig.h"
#include "rcm/util/number_format.h"
#include "reference_depth_flag.h"
#include "rig_flags.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_image_rewriter.h"
#endif

DEFINE_string(fit, "no-border",
              "output focal length: no-border (the widest view without "
              "black borders), virtual-pinhole (K_n = diag(n fx, n fy, 1) "
              "itself) or full (the whole field of view, black corners)");
DEFINE_double(focal, 0.0,
              "output focal length fx' in pixels, instead of the fit's (fy' "
              "keeps the camera's fy / fx); 0: the fit's");
DEFINE_string(size, "",
              "output image size WxH, e.g. 640x480 (default: the camera's; "
              "the principal point keeps its place relative to the image)");
DEFINE_bool(rectify, false,
            "rotate both cameras to the rectified pair with one K (rows of "
            "a scene point agree; extrinsics R = I, t along x)");
DEFINE_string(left_info_topic, "",
              "bag output: topic of the left camera_info messages (default: "
              "next to the image topic, /cam0/image_raw -> "
              "/cam0/camera_info)");
DEFINE_string(right_info_topic, "",
              "bag output: topic of the right camera_info messages (default: "
              "next to the image topic)");

namespace rcm::cli {
namespace {

namespace fs = std::filesystem;

constexpr char kUndistortUsage[] =
    "rcm undistort: refraction and lens corrected images of an underwater\n"
    "stereo rig calibrated in air, on ideal pinhole cameras in the water.\n\n"
    "usage: rcm undistort --calib RIG.yaml --n N --left DIR --right DIR "
    "--out OUT/\n"
    "       rcm undistort --calib RIG.yaml --n N --bag IN.bag --left-topic T0\n"
    "                     --right-topic T1 --out OUT.bag\n"
    "   [--fit no-border|virtual-pinhole|full] [--focal PX] [--size WxH]\n"
    "   [--rectify] [--from S --to S --stride K] [--json]\n\n"
    "Each camera's raw images are remapped to a pinhole in the water: the\n"
    "paper's virtual pinhole K_n = diag(n fx, n fy, 1) (eq. 9), zoomed by\n"
    "--fit or --focal; with --rectify both are also rotated to the\n"
    "rectified pair and share one K. The maps are built once for n and\n"
    "reused for every image.\n\n"
    "Folders (or a bag with --out DIR/) give\n"
    "  OUT/left/NAME.png, OUT/right/NAME.png  the corrected images (lossless "
    "PNG,\n"
    "                                         the input's names; a bag's "
    "stamps in ns)\n"
    "  OUT/left.yaml, OUT/right.yaml          ROS camera_info of the "
    "corrected\n"
    "                                         cameras (stereo R/P with "
    "--rectify)\n"
    "  OUT/camchain.yaml                      the corrected rig (Kalibr, "
    "pinhole,\n"
    "                                         distortion none), written "
    "last\n"
    "A bag with --out OUT.bag gives a copy of the bag with the two image\n"
    "topics corrected and camera_info messages added next to them, and\n"
    "OUT-camchain.yaml. A camchain input's IMU extrinsics (rotated into the\n"
    "corrected cameras), time shifts and topics are kept.\n\n"
    "Exit status: 0 on success, 1 on bad input, 2 on wrong flags.";

double Milliseconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now() - start)
      .count();
}

double Median(std::vector<double> values) {
  if (values.empty()) return NAN;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return NAN;
  double sum = 0.0;
  for (double value : values) sum += value;
  return sum / values.size();
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The flags that choose the output views.
StatusOr<VirtualPinholeRigOptions> RigOptionsFromFlags() {
  VirtualPinholeRigOptions options;
  const std::optional<VirtualPinholeFit> fit =
      VirtualPinholeFitFromName(FLAGS_fit);
  if (!fit) {
    return Status::Error("unknown --fit '" + FLAGS_fit +
                         "' (available: no-border, virtual-pinhole, full)");
  }
  options.fit = *fit;
  if (FLAGS_focal != 0.0) {
    if (!std::isfinite(FLAGS_focal) || FLAGS_focal < 0.0) {
      return Status::Error("--focal " + std::to_string(FLAGS_focal) +
                           " must be a positive number of pixels");
    }
    options.focal_px = FLAGS_focal;
  }
  if (!FLAGS_size.empty()) {
    int width = 0;
    int height = 0;
    char tail = 0;
    if (std::sscanf(FLAGS_size.c_str(), "%dx%d%c", &width, &height, &tail) !=
            2 ||
        width <= 0 || height <= 0) {
      return Status::Error(
          "--size must be WIDTHxHEIGHT in pixels, e.g. "
          "640x480, got '" +
          FLAGS_size + "'");
    }
    options.output_size = cv::Size(width, height);
  }
  options.rectify = FLAGS_rectify;
  options.reference_depth = FLAGS_reference_depth;
  RCM_RETURN_IF_ERROR(options.Check());
  return options;
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The same file or folder (either may not exist yet).
bool SamePath(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty()) return false;
  std::error_code error;
  const fs::path canonical_a = fs::weakly_canonical(a, error);
  if (error) return false;
  const fs::path canonical_b = fs::weakly_canonical(b, error);
  if (error) return false;
  // With a trailing separator on both: "out/" and "out" are one folder.
  return (canonical_a / "").lexically_normal() ==
         (canonical_b / "").lexically_normal();
}

// The camera_info topic next to an image topic: its last name replaced,
// /cam0/image_raw -> /cam0/camera_info.
std::string SiblingInfoTopic(const std::string& image_topic) {
  const size_t slash = image_topic.rfind('/');
  if (slash == std::string::npos) return "camera_info";
  return image_topic.substr(0, slash + 1) + "camera_info";
}

// The corrected camchain: from the input camchain when --calib is one
// (keeping IMU extrinsics, time shifts, topics), else from the rig alone.
Camchain OutputCamchain(const VirtualPinholeRig& rig) {
  if (FLAGS_calib.find(',') == std::string::npos) {
    const StatusOr<Camchain> source = ReadCamchain(FLAGS_calib);
    const std::optional<int> left = CamchainCameraIndex(FLAGS_left_camera);
    const std::optional<int> right = CamchainCameraIndex(FLAGS_right_camera);
    if (source.ok() && left && right) {
      StatusOr<Camchain> corrected =
          CorrectedCamchain(rig, *source, *left, *right);
      if (corrected.ok()) return *corrected;
    }
  }
  return CorrectedCamchain(rig);
}

nlohmann::json CameraJson(const VirtualPinholeCamera& camera) {
  const Camera& pinhole = camera.pinhole;
  return {{"k", {pinhole.fx(), pinhole.fy(), pinhole.cx(), pinhole.cy()}},
          {"width", pinhole.width()},
          {"height", pinhole.height()},
          {"focal_scale", camera.FocalScale()},
          {"black_fraction", camera.BlackFraction()}};
}

std::string CameraLine(const std::string& name,
                       const VirtualPinholeCamera& camera) {
  const Camera& pinhole = camera.pinhole;
  std::ostringstream line;
  line << "  " << name << "K' = [fx " << FormatFixed(pinhole.fx(), 2) << ", fy "
       << FormatFixed(pinhole.fy(), 2) << ", cx "
       << FormatFixed(pinhole.cx(), 2) << ", cy "
       << FormatFixed(pinhole.cy(), 2) << "], "
       << SizeText(pinhole.width(), pinhole.height()) << ", focal "
       << FormatFixed(camera.FocalScale(), 4) << " x K_n, "
       << FormatFixed(100.0 * camera.BlackFraction(), 1) << " % black";
  return line.str();
}

// What a run did, for the text and JSON reports.
struct RunReport {
  std::string source;
  int64_t pairs = 0;
  int64_t images = 0;
  std::vector<double> remap_ms;  // per image
  double total_ms = 0.0;         // the whole pass over the images
  std::vector<std::string> written;
  nlohmann::json extra = nlohmann::json::object();
};

Status CheckSize(const cv::Mat& image, const Camera& camera,
                 const std::string& camera_name, const std::string& name) {
  if (image.cols == camera.width() && image.rows == camera.height()) {
    return Status::Ok();
  }
  return Status::Error((name.empty() ? "" : name + ": ") + "image is " +
                       SizeText(image.cols, image.rows) +
                       " but the calibration's " + camera_name + " is " +
                       SizeText(camera.width(), camera.height()));
}

// File name of a pair's corrected image: the input's stem (folders) or the
// stamp in nanoseconds (bags; else the frame number), with .png.
std::string OutputName(const StereoImagePair& pair, bool left) {
  if (!FLAGS_bag.empty()) {
    if (pair.timestamp) {
      return std::to_string(std::llround(*pair.timestamp * 1e9)) + ".png";
    }
    char name[32];
    std::snprintf(name, sizeof(name), "%06lld",
                  static_cast<long long>(pair.frame));
    return std::string(name) + ".png";
  }
  return fs::path(left ? pair.left_name : pair.right_name).stem().string() +
         ".png";
}

// Folder output: OUT/left, OUT/right, the two camera_info files and the
// camchain last.
StatusOr<RunReport> WriteFolders(const VirtualPinholeRig& rig,
                                 StereoImageSource* source,
                                 const std::string& out) {
  RunReport report;
  report.source = source->Describe();
  const size_t pairs = source->NumPairs();
  // The first pair before anything is written: a wrong calibration
  // leaves no output at all.
  StatusOr<StereoImagePair> first = source->ReadPair(0);
  if (!first.ok()) return first.status();
  RCM_RETURN_IF_ERROR(CheckSize(first->left, rig.raw_rig().left(),
                                FLAGS_left_camera, first->left_name));
  RCM_RETURN_IF_ERROR(CheckSize(first->right, rig.raw_rig().right(),
                                FLAGS_right_camera, first->right_name));

  const fs::path out_dir(out);
  const fs::path left_dir = out_dir / "left";
  const fs::path right_dir = out_dir / "right";
  const std::string camchain_path = (out_dir / "camchain.yaml").string();
  for (const fs::path& dir : {left_dir, right_dir}) {
    std::error_code error;
    fs::create_directories(dir, error);
    if (error || !fs::is_directory(dir)) {
      return Status::Error(dir.string() + ": cannot create the output folder" +
                           (error ? " (" + error.message() + ")" : ""));
    }
  }
  // A camchain of an earlier run would make a failed run look complete.
  std::error_code ignored;
  fs::remove(camchain_path, ignored);

  Progress progress("rcm undistort: pair", pairs);
  std::set<std::string> names;
  cv::Mat left;
  cv::Mat right;
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < pairs; ++i) {
    StatusOr<StereoImagePair> pair =
        i == 0 ? std::move(first) : source->ReadPair(i);
    if (!pair.ok()) return pair.status();
    RCM_RETURN_IF_ERROR(CheckSize(pair->left, rig.raw_rig().left(),
                                  FLAGS_left_camera, pair->left_name));
    RCM_RETURN_IF_ERROR(CheckSize(pair->right, rig.raw_rig().right(),
                                  FLAGS_right_camera, pair->right_name));
    const std::string left_name = OutputName(*pair, true);
    const std::string right_name = OutputName(*pair, false);
    if (!names.insert("l/" + left_name).second ||
        !names.insert("r/" + right_name).second) {
      return Status::Error(pair->left_name +
                           ": a second image would be "
                           "written as " +
                           left_name +
                           " (input names that differ only in extension?)");
    }
    // Into the buffers of the previous pair: no allocation per image.
    auto remap_start = std::chrono::steady_clock::now();
    rig.left().Correct(pair->left, &left);
    report.remap_ms.push_back(Milliseconds(remap_start));
    remap_start = std::chrono::steady_clock::now();
    rig.right().Correct(pair->right, &right);
    report.remap_ms.push_back(Milliseconds(remap_start));
    RCM_RETURN_IF_ERROR(WritePng(left, (left_dir / left_name).string()));
    RCM_RETURN_IF_ERROR(WritePng(right, (right_dir / right_name).string()));
    ++report.pairs;
    report.images += 2;
    progress.Update(i + 1);
  }
  report.total_ms = Milliseconds(start);
  report.written.push_back(left_dir.string() + "/ (" +
                           std::to_string(report.pairs) + ")");
  report.written.push_back(right_dir.string() + "/ (" +
                           std::to_string(report.pairs) + ")");

  const auto [left_info, right_info] =
      CorrectedCameraInfos(rig, FLAGS_left_camera, FLAGS_right_camera);
  const std::string left_info_path = (out_dir / "left.yaml").string();
  const std::string right_info_path = (out_dir / "right.yaml").string();
  RCM_RETURN_IF_ERROR(WriteCameraInfo(left_info_path, left_info));
  RCM_RETURN_IF_ERROR(WriteCameraInfo(right_info_path, right_info));
  RCM_RETURN_IF_ERROR(WriteCamchain(camchain_path, OutputCamchain(rig)));
  report.written.push_back(left_info_path);
  report.written.push_back(right_info_path);
  report.written.push_back(camchain_path);
  report.extra["files"] = {{"left", left_dir.string()},
                           {"right", right_dir.string()},
                           {"left_camera_info", left_info_path},
                           {"right_camera_info", right_info_path},
                           {"camchain", camchain_path}};
  return report;
}

// OUT.bag -> OUT-camchain.yaml.
std::string BagCamchainPath(const std::string& bag) {
  return bag.substr(0, bag.size() - 4) + "-camchain.yaml";
}

#ifdef RCM_HAVE_ROSBAG
StatusOr<RunReport> WriteBag(const VirtualPinholeRig& rig,
                             const std::string& out) {
  RunReport report;
  report.source = "bag " + FLAGS_bag;
  const auto [left_info, right_info] =
      CorrectedCameraInfos(rig, FLAGS_left_camera, FLAGS_right_camera);
  const std::string left_info_topic = FLAGS_left_info_topic.empty()
                                          ? SiblingInfoTopic(FLAGS_left_topic)
                                          : FLAGS_left_info_topic;
  const std::string right_info_topic = FLAGS_right_info_topic.empty()
                                           ? SiblingInfoTopic(FLAGS_right_topic)
                                           : FLAGS_right_info_topic;
  const std::vector<BagImageRewriteTopic> topics = {
      {FLAGS_left_topic, left_info_topic, left_info},
      {FLAGS_right_topic, right_info_topic, right_info}};
  const VirtualPinholeCamera* cameras[2] = {&rig.left(), &rig.right()};
  const Camera* raw[2] = {&rig.raw_rig().left(), &rig.raw_rig().right()};
  const std::string names[2] = {FLAGS_left_camera, FLAGS_right_camera};
  std::vector<double> remap_ms;
  const BagImageTransform transform =
      [&](size_t topic, const cv::Mat& image) -> StatusOr<cv::Mat> {
    // The rewriter names the bag, topic and stamp.
    RCM_RETURN_IF_ERROR(CheckSize(image, *raw[topic], names[topic], ""));
    const auto remap_start = std::chrono::steady_clock::now();
    cv::Mat corrected = cameras[topic]->Correct(image);
    remap_ms.push_back(Milliseconds(remap_start));
    return corrected;
  };
  // The camchain of an earlier run would make a failed run look complete.
  const std::string camchain_path = BagCamchainPath(out);
  std::error_code ignored;
  fs::remove(camchain_path, ignored);

  std::unique_ptr<Progress> bar;
  const auto start = std::chrono::steady_clock::now();
  const StatusOr<BagRewriteSummary> summary = RewriteBagImages(
      FLAGS_bag, out, topics, transform, [&](int64_t done, int64_t total) {
        if (!bar) {
          bar = std::make_unique<Progress>("rcm undistort: message",
                                           static_cast<size_t>(total));
        }
        bar->Update(static_cast<size_t>(done));
      });
  bar.reset();
  if (!summary.ok()) return summary.status();
  report.total_ms = Milliseconds(start);
  report.remap_ms = std::move(remap_ms);
  for (int64_t count : summary->images) report.images += count;
  report.pairs = summary->images.empty() ? 0 : summary->images[0];

  Camchain camchain = OutputCamchain(rig);
  camchain.cameras[0].rostopic = FLAGS_left_topic;
  camchain.cameras[1].rostopic = FLAGS_right_topic;
  RCM_RETURN_IF_ERROR(WriteCamchain(camchain_path, camchain));
  report.written = {out, camchain_path};
  report.extra["bag"] = {
      {"images_per_topic", summary->images},
      {"copied_messages", summary->copied_messages},
      {"dropped_camera_infos", summary->dropped_camera_infos},
      {"camera_info_topics", {left_info_topic, right_info_topic}}};
  report.extra["files"] = {{"bag", out}, {"camchain", camchain_path}};
  return report;
}
#endif

int RunUndistort();

}  // namespace

extern const Subcommand kUndistortCommand = {
    "undistort",
    "refraction and lens corrected images (virtual pinholes) and their "
    "camchain",
    kUndistortUsage,
    {__FILE__, kRigFlagsSource, kIndexFlagSource, kImageInputFlagsSource,
     kReferenceDepthFlagSource},
    RunUndistort};

namespace {

int RunUndistort() {
  const Subcommand& command = kUndistortCommand;
  if (FLAGS_calib.empty()) {
    PrintError(command, "--calib is required (see rcm undistort --help)");
    return kExitUsage;
  }
  const StatusOr<double> n = RefractiveIndexFromFlag(/*required=*/true);
  if (!n.ok()) {
    PrintError(command, n.status().message());
    return kExitUsage;
  }
  if (FLAGS_out.empty()) {
    PrintError(command,
               "--out is required: a folder for the corrected images, or "
               "OUT.bag for a bag (see rcm undistort --help)");
    return kExitUsage;
  }
  const StatusOr<VirtualPinholeRigOptions> options = RigOptionsFromFlags();
  if (!options.ok()) {
    PrintError(command, options.status().message());
    return kExitUsage;
  }
  if (!ImageInputGiven()) {
    PrintError(command,
               "no images: give --left DIR --right DIR, --pairs LIST or --bag "
               "BAG (see rcm undistort --help)");
    return kExitUsage;
  }
  const bool bag_output = EndsWith(FLAGS_out, ".bag");
  if (bag_output) {
    if (FLAGS_bag.empty()) {
      PrintError(command, "--out " + FLAGS_out +
                              ": a bag is written only from a bag (--bag); "
                              "give a folder for image folders");
      return kExitUsage;
    }
    if (FLAGS_left_topic.empty() || FLAGS_right_topic.empty()) {
      PrintError(command, "--bag needs --left-topic and --right-topic");
      return kExitUsage;
    }
    if (!std::isnan(FLAGS_from) || !std::isnan(FLAGS_to) || FLAGS_stride != 1) {
      PrintError(command,
                 "--from, --to and --stride select pairs for folder output; "
                 "a rewritten bag keeps every message (give --out DIR/)");
      return kExitUsage;
    }
    if (SamePath(FLAGS_out, FLAGS_bag)) {
      PrintError(command, "--out " + FLAGS_out +
                              " is the input bag: write the corrected bag "
                              "to another file");
      return kExitUsage;
    }
  } else {
    for (const std::string& input : {FLAGS_left, FLAGS_right}) {
      if (SamePath(FLAGS_out, input) ||
          SamePath((fs::path(FLAGS_out) / "left").string(), input) ||
          SamePath((fs::path(FLAGS_out) / "right").string(), input)) {
        PrintError(command, "--out " + FLAGS_out + " is the input folder " +
                                input +
                                ": the corrected images would replace the "
                                "raw ones; give another folder");
        return kExitUsage;
      }
    }
  }

  // A camchain's dome blocks: each camera its dome's, central at
  // --reference-depth.
  RigFileOptions rig_options;
  rig_options.domes_allowed = true;
  const StatusOr<StereoRig> rig = ReadStereoRig(
      FLAGS_calib, FLAGS_left_camera, FLAGS_right_camera, rig_options);
  if (!rig.ok()) {
    PrintError(command, rig.status().message());
    return kExitFailure;
  }
  const StatusOr<std::optional<std::array<DomePort, 2>>> domes =
      ReadStereoRigDomes(FLAGS_calib, FLAGS_left_camera, FLAGS_right_camera);
  if (!domes.ok()) {
    PrintError(command, domes.status().message());
    return kExitFailure;
  }
  // Open the input before building the maps: a wrong path fails fast.
  std::unique_ptr<StereoImageSource> source;
  if (!bag_output) {
    StatusOr<std::unique_ptr<StereoImageSource>> opened =
        OpenImageInputFromFlags();
    if (!opened.ok()) {
      PrintError(command, opened.status().message());
      return kExitFailure;
    }
    source = std::move(*opened);
  } else {
#ifndef RCM_HAVE_ROSBAG
    PrintError(command,
               "this rcm was built without ROS bag support (Debian's "
               "librosbag-dev was missing): run scripts/setup.sh and "
               "rebuild");
    return kExitFailure;
#endif
  }
  VirtualPinholeRigOptions rig_view_options = *options;
  rig_view_options.domes = *domes;
  const StatusOr<VirtualPinholeRig> corrected =
      VirtualPinholeRig::Create(*rig, *n, rig_view_options);
  if (!corrected.ok()) {
    PrintError(command, corrected.status().message());
    return kExitFailure;
  }

  StatusOr<RunReport> report = Status::Error("no output");
  if (bag_output) {
#ifdef RCM_HAVE_ROSBAG
    report = WriteBag(*corrected, FLAGS_out);
#endif
  } else {
    report = WriteFolders(*corrected, source.get(), FLAGS_out);
  }
  if (!report.ok()) {
    PrintError(command, report.status().message());
    return kExitFailure;
  }

  const std::string fit =
      options->focal_px ? "focal" : VirtualPinholeFitName(options->fit);
  const double pairs = std::max<double>(1.0, report->pairs);
  if (FLAGS_json) {
    nlohmann::json json;
    json["n"] = *n;
    json["fit"] = fit;
    json["rectified"] = options->rectify;
    json["calib"] = FLAGS_calib;
    json["cameras"] = {{"left", CameraJson(corrected->left())},
                       {"right", CameraJson(corrected->right())}};
    json["baseline_m"] = corrected->corrected_rig().Baseline();
    json["source"] = report->source;
    json["pairs"] = report->pairs;
    json["images_written"] = report->images;
    json["ms"] = {{"maps", corrected->build_ms()},
                  {"remap_per_image", Median(report->remap_ms)},
                  {"remap_per_image_mean", Mean(report->remap_ms)},
                  {"per_pair", report->total_ms / pairs}};
    json["out"] = FLAGS_out;
    json["port"] = domes->has_value()    ? "dome"
                   : rig->HasThickPort() ? "thick"
                                         : "thin";
    if (domes->has_value()) {
      json["dome_parallax_px"] = DomeParallaxJson(*rig, **domes, *n);
    }
    if (rig->HasThickPort() || domes->has_value()) {
      json["reference_depth_m"] = options->reference_depth;
    }
    json.update(report->extra);
    std::cout << json.dump(2) << std::endl;
    return kExitOk;
  }
  std::ostringstream text;
  text << "rcm undistort: n " << *n << ", fit " << fit
       << (options->rectify ? ", rectified" : "") << "\n"
       << "  input  " << report->source << "\n"
       << (rig->HasThickPort() ? "  port   " + ThickPortNote(*rig) + "\n"
                               : std::string())
       << (domes->has_value() ? "  port   " + DomeNote(*rig, **domes, *n) + "\n"
                              : std::string())
       << CameraLine("left   ", corrected->left()) << "\n"
       << CameraLine("right  ", corrected->right()) << "\n"
       << "  images " << report->images << " written (" << report->pairs
       << " pairs); maps built once in "
       << FormatFixed(corrected->build_ms(), 0) << " ms, remap "
       << FormatFixed(Median(report->remap_ms), 2) << " ms per image (median), "
       << FormatFixed(report->total_ms / pairs, 1)
       << " ms per pair with reading and writing\n"
       << "  wrote ";
  for (const std::string& path : report->written) text << " " << path;
  text << "\n";
  std::cout << text.str() << std::flush;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
