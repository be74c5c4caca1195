// Bad input to every subcommand of the rcm executable, as a table: each row
// writes one bad input into a fresh folder, runs rcm on it and checks what
// docs/design.md, "The parts and their contracts", promises: a normal exit
// with a non-zero code (never a signal), exactly one line on stderr that
// names the problem, no message of a library (libpng, libjpeg, glog, a
// sanitizer), and no output that looks complete (no final camchain, JSON,
// CSV or report; no truncated image; every file that was there before
// unchanged).
//
// Every row is its own test, e.g.
// BadInput/CliBadInput.Refuses/EstimateMatchesWrongColumnCount.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "cli/cli_runner.h"
#include "support/camera_info_text.h"
#include "support/temp_file.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_image_writer.h"
#endif

namespace rcm::bad_input_table_test {
namespace {

namespace fs = std::filesystem;
using test::RunResult;

const std::string kRig = std::string(RCM_SOURCE_DIR) +
                         "/examples/data/alphasense_front_rectified.yaml";
const std::string kMatches =
    std::string(RCM_SOURCE_DIR) + "/examples/data/demo_matches.csv";

// The size of the dataset rig's images.
constexpr int kWidth = 720;
constexpr int kHeight = 540;

// ---------------------------------------------------------------------------
// What a row writes. `$D` in a row's arguments, expected text and paths
// stands for the row's own fresh folder.

using Setup = std::function<void(const std::string& dir)>;

std::string Expand(std::string text, const std::string& dir) {
  for (size_t at = text.find("$D"); at != std::string::npos;
       at = text.find("$D", at + dir.size())) {
    text.replace(at, 2, dir);
  }
  return text;
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << bytes;
  file.close();
  ASSERT_TRUE(file.good()) << "cannot write " << path;
}

// Bytes 0, 1, ..., 255.
std::string AllBytes() {
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes.push_back(static_cast<char>(i));
  return bytes;
}

// 4096 bytes of a fixed-seed generator (mt19937's output is the same on
// every platform).
std::string RandomBytes(uint32_t seed = 1) {
  std::mt19937 engine(seed);
  std::string bytes;
  for (int i = 0; i < 4096; ++i) {
    bytes.push_back(static_cast<char>(engine() & 0xff));
  }
  return bytes;
}

// A gray image of noise, so that its PNG and JPEG files are large enough
// to cut in the middle of their pixel data.
cv::Mat Noise(int width, int height, uint64_t seed = 1) {
  cv::Mat image(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

void WriteImage(const std::string& path, int width, int height,
                uint64_t seed = 1) {
  fs::create_directories(fs::path(path).parent_path());
  ASSERT_TRUE(cv::imwrite(path, Noise(width, height, seed))) << path;
}

// The first half of a file that cv::imwrite wrote.
void WriteTruncatedImage(const std::string& path) {
  WriteImage(path, kWidth, kHeight);
  fs::resize_file(path, fs::file_size(path) / 2);
}

// A PNG whose structure is whole but one byte of its pixel data (IDAT)
// changed, so its checksum no longer matches.
void WriteCorruptPng(const std::string& path) {
  WriteImage(path, kWidth, kHeight);
  std::string bytes = test::ReadWholeFile(path);
  const size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 100] = static_cast<char>(bytes[idat + 100] ^ 0x55);
  WriteBytes(path, bytes);
}

// CRC-32 as PNG chunks carry it.
uint32_t Crc32(const std::string& data) {
  uint32_t crc = 0xffffffffu;
  for (char byte : data) {
    crc ^= static_cast<uint8_t>(byte);
    for (int k = 0; k < 8; ++k)
      crc = (crc & 1) ? 0xedb88320u ^ (crc >> 1) : crc >> 1;
  }
  return crc ^ 0xffffffffu;
}

// A PNG whose first IDAT chunk has damaged compressed data but a CRC that
// matches them: whole in structure, not in its zlib stream.
void WritePngWithBadDeflateData(const std::string& path) {
  WriteImage(path, kWidth, kHeight);
  std::string bytes = test::ReadWholeFile(path);
  const size_t chunk = bytes.find("IDAT") - 4;
  const uint32_t length = static_cast<uint8_t>(bytes[chunk]) << 24 |
                          static_cast<uint8_t>(bytes[chunk + 1]) << 16 |
                          static_cast<uint8_t>(bytes[chunk + 2]) << 8 |
                          static_cast<uint8_t>(bytes[chunk + 3]);
  for (size_t k = 50; k < 80; ++k) {
    bytes[chunk + 8 + k] = static_cast<char>(bytes[chunk + 8 + k] ^ 0xa5);
  }
  const uint32_t crc = Crc32(bytes.substr(chunk + 4, 4 + length));
  for (int k = 0; k < 4; ++k) {
    bytes[chunk + 8 + length + k] = static_cast<char>(crc >> (24 - 8 * k));
  }
  WriteBytes(path, bytes);
}

// A JPEG whose scan data are damaged without making a marker (no 0xFF
// written or changed): whole in structure, not in its Huffman codes.
void WriteJpegWithDamagedScan(const std::string& path) {
  WriteImage(path, kWidth, kHeight);
  std::string bytes = test::ReadWholeFile(path);
  const size_t scan = bytes.find("\xff\xda");
  ASSERT_NE(scan, std::string::npos);
  for (size_t k = scan + 400; k < scan + 2000; k += 7) {
    const auto byte = static_cast<uint8_t>(bytes[k]);
    if (byte != 0xff && (byte ^ 0x5a) != 0xff &&
        static_cast<uint8_t>(bytes[k - 1]) != 0xff) {
      bytes[k] = static_cast<char>(byte ^ 0x5a);
    }
  }
  WriteBytes(path, bytes);
}

// Setups, composable.
Setup Nothing() {
  return [](const std::string&) {};
}

Setup Steps(std::vector<Setup> steps) {
  return [steps](const std::string& dir) {
    for (const Setup& step : steps) step(dir);
  };
}

Setup File(const std::string& name, const std::string& bytes) {
  return [name, bytes](const std::string& dir) {
    WriteBytes(dir + "/" + name, bytes);
  };
}

// A text file whose "$D" become the row's folder.
Setup FileInDir(const std::string& name, const std::string& text) {
  return [name, text](const std::string& dir) {
    std::string bytes = text;
    for (size_t at = bytes.find("$D"); at != std::string::npos;
         at = bytes.find("$D", at + dir.size())) {
      bytes.replace(at, 2, dir);
    }
    WriteBytes(dir + "/" + name, bytes);
  };
}

Setup Folder(const std::string& name) {
  return [name](const std::string& dir) {
    fs::create_directories(dir + "/" + name);
  };
}

// A symbolic link to itself: no reader can open it, even as root.
Setup LinkLoop(const std::string& name) {
  return [name](const std::string& dir) {
    fs::create_symlink(dir + "/" + name, dir + "/" + name);
  };
}

Setup Image(const std::string& name, int width = kWidth, int height = kHeight,
            uint64_t seed = 1) {
  return [=](const std::string& dir) {
    WriteImage(dir + "/" + name, width, height, seed);
  };
}

Setup TruncatedImage(const std::string& name) {
  return
      [name](const std::string& dir) { WriteTruncatedImage(dir + "/" + name); };
}

Setup CorruptPng(const std::string& name) {
  return [name](const std::string& dir) { WriteCorruptPng(dir + "/" + name); };
}

// The dataset rig with `from` replaced by `to`, as `name`.
Setup RigWith(const std::string& name, const std::string& from,
              const std::string& to) {
  return [=](const std::string& dir) {
    std::string text = test::ReadWholeFile(kRig);
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    WriteBytes(dir + "/" + name, text);
  };
}

// ROS camera_info files of a pinhole pair with an 11 cm baseline (R = I;
// the right projection's P[3] = -fx * baseline), with `from` replaced by
// `to` in the left or right file.
// The right projection's P[3] = -fx * baseline.
constexpr double kRightP03 = -346.7 * 0.11;

std::string PinholeCameraInfo(const std::string& name, double p03) {
  Eigen::Matrix3d k;
  k << 346.7, 0.0, 360.5, 0.0, 346.8, 271.0, 0.0, 0.0, 1.0;
  Eigen::Matrix<double, 3, 4> projection;
  projection << k, Eigen::Vector3d(p03, 0.0, 0.0);
  return test::CameraInfoText(name, k, {-0.01, 0.002, 0.0, 0.0, 0.0},
                              Eigen::Matrix3d::Identity(), projection);
}

Setup CameraInfos(bool change_left, const std::string& from,
                  const std::string& to) {
  return [=](const std::string& dir) {
    std::string left = PinholeCameraInfo("left", 0.0);
    std::string right = PinholeCameraInfo("right", kRightP03);
    std::string& changed = change_left ? left : right;
    if (!from.empty()) {
      const size_t at = changed.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      changed.replace(at, from.size(), to);
    }
    WriteBytes(dir + "/left.yaml", left);
    WriteBytes(dir + "/right.yaml", right);
  };
}

#ifdef RCM_HAVE_ROSBAG
// A bag of two stereo pairs (mono8) on /cam0/image_raw and /cam1/image_raw.
void WriteBag(const std::string& path, int width, int height) {
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (int i = 0; i < 2; ++i) {
    const double stamp = 1700000000.0 + 0.05 * i;
    ASSERT_TRUE(writer
                    ->WriteImage("/cam0/image_raw", stamp,
                                 Noise(width, height, 2 * i), "mono8", "cam0")
                    .ok());
    ASSERT_TRUE(writer
                    ->WriteImage("/cam1/image_raw", stamp,
                                 Noise(width, height, 2 * i + 1), "mono8",
                                 "cam1")
                    .ok());
  }
  ASSERT_TRUE(writer->Close().ok());
}

Setup Bag(const std::string& name) {
  return [name](const std::string& dir) {
    WriteBag(dir + "/" + name, kWidth, kHeight);
  };
}

// A bag of two stereo pairs as sensor_msgs/CompressedImage PNGs, one byte
// of each PNG's pixel data changed in the (uncompressed) bag file: the bag
// is whole, its images are not.
Setup BagWithCorruptPng(const std::string& name) {
  return [name](const std::string& dir) {
    const std::string path = dir + "/" + name;
    {
      StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
      ASSERT_TRUE(writer.ok()) << writer.status().message();
      for (int i = 0; i < 2; ++i) {
        const double stamp = 1700000000.0 + 0.05 * i;
        for (const char* topic : {"/cam0/image_raw", "/cam1/image_raw"}) {
          ASSERT_TRUE(writer
                          ->WriteCompressed(topic, stamp,
                                            Noise(160, 120, 2 * i), "png",
                                            "cam")
                          .ok());
        }
      }
      ASSERT_TRUE(writer->Close().ok());
    }
    std::string bytes = test::ReadWholeFile(path);
    int changed = 0;
    for (size_t idat = bytes.find("IDAT"); idat != std::string::npos;
         idat = bytes.find("IDAT", idat + 4)) {
      bytes[idat + 100] = static_cast<char>(bytes[idat + 100] ^ 0x55);
      ++changed;
    }
    ASSERT_GE(changed, 4);  // every image, some more than once
    WriteBytes(path, bytes);
  };
}

// The first half of a bag the project's own writer wrote: the header and
// some messages, no index (as a recording that was cut off).
Setup TruncatedBag(const std::string& name) {
  return [name](const std::string& dir) {
    const std::string path = dir + "/" + name;
    WriteBag(path, 160, 120);
    fs::resize_file(path, fs::file_size(path) / 2);
  };
}
#endif

// ---------------------------------------------------------------------------
// The table.

struct BadInputCase {
  std::string name;
  Setup setup;
  std::vector<std::string> args;
  // What the one line of stderr must contain ($D expanded).
  std::string expected;
  // Outputs that must not exist afterwards ($D expanded).
  std::vector<std::string> absent;
  // Non-empty: the row shows a bug in a file this test may not fix; it is
  // skipped with this text.
  std::string skip = {};
};

void PrintTo(const BadInputCase& row, std::ostream* out) { *out << row.name; }

std::vector<std::string> Concat(std::vector<std::string> a,
                                const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// A rig file (--calib) with a defect.
struct RigDefect {
  std::string name;
  Setup setup;
  std::string calib;     // the value of --calib
  std::string expected;  // in the error line
  std::string skip = {};
};

std::vector<RigDefect> RigDefects() {
  const std::string rig = "$D/rig.yaml";
  const std::string infos = "$D/left.yaml,$D/right.yaml";
  const std::string row1 = "- [1.0, 0.0, 0.0, -0.11]";
  return {
      {"Missing", Nothing(), rig,
       "$D/rig.yaml: cannot open: No such file or directory"},
      {"IsAFolder", Folder("rig.yaml"), rig,
       "$D/rig.yaml: is a directory, expected a file"},
      {"BelowAFile", File("file", "a file\n"), "$D/file/rig.yaml",
       "$D/file/rig.yaml: cannot open: Not a directory"},
      {"LinkLoop", LinkLoop("rig.yaml"), rig,
       "$D/rig.yaml: cannot open: Too many levels of symbolic links"},
      {"Empty", File("rig.yaml", ""), rig, "$D/rig.yaml: empty file"},
      {"Bytes0To255", File("rig.yaml", AllBytes()), rig,
       "$D/rig.yaml: neither a Kalibr camchain"},
      {"RandomBytes", File("rig.yaml", RandomBytes()), rig,
       "$D/rig.yaml:5: YAML syntax error"},
      {"YamlEscapeOfAControlByte", File("rig.yaml", "cam0: \"\\\x1b[31m\"\n"),
       rig, "$D/rig.yaml:1: YAML syntax error: unknown escape character"},
      {"NanIntrinsics",
       RigWith("rig.yaml", "intrinsics: [346.68681661781403",
               "intrinsics: [nan"),
       rig, "$D/rig.yaml:7: cam0.intrinsics: 'nan' is not a finite number"},
      {"InfIntrinsics", RigWith("rig.yaml", "262.02195974034373]", "inf]"), rig,
       "$D/rig.yaml:21: cam1.intrinsics: 'inf' is not a finite number"},
      {"NanDistortion",
       RigWith("rig.yaml", "distortion_coeffs: [-0.037934508908317364",
               "distortion_coeffs: [.nan"),
       rig,
       "$D/rig.yaml:4: cam0.distortion_coeffs: '.nan' is not a finite "
       "number"},
      {"InfDistortion",
       RigWith("rig.yaml", "0.00035009066006595556]", "-.inf]"), rig,
       "$D/rig.yaml:19: cam1.distortion_coeffs: '-.inf' is not a finite "
       "number"},
      {"NanTranslation", RigWith("rig.yaml", row1, "- [1.0, 0.0, 0.0, .nan]"),
       rig,
       "$D/rig.yaml:12: cam1.T_cn_cnm1 row 1: '.nan' is not a finite "
       "number"},
      {"InfRotation",
       RigWith("rig.yaml", "- [0.0, 1.0, 0.0, 0.0]", "- [0.0, inf, 0.0, 0.0]"),
       rig,
       "$D/rig.yaml:13: cam1.T_cn_cnm1 row 2: 'inf' is not a finite number"},
      {"ZeroBaseline", RigWith("rig.yaml", row1, "- [1.0, 0.0, 0.0, 0.0]"), rig,
       "$D/rig.yaml: cam1_from_cam0: zero baseline"},
      {"RotationScaledBy2",
       RigWith("rig.yaml",
               "  - [1.0, 0.0, 0.0, -0.11]\n  - [0.0, 1.0, 0.0, 0.0]\n"
               "  - [0.0, 0.0, 1.0, 0.0]",
               "  - [2.0, 0.0, 0.0, -0.11]\n  - [0.0, 2.0, 0.0, 0.0]\n"
               "  - [0.0, 0.0, 2.0, 0.0]"),
       rig,
       "$D/rig.yaml:12: cam1.T_cn_cnm1: not a rigid transform: rotation is "
       "not orthonormal"},
      {"RotationSheared", RigWith("rig.yaml", row1, "- [1.0, 0.3, 0.0, -0.11]"),
       rig,
       "$D/rig.yaml:12: cam1.T_cn_cnm1: not a rigid transform: rotation is "
       "not orthonormal"},
      {"LastRowNot0001",
       RigWith("rig.yaml", "- [0.0, 0.0, 0.0, 1.0]", "- [0.0, 0.0, 0.1, 1.0]"),
       rig,
       "$D/rig.yaml:12: cam1.T_cn_cnm1: not a rigid transform: last row is"},
      {"CameraInfoBytes0To255",
       Steps({CameraInfos(true, "", ""), File("left.yaml", AllBytes())}), infos,
       "$D/left.yaml: neither a Kalibr camchain"},
      // Of "L.yaml,R.yaml", a file that is empty or not YAML is told by the
      // camera_info parser (it used to be "a Kalibr camchain").
      {"CameraInfoRandomBytes",
       Steps({CameraInfos(false, "", ""), File("right.yaml", RandomBytes(2))}),
       infos, "$D/right.yaml:1: YAML syntax error"},
      {"CameraInfoEmpty",
       Steps({CameraInfos(false, "", ""), File("right.yaml", "")}), infos,
       "$D/right.yaml: empty file"},
      {"CameraInfoMissing",
       Steps({CameraInfos(true, "", ""),
              [](const std::string& dir) { fs::remove(dir + "/right.yaml"); }}),
       infos, "$D/right.yaml: cannot open: No such file or directory"},
      {"CameraInfoNanFocal", CameraInfos(true, "data: [346.7,", "data: [nan,"),
       infos, "$D/left.yaml:7: camera_matrix"},
      {"CameraInfoInfDistortion",
       CameraInfos(false, "[-0.01, 0.002", "[-0.01, .inf"), infos,
       "$D/right.yaml:12: distortion_coefficients"},
      {"CameraInfoZeroBaseline",
       CameraInfos(false, "360.5, " + FormatDouble(kRightP03), "360.5, 0"),
       infos, "zero baseline"},
  };
}

// rcm estimate gets every rig defect above. undistort, export and simulate
// read the rig with the same ReadStereoRig, so they get one of each kind:
// missing, unreadable, empty, binary, NaN and inf in intrinsics,
// distortion and T_cn_cnm1, no baseline, not rigid, bad camera_info.
bool IsCoreRigDefect(const RigDefect& defect) {
  static const char* const kCore[] = {"Missing",
                                      "IsAFolder",
                                      "Empty",
                                      "Bytes0To255",
                                      "RandomBytes",
                                      "NanIntrinsics",
                                      "InfDistortion",
                                      "NanTranslation",
                                      "InfRotation",
                                      "ZeroBaseline",
                                      "RotationScaledBy2",
                                      "LastRowNot0001",
                                      "CameraInfoBytes0To255",
                                      "CameraInfoNanFocal"};
  for (const char* name : kCore) {
    if (defect.name == name) return true;
  }
  return false;
}

// Values outside [1, 2] (or no number) for a flag that takes a refractive
// index.
struct IndexValue {
  std::string name;
  std::string value;
};

const std::vector<IndexValue>& IndexValues() {
  static const std::vector<IndexValue> values = {{"Below1", "0.5"},
                                                 {"Above2", "2.5"},
                                                 {"Nan", "nan"},
                                                 {"Inf", "inf"},
                                                 {"NotANumber", "abc"}};
  return values;
}

// The error line for --FLAG VALUE: RefractiveIndexFromFlag's, or gflags'
// for a value that is no number.
std::string IndexFlagError(const std::string& flag, const std::string& value) {
  if (value == "abc") {
    return "illegal value 'abc' specified for double flag '" + flag + "'";
  }
  return "--" + flag + " " + value + " is outside [1, 2]";
}

// An image file defect, for the subcommands that read stereo folders. The
// setups write $D/left and $D/right.
struct ImageDefect {
  std::string name;
  Setup setup;
  std::string expected;
};

std::vector<ImageDefect> ImageDefects(int width, int height) {
  const Setup right_png = Image("right/000000.png", width, height, 2);
  const Setup right_jpg = Image("right/000000.jpg", width, height, 2);
  return {
      {"LeftFolderMissing", Folder("right"), "$D/left: no such folder"},
      {"LeftFolderIsAFile", Steps({File("left", "a file\n"), right_png}),
       "$D/left: not a folder"},
      {"EmptyFolders", Steps({Folder("left"), Folder("right")}),
       "$D/left: no images"},
      {"PngBytes0To255",
       Steps({File("left/000000.png", AllBytes()), right_png}),
       "$D/left/000000.png: not an image"},
      {"PngRandomBytes",
       Steps({File("left/000000.png", RandomBytes(3)), right_png}),
       "$D/left/000000.png: not an image"},
      {"PngEmpty", Steps({File("left/000000.png", ""), right_png}),
       "$D/left/000000.png: not an image"},
      {"PngTruncated", Steps({TruncatedImage("left/000000.png"), right_png}),
       "$D/left/000000.png: truncated PNG"},
      {"PngCorruptPixelData", Steps({CorruptPng("left/000000.png"), right_png}),
       "$D/left/000000.png: corrupt PNG"},
      {"JpegBytes0To255",
       Steps({File("left/000000.jpg", AllBytes()), right_jpg}),
       "$D/left/000000.jpg: not an image"},
      {"JpegRandomBytes",
       Steps({File("left/000000.jpg", "\xff\xd8\xff" + RandomBytes(4)),
              right_jpg}),
       "$D/left/000000.jpg: corrupt JPEG (marker 0x7A at byte 2 is not a "
       "JPEG marker)"},
      {"JpegTruncated", Steps({TruncatedImage("left/000000.jpg"), right_jpg}),
       "$D/left/000000.jpg: truncated JPEG"},
      {"PairSizesDiffer",
       Steps({Image("left/000000.png", width, height),
              Image("right/000000.png", width / 2, height / 2)}),
       "$D/left/000000.png is " + std::to_string(width) + "x" +
           std::to_string(height) + " but $D/right/000000.png is " +
           std::to_string(width / 2) + "x" + std::to_string(height / 2)},
  };
}

// A bag defect (--bag $D/in.bag).
struct BagDefect {
  std::string name;
  Setup setup;
  std::string expected;
};

std::vector<BagDefect> BagDefects() {
  return {
      {"BagMissing", Nothing(),
       "$D/in.bag: cannot open: No such file or directory"},
      {"BagIsAFolder", Folder("in.bag"),
       "$D/in.bag: is a directory, expected a file"},
      {"BagEmpty", File("in.bag", ""), "$D/in.bag: not a readable ROS1 bag"},
      {"BagBytes0To255", File("in.bag", AllBytes()),
       "$D/in.bag: not a readable ROS1 bag"},
#ifdef RCM_HAVE_ROSBAG
      {"BagTruncated", TruncatedBag("in.bag"),
       "$D/in.bag: not a readable ROS1 bag"},
      {"BagWithCorruptPng", BagWithCorruptPng("in.bag"),
       "@ 1700000000.000000: compressed image: corrupt PNG (chunk IDAT"},
#endif
  };
}

std::vector<std::string> BagArgs() {
  return {"--bag",           "$D/in.bag",     "--left-topic",
          "/cam0/image_raw", "--right-topic", "/cam1/image_raw"};
}

// --- rcm estimate ----------------------------------------------------------

void AddEstimateRows(std::vector<BadInputCase>* rows) {
  for (const RigDefect& defect : RigDefects()) {
    rows->push_back({"EstimateCalib" + defect.name,
                     defect.setup,
                     {"estimate", "--calib", defect.calib, "--matches",
                      kMatches, "--out", "$D/out"},
                     defect.expected,
                     {"$D/out/estimate.json"},
                     defect.skip});
  }
  // The correspondence CSV.
  const std::string header = "frame,xl,yl,xr,yr\n";
  const std::string row = "0,100.5,120.25,90.5,118.75\n";
  const struct {
    std::string name;
    Setup setup;
    std::string matches;
    std::string expected;
  } csv_defects[] = {
      {"Missing", Nothing(), "$D/m.csv",
       "$D/m.csv: cannot open: No such file or directory"},
      {"IsAFolder", Folder("m.csv"), "$D/m.csv", "$D/m.csv: is a directory"},
      {"BelowAFile", File("file", "a file\n"), "$D/file/m.csv",
       "$D/file/m.csv: cannot open: Not a directory"},
      {"Empty", File("m.csv", ""), "$D/m.csv", "$D/m.csv: empty file"},
      {"HeaderOnly", File("m.csv", header), "$D/m.csv",
       "$D/m.csv: no correspondences after the header"},
      {"Bytes0To255", File("m.csv", AllBytes()), "$D/m.csv",
       "$D/m.csv:1: header lacks column 'xl'"},
      {"RandomBytes", File("m.csv", RandomBytes(4)), "$D/m.csv",
       "$D/m.csv:1: header lacks column 'xl'"},
      {"BinaryAfterHeader", File("m.csv", header + row + RandomBytes(5)),
       "$D/m.csv", "$D/m.csv:3: "},
      {"NanPixel", File("m.csv", header + row + "0,nan,120,90,118\n"),
       "$D/m.csv", "$D/m.csv:3: xl: nan is not finite"},
      {"InfPixel", File("m.csv", header + row + "0,100,120,90,inf\n"),
       "$D/m.csv", "$D/m.csv:3: yr: inf is not finite"},
      {"MinusInfPixel", File("m.csv", header + row + "0,100,-inf,90,118\n"),
       "$D/m.csv", "$D/m.csv:3: yl: -inf is not finite"},
      {"OverflowingPixel", File("m.csv", header + row + "0,1e999,120,90,118\n"),
       "$D/m.csv", "$D/m.csv:3: xl: '1e999' is out of the range"},
      {"NanTimestamp",
       File("m.csv", "frame,xl,yl,xr,yr,t\n0,100,120,90,118,nan\n"), "$D/m.csv",
       "$D/m.csv:2: t: nan is not finite"},
      {"NanFrame", File("m.csv", header + row + "nan,100,120,90,118\n"),
       "$D/m.csv", "$D/m.csv:3: frame: 'nan'"},
      {"WrongColumnCount", File("m.csv", header + row + "0,100,120,90\n"),
       "$D/m.csv", "$D/m.csv:3: expected 5 fields, got 4"},
      {"ExtraColumn", File("m.csv", header + row + "0,100,120,90,118,7\n"),
       "$D/m.csv", "$D/m.csv:3: expected 5 fields, got 6"},
      {"HeaderWithoutYr", File("m.csv", "frame,xl,yl,xr\n0,100,120,90\n"),
       "$D/m.csv", "$D/m.csv:1: header lacks column 'yr'"},
  };
  for (const auto& defect : csv_defects) {
    rows->push_back(
        {"EstimateMatches" + defect.name,
         defect.setup,
         {"estimate", "--calib", kRig, "--matches", defect.matches, "--out",
          "$D/out", "--per-frame", "$D/per_frame.csv"},
         defect.expected,
         {"$D/out/estimate.json", "$D/out/per_frame.csv", "$D/per_frame.csv"}});
  }
  // Images.
  const std::vector<std::string> folders = {"--left", "$D/left", "--right",
                                            "$D/right"};
  const std::vector<std::string> image_outputs = {
      "$D/out/estimate.json", "$D/out/matches.csv", "$D/out/per_frame.csv"};
  for (const ImageDefect& defect : ImageDefects(kWidth, kHeight)) {
    rows->push_back(
        {"EstimateImages" + defect.name, defect.setup,
         Concat({"estimate", "--calib", kRig, "--out", "$D/out"}, folders),
         defect.expected, image_outputs});
  }
  rows->push_back(
      {"EstimateImagesPngBadDeflateData",
       Steps({[](const std::string& dir) {
                WritePngWithBadDeflateData(dir + "/left/000000.png");
              },
              Image("right/000000.png")}),
       Concat({"estimate", "--calib", kRig, "--out", "$D/out"}, folders),
       "$D/left/000000.png: corrupt PNG (IDAT data: ", image_outputs});
  rows->push_back(
      {"EstimateImagesJpegDamagedScan",
       Steps({[](const std::string& dir) {
                WriteJpegWithDamagedScan(dir + "/left/000000.jpg");
              },
              Image("right/000000.jpg")}),
       Concat({"estimate", "--calib", kRig, "--out", "$D/out"}, folders),
       "$D/left/000000.jpg: corrupt JPEG (libjpeg: ", image_outputs});
  rows->push_back({"EstimatePairListMissing",
                   Nothing(),
                   {"estimate", "--calib", kRig, "--pairs", "$D/pairs.txt",
                    "--out", "$D/out"},
                   "$D/pairs.txt: cannot open: No such file or directory",
                   image_outputs});
  rows->push_back({"EstimatePairListIsAFolder",
                   Folder("pairs.txt"),
                   {"estimate", "--calib", kRig, "--pairs", "$D/pairs.txt",
                    "--out", "$D/out"},
                   "$D/pairs.txt: is a directory",
                   image_outputs});
  rows->push_back(
      {"EstimatePairListNamesAFolder",
       Steps({Folder("left/000000.png"), Image("right/000000.png"),
              File("pairs.txt", "left/000000.png right/000000.png\n")}),
       {"estimate", "--calib", kRig, "--pairs", "$D/pairs.txt", "--out",
        "$D/out"},
       "$D/pairs.txt:1: $D/left/000000.png: not a file",
       image_outputs});
  rows->push_back({"EstimatePairListBinary",
                   File("pairs.txt", RandomBytes(6)),
                   {"estimate", "--calib", kRig, "--pairs", "$D/pairs.txt",
                    "--out", "$D/out"},
                   "$D/pairs.txt:1: expected LEFT RIGHT [TIMESTAMP]",
                   image_outputs});
  for (const BagDefect& defect : BagDefects()) {
    rows->push_back(
        {"Estimate" + defect.name, defect.setup,
         Concat({"estimate", "--calib", kRig, "--out", "$D/out"}, BagArgs()),
         defect.expected, image_outputs});
  }
  // The search range is an interval of refractive indices.
  for (const IndexValue& value : IndexValues()) {
    for (const bool low : {true, false}) {
      const std::string range =
          low ? value.value + ",1.6" : "1.0," + value.value;
      const std::string expected =
          value.value == "abc"
              ? "--search-range must be MIN,MAX, got '" + range + "'"
              : "--search-range " + range + ": ";
      rows->push_back({std::string("EstimateSearchRange") +
                           (low ? "Low" : "High") + value.name,
                       Nothing(),
                       Concat({"estimate", "--calib", kRig, "--search-range",
                               range, "--out", "$D/out"},
                              folders),
                       expected, image_outputs});
    }
  }
  // The calibration's uncertainty: the drift prior flag and the sidecar.
  for (const auto& [name, value] :
       std::vector<std::pair<std::string, std::string>>{
           {"Text", "abc"},
           {"Negative", "-0.1"},
           {"TooLarge", "20"},
           {"FourNumbers", "0.1,0.1,0.1,0.1"},
           {"Nan", "nan"},
           {"FocalTooLarge", "0.1,0.1,20"},
           {"FocalNegative", "0.1,0.1,-1"}}) {
    rows->push_back({"EstimateDriftPrior" + name,
                     Nothing(),
                     {"estimate", "--calib", kRig, "--matches", kMatches,
                      "--drift-prior", value, "--out", "$D/out"},
                     "--drift-prior must be DEG[,MM[,PCT]]",
                     {"$D/out/estimate.json"}});
  }
  rows->push_back(
      {"EstimateCovarianceSidecarMalformed",
       Steps({File("rig.yaml", test::ReadWholeFile(kRig)),
              File("rig-covariance.yaml", "medium: air\ncam0: [1, 2]\n")}),
       {"estimate", "--calib", "$D/rig.yaml", "--matches", kMatches, "--out",
        "$D/out"},
       "$D/rig-covariance.yaml:2: cam0: ",
       {"$D/out/estimate.json"}});
  rows->push_back(
      {"EstimateCovarianceSidecarNotPositive",
       Steps(
           {File("rig.yaml", test::ReadWholeFile(kRig)),
            File("rig-covariance.yaml",
                 "medium: air\ncam0:\n  intrinsics_covariance:\n  - [-1]\n")}),
       {"estimate", "--calib", "$D/rig.yaml", "--matches", kMatches, "--out",
        "$D/out"},
       "$D/rig-covariance.yaml:4: cam0.intrinsics_covariance: is not positive "
       "semi-definite",
       {"$D/out/estimate.json"}});
  // Outputs that cannot be written.
  rows->push_back({"EstimateOutBelowAFile",
                   File("file", "a file\n"),
                   {"estimate", "--calib", kRig, "--matches", kMatches, "--out",
                    "$D/file/out"},
                   "$D/file/out: cannot create the output folder",
                   {"$D/file/out"}});
  rows->push_back(
      {"EstimateOutIsAFile",
       File("file", "a file\n"),
       {"estimate", "--calib", kRig, "--matches", kMatches, "--out", "$D/file"},
       "$D/file: cannot create the output folder",
       {}});
  // (The lenses taken as calibrated: with the default focal drift prior
  // the wide sigma_n's warning line would come before the error.)
  rows->push_back(
      {"EstimatePerFrameBelowAFile",
       File("file", "a file\n"),
       {"estimate", "--calib", kRig, "--matches", kMatches, "--drift-prior",
        "0.1,0.1,0", "--per-frame", "$D/file/per_frame.csv"},
       "$D/file/per_frame.csv: cannot write",
       {"$D/file/per_frame.csv"}});
}

// --- rcm undistort ---------------------------------------------------------

void AddUndistortRows(std::vector<BadInputCase>* rows) {
  const std::vector<std::string> folder_outputs = {
      "$D/out/camchain.yaml", "$D/out/left.yaml", "$D/out/right.yaml"};
  for (const RigDefect& defect : RigDefects()) {
    if (!IsCoreRigDefect(defect)) continue;
    rows->push_back(
        {"UndistortCalib" + defect.name,
         defect.setup,
         {"undistort", "--calib", defect.calib, "--n", "1.333", "--left",
          "$D/left", "--right", "$D/right", "--out", "$D/out"},
         defect.expected,
         folder_outputs,
         defect.skip});
  }
  for (const IndexValue& value : IndexValues()) {
    rows->push_back(
        {"UndistortN" + value.name,
         Steps({Image("left/000000.png"),
                Image("right/000000.png", kWidth, kHeight, 2)}),
         {"undistort", "--calib", kRig, "--n", value.value, "--left", "$D/left",
          "--right", "$D/right", "--out", "$D/out"},
         IndexFlagError("n", value.value),
         folder_outputs});
  }
  for (const ImageDefect& defect : ImageDefects(kWidth, kHeight)) {
    rows->push_back({"UndistortImages" + defect.name,
                     defect.setup,
                     {"undistort", "--calib", kRig, "--n", "1.333", "--left",
                      "$D/left", "--right", "$D/right", "--out", "$D/out"},
                     defect.expected,
                     folder_outputs});
  }
  rows->push_back(
      {"UndistortImagesOfAnotherSize",
       Steps({Image("left/000000.png", 360, 270),
              Image("right/000000.png", 360, 270, 2)}),
       {"undistort", "--calib", kRig, "--n", "1.333", "--left", "$D/left",
        "--right", "$D/right", "--out", "$D/out"},
       "$D/left/000000.png: image is 360x270 but the calibration's cam0 is "
       "720x540",
       folder_outputs});
  for (const BagDefect& defect : BagDefects()) {
    // To a bag (RewriteBagImages reads it), and to folders (the bag source,
    // as for rcm estimate) when the bag opens.
    if (defect.name == "BagTruncated" || defect.name == "BagWithCorruptPng") {
      rows->push_back({"Undistort" + defect.name + "ToFolders", defect.setup,
                       Concat({"undistort", "--calib", kRig, "--n", "1.333",
                               "--out", "$D/out"},
                              BagArgs()),
                       defect.expected, folder_outputs});
    }
    rows->push_back({"Undistort" + defect.name + "ToBag",
                     defect.setup,
                     Concat({"undistort", "--calib", kRig, "--n", "1.333",
                             "--out", "$D/out.bag"},
                            BagArgs()),
                     defect.expected,
                     {"$D/out.bag", "$D/out-camchain.yaml"}});
  }
  const Setup pair = Steps({File("file", "a file\n"), Image("left/000000.png"),
                            Image("right/000000.png", kWidth, kHeight, 2)});
  rows->push_back({"UndistortOutBelowAFile",
                   pair,
                   {"undistort", "--calib", kRig, "--n", "1.333", "--left",
                    "$D/left", "--right", "$D/right", "--out", "$D/file/out"},
                   "$D/file/out/left: cannot create the output folder",
                   {"$D/file/out"}});
  rows->push_back({"UndistortOutIsAFile",
                   pair,
                   {"undistort", "--calib", kRig, "--n", "1.333", "--left",
                    "$D/left", "--right", "$D/right", "--out", "$D/file"},
                   "$D/file/left: cannot create the output folder",
                   {}});
#ifdef RCM_HAVE_ROSBAG
  rows->push_back({"UndistortBagOutBelowAFile",
                   Steps({File("file", "a file\n"), Bag("in.bag")}),
                   Concat({"undistort", "--calib", kRig, "--n", "1.333",
                           "--out", "$D/file/out.bag"},
                          BagArgs()),
                   "$D/file/out.bag: cannot write: Not a directory",
                   {"$D/file/out.bag", "$D/file/out-camchain.yaml"}});
#endif
}

// --- rcm export ------------------------------------------------------------

void AddExportRows(std::vector<BadInputCase>* rows) {
  const std::vector<std::string> outputs = {
      "$D/out/camchain.yaml", "$D/out/export.json", "$D/out/left.yaml",
      "$D/out/right.yaml"};
  for (const RigDefect& defect : RigDefects()) {
    if (!IsCoreRigDefect(defect)) continue;
    rows->push_back(
        {"ExportCalib" + defect.name,
         defect.setup,
         {"export", "--calib", defect.calib, "--n", "1.333", "--out", "$D/out"},
         defect.expected,
         outputs,
         defect.skip});
  }
  for (const IndexValue& value : IndexValues()) {
    rows->push_back(
        {"ExportN" + value.name,
         Nothing(),
         {"export", "--calib", kRig, "--n", value.value, "--out", "$D/out"},
         IndexFlagError("n", value.value),
         outputs});
  }
  // Coarse grids: the fit runs before the output fails.
  rows->push_back({"ExportOutBelowAFile",
                   File("file", "a file\n"),
                   {"export", "--calib", kRig, "--n", "1.333", "--grid-step",
                    "24", "--out", "$D/file/out"},
                   "$D/file/out/left.yaml: cannot write",
                   {"$D/file/out"}});
  rows->push_back({"ExportOutYamlBelowAFile",
                   File("file", "a file\n"),
                   {"export", "--calib", kRig, "--n", "1.333", "--grid-step",
                    "24", "--out", "$D/file/water.yaml"},
                   "$D/file/water-left.yaml: cannot write",
                   {"$D/file/water.yaml"}});
  rows->push_back({"ExportOutIsAFile",
                   File("file", "a file\n"),
                   {"export", "--calib", kRig, "--n", "1.333", "--grid-step",
                    "24", "--out", "$D/file"},
                   "$D/file/left.yaml: cannot write",
                   {}});
}

// --- rcm simulate ----------------------------------------------------------

// Matches only, one frame: fast.
std::vector<std::string> SimulateArgs(std::vector<std::string> more) {
  return Concat(
      {"simulate", "--noimages", "--matches-per-frame", "10", "--frames", "1"},
      more);
}

void AddSimulateRows(std::vector<BadInputCase>* rows) {
  const std::vector<std::string> outputs = {
      "$D/out/truth.csv", "$D/out/camchain.yaml", "$D/out/matches.csv",
      "$D/out/simulation.json"};
  for (const RigDefect& defect : RigDefects()) {
    if (!IsCoreRigDefect(defect)) continue;
    rows->push_back({"SimulateCalib" + defect.name, defect.setup,
                     SimulateArgs({"--calib", defect.calib, "--out", "$D/out"}),
                     defect.expected, outputs, defect.skip});
  }
  for (const IndexValue& value : IndexValues()) {
    rows->push_back({"SimulateN" + value.name, Nothing(),
                     SimulateArgs({"--n", value.value, "--out", "$D/out"}),
                     IndexFlagError("n", value.value), outputs});
    rows->push_back(
        {"SimulateMedia" + value.name, Nothing(),
         SimulateArgs({"--media", "water:1,1.2:1," + value.value + ":1",
                       "--out", "$D/out"}),
         value.value == "abc"
             ? "--media: media segment 'abc:1'"
             : "--media: medium n = " + value.value + " is outside [1, 2]",
         outputs});
    rows->push_back(
        {"SimulateGlassIndex" + value.name, Nothing(),
         SimulateArgs({"--glass-thickness", "0.005", "--glass-index",
                       value.value, "--out", "$D/out"}),
         value.value == "abc"
             ? IndexFlagError("glass_index", value.value)
             : "glass_index = " + value.value + " is outside [1, 2]",
         outputs});
  }
  rows->push_back(
      {"SimulateExtrinsicDriftMalformed", Nothing(),
       SimulateArgs({"--extrinsic-drift", "0.5,x,0", "--out", "$D/out"}),
       "--extrinsic-drift 0.5,x,0: expected RX,RY,RZ[,TX,TY,TZ]", outputs});
  rows->push_back(
      {"SimulateExtrinsicDriftTooLarge", Nothing(),
       SimulateArgs({"--extrinsic-drift", "0,0,45", "--out", "$D/out"}),
       "rotation of 45 deg is above 10 deg", outputs});
  rows->push_back({"SimulateLensChangeMalformed", Nothing(),
                   SimulateArgs({"--lens-change", "0.5,x", "--out", "$D/out"}),
                   "--lens-change 0.5,x: expected PCT0[,PCT1]", outputs});
  rows->push_back({"SimulateLensChangeTooLarge", Nothing(),
                   SimulateArgs({"--lens-change", "0,8", "--out", "$D/out"}),
                   "lens change of camera 1: a focal scale of 0.08 is outside",
                   outputs});
  rows->push_back(
      {"SimulateBoardAprilGrid", Nothing(),
       SimulateArgs({"--board", "aprilgrid", "--cols", "6", "--rows", "6",
                     "--tag-size", "0.088", "--out", "$D/out"}),
       "--board aprilgrid: rcm simulate renders chessboards only",
       Concat(outputs, {"$D/out/board.csv"})});
  rows->push_back(
      {"SimulateBoardTargetFile",
       File("target.yaml",
            "target_type: 'checkerboard'\ntargetCols: 6\n"
            "targetRows: 7\nrowSpacingMeters: 0.06\n"
            "colSpacingMeters: 0.06\n"),
       SimulateArgs({"--target", "$D/target.yaml", "--out", "$D/out"}),
       "--target: rcm simulate renders chessboards only",
       Concat(outputs, {"$D/out/board.csv"})});
  rows->push_back({"SimulateOutBelowAFile",
                   File("file", "a file\n"),
                   SimulateArgs({"--out", "$D/file/out"}),
                   "cannot create folder $D/file/out: Not a directory",
                   {"$D/file/out"}});
  rows->push_back({"SimulateOutIsAFile",
                   File("file", "a file\n"),
                   SimulateArgs({"--out", "$D/file"}),
                   "$D/file exists and is not a folder",
                   {}});
}

// --- rcm demo --------------------------------------------------------------

void AddDemoRows(std::vector<BadInputCase>* rows) {
  const std::vector<std::string> outputs = {
      "$D/out/summary.json", "$D/out/per_frame.csv", "$D/out/n_per_frame.png",
      "$D/out/before.png", "$D/out/after.png"};
  for (const IndexValue& value : IndexValues()) {
    rows->push_back(
        {"DemoN" + value.name,
         Nothing(),
         {"demo", "--frames", "1", "--n", value.value, "--out", "$D/out"},
         IndexFlagError("n", value.value),
         Concat(outputs, {"$D/out"})});
    rows->push_back(
        {"DemoMedia" + value.name,
         Nothing(),
         {"demo", "--media", "water:1," + value.value + ":1", "--out",
          "$D/out"},
         value.value == "abc"
             ? "--media: media segment 'abc:1'"
             : "--media: medium n = " + value.value + " is outside [1, 2]",
         Concat(outputs, {"$D/out"})});
    rows->push_back(
        {"DemoGlassIndex" + value.name,
         Nothing(),
         {"demo", "--frames", "1", "--glass-thickness", "0.005",
          "--glass-index", value.value, "--out", "$D/out"},
         value.value == "abc"
             ? IndexFlagError("glass_index", value.value)
             : "glass_index = " + value.value + " is outside [1, 2]",
         Concat(outputs, {"$D/out"})});
  }
  rows->push_back({"DemoOutBelowAFile",
                   File("file", "a file\n"),
                   {"demo", "--frames", "1", "--out", "$D/file/out"},
                   "cannot create folder $D/file/out: Not a directory",
                   {"$D/file/out"}});
  rows->push_back({"DemoOutIsAFile",
                   File("file", "a file\n"),
                   {"demo", "--frames", "1", "--out", "$D/file"},
                   "cannot create folder $D/file",
                   {}});
}

// --- rcm compare -----------------------------------------------------------

void AddCompareRows(std::vector<BadInputCase>* rows) {
  const std::vector<std::string> outputs = {"$D/out/compare.json",
                                            "$D/out/compare_residuals.png"};
  for (const RigDefect& defect : RigDefects()) {
    // One camera file: a camchain or one camera_info.
    if (defect.name == "ZeroBaseline" ||
        defect.name == "CameraInfoZeroBaseline") {
      continue;  // a single camera has no baseline
    }
    std::string file = defect.calib;
    if (file == "$D/left.yaml,$D/right.yaml") {
      file = defect.expected.rfind("$D/right.yaml", 0) == 0 ? "$D/right.yaml"
                                                            : "$D/left.yaml";
    }
    // The skipped rows are bugs of the pair reader, which compare does not
    // use.
    rows->push_back(
        {"CompareAir" + defect.name,
         defect.setup,
         {"compare", "--air", file, "--water", kRig, "--out", "$D/out"},
         defect.expected,
         outputs});
    if (defect.name == "Missing" || defect.name == "Bytes0To255" ||
        defect.name == "NanIntrinsics" || defect.name == "CameraInfoNanFocal") {
      rows->push_back(
          {"CompareWater" + defect.name,
           defect.setup,
           {"compare", "--air", kRig, "--water", file, "--out", "$D/out"},
           defect.expected,
           outputs});
    }
  }
  rows->push_back({"CompareUnknownCamera",
                   Nothing(),
                   {"compare", "--air", kRig, "--water", kRig, "--camera",
                    "cam7", "--out", "$D/out"},
                   "cam7",
                   outputs});
  rows->push_back(
      {"CompareOutBelowAFile",
       File("file", "a file\n"),
       {"compare", "--air", kRig, "--water", kRig, "--out", "$D/file/out"},
       "$D/file/out/compare_residuals.png: cannot write",
       {"$D/file/out"}});
  rows->push_back(
      {"CompareOutIsAFile",
       File("file", "a file\n"),
       {"compare", "--air", kRig, "--water", kRig, "--out", "$D/file"},
       "$D/file/compare_residuals.png: cannot write",
       {}});
}

// --- rcm calibrate ---------------------------------------------------------

// Small blank images: nothing to detect, quickly.
constexpr int kBoardWidth = 160;
constexpr int kBoardHeight = 120;

std::vector<std::string> CalibrateArgs(std::vector<std::string> more) {
  return Concat({"calibrate", "--board", "chessboard", "--cols", "7", "--rows",
                 "5", "--square", "0.04", "--folds", "0"},
                more);
}

void AddCalibrateRows(std::vector<BadInputCase>* rows) {
  const std::vector<std::string> outputs = {
      "$D/out/rig.yaml", "$D/out/rig-report/calibration.json"};
  const std::vector<std::string> folders = {
      "--left", "$D/left", "--right", "$D/right", "--out", "$D/out/rig.yaml"};
  for (const ImageDefect& defect : ImageDefects(kBoardWidth, kBoardHeight)) {
    rows->push_back({"CalibrateImages" + defect.name, defect.setup,
                     CalibrateArgs(folders), defect.expected, outputs});
  }
  rows->push_back(
      {"CalibrateImagesOfOneCameraDifferInSize",
       Steps({Image("left/000000.png", kBoardWidth, kBoardHeight),
              Image("right/000000.png", kBoardWidth, kBoardHeight, 2),
              Image("left/000001.png", kBoardWidth / 2, kBoardHeight / 2, 3),
              Image("right/000001.png", kBoardWidth / 2, kBoardHeight / 2, 4)}),
       CalibrateArgs(folders),
       "$D/left/000001.png: 80x60, but the earlier left images are 160x120",
       outputs});
  for (const BagDefect& defect : BagDefects()) {
    rows->push_back(
        {"Calibrate" + defect.name, defect.setup,
         CalibrateArgs(Concat(BagArgs(), {"--out", "$D/out/rig.yaml"})),
         defect.expected, outputs});
  }
  // The target file.
  const Setup pair =
      Steps({Image("left/000000.png", kBoardWidth, kBoardHeight),
             Image("right/000000.png", kBoardWidth, kBoardHeight, 2)});
  const struct {
    std::string name;
    Setup setup;
    std::string expected;
  } target_defects[] = {
      {"Missing", Nothing(),
       "$D/target.yaml: cannot open: No such file or directory"},
      {"IsAFolder", Folder("target.yaml"), "$D/target.yaml: is a directory"},
      {"Empty", File("target.yaml", ""), "$D/target.yaml: empty file"},
      {"Bytes0To255", File("target.yaml", AllBytes()), "$D/target.yaml:"},
      {"RandomBytes", File("target.yaml", RandomBytes(7)), "$D/target.yaml:"},
      {"NanSpacing",
       File("target.yaml",
            "target_type: 'checkerboard'\ntargetCols: 7\ntargetRows: 5\n"
            "rowSpacingMeters: .nan\ncolSpacingMeters: 0.04\n"),
       "rowSpacingMeters"},
  };
  for (const auto& defect : target_defects) {
    rows->push_back(
        {"CalibrateTarget" + defect.name,
         Steps({pair, defect.setup}),
         {"calibrate", "--target", "$D/target.yaml", "--left", "$D/left",
          "--right", "$D/right", "--out", "$D/out/rig.yaml"},
         defect.expected,
         outputs});
  }
  // --corners FILE.vnl (mrcal's corners format) and --corners-out.
  const std::vector<std::string> corner_args = {
      "--corners", "$D/c.vnl", "--left", "$D/left",
      "--right",   "$D/right", "--out",  "$D/out/rig.yaml"};
  std::string full_board;  // 35 rows of the 7x5 board for one left image
  for (int i = 0; i < 35; ++i) full_board += "$D/left/000000.png 10 20 0\n";
  std::string nine_by_six;  // 54 rows: a 9x6 board's
  for (int i = 0; i < 54; ++i) nine_by_six += "a.png 10 20 0\n";
  const struct {
    std::string name;
    Setup setup;
    std::string expected;
  } corners_defects[] = {
      {"Missing", pair, "$D/c.vnl: cannot open: No such file or directory"},
      {"Empty", Steps({pair, File("c.vnl", "# filename x y level\n")}),
       "$D/c.vnl: no corners (no data rows)"},
      {"RowWithoutY", Steps({pair, File("c.vnl", "a.png 10\n")}),
       "$D/c.vnl:1: a row is 'filename x y [level]', got 2 fields"},
      {"RowWithAnExtraColumn",
       Steps({pair, File("c.vnl", "a.png 10 20 0 1\n")}),
       "$D/c.vnl:1: a row is 'filename x y [level]', got 5 fields"},
      {"OfAnotherBoard",
       Steps({pair, File("c.vnl", "# filename x y level\n" + nine_by_six)}),
       "$D/c.vnl:2: a.png has 54 rows, but the target has 35 points: corners "
       "of another board"},
      {"Nan", Steps({pair, File("c.vnl", "a.png nan 20 0\n")}),
       "$D/c.vnl:1: x and y must be finite numbers or '-'"},
      {"Bytes0To255", Steps({pair, File("c.vnl", AllBytes())}), "$D/c.vnl:"},
      {"ImagesOfNeitherCamera",
       Steps({pair, File("c.vnl", "elsewhere/a.png - - -\n")}),
       "$D/c.vnl: none of its 1 image matches --left $D/left or --right "
       "$D/right"},
      {"ImagesNotAtHand",
       FileInDir("c.vnl",
                 "$D/left/000000.png - - -\n$D/right/000000.png - - -\n"),
       "give --image-size W,H"},
  };
  for (const auto& defect : corners_defects) {
    rows->push_back({"CalibrateCorners" + defect.name, defect.setup,
                     CalibrateArgs(corner_args), defect.expected, outputs});
  }
  rows->push_back({"CalibrateCornersWithABadImageSize",
                   FileInDir("c.vnl", full_board),
                   CalibrateArgs(Concat(corner_args, {"--image-size", "640"})),
                   "--image-size 640: expected W,H in pixels", outputs});
  rows->push_back({"CalibrateCornersAndABag", pair,
                   CalibrateArgs({"--corners", "$D/c.vnl", "--bag", "$D/b.bag",
                                  "--out", "$D/out/rig.yaml"}),
                   "--corners takes --left and --right", outputs});
  rows->push_back(
      {"CalibrateCornersOutInAMissingFolder", pair,
       CalibrateArgs(Concat(folders, {"--corners-out", "$D/nowhere/c.vnl"})),
       "--corners-out $D/nowhere/c.vnl: folder $D/nowhere does "
       "not exist",
       Concat(outputs, {"$D/nowhere/c.vnl"})});
  rows->push_back({"CalibrateImageSizeWithoutCorners", pair,
                   CalibrateArgs(Concat(folders, {"--image-size", "640,480"})),
                   "--image-size goes with --corners", outputs});

  // Outputs that cannot be written.
  const Setup pair_and_file = Steps({pair, File("file", "a file\n")});
  rows->push_back({"CalibrateOutBelowAFile",
                   pair_and_file,
                   CalibrateArgs({"--left", "$D/left", "--right", "$D/right",
                                  "--out", "$D/file/rig.yaml"}),
                   "cannot create folder $D/file",
                   {"$D/file/rig.yaml"}});
  rows->push_back({"CalibrateOutIsAFile",
                   pair_and_file,
                   CalibrateArgs({"--left", "$D/left", "--right", "$D/right",
                                  "--out", "$D/file"}),
                   "cannot create folder $D/file",
                   {}});
  rows->push_back({"CalibrateOutIsAFolder",
                   Steps({pair, Folder("out/rig.yaml")}),
                   CalibrateArgs({"--left", "$D/left", "--right", "$D/right",
                                  "--out", "$D/out/rig.yaml"}),
                   "$D/out/rig.yaml: is a folder",
                   {"$D/out/rig-report"}});
  rows->push_back(
      {"CalibrateReportBelowAFile",
       pair_and_file,
       CalibrateArgs({"--left", "$D/left", "--right", "$D/right", "--out",
                      "$D/out/rig.yaml", "--report", "$D/file/report"}),
       "cannot create folder $D/file/report",
       {"$D/out/rig.yaml", "$D/file/report"}});
}

std::vector<BadInputCase> AllRows() {
  std::vector<BadInputCase> rows;
  AddCalibrateRows(&rows);
  AddCompareRows(&rows);
  AddDemoRows(&rows);
  AddEstimateRows(&rows);
  AddExportRows(&rows);
  AddSimulateRows(&rows);
  AddUndistortRows(&rows);
  return rows;
}

// ---------------------------------------------------------------------------
// The checks.

// What libraries print on their own, which must never reach the user.
constexpr const char* kForeignMessages[] = {
    "terminate called", "Check failed", "AddressSanitizer", "runtime error",
    "libpng",           "Corrupt JPEG", "Premature end"};

// The regular files under `dir` with their contents.
std::map<std::string, std::string> Snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  std::error_code error;
  for (auto it = fs::recursive_directory_iterator(dir, error);
       !error && it != fs::recursive_directory_iterator();
       it.increment(error)) {
    std::error_code file_error;
    if (it->is_symlink(file_error) || !it->is_regular_file(file_error)) {
      continue;
    }
    files[it->path().string()] = test::ReadWholeFile(it->path().string());
  }
  return files;
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A PNG that ends with its IEND chunk, a JPEG that ends with its
// end-of-image marker.
bool IsWholeImageFile(const std::string& path, const std::string& bytes) {
  if (EndsWith(path, ".png")) {
    return bytes.rfind("\x89PNG\r\n\x1a\n", 0) == 0 && bytes.size() >= 12 &&
           bytes.compare(bytes.size() - 8, 4, "IEND") == 0;
  }
  if (EndsWith(path, ".jpg") || EndsWith(path, ".jpeg")) {
    return bytes.size() >= 4 && bytes.rfind("\xff\xd8", 0) == 0 &&
           EndsWith(bytes, "\xff\xd9");
  }
  return false;
}

// Valid UTF-8 without control characters (C0, DEL, C1) before the final
// newline: no raw byte of a binary input, no terminal control sequence.
bool IsPrintableLine(const std::string& text) {
  size_t i = 0;
  while (i + 1 < text.size()) {
    const auto byte = static_cast<unsigned char>(text[i]);
    int length = 1;
    uint32_t code = byte;
    if (byte >= 0xf0 && byte <= 0xf4) {
      length = 4;
      code = byte & 0x07;
    } else if (byte >= 0xe0) {
      length = 3;
      code = byte & 0x0f;
    } else if (byte >= 0xc2 && byte <= 0xdf) {
      length = 2;
      code = byte & 0x1f;
    } else if (byte >= 0x80) {
      return false;  // a continuation byte, or an overlong or invalid lead
    }
    if (i + length > text.size() - 1) return false;
    for (int k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xc0) != 0x80) return false;
      code = code << 6 | (next & 0x3f);
    }
    if (code < 0x20 || (code >= 0x7f && code < 0xa0)) return false;
    i += length;
  }
  return true;
}

class CliBadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(CliBadInput, Refuses) {
  const BadInputCase& row = GetParam();
  if (!row.skip.empty()) GTEST_SKIP() << row.skip;
  const std::string dir = test::TempFilePath("case");
  fs::remove_all(dir);
  fs::create_directories(dir);
  row.setup(dir);
  if (HasFatalFailure()) return;
  const std::map<std::string, std::string> before = Snapshot(dir);

