// Signed-tetrahedron mesh volume (divergence theorem).
#include "caliper/volume.hpp"

#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

#include <Eigen/Geometry>

#include "caliper/errors.hpp"

namespace caliper {

double mesh_volume(const smpl::Vertices& vertices, const smpl::Faces& faces) {
  if (faces.rows() == 0) {
    throw InvalidInputError("mesh_volume: the mesh has no faces; a closed triangle mesh is needed");
  }
  const auto nv = vertices.rows();
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    if (!vertices.row(i).allFinite()) {
      throw InvalidInputError("mesh_volume: vertex " + std::to_string(i) +
                              " is NaN or infinite; check the model and the betas");
    }
  }
  double sum = 0.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const int ia = faces(f, 0), ib = faces(f, 1), ic = faces(f, 2);
    if (ia < 0 || ib < 0 || ic < 0 || ia >= nv || ib >= nv || ic >= nv) {
      throw InvalidInputError("mesh_volume: face " + std::to_string(f) +
                              " has a vertex index out of range [0, " + std::to_string(nv) + ")");
    }
    const Eigen::Vector3d a = vertices.row(ia).transpose();
    const Eigen::Vector3d b = vertices.row(ib).transpose();
    const Eigen::Vector3d c = vertices.row(ic).transpose();
    sum += a.dot(b.cross(c));
  }
  return sum / 6.0;
}

long open_edge_count(const smpl::Faces& faces) {
  // Directed edge (a, b) as one 64-bit key; a closed surface has each directed edge once and
  // its reverse once.
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(static_cast<size_t>(faces.rows()) * 3);
  const auto key = [](std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(a) << 32) | b;
  };
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      ++directed[key(static_cast<std::uint32_t>(faces(f, k)),
                     static_cast<std::uint32_t>(faces(f, (k + 1) % 3)))];
  long open = 0;
  for (const auto& [e, n] : directed) {
    const auto a = static_cast<std::uint32_t>(e >> 32), b = static_cast<std::uint32_t>(e);
    const auto reverse = directed.find(key(b, a));
    if (n != 1 || reverse == directed.end() || reverse->second != 1) ++open;
  }
  return open;
}

}  // namespace caliper
