// glTF 2.0 export and import of a skinned SMPL-family avatar (Khronos glTF 2.0 specification,
// sections 3.7 "Geometry" (meshes, morph targets, skins) and 4.4 "GLB file format"), and VRM 1.0
// export (VRM Consortium, VRMC_vrm 1.0: humanoid.md, meta.md, firstPerson.md, tpose.md).
// This is the only translation unit of the project that includes tiny_gltf.h; Debian's
// libtinygltf.so is linked (built with its default stb image support, which the header's
// declarations match when no TINYGLTF_NO_* macro is defined here).
//
// Sections: 1. buffer building helpers  2. avatar -> tinygltf::Model  3. write_gltf / glb_bytes
//           4. VRM  5. reading limits  6. accessor reading  7. read_gltf
#include "smpl/gltf.hpp"
#include "smpl/atomic_file.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include <tiny_gltf.h>

#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/npz.hpp"
#include "smpl/text.hpp"

#include <Eigen/Geometry>

namespace smpl {
namespace {

constexpr int kMaxInfluences = 4;  // glTF JOINTS_0/WEIGHTS_0 hold 4 influences per set
const char* const kGenerator = "The Virtual Caliper (libsmpl glTF export)";

// ---------------------------------------------------------------------------------------------
// 1. Buffer building helpers
// ---------------------------------------------------------------------------------------------

// Appends a tightly packed bufferView (4-byte aligned, as accessors need) and returns its index.
int add_view(tinygltf::Model& g, const void* data, size_t bytes, int target) {
  auto& buf = g.buffers[0].data;
  const size_t offset = (buf.size() + 3) & ~size_t{3};
  buf.resize(offset, 0);  // padding only: the data is appended, not zeroed and then copied
  const auto* p = static_cast<const unsigned char*>(data);
  if (bytes > 0) buf.insert(buf.end(), p, p + bytes);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = bytes;
  view.target = target;
  g.bufferViews.push_back(std::move(view));
  return static_cast<int>(g.bufferViews.size() - 1);
}

int add_accessor(tinygltf::Model& g, int view, int component, size_t count, int type,
                 std::vector<double> min = {}, std::vector<double> max = {}) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.byteOffset = 0;
  a.componentType = component;
  a.count = count;
  a.type = type;
  a.minValues = std::move(min);
  a.maxValues = std::move(max);
  g.accessors.push_back(std::move(a));
  return static_cast<int>(g.accessors.size() - 1);
}

// A VEC3 float accessor with the min/max that POSITION accessors require.
int add_vec3(tinygltf::Model& g, const std::vector<float>& xyz, int target, bool bounds) {
  const size_t n = xyz.size() / 3;
  std::vector<double> lo, hi;
  if (bounds) {
    lo.assign(3, HUGE_VAL);
    hi.assign(3, -HUGE_VAL);
    for (size_t i = 0; i < n; ++i) {
      for (size_t c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], static_cast<double>(xyz[3 * i + c]));
        hi[c] = std::max(hi[c], static_cast<double>(xyz[3 * i + c]));
      }
    }
    if (n == 0) lo = hi = {0.0, 0.0, 0.0};
  }
  const int view = add_view(g, xyz.data(), xyz.size() * sizeof(float), target);
  return add_accessor(g, view, TINYGLTF_COMPONENT_TYPE_FLOAT, n, TINYGLTF_TYPE_VEC3, lo, hi);
}

std::vector<float> to_float(const Vertices& v) {
  std::vector<float> out(static_cast<size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    out[static_cast<size_t>(i)] = static_cast<float>(v.data()[i]);
  return out;
}

// Rows `source` of a row-major array with `width` values per row: the per-vertex attribute of
// every vertex of a seam split (SeamSplit::source).
template <typename T>
std::vector<T> gather(const std::vector<T>& in, size_t width, const std::vector<int>& source) {
  std::vector<T> out(width * source.size());
  for (size_t i = 0; i < source.size(); ++i) {
    std::copy_n(in.begin() + static_cast<std::ptrdiff_t>(width * static_cast<size_t>(source[i])),
                width, out.begin() + static_cast<std::ptrdiff_t>(width * i));
  }
  return out;
}

// The 4 largest skinning weights of every vertex, renormalised so that their float sum is 1.
// Unused slots get joint 0 and weight 0.
void top_influences(const SparseMatrix& weights, std::vector<std::uint16_t>& joints,
                    std::vector<float>& w) {
  const auto V = static_cast<size_t>(weights.rows());
  joints.assign(kMaxInfluences * V, 0);
  w.assign(kMaxInfluences * V, 0.0f);
  std::vector<std::pair<double, int>> row;
  for (Eigen::Index v = 0; v < weights.rows(); ++v) {
    row.clear();
    for (SparseMatrix::InnerIterator it(weights, v); it; ++it) {
      if (it.value() > 0.0) row.emplace_back(it.value(), static_cast<int>(it.col()));
    }
    const size_t n = std::min<size_t>(kMaxInfluences, row.size());
    std::partial_sort(row.begin(), row.begin() + static_cast<std::ptrdiff_t>(n), row.end(),
                      [](const auto& a, const auto& b) {
                        return a.first > b.first || (a.first == b.first && a.second < b.second);
                      });
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) sum += row[i].first;
    const size_t base = kMaxInfluences * static_cast<size_t>(v);
    if (n == 0 || !(sum > 0.0)) {
      w[base] = 1.0f;  // a vertex without influence follows the root
      continue;
    }
    float fsum = 0.0f;
    for (size_t i = 0; i < n; ++i) {
      joints[base + i] = static_cast<std::uint16_t>(row[i].second);
      w[base + i] = static_cast<float>(row[i].first / sum);
      fsum += w[base + i];
    }
    w[base] += 1.0f - fsum;  // put the float rounding on the largest weight
  }
}

// ---------------------------------------------------------------------------------------------
// 2. Avatar -> tinygltf::Model
// ---------------------------------------------------------------------------------------------

// Column-major 4 x 4 quaternion of a rotation matrix, as glTF's node.rotation (x, y, z, w).
std::vector<double> gltf_quaternion(const Eigen::Matrix3d& r) {
  const Eigen::Quaterniond q(r);
  return {q.x(), q.y(), q.z(), q.w()};
}

// A VEC3 float accessor of one value per model vertex, gathered to the split vertices when the
// model is split at its texture seams (`split` not null).
int add_vertex_vec3(tinygltf::Model& g, const SeamSplit* split, const std::vector<float>& xyz,
                    bool bounds) {
  return split ? add_vec3(g, gather(xyz, 3, split->source), TINYGLTF_TARGET_ARRAY_BUFFER, bounds)
               : add_vec3(g, xyz, TINYGLTF_TARGET_ARRAY_BUFFER, bounds);
}

