#include "rcm/io/yaml_fields.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

#include "rcm/util/message_text.h"

namespace rcm {
namespace {

// The type of `node`; Undefined for a node that is not defined, whose
// Type() would throw.
YAML::NodeType::value TypeOf(const YAML::Node& node) {
  return node.IsDefined() ? node.Type() : YAML::NodeType::Undefined;
}

// YAML 1.1's spellings of infinity and NaN, which from_chars does not read.
bool IsYamlNonFinite(std::string_view text) {
  static constexpr std::string_view kSpellings[] = {
      ".nan",  ".NaN",  ".NAN",  ".inf",  ".Inf",  ".INF",
      "+.inf", "+.Inf", "+.INF", "-.inf", "-.Inf", "-.INF"};
  for (const std::string_view spelling : kSpellings) {
    if (text == spelling) return true;
  }
  return false;
}

// `text` without the one leading '+' that YAML allows and from_chars does
// not take ("+-1" keeps its '+', and so stays malformed).
std::string_view WithoutPlus(std::string_view text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') {
    text.remove_prefix(1);
  }
  return text;
}

// Reads all of `text` as a T with from_chars.
template <typename T>
NumberSyntax FromChars(std::string_view text, T* value) {
  const std::string_view digits = WithoutPlus(text);
  T parsed{};
  const char* const end = digits.data() + digits.size();
  const std::from_chars_result result =
      std::from_chars(digits.data(), end, parsed);
  if (digits.empty() || result.ptr != end ||
      (result.ec != std::errc() &&
       result.ec != std::errc::result_out_of_range)) {
    return NumberSyntax::kMalformed;
  }
  if (result.ec == std::errc::result_out_of_range) {
    return NumberSyntax::kOutOfRange;
  }
  *value = parsed;
  return NumberSyntax::kOk;
}

// "expected WHAT, got ..." about `node`.
Status Expected(const YamlReader& reader, const YAML::Node& node,
                std::string_view field, std::string_view what) {
  return reader.Error(
      node, field,
      "expected " + std::string(what) + ", got " + DescribeYamlNode(node));
}

// The error about the scalar `node`, which reads as `syntax` (not kOk),
// when it should be `what` ("a number", "an integer").
Status NotANumber(const YamlReader& reader, const YAML::Node& node,
                  std::string_view field, NumberSyntax syntax,
                  std::string_view what) {
  const std::string quoted = QuoteForMessage(node.Scalar());
  switch (syntax) {
    case NumberSyntax::kOutOfRange:
      return reader.Error(node, field, quoted + " is out of range");
    case NumberSyntax::kNotFinite:
      return reader.Error(node, field, quoted + " is not a finite number");
    case NumberSyntax::kOk:
    case NumberSyntax::kMalformed:
      break;
  }
  return reader.Error(node, field, quoted + " is not " + std::string(what));
}

// "expected 4 numbers" or "expected a list of numbers".
std::string ListExpectation(int length, const char* what) {
  if (length < 0) return std::string("expected a list of ") + what;
  return "expected " + std::to_string(length) + " " + what;
}

// The elements of a list read one by one with `read_element`, which takes
// (node, field) and returns a StatusOr<T>.
template <typename T, typename ReadElement>
StatusOr<std::vector<T>> ReadList(const YamlReader& reader,
                                  const YAML::Node& node,
                                  std::string_view field, int length,
                                  const char* what, ReadElement read_element) {
  if (TypeOf(node) != YAML::NodeType::Sequence) {
    return reader.Error(
        node, field,
        ListExpectation(length, what) + ", got " + DescribeYamlNode(node));
  }
  if (length >= 0 && static_cast<int>(node.size()) != length) {
    return reader.Error(
        node, field,
        ListExpectation(length, what) + ", got " + std::to_string(node.size()));
  }
  std::vector<T> values;
  values.reserve(node.size());
  for (const YAML::Node& element : node) {
    StatusOr<T> value = read_element(element, field);
    if (!value.ok()) return value.status();
    values.push_back(std::move(value).value());
  }
  return values;
}

}  // namespace

const YamlEntry* FindYamlEntry(const YamlEntries& entries,
                               std::string_view key) {
  const auto it = entries.find(key);
  return it == entries.end() ? nullptr : &it->second;
}

std::string DescribeYamlNode(const YAML::Node& node) {
  switch (TypeOf(node)) {
    case YAML::NodeType::Scalar:
      return QuoteForMessage(node.Scalar());
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      break;
  }
  return "nothing";
}

NumberSyntax ParseYamlDouble(std::string_view text, double* value) {
  if (IsYamlNonFinite(text)) return NumberSyntax::kNotFinite;
  double parsed = 0.0;
  const NumberSyntax syntax = FromChars(text, &parsed);
  if (syntax != NumberSyntax::kOk) return syntax;
  if (!std::isfinite(parsed)) return NumberSyntax::kNotFinite;
  *value = parsed;
  return NumberSyntax::kOk;
}

NumberSyntax ParseYamlInteger(std::string_view text, int64_t* value) {
  return FromChars(text, value);
}

YamlReader::YamlReader(std::string source_name, std::string syntax_error)
    : source_name_(std::move(source_name)),
      syntax_error_(std::move(syntax_error)) {}

StatusOr<YAML::Node> YamlReader::Load(const std::string& text) const {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& exception) {
    std::string location = source_name_;
    if (!exception.mark.is_null()) {
      location += ":" + std::to_string(exception.mark.line + 1);
    }
    return Status::Error(location + ": " + syntax_error_ + ": " +
                         EscapeControlCharacters(exception.msg));
  } catch (const std::exception& exception) {
    return CannotRead("YAML", exception);
  }
}

