// .npz archives: the zip container (PKWARE APPNOTE.TXT 6.3: local headers, central directory,
// end of central directory, zip64 records and extra fields), stored and deflated members (RFC 1951
// through zlib's raw inflate), CRC-32 checked.
#include <limits>

#include <zlib.h>

#include "smpl/npz.hpp"

namespace smpl {
namespace {

[[noreturn]] void fail(const std::string& context, const std::string& what) {
  throw ModelError(context + ": " + what);
}

constexpr std::uint32_t kLocalSig = 0x04034b50;
constexpr std::uint32_t kCentralSig = 0x02014b50;
constexpr std::uint32_t kEndSig = 0x06054b50;
constexpr std::uint32_t kEnd64Sig = 0x06064b50;
constexpr std::uint32_t kEnd64LocatorSig = 0x07064b50;
// Deflate cannot expand data by more than 1032:1; a larger claim is a corrupt or hostile file.
constexpr std::uint64_t kMaxDeflateRatio = 1032;
// No model array comes near this (SMPL-X's 400-component shapedirs are 100 MB).
constexpr std::uint64_t kMaxMember = std::uint64_t{16} << 30;

std::uint64_t le(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void put(std::vector<std::uint8_t>& out, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFF));
}

std::uint32_t crc_of(const std::uint8_t* p, std::size_t n) {
  uLong crc = crc32_z(0L, Z_NULL, 0);
  return static_cast<std::uint32_t>(crc32_z(crc, p, n));
}

// Inflates raw deflate data that the zip directory says gives `out_size` bytes. The output grows
// with the data actually produced (no allocation of the claimed size up front).
std::vector<std::uint8_t> inflate_raw(const std::uint8_t* in, std::size_t in_size,
                                      std::size_t out_size, const std::string& context) {
  constexpr std::size_t kChunk = std::numeric_limits<uInt>::max();
  constexpr std::size_t kInitial = std::size_t{64} << 20;
  std::vector<std::uint8_t> out(std::min(out_size, kInitial));
  z_stream zs{};
  if (inflateInit2(&zs, -15) != Z_OK) fail(context, "zlib inflateInit2 failed");
  zs.next_in = const_cast<Bytef*>(in);
  std::size_t in_left = in_size;
  std::size_t produced = 0;
  int rc = Z_OK;
  std::string problem;
  while (true) {
    if (produced == out.size() && out.size() < out_size) {
      out.resize(std::min(out_size, 2 * out.size()));
    }
    const std::size_t in_chunk = std::min(in_left, kChunk);
    const std::size_t out_chunk = std::min(out.size() - produced, kChunk);
    zs.next_out = out.data() + produced;
    zs.avail_in = static_cast<uInt>(in_chunk);
    zs.avail_out = static_cast<uInt>(out_chunk);
    rc = inflate(&zs, Z_NO_FLUSH);
    in_left -= in_chunk - zs.avail_in;
    produced += out_chunk - zs.avail_out;
    if (rc == Z_STREAM_END) break;
    if (rc == Z_OK) continue;
    if (rc == Z_BUF_ERROR && produced == out_size) {
      problem = "the deflate data gives more than the " + std::to_string(out_size) +
                " bytes the zip directory says";
    } else if (rc == Z_BUF_ERROR) {
      problem = "truncated deflate data";
    } else {
      problem =
          std::string("corrupt deflate data") + (zs.msg ? std::string(" (") + zs.msg + ")" : "");
    }
    break;
  }
  inflateEnd(&zs);
  if (!problem.empty()) fail(context, problem);
  if (produced != out_size) {
    fail(context, "deflate data gives " + std::to_string(produced) +
                      " bytes, the zip directory says " + std::to_string(out_size));
  }
  return out;
}

std::vector<std::uint8_t> deflate_raw(const std::vector<std::uint8_t>& in) {
  z_stream zs{};
  if (deflateInit2(&zs, 6, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw ModelError("zlib deflateInit2 failed");
  }
  std::vector<std::uint8_t> out(deflateBound(&zs, static_cast<uLong>(in.size())));
  zs.next_in = const_cast<Bytef*>(in.data());
  zs.avail_in = static_cast<uInt>(in.size());
  zs.next_out = out.data();
  zs.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  if (rc != Z_STREAM_END) throw ModelError("zlib deflate failed");
  return out;
}

struct Member {
  std::string name;
  std::uint16_t method = 0;
  std::uint16_t flags = 0;
  std::uint32_t crc = 0;
  std::uint64_t compressed = 0;
  std::uint64_t uncompressed = 0;
  std::uint64_t local_offset = 0;
};

}  // namespace

NpzArchive parse_npz(const std::uint8_t* bytes, std::size_t size, const std::string& context) {
  // End of central directory: the last signature whose comment fits the file.
  if (size < 22)
    fail(context, "truncated or not a zip/.npz file (" + std::to_string(size) + " bytes)");
  std::size_t eocd = std::numeric_limits<std::size_t>::max();
  const std::size_t lowest = size >= 22 + 65535 ? size - 22 - 65535 : 0;
  for (std::size_t pos = size - 22 + 1; pos-- > lowest;) {
    if (le(bytes + pos, 4) == kEndSig && pos + 22 + le(bytes + pos + 20, 2) <= size) {
      eocd = pos;
      break;
    }
  }
  if (eocd == std::numeric_limits<std::size_t>::max()) {
    fail(context, "not a zip/.npz file or truncated (no end-of-central-directory record)");
  }
  std::uint64_t entries = le(bytes + eocd + 10, 2);
  std::uint64_t cd_size = le(bytes + eocd + 12, 4);
  std::uint64_t cd_offset = le(bytes + eocd + 16, 4);
  if (entries == 0xFFFF || cd_size == 0xFFFFFFFF || cd_offset == 0xFFFFFFFF) {
    if (eocd < 20 || le(bytes + eocd - 20, 4) != kEnd64LocatorSig) {
      fail(context, "bad zip: zip64 end-of-central-directory locator missing");
    }
    const std::uint64_t e64 = le(bytes + eocd - 20 + 8, 8);
    if (e64 > size || size - e64 < 56 || le(bytes + e64, 4) != kEnd64Sig) {
      fail(context, "bad zip: zip64 end-of-central-directory record missing or truncated");
    }
    entries = le(bytes + e64 + 32, 8);
    cd_size = le(bytes + e64 + 40, 8);
    cd_offset = le(bytes + e64 + 48, 8);
  }
  if (cd_offset > size || cd_size > size - cd_offset) {
    fail(context, "truncated or bad zip: the central directory lies outside the file");
  }
  // Central directory.
  std::vector<Member> members;
  std::size_t pos = cd_offset;
  const std::size_t cd_end = cd_offset + cd_size;
  for (std::uint64_t i = 0; i < entries; ++i) {
    if (cd_end - pos < 46 || le(bytes + pos, 4) != kCentralSig) {
      fail(context, "bad zip: central directory entry " + std::to_string(i) + " is corrupt");
    }
    const std::uint8_t* h = bytes + pos;
    Member m;
    m.flags = static_cast<std::uint16_t>(le(h + 8, 2));
    m.method = static_cast<std::uint16_t>(le(h + 10, 2));
    m.crc = static_cast<std::uint32_t>(le(h + 16, 4));
    m.compressed = le(h + 20, 4);
    m.uncompressed = le(h + 24, 4);
    const std::size_t name_len = le(h + 28, 2);
    const std::size_t extra_len = le(h + 30, 2);
    const std::size_t comment_len = le(h + 32, 2);
    m.local_offset = le(h + 42, 4);
    if (cd_end - pos - 46 < name_len + extra_len + comment_len) {
      fail(context, "bad zip: central directory entry " + std::to_string(i) + " is truncated");
    }
    m.name.assign(reinterpret_cast<const char*>(h + 46), name_len);
    // zip64 extended information: the fields whose 32-bit value is 0xFFFFFFFF, in this order.
    const std::uint8_t* x = h + 46 + name_len;
    std::size_t xpos = 0;
    while (xpos + 4 <= extra_len) {
      const std::uint64_t id = le(x + xpos, 2);
      const std::size_t len = le(x + xpos + 2, 2);
      if (xpos + 4 + len > extra_len) break;
      if (id == 0x0001) {
        std::size_t f = xpos + 4;
        const std::size_t fend = xpos + 4 + len;
        auto field = [&](std::uint64_t& v) {
          if (v != 0xFFFFFFFF) return;
          if (f + 8 > fend) fail(context, "bad zip: zip64 field of '" + m.name + "' is truncated");
          v = le(x + f, 8);
          f += 8;
        };
        field(m.uncompressed);
        field(m.compressed);
        field(m.local_offset);
      }
      xpos += 4 + len;
    }
    members.push_back(m);
    pos += 46 + name_len + extra_len + comment_len;
  }
  // Members.
  NpzArchive out;
  for (const Member& m : members) {
    const std::string where = context + " member '" + m.name + "'";
    const std::string suffix = ".npy";
    if (m.name.size() < suffix.size() ||
        m.name.compare(m.name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    if (m.flags & 1) fail(where, "encrypted zip members are not supported");
    if (m.local_offset > size || size - m.local_offset < 30 ||
        le(bytes + m.local_offset, 4) != kLocalSig) {
      fail(where, "truncated or bad zip: the local header is missing");
    }
    const std::uint8_t* h = bytes + m.local_offset;
    const std::uint64_t start = m.local_offset + 30 + le(h + 26, 2) + le(h + 28, 2);
    if (start > size || m.compressed > size - start) {
      fail(where, "truncated: the member's data runs past the end of the file (" +
                      std::to_string(m.compressed) + " bytes from offset " + std::to_string(start) +
                      ", file size " + std::to_string(size) + ")");
    }
    const std::uint8_t* data = bytes + start;
    std::vector<std::uint8_t> inflated;
    const std::uint8_t* npy = data;
    std::size_t npy_size = 0;
    if (m.method == 0) {
      if (m.compressed != m.uncompressed) fail(where, "bad zip: stored member sizes disagree");
      npy_size = static_cast<std::size_t>(m.compressed);
    } else if (m.method == 8) {
      if (m.uncompressed > kMaxMember) {
        fail(where, "claims " + std::to_string(m.uncompressed) +
                        " uncompressed bytes, more than the 16 GiB a model member may have");
      }
      if (m.uncompressed > m.compressed * kMaxDeflateRatio + 1024) {
        fail(where, "bad zip: claims " + std::to_string(m.uncompressed) +
                        " uncompressed bytes from " + std::to_string(m.compressed) +
                        " compressed bytes, more than deflate can produce");
      }
      inflated = inflate_raw(data, static_cast<std::size_t>(m.compressed),
                             static_cast<std::size_t>(m.uncompressed), where);
      npy = inflated.data();
      npy_size = inflated.size();
    } else {
      fail(where, "unsupported zip compression method " + std::to_string(m.method) +
                      " (only stored and deflated members are read; re-save with np.savez or "
                      "np.savez_compressed)");
    }
    if (crc_of(npy, npy_size) != m.crc) fail(where, "CRC-32 mismatch: the file is corrupt");
    const std::string key = m.name.substr(0, m.name.size() - suffix.size());
    out[key] = parse_npy(npy, npy_size, where);
  }
  return out;
}

std::vector<std::uint8_t> npz_bytes(const NpzArchive& arrays, bool compress) {
  std::vector<std::uint8_t> out;
  std::vector<std::uint8_t> central;
  for (const auto& [key, array] : arrays) {
    const std::string name = key + ".npy";
    if (name.size() > 0xFFFF) throw ModelError("npz_bytes: key too long: " + key.substr(0, 80));
    const std::vector<std::uint8_t> npy = npy_bytes(array);
    const std::uint32_t crc = crc_of(npy.data(), npy.size());
    std::vector<std::uint8_t> deflated;
    if (compress) deflated = deflate_raw(npy);
    const std::vector<std::uint8_t>& payload = compress ? deflated : npy;
    const std::uint64_t offset = out.size();
    if (npy.size() >= 0xFFFFFFFFu || payload.size() >= 0xFFFFFFFFu || offset >= 0xFFFFFFFFu) {
      throw ModelError("npz_bytes: array '" + key + "' makes the archive larger than 4 GiB");
    }
    const std::uint16_t method = compress ? 8 : 0;
    // Local header: version 2.0, no flags, 1980-01-01 00:00:00 (DOS date 0x0021, time 0).
    put(out, kLocalSig, 4);
    put(out, 20, 2);
    put(out, 0, 2);
    put(out, method, 2);
    put(out, 0, 2);
    put(out, 0x0021, 2);
    put(out, crc, 4);
    put(out, payload.size(), 4);
    put(out, npy.size(), 4);
    put(out, name.size(), 2);
    put(out, 0, 2);
    out.insert(out.end(), name.begin(), name.end());
    out.insert(out.end(), payload.begin(), payload.end());
    put(central, kCentralSig, 4);
    put(central, 20, 2);  // made by: MS-DOS attributes, version 2.0
    put(central, 20, 2);
    put(central, 0, 2);
    put(central, method, 2);
    put(central, 0, 2);
    put(central, 0x0021, 2);
    put(central, crc, 4);
    put(central, payload.size(), 4);
    put(central, npy.size(), 4);
    put(central, name.size(), 2);
    put(central, 0, 2);  // extra
    put(central, 0, 2);  // comment
    put(central, 0, 2);  // disk
    put(central, 0, 2);  // internal attributes
    put(central, 0, 4);  // external attributes
    put(central, offset, 4);
    central.insert(central.end(), name.begin(), name.end());
  }
  if (arrays.size() >= 0xFFFF || out.size() >= 0xFFFFFFFFu) {
    throw ModelError("npz_bytes: too many arrays or larger than 4 GiB");
  }
  const std::uint64_t cd_offset = out.size();
  out.insert(out.end(), central.begin(), central.end());
  put(out, kEndSig, 4);
  put(out, 0, 2);
  put(out, 0, 2);
  put(out, arrays.size(), 2);
  put(out, arrays.size(), 2);
  put(out, central.size(), 4);
  put(out, cd_offset, 4);
  put(out, 0, 2);
  return out;
}

NpzArchive read_npz(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_npz(bytes.data(), bytes.size(), path);
}

void write_npz(const std::string& path, const NpzArchive& arrays, bool compress) {
  write_file_bytes(path, npz_bytes(arrays, compress));
}

}  // namespace smpl
