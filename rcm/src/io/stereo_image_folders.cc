#include "rcm/io/stereo_image_folders.h"

#include <glog/logging.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <future>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <utility>
#include <vector>

#include "rcm/io/atomic_file.h"
#include "rcm/io/image_file.h"
#include "rcm/util/message_text.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

namespace fs = std::filesystem;

constexpr const char* kImageExtensions[] = {"png", "jpg", "jpeg", "pgm",
                                            "ppm", "bmp", "tif",  "tiff"};

// Integers with at least this many digits name nanosecond stamps.
constexpr size_t kNanosecondDigits = 16;

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

char ToLower(char c) { return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c; }

bool IsImageName(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  const size_t dot = name.rfind('.');
  if (dot == std::string::npos || dot == 0) return false;
  std::string extension = name.substr(dot + 1);
  for (char& c : extension) c = ToLower(c);
  return std::find(std::begin(kImageExtensions), std::end(kImageExtensions),
                   extension) != std::end(kImageExtensions);
}

std::string_view Stem(std::string_view name) {
  return name.substr(0, name.rfind('.'));
}

// Natural order (see the header): <0, 0 or >0. Zero only for equal names.
int CompareNatural(std::string_view a, std::string_view b) {
  size_t i = 0;
  size_t j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      size_t a_end = i;
      while (a_end < a.size() && IsDigit(a[a_end])) ++a_end;
      size_t b_end = j;
      while (b_end < b.size() && IsDigit(b[b_end])) ++b_end;
      // Without leading zeros, keeping one digit of "000".
      while (i + 1 < a_end && a[i] == '0') ++i;
      while (j + 1 < b_end && b[j] == '0') ++j;
      const std::string_view a_digits = a.substr(i, a_end - i);
      const std::string_view b_digits = b.substr(j, b_end - j);
      if (a_digits.size() != b_digits.size()) {
        return a_digits.size() < b_digits.size() ? -1 : 1;
      }
      if (const int c = a_digits.compare(b_digits); c != 0) return c;
      i = a_end;
      j = b_end;
    } else {
      const auto a_byte = static_cast<unsigned char>(a[i]);
      const auto b_byte = static_cast<unsigned char>(b[j]);
      if (a_byte != b_byte) return a_byte < b_byte ? -1 : 1;
      ++i;
      ++j;
    }
  }
  if (i < a.size()) return 1;
  if (j < b.size()) return -1;
  return a.compare(b);
}

// What a file name's stem says about the image's time.
enum class StampKind { kNone, kNanoseconds, kSeconds };

StampKind KindOf(std::string_view stem) {
  size_t digits = 0;
  size_t points = 0;
  for (size_t k = 0; k < stem.size(); ++k) {
    if (IsDigit(stem[k])) {
      ++digits;
    } else if (stem[k] == '.' && k > 0 && k + 1 < stem.size()) {
      ++points;
    } else {
      return StampKind::kNone;
    }
  }
  if (points == 1) return StampKind::kSeconds;
  if (points == 0 && digits >= kNanosecondDigits) {
    return StampKind::kNanoseconds;
  }
  return StampKind::kNone;
}

std::string KindText(StampKind kind) {
  switch (kind) {
    case StampKind::kNanoseconds:
      return "a stamp in nanoseconds";
    case StampKind::kSeconds:
      return "a stamp in seconds";
    case StampKind::kNone:
      break;
  }
  return "no stamp";
}

// Seconds of a stem of kind kNanoseconds or kSeconds.
double StampSeconds(std::string_view stem, StampKind kind) {
  CHECK(kind != StampKind::kNone);
  double seconds = 0.0;
  if (kind == StampKind::kSeconds) {
    std::from_chars(stem.data(), stem.data() + stem.size(), seconds);
    return seconds;
  }
  // Whole seconds and the nine digits of nanoseconds, each exact.
  const std::string_view whole = stem.substr(0, stem.size() - 9);
  const std::string_view nanos = stem.substr(stem.size() - 9);
  uint32_t fraction = 0;
  std::from_chars(whole.data(), whole.data() + whole.size(), seconds);
  std::from_chars(nanos.data(), nanos.data() + nanos.size(), fraction);
  return seconds + fraction * 1e-9;
}

