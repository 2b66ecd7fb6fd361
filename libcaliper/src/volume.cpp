// Signed-tetrahedron mesh volume (divergence theorem).
#include "caliper/volume.hpp"

#include <cmath>
#include <string>

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

}  // namespace caliper
