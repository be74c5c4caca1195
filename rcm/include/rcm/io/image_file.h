// Image files: PNG output of the plots and remapped images the tools write,
// and image input for the feature front end, with one clear line of error
// instead of OpenCV's empty cv::Mat or exception.
#ifndef RCM_IO_IMAGE_FILE_H_
#define RCM_IO_IMAGE_FILE_H_

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "rcm/util/status.h"

namespace rcm {

// Encodes `image` (8- or 16-bit, 1, 3 or 4 channels, BGR order) as PNG and
// writes it atomically (WriteFileAtomically, atomic_file.h): readers see the
// old file or the whole new one. Errors: "PATH: cannot write: <reason>"
// (e.g. a missing or read-only directory), an empty image, a type PNG
// cannot hold.
Status WritePng(const cv::Mat& image, const std::string& path);

// Checks the bytes of a PNG or a JPEG file before they are decoded: libpng
// and libjpeg print their own warnings on stderr for a cut or damaged file,
// and libjpeg decodes a cut or damaged JPEG without an error (the missing
// rows gray, the damaged ones garbled). A PNG must have its IHDR chunk
// first with values libpng reads (at most 1000000 pixels wide and high),
// every chunk whole with a matching CRC, a PLTE chunk before the IDAT
// chunks of a palette image, its IDAT chunks one after the other, no
// unknown critical chunk and the IEND chunk; the data of its IDAT chunks
// must be one zlib stream, whole (Adler-32 checked), that inflates to
// exactly the bytes the header implies (inflated through a small buffer,
// not kept). A JPEG must have its markers and segments in order, at least
// one scan and the end-of-image marker (EOI), and libjpeg must read it
// (markers and the entropy-coded data of every scan, no inverse DCT)
// without an error or a warning, printing nothing. What follows IEND or
// EOI is ignored. Bytes that start as neither are not checked (OK).
// Errors, without context: "truncated PNG (the file ends inside chunk IDAT
// at byte 40960)", "corrupt PNG (chunk IDAT at byte 33: CRC mismatch)",
// "corrupt PNG (IDAT data: incorrect data check)" (zlib's message),
// "corrupt PNG (IDAT data holds 8190 bytes, the header implies 8192)",
// "truncated JPEG (the file ends inside the scan of marker 0xDA at byte
// 318, before its end-of-image marker)", "corrupt JPEG (marker 0x7A at
// byte 2 is not a JPEG marker)", "corrupt JPEG (libjpeg: 9695 extraneous
// bytes before marker 0xd9)" (libjpeg's message). Images of more than
// 2^30 pixels, which OpenCV refuses to decode, get the structure check
// only.
Status CheckImageFileStructure(std::string_view bytes);

// Reads an image file in any format OpenCV decodes (PNG, JPEG, PPM, ...) as
// 8-bit: CV_8UC1 when `grayscale`, else CV_8UC3 BGR. Errors: "PATH: cannot
// open: <reason>", "PATH: is a directory, expected a file", "PATH: " and
// CheckImageFileStructure's error, "PATH: not an image OpenCV can decode
// (corrupt or unsupported format)".
StatusOr<cv::Mat> ReadImage(const std::string& path, bool grayscale);

// The same, with the depth and channels as stored (cv::IMREAD_UNCHANGED):
// a 16-bit PNG stays 16-bit, an RGBA one BGRA. Same errors.
StatusOr<cv::Mat> ReadImageAsStored(const std::string& path);

}  // namespace rcm

#endif  // RCM_IO_IMAGE_FILE_H_
