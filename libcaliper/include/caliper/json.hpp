/// \file json.hpp
/// The JSON value (RFC 8259) of the project's own files: fitted regressors, protocol files, pose
/// logs (JSON Lines), session journals and reports. Reading and writing are nlohmann-json's (its
/// SAX parser and nlohmann::ordered_json's serialiser, in json.cpp; nlohmann stays out of this
/// header). This class adds what the project's readers need on top: typed access whose errors
/// say what was expected and what was found, missing keys named, and constant-time key lookup.
/// Objects keep their insertion order so that written files are stable and diff well.
///
/// Why a value class of its own and not nlohmann::ordered_json itself: the readers hold
/// `const Json*` / `const Json&` to members (find(), at()), and nlohmann's members are nlohmann
/// values, not Json; and ordered_json looks keys up linearly, which makes objects of many keys
/// quadratic (issue 10).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace caliper {

/// Thrown by parse_json() and by typed accessors. `line` and `column` are 1-based (0 when the
/// error is not about a position in text).
class JsonError : public std::runtime_error {
 public:
  JsonError(const std::string& what, int line_number = 0, int column_number = 0)
      : std::runtime_error(what), line(line_number), column(column_number) {}
  int line;
  int column;
};

class Json {
 public:
  enum class Type { Null, Bool, Number, String, Array, Object };
  using Array = std::vector<Json>;
  using Object = std::vector<std::pair<std::string, Json>>;

  Json() = default;  ///< null
  Json(const Json& other);
  Json(Json&& other) noexcept = default;
  Json& operator=(const Json& other);
  Json& operator=(Json&& other) noexcept = default;
  ~Json() = default;
  Json(std::nullptr_t) {}  ///< null
  Json(bool b) : type_(Type::Bool), bool_(b) {}
  Json(double d) : type_(Type::Number), number_(d) {}
  Json(int i) : type_(Type::Number), number_(i) {}
  Json(long i) : type_(Type::Number), number_(static_cast<double>(i)) {}
  Json(long long i) : type_(Type::Number), number_(static_cast<double>(i)) {}
  Json(unsigned i) : type_(Type::Number), number_(i) {}
  Json(unsigned long i) : type_(Type::Number), number_(static_cast<double>(i)) {}
  Json(const char* s) : type_(Type::String), string_(s) {}
  Json(std::string s) : type_(Type::String), string_(std::move(s)) {}
  Json(Array a) : type_(Type::Array), array_(std::move(a)) {}
  Json(const std::vector<double>& v);
  static Json object() {
    Json j;
    j.type_ = Type::Object;
    return j;
  }
  /// An object with `members` in order, as set() one after the other (a repeated key: the last
  /// one wins). Json::set returns the member, so it does not chain; this builds a whole object in
  /// one expression.
  static Json object(std::initializer_list<std::pair<std::string, Json>> members);
  static Json array() {
    Json j;
    j.type_ = Type::Array;
    return j;
  }

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::Null; }
  bool is_bool() const { return type_ == Type::Bool; }
  bool is_number() const { return type_ == Type::Number; }
  bool is_string() const { return type_ == Type::String; }
  bool is_array() const { return type_ == Type::Array; }
  bool is_object() const { return type_ == Type::Object; }

  /// Typed access; throws JsonError("expected a number, found a string") on a type mismatch.
  bool as_bool() const;
  double as_number() const;
  int as_int() const;  ///< a number that is an integer in int range
  const std::string& as_string() const;
  const Array& as_array() const;
  Array& as_array();
  const Object& as_object() const;
  std::vector<double> as_numbers() const;  ///< an array of numbers

  /// Object access. `at` throws JsonError naming the missing key; `find` returns nullptr.
  /// Constant time on average: objects of kIndexFrom members or more keep a hash index, so that
  /// reading or building an object of n keys is linear in n.
  const Json& at(const std::string& key) const;
  const Json* find(const std::string& key) const;
  bool contains(const std::string& key) const { return find(key) != nullptr; }
  /// Inserts or replaces `key` (turns a null into an object).
  Json& set(const std::string& key, Json value);
  /// Appends to an array (turns a null into an array).
  void push_back(Json value);
  /// Array element or object member count; 0 for scalars.
  size_t size() const;
  const Json& operator[](size_t i) const;

  /// Serialises (nlohmann::ordered_json::dump). indent < 0: one line with no spaces (for JSON
  /// Lines); otherwise pretty-printed, `indent` spaces a level, one array element a line.
  /// Integral numbers below 1e15 are written as integers ("3"); other numbers as the shortest
  /// text that reads back to the same double, so doubles round-trip exactly. NaN and infinity
  /// cannot be represented in JSON: dump() throws JsonError for them. Bytes of a string that are
  /// not valid UTF-8 are written as U+FFFD (JSON text is UTF-8; the reader refuses anything else).
  std::string dump(int indent = -1) const;

 private:
  void dump_to(std::string& out, int indent, int depth) const;
  /// Objects smaller than this are searched linearly (faster than hashing for a few keys).
  static constexpr size_t kIndexFrom = 16;
  using Index = std::unordered_map<std::string, size_t>;  ///< key -> position in object_
  Type type_ = Type::Null;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  Array array_;
  Object object_;
  std::unique_ptr<Index> index_;  ///< only for objects of kIndexFrom members or more
};

