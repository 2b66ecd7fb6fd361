// Restricted unpickler (placeholder until the full reader lands).
#include "smpl/pickle.hpp"

namespace smpl {

PickleDict parse_pickle(const std::uint8_t*, std::size_t, const std::string& context) {
  throw ModelError(context + ": .pkl files are not supported yet");
}

PickleDict read_pickle(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_pickle(bytes.data(), bytes.size(), path);
}

}  // namespace smpl
