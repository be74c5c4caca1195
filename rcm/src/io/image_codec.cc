#include "rcm/io/image_codec.h"

#include <dlfcn.h>
#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
// jpeglib.h uses FILE and size_t without declaring them: after <cstdio>.
#include <jpeglib.h>

#include <mutex>
#include <vector>

#include "image_bytes.h"

namespace rcm {
namespace {

using image_bytes::BigEndian32;

Status NotDecodable() {
  return Status::Error(
      "not an image OpenCV can decode (corrupt or unsupported format)");
}

// ---------------------------------------------------------------------------
// OpenCV's imdecode, loaded on first use.

// cv::imdecode(cv::InputArray, int), by its mangled name (the Itanium C++
// ABI, which gcc and clang share; the signature is OpenCV 4's).
using ImdecodeFunction = cv::Mat (*)(const cv::_InputArray&, int);
constexpr char kImdecodeSymbol[] = "_ZN2cv8imdecodeERKNS_11_InputArrayEi";

struct LoadedImdecode {
  ImdecodeFunction function = nullptr;
  std::string error;  // why `function` is null
};

const LoadedImdecode& OpenCvImdecode() {
  static const LoadedImdecode loaded = [] {
    LoadedImdecode result;
    // Kept loaded to the end of the process: OpenCV's codecs register
    // themselves in static objects.
    void* library = dlopen(RCM_OPENCV_IMGCODECS_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (library == nullptr) {
      const char* error = dlerror();
      result.error = error != nullptr ? error : RCM_OPENCV_IMGCODECS_LIBRARY;
      return result;
    }
    void* symbol = dlsym(library, kImdecodeSymbol);
    if (symbol == nullptr) {
      result.error = std::string(RCM_OPENCV_IMGCODECS_LIBRARY) +
                     " has no cv::imdecode(InputArray, int)";
      return result;
    }
    result.function = reinterpret_cast<ImdecodeFunction>(symbol);
    return result;
  }();
  return loaded;
}

int ImreadFlags(ImageReadMode mode) {
  switch (mode) {
    case ImageReadMode::kGray:
      return 0;  // cv::IMREAD_GRAYSCALE
    case ImageReadMode::kColor:
      return 1;  // cv::IMREAD_COLOR
    case ImageReadMode::kAsStored:
      break;
  }
  return -1;  // cv::IMREAD_UNCHANGED
}

StatusOr<cv::Mat> DecodeWithOpenCv(std::string_view bytes, ImageReadMode mode) {
  const LoadedImdecode& imdecode = OpenCvImdecode();
  if (imdecode.function == nullptr) {
    return Status::Error(
        "cannot decode this format: OpenCV's imgcodecs library could not "
        "be loaded (" +
        imdecode.error + ")");
  }
  cv::Mat image;
  try {
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                         const_cast<char*>(bytes.data()));
    image = imdecode.function(buffer, ImreadFlags(mode));
  } catch (const cv::Exception&) {
    image = cv::Mat();
  }
  if (image.empty()) return NotDecodable();
  return image;
}

// ---------------------------------------------------------------------------
// PNG (libpng), as OpenCV's PngDecoder and PngEncoder.

// libpng's errors and warnings: nothing printed; an error ends the call
// through the jump buffer libpng keeps (png_jmpbuf).
void PngErrorQuietly(png_structp png, png_const_charp) { png_longjmp(png, 1); }
void PngWarningQuietly(png_structp, png_const_charp) {}

struct PngReadSource {
  std::string_view bytes;
  size_t at = 0;
};

void ReadPngBytes(png_structp png, png_bytep out, png_size_t size) {
  auto* source = static_cast<PngReadSource*>(png_get_io_ptr(png));
  if (source->bytes.size() - source->at < size) {
    png_error(png, "the PNG ends early");
  }
  std::memcpy(out, source->bytes.data() + source->at, size);
  source->at += size;
}

// Whether a PNG's chunks before its image data hold an eXIf chunk, whose
// orientation OpenCV may apply.
bool PngHasExif(std::string_view bytes) {
  size_t at = image_bytes::kPngSignature.size();
  while (bytes.size() - at >= 8) {
    const uint64_t length = BigEndian32(bytes, at);
    const std::string_view type = bytes.substr(at + 4, 4);
    if (type == "eXIf") return true;
    if (type == "IDAT" || type == "IEND") return false;
    at += 12 + length;
    if (at > bytes.size()) return false;
  }
  return false;
}

// What the header says, and the image type OpenCV's decoder gives for it
// in `mode` (its readHeader, then imdecode's choice of type).
struct PngLayout {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 0;
  int color_type = 0;
  int type = 0;  // CV_8UC1, ...
};

// libpng's errors longjmp out of the two functions below, so neither holds
// an object with a destructor; the caller holds them.
bool ReadPngHeader(png_structp png, png_infop info, PngReadSource* source,
                   ImageReadMode mode, PngLayout* layout) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_set_read_fn(png, source, ReadPngBytes);
  png_read_info(png, info);
  png_get_IHDR(png, info, &layout->width, &layout->height, &layout->bit_depth,
               &layout->color_type, nullptr, nullptr, nullptr);
  int channels = 1;
  if (layout->color_type == PNG_COLOR_TYPE_RGB ||
      layout->color_type == PNG_COLOR_TYPE_PALETTE) {
    png_bytep transparent = nullptr;
    int transparent_count = 0;
    png_color_16p transparent_values = nullptr;
    png_get_tRNS(png, info, &transparent, &transparent_count,
                 &transparent_values);
    channels = transparent_count > 0 ? 4 : 3;
  } else if (layout->color_type == PNG_COLOR_TYPE_GRAY_ALPHA ||
             layout->color_type == PNG_COLOR_TYPE_RGB_ALPHA) {
    channels = 4;
  }
  int depth = layout->bit_depth == 16 ? CV_16U : CV_8U;
  if (mode != ImageReadMode::kAsStored) {
    depth = CV_8U;
    channels = mode == ImageReadMode::kColor ? 3 : 1;
  }
  layout->type = CV_MAKETYPE(depth, channels);
  return true;
}

// OpenCV's transformations, in its order (PngDecoder::readData), then the
// rows.
bool ReadPngRows(png_structp png, png_infop info, const PngLayout& layout,
                 png_bytep* rows) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  const int depth = CV_MAT_DEPTH(layout.type);
  const int channels = CV_MAT_CN(layout.type);
  if (depth == CV_8U && layout.bit_depth == 16) {
    png_set_strip_16(png);
  } else {
    png_set_swap(png);  // 16-bit samples little-endian, as x86 stores them
  }
  if (channels < 4) {
    png_set_strip_alpha(png);
  } else {
    png_set_tRNS_to_alpha(png);
  }
  if (layout.color_type == PNG_COLOR_TYPE_PALETTE) {
    png_set_palette_to_rgb(png);
  }
  if ((layout.color_type & PNG_COLOR_MASK_COLOR) == 0 && layout.bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(png);
  }
  const bool color = channels > 1;
  if ((layout.color_type & PNG_COLOR_MASK_COLOR) != 0 && color) {
    png_set_bgr(png);
  } else if (color) {
    png_set_gray_to_rgb(png);
  } else {
    png_set_rgb_to_gray(png, 1, 0.299, 0.587);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

StatusOr<cv::Mat> DecodePng(std::string_view bytes, ImageReadMode mode) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr,
                                           PngErrorQuietly, PngWarningQuietly);
  if (png == nullptr) return Status::Error("cannot decode PNG: out of memory");
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return Status::Error("cannot decode PNG: out of memory");
  }
  PngReadSource source{bytes};
  PngLayout layout;
  cv::Mat image;
  std::vector<png_bytep> rows;
  bool read = ReadPngHeader(png, info, &source, mode, &layout);
  if (read) {
    image.create(static_cast<int>(layout.height),
                 static_cast<int>(layout.width), layout.type);
    rows.resize(layout.height);
    for (png_uint_32 y = 0; y < layout.height; ++y) {
      rows[y] = image.ptr(static_cast<int>(y));
    }
    read = ReadPngRows(png, info, layout, rows.data());
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!read) return NotDecodable();
  return image;
}

