// Hostile files (issue 10, "Memory safety and resource exhaustion"): each test builds the
// reproducer in memory or in a temporary folder (small files) and checks that the reader refuses
// it with a clear error, or reads it correctly, without unbounded memory, time or recursion.
// The limits are checked through the readers' own errors and budgets, never by letting the
// machine run out of memory. docs/reliability.md lists these tests per reader.
#include <gtest/gtest.h>

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "caliper_test/random_model.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"
#include "smpl/mesh_read.hpp"
#include "smpl/npz.hpp"
#include "smpl/pickle.hpp"

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

fs::path out_dir(const std::string& name) {
  fs::path d = fs::path(CALIPER_TEST_DATA_DIR) / "hostile" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary).write(s.data(), static_cast<std::streamsize>(s.size()));
}

// The ModelError message of `f`, or "(no error)".
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const smpl::ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

#define EXPECT_HAS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "'"

// ---------------------------------------------------------------------------------------------
// glTF: a minimal skinned triangle (or V-vertex strip) written by hand, so that any field can be
// made hostile.
// ---------------------------------------------------------------------------------------------

std::string base64(const Bytes& b) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < b.size(); i += 3) {
    const std::uint32_t n =
        (b[i] << 16) | ((i + 1 < b.size() ? b[i + 1] : 0) << 8) | (i + 2 < b.size() ? b[i + 2] : 0);
    out += k[(n >> 18) & 63];
    out += k[(n >> 12) & 63];
    out += i + 1 < b.size() ? k[(n >> 6) & 63] : '=';
    out += i + 2 < b.size() ? k[n & 63] : '=';
  }
  return out;
}

template <typename T>
void append(Bytes& b, T v) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}

struct GltfParts {
  int vertices = 3;
  bool float_joints = false;    // JOINTS_0 as float VEC4 (component type 5126)
  float joint_value = 0.0f;     // the first JOINTS_0 value
  std::string position_offset;  // accessor byteOffset of POSITION ("" = 0)
  std::string buffer_uri;       // "" = embedded data URI
  std::string targets;          // the primitive's "targets" JSON ("" = none)
  std::string extras;           // asset.extras JSON ("" = none)
  int chain = 0;                // extra nodes in a parent chain below the joint node
};