  std::vector<std::string> args;
  for (const std::string& arg : row.args) args.push_back(Expand(arg, dir));
  const RunResult result = test::RunProgram(RCM_BINARY, args);

  std::string command = "rcm";
  for (const std::string& arg : args) command += " " + arg;
  SCOPED_TRACE(command);
  RecordProperty("stderr", result.err);
  EXPECT_NE(result.exit_code, -1) << "killed by a signal\n" << result.err;
  EXPECT_GT(result.exit_code, 0) << result.err;
  EXPECT_TRUE(test::IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_TRUE(IsPrintableLine(result.err)) << "stderr:\n" << result.err;
  const std::string expected = Expand(row.expected, dir);
  EXPECT_NE(result.err.find(expected), std::string::npos)
      << "expected: " << expected << "\nstderr:   " << result.err;
  for (const char* foreign : kForeignMessages) {
    EXPECT_EQ(result.err.find(foreign), std::string::npos) << result.err;
  }

  for (const std::string& path : row.absent) {
    EXPECT_FALSE(fs::exists(Expand(path, dir))) << Expand(path, dir);
  }
  // Inputs untouched; nothing new but whole pictures written before the
  // failure (no temporary file, no truncated image, no camchain, CSV or
  // JSON).
  const std::map<std::string, std::string> after = Snapshot(dir);
  for (const auto& [path, bytes] : before) {
    const auto found = after.find(path);
    EXPECT_TRUE(found != after.end() && found->second == bytes)
        << path << " was changed or removed";
  }
  for (const auto& [path, bytes] : after) {
    if (before.count(path) > 0) continue;
    EXPECT_TRUE(IsWholeImageFile(path, bytes)) << path << " was left behind";
  }
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, CliBadInput, ::testing::ValuesIn(AllRows()),
    [](const ::testing::TestParamInfo<BadInputCase>& info) {
      return info.param.name;
    });

}  // namespace
}  // namespace rcm::bad_input_table_test