std::string SecondsText(double seconds) { return FormatFixed(seconds, 3); }

// The images of one folder, sorted; stamps empty or one per image.
struct Folder {
  std::string dir;
  std::vector<std::string> names;
  std::vector<double> stamps;

  std::string Path(const std::string& name) const {
    return (fs::path(dir) / name).string();
  }
};

StatusOr<Folder> ListFolder(const std::string& dir) {
  std::error_code error;
  const fs::file_status status = fs::status(dir, error);
  if (status.type() == fs::file_type::not_found) {
    return Status::Error(dir + ": no such folder");
  }
  if (error) return Status::Error(dir + ": " + error.message());
  if (!fs::is_directory(status)) return Status::Error(dir + ": not a folder");

  Folder folder;
  folder.dir = dir;
  fs::directory_iterator it(dir, error);
  for (; !error && it != fs::directory_iterator(); it.increment(error)) {
    const std::string name = it->path().filename().string();
    std::error_code file_error;
    if (IsImageName(name) && it->is_regular_file(file_error)) {
      folder.names.push_back(name);
    }
  }
  if (error) return Status::Error(dir + ": cannot list: " + error.message());
  if (folder.names.empty()) {
    std::string looked_for;
    for (const char* extension : kImageExtensions) {
      looked_for +=
          std::string(looked_for.empty() ? "" : ", ") + "." + extension;
    }
    return Status::Error(dir + ": no images (looked for " + looked_for + ")");
  }
  std::sort(folder.names.begin(), folder.names.end(),
            [](const std::string& a, const std::string& b) {
              return CompareNatural(a, b) < 0;
            });

  // Stamps when every name is one of the same kind.
  const StampKind first_kind = KindOf(Stem(folder.names.front()));
  const std::string* stamped = nullptr;
  const std::string* other = nullptr;
  for (const std::string& name : folder.names) {
    const StampKind kind = KindOf(Stem(name));
    if (kind != StampKind::kNone && stamped == nullptr) stamped = &name;
    if (kind != first_kind && other == nullptr) other = &name;
  }
  if (stamped == nullptr) return folder;
  if (other != nullptr) {
    // Name a stamped file first, and one that differs from it.
    const StampKind stamped_kind = KindOf(Stem(*stamped));
    if (stamped == other) other = &folder.names.front();
    return Status::Error(dir + ": " + *stamped + " carries " +
                         KindText(stamped_kind) + " but " + *other +
                         " carries " + KindText(KindOf(Stem(*other))) +
                         ": name every image by its stamp (in one unit) or "
                         "none");
  }
  std::vector<std::pair<double, std::string>> by_time;
  for (std::string& name : folder.names) {
    by_time.emplace_back(StampSeconds(Stem(name), first_kind), std::move(name));
  }
  std::stable_sort(
      by_time.begin(), by_time.end(),
      [](const auto& a, const auto& b) { return a.first < b.first; });
  folder.names.clear();
  for (auto& [stamp, name] : by_time) {
    if (!folder.stamps.empty() && stamp == folder.stamps.back()) {
      return Status::Error(dir + ": " + folder.names.back() + " and " + name +
                           " carry the same timestamp, " + FormatDouble(stamp) +
                           " s: timestamps must increase from pair to pair");
    }
    folder.stamps.push_back(stamp);
    folder.names.push_back(std::move(name));
  }
  return folder;
}

std::string Ordinal(int n) {
  const int last_two = n % 100;
  const int last = n % 10;
  const char* suffix = "th";
  if (last_two < 11 || last_two > 13) {
    if (last == 1) suffix = "st";
    if (last == 2) suffix = "nd";
    if (last == 3) suffix = "rd";
  }
  return std::to_string(n) + suffix;
}

// One pair before selection.
struct PairFiles {
  std::string left;
  std::string right;
  std::optional<double> timestamp;
  // "pairs.txt:7: " for list entries, for messages; else empty.
  std::string origin;
};

