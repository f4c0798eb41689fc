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

// The rows of the docs' key tables: the type is the field's (with its rule, or as Type() says
// it), the default the field's value when bound, as code, or in words as Default() gives it.
TEST(OptionsBinder, RowsGiveEveryKeyItsTypeDefaultAndDoc) {
  Options o;
  OptionsBinder b = Keys(o);
  b.Add("ratio", &o.low, "a ratio >= 1", "how many times").Rule(AtLeast(1));
  b.Add("shape", &o.frames, "a shape", "a shape of its own").Type("list of points").Default("none");
  std::vector<std::string> got;
  for (const OptionsBinder::Row& r : b.Rows())
    got.push_back(r.key + " | " + r.type + " | " + r.default_cell + " | " + r.doc);
  EXPECT_EQ(got,
            (std::vector<std::string>{"frames | integer | `30` | frames to learn from",
                                      "block.low | number | `20` | where alpha starts to fall",
                                      "block.enabled | bool | `true` | whether the block applies",
                                      "colour | `red` | `green` | `red` | the screen's colour",
                                      "ratio | number >= 1 | `20` | how many times",
                                      "shape | list of points | none | a shape of its own"}));
}

}  // namespace
}  // namespace ss