// TEXCOORD_0 of the split vertices. glTF's texture origin is the top left corner: v = 1 - the
// model's (OBJ's) v.
int add_texcoords(tinygltf::Model& g, const SeamSplit& split) {
  const size_t out_v = split.source.size();
  std::vector<float> uv(2 * out_v);
  for (size_t i = 0; i < out_v; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    uv[2 * i] = static_cast<float>(split.uvs(r, 0));
    uv[2 * i + 1] = static_cast<float>(1.0 - split.uvs(r, 1));
  }
  return add_accessor(
      g, add_view(g, uv.data(), uv.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
      TINYGLTF_COMPONENT_TYPE_FLOAT, out_v, TINYGLTF_TYPE_VEC2);
}

// The triangles' indices: unsigned short when every index is below 65535 (glTF reserves each
// type's largest value), as for the open models' ~12,000-vertex meshes: half the bytes of
// unsigned int, which larger meshes get.
int add_indices(tinygltf::Model& g, const Faces& faces) {
  const int lo = faces.size() ? faces.minCoeff() : 0, hi = faces.size() ? faces.maxCoeff() : 0;
  const auto n = static_cast<size_t>(faces.size());
  int view = -1, component = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  if (hi < 65535) {
    std::vector<std::uint16_t> indices(n);
    for (size_t i = 0; i < n; ++i) indices[i] = static_cast<std::uint16_t>(faces.data()[i]);
    view = add_view(g, indices.data(), n * sizeof(std::uint16_t),
                    TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    component = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  } else {
    std::vector<std::uint32_t> indices(n);
    for (size_t i = 0; i < n; ++i) indices[i] = static_cast<std::uint32_t>(faces.data()[i]);
    view = add_view(g, indices.data(), n * sizeof(std::uint32_t),
                    TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  return add_accessor(g, view, component, n, TINYGLTF_TYPE_SCALAR, {static_cast<double>(lo)},
                      {static_cast<double>(hi)});
}

// JOINTS_0 and WEIGHTS_0 (the model's own four strongest influences unless options.skin_weights
// gives them), gathered to the split vertices; returns their accessors.
std::pair<int, int> add_skin_attributes(tinygltf::Model& g, const BodyModel& model,
                                        const GltfOptions& options, const SeamSplit* split,
                                        size_t out_v, const std::string& context) {
  const auto V = static_cast<size_t>(model.num_vertices());
  GltfSkinWeights own;
  const GltfSkinWeights* skin_w = options.skin_weights;
  if (!skin_w) {
    top_influences(model.weights, own.joints, own.weights);
    skin_w = &own;
  } else if (skin_w->joints.size() != kMaxInfluences * V ||
             skin_w->weights.size() != kMaxInfluences * V) {
    throw std::invalid_argument(context + ": GltfOptions::skin_weights has " +
                                std::to_string(skin_w->joints.size()) + " joints and " +
                                std::to_string(skin_w->weights.size()) + " weights, expected 4 x " +
                                std::to_string(V) + " (use gltf_skin_weights of this model)");
  }
  std::vector<std::uint16_t> split_ids;
  std::vector<float> split_weights;
  if (split) {
    split_ids = gather(skin_w->joints, kMaxInfluences, split->source);
    split_weights = gather(skin_w->weights, kMaxInfluences, split->source);
  }
  const std::vector<std::uint16_t>& joint_ids = split ? split_ids : skin_w->joints;
  const std::vector<float>& joint_weights = split ? split_weights : skin_w->weights;
  const int joints0 =
      add_accessor(g,
                   add_view(g, joint_ids.data(), joint_ids.size() * sizeof(std::uint16_t),
                            TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, out_v, TINYGLTF_TYPE_VEC4);
  const int weights0 =
      add_accessor(g,
                   add_view(g, joint_weights.data(), joint_weights.size() * sizeof(float),
                            TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, out_v, TINYGLTF_TYPE_VEC4);
  return {joints0, weights0};
}

// The morph targets of `prim`, their default weights and names (mesh.extras.targetNames): the
// first options.shape_keys shape components, then (options.pose_correctives) the pose blend
// shapes.
void add_morph_targets(tinygltf::Model& g, const BodyModel& model,
                       const Eigen::Ref<const Eigen::VectorXd>& betas, const GltfOptions& options,
                       const std::vector<std::string>& names, const SeamSplit* split,
                       tinygltf::Primitive& prim, tinygltf::Mesh& mesh) {
  const auto V = static_cast<size_t>(model.num_vertices());
  const int N = options.shape_keys;
  tinygltf::Value::Array target_names;
  std::vector<float> delta(3 * V);
  for (int b = 0; b < N; ++b) {
    for (size_t i = 0; i < 3 * V; ++i) {
      delta[i] = static_cast<float>(model.shapedirs(static_cast<Eigen::Index>(i), b));
    }
    prim.targets.push_back({{"POSITION", add_vertex_vec3(g, split, delta, true)}});
    mesh.weights.push_back(b < betas.size() ? betas[b] : 0.0);
    char name[32];
    std::snprintf(name, sizeof name, "beta_%02d", b);
    target_names.emplace_back(std::string(name));
  }
  if (options.pose_correctives && model.has_pose_blend_shapes()) {
    // One morph target per pose feature: the displacement of every vertex (posedirs column p
    // reshaped to V x 3). The target weight of feature 9 (k - 1) + 3 r + c is (R_k - I)(r, c),
    // which may be negative.
    for (Eigen::Index p = 0; p < model.posedirs.cols(); ++p) {
      for (size_t i = 0; i < 3 * V; ++i) {
        delta[i] = static_cast<float>(model.posedirs(static_cast<Eigen::Index>(i), p));
      }
      prim.targets.push_back({{"POSITION", add_vertex_vec3(g, split, delta, true)}});
      const int k = static_cast<int>(p / 9) + 1;
      const int r = static_cast<int>((p % 9) / 3), c = static_cast<int>(p % 3);
      double w = 0.0;
      if (options.pose.size() > 0) {
        const Eigen::Matrix3d R = rodrigues(options.pose.segment<3>(3 * Eigen::Index{k}));
        w = R(r, c) - (r == c ? 1.0 : 0.0);
      }
      mesh.weights.push_back(w);
      target_names.emplace_back("pose_" + names[static_cast<size_t>(k)] + "_" + std::to_string(r) +
                                std::to_string(c));
    }
  }
  if (!target_names.empty()) {
    tinygltf::Value::Object mesh_extras;
    mesh_extras["targetNames"] = tinygltf::Value(target_names);
    mesh.extras = tinygltf::Value(mesh_extras);
  }
}

// Nodes 1 + k = joint k (translation relative to its parent, rotation from options.pose), the
// skin with its inverse bind matrices. Node 0, the skinned mesh, is already there.
void add_skeleton(tinygltf::Model& g, const BodyModel& model, const Body& body,
                  const GltfOptions& options, const std::vector<std::string>& names) {
  const int K = model.num_joints();
  std::vector<float> ibm(static_cast<size_t>(16 * K), 0.0f);
  tinygltf::Skin skin_def;
  skin_def.name = options.name + "_skeleton";
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    tinygltf::Node joint;
    joint.name = names[ks];
    const int p = model.parents[ks];
    Eigen::Vector3d t = body.joints.row(k).transpose();
    if (p >= 0) t -= body.joints.row(p).transpose();
    joint.translation = {t.x(), t.y(), t.z()};
    if (options.pose.size() > 0) {
      const Eigen::Vector3d aa = options.pose.segment<3>(3 * Eigen::Index{k});
      if (aa.squaredNorm() > 0.0) joint.rotation = gltf_quaternion(rodrigues(aa));
    }
    g.nodes.push_back(std::move(joint));
    if (p >= 0) g.nodes[static_cast<size_t>(p) + 1].children.push_back(k + 1);
    skin_def.joints.push_back(k + 1);
    // Inverse bind matrix = translation(-J_k), column-major.
    float* m = ibm.data() + 16 * ks;
    m[0] = m[5] = m[10] = m[15] = 1.0f;
    for (int c = 0; c < 3; ++c) m[12 + c] = static_cast<float>(-body.joints(k, c));
  }
  skin_def.skeleton = K > 0 ? 1 : -1;
  skin_def.inverseBindMatrices =
      add_accessor(g, add_view(g, ibm.data(), ibm.size() * sizeof(float), 0),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, static_cast<size_t>(K), TINYGLTF_TYPE_MAT4);
  g.skins.push_back(std::move(skin_def));
}

tinygltf::Model build_model(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                            const GltfOptions& options, const std::string& context) {
  if (model.num_joints() > 65535) {
    throw ModelError(context + ": " + std::to_string(model.num_joints()) +
                     " joints do not fit glTF's unsigned short JOINTS_0");
  }
  if (options.shape_keys < 0 || options.shape_keys > model.num_betas()) {
    throw ModelError(context + ": " + std::to_string(options.shape_keys) +
                     " shape keys asked for but the model has " +
                     std::to_string(model.num_betas()) + " shape components");
  }
  check_pose(model, options, context);
  const std::vector<std::string> names = bone_names(model, options.bone_names);
  Body body = export_rest_body(model, betas, options, context);
  const auto V = static_cast<size_t>(body.vertices.rows());
  const int K = model.num_joints();
  // Texture seams: glTF indexes every attribute per vertex, so a model with texture coordinates
  // is split at its seams here (SeamSplit); every per-vertex array below is then gathered from
  // the model's vertices. Without texture coordinates nothing changes (and nothing is copied).
  const bool textured = model.has_uvs();
  const SeamSplit split = textured ? split_at_seams(model, context) : SeamSplit();
  const size_t out_v = textured ? split.source.size() : V;
  const SeamSplit* split_or_null = textured ? &split : nullptr;

  tinygltf::Model g;
  g.asset.version = "2.0";
  g.asset.generator = kGenerator;
  if (!options.extras.empty()) {
    tinygltf::Value::Object extras;
    for (const auto& [key, value] : options.extras) extras[key] = tinygltf::Value(value);
    g.asset.extras = tinygltf::Value(extras);
  }
  g.buffers.resize(1);
  g.buffers[0].data.reserve(out_v * (textured ? 56 : 48) +
                            static_cast<size_t>(model.num_faces()) * 12 +
                            static_cast<size_t>(K) * 64 + 64);

  // Geometry. With shape keys, POSITION is the body without its first N components; the targets'
  // default weights (the avatar's betas) add them back.
  const int N = options.shape_keys;
  Vertices base = body.vertices;
  for (int b = 0; b < N && b < betas.size(); ++b) {
    base -= betas[b] *
            Eigen::Map<const Vertices>(model.shapedirs.col(b).data(), model.num_vertices(), 3);
  }
  // Normals come from the unsplit mesh, so that the seams do not show in the shading.
  const int position = add_vertex_vec3(g, split_or_null, to_float(base), true);
  const int normal = add_vertex_vec3(g, split_or_null,
                                     to_float(vertex_normals(body.vertices, model.faces)), false);
  const auto [joints0, weights0] =
      add_skin_attributes(g, model, options, split_or_null, out_v, context);
  const int texcoord0 = textured ? add_texcoords(g, split) : -1;
  const int index_accessor = add_indices(g, textured ? split.faces : model.faces);

  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = position;
  prim.attributes["NORMAL"] = normal;
  prim.attributes["JOINTS_0"] = joints0;
  prim.attributes["WEIGHTS_0"] = weights0;
  if (texcoord0 >= 0) prim.attributes["TEXCOORD_0"] = texcoord0;
  prim.indices = index_accessor;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.material = 0;

  tinygltf::Mesh mesh;
  mesh.name = options.name;
  add_morph_targets(g, model, betas, options, names, split_or_null, prim, mesh);
  mesh.primitives.push_back(std::move(prim));
  g.meshes.push_back(std::move(mesh));

  tinygltf::Material skin;
  skin.name = "skin";
  skin.pbrMetallicRoughness.baseColorFactor = {0.80, 0.62, 0.52, 1.0};
  skin.pbrMetallicRoughness.metallicFactor = 0.0;
  skin.pbrMetallicRoughness.roughnessFactor = 0.8;
  g.materials.push_back(std::move(skin));

  // Nodes: 0 = the skinned mesh, 1 + k = joint k (translation relative to its parent).
  tinygltf::Node mesh_node;
  mesh_node.name = options.name;
  mesh_node.mesh = 0;
  mesh_node.skin = 0;
  g.nodes.push_back(std::move(mesh_node));
  add_skeleton(g, model, body, options, names);

  tinygltf::Scene scene;
  scene.name = options.name;
  scene.nodes.push_back(0);
  for (int k = 0; k < K; ++k) {
    if (model.parents[static_cast<size_t>(k)] < 0) scene.nodes.push_back(k + 1);
  }
  g.scenes.push_back(std::move(scene));
  g.defaultScene = 0;
  g.buffers[0].data.resize((g.buffers[0].data.size() + 3) & ~size_t{3}, 0);
  return g;
}

}  // namespace

GltfSkinWeights gltf_skin_weights(const BodyModel& model) {
  GltfSkinWeights s;
  top_influences(model.weights, s.joints, s.weights);
  return s;
}

// ---------------------------------------------------------------------------------------------
// 3. write_gltf / glb_bytes
// ---------------------------------------------------------------------------------------------

namespace {

// Serialises with tinygltf into memory: GLB (buffer 0 in the BIN chunk) or glTF JSON (buffers as
// base64 data URIs). Writing the file ourselves lets us check every I/O error, which
// tinygltf's own file writer does not report.
std::string serialise(const tinygltf::Model& g, bool binary, const std::string& context) {
  std::ostringstream out(binary ? std::ios::out | std::ios::binary : std::ios::out);
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&g, out, !binary, binary) || !out) {
    throw ModelError(context + ": tinygltf could not serialise the avatar");
  }
  return out.str();
}

void append_u32(std::string& out, std::uint32_t x) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((x >> (8 * i)) & 0xffu));
}

std::uint32_t read_u32(const std::string& s, size_t at) {
  std::uint32_t x = 0;
  for (int i = 0; i < 4; ++i)
    x |= static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + static_cast<size_t>(i)]))
         << (8 * i);
  return x;
}

