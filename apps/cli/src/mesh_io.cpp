#include "mesh_io.hpp"

#include <utility>

#include "cli_support.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"
#include "smpl/mesh_read.hpp"

namespace caliper::cli {

MeshFile read_mesh(const std::string& path) {
  if (!file_exists(path)) throw RuntimeError(path + ": file not found");
  const std::string ext = extension_of(path);
  MeshFile m;
  if (ext == ".glb" || ext == ".gltf") {
    smpl::GltfAvatar a = smpl::read_gltf(path);
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.extras);
  } else if (ext == ".obj" || ext == ".ply") {
    smpl::MeshData d = ext == ".obj" ? smpl::read_obj(path) : smpl::read_ply(path);
    m.vertices = std::move(d.vertices);
    m.faces = std::move(d.faces);
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
                  const std::map<std::string, std::string>& extras) {
  const std::string ext = extension_of(path);
  if (ext == ".glb" || ext == ".gltf") {
    smpl::GltfOptions o;
    o.extras = extras;
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
