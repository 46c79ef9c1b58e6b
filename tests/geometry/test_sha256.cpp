// SPDX-License-Identifier: AGPL-3.0-or-later
// SHA-256 against the FIPS 180-4 example vectors and the system's sha256sum.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "geometry/errors.h"
#include "geometry/sha256.h"
#include "test_support.h"

using namespace surftex;

TEST(Sha256, FipsExampleVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, FileMatchesSha256sumAcrossReadBlocks) {
  // 2.5 MiB + 7 bytes: three 1 MiB reads, padding in a partial block.
  const std::string d = test::temp_dir("sha");
  std::string bytes((5u << 19) + 7, '\0');
  std::uint32_t h = 7;
  for (char& c : bytes) c = static_cast<char>((h = h * 1103515245u + 12345u) >> 24);
  std::ofstream(d + "/f.bin", std::ios::binary) << bytes;
  FILE* p = ::popen(("sha256sum '" + d + "/f.bin'").c_str(), "r");
  ASSERT_NE(p, nullptr);
  char out[65] = {};
  ASSERT_EQ(std::fread(out, 1, 64, p), 64u);
  ::pclose(p);
  EXPECT_EQ(sha256_file_hex(d + "/f.bin"), std::string(out, 64));
  EXPECT_EQ(sha256_hex(bytes), std::string(out, 64));
  EXPECT_THROW(sha256_file_hex(d + "/missing"), IOError);
}
