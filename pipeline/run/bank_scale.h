#pragma once
// The bank's billboard scale (px_per_m), chosen once for a bank (docs/pipeline.md, "The
// bank's scale"): a bank that holds sprites keeps its own scale; a configured number
// (pipeline.px_per_m) overrides for an empty bank; `auto` (0) picks it from the cameras:
// the finest camera's typical resolution of the floor it sees (SeenFloorPixelsPerMetre), capped
// so that anything a camera can see whole standing on the floor fits the billboard size limit.
#include <string>
#include <vector>

#include "core/bank.h"
#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss {

// Image pixels per metre on the floor at the polygon's centre (0 when the camera does not see it).
double FloorPixelsPerMetre(const CameraModel& model, const GroundPolygon& floor);

// The camera's typical resolution of the floor: the median, over the image pixels that see the
// floor (a 32x24 grid), of the image pixels per metre of floor there (0 when it sees none). A
// subject near the camera covers more of the image than one far away, and the floor's centre
// can be far off (a wide view over a square): the centre alone would store near subjects below
// the resolution they were seen at.
double SeenFloorPixelsPerMetre(const CameraModel& model, const GroundPolygon& floor);

// The height (metres) of the tallest upright thing the camera sees whole, standing anywhere on
// the floor that the camera sees (0 when it sees none of it). A usable sprite never touches the
// image border, so no usable sprite of this camera is taller than this.
double TallestVisibleM(const CameraModel& model, const GroundPolygon& floor);

struct BankScale {
  double px_per_m = 0;
  std::string why;  // one sentence for the log and `ingest --json`
};

struct BankScaleInputs {
  double configured = 0;                   // pipeline.px_per_m; 0 = auto
  std::vector<double> bank_scales;         // Bank::BillboardScales() of the bank
  std::string bank_path;                   // for messages
  std::vector<const CameraModel*> models;  // the cameras that store sprites
  GroundPolygon floor;
  int max_side_px = 512;   // RectifierOptions::max_side_px
  double margin_m = 0.01;  // RectifierOptions::margin_m
};

// InputError naming both scales when a configured number differs from the scale the bank
// already holds (one bank keeps one scale), and naming the bank when it already mixes scales.
BankScale ChooseBankScale(const BankScaleInputs& in);

// Where a bank records its scale (`meta`), so that writers starting together on an empty
// bank (stations and ingests on one PostgreSQL bank) agree before any sprite is stored.
inline constexpr const char* kBankScaleMetaKey = "billboard.px_per_m";

// ChooseBankScale with the bank's scales read from `bank` (its sprites' and its recorded one;
// `in.bank_scales` is ignored), then recorded there unless another writer recorded one first,
// in which case that one is used (or the configured number that differs is refused).
BankScale ChooseAndKeepBankScale(BankWriter& bank, BankScaleInputs in);

}  // namespace ss
