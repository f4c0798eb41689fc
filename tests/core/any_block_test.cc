// AnyBlock (core/any_block.h): the block of keys a part registered apart owns, held by a struct
// that does not name its type, copied and compared with it.
#include "core/any_block.h"

#include <string>
#include <utility>

#include <gtest/gtest.h>

namespace ss {
namespace {

struct Lens {
  std::string mount = "c";
  double focal_mm = 8;
  bool operator==(const Lens&) const = default;
};

struct Port {
  int number = 0;
  bool operator==(const Port&) const = default;
};

TEST(AnyBlock, HoldsOneTypeCopiedAndComparedByValue) {
  AnyBlock empty;
  EXPECT_EQ(empty.Find<Lens>(), nullptr);
  EXPECT_EQ(empty.Get<Lens>(), Lens{});  // the defaults, nothing made
  EXPECT_EQ(empty.Find<Lens>(), nullptr);

  AnyBlock block;
  block.Use<Lens>().focal_mm = 12;
  ASSERT_NE(block.Find<Lens>(), nullptr);
  EXPECT_EQ(block.Find<Port>(), nullptr);
  EXPECT_EQ(block.Get<Lens>().focal_mm, 12);
  EXPECT_FALSE(block == empty);

  AnyBlock copy = block;  // a copy of its own
  EXPECT_TRUE(copy == block);
  copy.Use<Lens>().mount = "cs";
  EXPECT_FALSE(copy == block);
  EXPECT_EQ(block.Get<Lens>().mount, "c");

  // Another type replaces it; blocks of two types never compare equal.
  AnyBlock port;
  port.Use<Port>();
  EXPECT_FALSE(port == block);
  copy = port;
  EXPECT_EQ(copy.Find<Lens>(), nullptr);
  EXPECT_TRUE(copy == port);
  copy.Use<Lens>();
  EXPECT_EQ(copy.Get<Lens>(), Lens{});
  EXPECT_EQ(copy.Find<Port>(), nullptr);

  AnyBlock moved = std::move(block);
  EXPECT_EQ(moved.Get<Lens>().focal_mm, 12);
}

}  // namespace
}  // namespace ss