// Returns the glTF JSON; `bin` gets the buffer bytes.
std::string make_gltf(const GltfParts& p, Bytes& bin) {
  bin.clear();
  const int V = p.vertices;
  for (int i = 0; i < V; ++i) {  // positions: a grid two vertices wide
    const int column = i % 2, row = i / 2;
    append(bin, static_cast<float>(column));
    append(bin, static_cast<float>(row));
    append(bin, 0.0f);
  }
  const std::size_t joints_at = bin.size();
  for (int i = 0; i < 4 * V; ++i) {
    if (p.float_joints) {
      append(bin, i == 0 ? p.joint_value : 0.0f);
    } else {
      append(bin, static_cast<std::uint8_t>(0));
    }
  }
  while (bin.size() % 4) bin.push_back(0);
  const std::size_t weights_at = bin.size();
  for (int i = 0; i < V; ++i) {
    append(bin, 1.0f);
    append(bin, 0.0f);
    append(bin, 0.0f);
    append(bin, 0.0f);
  }
  const std::size_t indices_at = bin.size();
  for (std::uint32_t i = 0; i < 3; ++i) append(bin, i);
  const std::string uri =
      p.buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(bin) : p.buffer_uri;
  const auto num = [](std::size_t x) { return std::to_string(x); };
  std::string nodes = R"({"mesh":0,"skin":0},{"name":"root","translation":[0,1,0])";
  if (p.chain > 0) nodes += R"(,"children":[2])";
  nodes += "}";
  for (int i = 0; i < p.chain; ++i) {
    nodes += R"(,{"translation":[0,0.001,0])";
    if (i + 1 < p.chain) nodes += R"(,"children":[)" + std::to_string(i + 3) + "]";
    nodes += "}";
  }
  const std::string skin_joint = std::to_string(p.chain > 0 ? 1 + p.chain : 1);
  std::string j =
      R"({"asset":{"version":"2.0")" + (p.extras.empty() ? "" : R"(,"extras":)" + p.extras) + "},";
  j += R"("buffers":[{"byteLength":)" + num(bin.size()) + R"(,"uri":")" + uri + R"("}],)";
  j += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + num(joints_at) +
       R"(},{"buffer":0,"byteOffset":)" + num(joints_at) + R"(,"byteLength":)" +
       num(weights_at - joints_at) + R"(},{"buffer":0,"byteOffset":)" + num(weights_at) +
       R"(,"byteLength":)" + num(indices_at - weights_at) + R"(},{"buffer":0,"byteOffset":)" +
       num(indices_at) + R"(,"byteLength":12}],)";
  j += R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + num(V) +
       R"(,"type":"VEC3")" +
       (p.position_offset.empty() ? "" : R"(,"byteOffset":)" + p.position_offset) + "},";
  j += R"({"bufferView":1,"componentType":)" + std::string(p.float_joints ? "5126" : "5121") +
       R"(,"count":)" + num(V) + R"(,"type":"VEC4"},)";
  j += R"({"bufferView":2,"componentType":5126,"count":)" + num(V) + R"(,"type":"VEC4"},)";
  j += R"({"bufferView":3,"componentType":5125,"count":3,"type":"SCALAR"}],)";
  j += R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"JOINTS_0":1,"WEIGHTS_0":2},)";
  j += R"("indices":3)" + (p.targets.empty() ? "" : R"(,"targets":)" + p.targets) + "}]}],";
  j += R"("skins":[{"joints":[)" + skin_joint + "]}],";
  j += R"("nodes":[)" + nodes + R"(],"scenes":[{"nodes":[0,1]}],"scene":0})";
  return j;
}

std::string read_error(const std::string& json) {
  return error_of([&] {
    smpl::read_gltf_from_memory(reinterpret_cast<const std::uint8_t*>(json.data()), json.size(),
                                "hostile.gltf");
  });
}

TEST(HostileGltf, TheHandMadeAvatarReads) {
  Bytes bin;
  const std::string json = make_gltf({}, bin);
  const smpl::GltfAvatar a = smpl::read_gltf_from_memory(
      reinterpret_cast<const std::uint8_t*>(json.data()), json.size(), "ok.gltf");
  EXPECT_EQ(a.vertices.rows(), 3);
  EXPECT_EQ(a.faces.rows(), 1);
  EXPECT_EQ(a.joints.rows(), 1);
  EXPECT_DOUBLE_EQ(a.joints(0, 1), 1.0);
}

// byteOffset near 2^64: start + count * stride wrapped round to a small number, so the old check
// passed and the read landed before the buffer.
TEST(HostileGltf, AccessorByteOffsetNear2To64IsRefused) {
  for (const char* offset : {"18446744073709551600", "18446744073709551615", "4294967296"}) {
    GltfParts p;
    p.position_offset = offset;
    Bytes bin;
    const std::string e = read_error(make_gltf(p, bin));
    EXPECT_HAS(e, "hostile.gltf");
    EXPECT_HAS(e, "POSITION");
    EXPECT_HAS(e, "reaches past the end of its bufferView");
  }
}

// A 20,000-node parent chain (and a 100,000-node one) is read without recursion; the joint's
// world position is the sum of the chain's translations.
TEST(HostileGltf, DeepNodeChainDoesNotOverflowTheStack) {
  for (int chain : {20000, 100000}) {
    GltfParts p;
    p.chain = chain;
    Bytes bin;
    const std::string json = make_gltf(p, bin);
    const smpl::GltfAvatar a = smpl::read_gltf_from_memory(
        reinterpret_cast<const std::uint8_t*>(json.data()), json.size(), "chain.gltf");
    ASSERT_EQ(a.joints.rows(), 1);
    // 1 + chain * 0.001 summed in double: rounding stays far below 1e-9 for 1e5 terms.
    EXPECT_NEAR(a.joints(0, 1), 1.0 + 0.001 * chain, 1e-9) << chain;
  }
}

