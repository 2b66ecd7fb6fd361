// `caliper render`: PNG pictures of an avatar file or of a model with betas (front, side,
// three-quarter, back, turntable frames), through the off-screen renderer.
#include <filesystem>
#include <ostream>

#include "caliper/measurements.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "mesh_io.hpp"
#include "render_bridge.hpp"
#include "smpl/io.hpp"

namespace caliper::cli {

namespace {
const app::HelpText kRenderHelp{
    {"caliper render AVATAR.glb|.gltf|.obj|.ply [options]",
     "caliper render [--model FILE | --sex SEX] [--betas LIST] [options]"},
    "Renders PNG pictures with the off-screen (OSMesa) renderer; no display needed.",
    "example:\n  caliper render avatar.glb --views front,side --turntable 36 --out pics/avatar"};
}  // namespace

int cmd_render(const std::vector<std::string>& args, Io& io) {
  const std::vector<OptionSpec> specs = {
      {"model", "m", "FILE", "render this model (with --betas) instead of an avatar file", false},
      {"sex", "s", "SEX", "female, male or neutral: the open model to render (default neutral)",
       false},
      {"betas", "b", "LIST", "comma-separated betas for the model", false},
      {"views", "", "LIST", "front,side,three_quarter,back (default front,side,three_quarter)",
       false},
      {"turntable", "", "N", "also write N turntable frames", false},
      {"size", "", "WxH", "image size in pixels (default 600x800)", false},
      {"out", "o", "PREFIX", "output prefix: PREFIX_front.png, ... (default: avatar)", false},
  };
  const std::optional<ParsedArgs> parsed = parse_args_or_help(args, specs, kRenderHelp, io.out);
  if (!parsed) return kExitOk;
  const ParsedArgs& a = *parsed;
  if (a.positional.size() > 1) throw UsageError("give one avatar file");
  if (!a.positional.empty() && (a.get("betas") || a.get("model")))
    throw UsageError("give either an avatar file or --model/--betas, not both");
  int width = 600, height = 800;
  if (auto s = a.get("size")) {
    const size_t x = s->find('x');
    if (x == std::string::npos) throw UsageError("--size " + *s + ": expected WxH, e.g. 600x800");
    width = parse_int(s->substr(0, x), "size", 16, 8192);
    height = parse_int(s->substr(x + 1), "size", 16, 8192);
  }
  std::vector<std::string> views = {"front", "side", "three_quarter"};
  if (auto v = a.get("views")) {
    views.clear();
    std::string cur;
    for (char c : *v + ",") {
      if (c == ',') {
        if (cur != "front" && cur != "side" && cur != "three_quarter" && cur != "back")
          throw UsageError("--views: unknown view '" + cur +
                           "' (front, side, three_quarter, back)");
        views.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
  }
  int frames = 0;
  if (auto t = a.get("turntable")) frames = parse_int(*t, "turntable", 1, 3600);

  smpl::Vertices vertices;
  smpl::Faces faces;
  if (!a.positional.empty()) {
    MeshFile m = read_mesh(a.positional[0]);
    vertices = std::move(m.vertices);
    faces = std::move(m.faces);
  } else {
    const std::string sex = a.get("sex") ? normalise_sex(*a.get("sex")) : "neutral";
    const smpl::BodyModel model = smpl::load_model(resolve_model_path(a.get("model"), sex));
    std::vector<double> b;
    if (auto s = a.get("betas")) b = parse_number_list(*s, "--betas");
    if (static_cast<int>(b.size()) > model.num_betas())
      throw UsageError("--betas: more values than the model's " +
                       std::to_string(model.num_betas()) + " shape components");
    vertices = shaped_vertices(
        model, Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size())));
    faces = model.faces;
  }
  if (faces.rows() == 0) throw RuntimeError("the mesh has no faces to render");
  const std::string prefix = a.get_or("out", "avatar");
  const auto parent = std::filesystem::path(prefix).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  for (const auto& v : views) {
    const std::string path = prefix + "_" + v + ".png";
    render_png(vertices, faces, path, v, width, height);
    io.out << "wrote " << path << "\n";
  }
  if (frames > 0) {
    const auto written =
        render_turntable(vertices, faces, prefix + "_turntable", frames, width, height);
    io.out << "wrote " << written.size() << " turntable frames " << prefix << "_turntable_000.png"
           << " ...\n";
  }
  return kExitOk;
}

}  // namespace caliper::cli
