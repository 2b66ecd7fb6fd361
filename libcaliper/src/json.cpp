// caliper::Json on nlohmann-json: reading is nlohmann's SAX parser feeding the value below,
// writing is nlohmann::ordered_json's serialiser. What stays here is the typed access the
// project's readers use (errors that say what was expected and what was found) and the limits a
// hostile file must not pass (nesting depth).
#include "caliper/json.hpp"

#include <nlohmann/json.hpp>

#include "smpl/atomic_file.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/text.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>

namespace caliper {
namespace {

using Ordered = nlohmann::ordered_json;

/// Deeper nesting is refused: no honest file of the project comes near, and a hostile one must
/// not make later recursive code (dump, the readers) run out of stack.
constexpr size_t kMaxDepth = 256;

/// Integral numbers below this magnitude are written without a fraction ("3", not "3.0"), as the
/// project's files always have been; every integer up to it is exact in a double.
constexpr double kWriteAsIntegerBelow = 1e15;

const char* type_name(Json::Type t) {
  static constexpr std::array<const char*, 6> kNames = {"null",     "a boolean", "a number",
                                                        "a string", "an array",  "an object"};
  static_assert(kNames.size() == static_cast<std::size_t>(Json::Type::Object) + 1);
  return smpl::enum_name(t, kNames);
}

[[noreturn]] void type_error(const char* expected, Json::Type found) {
  throw JsonError(std::string("expected ") + expected + ", found " + type_name(found));
}

/// A character iterator over the text that records how far nlohmann's lexer has read, so that an
/// error the builder raises (too deep) can say where it is.
class TrackedIterator {
 public:
  using iterator_category = std::forward_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  TrackedIterator(const char* at, const char** read_to) : at_(at), read_to_(read_to) {}
  reference operator*() const { return *at_; }
  TrackedIterator& operator++() {
    *read_to_ = ++at_;
    return *this;
  }
  TrackedIterator operator++(int) {
    TrackedIterator before = *this;
    ++*this;
    return before;
  }
  bool operator==(const TrackedIterator& o) const { return at_ == o.at_; }
  bool operator!=(const TrackedIterator& o) const { return at_ != o.at_; }