TEST(HostileGltf, NodeCycleIsRefused) {
  Bytes bin;
  std::string json = make_gltf({}, bin);
  const std::string root = R"({"name":"root","translation":[0,1,0]})";
  json.replace(json.find(root), root.size(), R"({"name":"root","children":[2]},{"children":[1]})");
  // node 1 -> 2 -> 1: tinygltf or read_gltf must refuse it.
  EXPECT_NE(read_error(json), "(no error)");
}

// Float JOINTS_0 outside int range (or NaN) was cast to int: undefined behaviour.
TEST(HostileGltf, FloatJointsOutOfIntRangeAreRefused) {
  for (float bad : {1e30f, -1e30f, 3e9f, 0.5f, std::numeric_limits<float>::quiet_NaN()}) {
    GltfParts p;
    p.float_joints = true;
    p.joint_value = bad;
    Bytes bin;
    const std::string e = read_error(make_gltf(p, bin));
    EXPECT_HAS(e, "JOINTS_0 holds");
    EXPECT_HAS(e, "not a joint of the skin");
  }
  GltfParts ok;
  ok.float_joints = true;
  Bytes bin;
  const std::string json = make_gltf(ok, bin);
  EXPECT_NO_THROW(smpl::read_gltf_from_memory(reinterpret_cast<const std::uint8_t*>(json.data()),
                                              json.size(), "float-joints.gltf"));
}

// Buffer URIs may only name files inside the glTF file's folder.
TEST(HostileGltf, BufferUrisOutsideTheFolderAreRefused) {
  const fs::path dir = out_dir("gltf_uri");
  fs::create_directories(dir / "models");
  Bytes bin;
  GltfParts probe;
  make_gltf(probe, bin);
  write(dir / "models" / "avatar.bin", std::string(bin.begin(), bin.end()));
  write(dir / "secret.bin", std::string(bin.begin(), bin.end()));  // outside models/
  fs::create_symlink(dir / "secret.bin", dir / "models" / "link.bin");

  // A relative name inside the folder is read.
  GltfParts good;
  good.buffer_uri = "avatar.bin";
  write(dir / "models" / "good.gltf", make_gltf(good, bin));
  EXPECT_EQ(smpl::read_gltf((dir / "models" / "good.gltf").string()).vertices.rows(), 3);

  const std::vector<std::pair<std::string, std::string>> cases = {
      {"../../../etc/passwd", "leaves the folder"},
      {"../secret.bin", "leaves the folder"},
      {"%2e%2e/secret.bin", "leaves the folder"},
      {"sub/../../secret.bin", "leaves the folder"},
      {(dir / "secret.bin").string(), "absolute paths"},
      {"/etc/passwd", "absolute paths"},
      {"file:///etc/passwd", "URI schemes"},
      {"http://example.com/avatar.bin", "URI schemes"},
      {"link.bin", "outside the folder"},
  };
  for (const auto& [uri, why] : cases) {
    GltfParts p;
    p.buffer_uri = uri;
    const fs::path file = dir / "models" / "bad.gltf";
    write(file, make_gltf(p, bin));
    const std::string e = error_of([&] { smpl::read_gltf(file.string()); });
    EXPECT_HAS(e, "bad.gltf");
    EXPECT_HAS(e, "refused to read the external file");
    EXPECT_HAS(e, why);
  }
  // In memory, no external file at all.
  GltfParts p;
  p.buffer_uri = "avatar.bin";
  EXPECT_HAS(read_error(make_gltf(p, bin)), "external files are not read here");
}