/// Parses one JSON text (surrounding white space allowed, nothing else after it; UTF-8; no
/// comments, NaN or Infinity). Arrays and objects nested deeper than 256 levels are refused. A
/// duplicate key keeps its first position and its last value. Throws JsonError with the 1-based
/// line and column of the problem ("line 3, column 14: syntax error while parsing value -
/// unexpected
/// ','; ...": the message after the position is nlohmann's).
Json parse_json(const std::string& text);

/// Reads and parses a whole file; errors name the file (and line, column).
Json read_json_file(const std::string& path);

/// Reads the JSON file `path` and converts it with `from_json` (a callable taking `const Json&`).
/// A JsonError or a `Caught` error is rethrown as an `Error` that names the file
/// ("<path>: <what>"); a file that cannot be read or parsed throws JsonError (read_json_file).
template <class Error, class Caught, class FromJson>
auto read_json_file_as(const std::string& path, FromJson from_json) {
  const Json j = read_json_file(path);
  try {
    return from_json(j);
  } catch (const JsonError& e) {
    throw Error(path + ": " + e.what());
  } catch (const Caught& e) {
    throw Error(path + ": " + e.what());
  }
}

/// The start of one of the project's versioned JSON files: {"format": `format`, "version": 1}
/// (what check_format_version accepts); the caller adds the file's other members.
Json format_header(const std::string& format);

/// True when `j` is an object whose "format" member is the string `format`: how the project's
/// JSON files say what they are ("caliper-regressors", "caliper-mapping", ...).
bool has_format(const Json& j, const std::string& format);

/// Checks the start of one of the project's versioned JSON files: its format is `format` and its
/// "version" is 1. Otherwise throws `Error`: "not a <kind>: expected "format": "<format>"" or
/// "<kind> version <v> is not supported (this build reads version 1)" (JsonError when "version"
/// is missing or not an integer).
template <class Error>
void check_format_version(const Json& j, const std::string& format, const std::string& kind) {
  if (!has_format(j, format))
    throw Error("not a " + kind + ": expected \"format\": \"" + format + "\"");
  const int version = j.at("version").as_int();
  if (version != 1) {
    throw Error(kind + " version " + std::to_string(version) +
                " is not supported (this build reads version 1)");
  }
}

/// Writes `value.dump(2)` to `path` atomically (smpl::write_file_atomic: temporary file in the
/// same folder, fsync, rename). Throws JsonError for NaN or infinity (nothing is written) and
/// smpl::WriteError when writing fails (the previous file is then unchanged).
void write_json_file(const std::string& path, const Json& value);

}  // namespace caliper
