#include "mesh_io.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "cli_support.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"

namespace caliper::cli {

namespace {

MeshFile read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RuntimeError(path + ": cannot open the OBJ file");
  std::vector<double> v;
  std::vector<std::int32_t> f;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
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
  MeshFile m;
  m.vertices = Eigen::Map<smpl::Vertices>(v.data(), static_cast<Eigen::Index>(v.size() / 3), 3);
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
  while (std::getline(header, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "format") {
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
  MeshFile m;
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
  m.vertices = Eigen::Map<smpl::Vertices>(v.data(), static_cast<Eigen::Index>(v.size() / 3), 3);
  m.faces = Eigen::Map<smpl::Faces>(f.data(), static_cast<Eigen::Index>(f.size() / 3), 3);
  return m;
}

}  // namespace

MeshFile read_mesh(const std::string& path) {
  if (!file_exists(path)) throw RuntimeError(path + ": file not found");
  const std::string ext = extension_of(path);
  MeshFile m;
  if (ext == ".glb" || ext == ".gltf") {
    smpl::GltfAvatar a = smpl::read_gltf(path);
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.extras);
  } else if (ext == ".obj") {
    m = read_obj(path);
  } else if (ext == ".ply") {
    m = read_ply(path);
  } else {
    throw RuntimeError(path + ": unknown mesh extension '" + ext +
                       "' (expected .glb, .gltf, .obj or .ply)");
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

bool is_avatar_extension(const std::string& path) {
  const std::string ext = extension_of(path);
  return ext == ".glb" || ext == ".gltf" || ext == ".obj" || ext == ".ply";
}

void write_avatar(const std::string& path, const smpl::BodyModel& model,
                  const Eigen::VectorXd& betas, const smpl::Vertices& rest_vertices,
                  const std::map<std::string, std::string>& extras,
                  const smpl::GltfSkinWeights* skin_weights) {
  const std::string ext = extension_of(path);
  if (ext == ".glb" || ext == ".gltf") {
    smpl::GltfOptions o;
    o.extras = extras;
    o.skin_weights = skin_weights;
    smpl::write_gltf(path, model, betas, o);
    return;
  }
  if (ext != ".obj" && ext != ".ply") {
    throw UsageError(path + ": unknown avatar extension '" + ext +
                     "' (use .glb, .gltf, .obj or .ply)");
  }
  smpl::Vertices v = rest_vertices;
  if (v.rows() > 0) v.col(1).array() -= v.col(1).minCoeff();  // stand on the floor
  if (ext == ".obj") {
    smpl::write_obj(path, v, model.faces);
  } else {
    smpl::write_ply(path, v, model.faces);
  }
}

}  // namespace caliper::cli
