// `caliper batch`: a CSV of people (units in the header) or ANSUR II files in; avatars and a
// results CSV out; parallel jobs (std::thread) and progress on stderr.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "caliper/errors.hpp"
#include "caliper/training.hpp"
#include "caliper/weight.hpp"
#include "command_common.hpp"
#include "commands.hpp"
#include "inputs.hpp"
#include "mesh_io.hpp"
#include "report.hpp"
#include "smpl/atomic_file.hpp"
#include "smpl/text.hpp"

namespace caliper::cli {

namespace {
const app::HelpText kBatchHelp{
    {"caliper batch PEOPLE.csv [options]",
     "caliper batch --ansur ANSUR_II_MALE_Public.csv [--ansur ...] [options]"},
    "PEOPLE.csv: a header naming measurement ids with units (height_cm, weight_kg,\n"
    "arm_span_fingertips_cm, inseam_height_cm, hip_width_cm, arm_length_cm; also _mm,\n"
    "_m, _in, _lb) and optional id and sex columns. Results CSV: one row per person\n"
    "with status (ok, refused, error), the achieved measurements (cm, kg, L),\n"
    "plausibility, betas and (with --out-dir) the avatar's file; ids that give the\n"
    "same file name get -2, -3, ... The outputs are checked before the work starts\n"
    "and written atomically. Exit code 1 when any row was refused or failed, or a\n"
    "file could not be written.",
    "example:\n  caliper batch people.csv -j 2 --out results.csv --out-dir avatars"};
}  // namespace

namespace {

/// What one person gives.
struct Outcome {
  std::string status = "ok";  ///< ok | refused | error
  std::string regressor;
  std::string sex;
  std::string message;  ///< warnings or the error
  MeasurementMap achieved;
  Eigen::VectorXd betas;
  Plausibility plausibility;
};

std::string file_safe(const std::string& id) {
  std::string s;
  for (char c : id)
    s +=
        (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  if (s.size() > 200) s.resize(200);  // file names are limited to 255 bytes
  if (s.empty() || s.find_first_not_of('.') == std::string::npos) s = "person" + s;
  return s;
}

/// One avatar file name per person, in row order: ids that map to the same name ("a b", "a_b",
/// "a/b", repeated ids, empty ids) get "-2", "-3", ... so that no avatar overwrites another.
/// Names are compared without case, for case-insensitive file systems.
std::vector<std::string> avatar_file_names(const std::vector<Person>& people,
                                           const std::string& format) {
  std::set<std::string> taken;
  std::vector<std::string> names;
  names.reserve(people.size());
  for (const Person& p : people) {
    const std::string base = file_safe(p.id);
    std::string name = base + "." + format;
    for (int n = 2; taken.count(smpl::to_lower(name)); ++n)
      name = base + "-" + std::to_string(n) + "." + format;
    taken.insert(smpl::to_lower(name));
    names.push_back(name);
  }
  return names;
}

/// Fails before any work when `dir` cannot hold new files: creates it, then writes and removes
/// a probe file.
void check_writable_folder(const std::filesystem::path& dir, const std::string& what) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw RuntimeError(what + " " + dir.string() + ": cannot create the folder (" +
                       (ec ? ec.message() : std::string("a file of that name exists")) + ")");
  const std::filesystem::path probe = dir / ".caliper-write-check";
  try {
    smpl::write_file_atomic(probe.string(), "ok\n");
  } catch (const smpl::WriteError& e) {
    throw RuntimeError(what + " " + dir.string() + ": the folder is not writable (" + e.what() +
                       "); nothing was computed");
  }
  std::filesystem::remove(probe, ec);
}

/// Betas, measurements (paper's 13 available on the model, volume, weight) and plausibility of
/// one person without building the mesh: the same values as create_avatar() without
/// circumferences (ShapeMeasurer is exact), at a fraction of the cost.
void fast_avatar(const ModelBundle& b, const ShapeMeasurer& measurer, const std::string& regressor,
                 const MeasurementMap& inputs, const MeasurementMapping* mapping,
                 Eigen::VectorXd& betas, MeasurementMap& achieved, Plausibility& plaus) {
  const MeasurementMap mapped = mapping ? mapping->apply(inputs) : inputs;
  Eigen::VectorXd k_betas;
  if (regressor == "noise-aware") {
    if (!b.regressors.noise_aware) throw RuntimeError("no noise-aware regressor in the set");
    k_betas = b.regressors.noise_aware->predict(mapped).mean;
  } else {
    const LinearRegressor* r = b.regressors.find(regressor);
    if (!r) throw RuntimeError("the regressor set has no regressor " + regressor);
    k_betas = linear_betas(b.model, *r, mapped, b.curve ? &*b.curve : nullptr,
                           b.measure_info ? b.measure_info->landmarks : LandmarkTable{}, &measurer);
  }
  if (k_betas.size() > measurer.num_betas()) {
    // A shape curve over more betas than the exact maps take (kMaxMeasurerBetas): the mesh.
    MeasureOptions mo;
    mo.circumferences = false;
    const smpl::Vertices v = shaped_vertices(b.model, k_betas);
    achieved =
        b.measure_info ? measure_all(b.model, v, *b.measure_info, mo) : measure_all(b.model, v, mo);
  } else {
    const Eigen::VectorXd m = measurer.measure(k_betas);
    for (size_t i = 0; i < measurer.definitions().size(); ++i)
      achieved[measurer.definitions()[i].id] = m[static_cast<Eigen::Index>(i)];
    const double volume = measurer.volume(k_betas);
    achieved["volume"] = volume;
    achieved["weight"] = weight_from_volume(
        volume, b.measure_info ? b.measure_info->weight_formula : weight_formula_of(b.model));
  }
  plaus = plausibility(k_betas);
  betas = Eigen::VectorXd::Zero(b.model.num_betas());
  betas.head(k_betas.size()) = k_betas;
}

/// Says in the row's message that the avatar was made but its shape is unusual (the editor's
/// wording: outside the usual range).
void add_implausible_note(Outcome& o) {
  const std::string note = "unusual body shape (outside the usual range): Mahalanobis distance " +
                           format_number(o.plausibility.mahalanobis, 2) + ", " +
                           std::to_string(o.plausibility.beyond_3sd.size()) +
                           " components beyond 3 SD; check the measurements";
  o.message += (o.message.empty() ? "" : "; ") + note;
}

}  // namespace

namespace {

const std::vector<OptionSpec>& batch_options() {
  static const std::vector<OptionSpec> specs = {
      {"ansur", "", "FILE", "read an ANSUR II public CSV (repeatable: male and female files)",
       true},
      {"sex", "s", "SEX", "sex for rows without a sex column (default neutral)", false},
      {"regressor", "r", "NAME",
       "R2, R4, R5, R6 or noise-aware for every row (default: per row, "
       "as caliper create)",
       false},
      {"model", "m", "FILE", "one model for every row instead of the open model per sex", false},
      {"regressors", "", "FILE", "regressors saved by caliper train (with --model)", false},
      {"mapping", "", "FILE", "real-to-virtual mapping (.json or paired .csv)", false},
      {"out", "o", "FILE", "results CSV (default: standard output)", false},
      {"out-dir", "", "DIR", "write one avatar per person into DIR", false},
      {"format", "", "EXT", "avatar format in --out-dir: glb (default), gltf, vrm, fbx, obj, ply",
       false},
      {"jobs", "j", "N", "parallel jobs (default: the number of cores)", false},
      {"limit", "", "N", "process only the first N people", false},
      {"circumferences", "", "", "also measure circumferences (slices the mesh; slower)", false},
      {"exact-inputs", "", "", "refine the betas to reproduce every input exactly (slower)", false},
      {"no-shape-curve", "", "",
       "plain regressors (R2-R6) as in the paper: from the mean body, not from the general "
       "population's body of the height and weight",
       false},
      {"force", "", "", "create avatars even for inputs outside the hard limits", false},
  };
  return specs;
}

/// Everything `caliper batch` is asked to do.
struct BatchOptions {
  std::optional<std::string> people_csv;
  std::vector<std::string> ansur;
  std::string default_sex = "neutral";
  bool sex_given = false;
  std::optional<std::string> regressor;  ///< one regressor for every row (normalised name)
  std::optional<std::string> model, regressors, mapping, out, out_dir;
  std::string format = "glb";
  int jobs = 1;
  std::optional<int> limit;
  bool circumferences = false, exact_inputs = false, force = false;
  bool shape_curve = true;  ///< false: --no-shape-curve
  /// Without avatar files or circumferences no mesh is needed: the measurements, volume and
  /// weight come from the betas through ShapeMeasurer's exact precomputed maps (fast path).
  bool need_mesh() const { return circumferences || exact_inputs || out_dir.has_value(); }
};

BatchOptions batch_options_from(const ParsedArgs& a) {
  if (a.positional.size() > 1) throw UsageError("give one people CSV file");
  if (a.positional.empty() && !a.get("ansur"))
    throw UsageError("give a people CSV file or --ansur FILE");
  BatchOptions o;
  if (!a.positional.empty()) o.people_csv = a.positional[0];
  if (auto it = a.values.find("ansur"); it != a.values.end()) o.ansur = it->second;
  o.sex_given = a.get("sex").has_value();
  if (o.sex_given) o.default_sex = normalise_sex(*a.get("sex"));
  if (auto r = a.get("regressor")) o.regressor = normalise_regressor_name(*r);
  o.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (auto j = a.get("jobs")) o.jobs = parse_int(*j, "jobs", 1, 256);
  o.format = a.get_or("format", "glb");
  if (!is_avatar_extension("avatar." + o.format))
    throw UsageError("--format " + o.format + ": expected glb, gltf, vrm, fbx, obj or ply");
  o.model = a.get("model");
  o.regressors = a.get("regressors");
  if (o.regressors && !o.model)
    throw UsageError("--regressors needs --model (saved regressors belong to one model)");
  o.mapping = a.get("mapping");
  o.out = a.get("out");
  o.out_dir = a.get("out-dir");
  if (auto l = a.get("limit")) o.limit = parse_int(*l, "limit", 0, 100000000);
  o.circumferences = a.flags.count("circumferences") > 0;
  o.exact_inputs = a.flags.count("exact-inputs") > 0;
  o.shape_curve = a.flags.count("no-shape-curve") == 0;
  o.force = a.flags.count("force") > 0;
  return o;
}

std::vector<Person> read_batch_people(const BatchOptions& opt) {
  std::vector<Person> people;
  if (opt.people_csv) people = read_people_csv(*opt.people_csv);
  for (const auto& f : opt.ansur) {
    auto p = read_ansur_csv(f);
    people.insert(people.end(), std::make_move_iterator(p.begin()),
                  std::make_move_iterator(p.end()));
  }
  if (opt.limit && static_cast<size_t>(*opt.limit) < people.size())
    people.resize(static_cast<size_t>(*opt.limit));
  return people;
}

/// Checks the outputs before the work starts, so that a long batch does not end in an error.
void check_batch_outputs(const BatchOptions& opt) {
  if (opt.out_dir) check_writable_folder(*opt.out_dir, "--out-dir");
  if (!opt.out) return;
  const std::string& path = *opt.out;
  const std::filesystem::path p(path);
  std::error_code ec;
  if (std::filesystem::is_directory(p, ec))
    throw RuntimeError("--out " + path + ": is a folder; give a file name for the results CSV");
  const std::filesystem::path parent = p.parent_path().empty() ? "." : p.parent_path();
  if (!std::filesystem::is_directory(parent, ec))
    throw RuntimeError("--out " + path + ": the folder " + parent.string() +
                       " does not exist; create it first");
  // A device or FIFO (e.g. /dev/stdout) is written in place and cannot be probed.
  if (std::filesystem::is_regular_file(p, ec) || !std::filesystem::exists(p, ec))
    check_writable_folder(parent, "--out");
}

/// Every model, measurer, regressor check and skin the workers need, made before they start.
struct BatchModels {
  std::map<std::string, std::shared_ptr<const ModelBundle>> bundles;       ///< by sex
  std::map<const ModelBundle*, std::unique_ptr<ShapeMeasurer>> measurers;  ///< fast path only
  /// Each regressor checked against its model once (the check computes the model's
  /// fingerprint, a pass over the template and shape directions); a mismatch becomes the error
  /// of every person that would use that regressor. Value: null when the check passed.
  std::map<std::pair<const ModelBundle*, std::string>, std::exception_ptr> checked;
  /// The GLB skin attributes depend on the model only: computed once per model.
  std::map<const ModelBundle*, smpl::GltfSkinWeights> skins;
  std::optional<MeasurementMapping> mapping;
  /// Per model, when some person's arm was taken hanging (--ansur): caliper::hanging_arm_map().
  std::map<const ModelBundle*, LinearMap> arm_maps;
  double load_seconds = 0;
};

std::unique_ptr<ShapeMeasurer> fast_measurer(const ModelBundle& b) {
  const LandmarkTable lm = landmarks_for(b.model);
  // With a shape curve the avatars' betas are all the model's (linear_betas()).
  const int k = b.curve ? std::min(b.model.num_betas(), kMaxMeasurerBetas)
                : b.regressors.linear.empty()
                    ? std::min(10, b.model.num_betas())
                    : static_cast<int>(b.regressors.linear.front().coefficients().rows());
  return std::make_unique<ShapeMeasurer>(b.model, lm, available_measurements(lm), k);
}

void check_regressors_once(const ModelBundle& b, BatchModels& m) {
  const auto check = [&](const std::string& name, const ModelSignature& signature) {
    std::exception_ptr& result = m.checked[{&b, name}];
    try {
      signature.check(b.model);
    } catch (const std::exception&) {
      result = std::current_exception();
    }
  };
  for (const auto& r : b.regressors.linear) check(r.name(), r.signature());
  if (b.regressors.noise_aware) check("noise-aware", b.regressors.noise_aware->signature());
}

/// Loads (and trains) every model `people` need; people without a sex get the default one
/// (their count is returned in `no_sex`).
BatchModels load_batch_models(const BatchOptions& opt, std::vector<Person>& people,
                              long long& no_sex) {
  BatchModels m;
  const auto t_load = std::chrono::steady_clock::now();
  if (opt.mapping) m.mapping = load_mapping(*opt.mapping);
  BundleCache cache(opt.model, opt.regressors, opt.shape_curve);
  no_sex = 0;
  for (auto& p : people) {
    if (p.sex.empty()) {
      ++no_sex;
      p.sex = opt.default_sex;
    }
    if (!m.bundles.count(p.sex)) m.bundles[p.sex] = cache.get(p.sex);
  }
  const bool skins = opt.out_dir && (opt.format == "glb" || opt.format == "gltf");
  const bool hanging_arms =
      std::any_of(people.begin(), people.end(), [](const Person& p) { return p.hanging_arm; });
  for (const auto& [sex, b] : m.bundles) {
    (void)sex;
    if (hanging_arms && !m.arm_maps.count(b.get())) m.arm_maps[b.get()] = hanging_arm_map(b->model);
    if (!opt.need_mesh() && !m.measurers.count(b.get())) m.measurers[b.get()] = fast_measurer(*b);
    if (opt.need_mesh()) check_regressors_once(*b, m);
    if (skins && !m.skins.count(b.get())) m.skins[b.get()] = smpl::gltf_skin_weights(b->model);
  }
  m.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();
  return m;
}

/// One person's outcome. Per-person errors are data in the results CSV, not the end of the
/// batch.
Outcome batch_one(const BatchOptions& opt, const BatchModels& m, const Person& p,
                  const std::string& file_name) {
  Outcome o;
  o.sex = p.sex;
  try {
    if (!p.error.empty()) throw RuntimeError(p.error);
    const ModelBundle& b = *m.bundles.at(p.sex);
    const auto arm_map = m.arm_maps.find(&b);
    const MeasurementValues in =
        model_inputs(p, arm_map == m.arm_maps.end() ? nullptr : &arm_map->second);
    o.regressor = opt.regressor ? *opt.regressor : default_regressor(in);
    require_inputs(o.regressor, in);
    std::vector<std::string> warnings;
    try {
      // What the person measured is judged, not its mapping onto the model's virtual arm.
      warnings = check_inputs(p.inputs, opt.force);
    } catch (const ImplausibleInput& e) {
      o.status = "refused";
      o.message = e.what();
      return o;
    }
    const MeasurementMapping* mapping = m.mapping ? &*m.mapping : nullptr;
    for (size_t w = 0; w < warnings.size(); ++w) o.message += (w ? "; " : "") + warnings[w];
    if (!opt.need_mesh()) {
      fast_avatar(b, *m.measurers.at(&b), o.regressor, in, mapping, o.betas, o.achieved,
                  o.plausibility);
      if (!o.plausibility.plausible) add_implausible_note(o);
      return o;
    }
    const auto c = m.checked.find({&b, o.regressor});
    if (c != m.checked.end() && c->second) std::rethrow_exception(c->second);
    Avatar av = make_avatar(b, o.regressor, in, mapping, opt.circumferences, opt.exact_inputs,
                            /*check_model=*/c == m.checked.end());
    if (opt.out_dir) {
      const std::string path = (std::filesystem::path(*opt.out_dir) / file_name).string();
      const auto skin = m.skins.find(&b);
      write_avatar(path, b.model, av.betas, av.vertices,
                   {{"generator", version_string()}, {"regressor", o.regressor}},
                   skin == m.skins.end() ? nullptr : &skin->second);
    }
    o.achieved = std::move(av.achieved);
    o.betas = std::move(av.betas);
    o.plausibility = av.plausibility;
    if (!o.plausibility.plausible) add_implausible_note(o);
  } catch (const std::exception& e) {
    o.status = "error";
    o.message = e.what();
  }
  return o;
}

/// The outcome of a batch, in row order.
struct BatchResult {
  std::vector<Outcome> outcomes;
  std::vector<std::string> file_names;  ///< avatar file per person (with --out-dir)
  int threads = 1;
  double seconds = 0;
};

/// Runs every person on `opt.jobs` threads (the calling thread reports `progress`).
BatchResult run_batch(const BatchOptions& opt, const std::vector<Person>& people,
                      const BatchModels& m, Progress& progress) {
  BatchResult r;
  r.outcomes.resize(people.size());
  if (opt.out_dir) r.file_names = avatar_file_names(people, opt.format);
  std::atomic<size_t> next{0};
  std::atomic<size_t> done{0};
  auto work = [&]() {
    for (size_t i = next.fetch_add(1); i < people.size(); i = next.fetch_add(1)) {
      r.outcomes[i] = batch_one(opt, m, people[i], opt.out_dir ? r.file_names[i] : "");
      done.fetch_add(1);
    }
  };
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  r.threads = std::min<int>(opt.jobs, static_cast<int>(std::max<size_t>(1, people.size())));
  for (int t = 1; t < r.threads; ++t) threads.emplace_back(work);
  {
    // The main thread works too, reporting progress between people.
    std::thread main_worker(work);
    while (done.load() < people.size()) {
      progress.update(static_cast<std::int64_t>(done.load()));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    main_worker.join();
    progress.finish();
  }
  for (auto& t : threads) t.join();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

/// One person's row of the results CSV (without the line end).
std::string result_row(const Person& p, const Outcome& o,
                       const std::vector<std::string>& result_ids, int max_betas,
                       const std::string* file_name) {
  std::ostringstream out;
  out << csv_escape(p.id) << "," << o.sex << "," << o.status << "," << o.regressor;
  for (const auto& id : regressor_inputs(RegressorKind::R6)) {
    auto it = p.inputs.find(id);
    out << ",";
    if (it != p.inputs.end()) out << format_number(it->second * display_unit(id).second, 2);
  }
  for (const auto& id : result_ids) {
    auto it = o.achieved.find(id);
    out << ",";
    if (it != o.achieved.end()) out << format_number(it->second * display_unit(id).second, 2);
  }
  if (o.status == "ok") {
    out << "," << format_number(o.plausibility.mahalanobis, 4) << ","
        << format_number(o.plausibility.p_value, 6) << "," << o.plausibility.beyond_2sd.size()
        << "," << o.plausibility.beyond_3sd.size() << ","
        << (o.plausibility.plausible ? "yes" : "no");
  } else {
    out << ",,,,,";
  }
  for (int b = 0; b < max_betas; ++b) {
    out << ",";
    if (b < o.betas.size()) out << format_number(o.betas[b], 5);
  }
  if (file_name) out << "," << (o.status == "ok" ? csv_escape(*file_name) : "");
  out << "," << csv_escape(o.message);
  return out.str();
}

/// The results CSV (made in memory, so that it is written atomically: never a file cut
/// mid-row).
std::string results_csv(const BatchOptions& opt, const std::vector<Person>& people,
                        const BatchResult& r) {
  // Beta columns: the components the regressors set (the model's further ones are always 0).
  int max_betas = 0;
  for (const auto& o : r.outcomes) {
    if (o.status == "ok")
      max_betas = std::max(
          max_betas, std::min(static_cast<int>(o.betas.size()), std::max(1, o.plausibility.dof)));
  }
  // Circumference columns only when they are measured (--circumferences).
  std::vector<std::string> result_ids;
  for (const auto& id : report_ids()) {
    if (opt.circumferences || id.find("circumference") == std::string::npos)
      result_ids.push_back(id);
  }
  std::ostringstream out;
  auto col = [](const std::string& id) { return id + "_" + display_unit(id).first; };
  out << "id,sex,status,regressor";
  for (const auto& id : regressor_inputs(RegressorKind::R6)) out << ",input_" << col(id);
  for (const auto& id : result_ids) out << "," << col(id);
  out << ",mahalanobis,p_value,beyond_2sd,beyond_3sd,plausible";
  for (int b = 0; b < max_betas; ++b) out << ",beta" << b;
  if (opt.out_dir) out << ",file";
  out << ",message\n";
  for (size_t i = 0; i < people.size(); ++i) {
    out << result_row(people[i], r.outcomes[i], result_ids, max_betas,
                      opt.out_dir ? &r.file_names[i] : nullptr)
        << "\n";
  }
  return out.str();
}

/// Writes the results CSV and the summary line; returns the exit code.
int write_batch_report(const BatchOptions& opt, const std::vector<Person>& people,
                       const BatchModels& m, const BatchResult& r, Io& io) {
  const std::string csv = results_csv(opt, people, r);
  if (opt.out) {
    smpl::write_file_atomic(*opt.out, csv);
  } else {
    io.out << csv;
    io.out.flush();
    if (!io.out) throw RuntimeError("cannot write the results to standard output");
  }
  int ok = 0, refused = 0, errors = 0;
  for (const Outcome& o : r.outcomes) {
    ok += o.status == "ok";
    refused += o.status == "refused";
    errors += o.status == "error";
  }
  char buf[256];
  std::snprintf(buf, sizeof buf,
                " in %.3f s (%.0f per second, %s; models loaded and regressors trained in %.3f "
                "s): %d ok, %d refused, %s\n",
                r.seconds, r.seconds > 0 ? static_cast<double>(people.size()) / r.seconds : 0.0,
                count_noun(r.threads, "job", "jobs").c_str(), m.load_seconds, ok, refused,
                count_noun(errors, "error", "errors").c_str());
  io.err << "caliper batch: "
         << count_noun(static_cast<long long>(people.size()), "person", "people") << buf;
  return (refused + errors) > 0 ? kExitRuntime : kExitOk;
}

}  // namespace

int cmd_batch(const std::vector<std::string>& args, Io& io) {
  const std::optional<ParsedArgs> parsed =
      parse_args_or_help(args, batch_options(), kBatchHelp, io.out);
  if (!parsed) return kExitOk;
  const ParsedArgs& a = *parsed;
  const BatchOptions opt = batch_options_from(a);
  std::vector<Person> people = read_batch_people(opt);
  check_batch_outputs(opt);
  long long no_sex = 0;
  const BatchModels models = load_batch_models(opt, people, no_sex);
  if (no_sex > 0 && !opt.sex_given && !opt.model) {
    io.err << "caliper batch: " << count_noun(no_sex, "person has", "people have")
           << " no sex (no sex column or an empty cell): the " << opt.default_sex
           << " model was used; fill the sex column or give --sex\n";
  }
  Progress progress(io.err, static_cast<std::int64_t>(people.size()), io.err_is_terminal);
  const BatchResult result = run_batch(opt, people, models, progress);
  return write_batch_report(opt, people, models, result, io);
}

}  // namespace caliper::cli
