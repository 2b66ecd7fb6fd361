// Mesh readers for OBJ (Wavefront "Object Files", v and f statements) and PLY (Greg Turk's
// polygon file format: header, ascii and binary_little_endian bodies). Untrusted input: every
// count is bounded by the bytes that follow, every value is checked before it is converted.
#include "smpl/mesh_read.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "model_error.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/export.hpp"
#include "smpl/npz.hpp"
#include "smpl/scalar_types.hpp"
#include "smpl/text.hpp"

namespace smpl {
namespace {

using detail::fail;

// The largest vertex count whose indices fit the int32 faces.
constexpr std::int64_t kMaxVertices = std::numeric_limits<std::int32_t>::max();

MeshData make_mesh(const std::vector<double>& v, const std::vector<std::int64_t>& f,
                   const std::string& context) {
  const auto V = static_cast<std::int64_t>(v.size() / 3);
  if (V > kMaxVertices) fail(context, "more than 2^31 - 1 vertices");
  MeshData m;
  m.vertices = Eigen::Map<const Vertices>(v.data(), static_cast<Eigen::Index>(V), 3);
  m.faces.resize(static_cast<Eigen::Index>(f.size() / 3), 3);
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f[i] < 0 || f[i] >= V) {
      fail(context, "face index " + std::to_string(f[i]) + " is out of range (" +
                        std::to_string(V) + " vertices; indices count from 0 here)");
    }
    m.faces.data()[i] = static_cast<std::int32_t>(f[i]);
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------------

}  // namespace

MeshData parse_obj(const std::string& text, const std::string& context) {
  std::vector<double> v;
  std::vector<std::int64_t> f;
  std::istringstream in(text);
  std::string line;
  long line_no = 0;
  std::vector<std::int64_t> idx;
  std::vector<std::string> comments;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.rfind('#', 0) == 0) {
      comments.push_back(line.substr(1));
      continue;
    }
    const std::string where = context + ":" + std::to_string(line_no);
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      double x, y, z;
      if (!(s >> x >> y >> z)) fail(where, "malformed vertex line");
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        fail(where, "vertex coordinate is not a finite number");
      }
      v.insert(v.end(), {x, y, z});
    } else if (tag == "f") {
      idx.clear();
      std::string tok;
      while (s >> tok) {
        // "i", "i/t", "i//n", "i/t/n": the vertex index is the text before the first '/'.
        const std::size_t slash = std::min(tok.find('/'), tok.size());
        std::int64_t i = 0;
        const auto r = std::from_chars(tok.data(), tok.data() + slash, i);
        if (r.ec != std::errc() || r.ptr != tok.data() + slash || i == 0) {
          fail(where, "bad face index " + tok.substr(0, 40) +
                          (r.ec == std::errc::result_out_of_range ? " (out of range)" : ""));
        }
        const auto V = static_cast<std::int64_t>(v.size() / 3);
        const std::int64_t zero_based = i < 0 ? V + i : i - 1;
        if (zero_based < 0 || zero_based >= kMaxVertices) {
          fail(where, "face index " + tok.substr(0, 40) + " is out of range (" + std::to_string(V) +
                          " vertices so far)");
        }
        idx.push_back(zero_based);
      }
      if (idx.size() < 3) fail(where, "face with fewer than 3 vertices");
      for (std::size_t k = 1; k + 1 < idx.size(); ++k) {  // fan triangulation
        f.insert(f.end(), {idx[0], idx[k], idx[k + 1]});
      }
    }
  }
  MeshData m = make_mesh(v, f, context);
  m.comments = std::move(comments);
  return m;
}

// ---------------------------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------------------------
namespace {

// A PLY property's type: one of the first eight ScalarTypes (PLY has no 64-bit integers).
using PlyType = ScalarType;

// The names of PlyType's values, in its order: PLY's original ones and the sized ones.
constexpr std::array<const char*, 8> kPlyTypeNames = {"char", "uchar", "short", "ushort",
                                                      "int",  "uint",  "float", "double"};
constexpr std::array<const char*, 8> kPlySizedTypeNames = {"int8",  "uint8",  "int16",   "uint16",
                                                           "int32", "uint32", "float32", "float64"};
static_assert(kPlyTypeNames.size() == static_cast<std::size_t>(PlyType::kFloat64) + 1);

bool ply_type(const std::string& t, PlyType& out) {
  auto type = enum_from_name<PlyType>(t, kPlyTypeNames);
  if (!type) type = enum_from_name<PlyType>(t, kPlySizedTypeNames);
  if (type) out = *type;
  return type.has_value();
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;
};

// Reads the values of a PLY body one at a time, ascii or binary little-endian.
class PlyBody {
 public:
  PlyBody(const std::uint8_t* p, std::size_t size, bool ascii, const std::string& context)
      : p_(p), size_(size), ascii_(ascii), context_(context) {}

