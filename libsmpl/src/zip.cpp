// .npz archives: the zip container (PKWARE APPNOTE.TXT 6.3: local headers, central directory,
// end of central directory, zip64 records and extra fields), stored and deflated members (RFC 1951
// through zlib's raw inflate), CRC-32 checked.
#include <algorithm>
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

// Raw deflate data inflated on demand: fill(n) inflates until n bytes are out (or the stream
// ends); the output grows with the data actually produced (no allocation of a claimed size up
// front).
class RawInflater {
 public:
  RawInflater(const std::uint8_t* in, std::size_t in_size, std::string context)
      : in_left_(in_size), context_(std::move(context)) {
    if (inflateInit2(&zs_, -15) != Z_OK) fail(context_, "zlib inflateInit2 failed");
    zs_.next_in = const_cast<Bytef*>(in);
  }
  ~RawInflater() { inflateEnd(&zs_); }
  RawInflater(const RawInflater&) = delete;
  RawInflater& operator=(const RawInflater&) = delete;

  // Inflates until `n` bytes are out or the stream ends. Throws for corrupt data, and for data
  // that ends before the stream does (truncated).
  void fill(std::size_t n) {
    constexpr std::size_t kChunk = std::numeric_limits<uInt>::max();
    while (produced_ < n && !ended_) {
      if (produced_ == out_.size()) {
        out_.resize(std::min(n, std::max<std::size_t>(2 * out_.size(), std::size_t{1} << 16)));
      }
      const std::size_t in_chunk = std::min(in_left_, kChunk);
      const std::size_t out_chunk = std::min(out_.size() - produced_, kChunk);
      zs_.next_out = out_.data() + produced_;
      zs_.avail_in = static_cast<uInt>(in_chunk);
      zs_.avail_out = static_cast<uInt>(out_chunk);
      const int rc = inflate(&zs_, Z_NO_FLUSH);
      in_left_ -= in_chunk - zs_.avail_in;
      produced_ += out_chunk - zs_.avail_out;
      if (rc == Z_STREAM_END) {
        ended_ = true;
      } else if (rc == Z_BUF_ERROR) {
        fail(context_, "truncated deflate data");
      } else if (rc != Z_OK) {
        fail(context_, std::string("corrupt deflate data") +
                           (zs_.msg ? std::string(" (") + zs_.msg + ")" : ""));
      }
    }
  }
  // Inflates exactly `n` bytes and checks that the stream ends there.
  void finish(std::size_t n) {
    fill(n);
    if (produced_ < n) {
      fail(context_, "deflate data gives " + std::to_string(produced_) +
                         " bytes, the zip directory says " + std::to_string(n));
    }
    if (!ended_) {
      out_.resize(n + 1);
      fill(n + 1);
      if (produced_ > n) {
        fail(context_, "the deflate data gives more than the " + std::to_string(n) +
                           " bytes the zip directory says");
      }
    }
    out_.resize(n);
  }
  const std::vector<std::uint8_t>& out() const { return out_; }
  std::size_t produced() const { return produced_; }

 private:
  z_stream zs_{};
  std::size_t in_left_;
  std::string context_;
  std::vector<std::uint8_t> out_;
  std::size_t produced_ = 0;
  bool ended_ = false;
};

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

// Where the central directory is and how many entries it has: from the end-of-central-directory
// record (the last signature whose comment fits the file) or its zip64 version.
struct Directory {
  std::uint64_t entries = 0, size = 0, offset = 0;
};

Directory find_directory(const std::uint8_t* bytes, std::size_t size, const std::string& context) {
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
  return {entries, cd_size, cd_offset};
}

// One central directory entry (sizes and offset completed from its zip64 extra field).
struct DirEntry {
  std::string name;
  std::uint16_t method = 0, flags = 0;
  std::uint32_t crc = 0;
  std::uint64_t compressed = 0, uncompressed = 0, local_offset = 0;
  std::uint64_t data_offset = 0;  ///< set by locate_data
};

std::vector<DirEntry> read_directory(const std::uint8_t* bytes, const Directory& dir,
                                     const std::string& context) {
  const std::uint64_t entries = dir.entries;
  std::vector<DirEntry> entries_read;
  std::size_t pos = dir.offset;
  const std::size_t cd_end = dir.offset + dir.size;
  for (std::uint64_t i = 0; i < entries; ++i) {
    if (cd_end - pos < 46 || le(bytes + pos, 4) != kCentralSig) {
      fail(context, "bad zip: central directory entry " + std::to_string(i) + " is corrupt");
    }
    const std::uint8_t* h = bytes + pos;
    DirEntry m;
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
    entries_read.push_back(std::move(m));
    pos += 46 + name_len + extra_len + comment_len;
  }
  return entries_read;
}