// A GLB as pieces written one after the other: `head` (the 12-byte header, the JSON chunk and
// the BIN chunk's 8-byte header) and `bin` (buffer 0, moved out of the model), padded to 4
// bytes. The JSON is tinygltf's for the model with an empty buffer, its byteLength then set to
// the buffer's: the same bytes as tinygltf's GLB of the whole model (WriteBinaryGltfStream)
// without copying the buffer through tinygltf's copy, its stream and two strings (the largest
// cost of writing many avatars).
struct GlbPieces {
  std::string head;
  std::vector<unsigned char> bin;
  std::vector<std::string_view> views() const {
    static const char zeros[4] = {0, 0, 0, 0};
    return {head, std::string_view(reinterpret_cast<const char*>(bin.data()), bin.size()),
            std::string_view(zeros, (4 - bin.size() % 4) % 4)};
  }
};

GlbPieces glb_pieces(tinygltf::Model& g, const std::string& context) {
  GlbPieces p;
  if (!g.buffers.empty()) {
    p.bin = std::move(g.buffers[0].data);
    g.buffers[0].data.clear();
  }
  const std::string empty = serialise(g, true, context);  // header, JSON chunk, no BIN chunk
  if (p.bin.empty()) {
    p.head = empty;
    return p;
  }
  std::string json = empty.substr(20, read_u32(empty, 12));
  while (!json.empty() && json.back() == ' ') json.pop_back();  // the chunk's padding
  const std::string from = "\"buffers\":[{\"byteLength\":0}]";
  const size_t at = json.find(from);
  if (at == std::string::npos || json.find(from, at + 1) != std::string::npos) {
    throw ModelError(context + ": internal error: the GLB's buffer entry was not found");
  }
  json.replace(at, from.size(),
               "\"buffers\":[{\"byteLength\":" + std::to_string(p.bin.size()) + "}]");
  const size_t json_chunk = (json.size() + 3) & ~size_t{3};
  const size_t bin_chunk = (p.bin.size() + 3) & ~size_t{3};
  const size_t total = 12 + 8 + json_chunk + 8 + bin_chunk;
  if (total > 0xffffffffu) throw ModelError(context + ": the avatar is too large for a GLB");
  p.head.reserve(12 + 8 + json_chunk + 8);
  p.head = "glTF";
  append_u32(p.head, 2);
  append_u32(p.head, static_cast<std::uint32_t>(total));
  append_u32(p.head, static_cast<std::uint32_t>(json_chunk));
  append_u32(p.head, 0x4E4F534Au);  // "JSON"
  p.head += json;
  p.head.append(json_chunk - json.size(), ' ');
  append_u32(p.head, static_cast<std::uint32_t>(bin_chunk));
  append_u32(p.head, 0x004E4942u);  // "BIN\0"
  return p;
}

}  // namespace

