// Image files: PNG output of the plots and remapped images the tools write,
// and image input for the feature front end, with one clear line of error
// instead of OpenCV's empty cv::Mat or exception.
#ifndef RCM_IO_IMAGE_FILE_H_
#define RCM_IO_IMAGE_FILE_H_

#include <opencv2/core.hpp>
#include <string>

#include "rcm/util/status.h"

namespace rcm {

// Encodes `image` (8- or 16-bit, 1, 3 or 4 channels, BGR order) as PNG and
// writes it atomically (WriteFileAtomically, atomic_file.h): readers see the
// old file or the whole new one. Errors: "PATH: cannot write: <reason>"
// (e.g. a missing or read-only directory), an empty image, a type PNG
// cannot hold.
Status WritePng(const cv::Mat& image, const std::string& path);

// Reads an image file in any format OpenCV decodes (PNG, JPEG, PPM, ...) as
// 8-bit: CV_8UC1 when `grayscale`, else CV_8UC3 BGR. Errors: "PATH: cannot
// open: <reason>", "PATH: is a directory, expected a file", "PATH: not an
// image OpenCV can decode (corrupt or unsupported format)".
StatusOr<cv::Mat> ReadImage(const std::string& path, bool grayscale);

// The same, with the depth and channels as stored (cv::IMREAD_UNCHANGED):
// a 16-bit PNG stays 16-bit, an RGBA one BGRA. Same errors.
StatusOr<cv::Mat> ReadImageAsStored(const std::string& path);

}  // namespace rcm

#endif  // RCM_IO_IMAGE_FILE_H_
