// A small JSON reader and writer (RFC 8259) for the project's own files.
#include "caliper/json.hpp"

#include "smpl/atomic_file.hpp"
#include "smpl/text.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace caliper {
namespace {

const char* type_name(Json::Type t) {
  switch (t) {
    case Json::Type::Null:
      return "null";
    case Json::Type::Bool:
      return "a boolean";
    case Json::Type::Number:
      return "a number";
    case Json::Type::String:
      return "a string";
    case Json::Type::Array:
      return "an array";
    case Json::Type::Object:
      return "an object";
  }
  return "?";
}

[[noreturn]] void type_error(const char* expected, Json::Type found) {
  throw JsonError(std::string("expected ") + expected + ", found " + type_name(found));
}

void append_escaped(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  out += '"';
}

void append_number(std::string& out, double d) {
  if (!std::isfinite(d)) throw JsonError("cannot write NaN or infinity as JSON");
  if (d == std::floor(d) && std::fabs(d) < 1e15) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f", d);
    out += buf;
    return;
  }
  // Shortest of %.15g / %.17g that round-trips.
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.15g", d);
  if (std::strtod(buf, nullptr) != d) std::snprintf(buf, sizeof buf, "%.17g", d);
  out += buf;
}

class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  Json parse_document() {
    skip_ws();
    Json v = parse_value(0);
    skip_ws();
    if (pos_ != s_.size()) fail("unexpected text after the JSON value");
    return v;
  }

 private:
  static constexpr int kMaxDepth = 256;

  [[noreturn]] void fail(const std::string& what) const {
    int line = 1, col = 1;
    for (size_t i = 0; i < pos_ && i < s_.size(); ++i) {
      if (s_[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw JsonError(
        "line " + std::to_string(line) + ", column " + std::to_string(col) + ": " + what, line,
        col);
  }

  void skip_ws() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) {
      ++pos_;
    }
  }

  bool consume_literal(const char* lit) {
    size_t n = std::char_traits<char>::length(lit);
    if (s_.compare(pos_, n, lit) == 0) {
      pos_ += n;
      return true;
    }
    return false;
  }

  Json parse_value(int depth) {
    if (depth > kMaxDepth) fail("nesting deeper than 256 levels");
    if (pos_ >= s_.size()) fail("unexpected end of text, expected a value");
    const char c = s_[pos_];
    if (c == '{') return parse_object(depth);
    if (c == '[') return parse_array(depth);
    if (c == '"') return Json(parse_string());
    if (c == 't') {
      if (consume_literal("true")) return Json(true);
      fail("invalid literal");
    }
    if (c == 'f') {
      if (consume_literal("false")) return Json(false);
      fail("invalid literal");
    }
    if (c == 'n') {
      if (consume_literal("null")) return Json();
      fail("invalid literal");
    }
    if (c == '-' || (c >= '0' && c <= '9')) return Json(parse_number());
    if (c == 'N' || c == 'I') fail("NaN and Infinity are not valid JSON numbers");
    fail(std::string("unexpected character '") + c + "'");
  }

  double parse_number() {
    const size_t start = pos_;
    if (s_[pos_] == '-') ++pos_;
    auto digits = [&] {
      size_t d = 0;
      while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') {
        ++pos_;
        ++d;
      }
      return d;
    };
    if (pos_ < s_.size() && s_[pos_] == '0') {
      ++pos_;
    } else if (digits() == 0) {
      fail("invalid number");
    }
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (digits() == 0) fail("invalid number: digits expected after '.'");
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (digits() == 0) fail("invalid number: digits expected in the exponent");
    }
    const std::string token = s_.substr(start, pos_ - start);
    const double d = std::strtod(token.c_str(), nullptr);
    if (!std::isfinite(d)) fail("number out of range: " + token);
    return d;
  }

  unsigned parse_hex4() {
    if (pos_ + 4 > s_.size()) fail("truncated \\u escape");
    unsigned v = 0;
    for (int i = 0; i < 4; ++i) {
      const char h = s_[pos_++];
      v <<= 4;
      if (h >= '0' && h <= '9')
        v |= static_cast<unsigned>(h - '0');
      else if (h >= 'a' && h <= 'f')
        v |= static_cast<unsigned>(h - 'a' + 10);
      else if (h >= 'A' && h <= 'F')
        v |= static_cast<unsigned>(h - 'A' + 10);
      else
        fail("invalid hex digit in \\u escape");
    }
    return v;
  }

  std::string parse_string() {
    ++pos_;  // opening quote
    std::string out;
    while (true) {
      if (pos_ >= s_.size()) fail("unterminated string");
      const char c = s_[pos_++];
      if (c == '"') break;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (pos_ >= s_.size()) fail("unterminated escape");
      const char e = s_[pos_++];
      switch (e) {
        case '"':
          out += '"';
          break;
        case '\\':
          out += '\\';
          break;
        case '/':
          out += '/';
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          unsigned cp = parse_hex4();
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (pos_ + 2 <= s_.size() && s_[pos_] == '\\' && s_[pos_ + 1] == 'u') {
              pos_ += 2;
              const unsigned lo = parse_hex4();
              if (lo < 0xDC00 || lo > 0xDFFF) fail("invalid surrogate pair");
              cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
            } else {
              fail("unpaired surrogate");
            }
          }
          smpl::append_utf8(out, cp);
          break;
        }
        default:
          fail(std::string("invalid escape '\\") + e + "'");
      }
    }
    return out;
  }

  Json parse_array(int depth) {
    ++pos_;
    Json arr = Json::array();
    skip_ws();
    if (pos_ < s_.size() && s_[pos_] == ']') {
      ++pos_;
      return arr;
    }
    while (true) {
      skip_ws();
      arr.push_back(parse_value(depth + 1));
      skip_ws();
      if (pos_ >= s_.size()) fail("unterminated array");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == ']') {
        ++pos_;
        return arr;
      }
      fail("expected ',' or ']' in array");
    }
  }

  Json parse_object(int depth) {
    ++pos_;
    Json obj = Json::object();
    skip_ws();
    if (pos_ < s_.size() && s_[pos_] == '}') {
      ++pos_;
      return obj;
    }
    while (true) {
      skip_ws();
      if (pos_ >= s_.size() || s_[pos_] != '"') fail("expected a string key in object");
      std::string key = parse_string();
      skip_ws();
      if (pos_ >= s_.size() || s_[pos_] != ':') fail("expected ':' after object key");
      ++pos_;
      skip_ws();
      obj.set(key, parse_value(depth + 1));
      skip_ws();
      if (pos_ >= s_.size()) fail("unterminated object");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == '}') {
        ++pos_;
        return obj;
      }
      fail("expected ',' or '}' in object");
    }
  }

  const std::string& s_;
  size_t pos_ = 0;
};

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
  std::string out;
  dump_to(out, indent, 0);
  return out;
}