// Pairs two listed folders (rules in the header). `how` is set to
// "paired by name" or "paired by order".
StatusOr<std::vector<PairFiles>> PairFolders(const Folder& left,
                                             const Folder& right,
                                             std::string* how) {
  const std::unordered_set<std::string> right_names(right.names.begin(),
                                                    right.names.end());
  const std::unordered_set<std::string> left_names(left.names.begin(),
                                                   left.names.end());
  std::vector<std::string> left_alone;
  for (const std::string& name : left.names) {
    if (right_names.count(name) == 0) left_alone.push_back(name);
  }
  std::vector<std::string> right_alone;
  for (const std::string& name : right.names) {
    if (left_names.count(name) == 0) right_alone.push_back(name);
  }
  const size_t shared = left.names.size() - left_alone.size();
  const std::string counts =
      left.dir + " has " + std::to_string(left.names.size()) + " images, " +
      right.dir + " " + std::to_string(right.names.size());

  std::vector<PairFiles> pairs;
  if (left_alone.empty() && right_alone.empty()) {
    *how = "paired by name";
    for (size_t i = 0; i < left.names.size(); ++i) {
      PairFiles pair;
      pair.left = left.Path(left.names[i]);
      pair.right = right.Path(left.names[i]);
      if (!left.stamps.empty()) pair.timestamp = left.stamps[i];
      pairs.push_back(std::move(pair));
    }
    return pairs;
  }
  if (shared > 0) {
    std::string message = counts;
    for (const auto& [alone, other_dir] :
         {std::pair{&left_alone, &right.dir},
          std::pair{&right_alone, &left.dir}}) {
      if (alone->empty()) continue;
      message += "; " + alone->front() + " has no partner in " + *other_dir;
      if (alone->size() > 1) {
        message += " (nor have " + std::to_string(alone->size() - 1) + " more)";
      }
    }
    return Status::Error(message + ": pair the images with a list file");
  }
  if (left.names.size() != right.names.size()) {
    return Status::Error(counts +
                         ", and no name is in both, so the images can be "
                         "paired neither by name nor by order: pair them "
                         "with a list file");
  }
  *how = "paired by order";
  // With stamps on both sides, a pair's two stamps must agree to within
  // half a frame interval, or the folders are out of step.
  const size_t n = left.names.size();
  if (!left.stamps.empty() && !right.stamps.empty() && n >= 2) {
    std::vector<double> intervals;
    for (size_t i = 1; i < n; ++i) {
      intervals.push_back(left.stamps[i] - left.stamps[i - 1]);
    }
    std::nth_element(intervals.begin(),
                     intervals.begin() + intervals.size() / 2, intervals.end());
    const double tolerance = 0.5 * intervals[intervals.size() / 2];
    for (size_t i = 0; i < n; ++i) {
      const double offset = std::abs(right.stamps[i] - left.stamps[i]);
      if (offset > tolerance) {
        return Status::Error(
            "pairing by order: " + left.Path(left.names[i]) + " and " +
            right.Path(right.names[i]) + " are " + SecondsText(offset) +
            " s apart, more than half the frame interval (" +
            SecondsText(tolerance) +
            " s): the folders are out of step; pair the images with a list "
            "file");
      }
    }
  }
  for (size_t i = 0; i < n; ++i) {
    PairFiles pair;
    pair.left = left.Path(left.names[i]);
    pair.right = right.Path(right.names[i]);
    if (!left.stamps.empty()) pair.timestamp = left.stamps[i];
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

std::string_view TrimBlanks(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) {
    text.remove_prefix(1);
  }
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) {
    text.remove_suffix(1);
  }
  return text;
}

std::vector<std::string_view> SplitListLine(std::string_view line) {
  std::vector<std::string_view> fields;
  if (line.find(',') != std::string_view::npos) {
    while (true) {
      const size_t comma = line.find(',');
      fields.push_back(TrimBlanks(line.substr(0, comma)));
      if (comma == std::string_view::npos) return fields;
      line.remove_prefix(comma + 1);
    }
  }
  size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && (line[k] == ' ' || line[k] == '\t')) ++k;
    const size_t start = k;
    while (k < line.size() && line[k] != ' ' && line[k] != '\t') ++k;
    if (k > start) fields.push_back(line.substr(start, k - start));
  }
  return fields;
}

