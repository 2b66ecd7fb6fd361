#include "mesh_io.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "caliper/json.hpp"
#include "cli_support.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/export.hpp"
#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"

namespace caliper::cli {

namespace {

// An OBJ `#` or PLY `comment` line written by smpl::write_obj/write_ply: "up: z ..." gives the
// axis convention, "caliper-metadata {json}" the avatar's metadata. Other comments are ignored.
void read_comment(const std::string& text, const std::string& path, smpl::UpAxis& up,
                  std::map<std::string, std::string>& extras) {
  std::istringstream s(text);
  std::string tag;
  s >> tag;
  if (tag == "up:") {
    std::string axis;
    s >> axis;
    if (axis == "z") up = smpl::UpAxis::Z;
    if (axis == "y") up = smpl::UpAxis::Y;
  } else if (tag == "caliper-metadata") {
    std::string json;
    std::getline(s, json);
    try {
      const Json j = parse_json(json);
      for (const auto& [key, value] : j.as_object()) {
        if (value.is_string()) extras[key] = value.as_string();
      }
    } catch (const std::exception& e) {
      throw RuntimeError(path + ": its caliper-metadata comment is not valid JSON (" + e.what() +
                         ")");
    }
  }
}

MeshFile read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RuntimeError(path + ": cannot open the OBJ file");
  std::vector<double> v;
  std::vector<std::int32_t> f;
  std::string line;
  int line_no = 0;
  MeshFile m;
  smpl::UpAxis up = smpl::UpAxis::Y;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.rfind("#", 0) == 0) {
      read_comment(line.substr(1), path, up, m.extras);
      continue;
    }
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      double x, y, z;
      if (!(s >> x >> y >> z))
        throw RuntimeError(path + ":" + std::to_string(line_no) + ": malformed vertex line");
      v.insert(v.end(), {x, y, z});
    } else if (tag == "f") {
      std::vector<long> idx;
      std::string tok;
      while (s >> tok) {
        const long i = std::strtol(tok.c_str(), nullptr, 10);  // "i/t/n" -> i
        if (i == 0)
          throw RuntimeError(path + ":" + std::to_string(line_no) + ": bad face index " + tok);
        idx.push_back(i < 0 ? static_cast<long>(v.size() / 3) + i : i - 1);
      }
      if (idx.size() < 3)
        throw RuntimeError(path + ":" + std::to_string(line_no) +
                           ": face with fewer than 3 "
                           "vertices");
      for (size_t k = 1; k + 1 < idx.size(); ++k)  // fan triangulation
        f.insert(f.end(), {static_cast<std::int32_t>(idx[0]), static_cast<std::int32_t>(idx[k]),
                           static_cast<std::int32_t>(idx[k + 1])});
    }
  }
  m.vertices = smpl::from_up_axis(
      Eigen::Map<smpl::Vertices>(v.data(), static_cast<Eigen::Index>(v.size() / 3), 3), up);
  m.faces = Eigen::Map<smpl::Faces>(f.data(), static_cast<Eigen::Index>(f.size() / 3), 3);
  return m;
}

/// Size in bytes of a PLY scalar type; 0 if unknown.
int ply_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double ply_read_binary(const char* p, const std::string& t) {
  if (t == "char" || t == "int8") return static_cast<std::int8_t>(*p);
  if (t == "uchar" || t == "uint8") return static_cast<std::uint8_t>(*p);
  if (t == "short" || t == "int16") {
    std::int16_t x;
    std::memcpy(&x, p, 2);
    return x;
  }
  if (t == "ushort" || t == "uint16") {
    std::uint16_t x;
    std::memcpy(&x, p, 2);
    return x;
  }
  if (t == "int" || t == "int32") {
    std::int32_t x;
    std::memcpy(&x, p, 4);
    return x;
  }
  if (t == "uint" || t == "uint32") {
    std::uint32_t x;
    std::memcpy(&x, p, 4);
    return x;
  }
  if (t == "float" || t == "float32") {
    float x;
    std::memcpy(&x, p, 4);
    return x;
  }
  double x;
  std::memcpy(&x, p, 8);
  return x;
}