TEST(HostileGltf, DeeplyNestedJsonIsRefused) {
  GltfParts p;
  p.extras = R"({"a":)" + std::string(100000, '[') + std::string(100000, ']') + "}";
  Bytes bin;
  EXPECT_HAS(read_error(make_gltf(p, bin)), "nests arrays and objects more than 128 levels");
}

// A GLB whose buffer says byteLength 0 beside a non-empty BIN chunk: tinygltf's own parser throws
// std::out_of_range (vector::at on an empty vector; found by fuzz_gltf in CI). It must come out as
// a ModelError naming the file, like every other malformed file.
TEST(HostileGltf, EmptyBufferBesideABinChunkIsRefused) {
  std::string json = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":0}]})";
  while (json.size() % 4 != 0) json += ' ';
  const Bytes bin_chunk = {1, 2, 3, 4};
  Bytes glb;
  const auto put32 = [&glb](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) glb.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  const auto total = static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin_chunk.size());
  glb = {'g', 'l', 'T', 'F'};
  put32(2);
  put32(total);
  put32(static_cast<std::uint32_t>(json.size()));
  put32(0x4E4F534Au);  // "JSON"
  glb.insert(glb.end(), json.begin(), json.end());
  put32(static_cast<std::uint32_t>(bin_chunk.size()));
  put32(0x004E4942u);  // "BIN\0"
  glb.insert(glb.end(), bin_chunk.begin(), bin_chunk.end());
  const std::string e =
      error_of([&] { smpl::read_gltf_from_memory(glb.data(), glb.size(), "empty-buffer.glb"); });
  EXPECT_HAS(e, "empty-buffer.glb");
  EXPECT_HAS(e, "not a readable glTF file");
}

// 20,000 morph targets sharing one 10,000-vertex accessor would make 4.8 GB of doubles from a
// file of under 1 MB: the decoded-bytes budget refuses it before anything large is made.
TEST(HostileGltf, MorphTargetsSharingAnAccessorHitTheBudget) {
  GltfParts p;
  p.vertices = 10000;
  p.targets = "[";
  for (int t = 0; t < 20000; ++t) p.targets += std::string(t ? "," : "") + R"({"POSITION":0})";
  p.targets += "]";
  Bytes bin;
  const std::string json = make_gltf(p, bin);
  ASSERT_LT(json.size(), std::size_t{1} << 20);
  EXPECT_HAS(read_error(json), "would make the decoded data larger than 16 times");
  // Targets without POSITION (zero displacements) are charged too.
  p.targets = "[" + std::string(20000 * 3 - 1, ' ') + "]";
  for (int t = 0; t < 20000; ++t) p.targets.replace(1 + 3 * static_cast<std::size_t>(t), 2, "{}");
  for (std::size_t i = 3; i < p.targets.size() - 1; i += 3) p.targets[i] = ',';
  EXPECT_HAS(read_error(make_gltf(p, bin)), "would make the decoded data larger");
}

// ---------------------------------------------------------------------------------------------
// Pickle
// ---------------------------------------------------------------------------------------------

std::string u32(std::uint32_t v) {
  std::string s(4, '\0');
  for (int i = 0; i < 4; ++i) s[static_cast<std::size_t>(i)] = static_cast<char>(v >> (8 * i));
  return s;
}
std::string str(const std::string& s) {  // SHORT_BINSTRING / BINSTRING
  if (s.size() < 256) return "U" + std::string(1, static_cast<char>(s.size())) + s;
  return "T" + u32(static_cast<std::uint32_t>(s.size())) + s;
}
std::string key(int i) {
  std::string k = "k" + std::to_string(i);
  return str(k);
}

smpl::PickleDict parse_pickle(const std::string& s, const smpl::PickleLimits& limits = {}) {
  return smpl::parse_pickle(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), "h.pkl",
                            limits);
}

