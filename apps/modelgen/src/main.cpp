/// \file main.cpp
/// caliper-modelgen: writes the open default body models (female, male, neutral) in the
/// project's .npz format, deterministically, from MakeHuman's CC0 assets fitted to every ANSUR II
/// and NHANES subject (docs/models.md).
///
///   caliper-modelgen --out assets/models                 # all three models
///   caliper-modelgen --validate assets/models/caliper-female.npz --stats
///   assets/models/ansur_stats.csv caliper-modelgen --stats-from /path/to/ansur2 --stats-out
///   assets/models/ansur_stats.csv
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "ansur_stats.hpp"
#include "app/cli_style.hpp"
#include "contact.hpp"
#include "makehuman_rig.hpp"
#include "makehuman_shape.hpp"
#include "pose_correctives.hpp"
#include "smpl/io.hpp"
#include "validation.hpp"

namespace {

/// Everything the command line sets.
struct Options {
  std::string out, stats_path, stats_from, stats_out;
  bool quiet = false;
  std::string validate;
  std::string makehuman_dir = "../shared/data/makehuman";
  std::string survey_dir = "../shared/data";
  std::string fit_cache;
  int check_fit = 0;
  std::string population = "general";
  int samples = 10000;
};

/// The options on a CLI11 app in the programs' common style (app/cli_style.hpp).
void declare_options(CLI::App& cli, Options& o) {
  namespace app = caliper::app;
  app::apply_style(
      cli, {{"caliper-modelgen --out DIR [--makehuman DIR] [--surveys DIR] [--fit-cache FILE]",
             "                 [--check-fit N] [--shape-population general|pooled] [--quiet]",
             "caliper-modelgen --validate MODEL.npz --stats FILE [--samples N]",
             "caliper-modelgen --stats-from ANSUR_DIR --stats-out FILE"},
            "Writes DIR/caliper-{female,male,neutral}.npz, the open default body models:\n"
            "MakeHuman's CC0 base mesh (skin only, T-pose, SMPL's 24 joints, merged weights,\n"
            "fitted joint regressor, landmarks, texture coordinates), its targets fitted to every\n"
            "ANSUR II and NHANES subject under --surveys (ansur2/, nhanes/; default\n"
            "../shared/data) and their principal components per sex, touching skin separated and\n"
            "pose correctives fitted; the same bytes on every x86-64 CPU. About 5 minutes on 2\n"
            "cores; with --fit-cache a rerun on the same inputs takes under 2 minutes.\n"
            "--validate compares a model's bodies with the ANSUR II statistics table\n"
            "(assets/models/ansur_stats.csv, which --stats-from recomputes from the survey files).",
            "example:\n  caliper-modelgen --out assets/models --quiet\n\n"
            "exit codes: 0 ok, 1 error, 2 usage error"});
  app::add_value(cli, "--out", o.out, "DIR", "write the models into DIR");
  app::add_value(cli, "--stats", o.stats_path, "FILE",
                 "the ANSUR II statistics table --validate compares with");
  app::add_flag(cli, "--quiet", o.quiet, "print nothing but errors");
  app::add_value(cli, "--stats-from", o.stats_from, "ANSUR_DIR",
                 "recompute the statistics table from the ANSUR II survey files");
  app::add_value(cli, "--stats-out", o.stats_out, "FILE", "where --stats-from writes the table");
  app::add_value(cli, "--validate", o.validate, "MODEL.npz",
                 "compare the model's bodies (drawn from its ANSUR II population) with the survey "
                 "(needs --stats)");
  app::add_value(cli, "--samples", o.samples, "N", "bodies drawn by --validate");
  app::add_value(cli, "--makehuman", o.makehuman_dir, "DIR", "MakeHuman's CC0 assets");
  app::add_value(cli, "--surveys", o.survey_dir, "DIR",
                 "the folder that holds ansur2/ and nhanes/");
  app::add_value(cli, "--fit-cache", o.fit_cache, "FILE",
                 "reuse the registered subjects saved in FILE when it was made from the "
                 "same inputs, else fit them and save them there (keep it outside the repository; "
                 "delete it when the fitting code changes)");
  app::add_value(cli, "--check-fit", o.check_fit, "N",
                 "with --fit-cache FILE made from the same inputs: refit every N-th "
                 "subject with this CPU's arithmetic and stop with an error unless each comes out "
                 "bit for bit as in FILE (CI's check that a CPU without AVX2/FMA makes the same "
                 "models, at a fraction of a whole fit)")
      ->check(CLI::Range(1, 1000000));
  app::add_value(cli, "--shape-population", o.population, "POP",
                 "what each sex's betas ~ N(0, I) stand for: general (the general adult "
                 "population: NHANES for what NHANES measures, ANSUR II's spread given those "
                 "measurements for the rest) or pooled (every registered subject alike, about 2/3 "
                 "ANSUR II soldiers for the men)")
      ->check(CLI::IsMember({"pooled", "general"}));
}

/// The fit's residuals per survey, sex and measurement (mean, RMS, largest, how many beyond 3
/// tolerances) and how many subjects shape_model() leaves out (mh::registered()).
void print_fit_residuals(const std::vector<modelgen::mh::Subject>& subjects,
                         const modelgen::mh::FitResult& fit) {
  namespace mh = modelgen::mh;
  std::printf("residual (fitted body minus survey): mean / RMS / max |.|\n");
  for (const char* source : {"ANSUR II", "NHANES"}) {
    for (const char* sex : {"female", "male"}) {
      for (size_t j = 0; j < mh::fit_measures().size(); ++j) {
        double sum = 0, sq = 0, worst = 0;
        int n = 0;
        for (size_t i = 0; i < subjects.size(); ++i) {
          const double r =
              fit.residuals(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
          if (subjects[i].source != source || subjects[i].sex != sex || !std::isfinite(r)) continue;
          sum += r;
          sq += r * r;
          worst = std::max(worst, std::abs(r));
          ++n;
        }
        if (n == 0) continue;
        int far = 0;  // residuals beyond 3 tolerances
        for (size_t i = 0; i < subjects.size(); ++i) {
          const double r =
              fit.residuals(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
          if (subjects[i].source == source && subjects[i].sex == sex && std::isfinite(r) &&
              std::abs(r) > 3 * mh::fit_measures()[j].tolerance_for(sex, source)) {
            ++far;
          }
        }
        const bool kg = mh::fit_measures()[j].id == "weight";
        const double scale = kg ? 1.0 : 1000.0;
        std::printf("  %-8s %-6s %-26s n=%4d  %+7.1f %7.1f %7.1f %s, %d beyond 3 tol.\n", source,
                    sex, mh::fit_measures()[j].id.c_str(), n, scale * sum / n,
                    scale * std::sqrt(sq / n), scale * worst, kg ? "kg" : "mm", far);
      }
    }
  }
  int left_out = 0;
  for (size_t i = 0; i < subjects.size(); ++i) left_out += !mh::registered(fit, i);
  std::printf(
      "%d of %zu subjects beyond 3 tolerances on some measurement: left out of the "
      "populations\n",
      left_out, subjects.size());
}

/// The threads the generator's steps share: every core.
int generator_threads() {
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

/// Seconds since t.
double seconds(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// The generator's last steps on each shape model: touching skin separated and crumples
/// smoothed (contact.hpp), then the pose correctives fitted on the mean body
/// (pose_correctives.hpp).
void separate_contacts_and_add_correctives(smpl::BodyModel& m, const char* sex, bool quiet) {
  const int threads = generator_threads();
  const auto tc = std::chrono::steady_clock::now();
  modelgen::ContactOptions co;
  co.threads = threads;
  const modelgen::ContactReport cr = modelgen::separate_contacts_best(m, co);
  auto sum = [](const std::vector<int>& p) { return std::accumulate(p.begin(), p.end(), 0); };
  if (!quiet) {
    std::printf(
        "%s: touching skin separated (%s) in %d round(s), %.1f s: intersecting pairs over the "
        "%d check bodies %d -> %d (mean %d -> %d), %d vertices moved, at most %.1f mm\n",
        sex,
        cr.direction == modelgen::ContactDirection::InwardNormal ? "inward normals"
                                                                 : "out of the other sheet",
        cr.rounds, seconds(tc), cr.bodies, sum(cr.pairs_before), sum(cr.pairs_after),
        cr.pairs_before.front(), cr.pairs_after.front(), cr.moved_vertices,
        1000.0 * cr.largest_move);
  }
  const modelgen::UnfoldReport ur = modelgen::unfold_creases(m, co);
  if (!quiet) {
    std::printf(
        "%s: crumpled skin smoothed in %d round(s): pairs within two rings over the check bodies "
        "%d -> %d, %d vertices smoothed\n",
        sex, ur.rounds, sum(ur.pairs_before), sum(ur.pairs_after), ur.smoothed_vertices);
  }
  const auto tp = std::chrono::steady_clock::now();
  modelgen::PoseCorrectiveOptions po;
  po.threads = threads;
  modelgen::PoseCorrectiveReport pr;
  m.posedirs = modelgen::pose_correctives(m, po, &pr);
  if (!quiet) {
    int skinned = 0, target = 0;
    std::string dropped;
    for (const modelgen::JointCorrective& j : pr.joints) {
      skinned += j.folds_skinned;
      target += j.kept ? j.folds_target : j.folds_skinned;
      dropped += j.kept ? "" : " " + m.joint_names[static_cast<std::size_t>(j.joint)];
    }
    std::printf(
        "%s: pose correctives of %zu joints in %.1f s: folded triangles over their bends %d "
        "with skinning, %d in the targets fitted%s%s\n",
        sex, pr.joints.size(), seconds(tp), skinned, target,
        dropped.empty() ? "" : "; left to skinning (the targets folded more):", dropped.c_str());
  }
}

/// --check-fit: refits every `every`-th subject with this process's arithmetic and requires the
/// bits of the cached fit (mh::check_fit()); throws naming the first subjects that differ.
void check_cached_fit(const modelgen::mh::ShapeBasis& basis, const smpl::BodyModel& tmpl,
                      const std::vector<modelgen::mh::Subject>& subjects,
                      const std::string& fit_cache,
                      const std::optional<modelgen::mh::FitResult>& cached, int every, bool quiet) {
  namespace mh = modelgen::mh;
  if (fit_cache.empty()) throw std::runtime_error("--check-fit needs --fit-cache FILE");
  if (!cached) {
    throw std::runtime_error("--check-fit: " + fit_cache +
                             " holds no fit of these inputs (made from other MakeHuman assets or "
                             "surveys, or missing): run once without --check-fit to make it");
  }
  const auto t0 = std::chrono::steady_clock::now();
  const mh::FitCheckReport r =
      mh::check_fit(basis, tmpl, subjects, *cached, every, generator_threads());
  if (!r.differing.empty()) {
    std::string which;
    for (size_t n = 0; n < r.differing.size() && n < 5; ++n) {
      const mh::Subject& s = subjects[r.differing[n]];
      which +=
          (n ? ", " : "") + std::to_string(r.differing[n]) + " (" + s.source + " " + s.sex + ")";
    }
    throw std::runtime_error(
        "--check-fit: " + std::to_string(r.differing.size()) + " of " + std::to_string(r.checked) +
        " refitted subjects differ from " + fit_cache + " in their bits (subjects " + which +
        "): this CPU's arithmetic does not reproduce the fit, so the models would not be the "
        "committed bytes (docs/models.md, \"Same bytes on every CPU\")");
  }
  if (!quiet) {
    std::printf(
        "fit cache checked: %d subjects refitted (every %d-th), bit for bit as in %s (%.1f s)\n",
        r.checked, every, fit_cache.c_str(), seconds(t0));
  }
}

/// The shape models: every survey subject
/// registered to MakeHuman's targets, principal components per sex; prints the fit residuals.
void write_shape_models(const modelgen::mh::Assets& assets, const smpl::BodyModel& tmpl,
                        const std::string& survey_dir, const std::string& fit_cache,
                        int check_every, bool general, const std::string& out, bool quiet) {
  namespace mh = modelgen::mh;
  const auto t0 = std::chrono::steady_clock::now();
  const mh::ShapeBasis basis = mh::shape_basis(assets, tmpl);
  std::vector<mh::Subject> subjects;
  try {
    subjects = mh::read_subjects(survey_dir + "/ansur2", survey_dir + "/nhanes");
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(
        std::string(e.what()) +
        " (give the folder that holds ansur2/ and nhanes/ with --surveys DIR)");
  }
  if (!quiet) {
    std::printf("basis: %zu directions, %zu subjects, %.1f s\n", basis.names.size(),
                subjects.size(), seconds(t0));
  }
  const auto t1 = std::chrono::steady_clock::now();
  const std::uint64_t fingerprint =
      fit_cache.empty() ? 0 : mh::fit_fingerprint(basis, tmpl, subjects);
  std::optional<mh::FitResult> cached;
  if (!fit_cache.empty()) {
    cached = mh::load_fit(fit_cache, fingerprint, static_cast<Eigen::Index>(subjects.size()),
                          static_cast<Eigen::Index>(basis.names.size()));
  }
  if (check_every > 0)
    check_cached_fit(basis, tmpl, subjects, fit_cache, cached, check_every, quiet);
  const bool reused = cached.has_value();
  const mh::FitResult fit =
      reused ? *std::move(cached) : mh::fit_subjects(basis, tmpl, subjects, generator_threads());
  if (!fit_cache.empty() && !reused) mh::save_fit(fit_cache, fingerprint, fit);
  if (!quiet) {
    if (reused) {
      std::printf("registered subjects read from %s (%.1f s)\n", fit_cache.c_str(), seconds(t1));
    } else {
      std::printf("fitted in %.1f s%s%s\n", seconds(t1), fit_cache.empty() ? "" : ", saved to ",
                  fit_cache.c_str());
    }
    print_fit_residuals(subjects, fit);
  }
  // One component per fitted measurement (mh::fit_measures(), 23): each registration is the
  // prior's mean moved along the directions those measurements see, so the registered bodies
  // vary in about that many directions. With 16 the men's sampled biacromial SD was 0.88 of
  // ANSUR II's (0.99 with 20; docs/models.md).
  const int components = static_cast<int>(mh::fit_measures().size());
  for (const char* sex : {"female", "male", "neutral"}) {
    mh::Population population;
    population.general = general;
    smpl::BodyModel m = mh::shape_model(basis, tmpl, subjects, fit, sex, components, population);
    mh::level_soles(m);
    separate_contacts_and_add_correctives(m, sex, quiet);
    // Blend shapes at float32 (7 significant digits: under 0.1 um on a 1 m offset; smplx works
    // at this precision), so save_model stores them as such: half the bytes, half the load.
    m.shapedirs = m.shapedirs.cast<float>().cast<double>();
    m.posedirs = m.posedirs.cast<float>().cast<double>();
    const std::string path = out + "/caliper-" + sex + ".npz";
    smpl::SaveOptions so;
    so.compress = true;
    smpl::save_model(m, path, so);
    if (!quiet) {
      std::printf("wrote %s (%d betas; RMS vertex offset of +1 SD per component, mm:", path.c_str(),
                  m.num_betas());
      for (int b = 0; b < m.num_betas(); ++b) {
        std::printf(" %.1f", 1000.0 * m.shapedirs.col(b).norm() / std::sqrt(m.num_vertices()));
      }
      std::printf(")\n");
    }
  }
  if (!quiet) std::printf("shape models in %.1f s\n", seconds(t0));
}

/// --validate: the model's bodies against the survey statistics, as a markdown table. The
/// bodies are drawn from the model's ANSUR II population when the file carries one (the
/// open models: their betas ~ N(0, I) are the general population), else with betas ~ N(0, I).
void print_validation(const std::string& validate, const std::string& stats_path, int samples) {
  const modelgen::SurveyStats st = modelgen::read_stats_table(stats_path);
  const smpl::BodyModel model = smpl::load_model(validate);
  const std::optional<caliper::SurveyPopulation> ansur =
      caliper::survey_population(model, "ansur2");
  const auto t0 = std::chrono::steady_clock::now();
  const modelgen::ValidationFigures m =
      modelgen::model_figures(model, samples, 12345, ansur ? &*ansur : nullptr);
  const modelgen::ValidationFigures s = modelgen::survey_figures(st, model.meta.gender);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string drawn = ansur ? "betas ~ the model's ANSUR II population (" +
                                        std::to_string(ansur->subjects) + " registered subjects)"
                                  : std::string("betas ~ N(0, I)");
  std::printf("%s: %d bodies with %s vs ANSUR II (%d subjects), %.1f s\n", validate.c_str(),
              samples, drawn.c_str(), s.count, secs);
  std::printf(
      "| measurement | model mean | survey mean | mean error | model SD | survey SD | SD ratio "
      "|\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const std::string& id : modelgen::validation_ids()) {
    if (m.mean.count(id) == 0) continue;  // a measurement the model has no landmarks for
    const double scale = id == "weight" ? 1.0 : 1000.0;
    const char* unit = id == "weight" ? "kg" : "mm";
    std::printf("| %s (%s) | %.1f | %.1f | %+.2f %% | %.1f | %.1f | %.2f |\n", id.c_str(), unit,
                m.mean.at(id) * scale, s.mean.at(id) * scale,
                100.0 * (m.mean.at(id) / s.mean.at(id) - 1.0), m.sd.at(id) * scale,
                s.sd.at(id) * scale, m.sd.at(id) / s.sd.at(id));
  }
  std::printf("| corr(stature, span) | %.3f | %.3f | %+.3f | | | |\n", m.corr_stature_span,
              s.corr_stature_span, m.corr_stature_span - s.corr_stature_span);
  std::printf("| corr(stature, weight) | %.3f | %.3f | %+.3f | | | |\n", m.corr_stature_weight,
              s.corr_stature_weight, m.corr_stature_weight - s.corr_stature_weight);
}

/// The template model (MakeHuman's base mesh rigged and T-posed), then the shape models.
void write_models(const Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const modelgen::mh::Assets assets = modelgen::mh::read_assets(o.makehuman_dir);
  const smpl::BodyModel model =
      modelgen::mh::template_model(assets, modelgen::mh::default_regressor_targets());
  if (!o.quiet) {
    std::printf("template: %d vertices, %d faces, %.1f s\n", model.num_vertices(),
                model.num_faces(), seconds(t0));
  }
  write_shape_models(assets, model, o.survey_dir, o.fit_cache, o.check_fit,
                     o.population == "general", o.out, o.quiet);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Options o;
    CLI::App cli("", "caliper-modelgen");
    declare_options(cli, o);
    try {
      const caliper::app::CommandLine line =
          caliper::app::parse_command_line(cli, std::vector<std::string>(argv + 1, argv + argc));
      if (line.help) {
        std::cout << cli.help();
        return 0;
      }
      caliper::app::no_positional(line);
    } catch (const caliper::app::CommandLineError& e) {
      std::cerr << caliper::app::usage_error_line("caliper-modelgen", e.what());
      return 2;
    }
    const std::string& out = o.out;
    const std::string &stats_from = o.stats_from, &stats_out = o.stats_out;
    const std::string& stats_path = o.stats_path;
    const std::string& validate = o.validate;
    const bool quiet = o.quiet;
    const int samples = o.samples;
    if (!stats_from.empty()) {
      if (stats_out.empty()) {
        throw std::runtime_error("--stats-from needs --stats-out FILE");
      }
      modelgen::write_stats_table(modelgen::stats_from_survey(stats_from), stats_out);
      if (!quiet) {
        std::cout << "wrote " << stats_out << "\n";
      }
      if (out.empty()) {
        return 0;
      }
    }
    if (!validate.empty()) {
      if (stats_path.empty()) {
        throw std::runtime_error("--validate needs --stats FILE");
      }
      print_validation(validate, stats_path, samples);
      if (out.empty()) {
        return 0;
      }
    }
    if (out.empty()) {
      std::cerr << caliper::app::usage_error_line("caliper-modelgen",
                                                  "give the output folder with --out DIR");
      return 2;
    }
    if (o.check_fit > 0 && o.fit_cache.empty()) {
      std::cerr << caliper::app::usage_error_line(
          "caliper-modelgen", "--check-fit needs --fit-cache FILE (the fit to check)");
      return 2;
    }
    write_models(o);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "caliper-modelgen: " << e.what() << "\n";
    return 1;
  }
}
