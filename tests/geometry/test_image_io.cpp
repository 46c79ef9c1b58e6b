// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/output_file.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {
Image ramp(int w, int h, int c) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) img.at(x, y, k) = static_cast<float>((x * 7 + y * 13 + k * 50) % 256) / 255.f;
  return img;
}
}  // namespace

TEST(ImageIO, PngRoundTripIsExactFor8BitValues) {
  std::string dir = test::temp_dir("img");
  Image a = ramp(33, 17, 3);
  write_image(dir + "/a.png", a);
  Image b = read_image(dir + "/a.png");
  ASSERT_EQ(b.width, 33);
  ASSERT_EQ(b.height, 17);
  ASSERT_EQ(b.channels, 3);
  for (std::size_t i = 0; i < a.data.size(); ++i) EXPECT_NEAR(a.data[i], b.data[i], 1e-6);
}

TEST(ImageIO, ExrKeepsFloats) {
  std::string dir = test::temp_dir("img");
  Image a(4, 4, 1);
  a.at(1, 2) = 0.123456f;
  a.at(3, 3) = 7.5f;  // above 1: only float formats keep it
  write_image(dir + "/a.exr", a, {.eight_bit = false});
  Image b = read_image(dir + "/a.exr");
  EXPECT_FLOAT_EQ(b.at(1, 2), 0.123456f);
  EXPECT_FLOAT_EQ(b.at(3, 3), 7.5f);
}

TEST(ImageIO, MultiLayerTiffRoundTrip) {
  std::string dir = test::temp_dir("img");
  std::vector<Image> layers{ramp(8, 8, 3), ramp(8, 8, 3), ramp(8, 8, 3)};
  layers[1].at(0, 0, 0) = 1.f;
  layers[2].at(0, 0, 0) = 0.f;
  write_image_layers(dir + "/t.tif", layers);
  auto back = read_image_layers(dir + "/t.tif");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_FLOAT_EQ(back[1].at(0, 0, 0), 1.f);
  EXPECT_FLOAT_EQ(back[2].at(0, 0, 0), 0.f);
}

TEST(ImageIO, MissingFileIsIOErrorNamingThePath) {
  try {
    read_image("/nonexistent/x.png");
    FAIL() << "no throw";
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.png"), std::string::npos);
  }
}

TEST(ImageIO, GarbageAndEmptyFilesAreRefused) {
  std::string dir = test::temp_dir("img");
  { std::ofstream(dir + "/empty.png"); }
  {
    std::ofstream f(dir + "/junk.png", std::ios::binary);
    for (int i = 0; i < 1000; ++i) f.put(static_cast<char>((i * 2654435761u) >> 13));
  }
  try {
    read_image(dir + "/empty.png");
    FAIL() << "empty file accepted";
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("is empty (0 bytes)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_image(dir + "/junk.png"), Error);
}

TEST(ImageIO, TruncatedPngIsRefused) {
  std::string dir = test::temp_dir("img");
  write_image(dir + "/a.png", ramp(64, 64, 3));
  auto size = fs::file_size(dir + "/a.png");
  fs::resize_file(dir + "/a.png", size / 2);
  // The refusal is ours alone: libpng, left to find the damage, prints its
  // own "libpng error: ..." line on stderr before our error.
  testing::internal::CaptureStderr();
  try {
    read_image(dir + "/a.png");
    ADD_FAILURE() << "truncated file accepted";
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated or corrupt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("past the end of the file"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(ImageIO, PngWithADamagedChunkIsRefusedNamingTheChunk) {
  std::string dir = test::temp_dir("img");
  write_image(dir + "/a.png", ramp(64, 64, 3));
  std::string bytes;
  {
    std::ifstream f(dir + "/a.png", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(f), {});
  }
  const auto idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 10] = static_cast<char>(bytes[idat + 10] ^ 0x5A);  // one byte of compressed data
  {
    std::ofstream f(dir + "/b.png", std::ios::binary);
    f << bytes;
  }
  testing::internal::CaptureStderr();
  try {
    read_image(dir + "/b.png");
    ADD_FAILURE() << "damaged file accepted";
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("PNG chunk 'IDAT'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("CRC"), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  // The intact file still reads (the check accepts what libpng writes).
  EXPECT_EQ(read_image(dir + "/a.png").width, 64);
}

TEST(ImageIO, EmptyImageIsNotWrittenAndLeavesNoFile) {
  std::string dir = test::temp_dir("img");
  EXPECT_THROW(write_image(dir + "/e.png", Image()), InvalidInputError);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(OutputFile, RefusesToOverwriteWithoutPermission) {
  std::string dir = test::temp_dir("out");
  write_file_atomic(dir + "/f.txt", "one");
  EXPECT_THROW(write_file_atomic(dir + "/f.txt", "two", /*overwrite=*/false), IOError);
  std::ifstream f(dir + "/f.txt");
  std::string s;
  f >> s;
  EXPECT_EQ(s, "one");
}

TEST(OutputFile, UncommittedTemporaryIsRemoved) {
  std::string dir = test::temp_dir("out");
  {
    AtomicOutputFile out(dir + "/x.obj");
    std::ofstream(out.temp_path()) << "partial";
    // destroyed without commit: as when a writer throws half-way
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(OutputFile, MissingFolderIsAnError) {
  EXPECT_THROW(AtomicOutputFile("/nonexistent-dir/x.obj"), IOError);
}
