// Showing text taken from an input file inside a one-line error message.
//
// Every rcm reader quotes the offending value in its error messages, e.g.
//
//   m.csv:2: xl: '1\x0d2' is not a number
//   rig.yaml:3: cam0.camera_model: unknown model 'pin\x0ahole' (...)
//
// The text is shown as it is, except that
//   - control characters (bytes 0x00-0x1f and 0x7f) are written as \xNN
//     with two lowercase hex digits, so that the message stays on one line
//     and the byte that broke the value can be told;
//   - text longer than 40 bytes is cut after 40 bytes and "..." appended.
// Other bytes (including UTF-8 sequences) are passed through.
#ifndef RCM_UTIL_MESSAGE_TEXT_H_
#define RCM_UTIL_MESSAGE_TEXT_H_

#include <cstddef>
#include <string>
#include <string_view>

namespace rcm {

// How many bytes of a value a message shows before "...".
inline constexpr size_t kMaxMessageTextLength = 40;

// `text` with its control characters written as \xNN, whole: for text
// that a message shows in full, such as a parser library's own description
// of an error ("unknown escape character: \x0a").
std::string EscapeControlCharacters(std::string_view text);

// `text` made fit for a one-line message, without quotes:
// "a\tb" -> "a\x09b". For values whose spelling is already known to be
// plain (such as a number that parsed), where quotes would be noise.
std::string EscapeForMessage(std::string_view text);

// `text` as quoted in a one-line message: EscapeForMessage(text) in single
// quotes, "6cm" -> "'6cm'".
std::string QuoteForMessage(std::string_view text);

}  // namespace rcm

#endif  // RCM_UTIL_MESSAGE_TEXT_H_
