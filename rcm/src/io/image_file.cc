#include "rcm/io/image_file.h"

#include <zlib.h>

#include <array>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
// jpeglib.h uses FILE and size_t without declaring them: after <cstdio>.
#include <jpeglib.h>

#include <utility>
#include <vector>

#include "image_bytes.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/image_codec.h"

namespace rcm {

Status WritePng(const cv::Mat& image, const std::string& path) {
  if (image.empty()) {
    return Status::Error(path + ": cannot write an empty image");
  }
  const int depth = image.depth();
  const int channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) ||
      (channels != 1 && channels != 3 && channels != 4)) {
    return Status::Error(path + ": PNG holds 8- or 16-bit images with 1, 3 " +
                         "or 4 channels, got " +
                         cv::typeToString(image.type()));
  }
  StatusOr<std::string> encoded = EncodePng(image);
  if (!encoded.ok()) return encoded.status().WithContext(path);
  return WriteFileAtomically(path, *encoded);
}

namespace {

using image_bytes::BigEndian32;
using image_bytes::Byte;
using image_bytes::kPngSignature;

// OpenCV refuses to decode images of more pixels (CV_IO_MAX_IMAGE_PIXELS,
// imgcodecs/src/loadsave.cpp) before it reads their pixel data; the checks
// of the pixel data below leave such images to it rather than inflate or
// decode gigabytes first.
constexpr uint64_t kOpenCvMaxPixels = uint64_t{1} << 30;

const Bytef* ZlibBytes(std::string_view bytes) {
  return reinterpret_cast<const Bytef*>(bytes.data());
}

// The CRC-32 of PNG chunks (ISO 3309), zlib's.
uint32_t Crc32(std::string_view data) {
  return static_cast<uint32_t>(crc32_z(0, ZlibBytes(data), data.size()));
}

std::string Hex(uint8_t byte) {
  char text[8];
  std::snprintf(text, sizeof(text), "0x%02X", byte);
  return text;
}

bool IsLetter(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

Status CorruptPng(const std::string& what) {
  return Status::Error("corrupt PNG (" + what + ")");
}

Status TruncatedPng(const std::string& what) {
  return Status::Error("truncated PNG (" + what + ")");
}

// What the IHDR chunk says about the image data (PNG specification, sec.
// 11.2.2).
struct PngHeader {
  uint32_t width = 0;
  uint32_t height = 0;
  int color_type = 0;
  int bits_per_pixel = 0;
  bool interlaced = false;
};

// libpng's default limit of the width and the height (PNG_USER_WIDTH_MAX,
// PNG_USER_HEIGHT_MAX), which OpenCV keeps: libpng refuses larger images
// with a message on stderr.
constexpr uint32_t kLibpngMaxSize = 1000000;

// The fields of IHDR whose wrong values libpng refuses with a message on
// stderr.
StatusOr<PngHeader> ParsePngHeader(std::string_view ihdr) {
  PngHeader header;
  header.width = BigEndian32(ihdr, 0);
  header.height = BigEndian32(ihdr, 4);
  for (const auto& [name, size] :
       {std::pair{"width", header.width}, std::pair{"height", header.height}}) {
    if (size == 0 || size > kLibpngMaxSize) {
      return CorruptPng("IHDR: " + std::string(name) + " " +
                        std::to_string(size) + " is not 1 to " +
                        std::to_string(kLibpngMaxSize) + " (libpng's limit)");
    }
  }
  const int bit_depth = Byte(ihdr, 8);
  header.color_type = Byte(ihdr, 9);
  int channels = 0;
  bool depth_ok = false;
  switch (header.color_type) {
    case 0:  // gray
      channels = 1;
      depth_ok = bit_depth == 1 || bit_depth == 2 || bit_depth == 4 ||
                 bit_depth == 8 || bit_depth == 16;
      break;
    case 3:  // palette indices
      channels = 1;
      depth_ok =
          bit_depth == 1 || bit_depth == 2 || bit_depth == 4 || bit_depth == 8;
      break;
    case 2:  // RGB
    case 4:  // gray and alpha
    case 6:  // RGBA
      channels = header.color_type == 2 ? 3 : header.color_type == 4 ? 2 : 4;
      depth_ok = bit_depth == 8 || bit_depth == 16;
      break;
    default:
      return CorruptPng("IHDR: color type " +
                        std::to_string(header.color_type) +
                        " is not a PNG color type");
  }
  if (!depth_ok) {
    return CorruptPng("IHDR: bit depth " + std::to_string(bit_depth) +
                      " is not one of color type " +
                      std::to_string(header.color_type));
  }
  header.bits_per_pixel = channels * bit_depth;
  const char* const kMethods[] = {"compression", "filter"};
  for (int i = 0; i < 2; ++i) {
    if (Byte(ihdr, 10 + i) != 0) {
      return CorruptPng("IHDR: " + std::string(kMethods[i]) + " method " +
                        std::to_string(Byte(ihdr, 10 + i)) + ", expected 0");
    }
  }
  if (Byte(ihdr, 12) > 1) {
    return CorruptPng("IHDR: interlace method " +
                      std::to_string(Byte(ihdr, 12)) + ", expected 0 or 1");
  }
  header.interlaced = Byte(ihdr, 12) == 1;
  return header;
}

// The bytes the zlib stream of the IDAT chunks holds: each row of the image
// (of each of the 7 passes of Adam7 interlacing) is a filter type byte and
// its pixels, packed (PNG specification, sec. 7.2 and 8.2).
uint64_t ImageDataSize(const PngHeader& header) {
  const auto rows = [&header](uint64_t width, uint64_t height) {
    if (width == 0 || height == 0) return uint64_t{0};  // an empty pass
    return height * (1 + (width * header.bits_per_pixel + 7) / 8);
  };
  if (!header.interlaced) return rows(header.width, header.height);
  // Adam7: each pass's first column and row and its steps.
  constexpr uint32_t kPasses[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8},
                                      {2, 0, 4, 4}, {0, 2, 2, 4}, {1, 0, 2, 2},
                                      {0, 1, 1, 2}};
  uint64_t size = 0;
  for (const auto& [x0, y0, dx, dy] : kPasses) {
    const uint64_t width =
        header.width > x0 ? (header.width - x0 + dx - 1) / dx : 0;
    const uint64_t height =
        header.height > y0 ? (header.height - y0 + dy - 1) / dy : 0;
    size += rows(width, height);
  }
  return size;
}

// Inflates the data of the IDAT chunks, which start at byte `first_idat`
// and follow each other, through a small buffer: one valid zlib stream
// (its Adler-32 checked) that fills them exactly and holds exactly the
// bytes the header implies. libpng prints what it finds wrong here.
Status CheckPngImageData(std::string_view bytes, size_t first_idat,
                         const PngHeader& header) {
  z_stream stream{};
  if (inflateInit(&stream) != Z_OK) {
    return Status::Error("cannot check PNG data: zlib: out of memory");
  }
  struct End {
    z_stream* stream;
    ~End() { inflateEnd(stream); }
  } end{&stream};
  const uint64_t expected = ImageDataSize(header);
  uint64_t inflated = 0;
  size_t next_chunk = first_idat;  // the next IDAT chunk to inflate
  const auto more_chunks = [&bytes, &next_chunk] {
    return bytes.substr(next_chunk + 4, 4) == "IDAT";
  };
  std::array<Bytef, 16384> buffer;
  while (true) {
    while (stream.avail_in == 0 && more_chunks()) {
      const uint32_t length = BigEndian32(bytes, next_chunk);
      // zlib reads through next_in only (not const without ZLIB_CONST).
      stream.next_in =
          const_cast<Bytef*>(ZlibBytes(bytes.substr(next_chunk + 8)));
      stream.avail_in = length;
      next_chunk += 12 + length;
    }
    stream.next_out = buffer.data();
    stream.avail_out = buffer.size();
    const int result = inflate(&stream, Z_NO_FLUSH);
    inflated += buffer.size() - stream.avail_out;
    if (inflated > expected) {
      return CorruptPng("IDAT data holds more than the " +
                        std::to_string(expected) + " bytes the header implies");
    }
    if (result == Z_STREAM_END) break;
    if (result == Z_BUF_ERROR && stream.avail_in == 0 && !more_chunks()) {
      return CorruptPng("IDAT data ends inside its zlib stream, after " +
                        std::to_string(inflated) + " of the " +
                        std::to_string(expected) + " bytes the header implies");
    }
    if (result == Z_NEED_DICT) {
      return CorruptPng("IDAT data: a zlib stream with a preset dictionary");
    }
    if (result == Z_MEM_ERROR) {
      return Status::Error("cannot check PNG data: zlib: out of memory");
    }
    if (result != Z_OK && result != Z_BUF_ERROR) {
      return CorruptPng(std::string("IDAT data: ") +
                        (stream.msg != nullptr ? stream.msg : "zlib error"));
    }
  }
  uint64_t after_end = stream.avail_in;
  while (more_chunks()) {
    after_end += BigEndian32(bytes, next_chunk);
    next_chunk += 12 + BigEndian32(bytes, next_chunk);
  }
  if (after_end > 0) {
    return CorruptPng("IDAT data has " + std::to_string(after_end) +
                      " bytes after the end of its zlib stream");
  }
  if (inflated != expected) {
    return CorruptPng("IDAT data holds " + std::to_string(inflated) +
                      " bytes, the header implies " + std::to_string(expected));
  }
  return Status::Ok();
}

// Chunk by chunk from the signature to IEND (PNG specification, sec. 5),
// then the image data.
Status CheckPng(std::string_view bytes) {
  size_t at = kPngSignature.size();
  PngHeader header;
  size_t first_idat = 0;  // 0: no IDAT chunk yet
  bool after_idat = false;
  bool palette = false;
  while (true) {
    if (bytes.size() - at < 8) {
      return TruncatedPng("the file ends at byte " +
                          std::to_string(bytes.size()) +
                          ", before its IEND chunk");
    }
    const uint32_t length = BigEndian32(bytes, at);
    const std::string_view type = bytes.substr(at + 4, 4);
    for (char c : type) {
      if (!IsLetter(c)) {
        return CorruptPng("no chunk type at byte " + std::to_string(at + 4));
      }
    }
    const std::string chunk =
        "chunk " + std::string(type) + " at byte " + std::to_string(at);
    if (length > 0x7fffffffu) {
      return CorruptPng(chunk + ": length " + std::to_string(length) +
                        " is over 2^31 - 1");
    }
    if (bytes.size() - at < 12 + uint64_t{length}) {
      return TruncatedPng("the file ends inside " + chunk);
    }
    if (at == kPngSignature.size() && (type != "IHDR" || length != 13)) {
      return CorruptPng("the first chunk is " + std::string(type) +
                        ", expected IHDR");
    }
    if (Crc32(bytes.substr(at + 4, 4 + length)) !=
        BigEndian32(bytes, at + 8 + length)) {
      return CorruptPng(chunk + ": CRC mismatch");
    }
    // What libpng refuses, or warns about on stderr, of the critical chunks
    // (sec. 5.6 and 11.2).
    const bool critical = type[0] >= 'A' && type[0] <= 'Z';
    if (type == "IHDR") {
      if (at != kPngSignature.size()) {
        return CorruptPng(chunk + ": a second IHDR");
      }
      StatusOr<PngHeader> parsed = ParsePngHeader(bytes.substr(at + 8, 13));
      if (!parsed.ok()) return parsed.status();
      header = *parsed;
    } else if (type == "PLTE") {
      if (palette) return CorruptPng(chunk + ": a second PLTE");
      if (first_idat != 0) return CorruptPng(chunk + ": after IDAT");
      if (header.color_type == 0 || header.color_type == 4) {
        return CorruptPng(chunk + ": a palette in a gray image");
      }
      if (length == 0 || length % 3 != 0 || length > 3 * 256) {
        return CorruptPng(chunk + ": length " + std::to_string(length) +
                          " is not 1 to 256 palette entries of 3 bytes");
      }
      palette = true;
    } else if (type == "IDAT") {
      if (after_idat) {
        return CorruptPng(chunk + ": other chunks between IDAT chunks");
      }
      if (header.color_type == 3 && !palette) {
        return CorruptPng(chunk + ": no PLTE chunk before it");
      }
      if (first_idat == 0) first_idat = at;
    } else if (type == "IEND") {
      if (first_idat == 0) return CorruptPng("no IDAT chunk before IEND");
      if (length != 0) {
        return CorruptPng(chunk + ": length " + std::to_string(length) +
                          ", expected 0");
      }
      if (uint64_t{header.width} * header.height > kOpenCvMaxPixels) {
        return Status::Ok();  // OpenCV refuses it unread
      }
      // What follows IEND is not part of the image.
      return CheckPngImageData(bytes, first_idat, header);
    } else if (critical) {
      return CorruptPng(chunk + ": an unknown critical chunk");
    }
    if (first_idat != 0 && type != "IDAT") after_idat = true;
    at += 12 + length;
  }
}

Status CorruptJpeg(const std::string& what) {
  return Status::Error("corrupt JPEG (" + what + ")");
}

Status TruncatedJpeg(const std::string& what) {
  return Status::Error("truncated JPEG (" + what + ")");
}

// libjpeg's error manager, quiet: the first error or warning (a warning is
// corrupt data libjpeg would decode anyway, gray or garbled) stops it
// (libjpeg's state is freed by jpeg_destroy_decompress), nothing is printed.
struct QuietJpegErrors {
  jpeg_error_mgr manager;  // first: libjpeg's `err` points at it
  std::jmp_buf stop;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void StopAtJpegError(j_common_ptr info) {
  auto* errors = reinterpret_cast<QuietJpegErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->stop, 1);
}

void StopAtJpegWarning(j_common_ptr info, int level) {
  if (level < 0) StopAtJpegError(info);  // levels 0 and up: tracing
}

void PrintNothing(j_common_ptr) {}

// libjpeg's reading of the markers and entropy decoding of every scan (no
// inverse DCT, no color conversion): what OpenCV's decoding would warn
// about on stderr, or fail at. False, with `errors->message`, at the first
// error or warning. No objects with destructors here: longjmp skips them.
bool DecodeJpegCoefficients(std::string_view bytes, QuietJpegErrors* errors) {
  jpeg_decompress_struct info = {};
  info.err = jpeg_std_error(&errors->manager);
  errors->manager.error_exit = StopAtJpegError;
  errors->manager.emit_message = StopAtJpegWarning;
  errors->manager.output_message = PrintNothing;
  if (setjmp(errors->stop) != 0) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()),
               bytes.size());
  jpeg_read_header(&info, TRUE);
  if (uint64_t{info.image_width} * info.image_height <= kOpenCvMaxPixels) {
    jpeg_read_coefficients(&info);  // else OpenCV refuses it unread
  }
  jpeg_destroy_decompress(&info);
  return true;
}