std::vector<std::uint8_t> glb_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const GltfOptions& options) {
  tinygltf::Model g = build_model(model, betas, options, "glb_bytes");
  const GlbPieces p = glb_pieces(g, "glb_bytes");
  std::vector<std::uint8_t> out;
  for (const std::string_view v : p.views()) out.insert(out.end(), v.begin(), v.end());
  return out;
}

void write_gltf(const std::string& path, const BodyModel& model,
                const Eigen::Ref<const Eigen::VectorXd>& betas, const GltfOptions& options) {
  const bool binary = ends_with_ci(path, ".glb");
  if (!binary && !ends_with_ci(path, ".gltf")) {
    throw ModelError(path + ": unknown glTF file extension; use .glb (binary) or .gltf (JSON)");
  }
  tinygltf::Model g = build_model(model, betas, options, path);
  if (!binary) return write_file_atomic(path, serialise(g, false, path));
  const GlbPieces p = glb_pieces(g, path);
  write_file_atomic(path, p.views());
}

// ---------------------------------------------------------------------------------------------
// 4. VRM 1.0 (VRMC_vrm): humanoid bone map, meta, first person
// ---------------------------------------------------------------------------------------------

const std::map<std::string, std::string>& vrm_humanoid_bones() {
  static const std::map<std::string, std::string> bones = {
      {"pelvis", "hips"},
      {"spine1", "spine"},
      {"spine2", "chest"},
      {"spine3", "upperChest"},
      {"neck", "neck"},
      {"head", "head"},
      {"left_collar", "leftShoulder"},
      {"left_shoulder", "leftUpperArm"},
      {"left_elbow", "leftLowerArm"},
      {"left_wrist", "leftHand"},
      {"right_collar", "rightShoulder"},
      {"right_shoulder", "rightUpperArm"},
      {"right_elbow", "rightLowerArm"},
      {"right_wrist", "rightHand"},
      {"left_hip", "leftUpperLeg"},
      {"left_knee", "leftLowerLeg"},
      {"left_ankle", "leftFoot"},
      {"left_foot", "leftToes"},
      {"right_hip", "rightUpperLeg"},
      {"right_knee", "rightLowerLeg"},
      {"right_ankle", "rightFoot"},
      {"right_foot", "rightToes"},
  };
  return bones;
}

