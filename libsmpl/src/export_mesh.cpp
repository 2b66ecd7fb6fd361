// Export options shared by every format, and mesh export: Wavefront OBJ
// (text) and PLY 1.0 (binary little endian), with per-vertex normals, an axis convention and
// the avatar's metadata in a comment.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "smpl/atomic_file.hpp"
#include "smpl/export.hpp"
#include "smpl/text.hpp"

namespace smpl {
namespace {

void check_mesh(const Vertices& vertices, const Faces& faces, const std::string& path) {
  if (faces.size() > 0 && (faces.minCoeff() < 0 || faces.maxCoeff() >= vertices.rows())) {
    throw ModelError(path + ": a face refers to vertex " + std::to_string(faces.maxCoeff()) +
                     " but the mesh has " + std::to_string(vertices.rows()) + " vertices");
  }
}

// Texture-coordinate faces that fit `faces` and index finite coordinates of `uvs`.
void check_uvs(const TexCoords& uvs, const Faces& uv_faces, const Faces& faces,
               const std::string& context) {
  if (uv_faces.rows() != faces.rows()) {
    throw ModelError(context + ": " + std::to_string(uv_faces.rows()) +
                     " texture-coordinate faces given for " + std::to_string(faces.rows()) +
                     " faces (they must correspond one to one)");
  }
  for (Eigen::Index i = 0; i < uv_faces.size(); ++i) {
    const int t = uv_faces.data()[i];
    if (t < 0 || t >= uvs.rows()) {
      throw ModelError(context + ": a face refers to texture coordinate " + std::to_string(t) +
                       " but there are " + std::to_string(uvs.rows()));
    }
  }
  if (!uvs.allFinite()) throw ModelError(context + ": a texture coordinate is NaN or infinite");
}

// printf into a std::string (each call's output is short: one line of numbers).
__attribute__((format(printf, 2, 3))) void appendf(std::string& out, const char* format, ...) {
  char buf[512];
  va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(buf, sizeof buf, format, args);
  va_end(args);
  if (n > 0) out.append(buf, std::min(static_cast<size_t>(n), sizeof buf - 1));
}

// Metadata comments hold one line: any line break would end the comment early.
std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Options shared by every format
// ---------------------------------------------------------------------------------------------

const std::vector<std::string>& smpl_fbx_bone_names() {
  // "m_avg_" and the joint, in SMPL's joint order.
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const char* joint :
         {"Pelvis",  "L_Hip",    "R_Hip",    "Spine1",  "L_Knee",     "R_Knee",
          "Spine2",  "L_Ankle",  "R_Ankle",  "Spine3",  "L_Foot",     "R_Foot",
          "Neck",    "L_Collar", "R_Collar", "Head",    "L_Shoulder", "R_Shoulder",
          "L_Elbow", "R_Elbow",  "L_Wrist",  "R_Wrist", "L_Hand",     "R_Hand"})
      v.push_back(std::string("m_avg_") + joint);
    return v;
  }();
  return names;
}

std::vector<std::string> bone_names(const BodyModel& model, BoneNames naming) {
  const auto K = static_cast<size_t>(model.num_joints());
  if (naming == BoneNames::Smpl) {
    if (model.parents != smpl_parents() ||
        (!model.joint_names.empty() && model.joint_names != smpl_joint_names())) {
      throw ModelError(
          "SMPL bone names (m_avg_Pelvis, ...) need a model with SMPL's 24 joints; "
          "this model has " +
          std::to_string(K) +
          " joints with other names or parents: export with the model's own names");
    }
    return smpl_fbx_bone_names();
  }
  std::vector<std::string> names(K);
  for (size_t k = 0; k < K; ++k) {
    names[k] = k < model.joint_names.size() && !model.joint_names[k].empty()
                   ? model.joint_names[k]
                   : "joint" + std::to_string(k);
  }
  return names;
}

void check_pose(const BodyModel& model, const ExportOptions& options) {
  const auto n = options.pose.size();
  if (n == 0) return;
  if (n != 3 * Eigen::Index{model.num_joints()}) {
    throw ModelError("the pose has " + std::to_string(n) + " numbers but the model's " +
                     std::to_string(model.num_joints()) + " joints need " +
                     std::to_string(3 * model.num_joints()) +
                     " (axis-angle, joint 0 = global orientation)");
  }
  if (!options.pose.allFinite()) throw ModelError("the pose contains NaN or infinity");
}

