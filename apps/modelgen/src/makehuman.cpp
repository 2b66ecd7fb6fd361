/// \file makehuman.cpp
/// Readers for MakeHuman's CC0 asset formats and the skin-mesh selection (makehuman.hpp).
#include "makehuman.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace modelgen::mh {

namespace {

std::string where(const std::string& path, int line_no) {
  return "'" + path + "' line " + std::to_string(line_no);
}

/// Splits on spaces and tabs.
std::vector<std::string_view> tokens(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) {
      ++i;
    }
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') {
      ++j;
    }
    if (j > i) {
      out.push_back(s.substr(i, j - i));
    }
    i = j;
  }
  return out;
}

/// Locale-independent number parsing of a whole token.
double number(std::string_view t, const std::string& path, int line_no) {
  double v = 0.0;
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (!t.empty() && *b == '+') {
    ++b;
  }
  const auto r = std::from_chars(b, e, v);
  if (r.ec != std::errc() || r.ptr != e || !std::isfinite(v)) {
    throw AssetError(where(path, line_no) + ": expected a number, found '" + std::string(t) + "'");
  }
  return v;
}

int integer(std::string_view t, const std::string& path, int line_no) {
  int v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) {
    throw AssetError(where(path, line_no) + ": expected an integer, found '" + std::string(t) +
                     "'");
  }
  return v;
}

std::ifstream open(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw AssetError(std::string("cannot open MakeHuman ") + what + " '" + path +
                     "' (give the folder of the MakeHuman assets with --makehuman DIR)");
  }
  return in;
}

/// Calls `on_line(tokens, line_no)` for every line of the MakeHuman text file `path` (a `what`:
/// "base mesh", "target") that is neither blank nor a '#' comment; line_no is 1-based.
template <class OnLine>
void for_each_line(const std::string& path, const char* what, OnLine on_line) {
  std::ifstream in = open(path, what);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::vector<std::string_view> t = tokens(line);
    if (t.empty() || t[0][0] == '#') {
      continue;
    }
    on_line(t, line_no);
  }
}

nlohmann::json read_json(const std::string& path, const char* what) {
  std::ifstream in = open(path, what);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw AssetError(std::string("MakeHuman ") + what + " '" + path +
                     "' is not valid JSON: " + e.what());
  }
}

const nlohmann::json& key(const nlohmann::json& j, const std::string& k, const std::string& path,
                          const std::string& context) {
  if (!j.is_object() || !j.contains(k)) {
    throw AssetError("'" + path + "': " + context + " has no key '" + k + "'");
  }
  return j.at(k);
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// OBJ
// ------------------------------------------------------------------------------------------------

BaseMesh read_base_mesh(const std::string& path) {
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector2d> vt;
  BaseMesh mesh;
  std::map<std::string, int> group_ids;
  int group = -1;
  for_each_line(path, "base mesh", [&](const std::vector<std::string_view>& t, int line_no) {
    if (t[0] == "v") {
      if (t.size() < 4) {
        throw AssetError(where(path, line_no) + ": a vertex needs 3 coordinates");
      }
      v.emplace_back(number(t[1], path, line_no), number(t[2], path, line_no),
                     number(t[3], path, line_no));
    } else if (t[0] == "vt") {
      if (t.size() < 3) {
        throw AssetError(where(path, line_no) + ": a texture coordinate needs u and v");
      }
      vt.emplace_back(number(t[1], path, line_no), number(t[2], path, line_no));
    } else if (t[0] == "g") {
      const std::string name = t.size() > 1 ? std::string(t[1]) : std::string("default");
      const auto it = group_ids.find(name);
      if (it == group_ids.end()) {
        group = static_cast<int>(mesh.groups.size());
        group_ids.emplace(name, group);
        mesh.groups.push_back(name);
      } else {
        group = it->second;
      }
    } else if (t[0] == "f") {
      const int n = static_cast<int>(t.size()) - 1;
      if (n < 3 || n > 4) {
        throw AssetError(where(path, line_no) + ": a face needs 3 or 4 corners, found " +
                         std::to_string(n));
      }
      ObjFace f;
      f.corners = n;
      f.group = group;
      for (int c = 0; c < n; ++c) {
        const std::string_view s = t[static_cast<std::size_t>(c) + 1];
        const std::size_t slash = s.find('/');
        const int vi = integer(s.substr(0, slash), path, line_no);
        if (vi < 1 || vi > static_cast<int>(v.size())) {
          throw AssetError(where(path, line_no) + ": vertex index " + std::to_string(vi) +
                           " is not among the " + std::to_string(v.size()) +
                           " vertices defined before it (1-based; negative indices unsupported)");
        }
        f.v[static_cast<std::size_t>(c)] = vi - 1;
        if (slash != std::string_view::npos) {
          const std::string_view rest = s.substr(slash + 1);
          const std::string_view ts = rest.substr(0, rest.find('/'));
          if (!ts.empty()) {
            const int ti = integer(ts, path, line_no);
            if (ti < 1 || ti > static_cast<int>(vt.size())) {
              throw AssetError(where(path, line_no) + ": texture coordinate index " +
                               std::to_string(ti) + " is not among the " +
                               std::to_string(vt.size()) + " defined before it");
            }
            f.vt[static_cast<std::size_t>(c)] = ti - 1;
          }
        }
      }
      mesh.faces.push_back(f);
    }
  });
  if (v.empty() || mesh.faces.empty()) {
    throw AssetError("'" + path + "' has no vertices or no faces: not a MakeHuman base mesh");
  }
  mesh.vertices.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) {
    mesh.vertices.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  }
  mesh.uvs.resize(static_cast<Eigen::Index>(vt.size()), 2);
  for (std::size_t i = 0; i < vt.size(); ++i) {
    mesh.uvs.row(static_cast<Eigen::Index>(i)) = vt[i].transpose();
  }
  return mesh;
}