// libjpeg's message as a part of ours: without "Corrupt JPEG data: " or
// "Warning: " (ours says so), a capitalized first word (not an acronym, not
// Huffman) in lowercase.
std::string JpegMessage(std::string message) {
  for (std::string_view prefix : {"Corrupt JPEG data: ", "Warning: "}) {
    if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
  }
  if (message.size() > 1 && message[0] >= 'A' && message[0] <= 'Z' &&
      message[1] >= 'a' && message[1] <= 'z' &&
      message.rfind("Huffman", 0) != 0) {
    message[0] = static_cast<char>(message[0] - 'A' + 'a');
  }
  return message;
}

// Marker by marker from SOI to EOI (ITU T.81, annex B): segments by their
// lengths, the entropy-coded data of a scan up to the next marker (in it
// 0xFF is followed by 0x00 or a restart marker); then libjpeg's decoding.
Status CheckJpeg(std::string_view bytes) {
  size_t at = 2;  // after SOI
  bool scan = false;
  while (true) {
    if (at >= bytes.size()) {
      return TruncatedJpeg("the file ends at byte " +
                           std::to_string(bytes.size()) +
                           ", before its end-of-image marker");
    }
    if (Byte(bytes, at) != 0xff) {
      return CorruptJpeg("byte " + std::to_string(at) + " is " +
                         Hex(Byte(bytes, at)) + ", expected a marker");
    }
    while (at < bytes.size() && Byte(bytes, at) == 0xff) ++at;  // fill bytes
    if (at >= bytes.size()) continue;
    const uint8_t marker = Byte(bytes, at);
    const std::string where =
        "marker " + Hex(marker) + " at byte " + std::to_string(at - 1);
    ++at;
    if (marker == 0xd9) {  // EOI
      if (!scan) return CorruptJpeg("end-of-image marker before any scan");
      break;
    }
    if (marker < 0xc0 && marker != 0x01) {
      return CorruptJpeg(where + " is not a JPEG marker");
    }
    if (marker == 0xd8) return CorruptJpeg("a second start-of-image " + where);
    if ((marker >= 0xd0 && marker <= 0xd7) || marker == 0x01) continue;
    if (bytes.size() - at < 2) {
      return TruncatedJpeg("the file ends inside the segment of " + where);
    }
    const size_t length = size_t{Byte(bytes, at)} << 8 | Byte(bytes, at + 1);
    if (length < 2) {
      return CorruptJpeg("segment of " + where + " has length " +
                         std::to_string(length));
    }
    if (bytes.size() - at < length) {
      return TruncatedJpeg("the file ends inside the segment of " + where);
    }
    at += length;
    if (marker != 0xda) continue;
    scan = true;  // SOS: entropy-coded data up to the next marker
    while (true) {
      if (at + 1 >= bytes.size()) {
        return TruncatedJpeg("the file ends inside the scan of " + where +
                             ", before its end-of-image marker");
      }
      if (Byte(bytes, at) == 0xff) {
        const uint8_t next = Byte(bytes, at + 1);
        if (next == 0xff) {
          ++at;
          continue;
        }
        if (next != 0x00 && (next < 0xd0 || next > 0xd7)) break;
      }
      at += Byte(bytes, at) == 0xff ? 2 : 1;
    }
  }
  // What follows EOI is not part of the image.
  QuietJpegErrors errors;
  if (!DecodeJpegCoefficients(bytes.substr(0, at), &errors)) {
    return CorruptJpeg("libjpeg: " + JpegMessage(errors.message));
  }
  return Status::Ok();
}

StatusOr<cv::Mat> DecodeFile(const std::string& path, ImageReadMode mode) {
  StatusOr<std::string> contents = ReadFileToString(path);
  if (!contents.ok()) return contents.status();
  const std::string& bytes = *contents;
  RCM_RETURN_IF_ERROR(CheckImageFileStructure(bytes).WithContext(path));
  StatusOr<cv::Mat> image = DecodeImage(bytes, mode);
  if (!image.ok()) return image.status().WithContext(path);
  return image;
}

}  // namespace

Status CheckImageFileStructure(std::string_view bytes) {
  if (image_bytes::IsPng(bytes)) return CheckPng(bytes);
  if (image_bytes::IsJpeg(bytes)) return CheckJpeg(bytes);
  return Status::Ok();
}

StatusOr<cv::Mat> ReadImage(const std::string& path, bool grayscale) {
  return DecodeFile(path,
                    grayscale ? ImageReadMode::kGray : ImageReadMode::kColor);
}

StatusOr<cv::Mat> ReadImageAsStored(const std::string& path) {
  return DecodeFile(path, ImageReadMode::kAsStored);
}

}  // namespace rcm
