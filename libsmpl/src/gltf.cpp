// glTF 2.0 export and import of a skinned SMPL-family avatar (Khronos glTF 2.0 specification,
// sections 3.7 "Geometry" (meshes, morph targets, skins) and 4.4 "GLB file format").
// This is the only translation unit of the project that includes tiny_gltf.h; Debian's
// libtinygltf.so is linked (built with its default stb image support, which the header's
// declarations match when no TINYGLTF_NO_* macro is defined here).
//
// Sections: 1. buffer building helpers  2. avatar -> tinygltf::Model  3. write_gltf / glb_bytes
//           4. accessor reading  5. read_gltf
#include "smpl/gltf.hpp"
#include "smpl/atomic_file.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <sstream>

#include <tiny_gltf.h>

#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"

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
  buf.resize(offset + bytes, 0);
  if (bytes > 0) std::memcpy(buf.data() + offset, data, bytes);
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

tinygltf::Model build_model(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                            const GltfOptions& options, const std::string& context) {
  if (model.num_joints() > 65535) {
    throw ModelError(context + ": " + std::to_string(model.num_joints()) +
                     " joints do not fit glTF's unsigned short JOINTS_0");
  }
  if (betas.size() > model.num_betas()) {
    throw ModelError(context + ": " + std::to_string(betas.size()) +
                     " betas given but the model has " + std::to_string(model.num_betas()));
  }
  Body body = shape(model, betas);
  if (options.stand_on_floor && body.vertices.rows() > 0) {
    const double lift = -body.vertices.col(1).minCoeff();
    body.vertices.col(1).array() += lift;
    body.joints.col(1).array() += lift;
  }
  const auto V = static_cast<size_t>(body.vertices.rows());
  const int K = model.num_joints();

  tinygltf::Model g;
  g.asset.version = "2.0";
  g.asset.generator = kGenerator;
  if (!options.extras.empty()) {
    tinygltf::Value::Object extras;
    for (const auto& [key, value] : options.extras) extras[key] = tinygltf::Value(value);
    g.asset.extras = tinygltf::Value(extras);
  }
  g.buffers.resize(1);
  g.buffers[0].data.reserve(V * 48 + static_cast<size_t>(model.num_faces()) * 12 +
                            static_cast<size_t>(K) * 64 + 64);

  // Geometry.
  const int position = add_vec3(g, to_float(body.vertices), TINYGLTF_TARGET_ARRAY_BUFFER, true);
  const int normal = add_vec3(g, to_float(vertex_normals(body.vertices, model.faces)),
                              TINYGLTF_TARGET_ARRAY_BUFFER, false);
  std::vector<std::uint16_t> joint_ids;
  std::vector<float> joint_weights;
  top_influences(model.weights, joint_ids, joint_weights);
  const int joints0 =
      add_accessor(g,
                   add_view(g, joint_ids.data(), joint_ids.size() * sizeof(std::uint16_t),
                            TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, V, TINYGLTF_TYPE_VEC4);
  const int weights0 =
      add_accessor(g,
                   add_view(g, joint_weights.data(), joint_weights.size() * sizeof(float),
                            TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, V, TINYGLTF_TYPE_VEC4);
  std::vector<std::uint32_t> indices(static_cast<size_t>(model.faces.size()));
  for (Eigen::Index i = 0; i < model.faces.size(); ++i) {
    indices[static_cast<size_t>(i)] = static_cast<std::uint32_t>(model.faces.data()[i]);
  }
  const int index_accessor =
      add_accessor(g,
                   add_view(g, indices.data(), indices.size() * sizeof(std::uint32_t),
                            TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, indices.size(), TINYGLTF_TYPE_SCALAR,
                   {static_cast<double>(model.faces.size() ? model.faces.minCoeff() : 0)},
                   {static_cast<double>(model.faces.size() ? model.faces.maxCoeff() : 0)});

  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = position;
  prim.attributes["NORMAL"] = normal;
  prim.attributes["JOINTS_0"] = joints0;
  prim.attributes["WEIGHTS_0"] = weights0;
  prim.indices = index_accessor;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.material = 0;

  tinygltf::Mesh mesh;
  mesh.name = options.name;
  if (options.pose_correctives && model.has_pose_blend_shapes()) {
    // One morph target per pose feature: the displacement of every vertex (posedirs column p
    // reshaped to V x 3). The target weight of feature 9 (k - 1) + 3 r + c is (R_k - I)(r, c),
    // which may be negative.
    tinygltf::Value::Array names;
    std::vector<float> delta(3 * V);
    for (Eigen::Index p = 0; p < model.posedirs.cols(); ++p) {
      for (size_t i = 0; i < 3 * V; ++i) {
        delta[i] = static_cast<float>(model.posedirs(static_cast<Eigen::Index>(i), p));
      }
      prim.targets.push_back(
          {{"POSITION", add_vec3(g, delta, TINYGLTF_TARGET_ARRAY_BUFFER, true)}});
      mesh.weights.push_back(0.0);
      const int k = static_cast<int>(p / 9) + 1;
      const std::string joint = static_cast<size_t>(k) < model.joint_names.size()
                                    ? model.joint_names[static_cast<size_t>(k)]
                                    : "joint" + std::to_string(k);
      names.emplace_back("pose_" + joint + "_" + std::to_string((p % 9) / 3) +
                         std::to_string(p % 3));
    }
    tinygltf::Value::Object mesh_extras;
    mesh_extras["targetNames"] = tinygltf::Value(names);
    mesh.extras = tinygltf::Value(mesh_extras);
  }
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
  std::vector<float> ibm(static_cast<size_t>(16 * K), 0.0f);
  tinygltf::Skin skin_def;
  skin_def.name = options.name + "_skeleton";
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    tinygltf::Node joint;
    joint.name =
        ks < model.joint_names.size() ? model.joint_names[ks] : "joint" + std::to_string(k);
    const int p = model.parents[ks];
    Eigen::Vector3d t = body.joints.row(k).transpose();
    if (p >= 0) t -= body.joints.row(p).transpose();
    joint.translation = {t.x(), t.y(), t.z()};
    g.nodes.push_back(std::move(joint));
    if (p >= 0) g.nodes[static_cast<size_t>(p + 1)].children.push_back(k + 1);
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

bool ends_with(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) ==
           std::tolower(static_cast<unsigned char>(b));
  });
}

}  // namespace

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

}  // namespace