namespace {

// The VRM humanoid bones that must be present (VRMC_vrm-1.0/humanoid.md).
const char* const kRequiredVrmBones[] = {
    "hips",         "spine",         "head",          "leftUpperLeg",  "leftLowerLeg",
    "leftFoot",     "rightUpperLeg", "rightLowerLeg", "rightFoot",     "leftUpperArm",
    "leftLowerArm", "leftHand",      "rightUpperArm", "rightLowerArm", "rightHand"};
// meta.licenseUrl must be the VRM Public Licence 1.0 (VRMC_vrm-1.0/meta.md).
const char* const kVrmLicenceUrl = "https://vrm.dev/licenses/1.0/";
const char* const kMitUrl = "https://opensource.org/license/mit/";

tinygltf::Value str(const std::string& s) {
  return tinygltf::Value(s);
}

tinygltf::Model build_vrm(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                          const ExportOptions& options, const std::string& context) {
  if (options.pose.size() > 0) {
    throw ModelError(context +
                     ": a VRM's rest must be the T-pose, so a pose cannot be exported to .vrm; "
                     "leave out the pose (VRM applications pose the avatar themselves) or export "
                     ".glb/.fbx");
  }
  // The body model's licence: the caller's statement first, else the model's own metadata.
  std::string licence = options.licence;
  if (licence.empty()) {
    const auto it = model.meta.extra.find("licence");
    if (it != model.meta.extra.end()) licence = it->second;
  }
  if (licence.empty()) {
    throw ModelError(
        context + ": the body model '" + model.meta.name +
        "' states no licence, and a VRM must carry the licence of what it is made from. "
        "SMPL-family "
        "files are licensed by their owners (e.g. for non-commercial research only): state the "
        "licence that applies to you (caliper: --licence TEXT_OR_URL), or export .glb/.fbx");
  }
  const bool mit = licence.rfind("MIT", 0) == 0;
  const std::string licence_url = mit ? kMitUrl : licence;

  tinygltf::Model g = build_model(model, betas, options, context);
  // Humanoid: node 1 + k is joint k (build_model's layout); map by the model's joint names.
  tinygltf::Value::Object human_bones;
  for (int k = 0; k < model.num_joints(); ++k) {
    const auto ks = static_cast<size_t>(k);
    if (ks >= model.joint_names.size()) break;
    const auto it = vrm_humanoid_bones().find(model.joint_names[ks]);
    if (it == vrm_humanoid_bones().end()) continue;
    tinygltf::Value::Object bone;
    bone["node"] = tinygltf::Value(k + 1);
    human_bones[it->second] = tinygltf::Value(bone);
  }
  std::string missing;
  for (const char* b : kRequiredVrmBones) {
    if (!human_bones.count(b)) missing += (missing.empty() ? "" : ", ") + std::string(b);
  }
  if (!missing.empty()) {
    throw ModelError(context + ": the model has no joints for the VRM humanoid bones " + missing +
                     " (VRM needs SMPL's joint names: pelvis, spine1, head, left_hip, ...)");
  }
  tinygltf::Value::Object humanoid;
  humanoid["humanBones"] = tinygltf::Value(human_bones);

  tinygltf::Value::Object meta;
  meta["name"] = str(options.name.empty() ? "avatar" : options.name);
  meta["version"] = str("1");
  meta["authors"] = tinygltf::Value(
      tinygltf::Value::Array{str(options.author.empty() ? "unknown" : options.author)});
  meta["licenseUrl"] = str(kVrmLicenceUrl);
  meta["otherLicenseUrl"] = str(licence_url);
  meta["thirdPartyLicenses"] =
      str("Body model: " + (model.meta.name.empty() ? std::string("(unnamed)") : model.meta.name) +
          ". Licence: " + licence + ". Made with " + kGenerator + ".");
  meta["references"] = tinygltf::Value(tinygltf::Value::Array{
      str("Pujades et al., The Virtual Caliper: Rapid Creation of Metrically Accurate Avatars "
          "from 3D Measurements, IEEE TVCG 2019")});

  tinygltf::Value::Object annotation;
  annotation["node"] = tinygltf::Value(0);  // the skinned mesh (build_model's node 0)
  annotation["type"] = str("auto");         // head-weighted triangles: third person only
  tinygltf::Value::Object first_person;
  first_person["meshAnnotations"] =
      tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(annotation)});

  tinygltf::Value::Object vrm;
  vrm["specVersion"] = str("1.0");
  vrm["humanoid"] = tinygltf::Value(humanoid);
  vrm["meta"] = tinygltf::Value(meta);
  vrm["firstPerson"] = tinygltf::Value(first_person);
  g.extensionsUsed.push_back("VRMC_vrm");
  g.extensions["VRMC_vrm"] = tinygltf::Value(vrm);
  return g;
}

}  // namespace