// ------------------------------------------------------------------------------------------------
// Targets
// ------------------------------------------------------------------------------------------------

Target read_target(const std::string& path, int num_vertices) {
  Target target;
  for_each_line(path, "target", [&](const std::vector<std::string_view>& t, int line_no) {
    if (t.size() != 4) {
      throw AssetError(where(path, line_no) + ": expected 'index dx dy dz', found " +
                       std::to_string(t.size()) + " fields");
    }
    const int i = integer(t[0], path, line_no);
    if (i < 0 || i >= num_vertices) {
      throw AssetError(where(path, line_no) + ": vertex index " + std::to_string(i) +
                       " outside the base mesh's " + std::to_string(num_vertices) + " vertices");
    }
    target.index.push_back(i);
    target.delta.emplace_back(number(t[1], path, line_no), number(t[2], path, line_no),
                              number(t[3], path, line_no));
  });
  return target;
}

void add_target(const Target& target, double weight, Positions& positions) {
  for (std::size_t k = 0; k < target.index.size(); ++k) {
    positions.row(target.index[k]) += weight * target.delta[k].transpose();
  }
}

// ------------------------------------------------------------------------------------------------
// Skeleton and weights
// ------------------------------------------------------------------------------------------------

int Skeleton::bone(const std::string& name) const {
  for (std::size_t i = 0; i < bones.size(); ++i) {
    if (bones[i].name == name) {
      return static_cast<int>(i);
    }
  }
  throw AssetError("the MakeHuman skeleton has no bone '" + name + "'");
}

Skeleton read_skeleton(const std::string& path, int num_vertices) {
  const nlohmann::json j = read_json(path, "skeleton");
  Skeleton sk;
  try {
    for (const auto& [name, ids] : key(j, "joints", path, "the file").items()) {
      std::vector<int> list;
      for (const auto& id : ids) {
        const int i = id.get<int>();
        if (i < 0 || i >= num_vertices) {
          throw AssetError("'" + path + "': joint '" + name + "' names vertex " +
                           std::to_string(i) + ", outside the base mesh's " +
                           std::to_string(num_vertices) + " vertices");
        }
        list.push_back(i);
      }
      if (list.empty()) {
        throw AssetError("'" + path + "': joint '" + name + "' has no vertices");
      }
      sk.joints.emplace(name, std::move(list));
    }
    std::vector<Bone> unsorted;
    for (const auto& [name, b] : key(j, "bones", path, "the file").items()) {
      Bone bone;
      bone.name = name;
      bone.head = key(b, "head", path, "bone '" + name + "'").get<std::string>();
      bone.tail = key(b, "tail", path, "bone '" + name + "'").get<std::string>();
      const nlohmann::json& p = key(b, "parent", path, "bone '" + name + "'");
      bone.parent = p.is_null() ? std::string() : p.get<std::string>();
      for (const std::string* jn : {&bone.head, &bone.tail}) {
        if (sk.joints.count(*jn) == 0) {
          throw AssetError("'" + path + "': bone '" + name + "' uses joint '" + *jn +
                           "', which is not in 'joints'");
        }
      }
      unsorted.push_back(std::move(bone));
    }
    // Parents before children: repeatedly take the bones whose parent is placed (name order
    // within a pass, so the result does not depend on the JSON library's map order).
    std::set<std::string> placed;
    while (!unsorted.empty()) {
      std::vector<Bone> rest;
      for (Bone& b : unsorted) {
        if (b.parent.empty() || placed.count(b.parent) != 0) {
          placed.insert(b.name);
          sk.bones.push_back(std::move(b));
        } else {
          rest.push_back(std::move(b));
        }
      }
      if (rest.size() == unsorted.size()) {
        throw AssetError("'" + path + "': bone '" + rest.front().name + "' has parent '" +
                         rest.front().parent + "', which is unknown or part of a cycle");
      }
      unsorted = std::move(rest);
    }
  } catch (const nlohmann::json::exception& e) {
    throw AssetError("'" + path + "': unexpected JSON type: " + e.what());
  }
  return sk;
}

