// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/image_container.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <cctype>
#include <cstdio>
#include <string_view>
#include <utility>
#include <vector>

#include "geometry/errors.h"
#include "geometry/file_extension.h"

namespace surftex {

namespace {

// CRC-32 of the PNG specification (ISO/IEC 15948, annex D: polynomial
// 0xEDB88320, reflected, initial and final value 0xFFFFFFFF).
std::uint32_t png_crc(const unsigned char* p, std::size_t n, std::uint32_t crc = 0xFFFFFFFFu) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
  return crc;
}

std::uint32_t be32(const unsigned char* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) | p[3];
}

// The IHDR fields (PNG specification, section 11.2.2): libpng refuses
// invalid ones by printing "libpng error: Invalid IHDR data" itself.
void check_png_header(const unsigned char* d, std::uint32_t len, const std::string& what, const std::string& path,
                      const ImageLimits& lim) {
  if (len != 13) throw IOError(what + "the PNG header (IHDR) has " + std::to_string(len) + " bytes, not 13");
  const std::uint32_t w = be32(d), h = be32(d + 4);
  const int depth = d[8], type = d[9];
  if (w == 0 || h == 0 || w > 0x7FFFFFFFu || h > 0x7FFFFFFFu)
    throw IOError(what + "the PNG header claims " + std::to_string(w) + "x" + std::to_string(h) + " pixels");
  const bool ok_type = (type == 0 && (depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16)) ||
                       (type == 3 && (depth == 1 || depth == 2 || depth == 4 || depth == 8)) ||
                       ((type == 2 || type == 4 || type == 6) && (depth == 8 || depth == 16));
  if (!ok_type)
    throw IOError(what + "the PNG header's colour type " + std::to_string(type) + " with bit depth " +
                  std::to_string(depth) + " is not a PNG format");
  if (d[10] != 0 || d[11] != 0 || d[12] > 1)
    throw IOError(what + "the PNG header's compression, filter or interlace method is unknown");
  // Our limits before libpng's own (1,000,000 px a side, refused with its own text).
  lim.check(w, h, std::min(lim.max_side(), 1000000LL), path, "PNG header");
}

// A PNG file's chunk structure checked before libpng sees it: every chunk
// inside the file with a matching CRC, IHDR first and IEND last (PNG
// specification, sections 5.3-5.6). libpng reports a truncated or damaged
// file by printing "libpng error: ..." to stderr itself and longjmp-ing
// through OpenImageIO's reader (which leaks a string on the way); caught
// here, the user gets one `error:` line naming the chunk and the byte
// offset instead. Damage inside the compressed pixel data with a valid CRC
// (rare: the CRC covers it) still reaches libpng.
void check_png_structure(const std::string& path, const ImageLimits& lim) {
  std::ifstream f(path, std::ios::binary);
  f.seekg(8);  // the signature (sniff_image_format)
  const std::uintmax_t size = std::filesystem::file_size(path);
  const std::string what = "cannot decode image '" + path + "' (truncated or corrupt): ";
  std::uintmax_t at = 8;
  std::vector<unsigned char> buf;
  bool first = true;
  for (;;) {
    unsigned char head[8];
    if (size - at < 12 || !f.read(reinterpret_cast<char*>(head), 8))
      throw IOError(what + "the file ends at byte " + std::to_string(size) +
                    " before the PNG end chunk (IEND)");
    const std::uint32_t len = be32(head);
    const std::string type(reinterpret_cast<const char*>(head + 4), 4);
    if (len > 0x7FFFFFFFu || len > size - at - 12)
      throw IOError(what + "PNG chunk '" + type + "' at byte " + std::to_string(at) + " claims " +
                    std::to_string(len) + " bytes, past the end of the file (" + std::to_string(size) +
                    " bytes)");
    if (first && type != "IHDR")
      throw IOError(what + "the first PNG chunk is '" + type + "', not IHDR");
    buf.resize(static_cast<std::size_t>(len) + 4);
    f.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
    std::uint32_t crc = png_crc(head + 4, 4);
    crc = png_crc(buf.data(), len, crc) ^ 0xFFFFFFFFu;
    if (crc != be32(buf.data() + len))
      throw IOError(what + "PNG chunk '" + type + "' at byte " + std::to_string(at) +
                    " fails its CRC check");
    if (first) check_png_header(buf.data(), len, what, path, lim);
    first = false;
    at += 12 + static_cast<std::uintmax_t>(len);
    if (type == "IEND") return;
  }
}