std::vector<std::uint8_t> vrm_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const ExportOptions& options) {
  const std::string s = serialise(build_vrm(model, betas, options, "vrm_bytes"), true, "vrm_bytes");
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

void write_vrm(const std::string& path, const BodyModel& model,
               const Eigen::Ref<const Eigen::VectorXd>& betas, const ExportOptions& options) {
  if (!ends_with_ci(path, ".vrm")) throw ModelError(path + ": a VRM file name must end in .vrm");
  write_file_atomic(path, serialise(build_vrm(model, betas, options, path), true, path));
}

// ---------------------------------------------------------------------------------------------
// 5. Reading limits: buffer URIs, JSON nesting, decoded bytes
// ---------------------------------------------------------------------------------------------
namespace {

// glTF's own schema nests about 8 levels; extras may add some. Deeper JSON is refused before
// tinygltf sees it (its JSON-to-Value conversion recurses once per level).
constexpr int kMaxJsonDepth = 128;
// The arrays read_gltf() hands out may hold this many times the bytes of the file and its
// buffers (a float becomes a double: 2x; an unsigned byte JOINTS_0 becomes a double: 8x), plus
// a fixed allowance for tiny files.
constexpr size_t kDecodedPerInputByte = 16;
constexpr size_t kDecodedSlack = size_t{16} << 20;

// Counts the bytes of every array read_gltf() makes, against a limit relative to the input.
class DecodeBudget {
 public:
  DecodeBudget(size_t input_bytes, std::string path)
      : limit_(input_bytes > (SIZE_MAX - kDecodedSlack) / kDecodedPerInputByte
                   ? SIZE_MAX
                   : input_bytes * kDecodedPerInputByte + kDecodedSlack),
        input_(input_bytes),
        path_(std::move(path)) {}
  // Charges count x item_bytes bytes for `what`; throws when the total passes the limit.
  void charge(size_t count, size_t item_bytes, const std::string& what) {
    if (count > (limit_ - used_) / std::max<size_t>(item_bytes, 1)) {
      throw ModelError(path_ + ": " + what + " would make the decoded data larger than " +
                       std::to_string(kDecodedPerInputByte) + " times the " +
                       std::to_string(input_) +
                       " bytes of the file and its buffers (accessors or morph targets used "
                       "over and over): not an avatar file");
    }
    used_ += count * item_bytes;
  }

 private:
  size_t limit_;
  size_t used_ = 0;
  size_t input_;
  std::string path_;
};

// Where external buffer and image files may come from: only files inside `folder` (absolute,
// canonical), named by a relative URI without "..", without a scheme ("http:", "file:") and
// without a drive or backslash. The first refusal is kept for the error message.
struct UriPolicy {
  std::string folder;  // empty: no external file at all (in-memory reading)
  std::string refused;
};

bool uri_allowed(const std::string& joined, UriPolicy& policy) {
  auto refuse = [&](const std::string& uri, const std::string& why) {
    if (policy.refused.empty()) {
      policy.refused = "refused to read the external file '" + uri + "': " + why +
                       "; a glTF file may only use data: URIs and relative file names inside "
                       "its own folder (re-export it, or use .glb)";
    }
    return false;
  };
  // tinygltf asks for <base dir>/<uri> first, then ./<uri>: only the first form can be allowed.
  const std::string prefix =
      !policy.folder.empty() && policy.folder.back() == '/' ? policy.folder : policy.folder + "/";
  if (policy.folder.empty() || joined.compare(0, prefix.size(), prefix) != 0) {
    return refuse(joined, policy.folder.empty() ? "external files are not read here"
                                                : "it is not inside the folder of the file");
  }
  const std::string uri = joined.substr(prefix.size());
  if (uri.empty()) return refuse(uri, "the URI is empty");
  if (uri.find('\0') != std::string::npos || uri.find('\\') != std::string::npos) {
    return refuse(uri, "it holds a NUL or backslash");
  }
  if (uri[0] == '/') return refuse(uri, "absolute paths are not allowed");
  const size_t first_slash = uri.find('/');
  if (uri.substr(0, first_slash).find(':') != std::string::npos) {
    return refuse(uri, "URI schemes other than data: (http:, file:, ...) are not read");
  }
  size_t begin = 0;
  while (begin <= uri.size()) {
    const size_t end = std::min(uri.find('/', begin), uri.size());
    if (uri.compare(begin, end - begin, "..") == 0 && end - begin == 2) {
      return refuse(uri, "it leaves the folder of the file ('..')");
    }
    begin = end + 1;
  }
  // A symbolic link inside the folder must not lead out of it either.
  std::error_code ec;
  const std::filesystem::path real = std::filesystem::weakly_canonical(joined, ec);
  if (ec || real.string().compare(0, prefix.size(), prefix) != 0) {
    return refuse(uri, "it resolves to a file outside the folder of the file");
  }
  return true;
}

bool policy_file_exists(const std::string& path, void* user) {
  if (!uri_allowed(path, *static_cast<UriPolicy*>(user))) return false;
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

std::string policy_expand(const std::string& path, void*) {
  return path;
}

bool policy_read(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                 void* user) {
  if (!uri_allowed(path, *static_cast<UriPolicy*>(user))) {
    if (err) *err += static_cast<UriPolicy*>(user)->refused;
    return false;
  }
  try {
    *out = read_file_bytes(path);
  } catch (const ModelError& e) {
    if (err) *err += e.what();
    return false;
  }
  return true;
}

bool policy_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "read_gltf never writes files";
  return false;
}

// Images are not needed for an avatar: they are neither decoded nor kept.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*) {
  return true;
}

// The deepest nesting of arrays and objects in JSON text (strings skipped), stopping early once
// `limit` is passed.
int json_depth(const char* p, size_t n, int limit) {
  int depth = 0;
  int deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < n; ++i) {
    const char c = p[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// 6. Accessor reading
// ---------------------------------------------------------------------------------------------
namespace {

// Reads any accessor into a count x components double matrix (normalised integers are mapped
// to [0, 1] as the specification says). Every offset is checked without overflow: byteOffset
// values near 2^64 cannot wrap round to a small position. `budget` is charged with the bytes of
// the result.
Eigen::MatrixXd read_accessor(const tinygltf::Model& g, int index, const std::string& path,
                              const std::string& what, DecodeBudget& budget) {
  auto fail = [&](const std::string& why) -> ModelError {
    return ModelError(path + ": " + what + " (accessor " + std::to_string(index) + ") " + why);
  };
  if (index < 0 || static_cast<size_t>(index) >= g.accessors.size()) throw fail("does not exist");
  const auto& a = g.accessors[static_cast<size_t>(index)];
  if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= g.bufferViews.size()) {
    throw fail("has no bufferView (sparse or empty accessors are not supported)");
  }
  const auto& view = g.bufferViews[static_cast<size_t>(a.bufferView)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= g.buffers.size()) {
    throw fail("refers to a missing buffer");
  }
  const auto& data = g.buffers[static_cast<size_t>(view.buffer)].data;
  const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  const int size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
  const int stride = a.ByteStride(view);
  if (comps <= 0 || size <= 0 || stride <= 0) throw fail("has an invalid type or component type");
  const auto element = static_cast<size_t>(comps) * static_cast<size_t>(size);
  const auto ustride = static_cast<size_t>(stride);
  // view.byteOffset + view.byteLength <= data.size() and a.byteOffset + (count - 1) * stride +
  // element <= view.byteLength, each written so that no sum can wrap.
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
    throw fail("has a bufferView that reaches past the end of its buffer (byteOffset " +
               std::to_string(view.byteOffset) + ", byteLength " + std::to_string(view.byteLength) +
               ", buffer " + std::to_string(data.size()) +
               " bytes): the file is truncated or corrupt");
  }
  if (a.count > 0 && (a.byteOffset > view.byteLength || element > view.byteLength - a.byteOffset ||
                      a.count - 1 > (view.byteLength - a.byteOffset - element) / ustride)) {
    throw fail("reaches past the end of its bufferView (byteOffset " +
               std::to_string(a.byteOffset) + ", count " + std::to_string(a.count) +
               ", bufferView " + std::to_string(view.byteLength) +
               " bytes): the file is truncated or corrupt");
  }
  const size_t start = view.byteOffset + a.byteOffset;
  budget.charge(a.count, static_cast<size_t>(comps) * sizeof(double), what);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(a.count), comps);
  for (size_t i = 0; i < a.count; ++i) {
    const unsigned char* p = data.data() + start + i * ustride;
    for (int c = 0; c < comps; ++c) {
      const unsigned char* q = p + static_cast<size_t>(c) * static_cast<size_t>(size);
      double x = 0.0;
      switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
          float f;
          std::memcpy(&f, q, 4);
          x = f;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
          std::uint32_t u;
          std::memcpy(&u, q, 4);
          x = u;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          std::uint16_t u;
          std::memcpy(&u, q, 2);
          x = a.normalized ? u / 65535.0 : u;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          x = a.normalized ? *q / 255.0 : *q;
          break;
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          std::int16_t s;
          std::memcpy(&s, q, 2);
          x = a.normalized ? std::max(s / 32767.0, -1.0) : s;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
          const auto s = static_cast<std::int8_t>(*q);
          x = a.normalized ? std::max(s / 127.0, -1.0) : s;
          break;
        }
        default:
          throw fail("has an unsupported component type " + std::to_string(a.componentType));
      }
      out(static_cast<Eigen::Index>(i), c) = x;
    }
  }
  return out;
}

Eigen::Matrix4d local_matrix(const tinygltf::Node& n) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (n.matrix.size() == 16) {
    for (int i = 0; i < 16; ++i) m(i % 4, i / 4) = n.matrix[static_cast<size_t>(i)];
    return m;
  }
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  if (n.rotation.size() == 4) {
    r = Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2])
            .normalized()
            .toRotationMatrix();
  }
  Eigen::Vector3d s = Eigen::Vector3d::Ones();
  if (n.scale.size() == 3) s = Eigen::Vector3d(n.scale[0], n.scale[1], n.scale[2]);
  m.topLeftCorner<3, 3>() = r * s.asDiagonal();
  if (n.translation.size() == 3) {
    m.topRightCorner<3, 1>() =
        Eigen::Vector3d(n.translation[0], n.translation[1], n.translation[2]);
  }
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// 7. read_gltf
// ---------------------------------------------------------------------------------------------

