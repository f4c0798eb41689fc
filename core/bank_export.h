#pragma once
// `bank export`: a bank's visible sprites as PNG billboards plus one CSV of every field.
#include <cstdint>
#include <string>

#include "core/bank.h"

namespace ss {

// No IsValid (core/option_checks.h): any tag is a name a sprite may carry (an unknown one
// exports nothing) and the other field is a switch, so no value is out of range.
struct BankExportOptions {
  std::string tag;              // only sprites with this tag; empty = all
  bool include_mirrors = true;  // mirrored copies too (their flipped pixels)
};

// Writes DIR/sprites.csv (one row per sprite of a complete clip, every column of the
// sprites table plus tags) and DIR/sprite_<id>.png (BGRA billboard) and
// DIR/sprite_<id>_shadow.png. Returns the number of sprites written.
// WorkError naming the file when one cannot be written.
// The CSV's header line and one sprite's row (each ending in a newline); the png columns name
// the files ExportBank writes beside it.
std::string SpriteCsvHeader();
std::string SpriteCsvRow(const SpriteRecord& s);

int64_t ExportBank(const Bank& bank, const std::string& dir, const BankExportOptions& options);

}  // namespace ss
