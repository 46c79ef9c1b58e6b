// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cstdint>

#include "geometry/union_find.h"

namespace surftex {
namespace {

// Roots are the lowest index of their set whatever the order of the unions:
// the labels the quilting, PGP and fidelity code derive from them do not
// depend on traversal order.
TEST(UnionFind, RootIsTheLowestIndexWhateverTheUnionOrder) {
  UnionFind<int> a(8), b(8);
  a.unite(1, 5);
  a.unite(5, 7);
  a.unite(3, 2);
  b.unite(7, 5);
  b.unite(2, 3);
  b.unite(7, 1);
  for (int x = 0; x < 8; ++x) EXPECT_EQ(a.find(x), b.find(x)) << x;
  EXPECT_EQ(a.find(7), 1);
  EXPECT_EQ(a.find(3), 2);
  EXPECT_EQ(a.find(0), 0);
  EXPECT_EQ(a.find(6), 6);
}

TEST(UnionFind, UniteSaysWhetherTwoSetsWereMerged) {
  UnionFind<std::uint32_t> s(4);
  EXPECT_TRUE(s.unite(0, 1));
  EXPECT_TRUE(s.unite(2, 3));
  EXPECT_FALSE(s.unite(1, 0));
  EXPECT_TRUE(s.unite(3, 1));
  EXPECT_FALSE(s.unite(2, 0));
  s.reset(3);
  EXPECT_EQ(s.size(), 3u);
  EXPECT_EQ(s.find(2), 2u);
}

}  // namespace
}  // namespace surftex
