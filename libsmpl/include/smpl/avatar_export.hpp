/// \file avatar_export.hpp
/// One entry point for every avatar file format (target smpl::export, which links smpl::gltf
/// and smpl::fbx): the list of formats for file dialogs and help texts, and export_avatar(),
/// which picks the writer by the file's extension.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"
#include "smpl/export.hpp"

namespace smpl {

/// One export format.
struct ExportFormat {
  std::string extension;    ///< lower case with the dot, e.g. ".glb"
  std::string description;  ///< e.g. "glTF 2.0 binary (rigged)"
  bool rigged = false;      ///< skeleton and skinning weights (glb, gltf, vrm, fbx)
};

/// Every format export_avatar() writes, in the order a file dialog should offer them:
/// .glb, .gltf, .vrm, .fbx, .obj, .ply.
const std::vector<ExportFormat>& export_formats();

/// The format of `path` by its extension (case-insensitive), or nullptr.
const ExportFormat* export_format_of(const std::string& path);

/// Writes the avatar of `model` with `betas` to `path` in the format its extension names
/// (write_gltf, write_vrm, write_fbx, write_mesh_avatar), atomically. Throws ModelError naming
/// the file: unknown extension (listing the known ones), an option the format refuses, or a
/// write failure.
void export_avatar(const std::string& path, const BodyModel& model,
                   const Eigen::Ref<const Eigen::VectorXd>& betas,
                   const ExportOptions& options = {});

}  // namespace smpl
