// SPDX-License-Identifier: AGPL-3.0-or-later
// Regression tests for issue 21 (reliability under hostile input), geometry
// side: byte-order marks in the text mesh formats, image headers checked
// before decoding, staging of a run's outputs (the constraints parser's are in
// tests/texture/test_hostile_constraints.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "geometry/split_pinched_polygons.h"
#include "geometry/work_budget.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

using surftex::test::write_file;

const std::string kBom = "\xEF\xBB\xBF";

}  // namespace

// An OBJ starting with a UTF-8 BOM lost its first `v` line (the BOM glued to
// the keyword made it unknown): every face index shifted by one vertex and the
// read succeeded.
TEST(Utf8Bom, ObjWithBomKeepsItsFirstVertex) {
  const std::string dir = test::temp_dir("bom_obj");
  const std::string body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const PolygonSoup plain = read_polygon_soup(write_file(dir, "plain.obj", body));
  const PolygonSoup bom = read_polygon_soup(write_file(dir, "bom.obj", kBom + body));
  ASSERT_EQ(bom.points.size(), 4u);
  EXPECT_EQ(bom.points, plain.points);
  EXPECT_EQ(bom.polygons, plain.polygons);
  // Sniffed without an extension too.
  const PolygonSoup sniffed = read_polygon_soup(write_file(dir, "bom_noext", kBom + body));
  EXPECT_EQ(sniffed.points, plain.points);
}

