#include "rcm/util/message_text.h"

namespace rcm {

std::string EscapeControlCharacters(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string shown;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) {
      shown += "\\x";
      shown += kHex[byte >> 4];
      shown += kHex[byte & 0xf];
    } else {
      shown += c;
    }
  }
  return shown;
}

std::string EscapeForMessage(std::string_view text) {
  std::string shown =
      EscapeControlCharacters(text.substr(0, kMaxMessageTextLength));
  if (text.size() > kMaxMessageTextLength) shown += "...";
  return shown;
}

std::string QuoteForMessage(std::string_view text) {
  return "'" + EscapeForMessage(text) + "'";
}

}  // namespace rcm
