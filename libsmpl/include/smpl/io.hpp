/// \file io.hpp
/// Loading and saving SMPL-family model files.
/// - `.npz` (numpy zip of .npy members, stored or deflated; f4/f8/i4/i8/u4/b1; C or Fortran order)
/// - `.pkl` (restricted unpickler for protocols 2-5: builds only numpy arrays and dtypes, scipy
///   csc/csr matrices, chumpy Ch objects and plain containers; never executes anything)
/// - the project's own format: an `.npz` with SMPL's keys plus landmarks, joint names, metadata.
/// Facts on the formats: shared/reference/smpl-format.md and docs/file-formats.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "smpl/body_model.hpp"
#include "smpl/npz.hpp"

namespace smpl {

/// Options for load_model().
struct LoadOptions {
  /// Number of shape components to keep: -1 keeps all of the file's; a smaller number keeps the
  /// first ones; a larger number than the file has is an error.
  int num_betas = -1;
  /// Keep pose blend shapes (they are 3V x 207 doubles, 34 MB for SMPL).
  bool load_pose_blend_shapes = true;
};

/// Loads a model from `.npz` or `.pkl` (chosen by content, not extension). Throws ModelError naming
/// the file and the problem (missing key, wrong shape, unknown pickle class, truncated file, NaN).
/// The result passes validate().
BodyModel load_model(const std::string& path, const LoadOptions& options = {});

/// load_model() on file bytes already in memory; `context` (e.g. the path) starts every error
/// message. The format is chosen by content ("PK" zip: .npz; 0x80 PROTO: pickle).
BodyModel load_model_from_memory(const std::uint8_t* bytes, std::size_t size,
                                 const std::string& context, const LoadOptions& options = {});

/// Options for save_model().
struct SaveOptions {
  /// Deflate the members (like np.savez_compressed): about 2x smaller, slower to load.
  bool compress = false;
};

/// The arrays save_model() writes, by key (see docs/file-formats.md for the layout).
NpzArchive model_arrays(const BodyModel& model);

/// Saves in the project's `.npz` format (SMPL keys: v_template, f, shapedirs, posedirs,
/// J_regressor (dense), weights, kintree_table, J, vert_sym_idxs; plus landmark_names,
/// landmark_offsets, landmark_vertices, joint_names, meta_*). The output is byte-for-byte
/// deterministic for the same model. Throws ModelError when the model fails validate() or the
/// file cannot be written.
void save_model(const BodyModel& model, const std::string& path, const SaveOptions& options = {});

}  // namespace smpl