// Sets every entry's data_offset from its local header. The local headers and data spans must lie
// inside the file, and no two members may share a byte (a zip whose directory entries point at
// the same data would be inflated once per entry).
void locate_data(const std::uint8_t* bytes, std::size_t size, std::vector<DirEntry>& entries_read,
                 const std::string& context) {
  struct Span {
    std::uint64_t begin, end;
    const std::string* name;
  };
  std::vector<Span> spans;
  for (DirEntry& m : entries_read) {
    const std::string where = context + " member '" + m.name + "'";
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
    m.data_offset = start;
    spans.push_back({m.local_offset, start + m.compressed, &m.name});
  }
  std::sort(spans.begin(), spans.end(),
            [](const Span& a, const Span& b) { return a.begin < b.begin; });
  for (std::size_t i = 1; i < spans.size(); ++i) {
    if (spans[i].begin < spans[i - 1].end) {
      fail(context, "bad zip: members '" + *spans[i - 1].name + "' and '" + *spans[i].name +
                        "' overlap (bytes " + std::to_string(spans[i].begin) + " to " +
                        std::to_string(std::min(spans[i].end, spans[i - 1].end)) +
                        " belong to both): several directory entries point at the same data; "
                        "the file is corrupt or hostile");
    }
  }
}

}  // namespace

NpzReader::NpzReader(const std::uint8_t* bytes, std::size_t size, std::string context_in)
    : bytes_(bytes), context_(std::move(context_in)) {
  const std::string& context = context_;
  std::vector<DirEntry> entries_read =
      read_directory(bytes, find_directory(bytes, size, context), context);
  locate_data(bytes, size, entries_read, context);
  const std::string suffix = ".npy";
  for (const DirEntry& e : entries_read) {
    const std::string& name = e.name;
    if (name.size() < suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    const std::string key = name.substr(0, name.size() - suffix.size());
    Member m;
    m.name = e.name;
    m.method = e.method;
    m.flags = e.flags;
    m.crc = e.crc;
    m.compressed = e.compressed;
    m.uncompressed = e.uncompressed;
    m.data_offset = e.data_offset;
    if (!members_.emplace(key, m).second) {
      fail(context, "bad zip: member '" + name + "' appears twice in the directory");
    }
  }
}

std::vector<std::string> NpzReader::keys() const {
  std::vector<std::string> out;
  for (const auto& kv : members_) out.push_back(kv.first);
  return out;
}

bool NpzReader::has(const std::string& key) const {
  return members_.count(key) != 0;
}

NpyArray NpzReader::array(const std::string& key) const {
  const auto it = members_.find(key);
  if (it == members_.end()) fail(context_, "no member '" + key + ".npy'");
  const Member& m = it->second;
  const std::string where = context_ + " member '" + m.name + "'";
  if (m.flags & 1) fail(where, "encrypted zip members are not supported");
  const std::uint8_t* data = bytes_ + m.data_offset;
  if (m.method == 0) {
    if (m.compressed != m.uncompressed) fail(where, "bad zip: stored member sizes disagree");
    const auto n = static_cast<std::size_t>(m.compressed);
    if (crc_of(data, n) != m.crc) fail(where, "CRC-32 mismatch: the file is corrupt");
    return parse_npy(data, n, where);
  }
  if (m.method != 8) {
    fail(where, "unsupported zip compression method " + std::to_string(m.method) +
                    " (only stored and deflated members are read; re-save with np.savez or "
                    "np.savez_compressed)");
  }
  if (m.uncompressed > kMaxMember) {
    fail(where, "claims " + std::to_string(m.uncompressed) +
                    " uncompressed bytes, more than the 16 GiB a model member may have");
  }
  if (m.uncompressed > m.compressed * kMaxDeflateRatio + 1024) {
    fail(where, "bad zip: claims " + std::to_string(m.uncompressed) + " uncompressed bytes from " +
                    std::to_string(m.compressed) +
                    " compressed bytes, more than deflate can produce");
  }
  const auto claimed = static_cast<std::size_t>(m.uncompressed);
  RawInflater z(data, static_cast<std::size_t>(m.compressed), where);
  // First the .npy header, then exactly the size it declares.
  z.fill(std::min<std::size_t>(claimed, 12));
  const std::size_t header = npy_header_size(z.out().data(), z.produced(), where);
  z.fill(std::min(claimed, header));
  const std::size_t declared = npy_declared_size(z.out().data(), z.produced(), where);
  if (declared == 0) return parse_npy(z.out().data(), z.produced(), where);  // object array
  if (declared != claimed) {
    fail(where, "the zip directory says " + std::to_string(claimed) +
                    " bytes but the .npy header declares " + std::to_string(declared) +
                    " (header and data): the file is corrupt; nothing more was inflated");
  }
  z.finish(claimed);
  if (crc_of(z.out().data(), claimed) != m.crc) fail(where, "CRC-32 mismatch: the file is corrupt");
  return parse_npy(z.out().data(), claimed, where);
}

NpzArchive parse_npz(const std::uint8_t* bytes, std::size_t size, const std::string& context) {
  const NpzReader reader(bytes, size, context);
  NpzArchive out;
  for (const std::string& key : reader.keys()) out[key] = reader.array(key);
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