 private:
  const char* at_;
  const char** read_to_;
};

/// 1-based line and column of the character at byte `index` of `text`.
std::pair<int, int> line_and_column(const std::string& text, size_t index) {
  index = std::min(index, text.size());
  int line = 1;
  size_t line_start = 0;
  for (size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return {line, static_cast<int>(index - line_start) + 1};
}

/// nlohmann's message without its "[json.exception.parse_error.101] parse error at line 3,
/// column 14: " prefix (the position is given in the project's own form instead).
std::string without_prefix(std::string what) {
  const size_t tag_end = what.find("] ");
  if (what.rfind("[json.exception.", 0) == 0 && tag_end != std::string::npos)
    what.erase(0, tag_end + 2);
  if (what.rfind("parse error", 0) == 0) {
    const size_t colon = what.find(": ");
    if (colon != std::string::npos) what.erase(0, colon + 2);
  }
  return what;
}

/// Whether the lexer stopped at the first letter of NaN or Infinity (it reports what it read).
bool names_nan_or_infinity(const std::string& last_read) {
  const size_t n = last_read.size();
  if (n == 0 || (last_read[n - 1] != 'N' && last_read[n - 1] != 'I')) return false;
  return n == 1 || !std::isalpha(static_cast<unsigned char>(last_read[n - 2]));
}

/// Builds a Json from nlohmann's SAX events. Duplicate keys: the last value wins, in the first
/// position (Json::set), in constant time, so that reading is linear in the size of the text.
class Builder final : public nlohmann::json_sax<Ordered> {
 public:
  /// `read_to` points at the end of what the lexer has read of the text that starts at `begin`.
  Builder(const char* begin, const char* const* read_to) : begin_(begin), read_to_(read_to) {}

  bool null() override { return scalar(Json()); }
  bool boolean(bool b) override { return scalar(Json(b)); }
  bool number_integer(number_integer_t i) override { return scalar(Json(static_cast<double>(i))); }
  bool number_unsigned(number_unsigned_t u) override {
    return scalar(Json(static_cast<double>(u)));
  }
  // nlohmann refuses numbers that overflow a double (error 406) before they get here.
  bool number_float(number_float_t d, const string_t& /*text*/) override { return scalar(Json(d)); }
  bool string(string_t& s) override { return scalar(Json(std::move(s))); }
  bool binary(binary_t& /*bytes*/) override { return false; }  // not produced by JSON text
  bool start_object(std::size_t /*size*/) override { return open(Json::object()); }
  bool key(string_t& k) override {
    key_ = std::move(k);
    return true;
  }
  bool end_object() override {
    open_.pop_back();
    return true;
  }
  bool start_array(std::size_t /*size*/) override { return open(Json::array()); }
  bool end_array() override {
    open_.pop_back();
    return true;
  }
  bool parse_error(std::size_t position, const std::string& last_token,
                   const nlohmann::detail::exception& e) override {
    constexpr int kNumberOverflow = 406;  // nlohmann's out_of_range.406
    error_ =
        e.id == kNumberOverflow ? "number out of range: " + last_token : without_prefix(e.what());
    if (names_nan_or_infinity(last_token))
      error_ += " (NaN and Infinity are not valid JSON numbers)";
    error_at_ = position;
    return false;
  }

  Json& result() { return root_; }
  const std::string& error() const { return error_; }
  /// Number of characters read when the error was found (its last character is the culprit).
  size_t error_at() const { return error_at_; }

 private:
  /// Adds `v` to the innermost open array or object (or makes it the result); returns where it is.
  Json* put(Json v) {
    if (open_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Json& parent = *open_.back();
    if (parent.is_array()) {
      parent.push_back(std::move(v));
      return &parent.as_array().back();
    }
    return &parent.set(key_, std::move(v));
  }

  bool scalar(Json v) {
    put(std::move(v));
    return true;
  }

  bool open(Json container) {
    if (open_.size() > kMaxDepth) {
      error_ = "nesting deeper than " + std::to_string(kMaxDepth) + " levels";
      error_at_ = static_cast<size_t>(*read_to_ - begin_);
      return false;
    }
    // Pointers into a parent stay valid: a parent gets no new member while a child is open.
    open_.push_back(put(std::move(container)));
    return true;
  }

  const char* begin_;
  const char* const* read_to_;
  Json root_;
  std::vector<Json*> open_;
  std::string key_;
  std::string error_;
  size_t error_at_ = 0;
};

Ordered number_to_ordered(double d) {
  if (!std::isfinite(d)) throw JsonError("cannot write NaN or infinity as JSON");
  if (d == std::floor(d) && std::fabs(d) < kWriteAsIntegerBelow && !(d == 0 && std::signbit(d)))
    return static_cast<std::int64_t>(d);
  return d;  // nlohmann writes the shortest text that reads back to the same double
}

Ordered to_ordered(const Json& v) {
  switch (v.type()) {
    case Json::Type::Null:
      return nullptr;
    case Json::Type::Bool:
      return v.as_bool();
    case Json::Type::Number:
      return number_to_ordered(v.as_number());
    case Json::Type::String:
      return v.as_string();
    case Json::Type::Array: {
      Ordered out = Ordered::array();
      auto& elements = out.get_ref<Ordered::array_t&>();
      elements.reserve(v.size());
      for (const Json& e : v.as_array()) elements.push_back(to_ordered(e));
      return out;
    }
    case Json::Type::Object: {
      Ordered out = Ordered::object();
      // Json's keys are unique already: append without ordered_map's linear search for the key.
      auto& members = static_cast<Ordered::object_t::Container&>(out.get_ref<Ordered::object_t&>());
      members.reserve(v.size());
      for (const auto& [key, value] : v.as_object()) members.emplace_back(key, to_ordered(value));
      return out;
    }
  }
  return nullptr;
}

}  // namespace

Json::Json(const std::vector<double>& v) : type_(Type::Array) {
  array_.reserve(v.size());
  for (double d : v) array_.emplace_back(d);
}

bool Json::as_bool() const {
  if (type_ != Type::Bool) type_error("a boolean", type_);
  return bool_;
}
double Json::as_number() const {
  if (type_ != Type::Number) type_error("a number", type_);
  return number_;
}
int Json::as_int() const {
  const double d = as_number();
  if (d != std::floor(d) || d < std::numeric_limits<int>::min() ||
      d > std::numeric_limits<int>::max()) {
    throw JsonError("expected an integer, found " + std::to_string(d));
  }
  return static_cast<int>(d);
}
const std::string& Json::as_string() const {
  if (type_ != Type::String) type_error("a string", type_);
  return string_;
}
const Json::Array& Json::as_array() const {
  if (type_ != Type::Array) type_error("an array", type_);
  return array_;
}
Json::Array& Json::as_array() {
  if (type_ != Type::Array) type_error("an array", type_);
  return array_;
}
const Json::Object& Json::as_object() const {
  if (type_ != Type::Object) type_error("an object", type_);
  return object_;
}
std::vector<double> Json::as_numbers() const {
  std::vector<double> out;
  for (const Json& v : as_array()) out.push_back(v.as_number());
  return out;
}

Json::Json(const Json& o)
    : type_(o.type_),
      bool_(o.bool_),
      number_(o.number_),
      string_(o.string_),
      array_(o.array_),
      object_(o.object_),
      index_(o.index_ ? std::make_unique<Index>(*o.index_) : nullptr) {}

Json& Json::operator=(const Json& o) {
  if (this != &o) *this = Json(o);
  return *this;
}

const Json* Json::find(const std::string& key) const {
  if (type_ != Type::Object) return nullptr;
  if (index_) {
    const auto it = index_->find(key);
    return it == index_->end() ? nullptr : &object_[it->second].second;
  }
  for (const auto& [k, v] : object_) {
    if (k == key) return &v;
  }
  return nullptr;
}
const Json& Json::at(const std::string& key) const {
  if (type_ != Type::Object) type_error("an object", type_);
  const Json* v = find(key);
  if (!v) throw JsonError("missing key '" + key + "'");
  return *v;
}
Json Json::object(std::initializer_list<std::pair<std::string, Json>> members) {
  Json j = object();
  for (const auto& [key, value] : members) j.set(key, value);
  return j;
}

Json& Json::set(const std::string& key, Json value) {
  if (type_ == Type::Null) type_ = Type::Object;
  if (type_ != Type::Object) type_error("an object", type_);
  if (Json* existing = const_cast<Json*>(find(key))) {  // a duplicate key: the last one wins
    *existing = std::move(value);
    return *existing;
  }
  object_.emplace_back(key, std::move(value));
  if (index_) {
    index_->emplace(key, object_.size() - 1);
  } else if (object_.size() >= kIndexFrom) {
    index_ = std::make_unique<Index>();
    index_->reserve(2 * object_.size());
    for (size_t i = 0; i < object_.size(); ++i) index_->emplace(object_[i].first, i);
  }
  return object_.back().second;
}
void Json::push_back(Json value) {
  if (type_ == Type::Null) type_ = Type::Array;
  if (type_ != Type::Array) type_error("an array", type_);
  array_.push_back(std::move(value));
}
size_t Json::size() const {
  if (type_ == Type::Array) return array_.size();
  if (type_ == Type::Object) return object_.size();
  return 0;
}
const Json& Json::operator[](size_t i) const {
  const Array& a = as_array();
  if (i >= a.size()) {
    throw JsonError("index " + std::to_string(i) + " out of range for an array of " +
                    std::to_string(a.size()));
  }
  return a[i];
}

std::string Json::dump(int indent) const {
  // Strings that are not valid UTF-8 (a Latin-1 file name, say) are written with U+FFFD in place
  // of the bad bytes: the file stays valid JSON, which every reader requires.
  return to_ordered(*this).dump(indent < 0 ? -1 : indent, ' ', false,
                                Ordered::error_handler_t::replace);
}

Json parse_json(const std::string& text) {
  const char* read_to = text.data();
  Builder builder(text.data(), &read_to);
  const TrackedIterator first(text.data(), &read_to);
  const TrackedIterator last(text.data() + text.size(), &read_to);
  if (!Ordered::sax_parse(first, last, &builder)) {
    // error_at() characters were read; the last of them is where the problem is.
    const size_t at = builder.error_at() > 0 ? builder.error_at() - 1 : 0;
    const auto [line, column] = line_and_column(text, at);
    throw JsonError("line " + std::to_string(line) + ", column " + std::to_string(column) + ": " +
                        builder.error(),
                    line, column);
  }
  return std::move(builder.result());
}

Json read_json_file(const std::string& path) {
  const std::optional<std::string> text = smpl::read_file(path);
  if (!text) throw JsonError(path + ": cannot open the file for reading");
  try {
    return parse_json(*text);
  } catch (const JsonError& e) {
    throw JsonError(path + ": " + e.what(), e.line, e.column);
  }
}

Json format_header(const std::string& format) {
  Json j = Json::object();
  j.set("format", format);
  j.set("version", 1);
  return j;
}

bool has_format(const Json& j, const std::string& format) {
  return j.is_object() && j.contains("format") && j.at("format").is_string() &&
         j.at("format").as_string() == format;
}

void write_json_file(const std::string& path, const Json& value) {
  smpl::write_file_atomic(path, value.dump(2) + "\n");
}

}  // namespace caliper
