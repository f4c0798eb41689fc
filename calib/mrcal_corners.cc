#include "calib/mrcal_corners.h"

#include <cstdio>
#include <sstream>

namespace ss::calib {

std::string MrcalViewName(const std::string& camera, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "-frame%06d.png", frame);
  return camera + buf;
}

std::string MrcalCornersVnl(const BoardSpec& board, const std::vector<CameraViews>& cameras) {
  std::ostringstream out;
  out << "# filename x y level\n";
  char buf[96];
  for (const auto& cam : cameras) {
    for (size_t i = 0; i < cam.views.size(); ++i) {
      const BoardView& v = cam.views[i];
      if (!v.accepted) continue;
      const std::string name =
          MrcalViewName(cam.name, i < cam.frames.size() ? cam.frames[i] : static_cast<int>(i));
      std::vector<const Eigen::Vector2d*> grid(board.corner_count(), nullptr);
      for (size_t k = 0; k < v.ids.size(); ++k) {
        if (v.ids[k] >= 0 && v.ids[k] < board.corner_count()) grid[v.ids[k]] = &v.pixels[k];
      }
      for (const auto* p : grid) {
        if (p) {
          std::snprintf(buf, sizeof buf, " %.17g %.17g 0\n", p->x(), p->y());
          out << name << buf;
        } else {
          out << name << " - - -\n";
        }
      }
    }
  }
  return out.str();
}

std::string MrcalCalibrateCommand(const BoardSpec& board, const std::vector<CameraViews>& cameras,
                                  const std::string& vnl_path, const std::string& out_dir,
                                  const std::string& lensmodel, double focal_px) {
  std::ostringstream o;
  // The tool's shebang is the Debian python (which has the mrcal module).
  o << "mkdir -p '" << out_dir
    << "' && /usr/bin/python3 /usr/bin/mrcal-calibrate-cameras --corners-cache '" << vnl_path
    << "' --lensmodel " << lensmodel << " --focal " << focal_px << " --object-spacing "
    << board.square_m << " --object-width-n " << board.corners_x() << " --object-height-n "
    << board.corners_y();
  if (!cameras.empty())
    o << " --imagersize " << cameras.front().width << " " << cameras.front().height;
  o << " --outdir '" << out_dir << "'";
  for (const auto& cam : cameras) o << " '" << cam.name << "-frame*.png'";
  return o.str();
}

}  // namespace ss::calib