void Json::dump_to(std::string& out, int indent, int depth) const {
  auto newline = [&](int d) {
    if (indent < 0) return;
    out += '\n';
    out.append(static_cast<size_t>(indent * d), ' ');
  };
  switch (type_) {
    case Type::Null:
      out += "null";
      break;
    case Type::Bool:
      out += bool_ ? "true" : "false";
      break;
    case Type::Number:
      append_number(out, number_);
      break;
    case Type::String:
      append_escaped(out, string_);
      break;
    case Type::Array: {
      out += '[';
      // Arrays of scalars stay on one line even when pretty-printing.
      bool scalars = true;
      for (const Json& v : array_) scalars = scalars && !v.is_array() && !v.is_object();
      for (size_t i = 0; i < array_.size(); ++i) {
        if (i) out += indent >= 0 && scalars ? ", " : ",";
        if (!scalars) newline(depth + 1);
        array_[i].dump_to(out, indent, depth + 1);
      }
      if (!scalars && !array_.empty()) newline(depth);
      out += ']';
      break;
    }
    case Type::Object: {
      out += '{';
      for (size_t i = 0; i < object_.size(); ++i) {
        if (i) out += ',';
        newline(depth + 1);
        append_escaped(out, object_[i].first);
        out += indent >= 0 ? ": " : ":";
        object_[i].second.dump_to(out, indent, depth + 1);
      }
      if (!object_.empty()) newline(depth);
      out += '}';
      break;
    }
  }
}

Json parse_json(const std::string& text) {
  return Parser(text).parse_document();
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

void write_json_file(const std::string& path, const Json& value) {
  smpl::write_file_atomic(path, value.dump(2) + "\n");
}

}  // namespace caliper
