// FBX export and import of a skinned SMPL-family avatar through Assimp (assimp.org; Debian's
// libassimp 5.2), and the repair of Assimp 5.2's binary FBX (nested null records). The binary FBX
// layout (node records with end offsets, null records closing nested lists, the footer) follows
// the description in Blender's io_scene_fbx (which reads and writes it) and Assimp's FBX reader.
// This is the only translation unit of the project that includes Assimp's headers.
//
// Sections: 1. avatar -> aiScene  2. binary FBX null-record repair  3. write_fbx / fbx_bytes
//           4. read_fbx
#include "smpl/fbx.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <memory>

// Assimp's aiMetadata::Set() draws a false -Wnull-dereference from GCC 12 when inlined here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#pragma GCC diagnostic pop

#include "smpl/atomic_file.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/text.hpp"

namespace smpl {
namespace {

// FBX GlobalSettings UnitScaleFactor: centimetres per file unit. Our files are in metres.
constexpr double kCentimetresPerMetre = 100.0;

aiMatrix4x4 to_ai(const Eigen::Matrix4d& m) {
  aiMatrix4x4 out;  // row-major, like Eigen's (row, col) indexing
  for (unsigned r = 0; r < 4; ++r) {
    for (unsigned c = 0; c < 4; ++c) out[r][c] = static_cast<ai_real>(m(r, c));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// 1. Avatar -> aiScene
// ---------------------------------------------------------------------------------------------

using Transforms = std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>>;

// The body to export and every joint's world transform (its bind matrix). The bind pose is the
// exported pose: Assimp's FBX writer takes each cluster's bind matrix (TransformLink) and the
// scene's BindPose from the nodes, so a pose is baked into the mesh and the skeleton alike (an
// A-pose export is bound in the A-pose).
Body bind_pose(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
               const ExportOptions& options, const std::string& context, Transforms& world) {
  Body body = export_rest_body(model, betas, options, context);
  world.assign(static_cast<size_t>(model.num_joints()), Eigen::Matrix4d::Identity());
  for (int k = 0; k < model.num_joints(); ++k) {
    world[static_cast<size_t>(k)].topRightCorner<3, 1>() = body.joints.row(k).transpose();
  }
  if (options.pose.size() > 0) {
    const double lift = options.stand_on_floor ? body.vertices.col(1).minCoeff() -
                                                     shape(model, betas).vertices.col(1).minCoeff()
                                               : 0.0;
    body = evaluate(model, betas, options.pose);
    body.vertices.col(1).array() += lift;
    body.joints.col(1).array() += lift;
    for (int k = 0; k < model.num_joints(); ++k) {
      world[static_cast<size_t>(k)] = body.transforms[static_cast<size_t>(k)];
      world[static_cast<size_t>(k)](1, 3) += lift;
    }
  }
  return body;
}

// The vertices (split at the texture seams), normals (of the unsplit mesh), texture coordinates
// and triangles of the mesh.
void fill_geometry(aiMesh* mesh, const BodyModel& model, const Body& body, const SeamSplit& split) {
  const bool textured = split.uvs.rows() > 0;
  const auto V = static_cast<unsigned>(split.source.size());
  const auto F = static_cast<unsigned>(model.faces.rows());
  mesh->mNumVertices = V;
  mesh->mVertices = new aiVector3D[V];
  mesh->mNormals = new aiVector3D[V];
  const Vertices normals = vertex_normals(body.vertices, model.faces);
  for (unsigned v = 0; v < V; ++v) {
    const int s = split.source[v];
    mesh->mVertices[v] = aiVector3D(static_cast<ai_real>(body.vertices(s, 0)),
                                    static_cast<ai_real>(body.vertices(s, 1)),
                                    static_cast<ai_real>(body.vertices(s, 2)));
    mesh->mNormals[v] =
        aiVector3D(static_cast<ai_real>(normals(s, 0)), static_cast<ai_real>(normals(s, 1)),
                   static_cast<ai_real>(normals(s, 2)));
  }
  if (textured) {
    mesh->mNumUVComponents[0] = 2;
    mesh->mTextureCoords[0] = new aiVector3D[V];
    for (unsigned v = 0; v < V; ++v) {
      mesh->mTextureCoords[0][v] = aiVector3D(static_cast<ai_real>(split.uvs(v, 0)),
                                              static_cast<ai_real>(split.uvs(v, 1)), 0);
    }
  }
  mesh->mNumFaces = F;
  mesh->mFaces = new aiFace[F];
  for (unsigned f = 0; f < F; ++f) {
    mesh->mFaces[f].mNumIndices = 3;
    mesh->mFaces[f].mIndices = new unsigned[3];
    for (unsigned i = 0; i < 3; ++i) {
      mesh->mFaces[f].mIndices[i] = static_cast<unsigned>(split.faces(f, i));
    }
  }
}

// One bone per joint with every non-zero weight; offset = inverse bind = world[k]^-1.
void add_bones(aiMesh* mesh, const BodyModel& model, const SeamSplit& split,
               const Transforms& world, const std::vector<std::string>& names) {
  const auto V = static_cast<unsigned>(split.source.size());
  const int K = model.num_joints();
  std::vector<std::vector<aiVertexWeight>> weights(static_cast<size_t>(K));
  for (unsigned v = 0; v < V; ++v) {
    for (SparseMatrix::InnerIterator it(model.weights, split.source[v]); it; ++it) {
      if (it.value() != 0.0) {
        weights[static_cast<size_t>(it.col())].emplace_back(v, static_cast<ai_real>(it.value()));
      }
    }
  }
  mesh->mNumBones = static_cast<unsigned>(K);
  mesh->mBones = new aiBone*[static_cast<size_t>(K)];
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    auto* bone = new aiBone();
    mesh->mBones[ks] = bone;
    bone->mName = names[ks];
    bone->mOffsetMatrix = to_ai(world[ks].inverse());
    bone->mNumWeights = static_cast<unsigned>(weights[ks].size());
    bone->mWeights = new aiVertexWeight[weights[ks].size()];
    std::copy(weights[ks].begin(), weights[ks].end(), bone->mWeights);
  }
}

// Nodes: RootNode -> {mesh node, skeleton roots}; joint nodes local to their parents.
void add_nodes(aiScene& scene_ref, const BodyModel& model, const Transforms& world,
               const std::vector<std::string>& names, const ExportOptions& options) {
  aiScene* scene = &scene_ref;
  const int K = model.num_joints();
  auto* mesh_node = new aiNode(options.name);
  mesh_node->mNumMeshes = 1;
  mesh_node->mMeshes = new unsigned[1]{0};
  std::vector<aiNode*> joint_nodes(static_cast<size_t>(K));
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    joint_nodes[ks] = new aiNode(names[ks]);
    const int p = model.parents[ks];
    const Eigen::Matrix4d local =
        p >= 0 ? Eigen::Matrix4d(world[static_cast<size_t>(p)].inverse() * world[ks]) : world[ks];
    joint_nodes[ks]->mTransformation = to_ai(local);
  }
  std::vector<aiNode*> roots = {mesh_node};
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    const int p = model.parents[ks];
    if (p < 0) {
      roots.push_back(joint_nodes[ks]);
    } else {
      joint_nodes[static_cast<size_t>(p)]->addChildren(1, &joint_nodes[ks]);
    }
  }
  scene->mRootNode->addChildren(static_cast<unsigned>(roots.size()), roots.data());
}

std::unique_ptr<aiScene> build_scene(const BodyModel& model,
                                     const Eigen::Ref<const Eigen::VectorXd>& betas,
                                     const ExportOptions& options, const std::string& context) {
  check_pose(model, options, context);
  const std::vector<std::string> names = bone_names(model, options.bone_names);
  Transforms world;
  const Body body = bind_pose(model, betas, options, context, world);
  // Texture seams: an aiMesh has one texture coordinate per vertex, so a model with texture
  // coordinates is split at its seams (SeamSplit); each copy has its source vertex's position,
  // normal (of the unsplit mesh) and weights. Assimp's FBX writer merges the copies back into one
  // control point by position (export_fbx asks it to) and writes the texture coordinates per
  // polygon corner.
  const SeamSplit split = split_at_seams(model, context);

  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("RootNode");
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial*[1];
  scene->mMaterials[0] = new aiMaterial();
  {
    const aiString name("skin");
    scene->mMaterials[0]->AddProperty(&name, AI_MATKEY_NAME);
    const aiColor3D colour(0.80f, 0.62f, 0.52f);
    scene->mMaterials[0]->AddProperty(&colour, 1, AI_MATKEY_COLOR_DIFFUSE);
  }

  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh*[1];
  auto* mesh = new aiMesh();
  scene->mMeshes[0] = mesh;
  mesh->mName = options.name;
  mesh->mMaterialIndex = 0;
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  fill_geometry(mesh, model, body, split);
  add_bones(mesh, model, split, world, names);
  add_nodes(*scene, model, world, names, options);
  // Scene metadata: the unit, which Assimp's FBX writer puts into GlobalSettings. (The extras
  // are added to the mesh's Model node afterwards: Assimp writes no other scene metadata.)
  scene->mMetaData = aiMetadata::Alloc(2);
  scene->mMetaData->Set(0, "UnitScaleFactor", kCentimetresPerMetre);
  scene->mMetaData->Set(1, "OriginalUnitScaleFactor", kCentimetresPerMetre);
  return scene;
}

// ---------------------------------------------------------------------------------------------
// 2. Binary FBX null-record repair
// ---------------------------------------------------------------------------------------------

// A node record: name and properties kept as bytes, children parsed.
struct FbxNode {
  std::string head;  // name length, name and the property list, verbatim
  std::uint64_t num_properties = 0;
  std::uint64_t property_bytes = 0;
  std::vector<FbxNode> children;
};

class FbxReader {
 public:
  FbxReader(const std::string& bytes, bool wide) : b_(bytes), wide_(wide) {}
  std::uint64_t header_size() const { return wide_ ? 25 : 13; }