void check_pose(const BodyModel& model, const ExportOptions& options, const std::string& context) {
  try {
    check_pose(model, options);
  } catch (const ModelError& e) {
    throw ModelError(context + ": " + e.what());
  }
}

Body export_rest_body(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                      const ExportOptions& options, const std::string& context) {
  if (betas.size() > model.num_betas()) {
    throw ModelError(context + ": " + std::to_string(betas.size()) +
                     " betas given but the model has " + std::to_string(model.num_betas()));
  }
  Body body;
  if (options.rest_vertices) {
    if (options.rest_vertices->rows() != model.num_vertices()) {
      throw std::invalid_argument(context + ": ExportOptions::rest_vertices has " +
                                  std::to_string(options.rest_vertices->rows()) +
                                  " vertices, the model " + std::to_string(model.num_vertices()));
    }
    body.vertices = *options.rest_vertices;
    // J = J_regressor * v_shaped, as shape() computes it.
    body.joints.resize(model.j_regressor.rows(), 3);
    for (Eigen::Index k = 0; k < model.j_regressor.rows(); ++k) {
      Eigen::RowVector3d j = Eigen::RowVector3d::Zero();
      for (SparseMatrix::InnerIterator it(model.j_regressor, k); it; ++it)
        j += it.value() * body.vertices.row(it.col());
      body.joints.row(k) = j;
    }
    body.transforms.resize(static_cast<size_t>(model.j_regressor.rows()));
    for (size_t k = 0; k < body.transforms.size(); ++k) {
      body.transforms[k].setIdentity();
      body.transforms[k].topRightCorner<3, 1>() =
          body.joints.row(static_cast<Eigen::Index>(k)).transpose();
    }
  } else {
    body = shape(model, betas);
  }
  if (options.stand_on_floor && body.vertices.rows() > 0) {
    const double lift = -body.vertices.col(1).minCoeff();
    body.vertices.col(1).array() += lift;
    body.joints.col(1).array() += lift;
  }
  return body;
}

Vertices to_up_axis(const Vertices& vertices, UpAxis up) {
  if (up == UpAxis::Y) return vertices;
  Vertices out(vertices.rows(), 3);
  out.col(0) = vertices.col(0);
  out.col(1) = -vertices.col(2);
  out.col(2) = vertices.col(1);
  return out;
}

Vertices from_up_axis(const Vertices& vertices, UpAxis up) {
  if (up == UpAxis::Y) return vertices;
  Vertices out(vertices.rows(), 3);
  out.col(0) = vertices.col(0);
  out.col(1) = vertices.col(2);
  out.col(2) = -vertices.col(1);
  return out;
}

// ---------------------------------------------------------------------------------------------
// OBJ and PLY
// ---------------------------------------------------------------------------------------------

Vertices vertex_normals(const Vertices& vertices, const Faces& faces) {
  Vertices n = Vertices::Zero(vertices.rows(), 3);
  // On the raw row-major arrays (Eigen's row blocks cost twice as much here); the same
  // arithmetic in the same order as (b - a).cross(c - a) and row().norm(), so the same bits.
  const double* v = vertices.data();
  double* out = n.data();
  const std::int32_t* f = faces.data();
  for (Eigen::Index i = 0; i < faces.rows(); ++i, f += 3) {
    const double* a = v + 3 * static_cast<std::ptrdiff_t>(f[0]);
    const double* b = v + 3 * static_cast<std::ptrdiff_t>(f[1]);
    const double* c = v + 3 * static_cast<std::ptrdiff_t>(f[2]);
    const double u0 = b[0] - a[0], u1 = b[1] - a[1], u2 = b[2] - a[2];
    const double w0 = c[0] - a[0], w1 = c[1] - a[1], w2 = c[2] - a[2];
    const double x = u1 * w2 - u2 * w1, y = u2 * w0 - u0 * w2,
                 z = u0 * w1 - u1 * w0;  // |.| = 2 area
    for (int k = 0; k < 3; ++k) {
      double* o = out + 3 * static_cast<std::ptrdiff_t>(f[k]);
      o[0] += x;
      o[1] += y;
      o[2] += z;
    }
  }
  for (Eigen::Index i = 0; i < n.rows(); ++i) {
    double* o = out + 3 * i;
    const double len = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    if (len > 0.0) {
      o[0] /= len;
      o[1] /= len;
      o[2] /= len;
    } else {
      o[0] = 0.0;  // isolated or degenerate vertex: any unit vector will do
      o[1] = 1.0;
      o[2] = 0.0;
    }
  }
  return n;
}