struct PlyProperty {
  std::string name, type, count_type;  // count_type non-empty for a list
};

MeshFile read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RuntimeError(path + ": cannot open the PLY file");
  std::ostringstream all;
  all << in.rdbuf();
  const std::string data = all.str();
  const size_t end_header = data.find("end_header");
  if (data.compare(0, 3, "ply") != 0 || end_header == std::string::npos)
    throw RuntimeError(path + ": not a PLY file (no 'ply' magic or no end_header)");
  std::istringstream header(data.substr(0, end_header));
  size_t body = data.find('\n', end_header);
  if (body == std::string::npos) throw RuntimeError(path + ": truncated PLY header");
  ++body;
  std::string format;
  struct Element {
    std::string name;
    long count = 0;
    std::vector<PlyProperty> props;
  };
  std::vector<Element> elements;
  std::string line;
  MeshFile m;
  smpl::UpAxis up = smpl::UpAxis::Y;
  while (std::getline(header, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "comment") {
      read_comment(line.substr(std::min(line.size(), size_t{8})), path, up, m.extras);
    } else if (tag == "format") {
      s >> format;
    } else if (tag == "element") {
      Element e;
      s >> e.name >> e.count;
      elements.push_back(e);
    } else if (tag == "property" && !elements.empty()) {
      PlyProperty p;
      std::string t;
      s >> t;
      if (t == "list") {
        s >> p.count_type >> p.type >> p.name;
      } else {
        p.type = t;
        s >> p.name;
      }
      if (ply_size(p.type) == 0 || (!p.count_type.empty() && ply_size(p.count_type) == 0))
        throw RuntimeError(path + ": unsupported PLY property type in '" + line + "'");
      elements.back().props.push_back(p);
    }
  }
  const bool ascii = format == "ascii";
  if (!ascii && format != "binary_little_endian")
    throw RuntimeError(path + ": PLY format '" + format +
                       "' is not supported (use ascii or binary_little_endian)");
  std::vector<double> v;
  std::vector<std::int32_t> f;
  size_t pos = body;
  std::istringstream text(ascii ? data.substr(body) : std::string());
  auto next = [&](const std::string& type) -> double {
    if (ascii) {
      double x;
      if (!(text >> x)) throw RuntimeError(path + ": truncated PLY body");
      return x;
    }
    const int n = ply_size(type);
    if (pos + static_cast<size_t>(n) > data.size())
      throw RuntimeError(path + ": truncated PLY body");
    const double x = ply_read_binary(data.data() + pos, type);
    pos += static_cast<size_t>(n);
    return x;
  };
  for (const auto& e : elements) {
    for (long i = 0; i < e.count; ++i) {
      double xyz[3] = {0, 0, 0};
      for (const auto& p : e.props) {
        if (p.count_type.empty()) {
          const double x = next(p.type);
          if (e.name == "vertex") {
            if (p.name == "x") xyz[0] = x;
            if (p.name == "y") xyz[1] = x;
            if (p.name == "z") xyz[2] = x;
          }
        } else {
          const long n = static_cast<long>(next(p.count_type));
          std::vector<std::int32_t> idx;
          for (long k = 0; k < n; ++k) idx.push_back(static_cast<std::int32_t>(next(p.type)));
          if (e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index")) {
            for (size_t k = 1; k + 1 < idx.size(); ++k)
              f.insert(f.end(), {idx[0], idx[k], idx[k + 1]});
          }
        }
      }
      if (e.name == "vertex") v.insert(v.end(), xyz, xyz + 3);
    }
  }
  m.vertices = smpl::from_up_axis(
      Eigen::Map<smpl::Vertices>(v.data(), static_cast<Eigen::Index>(v.size() / 3), 3), up);
  m.faces = Eigen::Map<smpl::Faces>(f.data(), static_cast<Eigen::Index>(f.size() / 3), 3);
  return m;
}

}  // namespace