// set(list) REDUCE on one 200,000-item list, 20,000 times: the old unpickler copied the list
// into every set (32 GB). Sets now keep no copy; every container slot is charged to the
// decoded-bytes budget, so a copy would show up as a budget error here.
TEST(HostilePickle, SetOfASharedListCopiesNothing) {
  std::string s = "\x80\x02";
  s += "K\x01q\x03";  // memo 3: an int
  s += "](";          // the list
  for (int i = 0; i < 200000; ++i) s += "h\x03";
  s += "eq\x02";                    // memo 2: the list
  s += "c__builtin__\nset\nq\x01";  // memo 1: set
  s += "0";                         // pop it
  s += "}(";
  for (int i = 0; i < 20000; ++i) s += key(i) + "h\x01h\x02\x85R";
  s += "u.";
  ASSERT_LT(s.size(), std::size_t{1} << 20);
  // A tight budget: 32 bytes per input byte and no slack (the copies would need 40,000 per byte).
  smpl::PickleLimits tight;
  tight.decoded_per_input_byte = 32;
  tight.decoded_slack = 0;
  const smpl::PickleDict d = parse_pickle(s, tight);
  ASSERT_EQ(d.size(), 20000u);
  EXPECT_EQ(d.at("k19999").type_name, "set");
  EXPECT_EQ(parse_pickle(s).size(), 20000u);  // and with the default limits
}

// One 1 MiB array referenced from 2,000 keys through the memo: the result would hold 2 GB of
// copies. The budget (8 bytes per input byte + 16 MiB) refuses it with a clear message.
TEST(HostilePickle, MemoReferencesToABigArrayHitTheBudget) {
  const std::string raw(std::size_t{1} << 20, '\0');
  const std::string zero("K\0", 2);  // BININT1 0
  auto dtype = [&] {
    return std::string("cnumpy\ndtype\n(") + str("f8") + zero + "K\x01tR(K\x03" + str("<") +
           "NNNJ" + u32(0xFFFFFFFF) + "J" + u32(0xFFFFFFFF) + zero + "tb";
  };
  std::string array = "cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\n" + zero + "\x85" +
                      str("b") + "\x87R(K\x01(" + "J" + u32(131072) + "t" + dtype() + "\x89" +
                      str(raw) + "tb";
  std::string s = "\x80\x02}(" + key(0) + array + "q\x07";
  for (int i = 1; i < 2000; ++i) s += key(i) + "h\x07";
  s += "u.";
  const std::string e = error_of([&] { parse_pickle(s); });
  EXPECT_HAS(e, "h.pkl");
  EXPECT_HAS(e, "decoding needs more than");
  EXPECT_HAS(e, "the result's arrays");
  // Two references are fine.
  std::string two = "\x80\x02}(" + key(0) + array + "q\x07" + key(1) + "h\x07u.";
  const smpl::PickleDict d = parse_pickle(two);
  EXPECT_EQ(d.at("k1").array.data.size(), raw.size());
}

// A huge tuple shared through the memo as REDUCE arguments or BUILD state is refused by its
// length before anything is copied.
TEST(HostilePickle, HugeSharedArgumentTuplesAreNotCopied) {
  std::string s = "\x80\x02Nq\x01(";
  for (int i = 0; i < 100000; ++i) s += "h\x01";
  s += "tq\x02"
       "c__builtin__\nset\nh\x02R}(" +
       key(0) + "Nu.";
  EXPECT_HAS(error_of([&] { parse_pickle(s); }), "with 100000 arguments (at most 4 are taken)");
}

// ---------------------------------------------------------------------------------------------
// .npz
// ---------------------------------------------------------------------------------------------

struct ZipMember {
  std::string name;
  std::uint16_t method = 0;
  std::uint32_t crc = 0;
  Bytes data;  // as stored (deflated for method 8)
  std::uint64_t uncompressed = 0;
};