Eigen::Vector3d joint_position(const Skeleton& skeleton, const std::string& joint,
                               const Positions& positions) {
  const auto it = skeleton.joints.find(joint);
  if (it == skeleton.joints.end()) {
    throw AssetError("the MakeHuman skeleton has no joint '" + joint + "'");
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const int i : it->second) {
    sum += positions.row(i).transpose();
  }
  return sum / static_cast<double>(it->second.size());
}

BoneWeights read_weights(const std::string& path, int num_vertices) {
  const nlohmann::json j = read_json(path, "weights");
  BoneWeights out;
  try {
    for (const auto& [bone, pairs] : key(j, "weights", path, "the file").items()) {
      std::vector<std::pair<int, double>> list;
      for (const auto& p : pairs) {
        if (!p.is_array() || p.size() != 2) {
          throw AssetError("'" + path + "': bone '" + bone +
                           "' has an entry that is not a [vertex, weight] pair");
        }
        const int i = p[0].get<int>();
        const double w = p[1].get<double>();
        if (i < 0 || i >= num_vertices) {
          throw AssetError("'" + path + "': bone '" + bone + "' weights vertex " +
                           std::to_string(i) + ", outside the base mesh's " +
                           std::to_string(num_vertices) + " vertices");
        }
        if (!std::isfinite(w) || w < 0.0) {
          throw AssetError("'" + path + "': bone '" + bone + "' has weight " + std::to_string(w) +
                           " for vertex " + std::to_string(i) + " (expected a finite number >= 0)");
        }
        list.emplace_back(i, w);
      }
      out.emplace(bone, std::move(list));
    }
  } catch (const nlohmann::json::exception& e) {
    throw AssetError("'" + path + "': unexpected JSON type: " + e.what());
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// Skin mesh
// ------------------------------------------------------------------------------------------------

namespace {

/// The mirror map of the skin vertices `source` (base-mesh indices): the skin vertex whose
/// base-mesh position is exactly (-x, y, z). MakeHuman's base mesh is built symmetric to the
/// last bit, so the images are looked up exactly, not by nearest neighbour.
std::vector<int> skin_mirror(const BaseMesh& base, const std::vector<int>& source) {
  std::map<std::array<double, 3>, int> at;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(source[i]);
    at.emplace(std::array<double, 3>{base.vertices(r, 0), base.vertices(r, 1), base.vertices(r, 2)},
               static_cast<int>(i));
  }
  std::vector<int> mirror(source.size(), -1);
  for (std::size_t i = 0; i < source.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(source[i]);
    const auto it = at.find({-base.vertices(r, 0), base.vertices(r, 1), base.vertices(r, 2)});
    if (it == at.end()) {
      throw AssetError(
          "the base mesh's skin is not left/right symmetric: the mirror image of "
          "vertex " +
          std::to_string(source[i] + 1) +
          " (1-based, as in base.obj) is not a skin vertex; use MakeHuman's "
          "unmodified hm08 base.obj");
    }
    mirror[i] = it->second;
  }
  return mirror;
}

}  // namespace

SkinMesh skin_mesh(const BaseMesh& base) {
  const auto g = std::find(base.groups.begin(), base.groups.end(), "body");
  if (g == base.groups.end()) {
    throw AssetError("the base mesh has no 'body' group (is it MakeHuman's hm08 base.obj?)");
  }
  const int body = static_cast<int>(g - base.groups.begin());
  const int n = static_cast<int>(base.vertices.rows());
  SkinMesh skin;
  skin.skin_vertex.assign(static_cast<std::size_t>(n), -1);
  std::vector<int> uv_map(static_cast<std::size_t>(base.uvs.rows()), -1);
  std::vector<const ObjFace*> faces;
  for (const ObjFace& f : base.faces) {
    if (f.group != body) {
      continue;
    }
    faces.push_back(&f);
    for (int c = 0; c < f.corners; ++c) {
      skin.skin_vertex[static_cast<std::size_t>(f.v[static_cast<std::size_t>(c)])] = 0;
      const int t = f.vt[static_cast<std::size_t>(c)];
      if (t < 0) {
        throw AssetError("a face of the base mesh's 'body' group has no texture coordinates");
      }
      uv_map[static_cast<std::size_t>(t)] = 0;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (skin.skin_vertex[static_cast<std::size_t>(i)] == 0) {
      skin.skin_vertex[static_cast<std::size_t>(i)] = static_cast<int>(skin.source_vertex.size());
      skin.source_vertex.push_back(i);
    }
  }
  int num_uvs = 0;
  for (int& u : uv_map) {
    if (u == 0) {
      u = num_uvs++;
    }
  }
  skin.uvs.resize(num_uvs, 2);
  for (std::size_t t = 0; t < uv_map.size(); ++t) {
    if (uv_map[t] >= 0) {
      skin.uvs.row(uv_map[t]) = base.uvs.row(static_cast<Eigen::Index>(t));
    }
  }
  std::vector<std::array<int, 6>> tris;  // 3 vertex ids, 3 uv ids
  tris.reserve(faces.size() * 2);
  for (const ObjFace* f : faces) {
    auto corner = [&](int c) {
      const auto cc = static_cast<std::size_t>(c);
      return std::pair<int, int>(skin.skin_vertex[static_cast<std::size_t>(f->v[cc])],
                                 uv_map[static_cast<std::size_t>(f->vt[cc])]);
    };
    auto emit = [&](int a, int b, int c) {
      const auto [va, ta] = corner(a);
      const auto [vb, tb] = corner(b);
      const auto [vc, tc] = corner(c);
      tris.push_back({va, vb, vc, ta, tb, tc});
    };
    if (f->corners == 3) {
      emit(0, 1, 2);
      continue;
    }
    const double d02 = (base.vertices.row(f->v[0]) - base.vertices.row(f->v[2])).squaredNorm();
    const double d13 = (base.vertices.row(f->v[1]) - base.vertices.row(f->v[3])).squaredNorm();
    if (d02 <= d13) {
      emit(0, 1, 2);
      emit(0, 2, 3);
    } else {
      emit(0, 1, 3);
      emit(1, 2, 3);
    }
  }
  skin.faces.resize(static_cast<Eigen::Index>(tris.size()), 3);
  skin.uv_faces.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t k = 0; k < tris.size(); ++k) {
    const auto r = static_cast<Eigen::Index>(k);
    skin.faces.row(r) << tris[k][0], tris[k][1], tris[k][2];
    skin.uv_faces.row(r) << tris[k][3], tris[k][4], tris[k][5];
  }
  skin.mirror = skin_mirror(base, skin.source_vertex);
  return skin;
}

void symmetrize(Eigen::Ref<smpl::Vertices> v, const std::vector<int>& mirror) {
  if (static_cast<Eigen::Index>(mirror.size()) != v.rows()) {
    throw std::invalid_argument("symmetrize: the mirror map has " + std::to_string(mirror.size()) +
                                " entries for " + std::to_string(v.rows()) + " vertices");
  }
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const Eigen::Index m = mirror[static_cast<std::size_t>(i)];
    if (m < i) continue;  // done with its pair
    const double x = 0.5 * (v(i, 0) - v(m, 0));
    const double y = 0.5 * (v(i, 1) + v(m, 1));
    const double z = 0.5 * (v(i, 2) + v(m, 2));
    v.row(i) << x, y, z;
    v.row(m) << -x, y, z;  // the midline (m == i): x = 0
  }
}

smpl::Vertices skin_vertices(const SkinMesh& skin, const Positions& positions) {
  smpl::Vertices out(static_cast<Eigen::Index>(skin.source_vertex.size()), 3);
  for (std::size_t i = 0; i < skin.source_vertex.size(); ++i) {
    out.row(static_cast<Eigen::Index>(i)) = kMetresPerUnit * positions.row(skin.source_vertex[i]);
  }
  return out;
}

}  // namespace modelgen::mh