  std::uint64_t word(std::uint64_t at) const {
    std::uint64_t v = 0;
    if (wide_) {
      std::memcpy(&v, b_.data() + at, 8);
    } else {
      std::uint32_t w;
      std::memcpy(&w, b_.data() + at, 4);
      v = w;
    }
    return v;
  }
  bool null_record_at(std::uint64_t at) const {
    if (at + header_size() > b_.size()) return false;
    for (std::uint64_t i = 0; i < header_size(); ++i) {
      if (b_[at + i] != '\0') return false;
    }
    return true;
  }
  // A plausible node record at `at` ending at most at `limit`.
  bool record_at(std::uint64_t at, std::uint64_t limit) const {
    if (at + header_size() > limit || null_record_at(at)) return false;
    const std::uint64_t end = word(at);
    return end > at + header_size() && end <= limit;
  }
  FbxNode read(std::uint64_t& at, int depth) const {
    if (depth > 64) throw ModelError("FBX nodes nested deeper than 64 levels");
    const std::uint64_t w = wide_ ? 8 : 4;
    const std::uint64_t end = word(at);
    FbxNode n;
    n.num_properties = word(at + w);
    n.property_bytes = word(at + 2 * w);
    const std::uint64_t name_at = at + 3 * w;
    const auto name_len = static_cast<unsigned char>(b_[name_at]);
    const std::uint64_t children_at = name_at + 1 + name_len + n.property_bytes;
    if (children_at > end) throw ModelError("an FBX node's properties run past its end");
    n.head = b_.substr(name_at, children_at - name_at);
    std::uint64_t p = children_at;
    while (p < end) {
      if (null_record_at(p)) {  // a correct file closes the list with a null record
        p += header_size();
        break;
      }
      if (!record_at(p, end)) throw ModelError("an FBX node has a malformed child record");
      n.children.push_back(read(p, depth + 1));
    }
    at = end;
    return n;
  }