void put(Bytes& b, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

// A zip of `members`; `aliases` adds central directory entries named aliases[i] that point at
// member 0's local header.
Bytes make_zip(const std::vector<ZipMember>& members,
               const std::vector<std::string>& aliases = {}) {
  Bytes out, central;
  std::uint64_t first_offset = 0;
  auto entry = [&](const ZipMember& m, const std::string& name, std::uint64_t offset) {
    put(central, 0x02014b50, 4);
    put(central, 20, 2);
    put(central, 20, 2);
    put(central, 0, 2);
    put(central, m.method, 2);
    put(central, 0, 4);
    put(central, m.crc, 4);
    put(central, m.data.size(), 4);
    put(central, m.uncompressed, 4);
    put(central, name.size(), 2);
    put(central, 0, 2);
    put(central, 0, 2);
    put(central, 0, 2);
    put(central, 0, 2);
    put(central, 0, 4);
    put(central, offset, 4);
    central.insert(central.end(), name.begin(), name.end());
  };
  for (std::size_t i = 0; i < members.size(); ++i) {
    const ZipMember& m = members[i];
    const std::uint64_t offset = out.size();
    if (i == 0) first_offset = offset;
    put(out, 0x04034b50, 4);
    put(out, 20, 2);
    put(out, 0, 2);
    put(out, m.method, 2);
    put(out, 0, 4);
    put(out, m.crc, 4);
    put(out, m.data.size(), 4);
    put(out, m.uncompressed, 4);
    put(out, m.name.size(), 2);
    put(out, 0, 2);
    out.insert(out.end(), m.name.begin(), m.name.end());
    out.insert(out.end(), m.data.begin(), m.data.end());
    entry(m, m.name, offset);
  }
  for (const std::string& a : aliases) entry(members[0], a, first_offset);
  const std::uint64_t cd_offset = out.size();
  const std::size_t n = members.size() + aliases.size();
  out.insert(out.end(), central.begin(), central.end());
  put(out, 0x06054b50, 4);
  put(out, 0, 4);
  put(out, n, 2);
  put(out, n, 2);
  put(out, central.size(), 4);
  put(out, cd_offset, 4);
  put(out, 0, 2);
  return out;
}

std::uint32_t crc(const Bytes& b) {
  return static_cast<std::uint32_t>(crc32_z(crc32_z(0L, Z_NULL, 0), b.data(), b.size()));
}

Bytes deflate(const Bytes& in) {
  z_stream zs{};
  deflateInit2(&zs, 9, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY);
  Bytes out(deflateBound(&zs, static_cast<uLong>(in.size())));
  zs.next_in = const_cast<Bytef*>(in.data());
  zs.avail_in = static_cast<uInt>(in.size());
  zs.next_out = out.data();
  zs.avail_out = static_cast<uInt>(out.size());
  deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

// The members of a small valid model, stored.
std::vector<ZipMember> model_members() {
  const smpl::BodyModel m = caliper::test::make_random_model(4, 24, false, 5);
  std::vector<ZipMember> out;
  for (const auto& [k, a] : smpl::model_arrays(m)) {
    ZipMember z;
    z.name = k + ".npy";
    z.data = smpl::npy_bytes(a);
    z.crc = crc(z.data);
    z.uncompressed = z.data.size();
    out.push_back(std::move(z));
  }
  return out;
}

smpl::BodyModel load(const Bytes& b) {
  return smpl::load_model_from_memory(b.data(), b.size(), "bomb.npz");
}

// A 1 MiB deflated member that the model never uses claims 1 GiB: the loader never inflates it.
// Its deflate data is garbage, so inflating it at all would be an error (the old loader parsed
// every member and failed here).
TEST(HostileNpz, UnusedZipBombCostsNothing) {
  std::vector<ZipMember> members = model_members();
  ZipMember bomb;
  bomb.name = "bomb.npy";
  bomb.method = 8;
  bomb.data.assign(std::size_t{1} << 20, 0xFF);
  bomb.uncompressed = std::uint64_t{1} << 30;
  members.push_back(bomb);
  const Bytes zip = make_zip(members);
  const smpl::BodyModel m = load(zip);
  EXPECT_EQ(m.num_joints(), 24);
  const smpl::NpzReader reader(zip.data(), zip.size(), "bomb.npz");
  EXPECT_TRUE(reader.has("bomb"));
  EXPECT_HAS(error_of([&] { reader.array("bomb"); }), "corrupt deflate data");
}

// 30 directory entries pointing at one member (each would be inflated again) are refused.
TEST(HostileNpz, OverlappingMembersAreRefused) {
  std::vector<ZipMember> members = model_members();
  std::vector<std::string> aliases;
  aliases.reserve(30);
  for (int i = 0; i < 30; ++i) aliases.push_back("alias" + std::to_string(i) + ".npy");
  const Bytes zip = make_zip(members, aliases);
  const std::string e = error_of([&] { load(zip); });
  EXPECT_HAS(e, "bomb.npz");
  EXPECT_HAS(e, "overlap");
  EXPECT_HAS(e, "several directory entries point at the same data");
  EXPECT_HAS(error_of([&] { smpl::parse_npz(zip.data(), zip.size(), "bomb.npz"); }), "overlap");
  // The same name twice is refused too.
  EXPECT_HAS(error_of([&] { load(make_zip(members, {members[0].name})); }), "overlap");
}

// The .npy header of v_template declares 1 element; the member really inflates to 16 MiB more
// (and the directory says so). The old reader inflated everything and accepted the trailing
// bytes; now nothing past the header is inflated.
TEST(HostileNpz, InflationIsBoundedByTheNpyHeader) {
  const Bytes header = smpl::npy_bytes(smpl::make_npy(std::vector<double>{1.0}, {1}));
  Bytes npy = header;
  npy.resize(npy.size() + (std::size_t{16} << 20), 0);
  ZipMember m;
  m.name = "a.npy";
  m.method = 8;
  m.data = deflate(npy);
  m.crc = crc(npy);
  m.uncompressed = npy.size();
  const Bytes zip = make_zip({m});
  const std::string e = error_of([&] { smpl::parse_npz(zip.data(), zip.size(), "bound.npz"); });
  EXPECT_HAS(e, "member 'a.npy'");
  EXPECT_HAS(e, "the .npy header declares " + std::to_string(header.size()));
  EXPECT_HAS(e, "nothing more was inflated");
  // The directory agrees with the header but the stream goes on: inflation stops one byte past
  // the declared size.
  ZipMember longer = m;
  longer.uncompressed = header.size();
  const Bytes more = make_zip({longer});
  EXPECT_HAS(error_of([&] { smpl::parse_npz(more.data(), more.size(), "more.npz"); }),
             "the deflate data gives more than the " + std::to_string(header.size()) + " bytes");
  // The honest member reads.
  ZipMember ok = m;
  ok.data = deflate(header);
  ok.crc = crc(header);
  ok.uncompressed = header.size();
  const Bytes good = make_zip({ok});
  EXPECT_EQ(smpl::parse_npz(good.data(), good.size(), "ok.npz").at("a").to_double(),
            std::vector<double>{1.0});
}

// ---------------------------------------------------------------------------------------------
// PLY and OBJ
// ---------------------------------------------------------------------------------------------

std::string ply_error(const std::string& s) {
  return error_of(
      [&] { smpl::parse_ply(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), "h.ply"); });
}

// `element vertex 3000000000` in an 80-byte file: counts are bounded by the bytes left before
// anything is allocated.
TEST(HostileMesh, PlyCountsAreBoundedByTheBytesLeft) {
  const std::string no_props = "ply\nformat ascii 1.0\nelement vertex 3000000000\nend_header\n";
  ASSERT_LE(no_props.size(), 80u);
  EXPECT_HAS(ply_error(no_props), "'vertex' has 3000000000 entries but no properties");
  const std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3000000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n" +
      std::string(12, '\0');
  EXPECT_HAS(ply_error(binary), "claims 3000000000 entries of at least 12 bytes");
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3000000000\nproperty float x\nend_header\n0 0 0\n";
  EXPECT_HAS(ply_error(ascii), "claims 3000000000 entries");
  // A face list claiming 4 billion indices in a few bytes.
  std::string list =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  list += std::string(12, '\0') + std::string("\xff\xff\xff\xff", 4);
  EXPECT_HAS(ply_error(list), "PLY list count");
}

TEST(HostileMesh, PlyValuesAreCheckedBeforeConversion) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(ply_error(head + "3 0 1 2\n"), "(no error)");
  EXPECT_HAS(ply_error(head + "3 0 1 1e10\n"), "PLY face index");
  EXPECT_HAS(ply_error(head + "3 0 1 2.5\n"), "PLY face index");
  EXPECT_HAS(ply_error(head + "3 0 1 7\n"), "face index 7 is out of range (3 vertices");
  EXPECT_HAS(ply_error(head + "1e300 0 1 2\n"), "PLY list count");
  std::string float_count = head;
  float_count.replace(float_count.find("list uchar"), 10, "list float");
  EXPECT_HAS(ply_error(float_count + "3 0 1 2\n"), "list counts must be integers");
  const smpl::MeshData m = smpl::parse_ply(
      reinterpret_cast<const std::uint8_t*>((head + "3 0 1 2\n").data()), head.size() + 8, "ok");
  EXPECT_EQ(m.vertices.rows(), 3);
  EXPECT_EQ(m.faces.rows(), 1);
}

