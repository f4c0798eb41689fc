// spritestation plate SESSION --camera NAME --out IMAGE [--frames A:B] [--samples N]:
// writes one camera's clean plate (the per-pixel median of its empty-enclosure frames),
// e.g. as the background an animation is rendered over (docs/animation.md).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "apps/commands.h"
#include "capture/replay/session_plate.h"
#include "core/error.h"

namespace ss::apps {
namespace {

struct PlateArgs {
  std::string session, camera, out, frames = "0:29";
  int samples = 30;
};

PlateOptions ParseRange(const std::string& text, int samples) {
  PlateOptions o;
  o.samples = samples;
  const size_t colon = text.find(':');
  try {
    size_t used = 0;
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    o.first_frame = std::stoll(text.substr(0, colon), &used);
    if (used != colon) throw std::invalid_argument("first");
    const std::string last = text.substr(colon + 1);
    o.last_frame = std::stoll(last, &used);
    if (used != last.size()) throw std::invalid_argument("last");
  } catch (const std::exception&) {
    throw InputError("--frames",
                     "expected FIRST:LAST frame numbers, e.g. 0:29, got \"" + text + "\"");
  }
  return o;
}

void Run(const PlateArgs& args) {
  const PlateOptions options = ParseRange(args.frames, args.samples);
  // Before decoding anything: an image that could not be written.
  const std::filesystem::path out(args.out);
  if (!cv::haveImageWriter(args.out)) {
    throw InputError("--out", args.out + ": no image format for the extension \"" +
                                  out.extension().string() + "\" (use .png)");
  }
  if (const std::filesystem::path folder = out.parent_path();
      !folder.empty() && !std::filesystem::is_directory(folder)) {
    throw InputError("--out", args.out + ": the folder " + folder.string() + " does not exist");
  }
  const SessionPlate plate = ReadSessionPlate(args.session, args.camera, options);
  bool written = false;
  try {
    written = cv::imwrite(args.out, plate.bgr);
  } catch (const cv::Exception& e) {
    throw InputError("--out", args.out + ": cannot write the image (" + e.err + ")");
  }
  if (!written) throw WorkError(args.out, "cannot write the image");
  std::printf("%s camera %s: plate of %d frames (%lld..%lld, %.3f..%.3f s) -> %s (%dx%d)\n",
              args.session.c_str(), args.camera.c_str(), plate.frames_used,
              static_cast<long long>(plate.first_frame), static_cast<long long>(plate.last_frame),
              static_cast<double>(plate.first_timestamp_ns) / 1e9,
              static_cast<double>(plate.last_timestamp_ns) / 1e9, args.out.c_str(), plate.bgr.cols,
              plate.bgr.rows);
}

}  // namespace

void AddPlateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "plate", "Write a camera's clean plate (the empty enclosure) from a recorded session");
  auto args = std::make_shared<PlateArgs>();
  cmd->add_option("session", args->session, "Session folder (holds session.json)")->required();
  cmd->add_option("--camera", args->camera, "The session's camera")->required();
  cmd->add_option("--out", args->out, "Image to write (.png, .jpg, ...: by its extension)")
      ->required();
  cmd->add_option(
      "--frames", args->frames,
      "FIRST:LAST frames the plate is taken from (default 0:29, the frames a keyer learns the "
      "empty enclosure from)");
  cmd->add_option("--samples", args->samples,
                  "Frames taken, spread evenly over the range (default 30)")
      ->check(CLI::Range(1, 1000));
  cmd->callback([args] { Run(*args); });
}

}  // namespace ss::apps