// ---- OpenEXR (file layout: magic, version flags, header attributes, offset table)

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) | (std::uint32_t(p[3]) << 24);
}

// What the offset table's size depends on, from one part's header.
struct ExrPart {
  bool has_window = false;
  long long xmin = 0, ymin = 0, xmax = -1, ymax = -1;
  int compression = 0;
  bool tiled = false;
  long long tile_x = 0, tile_y = 0;
  long long chunk_count = -1;  // the multi-part "chunkCount" attribute
};

// Reads the header's attributes in order, refusing one that reaches past the file.
class ExrHeaderReader {
 public:
  ExrHeaderReader(const std::string& path, std::uintmax_t size) : f_(path, std::ios::binary), size_(size) {
    what_ = "cannot decode image '" + path + "' (truncated or corrupt): ";
    f_.seekg(8);
  }
  std::uint32_t flags() {
    f_.seekg(4);
    unsigned char v[4] = {};
    f_.read(reinterpret_cast<char*>(v), 4);
    f_.seekg(8);
    return le32(v);
  }
  // One header; false when it is empty (the end of a multi-part list).
  bool read_part(ExrPart& part) {
    bool any = false;
    for (;;) {
      const std::string name = read_name("attribute name");
      if (name.empty()) return any;
      any = true;
      const std::string type = read_name("attribute type of '" + name + "'");
      const long long size = read_size(name);
      read_value(name, type, size, part);
    }
  }
  std::uintmax_t at() const { return at_; }
  const std::string& what() const { return what_; }

 private:
  std::string read_name(const std::string& which) {
    std::string s;
    for (;;) {
      const int c = f_.get();
      if (c == EOF) throw IOError(what_ + "the OpenEXR header ends inside an " + which + " at byte " + std::to_string(at_));
      ++at_;
      if (c == 0) return s;
      if (s.size() >= 255)
        throw IOError(what_ + "OpenEXR " + which + " at byte " + std::to_string(at_ - s.size() - 1) +
                      " is longer than 255 bytes");
      s.push_back(static_cast<char>(c));
    }
  }
  long long read_size(const std::string& name) {
    unsigned char b[4] = {};
    if (!f_.read(reinterpret_cast<char*>(b), 4))
      throw IOError(what_ + "the OpenEXR header ends inside attribute '" + name + "'");
    at_ += 4;
    const auto size = static_cast<long long>(static_cast<std::int32_t>(le32(b)));
    if (size < 0 || static_cast<std::uintmax_t>(size) > size_ - at_)
      throw IOError(what_ + "OpenEXR attribute '" + name + "' at byte " + std::to_string(at_ - 4) + " claims " +
                    std::to_string(size) + " bytes; the file has " + std::to_string(size_ - at_) + " after it");
    return size;
  }
  // OpenEXR reads a value of a known type by the type's own layout, not by
  // the size the file declares: a declared size that differs would put
  // OpenEXR somewhere else in the stream than this walk (and a hostile
  // "size" read from there once asked for 1.7 GB). So every known type must
  // fill its declared size exactly.
  void read_value(const std::string& name, const std::string& type, long long size, ExrPart& part) {
    const long long fixed = exr_fixed_size(type);
    if (fixed >= 0 && size != fixed)
      throw IOError(what_ + "OpenEXR attribute '" + name + "' of type " + type + " has " + std::to_string(size) +
                    " bytes, not " + std::to_string(fixed));
    const bool variable = type == "chlist" || type == "preview" || type == "stringvector" || type == "idmanifest";
    const bool wanted = variable || name == "dataWindow" || name == "compression" || name == "tiles" ||
                        name == "chunkCount" || (name == "type" && size <= 64);
    if (!wanted) {
      f_.seekg(size, std::ios::cur);
      at_ += static_cast<std::uintmax_t>(size);
      return;
    }
    if (variable && size > (64LL << 20))
      throw IOError(what_ + "OpenEXR attribute '" + name + "' of type " + type + " has " + std::to_string(size) +
                    " bytes (more than 64 MiB)");
    std::vector<unsigned char> v(static_cast<std::size_t>(size));
    f_.read(reinterpret_cast<char*>(v.data()), size);
    at_ += static_cast<std::uintmax_t>(size);
    if (variable) return check_variable_value(name, type, v);
    auto i32 = [&](int k) { return static_cast<long long>(static_cast<std::int32_t>(le32(v.data() + 4 * k))); };
    if (name == "dataWindow" && type == "box2i") {
      part.has_window = true;
      part.xmin = i32(0), part.ymin = i32(1), part.xmax = i32(2), part.ymax = i32(3);
    } else if (name == "compression" && type == "compression") {
      part.compression = v[0];
    } else if (name == "tiles" && type == "tiledesc") {
      part.tiled = true;
      part.tile_x = le32(v.data()), part.tile_y = le32(v.data() + 4);
    } else if (name == "chunkCount" && type == "int") {
      part.chunk_count = i32(0);
    } else if (name == "type") {
      const std::string s(v.begin(), v.end());
      part.tiled = part.tiled || s.find("tile") != std::string::npos;
    }
  }