// OBJ face index 4294967298 wrapped to vertex 1 through the int32 cast.
TEST(HostileMesh, ObjFaceIndicesDoNotWrap) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  auto obj_error = [](const std::string& s) {
    return error_of([&] { smpl::parse_obj(s, "h.obj"); });
  };
  EXPECT_EQ(obj_error(v + "f 1 2 3\n"), "(no error)");
  EXPECT_HAS(obj_error(v + "f 1 2 4294967298\n"), "h.obj:4: face index 4294967298 is out of range");
  EXPECT_HAS(obj_error(v + "f 1 2 99999999999999999999\n"), "bad face index");
  EXPECT_HAS(obj_error(v + "f 1 2 -4\n"), "out of range");
  EXPECT_HAS(obj_error(v + "f 1 2 4\n"), "face index 3 is out of range (3 vertices");
  EXPECT_HAS(obj_error(v + "f 1 2 3x\n"), "bad face index");
  EXPECT_HAS(obj_error("v 1e999 0 0\n"), "malformed vertex line");
  const smpl::MeshData m = smpl::parse_obj(v + "f 1/1/1 2//2 -1\n", "ok.obj");
  EXPECT_EQ(m.faces(0, 2), 2);
}

// The readers give back what the writers wrote.
TEST(HostileMesh, ObjAndPlyRoundTrip) {
  const smpl::BodyModel model = caliper::test::make_random_model(2, 24, false, 3);
  const fs::path dir = out_dir("mesh");
  smpl::write_obj((dir / "a.obj").string(), model.v_template, model.faces);
  smpl::write_ply((dir / "a.ply").string(), model.v_template, model.faces);
  for (const smpl::MeshData& m :
       {smpl::read_obj((dir / "a.obj").string()), smpl::read_ply((dir / "a.ply").string())}) {
    EXPECT_EQ(m.faces, model.faces);
    // Both files hold float32 (PLY) or 6+ significant digits (OBJ): 1e-5 m is far above both.
    EXPECT_LT((m.vertices - model.v_template).cwiseAbs().maxCoeff(), 1e-5);
  }
}

}  // namespace
