// .npz archives. Reading: the zip container (PKWARE APPNOTE.TXT 6.3: local headers, central
// directory, end of central directory, zip64 records and extra fields) parsed here, with the
// hostile-input checks a model loader needs (sizes against the file and against what deflate can
// produce, overlapping members, the .npy header checked before a member is inflated); stored and
// deflated members (RFC 1951 through zlib's raw inflate), CRC-32 checked.
// Writing: minizip (Debian's libminizip, zlib's contrib/minizip), which is told every field the
// committed models carry (version 2.0 made by MS-DOS, no flags, no extra fields, DOS time
// 1980-01-01 00:00, raw deflate level 6, windowBits 15, memLevel 8, default strategy, no zip64), so
// the models regenerate byte-identically (`caliper-modelgen` + cmp, in CI).
// Why not libzip (1.7.3, Debian 12) for writing: it cannot be told two of those fields. Its deflate
// is hard-wired to memLevel 9 (MAX_MEM_LEVEL in zip_algorithm_deflate.c), which gives another
// stream: repacking caliper-neutral.npz's 17 members with libzip at level 6 gives 3,021,108 bytes
// instead of 3,020,056 (6 of the 17 deflate streams differ in length, e.g. f.npy 102,790 bytes, not
// 102,500, shapedirs.npy 2,576,700 instead of 2,576,820; first differing byte 3,353, f.npy's
// compressed size in its local header). And every central directory entry it writes has "version
// made by" 0x003F (6.3; _zip_dirent_apply_attributes sets the low byte to 63 unconditionally;
// zip_file_set_external_attributes sets only the host byte) where the models have 0x0014. minizip
// repacks the same members into the committed file exactly (cmp: identical).
// (Experiment: the 17 members of caliper-neutral.npz extracted, added in the same order with
// zip_source_buffer + zip_set_file_compression(DEFLATE, 6) + zip_file_set_mtime(1980-01-01) +
// zip_file_set_external_attributes(DOS, 0); and with minizip's zipOpenNewFileInZip4_64 using the
// fields above. npz_bytes gives the same bytes as the hand-written writer it replaced, stored and
// deflated; tests/smpl/test_npz.cpp pins every field.)
// Why the reader is not on libzip (yet): libzip 1.7.3 does not check that members' data spans are
// disjoint (_zip_checkcons in zip_open.c only keeps them below the central directory and compares
// each local header with its directory entry), and its zip_stat_t has no offsets, so the
// overlapping-members refusal (tests/smpl/test_hostile_files.cpp, HostileNpz) could not be kept
// on top of it. Not tried: minizip's unzip (unzGetCurrentFileZStreamPos64 gives data offsets).
#include <algorithm>
#include <cstring>
#include <limits>

#include <minizip/zip.h>  // not <zip.h>: libzip-dev installs a different /usr/include/zip.h
#include <zlib.h>

#include "model_error.hpp"
#include "smpl/npz.hpp"

namespace smpl {
namespace {

using detail::fail;

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
    while (produced_ < n && !ended_) {
      if (produced_ == out_.size()) {
        out_.resize(std::min(n, std::max<std::size_t>(2 * out_.size(), std::size_t{1} << 16)));
      }
      produced_ += step(out_.data() + produced_, out_.size() - produced_);
    }
  }
  // Inflates exactly `n` bytes and checks that the stream ends there.
  void finish(std::size_t n) {
    fill(n);
    if (produced_ < n) {
      fail(context_, "deflate data gives " + std::to_string(produced_) +
                         " bytes, the zip directory says " + std::to_string(n));
    }
    // Any byte more goes to a scratch byte (growing out_ by one would copy all of it).
    std::uint8_t extra = 0;
    while (!ended_) {
      if (step(&extra, 1) != 0) {
        fail(context_, "the deflate data gives more than the " + std::to_string(n) +
                           " bytes the zip directory says");
      }
    }
    out_.resize(n);
  }
  const std::vector<std::uint8_t>& out() const { return out_; }
  std::size_t produced() const { return produced_; }

 private:
  // One inflate call into [out, out + size); returns the bytes produced. Throws for corrupt data
  // and for data that ends before the stream does (truncated).
  std::size_t step(std::uint8_t* out, std::size_t size) {
    constexpr std::size_t kChunk = std::numeric_limits<uInt>::max();
    const std::size_t in_chunk = std::min(in_left_, kChunk);
    const std::size_t out_chunk = std::min(size, kChunk);
    zs_.next_out = out;
    zs_.avail_in = static_cast<uInt>(in_chunk);
    zs_.avail_out = static_cast<uInt>(out_chunk);
    const int rc = inflate(&zs_, Z_NO_FLUSH);
    in_left_ -= in_chunk - zs_.avail_in;
    if (rc == Z_STREAM_END) {
      ended_ = true;
    } else if (rc == Z_BUF_ERROR) {
      fail(context_, "truncated deflate data");
    } else if (rc != Z_OK) {
      fail(context_, std::string("corrupt deflate data") +
                         (zs_.msg ? std::string(" (") + zs_.msg + ")" : ""));
    }
    return out_chunk - zs_.avail_out;
  }

  z_stream zs_{};
  std::size_t in_left_;
  std::string context_;
  std::vector<std::uint8_t> out_;
  std::size_t produced_ = 0;
  bool ended_ = false;
};

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