MeshFile read_mesh(const std::string& path) {
  if (!file_exists(path)) throw RuntimeError(path + ": file not found");
  const std::string ext = extension_of(path);
  MeshFile m;
  if (ext == ".glb" || ext == ".gltf" || ext == ".vrm") {
    smpl::GltfAvatar a = smpl::read_gltf(path);
    // Shape keys (beta_NN targets) at their default weights are part of the avatar as made;
    // other targets (pose correctives) are not part of the rest shape.
    for (size_t t = 0; t < a.morph_targets.size(); ++t) {
      if (a.morph_names[t].rfind("beta_", 0) == 0) {
        a.vertices += a.morph_weights[t] * a.morph_targets[t];
      }
    }
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.extras);
  } else if (ext == ".fbx") {
    smpl::FbxAvatar a = smpl::read_fbx(path);
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.metadata);
    m.order_from_faces = true;
  } else if (ext == ".obj") {
    m = read_obj(path);
  } else if (ext == ".ply") {
    m = read_ply(path);
  } else {
    throw RuntimeError(path + ": unknown mesh extension '" + ext + "' (expected " +
                       avatar_extensions_text() + ")");
  }
  if (m.vertices.rows() == 0) throw RuntimeError(path + ": the mesh has no vertices");
  for (Eigen::Index i = 0; i < m.faces.size(); ++i) {
    const auto id = m.faces.data()[i];
    if (id < 0 || id >= m.vertices.rows())
      throw RuntimeError(path + ": face index " + std::to_string(id) + " out of range (" +
                         std::to_string(m.vertices.rows()) + " vertices)");
  }
  return m;
}

void put_in_model_order(MeshFile& mesh, const smpl::Faces& faces, const std::string& path) {
  if (!mesh.order_from_faces || mesh.faces == faces) return;
  if (mesh.faces.rows() != faces.rows()) {
    throw RuntimeError(path + ": the avatar has " + std::to_string(mesh.faces.rows()) +
                       " triangles but the model has " + std::to_string(faces.rows()) +
                       "; measure with the model it was made from (--model FILE or --sex)");
  }
  const Eigen::Index V = faces.size() > 0 ? faces.maxCoeff() + 1 : 0;
  smpl::Vertices v = smpl::Vertices::Constant(V, 3, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int i = 0; i < 3; ++i) {
      const Eigen::RowVector3d p = mesh.vertices.row(mesh.faces(f, i));
      auto row = v.row(faces(f, i));
      if (!std::isnan(row(0)) && (row - p).norm() > 0.0) {
        throw RuntimeError(path + ": its triangles do not match the model's (model vertex " +
                           std::to_string(faces(f, i)) +
                           " would be in two places); measure with the model it was made from");
      }
      row = p;
    }
  }
  mesh.vertices = std::move(v);
  mesh.faces = faces;
  mesh.order_from_faces = false;
}

bool is_avatar_extension(const std::string& path) {
  return smpl::export_format_of(path) != nullptr;
}

std::string avatar_extensions_text() {
  const auto& formats = smpl::export_formats();
  std::string text;
  for (size_t i = 0; i < formats.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == formats.size() ? " or " : ", ") + formats[i].extension;
  }
  return text;
}

void write_avatar(const std::string& path, const smpl::BodyModel& model,
                  const Eigen::VectorXd& betas, const smpl::ExportOptions& options) {
  if (!is_avatar_extension(path)) {
    throw UsageError(path + ": unknown avatar extension '" + extension_of(path) + "' (use " +
                     avatar_extensions_text() + ")");
  }
  smpl::export_avatar(path, model, betas, options);
}

void write_avatar(const std::string& path, const smpl::BodyModel& model,
                  const Eigen::VectorXd& betas, const smpl::Vertices& /*rest_vertices*/,
                  const std::map<std::string, std::string>& extras,
                  const smpl::GltfSkinWeights* skin_weights) {
  smpl::ExportOptions o;
  o.extras = extras;
  o.skin_weights = skin_weights;
  write_avatar(path, model, betas, o);
}

}  // namespace caliper::cli