TEST(Utf8Bom, OffPlyAndAsciiStlWithBomReadLikeWithout) {
  const std::string dir = test::temp_dir("bom_other");
  const std::string off = "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  std::ostringstream stl;
  stl << "solid t\n";
  const double P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int F[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (auto& f : F) {
    stl << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) stl << "vertex " << P[f[k]][0] << " " << P[f[k]][1] << " " << P[f[k]][2] << "\n";
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid t\n";
  for (const auto& [ext, body] : std::vector<std::pair<std::string, std::string>>{
           {".off", off}, {".ply", ply}, {".stl", stl.str()}}) {
    SCOPED_TRACE(ext);
    const PolygonSoup plain = read_polygon_soup(write_file(dir, "plain" + ext, body));
    PolygonSoup bom;
    ASSERT_NO_THROW(bom = read_polygon_soup(write_file(dir, "bom" + ext, kBom + body)));
    EXPECT_EQ(bom.points, plain.points);
    EXPECT_EQ(bom.polygons, plain.polygons);
    EXPECT_EQ(bom.points.size(), 4u);
    const PolygonSoup sniffed = read_polygon_soup(write_file(dir, "bom_noext" + ext.substr(1), kBom + body));
    EXPECT_EQ(sniffed.polygons, plain.polygons);
  }
}

// A BOM is skipped only at the very start: elsewhere it is still data, and
// line numbers in messages count from the BOM's line as line 1.
TEST(Utf8Bom, LineNumbersAfterABomStartAtOne) {
  const std::string dir = test::temp_dir("bom_line");
  const std::string p = write_file(dir, "bad.obj", kBom + "v 0 0 x\n");
  try {
    read_polygon_soup(p);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line 1"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------- images

namespace {
// A PNG signature + IHDR of WIDTH x HEIGHT (8-bit RGB, valid CRCs), one IDAT
// holding `zlib_stream` (default: an empty stream: the header claims the size,
// no pixel data follows), then IEND.
std::string png_header_only(std::uint32_t w, std::uint32_t h, const std::string& zlib_stream = "") {
  auto be = [](std::uint32_t v) {
    std::string s(4, '\0');
    for (int k = 0; k < 4; ++k) s[k] = static_cast<char>((v >> (24 - 8 * k)) & 255);
    return s;
  };
  auto crc = [](const std::string& d) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : d) {
      c ^= b;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xFFFFFFFFu;
  };
  std::string ihdr = "IHDR" + be(w) + be(h) + std::string("\x08\x02\x00\x00\x00", 5);
  std::string png("\x89PNG\r\n\x1a\n", 8);
  png += be(13) + ihdr + be(crc(ihdr));
  std::string zlib = zlib_stream.empty() ? std::string("\x78\x9c\x03\x00\x00\x00\x00\x01", 8) : zlib_stream;
  const std::string idat = "IDAT" + zlib;
  png += be(static_cast<std::uint32_t>(zlib.size())) + idat + be(crc(idat));
  png += be(0) + std::string("IEND") + be(crc("IEND"));
  return png;
}

// `raw` (at most 65535 bytes) as a zlib stream of one stored deflate block.
std::string zlib_stored(const std::string& raw) {
  const auto n = static_cast<std::uint16_t>(raw.size());
  std::string z("\x78\x01\x01", 3);
  z += static_cast<char>(n & 255);
  z += static_cast<char>(n >> 8);
  z += static_cast<char>(~n & 255);
  z += static_cast<char>((~n >> 8) & 255);
  z += raw;
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  const std::uint32_t adler = (b << 16) | a;
  for (int k = 0; k < 4; ++k) z += static_cast<char>((adler >> (24 - 8 * k)) & 255);
  return z;
}
}  // namespace

// A PNG row with filter type 7 (there are five, 0..4): libpng printed
// "libpng error: bad adaptive filter value" on stderr itself before our
// refusal (hostile image campaign). Now its words are in our one error.
TEST(HostileImages, DecoderTextBecomesPartOfTheOneError) {
  const std::string dir = test::temp_dir("image_decoder_text");
  std::string rows(2 * 7, '\0');  // 2 x 2 RGB: filter byte + 6 bytes per row
  rows[0] = 7;
  const std::string p = write_file(dir, "bad_filter.png", png_header_only(2, 2, zlib_stored(rows)));
  testing::internal::CaptureStderr();
  std::string what;
  try {
    read_image(p);
  } catch (const IOError& e) {
    what = e.what();
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "");
  EXPECT_NE(what.find("cannot decode image"), std::string::npos) << what;
  EXPECT_NE(what.find("filter"), std::string::npos) << what;
  // A good PNG still decodes, and prints nothing.
  rows[0] = 0;
  const std::string q = write_file(dir, "good.png", png_header_only(2, 2, zlib_stored(rows)));
  testing::internal::CaptureStderr();
  EXPECT_EQ(read_image(q).width, 2);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// A 261 KB PNG of 16384^2 took 3.2 GB before failing; now the header alone decides.
TEST(HostileImages, HeadersOverTheLimitsAreRefusedWithoutDecoding) {
  const std::string dir = test::temp_dir("image_headers");
  for (auto [w, h] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{{16384, 16384}, {65000, 4100}, {20000, 1}}) {
    const std::string p = dir + "/big_" + std::to_string(w) + "x" + std::to_string(h) + ".png";
    write_file(dir, fs::path(p).filename().string(), png_header_only(w, h));
    try {
      read_image_header(p);
      FAIL() << "no error for " << w << "x" << h;
    } catch (const InvalidInputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(std::to_string(w) + "x" + std::to_string(h)), std::string::npos) << what;
      EXPECT_NE(what.find("--max-image-pixels"), std::string::npos) << what;
    }
    EXPECT_THROW(read_image(p), InvalidInputError);
  }
  // Within the limits the header is read without the pixels.
  const std::string small = dir + "/ok.png";
  write_image(small, Image(40, 30, 3, 0.5f));
  const ImageHeader hd = read_image_header(small);
  EXPECT_EQ(hd.width, 40);
  EXPECT_EQ(hd.height, 30);
  EXPECT_EQ(hd.channels, 3);
  ImageLimits tight;
  tight.max_pixels = 1000;
  EXPECT_THROW(read_image_header(small, tight), InvalidInputError);
  EXPECT_EQ(tight.max_side(), 16384);
  ImageLimits wide;
  wide.max_pixels = 1LL << 30;
  EXPECT_EQ(wide.max_side(), 32768);
}

// ---------------------------------------------------------------- staging

TEST(OutputStaging, NothingReachesItsPlaceBeforeCommit) {
  const std::string dir = test::temp_dir("staging_commit");
  {
    OutputStaging stage;
    write_file_atomic(dir + "/a.txt", "A");
    ensure_directory(dir + "/sub/deeper");
    write_file_atomic(dir + "/sub/deeper/b.txt", "B");
    EXPECT_FALSE(fs::exists(dir + "/a.txt"));
    EXPECT_FALSE(fs::exists(dir + "/sub"));
    std::ifstream f(staged_path(dir + "/sub/deeper/b.txt"));
    std::string b;
    f >> b;
    EXPECT_EQ(b, "B");  // readable where it is staged
    stage.commit();
  }
  EXPECT_TRUE(fs::exists(dir + "/a.txt"));
  EXPECT_TRUE(fs::exists(dir + "/sub/deeper/b.txt"));
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a.txt", "sub"}));
}

TEST(OutputStaging, AbandonLeavesNothingAndKeepsWhatWasThere) {
  const std::string dir = test::temp_dir("staging_abandon");
  write_file_atomic(dir + "/old.txt", "old");
  {
    OutputStaging stage;
    write_file_atomic(dir + "/old.txt", "new", true);
    write_file_atomic(dir + "/new.txt", "x");
    ensure_directory(dir + "/folder");
  }  // destroyed without commit
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"old.txt"});
  std::ifstream f(dir + "/old.txt");
  std::string s;
  f >> s;
  EXPECT_EQ(s, "old");
}