void WritePngBytes(png_structp png, png_bytep data, png_size_t size) {
  static_cast<std::string*>(png_get_io_ptr(png))
      ->append(reinterpret_cast<const char*>(data), size);
}

void FlushNothing(png_structp) {}

// libpng's errors longjmp out: no object with a destructor here.
bool WritePngPixels(png_structp png, png_infop info, const cv::Mat& image,
                    png_bytep* rows, std::string* out) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_set_write_fn(png, out, WritePngBytes, FlushNothing);
  // OpenCV's defaults when no compression level is given (PngEncoder::write):
  // tuned for speed.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  const int channels = image.channels();
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows),
               image.depth() == CV_8U ? 8 : 16,
               channels == 1   ? PNG_COLOR_TYPE_GRAY
               : channels == 3 ? PNG_COLOR_TYPE_RGB
                               : PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_bgr(png);
  png_set_swap(png);  // from x86's little-endian 16-bit samples
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

// ---------------------------------------------------------------------------
// JPEG (libjpeg), as OpenCV's JpegDecoder and JpegEncoder.

// libjpeg's errors: nothing printed, the call ends through `stop`. Its
// warnings are ignored, as OpenCV's decoder ignores them (the structure
// check of image_file.h refuses such files before they get here).
struct QuietJpegErrors {
  jpeg_error_mgr manager;  // first: libjpeg's `err` points at it
  std::jmp_buf stop;
};