StatusOr<std::vector<PairFiles>> ReadPairList(const std::string& list_path) {
  StatusOr<std::string> contents = ReadFileToString(list_path);
  if (!contents.ok()) return contents.status();
  const fs::path base = fs::path(list_path).parent_path();
  std::vector<PairFiles> pairs;
  // The line of the first pair, and whether it had a timestamp.
  int first_line = 0;
  bool with_stamps = false;
  std::string_view text = *contents;
  for (int line_number = 1; !text.empty(); ++line_number) {
    const size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    line = TrimBlanks(line);
    if (line.empty() || line.front() == '#') continue;

    const std::string where = list_path + ":" + std::to_string(line_number);
    const std::vector<std::string_view> fields = SplitListLine(line);
    if (fields.size() != 2 && fields.size() != 3) {
      return Status::Error(where + ": expected LEFT RIGHT [TIMESTAMP], found " +
                           std::to_string(fields.size()) +
                           (fields.size() == 1 ? " field" : " fields"));
    }
    PairFiles pair;
    pair.origin = where + ": ";
    for (int side = 0; side < 2; ++side) {
      if (fields[side].empty()) {
        return Status::Error(where + ": empty " +
                             (side == 0 ? "left" : "right") + " path");
      }
      fs::path path{std::string(fields[side])};
      if (path.is_relative() && !base.empty()) path = base / path;
      std::error_code error;
      const fs::file_status status = fs::status(path, error);
      if (status.type() == fs::file_type::not_found) {
        return Status::Error(where + ": " + path.string() + ": no such file");
      }
      if (!fs::is_regular_file(status)) {
        return Status::Error(where + ": " + path.string() + ": not a file");
      }
      (side == 0 ? pair.left : pair.right) = path.string();
    }
    const bool has_stamp = fields.size() == 3;
    if (pairs.empty()) {
      first_line = line_number;
      with_stamps = has_stamp;
    } else if (has_stamp != with_stamps) {
      return Status::Error(where +
                           (has_stamp ? ": a timestamp, but line "
                                      : ": no timestamp, "
                                        "but line ") +
                           std::to_string(first_line) +
                           (with_stamps ? " has one" : " has none") +
                           ": give a timestamp on every line or on none");
    }
    if (has_stamp) {
      const std::string_view field = fields[2];
      double stamp = 0.0;
      const auto [stop, error] =
          std::from_chars(field.data(), field.data() + field.size(), stamp);
      if (error != std::errc() || stop != field.data() + field.size() ||
          field.empty() || !std::isfinite(stamp)) {
        return Status::Error(where + ": timestamp " + QuoteForMessage(field) +
                             " is not a number of seconds");
      }
      pair.timestamp = stamp;
    }
    pairs.push_back(std::move(pair));
  }
  if (pairs.empty()) return Status::Error(list_path + ": no pairs listed");
  return pairs;
}

// Errors: a pair whose timestamp is not after the previous pair's.
Status CheckIncreasing(const std::vector<PairFiles>& pairs) {
  for (size_t i = 1; i < pairs.size(); ++i) {
    const PairFiles& before = pairs[i - 1];
    const PairFiles& pair = pairs[i];
    if (!before.timestamp || !pair.timestamp) continue;
    if (*pair.timestamp > *before.timestamp) continue;
    return Status::Error(pair.origin + pair.left +
                         " (t = " + FormatDouble(*pair.timestamp) +
                         " s) is not after " + before.left +
                         " (t = " + FormatDouble(*before.timestamp) +
                         " s): timestamps must increase from pair to pair");
  }
  return Status::Ok();
}