  std::size_t left() const { return size_ - pos_; }

  double next(PlyType t) {
    if (!ascii_) {
      const std::size_t n = scalar_size(t);
      if (n > left()) fail(context_, "truncated PLY body");
      const std::uint8_t* q = p_ + pos_;
      pos_ += n;
      return visit_scalar_type(
          t, [q](auto tag) { return static_cast<double>(load_scalar<decltype(tag)>(q)); });
    }
    auto space = [](std::uint8_t c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
    while (pos_ < size_ && space(p_[pos_])) ++pos_;
    std::size_t end = pos_;
    while (end < size_ && !space(p_[end])) ++end;
    if (end == pos_) fail(context_, "truncated PLY body");
    double x = 0.0;
    const char* b = reinterpret_cast<const char*>(p_ + pos_);
    const char* e = reinterpret_cast<const char*>(p_ + end);
    const auto r = std::from_chars(b, e, x);
    if (r.ec != std::errc() || r.ptr != e) {
      fail(context_,
           "bad PLY value '" + std::string(b, std::min<std::size_t>(end - pos_, 40)) + "'");
    }
    pos_ = end;
    return x;
  }

 private:
  const std::uint8_t* p_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool ascii_;
  const std::string& context_;
};

// A value that must be an integer in [0, hi] (list counts, face indices).
std::int64_t whole(double x, double hi, const std::string& context, const char* what) {
  if (!(x >= 0.0 && x <= hi) || x != std::floor(x)) {
    fail(context, std::string(what) + " " + std::to_string(x) + " is not an integer from 0 to " +
                      std::to_string(static_cast<std::int64_t>(hi)));
  }
  return static_cast<std::int64_t>(x);
}

// A PLY header: the body's format and offset, the elements with their properties, the comments.
struct PlyHeader {
  bool ascii = false;
  std::size_t body = 0;  ///< offset of the body (the byte after end_header's line)
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;
};

PlyHeader parse_ply_header(const std::uint8_t* bytes, std::size_t size,
                           const std::string& context) {
  const std::string head(reinterpret_cast<const char*>(bytes),
                         std::min<std::size_t>(size, 1 << 16));
  const std::size_t end_header = head.find("end_header");
  if (head.compare(0, 3, "ply") != 0 || end_header == std::string::npos) {
    fail(context, "not a PLY file (no 'ply' magic or no end_header in the first 64 KiB)");
  }
  std::size_t body = head.find('\n', end_header);
  if (body == std::string::npos) fail(context, "truncated PLY header");
  ++body;
  std::istringstream header(head.substr(0, end_header));
  std::string format;
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;
  std::string line;
  while (std::getline(header, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "comment") {
      comments.push_back(line.substr(std::min<std::size_t>(line.size(), 8)));
    } else if (tag == "format") {
      s >> format;
    } else if (tag == "element") {
      PlyElement e;
      std::string count;
      s >> e.name >> count;
      const auto r = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (e.name.empty() || count.empty() || r.ec != std::errc() ||
          r.ptr != count.data() + count.size()) {
        fail(context, "bad PLY element line '" + line.substr(0, 80) + "'");
      }
      elements.push_back(e);
    } else if (tag == "property") {
      if (elements.empty()) fail(context, "PLY property before any element");
      PlyProperty p;
      std::string t, item;
      s >> t;
      bool ok = true;
      if (t == "list") {
        std::string count;
        s >> count >> item >> p.name;
        p.list = true;
        ok = ply_type(count, p.count_type) && ply_type(item, p.type) &&
             p.count_type != PlyType::kFloat32 && p.count_type != PlyType::kFloat64;
      } else {
        s >> p.name;
        ok = ply_type(t, p.type);
      }
      if (!ok || p.name.empty()) {
        fail(context, "unsupported PLY property type in '" + line.substr(0, 80) +
                          "' (list counts must be integers)");
      }
      elements.back().props.push_back(p);
    }
  }
  const bool ascii = format == "ascii";
  if (!ascii && format != "binary_little_endian") {
    fail(context, "PLY format '" + format.substr(0, 40) +
                      "' is not supported (use ascii or binary_little_endian)");
  }
  return {ascii, body, std::move(elements), std::move(comments)};
}

// Every entry of an element takes at least this many bytes (ascii: a character per value),
// so no count can claim more entries than the bytes that follow the header can hold.
void check_ply_counts(const PlyHeader& h, std::size_t body_size, const std::string& context) {
  const bool ascii = h.ascii;
  std::uint64_t need = 0;
  for (const PlyElement& e : h.elements) {
    std::uint64_t per = 0;
    for (const PlyProperty& p : e.props)
      per += ascii ? 1 : scalar_size(p.list ? p.count_type : p.type);
    if (per == 0) {
      if (e.count > 0 && (e.name == "vertex" || e.name == "face")) {
        fail(context, "PLY element '" + e.name + "' has " + std::to_string(e.count) +
                          " entries but no properties");
      }
      continue;
    }
    if (e.count > (body_size - need) / per) {
      fail(context, "PLY element '" + e.name.substr(0, 40) + "' claims " + std::to_string(e.count) +
                        " entries of at least " + std::to_string(per) + " bytes, but only " +
                        std::to_string(body_size) +
                        " bytes follow the header: the file is truncated or corrupt");
    }
    need += e.count * per;
  }
}

// Reads the body: the x, y, z of every vertex into v, every face (fanned into triangles) into f;
// other elements and properties are read and dropped.
void read_ply_body(PlyBody& in, const PlyHeader& h, const std::string& context,
                   std::vector<double>& v, std::vector<std::int64_t>& f) {
  const bool ascii = h.ascii;
  std::vector<std::int64_t> idx;
  for (const PlyElement& e : h.elements) {
    if (e.props.empty()) continue;
    const bool vertex = e.name == "vertex";
    for (std::uint64_t i = 0; i < e.count; ++i) {
      double xyz[3] = {0, 0, 0};
      for (const PlyProperty& p : e.props) {
        if (!p.list) {
          const double x = in.next(p.type);
          if (vertex && (p.name == "x" || p.name == "y" || p.name == "z")) {
            if (!std::isfinite(x)) fail(context, "PLY vertex coordinate is not a finite number");
            xyz[p.name[0] - 'x'] = x;
          }
          continue;
        }
        // A list: its count is bounded by the bytes left, its items are read one by one.
        const double per_item = ascii ? 1.0 : static_cast<double>(scalar_size(p.type));
        const std::int64_t n =
            whole(in.next(p.count_type), static_cast<double>(in.left()) / per_item, context,
                  "PLY list count");
        const bool indices =
            e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index");
        idx.clear();
        for (std::int64_t k = 0; k < n; ++k) {
          const double x = in.next(p.type);
          if (indices) {
            idx.push_back(
                whole(x, static_cast<double>(kMaxVertices - 1), context, "PLY face index"));
          }
        }
        for (std::size_t k = 1; k + 1 < idx.size(); ++k) {
          f.insert(f.end(), {idx[0], idx[k], idx[k + 1]});
        }
      }
      if (vertex) v.insert(v.end(), xyz, xyz + 3);
    }
  }
}

}  // namespace

MeshData parse_ply(const std::uint8_t* bytes, std::size_t size, const std::string& context) {
  PlyHeader h = parse_ply_header(bytes, size, context);
  const std::size_t body_size = size - std::min(size, h.body);
  check_ply_counts(h, body_size, context);
  PlyBody in(bytes + std::min(size, h.body), body_size, h.ascii, context);
  std::vector<double> v;
  std::vector<std::int64_t> f;
  read_ply_body(in, h, context, v, f);
  MeshData m = make_mesh(v, f, context);
  m.comments = std::move(h.comments);
  return m;
}

MeshData read_obj(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_obj(std::string(bytes.begin(), bytes.end()), path);
}

MeshData read_ply(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_ply(bytes.data(), bytes.size(), path);
}

std::map<std::string, std::string> parse_mesh_metadata_json(const std::string& json,
                                                            const std::string& context) {
  // Not valid JSON, or not an object: parse() without exceptions gives a discarded value.
  const nlohmann::json j = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) {
    throw ModelError(context +
                     ": its caliper-metadata comment is not a JSON object; remove the comment or "
                     "export the avatar again");
  }
  std::map<std::string, std::string> extras;
  for (const auto& [key, value] : j.items()) {
    if (value.is_string()) extras[key] = value.get<std::string>();
  }
  return extras;
}

MeshAvatar read_mesh_avatar(const std::string& path) {
  const bool obj = ends_with_ci(path, ".obj");
  if (!obj && !ends_with_ci(path, ".ply")) {
    throw ModelError(path + ": not an OBJ or PLY file name (expected .obj or .ply)");
  }
  MeshData d = obj ? read_obj(path) : read_ply(path);
  MeshAvatar a;
  UpAxis up = UpAxis::Y;
  // The comments written by write_obj / write_ply: "up: z ..." and "caliper-metadata {json}".
  for (const std::string& c : d.comments) {
    std::istringstream s(c);
    std::string tag;
    s >> tag;
    if (tag == "up:") {
      std::string axis;
      s >> axis;
      if (axis == "z") up = UpAxis::Z;
      if (axis == "y") up = UpAxis::Y;
    } else if (tag == "caliper-metadata") {
      std::string json;
      std::getline(s, json);
      for (auto& [key, value] : parse_mesh_metadata_json(json, path)) a.extras[key] = value;
    }
  }
  a.vertices = from_up_axis(d.vertices, up);
  a.faces = std::move(d.faces);
  return a;
}

}  // namespace smpl