Status YamlReader::Error(const YAML::Node& at, std::string_view field,
                         std::string_view message) const {
  std::string text = source_name_;
  if (at.IsDefined()) {
    const YAML::Mark mark = at.Mark();
    if (!mark.is_null()) text += ":" + std::to_string(mark.line + 1);
  }
  if (!field.empty()) text.append(": ").append(EscapeControlCharacters(field));
  return Status::Error(text.append(": ").append(message));
}

Status YamlReader::Error(std::string_view field,
                         std::string_view message) const {
  std::string text = source_name_;
  if (!field.empty()) text.append(": ").append(EscapeControlCharacters(field));
  return Status::Error(text.append(": ").append(message));
}

Status YamlReader::MissingKey(std::string_view field,
                              std::string_view key) const {
  return Error(field, "missing key " + QuoteForMessage(key));
}

StatusOr<YamlEntries> YamlReader::Entries(const YAML::Node& map,
                                          std::string_view field) const {
  if (TypeOf(map) != YAML::NodeType::Map) {
    return Error(map, field, "expected a map, got " + DescribeYamlNode(map));
  }
  YamlEntries entries;
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (TypeOf(it->first) != YAML::NodeType::Scalar) continue;
    const std::string& key = it->first.Scalar();
    if (entries.count(key) > 0) {
      return Error(it->first, field, "duplicate key " + QuoteForMessage(key));
    }
    entries.emplace(key, YamlEntry{it->first, it->second});
  }
  return entries;
}

StatusOr<double> YamlReader::Number(const YAML::Node& node,
                                    std::string_view field) const {
  if (TypeOf(node) != YAML::NodeType::Scalar) {
    return Expected(*this, node, field, "a number");
  }
  double value = 0.0;
  const NumberSyntax syntax = ParseYamlDouble(node.Scalar(), &value);
  if (syntax != NumberSyntax::kOk) {
    return NotANumber(*this, node, field, syntax, "a number");
  }
  return value;
}

StatusOr<int> YamlReader::Integer(const YAML::Node& node,
                                  std::string_view field) const {
  if (TypeOf(node) != YAML::NodeType::Scalar) {
    return Expected(*this, node, field, "an integer");
  }
  int64_t value = 0;
  NumberSyntax syntax = ParseYamlInteger(node.Scalar(), &value);
  if (syntax == NumberSyntax::kOk &&
      (value < std::numeric_limits<int>::min() ||
       value > std::numeric_limits<int>::max())) {
    syntax = NumberSyntax::kOutOfRange;
  }
  if (syntax != NumberSyntax::kOk) {
    return NotANumber(*this, node, field, syntax, "an integer");
  }
  return static_cast<int>(value);
}

StatusOr<std::string> YamlReader::String(const YAML::Node& node,
                                         std::string_view field) const {
  if (TypeOf(node) != YAML::NodeType::Scalar) {
    return Expected(*this, node, field, "a string");
  }
  return node.Scalar();
}

StatusOr<std::vector<double>> YamlReader::NumberList(const YAML::Node& node,
                                                     std::string_view field,
                                                     int length) const {
  return ReadList<double>(
      *this, node, field, length, "numbers",
      [this](const YAML::Node& element, std::string_view element_field) {
        return Number(element, element_field);
      });
}

StatusOr<std::vector<int>> YamlReader::IntegerList(const YAML::Node& node,
                                                   std::string_view field,
                                                   int length) const {
  return ReadList<int>(
      *this, node, field, length, "integers",
      [this](const YAML::Node& element, std::string_view element_field) {
        return Integer(element, element_field);
      });
}

StatusOr<YamlEntries> YamlReader::RootEntries(const YAML::Node& root,
                                              std::string_view expected) const {
  if (TypeOf(root) == YAML::NodeType::Null) return Error("", "empty file");
  if (TypeOf(root) != YAML::NodeType::Map) {
    return Error(root, "",
                 "top level is not a map (" + std::string(expected) +
                     "), got " + DescribeYamlNode(root));
  }
  return Entries(root, "");
}

Status YamlReader::CannotRead(std::string_view document,
                              const std::exception& exception) const {
  return Status::Error(source_name_ + ": cannot read " + std::string(document) +
                       ": " + EscapeControlCharacters(exception.what()));
}

Status YamlReader::ReadMatrix(const YAML::Node& node, std::string_view field,
                              int rows, int cols, double* row_major) const {
  const std::string expected = "expected a " + std::to_string(rows) + "x" +
                               std::to_string(cols) + " matrix (" +
                               std::to_string(rows) + " rows of " +
                               std::to_string(cols) + " numbers)";
  if (TypeOf(node) != YAML::NodeType::Sequence) {
    return Error(node, field, expected + ", got " + DescribeYamlNode(node));
  }
  if (static_cast<int>(node.size()) != rows) {
    return Error(node, field,
                 expected + ", got " + std::to_string(node.size()) + " rows");
  }
  int row = 0;
  for (const YAML::Node& row_node : node) {
    const StatusOr<std::vector<double>> values = NumberList(
        row_node, std::string(field) + " row " + std::to_string(row + 1), cols);
    if (!values.ok()) return values.status();
    for (int col = 0; col < cols; ++col) {
      row_major[row * cols + col] = (*values)[col];
    }
    ++row;
  }
  return Status::Ok();
}

}  // namespace rcm
