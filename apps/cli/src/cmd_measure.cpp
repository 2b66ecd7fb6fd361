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

namespace {
const app::HelpText kMeasureHelp{
    {"caliper measure AVATAR.glb|.gltf|.vrm|.fbx|.obj|.ply [--model FILE | --sex SEX]",
     "caliper measure [--model FILE | --sex SEX] --betas b1,b2,..."},
    "Measures a rest-pose avatar (the 13 measurements of the paper, circumferences,\n"
    "volume and weight from volume). An avatar file needs a model of the same\n"
    "topology for its landmarks; a file written by `caliper create` or the editor\n"
    "(any format) names its open model, which is used unless --model or --sex is\n"
    "given.",
    "example:\n  caliper measure avatar.glb --sex female --json"};
}  // namespace

namespace {

const std::vector<OptionSpec>& measure_options() {
  static const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "the model (topology and landmarks); default: the open model", false},
      {"sex", "s", "SEX",
       "female, male or neutral: which open model (default: the one a `caliper create` GLB "
       "names, else neutral)",
       false},
      {"betas", "b", "LIST", "comma-separated betas, e.g. 0.5,-1,0 (measures the model)", false},
      {"no-circumferences", "", "", "skip the circumferences (plane slicing)", false},
      {"json", "", "", "print JSON (SI units: m, kg, m3)", false},
  };
  return specs;
}

/// Everything `caliper measure` is asked to do.
struct MeasureCommand {
  std::optional<std::string> avatar;  ///< the avatar file, or none: the model with `betas`
  std::optional<std::string> model, sex;
  std::vector<double> betas;
  bool circumferences = true, json = false;
};

MeasureCommand measure_command_from(const ParsedArgs& a) {
  if (a.positional.size() > 1)
    throw UsageError("give one avatar file (got " + std::to_string(a.positional.size()) + ")");
  if (a.positional.empty() && !a.get("betas") && !a.get("model"))
    throw UsageError("give an avatar file, or --betas (and optionally --model)");
  if (!a.positional.empty() && a.get("betas"))
    throw UsageError("give either an avatar file or --betas, not both");
  MeasureCommand c;
  if (!a.positional.empty()) c.avatar = a.positional[0];
  c.model = a.get("model");
  if (a.get("sex")) c.sex = normalise_sex(*a.get("sex"));
  if (auto s = a.get("betas")) c.betas = parse_number_list(*s, "--betas");
  c.circumferences = a.flags.count("no-circumferences") == 0;
  c.json = a.flags.count("json") > 0;
  return c;
}

/// What `caliper measure` found.
struct MeasureResult {
  std::string source;      ///< the avatar file or the model file
  std::string model_path;  ///< the model used
  std::string gender;      ///< the model's
  std::string sex_from;    ///< what chose the open model: "--sex", "the avatar file", "default"
  Eigen::VectorXd betas;   ///< when the model was measured with betas
  MeasurementMap measurements;
  std::vector<std::string> notes;     ///< what was left out and why
  std::vector<std::string> warnings;  ///< sanity checks and orientation
};

/// The open model's sex: --sex, else the one an avatar written by `caliper create` names
/// (asset.extras open_model_sex) unless --model is given, else neutral. Sets `from`.
std::string open_model_sex(const MeasureCommand& c, const MeshFile* mesh, std::string& from) {
  from = "default";
  if (c.sex) {
    from = "--sex";
    return *c.sex;
  }
  if (c.model || !mesh) return "neutral";
  const auto it = mesh->extras.find("open_model_sex");
  if (it == mesh->extras.end()) return "neutral";
  try {
    std::string sex = normalise_sex(it->second);
    from = "the avatar file";
    return sex;
  } catch (const UsageError&) {
    throw RuntimeError(*c.avatar + ": its asset.extras name an unknown open model sex '" +
                       it->second + "'; pass --sex or --model FILE");
  }
}