namespace {

// Parses the glTF or GLB file (external buffers only from `folder`, images skipped); tinygltf's
// warnings go to `warn`.
tinygltf::Model parse_gltf(const std::uint8_t* bytes, size_t size, const std::string& path,
                           const std::string& folder, std::string& warn) {
  if (size > std::numeric_limits<unsigned int>::max()) {
    throw ModelError(path + ": larger than 4 GiB, which glTF files cannot be");
  }
  const bool binary = size >= 4 && std::memcmp(bytes, "glTF", 4) == 0;
  // The JSON text: the whole file, or the GLB's first chunk (header 12 bytes, chunk header 8).
  const char* json = reinterpret_cast<const char*>(bytes);
  size_t json_size = size;
  if (binary) {
    std::uint32_t chunk = 0;
    if (size >= 20) std::memcpy(&chunk, bytes + 12, 4);
    json += std::min<size_t>(size, 20);
    json_size = std::min<size_t>(chunk, size - std::min<size_t>(size, 20));
  }
  if (json_depth(json, json_size, kMaxJsonDepth) > kMaxJsonDepth) {
    throw ModelError(path + ": the JSON nests arrays and objects more than " +
                     std::to_string(kMaxJsonDepth) + " levels deep: not an avatar file");
  }
  tinygltf::Model g;
  tinygltf::TinyGLTF loader;
  UriPolicy policy{folder, {}};
  loader.SetFsCallbacks(
      {&policy_file_exists, &policy_expand, &policy_read, &policy_write, &policy});
  loader.SetImageLoader(&skip_image, nullptr);
  std::string err;
  const auto n = static_cast<unsigned int>(size);
  const std::string base = folder.empty() ? std::string("/nonexistent") : folder;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&g, &err, &warn, bytes, n, base)
                : loader.LoadASCIIFromString(&g, &err, &warn, reinterpret_cast<const char*>(bytes),
                                             n, base);
  } catch (const std::exception& e) {
    // tinygltf itself throws on some malformed files (a GLB buffer of byteLength 0 beside a
    // non-empty BIN chunk: std::out_of_range from vector::at); found by fuzz_gltf.
    throw ModelError(path + ": not a readable glTF file: the glTF parser failed on it (" +
                     e.what() + "); re-export the avatar from its original application");
  }
  if (!policy.refused.empty()) throw ModelError(path + ": " + policy.refused);
  if (!ok) {
    throw ModelError(path + ": not a readable glTF file: " + (err.empty() ? "unknown error" : err) +
                     (warn.empty() ? "" : " (tinygltf warnings: " + warn + ")"));
  }
  return g;
}

// The first node with both a mesh and a skin, checked to refer to existing ones.
const tinygltf::Node& skinned_node(const tinygltf::Model& g, const std::string& path) {
  const tinygltf::Node* skinned = nullptr;
  for (const auto& node : g.nodes) {
    if (node.mesh >= 0 && node.skin >= 0) {
      skinned = &node;
      break;
    }
  }
  if (!skinned) throw ModelError(path + ": no node has both a mesh and a skin");
  if (static_cast<size_t>(skinned->mesh) >= g.meshes.size() ||
      static_cast<size_t>(skinned->skin) >= g.skins.size() ||
      g.meshes[static_cast<size_t>(skinned->mesh)].primitives.empty()) {
    throw ModelError(path + ": the skinned node refers to a missing mesh, skin or primitive");
  }
  return *skinned;
}

// The morph targets of `prim` (a target without POSITION moves nothing), their default weights
// and names (mesh.extras.targetNames) from `gmesh`.
void read_morph_targets(const tinygltf::Model& g, const tinygltf::Primitive& prim,
                        const tinygltf::Mesh& gmesh, const Eigen::MatrixXd& pos,
                        const std::string& path, DecodeBudget& budget, GltfAvatar& out) {
  for (size_t t = 0; t < prim.targets.size(); ++t) {
    const std::string what = "morph target " + std::to_string(t) + " POSITION";
    const auto it = prim.targets[t].find("POSITION");
    if (it == prim.targets[t].end()) {
      budget.charge(static_cast<size_t>(pos.rows()), 3 * sizeof(double), what);
      out.morph_targets.emplace_back(Vertices::Zero(pos.rows(), 3));
      continue;
    }
    const Eigen::MatrixXd d = read_accessor(g, it->second, path, what, budget);
    if (d.rows() != pos.rows() || d.cols() != 3) {
      throw ModelError(path + ": morph target " + std::to_string(t) +
                       " does not have one VEC3 per vertex");
    }
    out.morph_targets.emplace_back(d);
  }
  out.morph_weights.assign(out.morph_targets.size(), 0.0);
  out.morph_names.assign(out.morph_targets.size(), std::string());
  for (size_t t = 0; t < out.morph_targets.size() && t < gmesh.weights.size(); ++t) {
    out.morph_weights[t] = gmesh.weights[t];
  }
  if (gmesh.extras.IsObject() && gmesh.extras.Has("targetNames")) {
    const auto& names = gmesh.extras.Get("targetNames");
    for (size_t t = 0; names.IsArray() && t < out.morph_targets.size() &&
                       t < static_cast<size_t>(names.ArrayLen());
         ++t) {
      if (names.Get(static_cast<int>(t)).IsString()) {
        out.morph_names[t] = names.Get(static_cast<int>(t)).Get<std::string>();
      }
    }
  }
}

// The triangles of `prim`, checked against the vertex count.
void read_faces(const tinygltf::Model& g, const tinygltf::Primitive& prim, Eigen::Index vertices,
                const std::string& path, DecodeBudget& budget, GltfAvatar& out) {
  if (prim.indices < 0) return;
  const Eigen::MatrixXd idx = read_accessor(g, prim.indices, path, "indices", budget);
  if (idx.size() % 3 != 0) throw ModelError(path + ": the index count is not a multiple of 3");
  out.faces.resize(idx.size() / 3, 3);
  for (Eigen::Index i = 0; i < idx.size(); ++i) {
    const double x = idx(i, 0);
    if (!(x >= 0 && x < static_cast<double>(vertices))) {
      throw ModelError(path + ": index " + std::to_string(x) + " is out of range");
    }
    out.faces.data()[i] = static_cast<std::int32_t>(x);
  }
}

// The parent of every node (-1: a root); a child listed twice or out of range is an error.
std::vector<int> node_parents(const tinygltf::Model& g, const std::string& path) {
  const auto N = g.nodes.size();
  std::vector<int> node_parent(N, -1);
  for (size_t i = 0; i < N; ++i) {
    for (int c : g.nodes[i].children) {
      if (c < 0 || static_cast<size_t>(c) >= N || node_parent[static_cast<size_t>(c)] != -1) {
        throw ModelError(path + ": node " + std::to_string(i) + " has an invalid child " +
                         std::to_string(c));
      }
      node_parent[static_cast<size_t>(c)] = static_cast<int>(i);
    }
  }
  return node_parent;
}