SeamSplit split_at_seams(const BodyModel& model, const std::string& context) {
  const auto V = static_cast<size_t>(model.num_vertices());
  SeamSplit s;
  s.faces = model.faces;
  s.source.resize(V);
  for (size_t v = 0; v < V; ++v) s.source[v] = static_cast<int>(v);
  if (!model.has_uvs()) return s;
  check_uvs(model.uvs, model.uv_faces, model.faces, context);
  std::vector<int> first(V, -1);                 // texture coordinate of output vertex v < V
  std::vector<int> extra_uv;                     // texture coordinate of output vertex V + i
  std::unordered_map<std::uint64_t, int> extra;  // (vertex, coordinate) -> output vertex >= V
  for (Eigen::Index f = 0; f < model.faces.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int v = model.faces(f, c);
      const int t = model.uv_faces(f, c);
      int& p = first[static_cast<size_t>(v)];
      if (p < 0) p = t;
      if (p == t) continue;
      const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(v)) << 32) |
                                static_cast<std::uint32_t>(t);
      const auto [it, added] = extra.emplace(key, static_cast<int>(V + extra_uv.size()));
      if (added) {
        s.source.push_back(v);
        extra_uv.push_back(t);
      }
      s.faces(f, c) = it->second;
    }
  }
  s.uvs = TexCoords::Zero(static_cast<Eigen::Index>(s.source.size()), 2);
  for (size_t v = 0; v < V; ++v) {
    if (first[v] >= 0) s.uvs.row(static_cast<Eigen::Index>(v)) = model.uvs.row(first[v]);
  }
  for (size_t i = 0; i < extra_uv.size(); ++i) {
    s.uvs.row(static_cast<Eigen::Index>(V + i)) = model.uvs.row(extra_uv[i]);
  }
  return s;
}

SeamJoin join_seams(const Vertices& vertices, const Faces& faces) {
  struct Key {
    std::array<std::uint64_t, 3> bits;
    bool operator==(const Key& o) const { return bits == o.bits; }
  };
  struct Hash {
    size_t operator()(const Key& k) const {
      std::uint64_t h = k.bits[0];
      h = h * 0x9E3779B97F4A7C15ULL ^ k.bits[1];
      h = h * 0x9E3779B97F4A7C15ULL ^ k.bits[2];
      return static_cast<size_t>(h ^ (h >> 29));
    }
  };
  check_mesh(vertices, faces, "join_seams");
  // Keys are the coordinates' bits: exact, and a NaN a hostile file may hold is one key too.
  SeamJoin j;
  const auto n = static_cast<size_t>(vertices.rows());
  j.to_kept.resize(n);
  std::unordered_map<Key, int, Hash> first;
  first.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    Key k{};
    for (int c = 0; c < 3; ++c) {
      const double x = vertices(static_cast<Eigen::Index>(i), c);
      std::memcpy(&k.bits[static_cast<size_t>(c)], &x, sizeof x);
    }
    const auto [it, added] = first.emplace(k, static_cast<int>(j.kept.size()));
    if (added) j.kept.push_back(static_cast<int>(i));
    j.to_kept[i] = it->second;
  }
  j.faces.resize(faces.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int c = 0; c < 3; ++c) j.faces(f, c) = j.to_kept[static_cast<size_t>(faces(f, c))];
  }
  return j;
}

