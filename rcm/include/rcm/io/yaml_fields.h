// Reading YAML files field by field, with one-line error messages.
//
// Every rcm reader of a YAML file (camchain.h, camera_info.h, stereo rig
// files and rcm::calib's calibration targets) is built on this layer, so
// that they all accept numbers the same way and word their errors the same
// way:
//
//   SOURCE[:LINE]: [FIELD: ]MESSAGE
//
// SOURCE is the name the text was read from (usually the file path), LINE
// the 1-based line of the YAML node the message is about (left out when
// there is none, e.g. for a missing key), FIELD the dotted name of the
// value (left out when empty, e.g. for a problem with the whole document).
// Values from the file are quoted with QuoteForMessage (message_text.h), so
// that a message is always a single line. Examples:
//
//   rig.yaml:18: cam1.intrinsics: 'abc' is not a number
//   rig.yaml:18: cam1.intrinsics: '-.inf' is not a finite number
//   rig.yaml:7: cam0.resolution: expected 2 integers, got 3
//   rig.yaml:13: cam1.T_cn_cnm1 row 4: expected 4 numbers, got 3
//   rig.yaml:8: cam0: duplicate key 'resolution'
//   left.yaml: camera_matrix: missing key 'data'
//   rig.yaml:7: YAML syntax error: end of sequence flow not found
//
// Typical use:
//
//   const YamlReader reader(path);
//   return reader.ReadDocument(text, "the camchain",
//       [&](const YAML::Node& root) -> StatusOr<Camchain> {
//         const StatusOr<YamlEntries> entries =
//             reader.RootEntries(root, "expected cam0, cam1, ...");
//         if (!entries.ok()) return entries.status();
//         ...
//         const YamlEntry* entry = FindYamlEntry(*entries, "intrinsics");
//         if (entry == nullptr) return reader.MissingKey("cam0", "intrinsics");
//         const StatusOr<std::vector<double>> intrinsics =
//             reader.NumberList(entry->value, "cam0.intrinsics", 4);
//         ...
//       });
//
// Nothing here throws, and nothing crashes on any YAML input: yaml-cpp's
// exceptions are caught and turned into errors, and every node is checked
// before it is used (also nodes that are not defined).
#ifndef RCM_IO_YAML_FIELDS_H_
#define RCM_IO_YAML_FIELDS_H_

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

// ---------------------------------------------------------------------------
// Nodes and maps.

// A key of a YAML map with its value. The key node is kept for its line:
// an error about a value that has no line of its own (an empty value is
// marked at the next token) points at the key.
struct YamlEntry {
  YAML::Node key;
  YAML::Node value;
};

// The scalar-keyed entries of a YAML map by key (see YamlReader::Entries).
using YamlEntries = std::map<std::string, YamlEntry, std::less<>>;

// The entry of `key`, or nullptr when the map has none.
const YamlEntry* FindYamlEntry(const YamlEntries& entries,
                               std::string_view key);

// What a node is, for "expected X, got ..." messages: a scalar as quoted by
// QuoteForMessage ('abc'), "a list", "a map", or "nothing" (an empty value
// or an undefined node).
std::string DescribeYamlNode(const YAML::Node& node);

// ---------------------------------------------------------------------------
// Numbers in scalars.

// How the text of a scalar reads as a number.
enum class NumberSyntax {
  kOk,
  kMalformed,   // not (only) a number: "abc", "6cm", "1,5", "+-1", ""
  kOutOfRange,  // too large (or, for a double, too small) for the type
  kNotFinite,   // nan, inf, infinity and YAML's .nan, .inf, -.Inf, ...
};

// Reads all of `text` as a double in decimal or scientific notation with
// an optional sign ('+' included, as YAML allows): "1", "-0.5", "+2.5e-3".
// `*value` is set only when the result is kOk.
NumberSyntax ParseYamlDouble(std::string_view text, double* value);

// Reads all of `text` as a decimal integer with an optional sign ('+'
// included). `*value` is set only when the result is kOk.
NumberSyntax ParseYamlInteger(std::string_view text, int64_t* value);

// ---------------------------------------------------------------------------
// The reader.

// Reads the fields of one YAML text and words the errors, each prefixed
// with the source name the reader is bound to. FIELD arguments are the
// dotted names used in the messages ("cam0.intrinsics"); an empty FIELD is
// left out of the message.
class YamlReader {
 public:
  // The `length` of a list that may have any number of elements.
  static constexpr int kAnyLength = -1;

  // `source_name` starts every message. `syntax_error` is what Load calls
  // a YAML syntax error in its message.
  explicit YamlReader(std::string source_name,
                      std::string syntax_error = "YAML syntax error");

  // --- Documents.

  // The root node of `text`: a map, list or scalar, or a null node when
  // the text holds no document (empty, or only comments). A syntax error
  // fails with "SOURCE:LINE: YAML syntax error: MESSAGE" (yaml-cpp's
  // message; the constructor's `syntax_error` in place of "YAML syntax
  // error"), any other failure of yaml-cpp with "SOURCE: cannot read YAML:
  // WHAT".
  StatusOr<YAML::Node> Load(const std::string& text) const;