/// Notes and warnings about the measured mesh, so that an odd mesh is never reported without a
/// word: what was left out, the orientation, and the sanity checks of typed inputs.
void check_measured(const smpl::BodyModel& model, const smpl::Vertices& vertices,
                    MeasureResult& r) {
  const MeasurementMap& m = r.measurements;
  if (!m.count("volume")) {
    r.notes.push_back("volume and weight left out: the mesh is not closed (" +
                      std::to_string(open_edge_count(model.faces)) +
                      " open edges, e.g. a hand cut at the wrist); a volume needs a closed "
                      "surface");
  }
  const LandmarkTable lm = landmarks_for(model);
  if (auto head = lm.find("head_top"); head != lm.end() && vertices.rows() > 0) {
    const double top = landmark_point(vertices, head->second).y();
    const double mid = 0.5 * (vertices.col(1).minCoeff() + vertices.col(1).maxCoeff());
    if (top < mid)
      r.warnings.push_back(
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
    r.warnings.push_back(
        (v.severity == Severity::Error ? "implausible measurement: " : "unusual measurement: ") +
        v.message);
}

/// Measures the avatar file (in the model's vertex order) or the model with the betas.
MeasureResult run_measure(const MeasureCommand& c) {
  MeasureResult r;
  std::optional<MeshFile> mesh;
  if (c.avatar) mesh = read_mesh(*c.avatar);
  const std::string sex = open_model_sex(c, mesh ? &*mesh : nullptr, r.sex_from);
  r.model_path = resolve_model_path(c.model, sex);
  const smpl::BodyModel model = smpl::load_model(r.model_path);
  r.gender = model.meta.gender;
  smpl::Vertices vertices;
  if (mesh) {
    r.source = *c.avatar;
    put_in_model_order(*mesh, model.faces, r.source);
    if (mesh->vertices.rows() != model.num_vertices()) {
      throw RuntimeError(r.source + ": the avatar has " + std::to_string(mesh->vertices.rows()) +
                         " vertices but the model " + r.model_path + " has " +
                         std::to_string(model.num_vertices()) +
                         "; measure with the model it was made from (--model FILE or --sex)");
    }
    vertices = std::move(mesh->vertices);
  } else {
    r.source = r.model_path;
    if (static_cast<int>(c.betas.size()) > model.num_betas()) {
      throw UsageError("--betas: " + std::to_string(c.betas.size()) +
                       " values, but the model has " + std::to_string(model.num_betas()) +
                       " shape components");
    }
    r.betas = Eigen::Map<const Eigen::VectorXd>(c.betas.data(),
                                                static_cast<Eigen::Index>(c.betas.size()));
    vertices = shaped_vertices(model, r.betas);
  }
  MeasureOptions mo;
  mo.circumferences = c.circumferences;
  r.measurements = measure_all(model, vertices, mo);
  check_measured(model, vertices, r);
  return r;
}

/// Prints the warnings, then the report: text, or JSON with --json.
int write_measure_report(const MeasureCommand& c, const MeasureResult& r, Io& io) {
  for (const auto& w : r.warnings) io.err << "caliper: warning: " << w << "\n";
  if (c.json) {
    Json j = Json::object();
    j.set("command", "measure");
    j.set("source", r.source);
    j.set("model", r.model_path);
    if (!c.model) j.set("model_chosen_by", r.sex_from);
    if (r.betas.size() > 0) j.set("betas", betas_json(r.betas));
    j.set("units",
          Json::object({{"length", Json("m")}, {"weight", Json("kg")}, {"volume", Json("m3")}}));
    j.set("measurements", measurements_json(r.measurements));
    Json jn = Json::array(), jw = Json::array();
    for (const auto& n : r.notes) jn.push_back(n);
    for (const auto& w : r.warnings) jw.push_back(w);
    j.set("notes", jn);
    j.set("warnings", jw);
    io.out << j.dump(2) << "\n";
    return kExitOk;
  }
  io.out << "source: " << r.source << "\nmodel: " << r.model_path << " ("
         << (r.gender.empty() ? "?" : r.gender) << ")"
         << (c.model ? "" : "; open model chosen by " + r.sex_from) << "\n";
  if (r.betas.size() > 0) io.out << "betas: " << format_betas(r.betas) << "\n";
  io.out << "\n" << measurement_table({}, r.measurements);
  for (const auto& n : r.notes) io.out << "note: " << n << "\n";
  return kExitOk;
}

}  // namespace

int cmd_measure(const std::vector<std::string>& args, Io& io) {
  return run_command(args, measure_options(), kMeasureHelp, io, measure_command_from, run_measure,
                     write_measure_report);
}

}  // namespace caliper::cli
