/// \file pickle.hpp
/// A restricted unpickler for SMPL-family model files (Python pickle protocols 2 to 5; the opcode
/// semantics of CPython's Lib/pickletools.py). It interprets a fixed set of opcodes and builds only
/// a fixed set of classes, as data, and never executes anything:
/// - numpy arrays: `numpy.core.multiarray._reconstruct` / `numpy._core.multiarray._reconstruct`
///   with `numpy.ndarray` + BUILD state, and `numpy.core.numeric._frombuffer` /
///   `numpy._core.numeric._frombuffer` (protocol 5); numpy scalars (`multiarray.scalar`);
/// - dtypes: `numpy.dtype` (byte order from its BUILD state);
/// - sparse matrices: `scipy.sparse.csc.csc_matrix`, `scipy.sparse._csc.csc_matrix`, and the same
///   for csr (also `*_array` classes);
/// - chumpy `chumpy.ch.Ch` objects (the array is `state['x']`);
/// - `set` / `frozenset` from `__builtin__` or `builtins`; plain dict, list, tuple, str, bytes,
///   int, float, bool, None.
/// Any other GLOBAL / STACK_GLOBAL is refused with an error naming the module and the name.
/// Limits: at most 2^20 objects and 2^20 memo entries, 64 levels of nesting in what is
/// converted, and a budget on the bytes decoded relative to the input's size (PickleLimits):
/// memo references and set(list) never copy, so a small file cannot expand into a large result.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "smpl/npz.hpp"

namespace smpl {

/// A scipy.sparse csc or csr matrix as its three arrays.
struct SparseNpy {
  std::string format;  ///< "csc" (indptr runs over columns) or "csr" (over rows).
  std::size_t rows = 0;
  std::size_t cols = 0;
  NpyArray data;     ///< nnz values.
  NpyArray indices;  ///< nnz row (csc) or column (csr) indices.
  NpyArray indptr;   ///< cols + 1 (csc) or rows + 1 (csr) offsets into data.
};

/// One value of the pickle's top-level dictionary (or one member of an npz).
struct PickleValue {
  enum class Kind {
    kArray,   ///< numpy array, or a chumpy Ch object's array (`array`).
    kSparse,  ///< scipy csc/csr matrix (`sparse`).
    kText,    ///< str / bytes (`text`, raw bytes for Python-2 str).
    kNumber,  ///< int, float or bool (`number`).
    kOther    ///< anything else (dict, list, None, ...): kept only by its type name.
  };
  Kind kind = Kind::kOther;
  NpyArray array;
  SparseNpy sparse;
  std::string text;
  double number = 0.0;
  std::string type_name;  ///< "ndarray", "chumpy.ch.Ch", "csc_matrix", "dict", "str", ...
};

/// The top-level dictionary of a model pickle, by key.
using PickleDict = std::map<std::string, PickleValue>;

/// Resource limits of parse_pickle().
struct PickleLimits {
  /// Bytes the unpickler may make or visit in total, per input byte: strings, array data,
  /// container and memo slots, dictionary scans, and every copy handed out in the result (the
  /// fixed-size record of each object is bounded by the 2^20 object limit instead). A model pickle
  /// needs about 3 per byte (its strings, the arrays made from them, the result's copies).
  std::size_t decoded_per_input_byte = 8;
  /// A fixed allowance on top, so that tiny files load whatever their overheads.
  std::size_t decoded_slack = std::size_t{16} << 20;
};

/// Parses a pickle whose top-level object is a dict with str (or Python-2 str) keys. `context`
/// (usually the file path) starts every error message. Throws ModelError for truncated or
/// malformed data, unsupported opcodes and protocols, refused classes (naming them), bad array
/// states, limits exceeded (the decoded-bytes budget says "decoding needs more than N bytes").
/// Never crashes, never executes anything.
PickleDict parse_pickle(const std::uint8_t* bytes, std::size_t size, const std::string& context,
                        const PickleLimits& limits = {});

/// Reads and parses a pickle file; errors name `path`.
PickleDict read_pickle(const std::string& path);

/// `text` made safe to print: every byte outside printable ASCII (control characters, terminal
/// escapes, DEL, non-ASCII) is written as \xNN and a backslash as \\. For names read from a
/// file (keys, class names) before they go into an error message.
std::string printable(const std::string& text);

/// True when `bytes` is a Git LFS pointer file ("version https://git-lfs.github.com/spec/v1"
/// and an oid) instead of the real file, which `git lfs pull` fetches.
bool is_git_lfs_pointer(const std::uint8_t* bytes, std::size_t size);
/// The error text for a Git LFS pointer given as a model ("... run `git lfs pull` ...").
extern const char* const kLfsPointerMessage;

}  // namespace smpl
