// Where rcm calibrate's corners come from, in air and under water: the
// target detected in the images (--left/--right, --pairs, --bag), or a
// corners file in mrcal's format (--corners FILE.vnl,
// rcm/calib/corners_file.h); and --corners-out FILE.vnl, which writes the
// corners the run calibrates from, so that another tool (mrcal) can be run
// on the same detections.
//
// With --corners, --left and --right say which rows of the file belong to
// which camera: a pattern with one '*' ('data/left*.jpg', as mrcal takes
// them) or a folder (= 'FOLDER/*', what --corners-out writes for folders).
// A left and a right image pair up when the '*' matched the same text
// (left01.jpg and right01.jpg; left/01.jpg and right/01.jpg). The image
// sizes come from the first image of each camera that can be read, or from
// --image-size W,H when the images are not at hand.
#ifndef RCM_EXAMPLES_CLI_CALIBRATION_INPUT_H_
#define RCM_EXAMPLES_CLI_CALIBRATION_INPUT_H_

#include <gflags/gflags.h>

#include <functional>
#include <string>

#include "calibration_run.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/util/status.h"

DECLARE_string(corners);
DECLARE_string(corners_out);
DECLARE_string(image_size);

namespace rcm::cli {

extern const char kCalibrationInputFlagsSource[];

// --corners is given (the images are not read, only their sizes).
bool CornersInputGiven();

// A corners file and the names of its images per camera: --corners with
// --left/--right (--image-size), or the air views' --air-corners with
// --air-left/--air-right.
struct CornersSource {
  std::string file;
  std::string left;        // a folder or a pattern with one '*'
  std::string right;       // empty: one camera (when allowed)
  std::string image_size;  // "W,H" or empty
  // The flags the values came from, for messages.
  struct Flags {
    std::string file = "--corners";
    std::string left = "--left";
    std::string right = "--right";
  } flags;
};

struct CalibrationInput {
  Detections detections;
  // "folders L and R: 13 pairs, paired by name", "corners file F: 26
  // images, 13 pairs".
  std::string description;
};

// The views of a corners file, paired by name (header). Every failure is
// one line naming the flags.
StatusOr<CalibrationInput> ReadCornersInput(
    const calib::CalibrationTarget& target, bool allow_left_only,
    const CornersSource& source);

// Opens the input (corners file or images), checks that the outputs can be
// written (CheckCalibrationOutputPaths), calls `started(description)`, then
// detects the target in every pair (or pairs the file's images), and
// writes --corners-out when given. `allow_left_only`: one camera (--left
// alone) is a valid input. Every failure is one line.
StatusOr<CalibrationInput> ReadCalibrationInput(
    const calib::CalibrationTarget& target, bool allow_left_only,
    const CalibrationOutputPaths& paths,
    const std::function<void(const std::string&)>& started);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_CALIBRATION_INPUT_H_