namespace {

// minizip's file functions over a byte vector: the archive is made in memory (npz_bytes returns
// it; write_npz writes it atomically). minizip writes sequentially and seeks back to complete
// each local header, so the buffer grows on writes past its end.
struct MemoryZip {
  std::vector<std::uint8_t> bytes;
  std::uint64_t pos = 0;
};

voidpf ZCALLBACK memory_open(voidpf opaque, const void* /*filename*/, int /*mode*/) {
  return opaque;
}
uLong ZCALLBACK memory_read(voidpf /*opaque*/, voidpf /*stream*/, void* /*buf*/, uLong /*size*/) {
  return 0;  // the writer never reads (APPEND_STATUS_CREATE)
}
uLong ZCALLBACK memory_write(voidpf /*opaque*/, voidpf stream, const void* buf, uLong size) {
  auto& z = *static_cast<MemoryZip*>(stream);
  if (z.pos + size > z.bytes.size()) z.bytes.resize(z.pos + size);
  std::memcpy(z.bytes.data() + z.pos, buf, size);
  z.pos += size;
  return size;
}
ZPOS64_T ZCALLBACK memory_tell(voidpf /*opaque*/, voidpf stream) {
  return static_cast<MemoryZip*>(stream)->pos;
}
long ZCALLBACK memory_seek(voidpf /*opaque*/, voidpf stream, ZPOS64_T offset, int origin) {
  auto& z = *static_cast<MemoryZip*>(stream);
  const std::uint64_t base = origin == ZLIB_FILEFUNC_SEEK_SET   ? 0
                             : origin == ZLIB_FILEFUNC_SEEK_CUR ? z.pos
                                                                : z.bytes.size();
  if (base + offset > z.bytes.size()) return -1;
  z.pos = base + offset;
  return 0;
}
int ZCALLBACK memory_close(voidpf /*opaque*/, voidpf /*stream*/) {
  return 0;
}
int ZCALLBACK memory_error(voidpf /*opaque*/, voidpf /*stream*/) {
  return 0;
}

// The fields every member gets (see the file's header): DOS date 1980-01-01 (0x0021), time 0;
// version 2.0 made by MS-DOS; no attributes.
constexpr uLong kDosDate1980 = 0x00210000;
constexpr uLong kMadeByDos20 = 20;

}  // namespace

std::vector<std::uint8_t> npz_bytes(const NpzArchive& arrays, bool compress) {
  if (arrays.size() >= 0xFFFF) throw ModelError("npz_bytes: too many arrays (65535 or more)");
  MemoryZip memory;
  zlib_filefunc64_def io{};
  io.zopen64_file = memory_open;
  io.zread_file = memory_read;
  io.zwrite_file = memory_write;
  io.ztell64_file = memory_tell;
  io.zseek64_file = memory_seek;
  io.zclose_file = memory_close;
  io.zerror_file = memory_error;
  io.opaque = &memory;
  zipFile zf = zipOpen2_64("npz_bytes", APPEND_STATUS_CREATE, nullptr, &io);
  if (zf == nullptr) throw ModelError("npz_bytes: minizip could not start the archive");
  // Closes the archive (and so frees minizip's state) on every path; the bytes are kept only
  // when everything was written.
  auto close_or_fail = [&zf](const std::string& what) {
    zipClose(zf, nullptr);
    throw ModelError("npz_bytes: " + what);
  };
  for (const auto& [key, array] : arrays) {
    const std::string name = key + ".npy";
    if (name.size() > 0xFFFF) close_or_fail("key too long: " + key.substr(0, 80));
    const std::vector<std::uint8_t> npy = npy_bytes(array);
    if (npy.size() >= 0xFFFFFFFFu || memory.bytes.size() >= 0xFFFFFFFFu) {
      close_or_fail("array '" + key + "' makes the archive larger than 4 GiB");
    }
    zip_fileinfo info{};
    info.dosDate = kDosDate1980;
    const int method = compress ? Z_DEFLATED : 0;
    const int level = compress ? 6 : 0;
    if (zipOpenNewFileInZip4_64(zf, name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr, method,
                                level, 0, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY, nullptr, 0,
                                kMadeByDos20, 0, 0) != ZIP_OK ||
        zipWriteInFileInZip(zf, npy.data(), static_cast<unsigned>(npy.size())) != ZIP_OK ||
        zipCloseFileInZip(zf) != ZIP_OK) {
      close_or_fail("minizip could not write member '" + name + "'");
    }
    if (memory.bytes.size() >= 0xFFFFFFFFu) {
      close_or_fail("array '" + key + "' makes the archive larger than 4 GiB");
    }
  }
  if (zipClose(zf, nullptr) != ZIP_OK) throw ModelError("npz_bytes: minizip could not finish");
  if (memory.bytes.size() >= 0xFFFFFFFFu) {
    throw ModelError("npz_bytes: the archive is larger than 4 GiB");
  }
  return std::move(memory.bytes);
}

NpzArchive read_npz(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_npz(bytes.data(), bytes.size(), path);
}

void write_npz(const std::string& path, const NpzArchive& arrays, bool compress) {
  write_file_bytes(path, npz_bytes(arrays, compress));
}

}  // namespace smpl