TEST(OutputStaging, AnOutputWrittenTwiceInOneRunIsRefused) {
  const std::string dir = test::temp_dir("staging_twice");
  OutputStaging stage;
  write_file_atomic(dir + "/r.json", "1");
  EXPECT_THROW(write_file_atomic(dir + "/./r.json", "2"), IOError);
  ensure_directory(dir + "/o");
  write_file_atomic(dir + "/o/x", "1");
  EXPECT_THROW(write_file_atomic(dir + "/o/../o/x", "2"), IOError);
}

TEST(OutputStaging, SameFileComparesPathsThatDoNotExistYet) {
  const std::string dir = test::temp_dir("same_file");
  EXPECT_TRUE(same_file(dir + "/r.ply", dir + "/./r.ply"));
  EXPECT_TRUE(same_file(dir + "/r.ply", dir + "/x/../r.ply"));
  EXPECT_FALSE(same_file(dir + "/r.ply", dir + "/s.ply"));
  EXPECT_FALSE(same_file("", ""));
}

// A temporary name beside a 255-character output was longer than the limit.
TEST(OutputStaging, A255CharacterNameWorksStagedOrNot) {
  const std::string dir = test::temp_dir("long_names");
  const std::string name = std::string(251, 'x') + ".txt";
  write_file_atomic(dir + "/" + name, "plain");
  EXPECT_TRUE(fs::exists(dir + "/" + name));
  const std::string name2 = std::string(251, 'y') + ".txt";
  {
    OutputStaging stage;
    write_file_atomic(dir + "/" + name2, "staged");
    stage.commit();
  }
  EXPECT_TRUE(fs::exists(dir + "/" + name2));
}

// A dead run's staging folder and temporaries are removed by the next sweep;
// a live run's are not.
TEST(OutputStaging, SweepRemovesOnlyWhatDeadRunsLeft) {
  const std::string dir = test::temp_dir("sweep");
  // Pid 2^22+1 is above Linux's default pid_max: never alive.
  fs::create_directories(dir + "/.surftex-stage-4194305-123/e0");
  write_file(dir, ".surftex-tmp-4194305-123-0.ply", "x");
  // Our own pid with another start time is a reused pid: stale too.
  fs::create_directories(dir + "/.surftex-stage-" + std::to_string(::getpid()) + "-1");
  // This process, with its real start time (/proc/self/stat field 22): alive, kept.
  std::ifstream st("/proc/self/stat");
  std::string stat((std::istreambuf_iterator<char>(st)), std::istreambuf_iterator<char>());
  std::istringstream rest(stat.substr(stat.rfind(')') + 1));
  std::string tok, start;
  for (int field = 3; field <= 22 && (rest >> tok); ++field) start = tok;
  const std::string live = ".surftex-stage-" + std::to_string(::getpid()) + "-" + start;
  fs::create_directories(dir + "/" + live);
  write_file(dir, "keep.txt", "k");
  EXPECT_EQ(sweep_stale_outputs(dir), 3u);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{live, "keep.txt"}));
}