// What the selection did, e.g. " (every 2nd, t = 10.000 s to end, of 240)";
// empty when it keeps every pair.
std::string SelectionText(const FrameSelection& selection, size_t total) {
  std::vector<std::string> parts;
  if (selection.stride > 1)
    parts.push_back("every " + Ordinal(selection.stride));
  if (selection.HasTimeRange()) {
    parts.push_back("t = " + SecondsText(selection.from_s.value_or(0.0)) +
                    " s to " +
                    (selection.to_s ? SecondsText(*selection.to_s) + " s"
                                    : std::string("end")));
  }
  if (parts.empty()) return "";
  std::string text = " (" + parts.front();
  for (size_t k = 1; k < parts.size(); ++k) text += ", " + parts[k];
  return text + (parts.size() > 1 ? ", of " : " of ") + std::to_string(total) +
         ")";
}

std::string DepthText(int depth) {
  switch (depth) {
    case CV_8S:
      return "8-bit signed";
    case CV_16U:
      return "16-bit";
    case CV_16S:
      return "16-bit signed";
    case CV_32S:
      return "32-bit integer";
    case CV_32F:
      return "32-bit float";
    case CV_64F:
      return "64-bit float";
    default:
      break;
  }
  return cv::typeToString(CV_MAKETYPE(depth, 1));
}

// Decodes one file as stored: 8-bit gray or BGR (BGRA loses alpha).
StatusOr<cv::Mat> DecodeImage(const std::string& path) {
  StatusOr<cv::Mat> decoded = ReadImageAsStored(path);
  if (!decoded.ok()) return decoded.status();
  const cv::Mat& image = *decoded;
  if (image.depth() != CV_8U) {
    return Status::Error(path + ": " + DepthText(image.depth()) +
                         " image, expected 8-bit");
  }
  switch (image.channels()) {
    case 1:
    case 3:
      return image;
    case 4: {
      cv::Mat bgr;
      cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
      return bgr;
    }
    default:
      break;
  }
  return Status::Error(path + ": " + std::to_string(image.channels()) +
                       "-channel image, expected 1 (gray), 3 (BGR) or 4 "
                       "(BGRA)");
}

std::string SizeText(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

class ImageFileSource : public StereoImageSource {
 public:
  ImageFileSource(std::vector<PairFiles> pairs, std::vector<size_t> selected,
                  std::string description)
      : pairs_(std::move(pairs)),
        selected_(std::move(selected)),
        description_(std::move(description)) {}

  size_t NumPairs() const override { return selected_.size(); }

  StatusOr<StereoImagePair> ReadPair(size_t i) override {
    CHECK_LT(i, selected_.size()) << "pair index out of range";
    const size_t index = selected_[i];
    const PairFiles& files = pairs_[index];
    if (files.right.empty()) {
      // One camera only (StereoFolderOptions::left_only).
      StatusOr<cv::Mat> left = DecodeImage(files.left);
      if (!left.ok()) return left.status();
      StereoImagePair pair;
      pair.frame = static_cast<int64_t>(index);
      pair.timestamp = files.timestamp;
      pair.left = std::move(left).value();
      pair.left_name = files.left;
      return pair;
    }
    // Decoding takes most of the time of a pair: the right image on a
    // thread of its own.
    std::future<StatusOr<cv::Mat>> right_future =
        std::async(std::launch::async, DecodeImage, files.right);
    StatusOr<cv::Mat> left = DecodeImage(files.left);
    StatusOr<cv::Mat> right = right_future.get();
    if (!left.ok()) return left.status();
    if (!right.ok()) return right.status();
    if (left->size() != right->size()) {
      return Status::Error(files.left + " is " + SizeText(*left) + " but " +
                           files.right + " is " + SizeText(*right) +
                           ": the two images of a pair must have the same "
                           "size");
    }
    // A gray camera next to a color one: both BGR.
    if (left->channels() != right->channels()) {
      cv::Mat& gray = left->channels() == 1 ? *left : *right;
      cv::Mat bgr;
      cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
      gray = bgr;
    }
    StereoImagePair pair;
    pair.frame = static_cast<int64_t>(index);
    pair.timestamp = files.timestamp;
    pair.left = std::move(left).value();
    pair.right = std::move(right).value();
    pair.left_name = files.left;
    pair.right_name = files.right;
    return pair;
  }

  std::string Describe() const override { return description_; }

 private:
  std::vector<PairFiles> pairs_;
  std::vector<size_t> selected_;
  std::string description_;
};

}  // namespace

