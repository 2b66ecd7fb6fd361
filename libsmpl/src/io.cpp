// Loading SMPL-family model files (.npz, .pkl) into a BodyModel and saving the project's own .npz
// (key layout: docs/file-formats.md; SMPL's keys: Loper et al. 2015 and its released files).
#include "smpl/io.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <limits>

#include "smpl/npz.hpp"
#include "smpl/pickle.hpp"
#include "smpl/text.hpp"

namespace smpl {
namespace {

// `what` may carry keys, dtypes and type names read from the file: escaped (pickle.hpp).
[[noreturn]] void fail_printable(const std::string& context, const std::string& what) {
  throw ModelError(context + ": " + printable(what));
}

constexpr std::uint64_t kUint32Minus1 = 0xFFFFFFFFull;

/// The file's values by key with the helpers that check and convert them. The values of an
/// .npz are read from the archive when first asked for, so members the model does not use are
/// never inflated.
class Source {
 public:
  Source(PickleDict values, std::string context)
      : values_(std::move(values)), context_(std::move(context)) {}
  Source(const NpzReader& npz, std::string context) : npz_(&npz), context_(std::move(context)) {}

  bool has(const std::string& key) const {
    return values_.count(key) != 0 || (npz_ && npz_->has(key));
  }

  const PickleValue& get(const std::string& key) const {
    const auto it = values_.find(key);
    if (it != values_.end()) return it->second;
    if (npz_ && npz_->has(key)) {
      PickleValue v;
      v.kind = PickleValue::Kind::kArray;
      v.type_name = "ndarray";
      v.array = npz_->array(key);
      return values_.emplace(key, std::move(v)).first->second;
    }
    std::string keys;
    for (const std::string& k : npz_ ? npz_->keys() : key_list()) {
      keys += (keys.empty() ? "" : ", ") + k;
    }
    fail_printable(context_, "missing key '" + key + "' (the file has: " + keys + ")");
  }

  const NpyArray& array(const std::string& key) const {
    const PickleValue& v = get(key);
    if (v.kind != PickleValue::Kind::kArray) {
      fail_printable(context_, "'" + key + "' is a " + v.type_name + ", expected a numeric array");
    }
    if (v.array.kind() == 'O')
      fail_printable(context_, "'" + key + "' " + npy_object_array_advice());
    if (!v.array.is_numeric()) {
      fail_printable(context_,
                     "'" + key + "' has dtype " + v.array.dtype + ", expected a numeric array");
    }
    return v.array;
  }

  std::vector<double> doubles(const std::string& key, const NpyArray& a) const {
    try {
      return a.to_double();
    } catch (const ModelError& e) {
      fail_printable(context_, "'" + key + "': " + e.what());
    }
  }

  std::vector<std::int64_t> ints(const std::string& key, const NpyArray& a) const {
    try {
      return a.to_int64();
    } catch (const ModelError& e) {
      fail_printable(context_, "'" + key + "': " + e.what());
    }
  }

  std::vector<std::string> strings(const std::string& key) const {
    const PickleValue& v = get(key);
    if (v.kind == PickleValue::Kind::kText) return {v.text};
    if (v.kind != PickleValue::Kind::kArray || (v.array.kind() != 'U' && v.array.kind() != 'S')) {
      fail_printable(context_, "'" + key + "' is not a text array");
    }
    try {
      return v.array.to_strings();
    } catch (const ModelError& e) {
      fail_printable(context_, "'" + key + "': " + e.what());
    }
  }

  [[noreturn]] void bad_shape(const std::string& key, const NpyArray& a,
                              const std::string& expected) const {
    fail_printable(context_,
                   "'" + key + "' has shape " + a.shape_string() + ", expected " + expected);
  }

  const std::string& context() const { return context_; }

 private:
  std::vector<std::string> key_list() const {
    std::vector<std::string> out;
    for (const auto& kv : values_) out.push_back(kv.first);
    return out;
  }