  // Loads `text` and returns read(root), where `read` is a callable taking
  // the root node (const YAML::Node&) and returning a StatusOr. Load's
  // errors are returned as they are. Should yaml-cpp throw while `read`
  // works (it throws only on misuse, such as reading an undefined node),
  // the result is "SOURCE: cannot read DOCUMENT: WHAT" rather than an
  // escaping exception; `document` names what is read ("the camchain").
  template <typename Read>
  std::invoke_result_t<Read&, const YAML::Node&> ReadDocument(
      const std::string& text, std::string_view document, Read&& read) const;

  // --- Errors.

  // "SOURCE:LINE: FIELD: MESSAGE" with the line of `at` (left out when it
  // has none). FIELD is built from the file's own keys, so its control
  // characters are escaped (\x0a): the message stays one line.
  Status Error(const YAML::Node& at, std::string_view field,
               std::string_view message) const;
  // "SOURCE: FIELD: MESSAGE", for a problem that no node stands for.
  Status Error(std::string_view field, std::string_view message) const;
  // "SOURCE: FIELD: missing key 'KEY'".
  Status MissingKey(std::string_view field, std::string_view key) const;

  // --- Maps.

  // The scalar-keyed entries of a map; keys that are not scalars are
  // skipped (no rcm file has one). Fails on a duplicated key, "duplicate
  // key 'KEY'" at the second occurrence (yaml-cpp keeps both, and which
  // one a YAML library returns differs), and when `map` is not a map.
  StatusOr<YamlEntries> Entries(const YAML::Node& map,
                                std::string_view field) const;

  // The entries of the root map of a document (see Entries). Fails with
  // "SOURCE: empty file" when there is no document, and with
  // "SOURCE:LINE: top level is not a map (EXPECTED), got 'abc'" when the
  // root is something else; `expected` says what the file should hold
  // ("expected cam0, cam1, ...").
  StatusOr<YamlEntries> RootEntries(const YAML::Node& root,
                                    std::string_view expected) const;

  // --- Scalars.

  // A finite double (see ParseYamlDouble): "'abc' is not a number",
  // "'1e999' is out of range", "'.nan' is not a finite number",
  // "expected a number, got a list".
  StatusOr<double> Number(const YAML::Node& node, std::string_view field) const;

  // An int (see ParseYamlInteger): "'720.5' is not an integer",
  // "'99999999999' is out of range", "expected an integer, got a map".
  StatusOr<int> Integer(const YAML::Node& node, std::string_view field) const;

  // The text of a scalar: "expected a string, got a list". An empty value
  // (`key:`) is not a string; a reader that allows it checks IsNull first.
  StatusOr<std::string> String(const YAML::Node& node,
                               std::string_view field) const;

  // --- Lists.

  // A list of numbers (each read by Number) of `length` elements, or of
  // any length with kAnyLength: "expected 4 numbers, got 3", "expected a
  // list of numbers, got 'abc'".
  StatusOr<std::vector<double>> NumberList(const YAML::Node& node,
                                           std::string_view field,
                                           int length = kAnyLength) const;

  // A list of integers (each read by Integer), as NumberList: "expected 2
  // integers, got 3".
  StatusOr<std::vector<int>> IntegerList(const YAML::Node& node,
                                         std::string_view field,
                                         int length = kAnyLength) const;

  // A kRows x kCols matrix written as a list of kRows rows, each a list of
  // kCols numbers (Kalibr's 4x4 transforms):
  //   - [1.0, 0.0, 0.0, -0.11]
  //   - ...
  // "expected a 4x4 matrix (4 rows of 4 numbers), got 3 rows"; an error
  // inside row i (1-based) names the field "FIELD row i".
  template <int kRows, int kCols>
  StatusOr<Eigen::Matrix<double, kRows, kCols>> Matrix(
      const YAML::Node& node, std::string_view field) const;

 private:
  // "SOURCE: cannot read DOCUMENT: WHAT".
  Status CannotRead(std::string_view document,
                    const std::exception& exception) const;
  // Reads a `rows` x `cols` matrix in the form Matrix describes into
  // `row_major` (rows * cols values).
  Status ReadMatrix(const YAML::Node& node, std::string_view field, int rows,
                    int cols, double* row_major) const;

  std::string source_name_;
  std::string syntax_error_;
};

// ---------------------------------------------------------------------------
// Implementation of the templates.

template <typename Read>
std::invoke_result_t<Read&, const YAML::Node&> YamlReader::ReadDocument(
    const std::string& text, std::string_view document, Read&& read) const {
  try {
    const StatusOr<YAML::Node> root = Load(text);
    if (!root.ok()) return root.status();
    return read(*root);
  } catch (const std::exception& exception) {
    return CannotRead(document, exception);
  }
}

template <int kRows, int kCols>
StatusOr<Eigen::Matrix<double, kRows, kCols>> YamlReader::Matrix(
    const YAML::Node& node, std::string_view field) const {
  static_assert(kRows > 0 && kCols > 0, "a matrix has a fixed, known size");
  std::array<double, kRows * kCols> row_major;
  const Status status = ReadMatrix(node, field, kRows, kCols, row_major.data());
  if (!status.ok()) return status;
  Eigen::Matrix<double, kRows, kCols> matrix;
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kCols; ++col) {
      matrix(row, col) = row_major[row * kCols + col];
    }
  }
  return matrix;
}

}  // namespace rcm

#endif  // RCM_IO_YAML_FIELDS_H_
