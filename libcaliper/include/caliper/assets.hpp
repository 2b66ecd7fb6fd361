/// \file assets.hpp
/// Where the project's data lives at run time: the open default body models
/// (`models/caliper-{female,male,neutral}.npz`), measuring protocols, media. One lookup for
/// every program (caliper, caliper-editor, caliper-vr), so one setting moves them all.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace caliper {

/// The folders tried, in order: `$CALIPER_ASSETS` when it is set (and then only it), else,
/// relative to the running executable, `../../assets` (the build tree: build/bin),
/// `../share/virtual-caliper/assets` (an installed prefix: `cmake --install`) and `../assets`.
std::vector<std::string> assets_dir_candidates();

/// The first candidate that is a folder, or nothing (say which were tried with
/// assets_dir_candidates()). A `$CALIPER_ASSETS` that names no folder gives nothing: a wrong
/// setting is reported rather than silently replaced by another folder.
std::optional<std::string> find_assets_dir();

/// The file name of an open default model: "caliper-<sex>.npz" ("caliper-female.npz"). `sex` is
/// used as given; the caller picks "female", "male" or "neutral" (an unknown sex names a file
/// that does not exist, which loading then reports).
std::string default_model_file_name(const std::string& sex);

/// `models_dir` / default_model_file_name(sex), joined as std::filesystem::path joins
/// ("assets/models" and "male" give "assets/models/caliper-male.npz").
std::string default_model_path(const std::string& models_dir, const std::string& sex);

}  // namespace caliper