void write_obj(const std::string& path, const Vertices& vertices_y_up, const Faces& faces,
               UpAxis up, const std::string& metadata, const TexCoords& uvs,
               const Faces& uv_faces) {
  check_mesh(vertices_y_up, faces, path);
  const bool textured = uv_faces.rows() > 0 || uvs.rows() > 0;
  if (textured) check_uvs(uvs, uv_faces, faces, path);
  const Vertices vertices = to_up_axis(vertices_y_up, up);
  const Vertices normals = vertex_normals(vertices, faces);
  std::string out;
  out.reserve(static_cast<size_t>(vertices.rows() * 80 + faces.rows() * 40) + 256);
  appendf(out, "# The Virtual Caliper mesh export: %lld vertices, %lld faces, metres\n",
          static_cast<long long>(vertices.rows()), static_cast<long long>(faces.rows()));
  out += up == UpAxis::Z ? "# up: z (+Z up, the body faces -Y)\n"
                         : "# up: y (+Y up, the body faces +Z)\n";
  if (!metadata.empty()) out += "# caliper-metadata " + one_line(metadata) + "\n";
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    appendf(out, "v %.9g %.9g %.9g\n", vertices(v, 0), vertices(v, 1), vertices(v, 2));
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    appendf(out, "vn %.6f %.6f %.6f\n", normals(v, 0), normals(v, 1), normals(v, 2));
  }
  for (Eigen::Index t = 0; textured && t < uvs.rows(); ++t) {
    appendf(out, "vt %.9g %.9g\n", uvs(t, 0), uvs(t, 1));
  }
  for (Eigen::Index i = 0; i < faces.rows(); ++i) {
    const int a = faces(i, 0) + 1, b = faces(i, 1) + 1, c = faces(i, 2) + 1;
    if (textured) {
      const int ta = uv_faces(i, 0) + 1, tb = uv_faces(i, 1) + 1, tc = uv_faces(i, 2) + 1;
      appendf(out, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", a, ta, a, b, tb, b, c, tc, c);
    } else {
      appendf(out, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
    }
  }
  write_file_atomic(path, out);
}

void write_ply(const std::string& path, const Vertices& vertices_y_up, const Faces& faces,
               UpAxis up, const std::string& metadata) {
  check_mesh(vertices_y_up, faces, path);
  const Vertices vertices = to_up_axis(vertices_y_up, up);
  const Vertices normals = vertex_normals(vertices, faces);
  std::string buf =
      "ply\nformat binary_little_endian 1.0\ncomment The Virtual Caliper mesh export, "
      "metres\n";
  buf += up == UpAxis::Z ? "comment up: z (+Z up, the body faces -Y)\n"
                         : "comment up: y (+Y up, the body faces +Z)\n";
  if (!metadata.empty()) buf += "comment caliper-metadata " + one_line(metadata) + "\n";
  appendf(buf,
          "element vertex %lld\nproperty float x\nproperty float y\nproperty float "
          "z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face "
          "%lld\nproperty list uchar int vertex_indices\nend_header\n",
          static_cast<long long>(vertices.rows()), static_cast<long long>(faces.rows()));
  static_assert(sizeof(float) == 4, "PLY float is 4 bytes");
  buf.reserve(buf.size() + static_cast<size_t>(vertices.rows() * 24 + faces.rows() * 13));
  auto put = [&buf](const void* p, size_t n) {
    buf.append(static_cast<const char*>(p), n);  // x86 and ARM Linux are little endian, as PLY
  };
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    const float xyz[6] = {static_cast<float>(vertices(v, 0)), static_cast<float>(vertices(v, 1)),
                          static_cast<float>(vertices(v, 2)), static_cast<float>(normals(v, 0)),
                          static_cast<float>(normals(v, 1)),  static_cast<float>(normals(v, 2))};
    put(xyz, sizeof xyz);
  }
  for (Eigen::Index i = 0; i < faces.rows(); ++i) {
    const unsigned char three = 3;
    const std::int32_t ids[3] = {faces(i, 0), faces(i, 1), faces(i, 2)};
    put(&three, 1);
    put(ids, sizeof ids);
  }
  write_file_atomic(path, buf);
}

void write_mesh_avatar(const std::string& path, const BodyModel& model,
                       const Eigen::Ref<const Eigen::VectorXd>& betas,
                       const ExportOptions& options) {
  const bool obj = ends_with_ci(path, ".obj");
  if (!obj && !ends_with_ci(path, ".ply")) {
    throw ModelError(path + ": unknown mesh file extension; use .obj or .ply");
  }
  check_pose(model, options);
  Vertices v;
  if (options.pose.size() == 0) {
    v = export_rest_body(model, betas, options, path).vertices;
  } else {
    if (betas.size() > model.num_betas()) {
      throw ModelError(path + ": " + std::to_string(betas.size()) +
                       " betas given but the model has " + std::to_string(model.num_betas()));
    }
    // The posed mesh, lifted by the rest pose's floor offset (a pose keeps its root in place).
    const double lift = options.stand_on_floor && model.num_vertices() > 0
                            ? -shape(model, betas).vertices.col(1).minCoeff()
                            : 0.0;
    v = evaluate(model, betas, options.pose).vertices;
    v.col(1).array() += lift;
  }
  const std::string metadata = mesh_metadata_json(options.extras);
  if (obj) {
    write_obj(path, v, model.faces, options.up, metadata, model.uvs, model.uv_faces);
  } else {
    write_ply(path, v, model.faces, options.up, metadata);
  }
}

std::string mesh_metadata_json(const std::map<std::string, std::string>& extras) {
  if (extras.empty()) return "";
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& [key, value] : extras) j[key] = value;
  return j.dump(-1, ' ', /*ensure_ascii=*/false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace smpl