 private:
  const std::string& b_;
  bool wide_;
};

void put_word(std::string& out, std::uint64_t v, bool wide) {
  if (wide) {
    out.append(reinterpret_cast<const char*>(&v), 8);
  } else {
    const auto w = static_cast<std::uint32_t>(v);
    out.append(reinterpret_cast<const char*>(&w), 4);
  }
}

void write_node(std::string& out, const FbxNode& n, bool wide) {
  const size_t header = out.size();
  put_word(out, 0, wide);  // end offset, patched below
  put_word(out, n.num_properties, wide);
  put_word(out, n.property_bytes, wide);
  out += n.head;
  if (!n.children.empty()) {
    for (const auto& c : n.children) write_node(out, c, wide);
    out.append(wide ? 25 : 13, '\0');  // the null record closing the nested list
  }
  const std::uint64_t end = out.size();
  if (wide) {
    std::memcpy(&out[header], &end, 8);
  } else {
    const auto e = static_cast<std::uint32_t>(end);
    std::memcpy(&out[header], &e, 4);
  }
}

}  // namespace

namespace {

// The string values of a node's property list (only 'S' and 'L' properties are expected on the
// nodes this is used for); stops at the first other type.
std::vector<std::string> string_properties(const FbxNode& n) {
  std::vector<std::string> out;
  const std::string& h = n.head;
  size_t p = 1 + static_cast<unsigned char>(h[0]);  // skip the name
  for (std::uint64_t i = 0; i < n.num_properties && p < h.size(); ++i) {
    const char type = h[p++];
    if (type == 'L') {
      p += 8;
    } else if (type == 'S' || type == 'R') {
      if (p + 4 > h.size()) break;
      std::uint32_t len;
      std::memcpy(&len, h.data() + p, 4);
      p += 4;
      if (p + len > h.size()) break;
      out.push_back(h.substr(p, len));
      p += len;
    } else {
      break;
    }
  }
  return out;
}

std::string node_name(const FbxNode& n) {
  return n.head.substr(1, static_cast<unsigned char>(n.head[0]));
}

// A `P` record: "name", "KString", "", "U", "value" (a user-defined string property).
FbxNode string_property(const std::string& name, const std::string& value) {
  FbxNode p;
  p.head = std::string(1, '\x01') + "P";
  const std::string fields[5] = {name, "KString", "", "U", value};
  for (const auto& f : fields) {
    p.head += 'S';
    const auto len = static_cast<std::uint32_t>(f.size());
    p.head.append(reinterpret_cast<const char*>(&len), 4);
    p.head += f;
  }
  p.num_properties = 5;
  p.property_bytes = p.head.size() - 2;
  return p;
}

// Parses binary FBX, adds `extras` as user string properties of the mesh's Model node, and
// writes it back with every null record (see fix_fbx_null_records).
std::string finish_fbx(const std::string& bytes, const std::map<std::string, std::string>& extras) {
  static const char kMagic[] = "Kaydara FBX Binary  ";
  if (bytes.size() < 27 + 16 || bytes.compare(0, 20, kMagic) != 0) {
    throw ModelError("not a binary FBX file (no 'Kaydara FBX Binary' header)");
  }
  std::uint32_t version;
  std::memcpy(&version, bytes.data() + 23, 4);
  if (version < 7000 || version >= 8000) {
    throw ModelError("binary FBX version " + std::to_string(version) + " is not 7.x");
  }
  const bool wide = version >= 7500;
  const FbxReader reader(bytes, wide);
  std::vector<FbxNode> top;
  std::uint64_t p = 27;
  while (reader.record_at(p, bytes.size())) top.push_back(reader.read(p, 0));
  if (reader.null_record_at(p)) p += reader.header_size();
  // Footer: a 16-byte id, 4 zero bytes, padding to a multiple of 16 (16 when already aligned),
  // the version, 120 zero bytes and a 16-byte end magic.
  if (bytes.size() < p + 16 + 16) throw ModelError("the binary FBX footer is missing");
  const std::string footer_id = bytes.substr(p, 16);
  const std::string end_magic = bytes.substr(bytes.size() - 16);

  if (!extras.empty()) {
    bool added = false;
    for (auto& object : top) {
      if (node_name(object) != "Objects") continue;
      for (auto& model : object.children) {
        const auto props = string_properties(model);
        if (node_name(model) != "Model" || props.size() < 2 || props.back() != "Mesh") continue;
        for (auto& child : model.children) {
          if (node_name(child) != "Properties70") continue;
          for (const auto& [key, value] : extras) {
            child.children.push_back(string_property(key, value));
          }
          added = true;
          break;
        }
        break;
      }
    }
    if (!added) throw ModelError("Assimp's FBX output has no mesh Model with properties");
  }

  std::string out = bytes.substr(0, 27);
  out.reserve(bytes.size() + bytes.size() / 8);
  for (const auto& n : top) write_node(out, n, wide);
  out.append(wide ? 25 : 13, '\0');
  out += footer_id;
  out.append(4, '\0');
  size_t pad = ((out.size() + 15) & ~size_t{15}) - out.size();
  if (pad == 0) pad = 16;
  out.append(pad, '\0');
  out.append(reinterpret_cast<const char*>(&version), 4);
  out.append(120, '\0');
  out += end_magic;
  return out;
}

}  // namespace