[[noreturn]] void StopAtJpegError(j_common_ptr info) {
  std::longjmp(reinterpret_cast<QuietJpegErrors*>(info->err)->stop, 1);
}

void IgnoreJpegMessage(j_common_ptr, int) {}

void InstallQuietErrors(QuietJpegErrors* errors) {
  jpeg_std_error(&errors->manager);
  errors->manager.error_exit = StopAtJpegError;
  errors->manager.emit_message = IgnoreJpegMessage;
}

// What libjpeg decodes as OpenCV does; false for what goes to OpenCV
// (`*to_opencv`) or is not a JPEG libjpeg reads. No objects with
// destructors here: longjmp skips them.
bool ReadJpegPixels(std::string_view bytes, ImageReadMode mode, cv::Mat* image,
                    bool* to_opencv) {
  jpeg_decompress_struct info = {};
  QuietJpegErrors errors;
  info.err = &errors.manager;
  InstallQuietErrors(&errors);
  if (setjmp(errors.stop) != 0) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()),
               bytes.size());
  jpeg_save_markers(&info, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&info, TRUE);
  bool exif = false;
  for (jpeg_saved_marker_ptr marker = info.marker_list; marker != nullptr;
       marker = marker->next) {
    exif =
        exif || (marker->marker == JPEG_APP0 + 1 && marker->data_length >= 6 &&
                 std::memcmp(marker->data, "Exif\0\0", 6) == 0);
  }
  if ((exif && mode != ImageReadMode::kAsStored) || info.num_components == 4 ||
      info.ac_huff_tbl_ptrs[0] == nullptr ||
      info.dc_huff_tbl_ptrs[0] == nullptr) {
    *to_opencv = true;
    jpeg_destroy_decompress(&info);
    return false;
  }
  const bool color =
      mode == ImageReadMode::kColor ||
      (mode == ImageReadMode::kAsStored && info.num_components > 1);
  info.out_color_space = color ? JCS_EXT_BGR : JCS_GRAYSCALE;
  info.out_color_components = color ? 3 : 1;
  jpeg_start_decompress(&info);
  *image =
      cv::Mat(static_cast<int>(info.output_height),
              static_cast<int>(info.output_width), color ? CV_8UC3 : CV_8UC1);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = image->ptr(static_cast<int>(info.output_scanline));
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

