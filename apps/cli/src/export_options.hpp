/// \file export_options.hpp
/// The avatar export options of `caliper create` (docs/cli.md): --shape-keys, --bone-names,
/// --pose, --up, --licence, read into one smpl::ExportOptions; and pose files (72 SMPL
/// axis-angle numbers as JSON or .npy).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "cli_support.hpp"
#include "smpl/body_model.hpp"
#include "smpl/export.hpp"

namespace caliper::cli {

/// The option specs (for parse_args and --help).
const std::vector<OptionSpec>& export_option_specs();

/// Reads the export options for writing `out` (its extension decides which options apply) with
/// `model`. Throws UsageError naming the option for a bad value or an option the format does not
/// take (--up for a rigged format, --shape-keys outside glTF/VRM, --pose for VRM, --licence
/// outside VRM), RuntimeError for an unreadable pose file.
smpl::ExportOptions read_export_options(const ParsedArgs& args, const std::string& out,
                                        const smpl::BodyModel& model);

/// Reads a pose file: `.npy` (any shape with 3K numbers, e.g. (72,), (1, 72), (24, 3)) or JSON
/// (an array of 3K numbers, an array of K [x, y, z] triples, or an object whose "pose" member is
/// one of those). Values are axis-angle radians, joint 0 = global orientation. Throws
/// RuntimeError naming the file and what was found.
Eigen::VectorXd read_pose_file(const std::string& path, int num_joints);

}  // namespace caliper::cli