std::string fix_fbx_null_records(const std::string& bytes) {
  return finish_fbx(bytes, {});
}

// ---------------------------------------------------------------------------------------------
// 3. write_fbx / fbx_bytes
// ---------------------------------------------------------------------------------------------

namespace {

std::string export_fbx(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                       const ExportOptions& options, const std::string& context) {
  const std::unique_ptr<aiScene> scene = build_scene(model, betas, options, context);
  Assimp::Exporter exporter;
  // A mesh split at texture seams is welded back into one control point per position by
  // Assimp's FBX writer, which does so only when asked through the JoinIdenticalVertices step
  // (it then also runs that step on its copy of the scene: it joins vertices equal in every
  // attribute, and the seam copies differ in their texture coordinate). Without texture
  // coordinates the scene goes out as before, one control point per model vertex.
  const unsigned steps = model.has_uvs() ? aiProcess_JoinIdenticalVertices : 0u;
  const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), "fbx", steps);
  if (!blob || !blob->data) {
    throw ModelError(context +
                     ": Assimp could not write the FBX file: " + exporter.GetErrorString());
  }
  try {
    return finish_fbx(
        std::string(static_cast<const char*>(blob->data), static_cast<size_t>(blob->size)),
        options.extras);
  } catch (const ModelError& e) {
    throw ModelError(context + ": Assimp's FBX output could not be completed: " + e.what());
  }
}

}  // namespace

