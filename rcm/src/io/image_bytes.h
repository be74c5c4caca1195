// The bytes of PNG and JPEG files that both the structure check
// (image_file.cc) and the codec (image_codec.cc) read: the signatures and
// PNG's big-endian 32-bit fields. Private to src/io.
#ifndef RCM_SRC_IO_IMAGE_BYTES_H_
#define RCM_SRC_IO_IMAGE_BYTES_H_

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace rcm::image_bytes {

inline constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);
inline constexpr std::string_view kJpegStart("\xff\xd8\xff", 3);

inline bool IsPng(std::string_view bytes) {
  return bytes.substr(0, kPngSignature.size()) == kPngSignature;
}
inline bool IsJpeg(std::string_view bytes) {
  return bytes.substr(0, kJpegStart.size()) == kJpegStart;
}

inline uint8_t Byte(std::string_view bytes, size_t at) {
  return static_cast<uint8_t>(bytes[at]);
}

// The big-endian 32-bit number at `at` (PNG's chunk lengths, IHDR's size).
inline uint32_t BigEndian32(std::string_view bytes, size_t at) {
  return uint32_t{Byte(bytes, at)} << 24 | uint32_t{Byte(bytes, at + 1)} << 16 |
         uint32_t{Byte(bytes, at + 2)} << 8 | uint32_t{Byte(bytes, at + 3)};
}

}  // namespace rcm::image_bytes

#endif  // RCM_SRC_IO_IMAGE_BYTES_H_
