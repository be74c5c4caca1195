// Detected target corners as a file, in mrcal's corners format, so that rcm
// and another tool (mrcal-calibrate-cameras --corners-cache) can calibrate
// from identical detections.
//
// The format is mrcal's (and mrgingham's) vnlog:
//
//   # filename x y level
//   left/01.jpg 244.37 94.81 0
//   left/01.jpg 271.02 95.56 0
//   ...
//   left/02.jpg - - -
//
//   - a legend line "# filename x y level" (other lines starting with '#'
//     are comments); fields are separated by blanks;
//   - per image that shows the target, exactly num_points rows, one per
//     target point in TargetPoints order (calibration_target.h: row-major,
//     x along the columns, so a chessboard's point r * cols + c is corner
//     (col c, row r), mrcal's order for an object_width_n = cols,
//     object_height_n = rows board);
//   - x, y in pixels with pixel centers at integers (OpenCV's and mrcal's
//     convention); a point that was not found has x, y (or its level) "-";
//   - level: the detector's decimation level, 0 = full resolution (mrcal
//     weighs a level-l corner by 1 / 2^l). rcm writes 0 and reads any
//     level >= 0, weighing every corner the same; "-" or < 0 means "not
//     found". The level column may be absent (mrcal then assumes 0);
//   - an image in which the target was not found is one row
//     "filename - - -".
//
// The rows of one image are consecutive; the images keep their order.
// File names are written as they are given and may not contain blanks.
#ifndef RCM_CALIB_CORNERS_FILE_H_
#define RCM_CALIB_CORNERS_FILE_H_

#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/target_observation.h"
#include "rcm/util/status.h"

namespace rcm::calib {

// One image of a corners file: its name and the corners found in it
// (nullopt when the target was not found).
struct CornersFileImage {
  std::string filename;
  std::optional<TargetObservation> observation;
};

// The file's text. Fails (one line) on a file name that is empty, contains
// a blank or starts with '#', or an observation with a point id outside
// [0, num_points), a repeated id or a pixel that is not finite.
StatusOr<std::string> FormatCornersFile(
    const std::vector<CornersFileImage>& images, int num_points);

// Writes FormatCornersFile's text to `path` atomically.
Status WriteCornersFile(const std::string& path,
                        const std::vector<CornersFileImage>& images,
                        int num_points);

// Parses a corners file of a target with num_points points (`source_name`
// names it in errors). Fails with one line "NAME:LINE: ..." on a data row
// that has not 3 or 4 fields, a coordinate that is not a finite number, an
// image whose rows are not num_points ("corners of another board"), or an
// image that appears in two separate blocks; and with "NAME: ..." on a file
// without data rows. Observations keep the points that were found, in
// point order, with detector "corners-file".
StatusOr<std::vector<CornersFileImage>> ParseCornersFile(
    const std::string& text, int num_points, const std::string& source_name);
StatusOr<std::vector<CornersFileImage>> ReadCornersFile(const std::string& path,
                                                        int num_points);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CORNERS_FILE_H_
