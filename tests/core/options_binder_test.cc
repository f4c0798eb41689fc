// Config keys bound to option fields: a key sets its field, nested keys read their own
// mapping, an unknown key is refused by its full name with a near miss suggested, a wrong type
// names the file, the line and the key, and the defaults are the fields' values when bound.
#include "core/options_binder.h"

#include <gtest/gtest.h>

namespace ss {
namespace {

enum class Colour { kRed, kGreen };
constexpr EnumText<Colour> kColourTexts[] = {{Colour::kRed, "red"}, {Colour::kGreen, "green"}};

struct Options {
  int frames = 30;
  double low = 20;
  bool enabled = true;
  Colour colour = Colour::kRed;
};

OptionsBinder Keys(Options& o) {
  OptionsBinder b;
  b.Add("frames", &o.frames, "a number of frames", "frames to learn from")
      .Add("block.low", &o.low, "a level 0..255", "where alpha starts to fall")
      .Add("block.enabled", &o.enabled, "whether the block applies")
      .AddEnum("colour", &o.colour, kColourTexts, "the screen's colour");
  return b;
}

// Reads `yaml` as the block `path`; the messages, one per line.
std::vector<std::string> Read(const std::string& yaml, Options& o,
                              const std::string& path = "keying") {
  std::map<std::string, int> lines;
  YamlMessages msg("station.yaml", lines);
  YamlReader r(msg, lines, "/studio");
  Keys(o).Read(r, YAML::Load(yaml), path);
  return msg.errors;
}

TEST(OptionsBinder, SetsEachBoundFieldFromItsKey) {
  Options o;
  EXPECT_TRUE(Read("frames: 5\nblock:\n  low: 12\n  enabled: false\ncolour: green\n", o).empty());
  EXPECT_EQ(o.frames, 5);
  EXPECT_EQ(o.low, 12);
  EXPECT_FALSE(o.enabled);
  EXPECT_EQ(o.colour, Colour::kGreen);
}

TEST(OptionsBinder, KeysNotGivenKeepTheirDefaults) {
  Options o;
  EXPECT_TRUE(Read("frames: 5\n", o).empty());
  EXPECT_EQ(o.low, 20);
  EXPECT_TRUE(o.enabled);
}

TEST(OptionsBinder, ErrorsNameTheFileLineAndFullKey) {
  Options o;
  EXPECT_EQ(Read("frames: 5\nblock:\n  lw: 12\n", o),
            std::vector<std::string>{
                "station.yaml:3: keying.block.lw: unknown key (did you mean \"low\"?)"});
  EXPECT_EQ(Read("frames: many\n", o),
            std::vector<std::string>{
                "station.yaml:1: keying.frames: expected a number of frames, got \"many\""});
  EXPECT_EQ(Read("colour: blue\n", o),
            std::vector<std::string>{
                "station.yaml:1: keying.colour: expected one of red, green, got \"blue\""});
  EXPECT_EQ(Read("block: 3\n", o),
            std::vector<std::string>{
                "station.yaml:1: keying.block: expected a mapping of keys, got \"3\""});
}

TEST(OptionsBinder, DescribesEveryKeyWithItsDefault) {
  Options o;
  EXPECT_EQ(Keys(o).Describe("keying"),
            "keying.frames: 30  # frames to learn from\n"
            "keying.block.low: 20  # where alpha starts to fall\n"
            "keying.block.enabled: true  # whether the block applies\n"
            "keying.colour: red  # the screen's colour\n");
}

}  // namespace
}  // namespace ss