std::vector<std::uint8_t> fbx_bytes(const BodyModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& betas,
                                    const ExportOptions& options) {
  const std::string s = export_fbx(model, betas, options, "fbx_bytes");
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

void write_fbx(const std::string& path, const BodyModel& model,
               const Eigen::Ref<const Eigen::VectorXd>& betas, const ExportOptions& options) {
  if (!ends_with_ci(path, ".fbx")) throw ModelError(path + ": an FBX file name must end in .fbx");
  write_file_atomic(path, export_fbx(model, betas, options, path));
}

// ---------------------------------------------------------------------------------------------
// 4. read_fbx
// ---------------------------------------------------------------------------------------------

namespace {

FbxAvatar read_assimp(const std::string& path, const std::string& what) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_JoinIdenticalVertices);
  if (!scene) {
    throw ModelError(path + ": not a readable " + what + " file: " + importer.GetErrorString());
  }
  if (scene->mNumMeshes < 1 || !scene->mMeshes[0]->HasFaces()) {
    throw ModelError(path + ": the " + what + " file has no mesh");
  }
  const aiMesh* mesh = scene->mMeshes[0];
  FbxAvatar out;
  out.vertices.resize(mesh->mNumVertices, 3);
  for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
    for (unsigned c = 0; c < 3; ++c) out.vertices(v, c) = mesh->mVertices[v][c];
  }
  if (mesh->HasNormals()) {
    out.normals.resize(mesh->mNumVertices, 3);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      for (unsigned c = 0; c < 3; ++c) out.normals(v, c) = mesh->mNormals[v][c];
    }
  }
  if (mesh->HasTextureCoords(0)) {
    out.uvs.resize(mesh->mNumVertices, 2);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      for (unsigned c = 0; c < 2; ++c) out.uvs(v, c) = mesh->mTextureCoords[0][v][c];
    }
  }
  out.faces.resize(mesh->mNumFaces, 3);
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    if (mesh->mFaces[f].mNumIndices != 3) {
      throw ModelError(path + ": face " + std::to_string(f) + " is not a triangle");
    }
    for (unsigned i = 0; i < 3; ++i) {
      out.faces(f, i) = static_cast<std::int32_t>(mesh->mFaces[f].mIndices[i]);
    }
  }
  out.weight_sums = Eigen::VectorXd::Zero(mesh->mNumVertices);
  out.bind_joints.resize(mesh->mNumBones, 3);
  for (unsigned b = 0; b < mesh->mNumBones; ++b) {
    const aiBone* bone = mesh->mBones[b];
    out.bone_names.emplace_back(bone->mName.C_Str());
    for (unsigned w = 0; w < bone->mNumWeights; ++w) {
      const unsigned v = bone->mWeights[w].mVertexId;
      if (v < mesh->mNumVertices) out.weight_sums[v] += bone->mWeights[w].mWeight;
    }
    aiMatrix4x4 bind = bone->mOffsetMatrix;
    bind.Inverse();
    out.bind_joints(b, 0) = bind.a4;
    out.bind_joints(b, 1) = bind.b4;
    out.bind_joints(b, 2) = bind.c4;
  }
  if (scene->mMetaData) {
    for (unsigned i = 0; i < scene->mMetaData->mNumProperties; ++i) {
      const std::string key = scene->mMetaData->mKeys[i].C_Str();
      const aiMetadataEntry& e = scene->mMetaData->mValues[i];
      if (key == "UnitScaleFactor") {
        if (e.mType == AI_DOUBLE) out.unit_scale_factor = *static_cast<const double*>(e.mData);
        if (e.mType == AI_FLOAT) out.unit_scale_factor = *static_cast<const float*>(e.mData);
      }
    }
  }
  // The avatar's metadata: user string properties of the node holding the mesh.
  std::vector<const aiNode*> stack = {scene->mRootNode};
  while (!stack.empty()) {
    const aiNode* n = stack.back();
    stack.pop_back();
    if (!n) continue;
    if (n->mNumMeshes > 0 && n->mMetaData) {
      for (unsigned i = 0; i < n->mMetaData->mNumProperties; ++i) {
        if (n->mMetaData->mValues[i].mType == AI_AISTRING) {
          out.metadata[n->mMetaData->mKeys[i].C_Str()] =
              static_cast<const aiString*>(n->mMetaData->mValues[i].mData)->C_Str();
        }
      }
    }
    for (unsigned c = 0; c < n->mNumChildren; ++c) stack.push_back(n->mChildren[c]);
  }
  return out;
}

}  // namespace

FbxAvatar read_fbx(const std::string& path) {
  return read_assimp(path, "FBX");
}

FbxAvatar read_with_assimp(const std::string& path) {
  return read_assimp(path, "mesh");
}

}  // namespace smpl
