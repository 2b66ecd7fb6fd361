// The `caliper` command: subcommand dispatch, top-level help, --version, and main_guarded(),
// the one place where exceptions become messages and exit codes.
#include <exception>
#include <iostream>
#include <new>

#include "app/cli_style.hpp"
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

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>&, Io&);
};

const Command kCommands[] = {
    {"create", "measurements in (with units), an avatar (.glb/.gltf/.obj/.ply) and a report out",
     cmd_create},
    {"measure", "all measurements, volume and weight of an avatar file or of a model + betas",
     cmd_measure},
    {"train", "fit and report the regressors R2, R4, R5, R6 and noise-aware for a model",
     cmd_train},
    {"batch", "a CSV of people (or ANSUR II files) in, a results CSV and avatars out", cmd_batch},
    {"models", "list the open default models and describe model files", cmd_models},
    {"render", "PNG pictures of an avatar or a model (front, side, three-quarter, turntable)",
     cmd_render},
    {"evaluate", "the evaluation studies of docs/evaluation.md (table1, simulation, ansur, nhanes)",
     cmd_evaluate},
};

const app::HelpText kTopHelp{
    {"caliper <command> [options]"},
    "caliper: metrically accurate avatars from body measurements (The Virtual Caliper);\n"
    "`caliper <command> --help` for a command's options",
    "example:\n"
    "  caliper create --sex female --height 168cm --weight 62kg --out avatar.glb --png avatar.png\n"
    "\n"
    "exit codes: 0 ok, 1 runtime or input-file error, 2 usage error, 3 implausible input refused\n"
    "environment: CALIPER_ASSETS=<folder with models/caliper-{female,male,neutral}.npz>"};

int dispatch(const std::vector<std::string>& args, Io& io) {
  // The commands are CLI11 subcommands that take the rest of the line as it is: each command
  // parses its own options (parse_args), so that `caliper create --help` is create's help.
  CLI::App top("", "caliper");
  app::apply_style(top, kTopHelp);
  bool version = false;
  app::add_flag(top, "--version", version, "print the version");
  for (const Command& c : kCommands) {
    CLI::App* sub = top.add_subcommand(c.name, c.summary);
    sub->group("commands")->prefix_command()->set_help_flag();
  }
  app::CommandLine line;
  try {
    line = app::parse_command_line(top, args);
  } catch (const app::CommandLineError& e) {
    throw UsageError(e.what());
  }
  for (const Command& c : kCommands) {
    if (CLI::App* sub = top.get_subcommand(c.name); sub->parsed())
      return c.run(sub->remaining(), io);
  }
  if (line.help || (line.positional.size() == 1 && line.positional[0] == "help")) {
    io.out << top.help();
    return kExitOk;
  }
  if (version || (line.positional.size() == 1 && line.positional[0] == "version")) {
    io.out << version_string() << "\n";
    return kExitOk;
  }
  if (line.positional.empty()) {
    io.err << top.help();
    return kExitUsage;
  }
  const std::string& cmd = line.positional[0];
  std::vector<std::string> names;
  for (const Command& c : kCommands) names.emplace_back(c.name);
  const std::string near = closest_name(cmd, names);
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
      if (e.forceable()) hint = " (use --force to create the avatar anyway)";
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
