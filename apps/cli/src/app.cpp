// The `caliper` command: subcommand dispatch, top-level help, --version, and main_guarded(),
// the one place where exceptions become messages and exit codes.
#include <exception>
#include <iostream>
#include <new>

#include "caliper/errors.hpp"
#include "caliper/json.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "smpl/body_model.hpp"

#ifndef CALIPER_VERSION
#define CALIPER_VERSION "0.0.0"
#endif

namespace caliper::cli {

std::string version_string() {
  return std::string("caliper ") + CALIPER_VERSION;
}

namespace {

const char* kTopHelp =
    "caliper: metrically accurate avatars from body measurements (The Virtual Caliper)\n"
    "\n"
    "usage: caliper <command> [options]\n"
    "\n"
    "commands:\n"
    "  create     measurements in (with units), an avatar (.glb/.gltf/.obj/.ply) and a report out\n"
    "  measure    all measurements, volume and weight of an avatar file or of a model + betas\n"
    "  train      fit and report the regressors R2, R4, R5, R6 and noise-aware for a model\n"
    "  batch      a CSV of people (or ANSUR II files) in, a results CSV and avatars out\n"
    "  models     list the open default models and describe model files\n"
    "  render     PNG pictures of an avatar or a model (front, side, three-quarter, turntable)\n"
    "  evaluate   the evaluation studies of docs/evaluation.md (table1, simulation, ansur)\n"
    "\n"
    "options:\n"
    "  -h, --help     this help; `caliper <command> --help` for a command's options\n"
    "  --version      print the version\n"
    "\n"
    "example:\n"
    "  caliper create --sex female --height 168cm --weight 62kg --out avatar.glb --png "
    "avatar.png\n"
    "\n"
    "exit codes: 0 ok, 1 runtime or input-file error, 2 usage error, 3 implausible input "
    "refused\n"
    "environment: CALIPER_ASSETS=<folder with models/caliper-{female,male,neutral}.npz>\n";

int dispatch(const std::vector<std::string>& args, Io& io) {
  if (args.empty()) {
    io.err << kTopHelp;
    return kExitUsage;
  }
  const std::string& cmd = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (cmd == "-h" || cmd == "--help" || cmd == "help") {
    io.out << kTopHelp;
    return kExitOk;
  }
  if (cmd == "--version" || cmd == "version") {
    io.out << version_string() << "\n";
    return kExitOk;
  }
  if (cmd == "create") return cmd_create(rest, io);
  if (cmd == "measure") return cmd_measure(rest, io);
  if (cmd == "train") return cmd_train(rest, io);
  if (cmd == "batch") return cmd_batch(rest, io);
  if (cmd == "models") return cmd_models(rest, io);
  if (cmd == "render") return cmd_render(rest, io);
  if (cmd == "evaluate") return cmd_evaluate(rest, io);
  const std::string near =
      closest_name(cmd, {"create", "measure", "train", "batch", "models", "render", "evaluate"});
  throw UsageError("unknown command '" + cmd + "'" +
                   (near.empty() ? "" : " (did you mean " + near + "?)") +
                   "; commands: create, measure, train, batch, models, render, evaluate");
}

}  // namespace

int main_guarded(const std::vector<std::string>& args, Io& io) {
  // The one catch of the program: every error becomes one plain line and an exit code.
  try {
    return dispatch(args, io);
  } catch (...) {
    int code = kExitRuntime;
    std::string message;
    std::string hint;
    try {
      throw;
    } catch (const UsageError& e) {
      code = kExitUsage;
      message = e.what();
      // One pointer to the help, whatever the message already says.
      if (message.find("--help") == std::string::npos) hint = " (see --help)";
    } catch (const ImplausibleInput& e) {
      code = kExitImplausible;
      message = e.what();
      hint = " (use --force to create the avatar anyway)";
    } catch (const InvalidInputError& e) {
      code = kExitImplausible;
      message = e.what();
    } catch (const std::bad_alloc&) {
      message = "out of memory";
    } catch (const std::exception& e) {
      message = e.what();
    } catch (...) {
      message = "unknown error";
    }
    io.err << "caliper: error: " << message << hint << "\n";
    return code;
  }
}

}  // namespace caliper::cli
