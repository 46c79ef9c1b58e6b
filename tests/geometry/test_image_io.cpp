// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include <cstdint>
#include <filesystem>
#include <fstream>

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

// The TIFF writer stamped the clock into its DateTime tag: material-tile's
// layers.tif differed between two runs of the same input and seed.
TEST(ImageIO, TiffBytesDoNotDependOnTheClock) {
  std::string dir = test::temp_dir("img_tiff_time");
  const std::vector<Image> layers{ramp(8, 8, 3), ramp(8, 8, 3)};
  write_image_layers(dir + "/a.tif", layers);
  write_image(dir + "/a1.tif", layers[0]);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // the tag has one-second resolution
  write_image_layers(dir + "/b.tif", layers);
  write_image(dir + "/b1.tif", layers[0]);
  EXPECT_EQ(test::file_bytes(dir + "/a.tif"), test::file_bytes(dir + "/b.tif"));
  EXPECT_EQ(test::file_bytes(dir + "/a1.tif"), test::file_bytes(dir + "/b1.tif"));
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
  std::string bytes = test::file_bytes(dir + "/a.png");
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

namespace {
void spit(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }
// The message of the error read_image throws on `path` ("" when it reads).
template <class E>
std::string refusal(const std::string& path) {
  try {
    read_image(path);
  } catch (const E& e) {
    return e.what();
  }
  return "";
}
// Where the 4-byte size of OpenEXR attribute `name` of `type` sits in `bytes`
// (its value follows it); npos when the header has no such attribute.
std::size_t exr_size_field(const std::string& bytes, const std::string& name, const std::string& type) {
  const std::string key = name + '\0' + type + '\0';
  const auto at = bytes.find(key);
  return at == std::string::npos ? at : at + key.size();
}
// Overwrites the 4 little-endian bytes at `at`.
void put_le32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b[at + k] = static_cast<char>((v >> (8 * k)) & 0xFFu);
}
}  // namespace

// Every format the gate lets through (by its first bytes) still reads, whatever
// the file is called.
TEST(ImageFormatGate, EveryWrittenFormatReadsBackByItsFirstBytes) {
  std::string dir = test::temp_dir("img");
  for (const std::string ext : {"png", "jpg", "tif", "exr", "bmp", "hdr", "ppm", "tga"}) {
    const std::string path = dir + "/a." + ext;
    write_image(path, ramp(8, 6, 3));
    const Image back = read_image(path);
    EXPECT_EQ(back.width, 8) << ext;
    EXPECT_EQ(back.height, 6) << ext;
    if (ext == "tga") continue;  // Targa has no signature: read by its name only
    fs::copy_file(path, dir + "/noext_" + ext);
    EXPECT_EQ(read_image(dir + "/noext_" + ext).width, 8) << ext << " without its extension";
  }
}

// A file that is no image format surftex reads is refused by its first bytes,
// not handed to every OpenImageIO plugin in turn (DICOM's among them).
TEST(ImageFormatGate, NonImageBytesAreRefusedByName) {
  std::string dir = test::temp_dir("img");
  spit(dir + "/notes.png", "just some text, not a picture\n");
  std::string dicom(128, '\0');
  dicom += "DICM";
  dicom += std::string(64, '\x02');
  spit(dir + "/scan.dcm", dicom);
  for (const std::string name : {"notes.png", "scan.dcm"}) {
    const std::string msg = refusal<IOError>(dir + "/" + name);
    EXPECT_NE(msg.find("it is not a PNG, JPEG, TIFF, OpenEXR"), std::string::npos) << msg;
    EXPECT_NE(msg.find(name), std::string::npos) << msg;
  }
}

