#include "mesh_io.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "cli_support.hpp"
#include "smpl/avatar_export.hpp"
#include "smpl/export.hpp"
#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"
#include "smpl/mesh_read.hpp"

namespace caliper::cli {

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
    // A textured avatar is split at its texture seams (more vertices than the model, the
    // model's triangles in order): measure maps it back through the faces.
    m.order_from_faces = a.texcoords.rows() > 0;
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.extras);
  } else if (ext == ".fbx") {
    smpl::FbxAvatar a = smpl::read_fbx(path);
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.metadata);
    m.order_from_faces = true;
  } else if (ext == ".obj" || ext == ".ply") {
    smpl::MeshAvatar a = smpl::read_mesh_avatar(path);
    m.vertices = std::move(a.vertices);
    m.faces = std::move(a.faces);
    m.extras = std::move(a.extras);
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
                  const Eigen::VectorXd& betas, const smpl::Vertices& rest_vertices,
                  const std::map<std::string, std::string>& extras,
                  const smpl::GltfSkinWeights* skin_weights) {
  smpl::ExportOptions o;
  o.extras = extras;
  o.skin_weights = skin_weights;
  o.rest_vertices = &rest_vertices;
  write_avatar(path, model, betas, o);
}

}  // namespace caliper::cli