StatusOr<cv::Mat> DecodeJpeg(std::string_view bytes, ImageReadMode mode) {
  cv::Mat image;
  bool to_opencv = false;
  if (ReadJpegPixels(bytes, mode, &image, &to_opencv)) return image;
  if (to_opencv) return DecodeWithOpenCv(bytes, mode);
  return NotDecodable();
}

bool WriteJpegPixels(const cv::Mat& image, int quality, unsigned char** data,
                     unsigned long* size) {
  jpeg_compress_struct info = {};
  QuietJpegErrors errors;
  info.err = &errors.manager;
  InstallQuietErrors(&errors);
  if (setjmp(errors.stop) != 0) {
    jpeg_destroy_compress(&info);
    return false;
  }
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, data, size);
  info.image_width = static_cast<JDIMENSION>(image.cols);
  info.image_height = static_cast<JDIMENSION>(image.rows);
  const bool color = image.channels() == 3;
  info.input_components = color ? 3 : 1;
  info.in_color_space = color ? JCS_EXT_BGR : JCS_GRAYSCALE;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, quality, TRUE);  // baseline quantization tables
  jpeg_start_compress(&info, TRUE);
  while (info.next_scanline < info.image_height) {
    JSAMPROW row =
        const_cast<JSAMPROW>(image.ptr(static_cast<int>(info.next_scanline)));
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  jpeg_destroy_compress(&info);
  return true;
}

}  // namespace

StatusOr<cv::Mat> DecodeImage(std::string_view bytes, ImageReadMode mode) {
  if (bytes.empty()) return NotDecodable();
  if (image_bytes::IsPng(bytes)) {
    if (PngHasExif(bytes) && mode != ImageReadMode::kAsStored) {
      return DecodeWithOpenCv(bytes, mode);
    }
    return DecodePng(bytes, mode);
  }
  if (image_bytes::IsJpeg(bytes)) {
    return DecodeJpeg(bytes, mode);
  }
  return DecodeWithOpenCv(bytes, mode);
}

StatusOr<std::string> EncodePng(const cv::Mat& image) {
  if (image.empty()) return Status::Error("cannot encode an empty image");
  const int depth = image.depth();
  const int channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) ||
      (channels != 1 && channels != 3 && channels != 4)) {
    return Status::Error(
        "PNG holds 8- or 16-bit images with 1, 3 or 4 channels, got " +
        cv::typeToString(image.type()));
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr,
                                            PngErrorQuietly, PngWarningQuietly);
  if (png == nullptr) return Status::Error("PNG encoding: out of memory");
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return Status::Error("PNG encoding: out of memory");
  }
  std::vector<png_bytep> rows(image.rows);
  for (int y = 0; y < image.rows; ++y) {
    rows[y] = const_cast<png_bytep>(image.ptr(y));
  }
  std::string out;
  const bool written = WritePngPixels(png, info, image, rows.data(), &out);
  png_destroy_write_struct(&png, &info);
  if (!written) return Status::Error("PNG encoding failed");
  return out;
}

StatusOr<std::string> EncodeJpeg(const cv::Mat& image, int quality) {
  if (image.empty()) return Status::Error("cannot encode an empty image");
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3) {
    return Status::Error("JPEG holds CV_8UC1 or CV_8UC3 images, got " +
                         cv::typeToString(image.type()));
  }
  if (quality < 1 || quality > 100) {
    return Status::Error("JPEG quality " + std::to_string(quality) +
                         " is not 1 to 100");
  }
  unsigned char* data = nullptr;
  unsigned long size = 0;  // NOLINT(runtime/int): libjpeg's type
  const bool written = WriteJpegPixels(image, quality, &data, &size);
  std::string out;
  if (written && data != nullptr) {
    out.assign(reinterpret_cast<const char*>(data), size);
  }
  std::free(data);
  if (!written) return Status::Error("JPEG encoding failed");
  return out;
}

}  // namespace rcm