// An OpenEXR header attribute claiming more bytes than the file holds made
// OpenEXR allocate that much (fuzz_image_header, 342 MB for a 2 kB file):
// refused before OpenEXR reads it, naming the attribute.
TEST(ImageFormatGate, ExrAttributeLongerThanTheFileIsRefused) {
  std::string dir = test::temp_dir("img");
  write_image(dir + "/a.exr", ramp(4, 4, 3));
  std::string b = test::file_bytes(dir + "/a.exr");
  const auto size = exr_size_field(b, "channels", "chlist");
  ASSERT_NE(size, std::string::npos);
  put_le32(b, size, 400u << 20);
  spit(dir + "/b.exr", b);
  const std::string msg = refusal<IOError>(dir + "/b.exr");
  EXPECT_NE(msg.find("OpenEXR attribute 'channels'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("claims 419430400 bytes"), std::string::npos) << msg;
  EXPECT_EQ(read_image(dir + "/a.exr").width, 4);  // the intact file still reads
}

// A data window beyond the image limits, and one whose offset table would
// need more bytes than the file has, are refused from the header alone.
TEST(ImageFormatGate, ExrDataWindowAndOffsetTableAreCheckedAgainstTheFile) {
  std::string dir = test::temp_dir("img");
  write_image(dir + "/a.exr", ramp(4, 4, 3));
  const std::string a = test::file_bytes(dir + "/a.exr");
  const auto win = exr_size_field(a, "dataWindow", "box2i");
  ASSERT_NE(win, std::string::npos);
  const std::size_t box = win + 4;  // xmin ymin xmax ymax after the size
  std::string huge = a;
  put_le32(huge, box + 8, 3000000u);  // xmax
  spit(dir + "/huge.exr", huge);
  const std::string big = refusal<InvalidInputError>(dir + "/huge.exr");
  EXPECT_NE(big.find("OpenEXR data window"), std::string::npos) << big;
  EXPECT_NE(big.find("--max-image-pixels"), std::string::npos) << big;

  // 4 x 16000 lines, within the limits, but its offsets cannot fit in the file.
  std::string tall = a;
  put_le32(tall, box + 12, 15999u);  // ymax
  const auto disp = exr_size_field(tall, "displayWindow", "box2i");
  ASSERT_NE(disp, std::string::npos);
  put_le32(tall, disp + 4 + 12, 15999u);
  spit(dir + "/tall.exr", tall);
  const std::string off = refusal<IOError>(dir + "/tall.exr");
  EXPECT_NE(off.find("OpenEXR offset table"), std::string::npos) << off;
}

// OpenEXR reads a box2i as 16 bytes whatever size the file declares; a
// declared 0 made it read on from the wrong place (a later "size" of 1.7 GB,
// fuzz_image_header). A known type must fill its declared size exactly.
TEST(ImageFormatGate, ExrAttributeOfAKnownTypeMustFillItsDeclaredSize) {
  std::string dir = test::temp_dir("img");
  write_image(dir + "/a.exr", ramp(4, 4, 3));
  std::string b = test::file_bytes(dir + "/a.exr");
  const auto win = exr_size_field(b, "dataWindow", "box2i");
  ASSERT_NE(win, std::string::npos);
  put_le32(b, win, 0u);
  spit(dir + "/b.exr", b);
  const std::string msg = refusal<IOError>(dir + "/b.exr");
  EXPECT_NE(msg.find("OpenEXR attribute 'dataWindow' of type box2i has 0 bytes, not 16"), std::string::npos) << msg;
}

// OpenImageIO 2.4 copies a Photoshop (APP13) segment's IPTC block by the size
// the block declares, past the segment's end (a heap overflow under ASan,
// fuzz_image_header): refused when the block does not fit its segment. A
// well-formed block still reads.
TEST(ImageFormatGate, JpegIptcBlockMustFitItsSegment) {
  std::string dir = test::temp_dir("img");
  write_image(dir + "/a.jpg", ramp(8, 8, 3));
  const std::string a = test::file_bytes(dir + "/a.jpg");
  auto with_app13 = [&](std::uint16_t declared, std::size_t held) {
    std::string payload = std::string("Photoshop 3.0\0", 14) + "8BIM" + std::string("\x04\x04\0\0\0\0", 6);
    payload += static_cast<char>(declared >> 8);
    payload += static_cast<char>(declared & 0xFF);
    payload += std::string(held, 'x');
    const std::size_t len = payload.size() + 2;
    std::string seg = "\xFF\xED";
    seg += static_cast<char>(len >> 8);
    seg += static_cast<char>(len & 0xFF);
    return a.substr(0, 2) + seg + payload + a.substr(2);
  };
  spit(dir + "/ok.jpg", with_app13(0, 0));
  EXPECT_EQ(read_image(dir + "/ok.jpg").width, 8);
  spit(dir + "/bad.jpg", with_app13(60000, 8));
  const std::string msg = refusal<IOError>(dir + "/bad.jpg");
  EXPECT_NE(msg.find("the Photoshop (APP13) segment at byte 2 holds an IPTC block of 60000 bytes"), std::string::npos)
      << msg;
}