// The world transform of every node.
std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> world_transforms(
    const tinygltf::Model& g, const std::vector<int>& node_parent, const std::string& path) {
  const auto N = g.nodes.size();
  // World transforms without recursion (a parent chain may be as long as the file allows): walk
  // up from each node to the first finished ancestor, then come back down.
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> world(N);
  std::vector<char> state(N, 0);  // 0 = todo, 1 = on the current chain, 2 = done
  std::vector<size_t> chain;
  for (size_t i = 0; i < N; ++i) {
    chain.clear();
    for (size_t at = i; state[at] != 2;) {
      if (state[at] == 1) throw ModelError(path + ": the node hierarchy has a cycle");
      state[at] = 1;
      chain.push_back(at);
      if (node_parent[at] < 0) break;
      at = static_cast<size_t>(node_parent[at]);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int p = node_parent[*it];
      world[*it] = p >= 0
                       ? Eigen::Matrix4d(world[static_cast<size_t>(p)] * local_matrix(g.nodes[*it]))
                       : local_matrix(g.nodes[*it]);
      state[*it] = 2;
    }
  }
  return world;
}

// The skin's joints in order: rest positions (world), names and parents (the nearest ancestor
// node that is a joint of the skin).
void read_skeleton(const tinygltf::Model& g, const tinygltf::Skin& skin, const std::string& path,
                   GltfAvatar& out) {
  const auto K = skin.joints.size();
  const auto N = g.nodes.size();
  const std::vector<int> node_parent = node_parents(g, path);
  const auto world = world_transforms(g, node_parent, path);
  out.joints.resize(static_cast<Eigen::Index>(K), 3);
  out.joint_names.resize(K);
  out.parents.assign(K, -1);
  std::unordered_map<int, int> joint_of_node;  // first skin joint of each node
  for (size_t k = 0; k < K; ++k) joint_of_node.emplace(skin.joints[k], static_cast<int>(k));
  for (size_t k = 0; k < K; ++k) {
    const int node = skin.joints[k];
    if (node < 0 || static_cast<size_t>(node) >= N) {
      throw ModelError(path + ": skin joint " + std::to_string(k) + " refers to a missing node");
    }
    out.joints.row(static_cast<Eigen::Index>(k)) =
        world[static_cast<size_t>(node)].topRightCorner<3, 1>().transpose();
    out.joint_names[k] = g.nodes[static_cast<size_t>(node)].name;
    const int pn = node_parent[static_cast<size_t>(node)];
    const auto it = joint_of_node.find(pn);
    if (pn >= 0 && it != joint_of_node.end()) out.parents[k] = it->second;
  }
}

GltfAvatar read_gltf_impl(const std::uint8_t* bytes, size_t size, const std::string& path,
                          const std::string& folder) {
  std::string warn;
  const tinygltf::Model g = parse_gltf(bytes, size, path, folder, warn);
  GltfAvatar out;
  if (!warn.empty()) out.warnings.push_back(warn);
  size_t input_bytes = size;
  for (const auto& b : g.buffers) input_bytes += b.data.size();
  DecodeBudget budget(input_bytes, path);

  const tinygltf::Node* skinned = &skinned_node(g, path);
  const auto& skin = g.skins[static_cast<size_t>(skinned->skin)];
  const auto K = skin.joints.size();
  const auto& prim = g.meshes[static_cast<size_t>(skinned->mesh)].primitives[0];
  auto attribute = [&](const char* name) {
    const auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) {
      throw ModelError(path + ": the skinned mesh has no " + std::string(name) + " attribute");
    }
    return read_accessor(g, it->second, path, name, budget);
  };
  const Eigen::MatrixXd pos = attribute("POSITION");
  if (pos.cols() != 3) throw ModelError(path + ": POSITION is not VEC3");
  out.vertices = pos;
  const Eigen::MatrixXd ids = attribute("JOINTS_0");
  const Eigen::MatrixXd wts = attribute("WEIGHTS_0");
  if (ids.cols() != 4 || wts.cols() != 4 || ids.rows() != pos.rows() || wts.rows() != pos.rows()) {
    throw ModelError(path + ": JOINTS_0/WEIGHTS_0 must be VEC4 with one entry per vertex");
  }
  // Joint indices are checked as doubles before any conversion: a float JOINTS_0 may hold 1e30
  // or NaN, which no int can represent.
  for (Eigen::Index i = 0; i < ids.size(); ++i) {
    const double x = ids.data()[i];
    if (!(x >= 0.0 && x < static_cast<double>(K)) || x != std::floor(x)) {
      throw ModelError(path + ": JOINTS_0 holds " + std::to_string(x) +
                       ", which is not a joint of the skin (integers 0 to " +
                       std::to_string(K == 0 ? 0 : K - 1) + ")");
    }
  }
  out.joint_ids = ids.cast<int>();
  if (prim.attributes.count("TEXCOORD_0") > 0) {
    const Eigen::MatrixXd uv = attribute("TEXCOORD_0");
    if (uv.cols() != 2 || uv.rows() != pos.rows()) {
      throw ModelError(path + ": TEXCOORD_0 must be VEC2 with one entry per vertex");
    }
    out.texcoords = uv;
    out.texcoords.col(1) = 1.0 - out.texcoords.col(1).array();  // glTF's v runs downwards
  }
  read_morph_targets(g, prim, g.meshes[static_cast<size_t>(skinned->mesh)], pos, path, budget, out);
  out.generator = g.asset.generator;
  if (g.asset.extras.IsObject()) {
    for (const auto& key : g.asset.extras.Keys()) {
      const auto& v = g.asset.extras.Get(key);
      if (v.IsString()) out.extras[key] = v.Get<std::string>();
    }
  }
  out.joint_weights = wts;
  read_faces(g, prim, pos.rows(), path, budget, out);

  // Skeleton: world transforms of every node, then the skin's joints in order.
  read_skeleton(g, skin, path, out);
  return out;
}

}  // namespace

GltfAvatar read_gltf(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  std::error_code ec;
  std::filesystem::path folder = std::filesystem::absolute(path, ec).parent_path();
  folder = std::filesystem::weakly_canonical(folder, ec);
  if (ec) throw ModelError(path + ": cannot resolve the folder of the file (" + ec.message() + ")");
  return read_gltf_impl(bytes.data(), bytes.size(), path, folder.string());
}

GltfAvatar read_gltf_from_memory(const std::uint8_t* bytes, std::size_t size,
                                 const std::string& context) {
  return read_gltf_impl(bytes, size, context, std::string());
}

}  // namespace smpl