  mutable PickleDict values_;  // an .npz's members are added when first read
  const NpzReader* npz_ = nullptr;
  std::string context_;
};

std::string shape_text(std::initializer_list<std::string> dims) {
  std::string s = "(";
  for (const std::string& d : dims) s += (s.size() > 1 ? ", " : "") + d;
  return s + ")";
}

// m (rows x m.cols(), column-major) from the first m.cols() columns of a C-order rows x stride
// array of T at p. In blocks of rows, so each column is written in runs of consecutive doubles
// (row by row, every write of a 66 MB posedirs would land on another page).
template <typename T>
void transpose_rows(const std::uint8_t* p, Eigen::Index rows, Eigen::Index stride,
                    Eigen::MatrixXd& m) {
  constexpr Eigen::Index kBlock = 64;
  for (Eigen::Index r0 = 0; r0 < rows; r0 += kBlock) {
    const Eigen::Index r1 = std::min(rows, r0 + kBlock);
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      double* column = m.col(c).data();
      for (Eigen::Index r = r0; r < r1; ++r) {
        T v;
        std::memcpy(&v, p + static_cast<std::size_t>(r * stride + c) * sizeof(T), sizeof(T));
        column[r] = static_cast<double>(v);
      }
    }
  }
}

// Reads a (V, 3, N) or (3V, N) array into a 3V x n matrix (first n columns).
Eigen::MatrixXd blend_shapes(const Source& src, const std::string& key, Eigen::Index V, int keep,
                             const char* what) {
  const NpyArray& a = src.array(key);
  std::size_t n_cols = 0;
  if (a.shape.size() == 3 && a.shape[0] == static_cast<std::size_t>(V) && a.shape[1] == 3) {
    n_cols = a.shape[2];
  } else if (a.shape.size() == 2 && a.shape[0] == static_cast<std::size_t>(3 * V)) {
    n_cols = a.shape[1];
  } else {
    src.bad_shape(key, a, shape_text({std::to_string(V), "3", what}));
  }
  const auto n = keep < 0 ? static_cast<Eigen::Index>(n_cols) : keep;
  if (n > static_cast<Eigen::Index>(n_cols)) {
    fail_printable(src.context(), "'" + key + "' has " + std::to_string(n_cols) +
                                      " components but " + std::to_string(n) +
                                      " were requested (LoadOptions::num_betas)");
  }
  Eigen::MatrixXd m(3 * V, n);
  const auto stride = static_cast<Eigen::Index>(n_cols);
  // The common cases (SMPL files: float64; the project's own: float32, see model_arrays): straight
  // from the file's bytes.
  if (a.dtype == "<f8" && !a.fortran_order) {
    transpose_rows<double>(a.data.data(), 3 * V, stride, m);
    return m;
  }
  if (a.dtype == "<f4" && !a.fortran_order) {
    transpose_rows<float>(a.data.data(), 3 * V, stride, m);
    return m;
  }
  const std::vector<double> d = src.doubles(key, a);
  for (Eigen::Index r = 0; r < 3 * V; ++r) {
    for (Eigen::Index c = 0; c < n; ++c) m(r, c) = d[static_cast<std::size_t>(r * stride + c)];
  }
  return m;
}

// A dense (rows x cols) array or a csc/csr matrix as a row-major sparse matrix; dense exact zeros
// are dropped.
SparseMatrix sparse_matrix(const Source& src, const std::string& key, Eigen::Index rows,
                           Eigen::Index cols) {
  const PickleValue& v = src.get(key);
  const std::string expected = shape_text({std::to_string(rows), std::to_string(cols)});
  std::vector<Eigen::Triplet<double>> triplets;
  if (v.kind == PickleValue::Kind::kSparse) {
    const SparseNpy& s = v.sparse;
    if (s.rows != static_cast<std::size_t>(rows) || s.cols != static_cast<std::size_t>(cols)) {
      fail_printable(src.context(), "'" + key + "' is a sparse matrix of shape (" +
                                        std::to_string(s.rows) + ", " + std::to_string(s.cols) +
                                        "), expected " + expected);
    }
    const bool csc = s.format == "csc";
    const std::size_t outer = csc ? s.cols : s.rows;
    const std::size_t inner = csc ? s.rows : s.cols;
    const std::vector<double> data = src.doubles(key + ".data", s.data);
    const std::vector<std::int64_t> indices = src.ints(key + ".indices", s.indices);
    const std::vector<std::int64_t> indptr = src.ints(key + ".indptr", s.indptr);
    if (indptr.size() != outer + 1 || indices.size() != data.size() || indptr[0] != 0 ||
        static_cast<std::size_t>(indptr.back()) != data.size()) {
      fail_printable(src.context(), "'" + key + "' is a corrupt " + s.format +
                                        " matrix (indptr, indices and data sizes disagree)");
    }
    for (std::size_t o = 0; o < outer; ++o) {
      if (indptr[o + 1] < indptr[o]) {
        fail_printable(src.context(),
                       "'" + key + "' is a corrupt sparse matrix (indptr decreases)");
      }
    }
    for (std::size_t o = 0; o < outer; ++o) {
      for (auto j = indptr[o]; j < indptr[o + 1]; ++j) {
        const auto i = indices[static_cast<std::size_t>(j)];
        if (i < 0 || static_cast<std::size_t>(i) >= inner) {
          fail_printable(src.context(),
                         "'" + key + "' has an index out of range (" + std::to_string(i) + ")");
        }
        const auto oo = static_cast<Eigen::Index>(o);
        const auto ii = static_cast<Eigen::Index>(i);
        triplets.emplace_back(csc ? ii : oo, csc ? oo : ii, data[static_cast<std::size_t>(j)]);
      }
    }
  } else {
    const NpyArray& a = src.array(key);
    if (a.shape.size() != 2 || a.shape[0] != static_cast<std::size_t>(rows) ||
        a.shape[1] != static_cast<std::size_t>(cols)) {
      src.bad_shape(key, a, expected);
    }
    const std::vector<double> d = src.doubles(key, a);
    for (Eigen::Index r = 0; r < rows; ++r) {
      for (Eigen::Index c = 0; c < cols; ++c) {
        const double x = d[static_cast<std::size_t>(r * cols + c)];
        if (x != 0.0) triplets.emplace_back(r, c, x);  // NaN is kept: validate() reports it
      }
    }
  }
  SparseMatrix m(rows, cols);
  m.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

std::vector<int> int_vector(const Source& src, const std::string& key, const NpyArray& a,
                            std::int64_t lo, std::int64_t hi) {
  std::vector<int> out;
  for (std::int64_t x : src.ints(key, a)) {
    if (x < lo || x > hi) {
      fail_printable(src.context(), "'" + key + "' holds " + std::to_string(x) + ", outside [" +
                                        std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    out.push_back(static_cast<int>(x));
  }
  return out;
}

std::string single_string(const Source& src, const std::string& key) {
  const std::vector<std::string> s = src.strings(key);
  if (s.size() != 1) fail_printable(src.context(), "'" + key + "' must hold exactly one string");
  return s[0];
}

// The parents from kintree_table (K columns): row 0 parents (root: -1 or 4294967295), row 1
// joint ids 0..K-1.
std::vector<int> read_parents(const Source& src, const NpyArray& kt, Eigen::Index K) {
  const std::string& ctx = src.context();
  std::vector<int> parents;
  const std::vector<std::int64_t> ktv = src.ints("kintree_table", kt);
  for (Eigen::Index k = 0; k < K; ++k) {
    const std::int64_t id = ktv[static_cast<std::size_t>(K + k)];
    if (id != k) {
      fail_printable(ctx, "'kintree_table' row 1 must list the joints 0.." + std::to_string(K - 1) +
                              " in order; column " + std::to_string(k) + " holds " +
                              std::to_string(id));
    }
    std::int64_t p = ktv[static_cast<std::size_t>(k)];
    if (k == 0 && (p == -1 || p == static_cast<std::int64_t>(kUint32Minus1))) p = -1;
    if (p < -1 || p >= K) {
      fail_printable(ctx, "'kintree_table' gives joint " + std::to_string(k) + " the parent " +
                              std::to_string(p) + " (the model has " + std::to_string(K) +
                              " joints)");
    }
    parents.push_back(static_cast<int>(p));
  }
  return parents;
}

// A (N, kCols) array of points (vertices, texture coordinates), N >= 1 and N * kCols within int
// range; `expected` names the shape for the error, e.g. "(V, 3)".
template <int kCols>
Eigen::Matrix<double, Eigen::Dynamic, kCols, Eigen::RowMajor> point_rows(const Source& src,
                                                                         const std::string& key,
                                                                         const char* expected) {
  const NpyArray& a = src.array(key);
  if (a.shape.size() != 2 || a.shape[1] != static_cast<std::size_t>(kCols) || a.shape[0] == 0 ||
      a.shape[0] > static_cast<std::size_t>(std::numeric_limits<int>::max() / kCols)) {
    src.bad_shape(key, a, expected);
  }
  const std::vector<double> d = src.doubles(key, a);
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, kCols, Eigen::RowMajor>>(
      d.data(), static_cast<Eigen::Index>(a.shape[0]), kCols);
}

// The texture coordinates vt (T, 2) and their faces ft (F, 3), both or neither.
void read_uvs(const Source& src, BodyModel& m) {
  m.uvs = point_rows<2>(src, "vt", "(T, 2)");
  const Eigen::Index T = m.uvs.rows();
  const NpyArray& ft = src.array("ft");
  if (ft.shape.size() != 2 || ft.shape[1] != 3 ||
      ft.shape[0] != static_cast<std::size_t>(m.faces.rows())) {
    src.bad_shape("ft", ft, "(" + std::to_string(m.faces.rows()) + ", 3)");
  }
  const std::vector<int> ftv = int_vector(src, "ft", ft, 0, static_cast<int>(T) - 1);
  m.uv_faces = Eigen::Map<const Faces>(ftv.data(), m.faces.rows(), 3);
}

// The landmarks: landmark_names, landmark_offsets (names + 1, from 0) into landmark_vertices.
void read_landmarks(const Source& src, Eigen::Index V, BodyModel& m) {
  const std::string& ctx = src.context();
  const std::vector<std::string> names = src.strings("landmark_names");
  const NpyArray& off = src.array("landmark_offsets");
  const NpyArray& ids = src.array("landmark_vertices");
  const std::vector<std::int64_t> o = src.ints("landmark_offsets", off);
  const std::vector<int> vids = int_vector(src, "landmark_vertices", ids, 0, V - 1);
  if (o.size() != names.size() + 1 || o[0] != 0 ||
      o.back() != static_cast<std::int64_t>(vids.size())) {
    fail_printable(ctx, "'landmark_offsets' must hold " + std::to_string(names.size() + 1) +
                            " offsets from 0 to the length of 'landmark_vertices'");
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (o[i + 1] < o[i]) fail_printable(ctx, "'landmark_offsets' must not decrease");
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    m.landmarks[names[i]].assign(vids.begin() + o[i], vids.begin() + o[i + 1]);
  }
}

// Metadata: the file's meta_* keys, else guesses from the file name.
void read_meta(const Source& src, BodyModel& m) {
  const std::string& ctx = src.context();
  std::string base =
      ctx.substr(ctx.find_last_of('/') == std::string::npos ? 0 : ctx.find_last_of('/') + 1);
  m.meta.name = src.has("meta_name") ? single_string(src, "meta_name")
                                     : base.substr(0, base.find_last_of('.'));
  if (src.has("meta_gender")) {
    m.meta.gender = single_string(src, "meta_gender");
  } else {
    const std::string b = to_lower(base);
    if (b.find("female") != std::string::npos || b.find("_f_") != std::string::npos) {
      m.meta.gender = "female";
    } else if (b.find("male") != std::string::npos || b.find("_m_") != std::string::npos) {
      m.meta.gender = "male";
    } else if (b.find("neutral") != std::string::npos) {
      m.meta.gender = "neutral";
    }
  }
  m.meta.source = src.has("meta_source") ? single_string(src, "meta_source") : ctx;
  if (src.has("meta_extra_keys") || src.has("meta_extra_values")) {
    const std::vector<std::string> keys = src.strings("meta_extra_keys");
    const std::vector<std::string> vals = src.strings("meta_extra_values");
    if (keys.size() != vals.size()) {
      fail_printable(ctx, "'meta_extra_keys' and 'meta_extra_values' differ in length");
    }
    for (std::size_t i = 0; i < keys.size(); ++i) m.meta.extra[keys[i]] = vals[i];
  }
}

BodyModel build_model(const Source& src, const LoadOptions& options) {
  BodyModel m;
  const std::string& ctx = src.context();
  // v_template (V, 3).
  m.v_template = point_rows<3>(src, "v_template", "(V, 3)");
  const Eigen::Index V = m.v_template.rows();
  // f (F, 3).
  const NpyArray& f = src.array("f");
  if (f.shape.size() != 2 || f.shape[1] != 3) src.bad_shape("f", f, "(F, 3)");
  const std::vector<int> fv = int_vector(src, "f", f, 0, V - 1);
  m.faces = Eigen::Map<const Faces>(fv.data(), static_cast<Eigen::Index>(f.shape[0]), 3);
  // kintree_table (2, K): row 0 parents (root: -1 or 4294967295), row 1 joint ids 0..K-1.
  const NpyArray& kt = src.array("kintree_table");
  if (kt.shape.size() != 2 || kt.shape[0] != 2 || kt.shape[1] == 0 || kt.shape[1] > 100000) {
    src.bad_shape("kintree_table", kt, "(2, K)");
  }
  const auto K = static_cast<Eigen::Index>(kt.shape[1]);
  m.parents = read_parents(src, kt, K);
  // Blend shapes.
  m.shapedirs = blend_shapes(src, "shapedirs", V, options.num_betas, "B");
  if (options.load_pose_blend_shapes && src.has("posedirs")) {
    m.posedirs = blend_shapes(src, "posedirs", V, -1, "P");
  } else {
    m.posedirs.resize(3 * V, 0);
  }
  m.j_regressor = sparse_matrix(src, "J_regressor", K, V);
  m.weights = sparse_matrix(src, "weights", V, K);
  // Optional keys.
  if (src.has("vert_sym_idxs")) {
    const NpyArray& a = src.array("vert_sym_idxs");
    if (a.shape.size() != 1 || a.shape[0] != static_cast<std::size_t>(V)) {
      src.bad_shape("vert_sym_idxs", a, "(" + std::to_string(V) + ",)");
    }
    m.mirror = int_vector(src, "vert_sym_idxs", a, 0, V - 1);
  }
  if (src.has("vt") || src.has("ft")) read_uvs(src, m);
  if (src.has("joint_names")) {
    m.joint_names = src.strings("joint_names");
  } else if (K == 24) {
    m.joint_names = smpl_joint_names();
  }
  if (src.has("landmark_names") || src.has("landmark_offsets") || src.has("landmark_vertices")) {
    read_landmarks(src, V, m);
  }
  read_meta(src, m);
  validate(m, ctx);
  return m;
}

bool starts_with(const std::uint8_t* bytes, std::size_t size, const char* magic, std::size_t n) {
  return size >= n && std::memcmp(bytes, magic, n) == 0;
}

}  // namespace

BodyModel load_model_from_memory(const std::uint8_t* bytes, std::size_t size,
                                 const std::string& context, const LoadOptions& options) {
  if (is_git_lfs_pointer(bytes, size)) fail_printable(context, kLfsPointerMessage);
  if (starts_with(bytes, size, "PK\x03\x04", 4) || starts_with(bytes, size, "PK\x05\x06", 4)) {
    const NpzReader npz(bytes, size, context);
    return build_model(Source(npz, context), options);
  }
  if (size >= 2 && bytes[0] == 0x80) {
    return build_model(Source(parse_pickle(bytes, size, context), context), options);
  }
  if (size == 0) fail_printable(context, "the file is empty");
  fail_printable(context, "neither an .npz (zip) nor a .pkl (pickle protocol 2-5) file");
}

BodyModel load_model(const std::string& path, const LoadOptions& options) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return load_model_from_memory(bytes.data(), bytes.size(), path, options);
}

namespace {

// A 3V x N blend-shape matrix as numpy's (V, 3, N): float32 when every value is a float32 (no
// value changes; the open models are made so, which halves their largest arrays), else float64.
NpyArray blend_shape_npy(const Eigen::MatrixXd& m, std::size_t V) {
  const Eigen::MatrixXf single = m.cast<float>();
  NpyArray a = (single.cast<double>().array() == m.array()).all() ? make_npy(single) : make_npy(m);
  a.shape = {V, 3, static_cast<std::size_t>(m.cols())};
  return a;
}

}  // namespace

NpzArchive model_arrays(const BodyModel& m) {
  NpzArchive out;
  const auto V = static_cast<std::size_t>(m.num_vertices());
  const auto K = static_cast<std::size_t>(m.num_joints());
  out["v_template"] = make_npy(m.v_template);
  const Eigen::Matrix<std::uint32_t, Eigen::Dynamic, 3, Eigen::RowMajor> f =
      m.faces.cast<std::uint32_t>();
  out["f"] = make_npy(f);
  out["shapedirs"] = blend_shape_npy(m.shapedirs, V);
  if (m.has_pose_blend_shapes()) out["posedirs"] = blend_shape_npy(m.posedirs, V);
  out["J_regressor"] = make_npy(Eigen::MatrixXd(m.j_regressor));
  out["weights"] = make_npy(Eigen::MatrixXd(m.weights));
  const Joints joints = m.j_regressor * m.v_template;
  out["J"] = make_npy(joints);
  std::vector<std::uint32_t> kt(2 * K);
  for (std::size_t k = 0; k < K; ++k) {
    kt[k] = m.parents[k] < 0 ? static_cast<std::uint32_t>(kUint32Minus1)
                             : static_cast<std::uint32_t>(m.parents[k]);
    kt[K + k] = static_cast<std::uint32_t>(k);
  }
  out["kintree_table"] = make_npy(kt, {2, K});
  if (!m.mirror.empty()) {
    out["vert_sym_idxs"] =
        make_npy(std::vector<std::int64_t>(m.mirror.begin(), m.mirror.end()), {m.mirror.size()});
  }
  if (m.has_uvs()) {
    out["vt"] = make_npy(m.uvs);
    const Eigen::Matrix<std::uint32_t, Eigen::Dynamic, 3, Eigen::RowMajor> ft =
        m.uv_faces.cast<std::uint32_t>();
    out["ft"] = make_npy(ft);
  }
  if (!m.joint_names.empty()) out["joint_names"] = make_npy_strings(m.joint_names);
  if (!m.landmarks.empty()) {
    std::vector<std::string> names;
    std::vector<std::int64_t> offsets{0};
    std::vector<std::int64_t> ids;
    for (const auto& [name, vids] : m.landmarks) {
      names.push_back(name);
      ids.insert(ids.end(), vids.begin(), vids.end());
      offsets.push_back(static_cast<std::int64_t>(ids.size()));
    }
    out["landmark_names"] = make_npy_strings(names);
    out["landmark_offsets"] = make_npy(offsets, {offsets.size()});
    out["landmark_vertices"] = make_npy(ids, {ids.size()});
  }
  out["meta_name"] = make_npy_strings({m.meta.name}, true);
  out["meta_gender"] = make_npy_strings({m.meta.gender}, true);
  out["meta_source"] = make_npy_strings({m.meta.source}, true);
  if (!m.meta.extra.empty()) {
    std::vector<std::string> keys;
    std::vector<std::string> vals;
    for (const auto& [k, v] : m.meta.extra) {
      keys.push_back(k);
      vals.push_back(v);
    }
    out["meta_extra_keys"] = make_npy_strings(keys);
    out["meta_extra_values"] = make_npy_strings(vals);
  }
  return out;
}

void save_model(const BodyModel& model, const std::string& path, const SaveOptions& options) {
  validate(model, "save_model(" + path + ")");
  write_npz(path, model_arrays(model), options.compress);
}

}  // namespace smpl