  // Bytes of the fixed-size attribute types of OpenEXR 3.1; -1 for the rest.
  static long long exr_fixed_size(const std::string& type) {
    static const std::pair<const char*, int> kSizes[] = {
        {"box2i", 16},  {"box2f", 16},    {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
        {"double", 8},  {"envmap", 1},    {"float", 4},           {"int", 4},         {"keycode", 28},
        {"lineOrder", 1}, {"m33f", 36},   {"m33d", 72},           {"m44f", 64},       {"m44d", 128},
        {"rational", 8}, {"tiledesc", 9}, {"timecode", 8},        {"v2i", 8},         {"v2f", 8},
        {"v2d", 16},    {"v3i", 12},      {"v3f", 12},            {"v3d", 24}};
    for (const auto& [t, n] : kSizes)
      if (type == t) return n;
    return -1;
  }

  // The variable-size types OpenEXR parses by their contents: the contents
  // must end exactly at the declared size.
  void check_variable_value(const std::string& name, const std::string& type, const std::vector<unsigned char>& v) {
    const std::size_t n = v.size();
    auto bad = [&](const std::string& why) {
      return IOError(what_ + "OpenEXR attribute '" + name + "' of type " + type + ": " + why);
    };
    if (type == "chlist") {  // name\0, pixel type, pLinear + 3 reserved, x and y sampling; an empty name ends it
      std::size_t i = 0;
      for (;;) {
        if (i >= n) throw bad("the channel list has no end within its " + std::to_string(n) + " bytes");
        if (v[i] == 0) break;
        const std::size_t len = std::find(v.begin() + static_cast<long>(i), v.end(), 0) - (v.begin() + static_cast<long>(i));
        if (len > 255 || i + len + 1 + 16 > n) throw bad("channel at byte " + std::to_string(i) + " runs past the list");
        i += len + 1 + 16;
      }
      if (i + 1 != n) throw bad("the channel list ends at byte " + std::to_string(i + 1) + " of " + std::to_string(n));
    } else if (type == "preview") {  // width, height, then width x height RGBA bytes
      if (n < 8) throw bad("the preview has " + std::to_string(n) + " bytes");
      const unsigned long long w = le32(v.data()), h = le32(v.data() + 4);
      if (w > n || h > n || 8 + 4 * w * h != n)
        throw bad("a " + std::to_string(w) + "x" + std::to_string(h) + " preview in " + std::to_string(n) + " bytes");
    } else if (type == "stringvector") {  // (length, bytes)...
      std::size_t i = 0;
      while (i < n) {
        if (n - i < 4) throw bad("a string length runs past the attribute");
        const long long len = static_cast<std::int32_t>(le32(v.data() + i));
        if (len < 0 || static_cast<unsigned long long>(len) > n - i - 4)
          throw bad("a string of " + std::to_string(len) + " bytes at byte " + std::to_string(i));
        i += 4 + static_cast<std::size_t>(len);
      }
    } else if (type == "idmanifest" && n < 4) {
      throw bad("it has " + std::to_string(n) + " bytes, fewer than 4");
    }
  }

  std::ifstream f_;
  std::uintmax_t size_;
  std::uintmax_t at_ = 8;
  std::string what_;
};

long long ceil_div(long long a, long long b) { return (a + b - 1) / b; }

// Chunks in one part's offset table: scan-line blocks (lines per block by
// compression: none, RLE, ZIPS 1; ZIP, PXR24 16; PIZ, B44, B44A, DWAA 32;
// DWAB 256) or level-0 tiles (mip levels only add to it).
long long exr_chunks(const ExrPart& p, const std::string& what) {
  if (p.chunk_count >= 0) return p.chunk_count;
  const long long w = p.xmax - p.xmin + 1, h = p.ymax - p.ymin + 1;
  if (p.tiled) {
    if (p.tile_x < 1 || p.tile_y < 1)
      throw IOError(what + "the OpenEXR tile size is " + std::to_string(p.tile_x) + "x" + std::to_string(p.tile_y));
    return ceil_div(w, p.tile_x) * ceil_div(h, p.tile_y);
  }
  static const int kLines[10] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  return ceil_div(h, p.compression < 10 ? kLines[p.compression] : 256);
}

void check_exr_structure(const std::string& path, const ImageLimits& lim) {
  const std::uintmax_t size = std::filesystem::file_size(path);
  ExrHeaderReader r(path, size);
  const std::string& what = r.what();
  if (size < 8) throw IOError(what + "the file ends inside the OpenEXR version field");
  const bool multipart = (r.flags() & 0x1000u) != 0;
  const bool single_tiled = (r.flags() & 0x200u) != 0;
  long long chunks = 0;
  for (int part_no = 0;; ++part_no) {
    ExrPart part;
    part.tiled = single_tiled;
    if (!r.read_part(part)) {
      if (part_no == 0) throw IOError(what + "the OpenEXR header is empty");
      break;
    }
    if (!part.has_window) throw IOError(what + "OpenEXR part " + std::to_string(part_no) + " has no dataWindow");
    const long long w = part.xmax - part.xmin + 1, h = part.ymax - part.ymin + 1;
    if (w <= 0 || h <= 0)
      throw InvalidInputError("image '" + path + "' is empty (OpenEXR data window " + std::to_string(w) + "x" +
                              std::to_string(h) + ")");
    lim.check(w, h, lim.max_side(), path, "OpenEXR data window");
    chunks += exr_chunks(part, what);
    if (!multipart) break;
  }
  if (chunks < 0 || static_cast<std::uintmax_t>(chunks) > (size - r.at()) / 8)
    throw IOError(what + "the OpenEXR offset table of " + std::to_string(chunks) + " chunks needs " +
                  std::to_string(8 * chunks) + " bytes; the file has " + std::to_string(size - r.at()) +
                  " after its header");
}

// ---- JPEG (ITU-T T.81, annex B.1: marker segments before the scan)

// OpenImageIO 2.4 reads the IPTC block of a Photoshop APP13 segment
// ("Photoshop 3.0\0", "8BIM", resource 0x0404, 4 bytes, a 16-bit size) and
// copies that many bytes without comparing the size with the segment's
// (a heap overflow under ASan, fuzz_image_header). Segments up to the scan
// are walked here; such a block must lie inside its segment.
void check_jpeg_app13(const std::vector<unsigned char>& seg, std::uintmax_t at, const std::string& what) {
  static const char kTag[] = "Photoshop 3.0";  // 14 bytes with its NUL
  const std::size_t n = seg.size();
  if (!std::equal(seg.begin(), seg.begin() + static_cast<long>(std::min<std::size_t>(n, sizeof kTag)), kTag)) return;
  auto bad = [&](const std::string& why) {
    return IOError(what + "the Photoshop (APP13) segment at byte " + std::to_string(at) + " " + why);
  };
  if (n < 20) throw bad("has " + std::to_string(n) + " bytes, too few for its resource header");
  if (std::string(seg.begin() + 14, seg.begin() + 18) != "8BIM" || seg[18] != 0x04 || seg[19] != 0x04) return;
  if (n < 26) throw bad("has " + std::to_string(n) + " bytes, too few for its IPTC block's size");
  const std::size_t size = (std::size_t(seg[24]) << 8) | seg[25];
  if (26 + size > n)
    throw bad("holds an IPTC block of " + std::to_string(size) + " bytes; the segment has " + std::to_string(n - 26) +
              " after its header");
}

void check_jpeg_structure(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  const std::uintmax_t size = std::filesystem::file_size(path);
  const std::string what = "cannot decode image '" + path + "' (truncated or corrupt): ";
  std::uintmax_t at = 2;  // offset of the next byte: after SOI
  f.seekg(2);
  auto get = [&] {
    const int c = f.get();
    if (c != EOF) ++at;
    return c;
  };
  std::vector<unsigned char> seg;
  for (;;) {
    int c = get();
    while (c != EOF && c != 0xFF) c = get();  // libjpeg skips extraneous bytes too
    while (c == 0xFF) c = get();              // fill bytes
    if (c == EOF) return;                     // libjpeg reports the missing scan itself
    const int marker = c;
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length
    if (marker == 0xD9 || marker == 0xDA) return;  // end of image, start of scan
    const std::uintmax_t start = at - 2;
    const int hi = get(), lo = get();
    if (lo == EOF) return;
    const std::size_t len = (std::size_t(hi) << 8) | std::size_t(lo);
    if (len < 2 || len - 2 > size - at) {
      char name[8];
      std::snprintf(name, sizeof name, "0xFF%02X", marker);
      throw IOError(what + "JPEG marker segment " + name + " at byte " + std::to_string(start) + " claims " +
                    std::to_string(len) + " bytes; the file has " + std::to_string(size - at + 2) + " from there");
    }
    seg.resize(len - 2);
    f.read(reinterpret_cast<char*>(seg.data()), static_cast<std::streamsize>(seg.size()));
    at += seg.size();
    if (marker == 0xED) check_jpeg_app13(seg, start, what);
  }
}

// ---- GIF (GIF89a specification, section 18: the logical screen descriptor)

// OpenImageIO sizes its canvas from the logical screen (width x height x 4 in
// an int): a hostile screen size threw std::length_error out of a noexcept
// path (std::terminate; fuzz_image_header).
void check_gif_screen(const std::string& path, const ImageLimits& lim) {
  std::ifstream f(path, std::ios::binary);
  unsigned char b[10] = {};
  const std::string what = "cannot decode image '" + path + "' (truncated or corrupt): ";
  if (!f.read(reinterpret_cast<char*>(b), 10)) throw IOError(what + "the file ends inside the GIF screen descriptor");
  const long long w = b[6] | (b[7] << 8), h = b[8] | (b[9] << 8);
  if (w == 0 || h == 0)
    throw IOError(what + "the GIF logical screen is " + std::to_string(w) + "x" + std::to_string(h));
  lim.check(w, h, lim.max_side(), path, "GIF logical screen");
  if (w * h * 4 > 0x7FFFFFFFLL)
    throw InvalidInputError("image '" + path + "' is " + std::to_string(w) + "x" + std::to_string(h) +
                            " (GIF logical screen): OpenImageIO reads at most 2^29 GIF pixels");
}

}  // namespace

