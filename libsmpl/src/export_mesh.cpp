// Mesh export: Wavefront OBJ (text) and PLY 1.0 (binary little endian), with per-vertex normals.
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "smpl/atomic_file.hpp"
#include "smpl/export.hpp"

namespace smpl {
namespace {

/// Appends printf-formatted text to `out`.
__attribute__((format(printf, 2, 3))) void appendf(std::string& out, const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  if (n > 0) {
    const size_t old = out.size();
    out.resize(old + static_cast<size_t>(n) + 1);
    std::vsnprintf(&out[old], static_cast<size_t>(n) + 1, format, again);
    out.resize(old + static_cast<size_t>(n));
  }
  va_end(again);
}

void check_mesh(const Vertices& vertices, const Faces& faces, const std::string& path) {
  if (faces.size() > 0 && (faces.minCoeff() < 0 || faces.maxCoeff() >= vertices.rows())) {
    throw ModelError(path + ": a face refers to vertex " + std::to_string(faces.maxCoeff()) +
                     " but the mesh has " + std::to_string(vertices.rows()) + " vertices");
  }
}

}  // namespace

Vertices vertex_normals(const Vertices& vertices, const Faces& faces) {
  Vertices n = Vertices::Zero(vertices.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::RowVector3d a = vertices.row(faces(f, 0));
    const Eigen::RowVector3d b = vertices.row(faces(f, 1));
    const Eigen::RowVector3d c = vertices.row(faces(f, 2));
    const Eigen::RowVector3d area2 = (b - a).cross(c - a);  // |.| = twice the area
    for (int i = 0; i < 3; ++i) n.row(faces(f, i)) += area2;
  }
  for (Eigen::Index v = 0; v < n.rows(); ++v) {
    const double len = n.row(v).norm();
    if (len > 0.0) {
      n.row(v) /= len;
    } else {
      n.row(v) << 0.0, 1.0, 0.0;  // isolated or degenerate vertex: any unit vector will do
    }
  }
  return n;
}

void write_obj(const std::string& path, const Vertices& vertices, const Faces& faces) {
  check_mesh(vertices, faces, path);
  const Vertices normals = vertex_normals(vertices, faces);
  std::string out;
  appendf(out, "# The Virtual Caliper mesh export: %lld vertices, %lld faces, metres\n",
          static_cast<long long>(vertices.rows()), static_cast<long long>(faces.rows()));
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    appendf(out, "v %.9g %.9g %.9g\n", vertices(v, 0), vertices(v, 1), vertices(v, 2));
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    appendf(out, "vn %.6f %.6f %.6f\n", normals(v, 0), normals(v, 1), normals(v, 2));
  }
  for (Eigen::Index i = 0; i < faces.rows(); ++i) {
    const int a = faces(i, 0) + 1, b = faces(i, 1) + 1, c = faces(i, 2) + 1;
    appendf(out, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
  }
  write_file_atomic(path, out);
}

void write_ply(const std::string& path, const Vertices& vertices, const Faces& faces) {
  check_mesh(vertices, faces, path);
  const Vertices normals = vertex_normals(vertices, faces);
  std::string header;
  appendf(header,
          "ply\nformat binary_little_endian 1.0\ncomment The Virtual Caliper mesh export, "
          "metres\nelement vertex %lld\nproperty float x\nproperty float y\nproperty float "
          "z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face "
          "%lld\nproperty list uchar int vertex_indices\nend_header\n",
          static_cast<long long>(vertices.rows()), static_cast<long long>(faces.rows()));
  static_assert(sizeof(float) == 4, "PLY float is 4 bytes");
  std::string buf = header;
  buf.reserve(header.size() + static_cast<size_t>(vertices.rows() * 24 + faces.rows() * 13));
  auto put = [&buf](const void* p, size_t n) {
    buf.append(static_cast<const char*>(p),
               n);  // x86 and ARM Linux are little endian, as PLY asks here
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

}  // namespace smpl
