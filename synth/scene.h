#pragma once
// The studio the synthetic cameras look at: a green floor (the ground, z = 0)
// with green walls, inside a plain grey room, lit diffusely from above. Every
// background surface is a flat quad, so a ray meets the background exactly.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/enum_text.h"
#include "core/geometry.h"
#include "synth/lens.h"

namespace ss::synth {

// enclosure: 1.2 m x 0.8 m floor, 0.25 m walls on all four sides (animals).
// stage: 4 m x 3 m floor, 2.5 m walls at the back and the sides (figures).
enum class StudioKind { kEnclosure, kStage };
inline constexpr EnumText<StudioKind> kStudioKindTexts[] = {{StudioKind::kEnclosure, "enclosure"},
                                                            {StudioKind::kStage, "stage"}};

enum class Surface : int { kGreenFloor, kGreenWall, kWallOutside, kRoomFloor, kRoomWall, kCeiling };

struct Quad {
  Eigen::Vector3d origin;
  Eigen::Vector3d u, v;    // edge vectors; the quad is origin + a u + b v, a, b in [0, 1]
  Eigen::Vector3d normal;  // unit, u x v
  Surface front = Surface::kGreenWall;  // seen from the normal's side
  Surface back = Surface::kWallOutside;
};

struct BackgroundHit {
  double t = 0.0;  // distance along the (unit) ray
  int quad = -1;
  Surface surface = Surface::kRoomWall;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // facing the ray
};

struct Studio {
  StudioKind kind = StudioKind::kEnclosure;
  double half_x = 0.6, half_y = 0.4;  // green floor: [-half_x, half_x] x [-half_y, half_y]
  double wall_height = 0.25;
  bool room_backdrop = true;  // false: everything outside the walls is green too
  uint64_t seed = 0;
  GroundPolygon floor;           // the green floor, counter-clockwise
  std::vector<Quad> quads;       // [0] is the whole z = 0 plane of the room
  std::vector<int> green_walls;  // indices into quads
  double subject_scale = 0.1;    // typical subject size in metres (lighting, shadows)

  // The first background surface along the ray (the room closes everything).
  BackgroundHit Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  // Radiance (B, G, R, 0..255 before camera gain and vignetting) at a background hit.
  Eigen::Vector3d Radiance(const BackgroundHit& hit) const;
  // Distance from a floor point to the nearest green wall (infinity without walls).
  double DistanceToWall(const Eigen::Vector2d& point_in_ground) const;
  // The green-floor colour as lit from above (used for bounce light on subjects).
  Eigen::Vector3d FloorBounce() const;
};

// `room_backdrop` false paints the room green (a cyclorama everywhere).
Studio MakeStudio(StudioKind kind, uint64_t seed, bool room_backdrop = true);

// Where the cameras stand: around the floor looking down at it obliquely (38-62 degrees above
// it, as the paper filmed its hamster), or above it looking (nearly) straight down, as
// open-field and home-cage rigs film (82-90 degrees; enclosure only).
enum class CameraView { kOblique, kOverhead };
inline constexpr EnumText<CameraView> kCameraViewTexts[] = {{CameraView::kOblique, "oblique"},
                                                            {CameraView::kOverhead, "overhead"}};

// K cameras with OPENCV8 lenses, at different azimuths and heights, looking at
// the floor. Depends only on (studio kind, count, size, seed, view); the overhead view draws the
// same random numbers, so its lenses and gains are the oblique view's.
std::vector<SynthCamera> MakeCameras(const Studio& studio, int count, int width, int height,
                                     uint64_t seed, CameraView view = CameraView::kOblique);

// A camera pose looking from `centre` at `target` (ground frame, z up), rolled by `roll_rad`.
Rigid3 LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll_rad);

std::string StudioKindName(StudioKind kind);

// How far the ray from `position` along `heading_rad` runs before it leaves the studio's floor
// polygon, metres (infinity when it meets no edge).
double RoomAhead(const Studio& studio, const Eigen::Vector2d& position, double heading_rad);

}  // namespace ss::synth
