// Image bytes to pixels and back: PNG through libpng and JPEG through
// libjpeg, called directly and set up as OpenCV 4's own PNG and JPEG codecs
// set them up (imgcodecs' grfmt_png.cpp and grfmt_jpeg.cpp), so the pixels
// are the ones cv::imdecode gives (tests/io/image_codec_test.cc compares
// them byte for byte over every PNG color type and bit depth, interlaced,
// with transparency, and baseline, progressive and gray JPEGs).
//
// Why not cv::imdecode itself: Debian's libopencv_imgcodecs links GDAL, and
// loading it and its ~150 libraries costs 0.2 s at each start of a process
// that links it (the rcm executable started in 0.25 s, 0.05 s without it),
// which is most of a short `rcm` run. Every other format (PPM, BMP, TIFF,
// WebP, ...), a JPEG with an Exif block read as gray or color (OpenCV turns
// it upright by its orientation tag), a CMYK JPEG and a JPEG without its
// Huffman tables (motion JPEG) go to cv::imdecode, loaded on first use
// (dlopen, by the soname of the OpenCV rcm was built with).
#ifndef RCM_IO_IMAGE_CODEC_H_
#define RCM_IO_IMAGE_CODEC_H_

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "rcm/util/status.h"

namespace rcm {

// What DecodeImage returns, as OpenCV's imread flags.
enum class ImageReadMode {
  kGray,      // CV_8UC1 (cv::IMREAD_GRAYSCALE)
  kColor,     // CV_8UC3, BGR (cv::IMREAD_COLOR)
  kAsStored,  // the depth and channels stored, BGR(A) (cv::IMREAD_UNCHANGED)
};

// The pixels of `bytes` in `mode`. Errors: "not an image OpenCV can decode
// (corrupt or unsupported format)" (empty bytes, a damaged file, a format
// OpenCV does not read), "cannot decode <format>: OpenCV's imgcodecs
// library could not be loaded (<dlerror>)". Bytes are not checked here for
// the damage libpng and libjpeg print warnings about:
// CheckImageFileStructure (image_file.h) does that first, and nothing is
// printed here either way.
StatusOr<cv::Mat> DecodeImage(std::string_view bytes, ImageReadMode mode);

// `image` (8- or 16-bit, 1, 3 or 4 channels, BGR order) as PNG bytes, with
// OpenCV's default settings for imencode(".png"): zlib level 1, the Sub
// filter, the RLE strategy. Errors: an empty image, a type PNG cannot hold.
StatusOr<std::string> EncodePng(const cv::Mat& image);

// `image` (CV_8UC1 or CV_8UC3 BGR) as a baseline JPEG of `quality` (1-100),
// 4:2:0 chroma for color, as imencode(".jpg", {IMWRITE_JPEG_QUALITY,
// quality}). Errors: an empty image, another type, a quality out of range.
StatusOr<std::string> EncodeJpeg(const cv::Mat& image, int quality);

}  // namespace rcm

#endif  // RCM_IO_IMAGE_CODEC_H_