Status StereoFolderOptions::Check() const {
  if (left_only) {
    if (left_dir.empty() || !right_dir.empty() || !pair_list.empty()) {
      return Status::Error(
          "one camera's images are read from the left folder alone");
    }
    return selection.Check();
  }
  if (!pair_list.empty()) {
    if (!left_dir.empty() || !right_dir.empty()) {
      return Status::Error(
          "give either a pair list or the left and right image folders, not "
          "both");
    }
  } else if (left_dir.empty() && right_dir.empty()) {
    return Status::Error(
        "no stereo images: give the left and right image folders, or a pair "
        "list");
  } else if (left_dir.empty() || right_dir.empty()) {
    return Status::Error(std::string("no ") +
                         (left_dir.empty() ? "left" : "right") +
                         " image folder given");
  }
  return selection.Check();
}

StatusOr<std::unique_ptr<StereoImageSource>> OpenStereoImageFolders(
    const StereoFolderOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  std::vector<PairFiles> pairs;
  // Names the source in messages and in Describe().
  std::string context;
  std::string how;
  if (!options.pair_list.empty()) {
    StatusOr<std::vector<PairFiles>> listed = ReadPairList(options.pair_list);
    if (!listed.ok()) return listed.status();
    pairs = std::move(listed).value();
    context = options.pair_list;
    if (options.selection.HasTimeRange() && !pairs.front().timestamp) {
      return Status::Error(options.pair_list +
                           ": a time range needs timestamps: give each "
                           "pair's stamp in seconds as a third column");
    }
  } else if (options.left_only) {
    StatusOr<Folder> left = ListFolder(options.left_dir);
    if (!left.ok()) return left.status();
    for (size_t i = 0; i < left->names.size(); ++i) {
      PairFiles files;
      files.left = left->Path(left->names[i]);
      if (!left->stamps.empty()) files.timestamp = left->stamps[i];
      pairs.push_back(std::move(files));
    }
    how = "left camera only";
    context = "folder " + options.left_dir;
  } else {
    StatusOr<Folder> left = ListFolder(options.left_dir);
    if (!left.ok()) return left.status();
    StatusOr<Folder> right = ListFolder(options.right_dir);
    if (!right.ok()) return right.status();
    std::error_code error;
    if (fs::equivalent(options.left_dir, options.right_dir, error)) {
      return Status::Error(options.left_dir + " and " + options.right_dir +
                           " are the same folder");
    }
    StatusOr<std::vector<PairFiles>> paired = PairFolders(*left, *right, &how);
    if (!paired.ok()) return paired.status();
    pairs = std::move(paired).value();
    context = "folders " + options.left_dir + " and " + options.right_dir;
  }
  RCM_RETURN_IF_ERROR(CheckIncreasing(pairs));

  std::vector<double> stamps;
  if (pairs.front().timestamp) {
    for (const PairFiles& pair : pairs) stamps.push_back(*pair.timestamp);
  }
  StatusOr<std::vector<size_t>> selected =
      SelectFrames(stamps, pairs.size(), options.selection);
  if (!selected.ok()) return selected.status().WithContext(context);

  // "folders left/ and right/: 120 pairs (every 2nd of 240), paired by
  // name", "120 pairs from list pairs.txt (every 2nd of 240)".
  const char* unit = options.left_only ? " image" : " pair";
  const std::string count = std::to_string(selected->size()) + unit +
                            (selected->size() == 1 ? "" : "s");
  const std::string selection_text =
      SelectionText(options.selection, pairs.size());
  const std::string description =
      options.pair_list.empty()
          ? context + ": " + count + selection_text + ", " + how
          : count + " from list " + options.pair_list + selection_text;
  return std::unique_ptr<StereoImageSource>(std::make_unique<ImageFileSource>(
      std::move(pairs), std::move(selected).value(), std::move(description)));
}

}  // namespace rcm