std::string sniff_image_format(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IOError("cannot open image '" + path + "'");
  char buf[16] = {};
  f.read(buf, sizeof buf);
  const std::string_view h(buf, static_cast<std::size_t>(f.gcount()));
  auto is = [&](std::string_view sig, std::size_t at = 0) { return h.substr(std::min(at, h.size())).substr(0, sig.size()) == sig; };
  using namespace std::string_view_literals;
  if (is("\x89PNG\r\n\x1a\n"sv)) return "png";
  if (is("\xff\xd8\xff"sv)) return "jpeg";
  if (is("II*\0"sv) || is("MM\0*"sv) || is("II+\0"sv) || is("MM\0+"sv)) return "tiff";
  if (is("v/1\x01"sv)) return "openexr";
  if (is("BM"sv)) return "bmp";
  if (is("#?RADIANCE"sv) || is("#?RGBE"sv)) return "hdr";
  if (h.size() >= 3 && h[0] == 'P' && std::string_view("123456fF").find(h[1]) != std::string_view::npos &&
      std::isspace(static_cast<unsigned char>(h[2])))
    return "pnm";
  if (is("RIFF"sv) && is("WEBP"sv, 8)) return "webp";
  if (is("GIF87a"sv) || is("GIF89a"sv)) return "gif";
  const std::string ext = lower_extension(path);
  if (ext == ".tga" || ext == ".tpic") return "targa";
  throw IOError("cannot read image '" + path +
                "': it is not a PNG, JPEG, TIFF, OpenEXR, BMP, Radiance HDR, PNM/PFM, WebP or GIF file (by its first "
                "bytes), nor named .tga");
}

void check_image_container(const std::string& path, const std::string& format, const ImageLimits& limits) {
  if (format == "png") check_png_structure(path, limits);
  if (format == "openexr") check_exr_structure(path, limits);
  if (format == "gif") check_gif_screen(path, limits);
  if (format == "jpeg") check_jpeg_structure(path);
}

}  // namespace surftex