std::vector<std::uint8_t> glb_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const GltfOptions& options) {
  const std::string s =
      serialise(build_model(model, betas, options, "glb_bytes"), true, "glb_bytes");
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

void write_gltf(const std::string& path, const BodyModel& model,
                const Eigen::Ref<const Eigen::VectorXd>& betas, const GltfOptions& options) {
  const bool binary = ends_with(path, ".glb");
  if (!binary && !ends_with(path, ".gltf")) {
    throw ModelError(path + ": unknown glTF file extension; use .glb (binary) or .gltf (JSON)");
  }
  const std::string bytes = serialise(build_model(model, betas, options, path), binary, path);
  write_file_atomic(path, bytes);
}

// ---------------------------------------------------------------------------------------------
// 4. Accessor reading
// ---------------------------------------------------------------------------------------------
namespace {

// Reads any accessor into a count x components double matrix (normalised integers are mapped
// to [0, 1] as the specification says).
Eigen::MatrixXd read_accessor(const tinygltf::Model& g, int index, const std::string& path,
                              const std::string& what) {
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
  const size_t start = view.byteOffset + a.byteOffset;
  if (a.count > 0 &&
      (start + (a.count - 1) * static_cast<size_t>(stride) + static_cast<size_t>(comps * size) >
           data.size() ||
       start + (a.count - 1) * static_cast<size_t>(stride) + static_cast<size_t>(comps * size) >
           view.byteOffset + view.byteLength)) {
    throw fail("reaches past the end of its buffer: the file is truncated or corrupt");
  }
  Eigen::MatrixXd out(static_cast<Eigen::Index>(a.count), comps);
  for (size_t i = 0; i < a.count; ++i) {
    const unsigned char* p = data.data() + start + i * static_cast<size_t>(stride);
    for (int c = 0; c < comps; ++c) {
      const unsigned char* q = p + c * size;
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
// 5. read_gltf
// ---------------------------------------------------------------------------------------------

GltfAvatar read_gltf(const std::string& path) {
  tinygltf::Model g;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool ok = ends_with(path, ".glb") ? loader.LoadBinaryFromFile(&g, &err, &warn, path)
                                          : loader.LoadASCIIFromFile(&g, &err, &warn, path);
  if (!ok) {
    throw ModelError(path + ": not a readable glTF file: " + (err.empty() ? "unknown error" : err) +
                     (warn.empty() ? "" : " (tinygltf warnings: " + warn + ")"));
  }
  GltfAvatar out;
  if (!warn.empty()) out.warnings.push_back(warn);

  const tinygltf::Node* skinned = nullptr;
  for (const auto& n : g.nodes) {
    if (n.mesh >= 0 && n.skin >= 0) {
      skinned = &n;
      break;
    }
  }
  if (!skinned) throw ModelError(path + ": no node has both a mesh and a skin");
  if (static_cast<size_t>(skinned->mesh) >= g.meshes.size() ||
      static_cast<size_t>(skinned->skin) >= g.skins.size() ||
      g.meshes[static_cast<size_t>(skinned->mesh)].primitives.empty()) {
    throw ModelError(path + ": the skinned node refers to a missing mesh, skin or primitive");
  }
  const auto& prim = g.meshes[static_cast<size_t>(skinned->mesh)].primitives[0];
  auto attribute = [&](const char* name) {
    const auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) {
      throw ModelError(path + ": the skinned mesh has no " + std::string(name) + " attribute");
    }
    return read_accessor(g, it->second, path, name);
  };
  const Eigen::MatrixXd pos = attribute("POSITION");
  if (pos.cols() != 3) throw ModelError(path + ": POSITION is not VEC3");
  out.vertices = pos;
  const Eigen::MatrixXd ids = attribute("JOINTS_0");
  const Eigen::MatrixXd wts = attribute("WEIGHTS_0");
  if (ids.cols() != 4 || wts.cols() != 4 || ids.rows() != pos.rows() || wts.rows() != pos.rows()) {
    throw ModelError(path + ": JOINTS_0/WEIGHTS_0 must be VEC4 with one entry per vertex");
  }
  out.joint_ids = ids.cast<int>();
  for (size_t t = 0; t < prim.targets.size(); ++t) {
    const auto it = prim.targets[t].find("POSITION");
    if (it == prim.targets[t].end()) {
      out.morph_targets.emplace_back(Vertices::Zero(pos.rows(), 3));
      continue;
    }
    const Eigen::MatrixXd d =
        read_accessor(g, it->second, path, "morph target " + std::to_string(t) + " POSITION");
    if (d.rows() != pos.rows() || d.cols() != 3) {
      throw ModelError(path + ": morph target " + std::to_string(t) +
                       " does not have one VEC3 per vertex");
    }
    out.morph_targets.emplace_back(d);
  }
  out.generator = g.asset.generator;
  if (g.asset.extras.IsObject()) {
    for (const auto& key : g.asset.extras.Keys()) {
      const auto& v = g.asset.extras.Get(key);
      if (v.IsString()) out.extras[key] = v.Get<std::string>();
    }
  }
  out.joint_weights = wts;
  if (prim.indices >= 0) {
    const Eigen::MatrixXd idx = read_accessor(g, prim.indices, path, "indices");
    if (idx.size() % 3 != 0) throw ModelError(path + ": the index count is not a multiple of 3");
    out.faces.resize(idx.size() / 3, 3);
    for (Eigen::Index i = 0; i < idx.size(); ++i) {
      const double x = idx(i, 0);
      if (x < 0 || x >= static_cast<double>(pos.rows())) {
        throw ModelError(path + ": index " + std::to_string(x) + " is out of range");
      }
      out.faces.data()[i] = static_cast<std::int32_t>(x);
    }
  }

  // Skeleton: world transforms of every node, then the skin's joints in order.
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
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> world(N);
  std::vector<int> state(N, 0);  // 0 = todo, 1 = in progress, 2 = done
  std::function<void(size_t)> visit = [&](size_t i) {
    if (state[i] == 2) return;
    if (state[i] == 1) throw ModelError(path + ": the node hierarchy has a cycle");
    state[i] = 1;
    const int p = node_parent[i];
    Eigen::Matrix4d parent = Eigen::Matrix4d::Identity();
    if (p >= 0) {
      visit(static_cast<size_t>(p));
      parent = world[static_cast<size_t>(p)];
    }
    world[i] = parent * local_matrix(g.nodes[i]);
    state[i] = 2;
  };
  for (size_t i = 0; i < N; ++i) visit(i);

  const auto& skin = g.skins[static_cast<size_t>(skinned->skin)];
  const auto K = skin.joints.size();
  out.joints.resize(static_cast<Eigen::Index>(K), 3);
  out.joint_names.resize(K);
  out.parents.assign(K, -1);
  for (size_t k = 0; k < K; ++k) {
    const int node = skin.joints[k];
    if (node < 0 || static_cast<size_t>(node) >= N) {
      throw ModelError(path + ": skin joint " + std::to_string(k) + " refers to a missing node");
    }
    out.joints.row(static_cast<Eigen::Index>(k)) =
        world[static_cast<size_t>(node)].topRightCorner<3, 1>().transpose();
    out.joint_names[k] = g.nodes[static_cast<size_t>(node)].name;
    const int pn = node_parent[static_cast<size_t>(node)];
    const auto it = std::find(skin.joints.begin(), skin.joints.end(), pn);
    if (pn >= 0 && it != skin.joints.end()) {
      out.parents[k] = static_cast<int>(it - skin.joints.begin());
    }
  }
  if (out.joint_ids.size() > 0 &&
      (out.joint_ids.minCoeff() < 0 || out.joint_ids.maxCoeff() >= static_cast<int>(K))) {
    throw ModelError(path + ": JOINTS_0 refers to joint " +
                     std::to_string(out.joint_ids.maxCoeff()) + " but the skin has " +
                     std::to_string(K) + " joints");
  }
  return out;
}

}  // namespace smpl
