// `caliper measure`: all measurements, volume and weight of an avatar file, or of a model with
// betas.
#include <optional>
#include <ostream>

#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/volume.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "mesh_io.hpp"
#include "report.hpp"
#include "smpl/io.hpp"

namespace caliper::cli {

int cmd_measure(const std::vector<std::string>& args, Io& io) {
  const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "the model (topology and landmarks); default: the open model", false},
      {"sex", "s", "SEX",
       "female, male or neutral: which open model (default: the one a `caliper create` GLB "
       "names, else neutral)",
       false},
      {"betas", "b", "LIST", "comma-separated betas, e.g. 0.5,-1,0 (measures the model)", false},
      {"no-circumferences", "", "", "skip the circumferences (plane slicing)", false},
      {"json", "", "", "print JSON (SI units: m, kg, m3)", false},
  };
  const ParsedArgs a = parse_args(args, specs);
  if (a.flags.count("help")) {
    io.out << "usage: caliper measure AVATAR.glb|.gltf|.vrm|.fbx|.obj|.ply [--model FILE | --sex "
              "SEX]\n"
              "       caliper measure [--model FILE | --sex SEX] --betas b1,b2,...\n\n"
              "Measures a rest-pose avatar (the 13 measurements of the paper, circumferences,\n"
              "volume and weight from volume). An avatar file needs a model of the same\n"
              "topology for its landmarks; a file written by `caliper create` or the editor\n"
              "(any format) names its open model, which is used unless --model or --sex is\n"
              "given.\n\n"
           << format_options(specs)
           << "\nexample:\n  caliper measure avatar.glb --sex female --json\n";
    return kExitOk;
  }
  if (a.positional.size() > 1)
    throw UsageError("give one avatar file (got " + std::to_string(a.positional.size()) + ")");
  if (a.positional.empty() && !a.get("betas") && !a.get("model"))
    throw UsageError("give an avatar file, or --betas (and optionally --model)");
  if (!a.positional.empty() && a.get("betas"))
    throw UsageError("give either an avatar file or --betas, not both");
  // An avatar written by `caliper create` names the open model it was made from
  // (asset.extras open_model_sex); that choice applies unless --model or --sex says otherwise.
  std::optional<MeshFile> mesh;
  if (!a.positional.empty()) mesh = read_mesh(a.positional[0]);
  std::string sex = "neutral", sex_from = "default";
  if (a.get("sex")) {
    sex = normalise_sex(*a.get("sex"));
    sex_from = "--sex";
  } else if (!a.get("model") && mesh) {
    const auto it = mesh->extras.find("open_model_sex");
    if (it != mesh->extras.end()) {
      try {
        sex = normalise_sex(it->second);
        sex_from = "the avatar file";
      } catch (const UsageError&) {
        throw RuntimeError(a.positional[0] + ": its asset.extras name an unknown open model sex '" +
                           it->second + "'; pass --sex or --model FILE");
      }
    }
  }
  const std::string model_path = resolve_model_path(a.get("model"), sex);
  const smpl::BodyModel model = smpl::load_model(model_path);

  smpl::Vertices vertices;
  std::string source;
  Eigen::VectorXd betas;
  if (mesh) {
    source = a.positional[0];
    put_in_model_order(*mesh, model.faces, source);
    if (mesh->vertices.rows() != model.num_vertices()) {
      throw RuntimeError(source + ": the avatar has " + std::to_string(mesh->vertices.rows()) +
                         " vertices but the model " + model_path + " has " +
                         std::to_string(model.num_vertices()) +
                         "; measure with the model it was made from (--model FILE or --sex)");
    }
    vertices = std::move(mesh->vertices);
  } else {
    source = model_path;
    std::vector<double> b;
    if (auto s = a.get("betas")) b = parse_number_list(*s, "--betas");
    if (static_cast<int>(b.size()) > model.num_betas()) {
      throw UsageError("--betas: " + std::to_string(b.size()) + " values, but the model has " +
                       std::to_string(model.num_betas()) + " shape components");
    }
    betas = Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size()));
    vertices = shaped_vertices(model, betas);
  }
  MeasureOptions mo;
  mo.circumferences = a.flags.count("no-circumferences") == 0;
  const MeasurementMap m = measure_all(model, vertices, mo);

  // Notes: what was left out and why; warnings: the measurement sanity checks (the same as for
  // typed inputs) and the orientation, so that an odd mesh is never reported without a word.
  std::vector<std::string> notes, warnings;
  if (!m.count("volume")) {
    notes.push_back("volume and weight left out: the mesh is not closed (" +
                    std::to_string(open_edge_count(model.faces)) +
                    " open edges, e.g. a hand cut at the wrist); a volume needs a closed surface");
  }
  const LandmarkTable lm = landmarks_for(model);
  if (auto head = lm.find("head_top"); head != lm.end() && vertices.rows() > 0) {
    const double top = landmark_point(vertices, head->second).y();
    const double mid = 0.5 * (vertices.col(1).minCoeff() + vertices.col(1).maxCoeff());
    if (top < mid)
      warnings.push_back(
          "the top of the head is in the lower half of the mesh: is it upside "
          "down? (+Y must point up, the feet on the floor)");
  }
  MeasurementMap checked;  // the ids with a plausible range (not volume)
  for (const auto& [id, v] : m) {
    try {
      (void)measurement_range(id);
      checked[id] = v;
    } catch (const InvalidInputError&) {
    }
  }
  for (const ValidationMessage& v : validate_measurements(checked))
    warnings.push_back(
        (v.severity == Severity::Error ? "implausible measurement: " : "unusual measurement: ") +
        v.message);
  for (const auto& w : warnings) io.err << "caliper: warning: " << w << "\n";

  if (a.flags.count("json")) {
    Json j = Json::object();
    j.set("command", "measure");
    j.set("source", source);
    j.set("model", model_path);
    if (!a.get("model")) j.set("model_chosen_by", sex_from);
    if (betas.size() > 0) j.set("betas", betas_json(betas));
    j.set("units",
          json_object({{"length", Json("m")}, {"weight", Json("kg")}, {"volume", Json("m3")}}));
    j.set("measurements", measurements_json(m));
    Json jn = Json::array(), jw = Json::array();
    for (const auto& n : notes) jn.push_back(n);
    for (const auto& w : warnings) jw.push_back(w);
    j.set("notes", jn);
    j.set("warnings", jw);
    io.out << j.dump(2) << "\n";
    return kExitOk;
  }
  io.out << "source: " << source << "\nmodel: " << model_path << " ("
         << (model.meta.gender.empty() ? "?" : model.meta.gender) << ")"
         << (a.get("model") ? "" : "; open model chosen by " + sex_from) << "\n";
  if (betas.size() > 0) io.out << "betas: " << format_betas(betas) << "\n";
  io.out << "\n" << measurement_table({}, m);
  for (const auto& n : notes) io.out << "note: " << n << "\n";
  return kExitOk;
}

}  // namespace caliper::cli
