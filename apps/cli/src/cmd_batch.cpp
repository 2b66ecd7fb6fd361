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
    k_betas = r->predict(mapped);
  }
  const Eigen::VectorXd m = measurer.measure(k_betas);
  for (size_t i = 0; i < measurer.definitions().size(); ++i)
    achieved[measurer.definitions()[i].id] = m[static_cast<Eigen::Index>(i)];
  const double volume = measurer.volume(k_betas);
  achieved["volume"] = volume;
  achieved["weight"] = weight_from_volume(volume, weight_formula_for(b.model.meta.gender));
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

int cmd_batch(const std::vector<std::string>& args, Io& io) {
  const std::vector<OptionSpec> specs = {
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
      {"exact-inputs", "", "", "refine R2-R6 betas to reproduce every input exactly (slower)",
       false},
      {"force", "", "", "create avatars even for inputs outside the hard limits", false},
  };
  const ParsedArgs a = parse_args(args, specs);
  if (a.flags.count("help")) {
    io.out << "usage: caliper batch PEOPLE.csv [options]\n"
              "       caliper batch --ansur ANSUR_II_MALE_Public.csv [--ansur ...] [options]\n\n"
              "PEOPLE.csv: a header naming measurement ids with units (height_cm, weight_kg,\n"
              "arm_span_fingertips_cm, inseam_height_cm, hip_width_cm, arm_length_cm; also _mm,\n"
              "_m, _in, _lb) and optional id and sex columns. Results CSV: one row per person\n"
              "with status (ok, refused, error), the achieved measurements (cm, kg, L),\n"
              "plausibility, betas and (with --out-dir) the avatar's file; ids that give the\n"
              "same file name get -2, -3, ... The outputs are checked before the work starts\n"
              "and written atomically. Exit code 1 when any row was refused or failed, or a\n"
              "file could not be written.\n\n"
           << format_options(specs)
           << "\nexample:\n  caliper batch people.csv -j 2 --out results.csv --out-dir avatars\n";
    return kExitOk;
  }
  if (a.positional.size() > 1) throw UsageError("give one people CSV file");
  if (a.positional.empty() && !a.get("ansur"))
    throw UsageError("give a people CSV file or --ansur FILE");
  const std::string default_sex = a.get("sex") ? normalise_sex(*a.get("sex")) : "neutral";
  std::optional<std::string> fixed_regressor;
  if (auto r = a.get("regressor")) fixed_regressor = normalise_regressor_name(*r);
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (auto j = a.get("jobs")) jobs = parse_int(*j, "jobs", 1, 256);
  const std::string format = a.get_or("format", "glb");
  if (!is_avatar_extension("avatar." + format))
    throw UsageError("--format " + format + ": expected glb, gltf, vrm, fbx, obj or ply");
  if (a.get("regressors") && !a.get("model"))
    throw UsageError("--regressors needs --model (saved regressors belong to one model)");

  std::vector<Person> people;
  if (!a.positional.empty()) people = read_people_csv(a.positional[0]);
  if (auto it = a.values.find("ansur"); it != a.values.end()) {
    for (const auto& f : it->second) {
      auto p = read_ansur_csv(f);
      people.insert(people.end(), std::make_move_iterator(p.begin()),
                    std::make_move_iterator(p.end()));
    }
  }
  if (auto l = a.get("limit")) {
    const int n = parse_int(*l, "limit", 0, 100000000);
    if (static_cast<size_t>(n) < people.size()) people.resize(static_cast<size_t>(n));
  }
  // Outputs are checked before the work starts, so that a long batch does not end in an error.
  const std::optional<std::string> out_dir = a.get("out-dir");
  if (out_dir) check_writable_folder(*out_dir, "--out-dir");
  if (auto path = a.get("out")) {
    const std::filesystem::path p(*path);
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec))
      throw RuntimeError("--out " + *path + ": is a folder; give a file name for the results CSV");
    const std::filesystem::path parent = p.parent_path().empty() ? "." : p.parent_path();
    if (!std::filesystem::is_directory(parent, ec))
      throw RuntimeError("--out " + *path + ": the folder " + parent.string() +
                         " does not exist; create it first");
    // A device or FIFO (e.g. /dev/stdout) is written in place and cannot be probed.
    if (std::filesystem::is_regular_file(p, ec) || !std::filesystem::exists(p, ec))
      check_writable_folder(parent, "--out");
  }
  const std::vector<std::string> file_names =
      out_dir ? avatar_file_names(people, format) : std::vector<std::string>{};
  const bool circumferences = a.flags.count("circumferences") > 0;
  // Without avatar files or circumferences no mesh is needed: the measurements, volume and
  // weight come from the betas through ShapeMeasurer's exact precomputed maps (fast path).
  const bool exact_inputs = a.flags.count("exact-inputs") > 0;
  const bool need_mesh = circumferences || exact_inputs || out_dir.has_value();
  const bool force = a.flags.count("force") > 0;
  std::optional<MeasurementMapping> mapping;
  if (auto m = a.get("mapping")) mapping = load_mapping(*m);

  // Load (and train) every model needed before the workers start.
  BundleCache cache(a.get("model"), a.get("regressors"));
  std::map<std::string, std::shared_ptr<const ModelBundle>> bundles;
  const auto t_load = std::chrono::steady_clock::now();
  long long no_sex = 0;
  for (auto& p : people) {
    if (p.sex.empty()) {
      ++no_sex;
      p.sex = default_sex;
    }
    if (!bundles.count(p.sex)) bundles[p.sex] = cache.get(p.sex);
  }
  if (no_sex > 0 && !a.get("sex") && !a.get("model")) {
    io.err << "caliper batch: " << count_noun(no_sex, "person has", "people have")
           << " no sex (no sex column or an empty cell): the " << default_sex
           << " model was used; fill the sex column or give --sex\n";
  }
  std::map<const ModelBundle*, std::unique_ptr<ShapeMeasurer>> measurers;
  if (!need_mesh) {
    for (const auto& [sex, b] : bundles) {
      (void)sex;
      if (measurers.count(b.get())) continue;
      const LandmarkTable lm = landmarks_for(b->model);
      const int k = b->regressors.linear.empty()
                        ? std::min(10, b->model.num_betas())
                        : static_cast<int>(b->regressors.linear.front().coefficients().rows());
      measurers[b.get()] =
          std::make_unique<ShapeMeasurer>(b->model, lm, available_measurements(lm), k);
    }
  }
  // Each regressor is checked against its model once here (the check computes the model's
  // fingerprint, a pass over the template and shape directions); a mismatch becomes the error of
  // every person that would use that regressor, as a per-avatar check would make it.
  // (Value: null when the check passed.)
  std::map<std::pair<const ModelBundle*, std::string>, std::exception_ptr> checked;
  if (need_mesh) {
    for (const auto& [sex, b] : bundles) {
      (void)sex;
      const auto check = [&](const std::string& name, const ModelSignature& signature) {
        std::exception_ptr& result = checked[{b.get(), name}];
        try {
          signature.check(b->model);
        } catch (const std::exception&) {
          result = std::current_exception();
        }
      };
      for (const auto& r : b->regressors.linear) check(r.name(), r.signature());
      if (b->regressors.noise_aware) check("noise-aware", b->regressors.noise_aware->signature());
    }
  }
  // The GLB skin attributes depend on the model only: computed once per model.
  std::map<const ModelBundle*, smpl::GltfSkinWeights> skins;
  if (out_dir && (format == "glb" || format == "gltf")) {
    for (const auto& [sex, b] : bundles) {
      (void)sex;
      if (!skins.count(b.get())) skins[b.get()] = smpl::gltf_skin_weights(b->model);
    }
  }
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();

  std::vector<Outcome> outcomes(people.size());
  std::atomic<size_t> next{0};
  std::atomic<size_t> done{0};
  auto work = [&]() {
    for (size_t i = next.fetch_add(1); i < people.size(); i = next.fetch_add(1)) {
      const Person& p = people[i];
      Outcome& o = outcomes[i];
      o.sex = p.sex;
      // Per-person errors are data in the results CSV, not the end of the batch.
      try {
        if (!p.error.empty()) throw RuntimeError(p.error);
        o.regressor = fixed_regressor ? *fixed_regressor : default_regressor(p.inputs);
        require_inputs(o.regressor, p.inputs);
        std::vector<std::string> warnings;
        try {
          warnings = check_inputs(p.inputs, force);
        } catch (const ImplausibleInput& e) {
          o.status = "refused";
          o.message = e.what();
          done.fetch_add(1);
          continue;
        }
        const ModelBundle& b = *bundles.at(p.sex);
        for (size_t w = 0; w < warnings.size(); ++w) o.message += (w ? "; " : "") + warnings[w];
        if (!need_mesh) {
          fast_avatar(b, *measurers.at(&b), o.regressor, p.inputs, mapping ? &*mapping : nullptr,
                      o.betas, o.achieved, o.plausibility);
          if (!o.plausibility.plausible) add_implausible_note(o);
          done.fetch_add(1);
          continue;
        }
        const auto c = checked.find({&b, o.regressor});
        if (c != checked.end() && c->second) std::rethrow_exception(c->second);
        Avatar av = make_avatar(b, o.regressor, p.inputs, mapping ? &*mapping : nullptr,
                                circumferences, exact_inputs, /*check_model=*/c == checked.end());
        if (out_dir) {
          const std::string path = (std::filesystem::path(*out_dir) / file_names[i]).string();
          const auto skin = skins.find(&b);
          write_avatar(path, b.model, av.betas, av.vertices,
                       {{"generator", version_string()}, {"regressor", o.regressor}},
                       skin == skins.end() ? nullptr : &skin->second);
        }
        o.achieved = std::move(av.achieved);
        o.betas = std::move(av.betas);
        o.plausibility = av.plausibility;
        if (!o.plausibility.plausible) add_implausible_note(o);
      } catch (const std::exception& e) {
        o.status = "error";
        o.message = e.what();
      }
      done.fetch_add(1);
    }
  };
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  const int n_threads = std::min<int>(jobs, static_cast<int>(std::max<size_t>(1, people.size())));
  for (int t = 1; t < n_threads; ++t) threads.emplace_back(work);
  {
    Progress progress(io.err, static_cast<std::int64_t>(people.size()), io.err_is_terminal);
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
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Results CSV.
  // Beta columns: the components the regressors set (the model's further ones are always 0).
  int max_betas = 0;
  for (const auto& o : outcomes) {
    if (o.status == "ok")
      max_betas = std::max(
          max_betas, std::min(static_cast<int>(o.betas.size()), std::max(1, o.plausibility.dof)));
  }
  // Circumference columns only when they are measured (--circumferences).
  std::vector<std::string> result_ids;
  for (const auto& id : report_ids()) {
    if (circumferences || id.find("circumference") == std::string::npos) result_ids.push_back(id);
  }
  // The results CSV is made in memory and written atomically: never a file cut mid-row.
  std::ostringstream csv;
  std::ostream* out = &csv;
  const auto& inputs = regressor_inputs(RegressorKind::R6);
  auto col = [](const std::string& id) { return id + "_" + display_unit(id).first; };
  *out << "id,sex,status,regressor";
  for (const auto& id : inputs) *out << ",input_" << col(id);
  for (const auto& id : result_ids) *out << "," << col(id);
  *out << ",mahalanobis,p_value,beyond_2sd,beyond_3sd,plausible";
  for (int b = 0; b < max_betas; ++b) *out << ",beta" << b;
  if (out_dir) *out << ",file";
  *out << ",message\n";
  int ok = 0, refused = 0, errors = 0;
  for (size_t i = 0; i < people.size(); ++i) {
    const Person& p = people[i];
    const Outcome& o = outcomes[i];
    ok += o.status == "ok";
    refused += o.status == "refused";
    errors += o.status == "error";
    *out << csv_escape(p.id) << "," << o.sex << "," << o.status << "," << o.regressor;
    for (const auto& id : inputs) {
      auto it = p.inputs.find(id);
      *out << ",";
      if (it != p.inputs.end()) *out << format_number(it->second * display_unit(id).second, 2);
    }
    for (const auto& id : result_ids) {
      auto it = o.achieved.find(id);
      *out << ",";
      if (it != o.achieved.end()) *out << format_number(it->second * display_unit(id).second, 2);
    }
    if (o.status == "ok") {
      *out << "," << format_number(o.plausibility.mahalanobis, 4) << ","
           << format_number(o.plausibility.p_value, 6) << "," << o.plausibility.beyond_2sd.size()
           << "," << o.plausibility.beyond_3sd.size() << ","
           << (o.plausibility.plausible ? "yes" : "no");
    } else {
      *out << ",,,,,";
    }
    for (int b = 0; b < max_betas; ++b) {
      *out << ",";
      if (b < o.betas.size()) *out << format_number(o.betas[b], 5);
    }
    if (out_dir) *out << "," << (o.status == "ok" ? csv_escape(file_names[i]) : "");
    *out << "," << csv_escape(o.message) << "\n";
  }
  if (auto path = a.get("out")) {
    smpl::write_file_atomic(*path, csv.str());
  } else {
    io.out << csv.str();
    io.out.flush();
    if (!io.out) throw RuntimeError("cannot write the results to standard output");
  }
  char buf[256];
  std::snprintf(buf, sizeof buf,
                " in %.3f s (%.0f per second, %s; models loaded and regressors trained in %.3f "
                "s): %d ok, %d refused, %s\n",
                seconds, seconds > 0 ? static_cast<double>(people.size()) / seconds : 0.0,
                count_noun(n_threads, "job", "jobs").c_str(), load_s, ok, refused,
                count_noun(errors, "error", "errors").c_str());
  io.err << "caliper batch: "
         << count_noun(static_cast<long long>(people.size()), "person", "people") << buf;
  return (refused + errors) > 0 ? kExitRuntime : kExitOk;
}

}  // namespace caliper::cli