// ---------------------------------------------------------------- polygons

// One face of 800K corners cycling over 4 vertices: `info` took 105 s
// (quadratic in CGAL's split of pinched polygons).
TEST(PinchedPolygons, ARepeatingPolygonIsSplitInLinearTime) {
  std::vector<std::vector<std::size_t>> polys(1);
  for (std::size_t i = 0; i < 800000; ++i) polys[0].push_back(i % 4);
  polys.push_back({0, 1, 2});
  const PinchedSplitCounts c = split_pinched_polygons(polys, 4);
  EXPECT_EQ(c.polygons_split, 1u);
  ASSERT_EQ(polys.size(), 2u + 199999u);
  for (std::size_t i = 2; i < polys.size(); ++i) EXPECT_EQ(polys[i], (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(polys[0], (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(polys[1], (std::vector<std::size_t>{0, 1, 2}));
  // A figure eight: two triangles sharing vertex 0.
  std::vector<std::vector<std::size_t>> eight{{0, 1, 2, 0, 3, 4}};
  split_pinched_polygons(eight, 5);
  ASSERT_EQ(eight.size(), 2u);
  EXPECT_EQ(eight[0], (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(eight[1], (std::vector<std::size_t>{0, 3, 4}));
}

TEST(PinchedPolygons, TheHugeFaceFileLoadsQuickly) {
  const std::string dir = test::temp_dir("pinched_file");
  std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf";
  for (int i = 0; i < 200000; ++i) obj += " " + std::to_string(i % 4 + 1);
  obj += "\n";
  const std::string p = write_file(dir, "pinched.obj", obj);
  Mesh m;
  SoupRepairCounts counts;
  read_mesh(p, m, {}, &counts);  // was 26 s at 400K corners, quadratic
  EXPECT_EQ(m.number_of_faces(), 2u);  // one quad left after duplicates merge, triangulated
}

// material-map's baked atlas is most of its memory at small meshes: 977 MB
// peak was measured for a 128-face sphere with a 4096^2 atlas (decision 602),
// 376 MB at 2048^2. The estimate must cover what the atlas costs.
TEST(WorkBudget, MaterialMapEstimateCoversTheBakedAtlas) {
  const double MiB = 1048576.0;
  const auto small = surftex::estimate_material_map(128, 9 * 256 * 256 * 12, 512, 512);
  const auto base = surftex::estimate_material_map(128, 9 * 256 * 256 * 12, 512, 2048);
  const auto big = surftex::estimate_material_map(128, 9 * 256 * 256 * 12, 512, 4096);
  EXPECT_GE(small.bytes, 246.0 * MiB);
  EXPECT_GE(base.bytes, 368.0 * MiB);
  EXPECT_GE(big.bytes, 955.0 * MiB);
  EXPECT_LT(big.bytes, 2.0 * 955.0 * MiB);  // not so far above that it refuses what fits
  EXPECT_NE(big.shrink.find("--atlas-size"), std::string::npos);
}

// The patches time estimate followed the exhaustive search (exemplar area x
// window^2 per texel): "38.9 min" was printed for a 116K-face run of 90 CPU s
// at the default approximate search, whose cost barely grows with the exemplar.
TEST(WorkBudget, PatchesTimeEstimateFollowsTheSearchInUse) {
  const auto approx64 = surftex::estimate_patches(116514, 64, 64, 1, 128, 200, 11, 64);
  const auto approx512 = surftex::estimate_patches(116514, 512, 512, 1, 128, 200, 11, 64);
  const auto exact512 = surftex::estimate_patches(116514, 512, 512, 1, 128, 200, 11, 64, true);
  EXPECT_LT(approx512.seconds, 3.0 * approx64.seconds);
  EXPECT_LT(approx512.seconds, 600.0);  // measured: 90 CPU s with a 256 px exemplar
  EXPECT_GT(approx512.seconds, 60.0);
  EXPECT_GT(exact512.seconds, 10.0 * approx512.seconds);
  EXPECT_EQ(approx512.bytes, exact512.bytes);
}
