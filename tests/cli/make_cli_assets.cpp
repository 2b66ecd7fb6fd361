// Writes <dir>/models/caliper-{female,male,neutral}.npz test models (cli_fixture.hpp) for the
// tests that run the built `caliper` binary with CALIPER_ASSETS=<dir>; --full-size writes
// SMPL-sized (6,890-vertex) versions for the studies of docs/evaluation.md.
#include <filesystem>
#include <iostream>

#include "cli_fixture.hpp"
#include "smpl/io.hpp"

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 3 && std::string(argv[2]) == "--full-size")) {
    std::cerr << "usage: make_cli_assets DIR [--full-size]\n";
    return 2;
  }
  const bool full = argc == 3;
  const std::filesystem::path dir = std::filesystem::path(argv[1]) / "models";
  std::filesystem::create_directories(dir);
  for (const char* g : {"female", "male", "neutral"}) {
    smpl::save_model(caliper::test::cli_test_model(g, 7, full),
                     (dir / ("caliper-" + std::string(g) + ".npz")).string());
  }
  std::cout << "wrote test models to " << dir.string() << "\n";
  return 0;
}
