// The camera model against independent ground truth: a hand-written OpenCV
// rational projection, floor points, libmrcal's own reader and writer, and
// (when python3-mrcal is installed) mrcal's Python reader and projection.
#include "core/camera_model.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/test_support.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace ss {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using ss::testing::ScratchDir;

// fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6: a wide 1080p lens with strong barrel distortion
// (the image corner is 18% in from where it would be without), still invertible
// out to the corners.
const std::vector<double> kOpencv8 = {1100.0, 1098.5,  961.3,  538.7, -0.20, 0.05,
                                      0.0006, -0.0004, -0.005, 0.03,  0.004, -0.001};

// A camera at `centre` looking at `target` (x right, y down, z forward).
Rigid3 LookAt(const Vector3d& centre, const Vector3d& target) {
  const Vector3d z = (target - centre).normalized();
  const Vector3d x = z.cross(Vector3d::UnitZ()).normalized();
  const Vector3d y = z.cross(x);
  Rigid3 cam_from_ground;
  cam_from_ground.rotation.row(0) = x;
  cam_from_ground.rotation.row(1) = y;
  cam_from_ground.rotation.row(2) = z;
  cam_from_ground.translation = -(cam_from_ground.rotation * centre);
  return cam_from_ground;
}

CameraModel Opencv8Camera() {
  return CameraModel("LENSMODEL_OPENCV8", kOpencv8, 1920, 1080,
                     LookAt(Vector3d(0.2, -2.5, 1.6), Vector3d(0.0, 0.6, 0.0)));
}

// OpenCV's rational model written out by hand (the definition mrcal's OPENCV8 follows).
Vector2d ProjectOpencv8ByHand(const std::vector<double>& k, const Vector3d& p) {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial =
      (1 + k[4] * r2 + k[5] * r4 + k[8] * r6) / (1 + k[9] * r2 + k[10] * r4 + k[11] * r6);
  const double xd = x * radial + 2 * k[6] * x * y + k[7] * (r2 + 2 * x * x);
  const double yd = y * radial + k[6] * (r2 + 2 * y * y) + 2 * k[7] * x * y;
  return {k[0] * xd + k[2], k[1] * yd + k[3]};
}

std::vector<Vector2d> PixelGrid(int width, int height, int step) {
  std::vector<Vector2d> pixels;
  for (int v = 0;; v += step) {
    const double vv = std::min(v, height - 1);
    for (int u = 0;; u += step) {
      pixels.emplace_back(std::min(u, width - 1), vv);
      if (u >= width - 1) break;
    }
    if (v >= height - 1) break;
  }
  return pixels;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// The message of the InputError `fn` throws; fails the test if it throws nothing or something else.
template <typename Fn>
std::string InputErrorOf(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing thrown";
  return {};
}

TEST(CameraModel, Opencv8ProjectsLikeOpencvRationalModel) {
  const CameraModel cam = Opencv8Camera();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.8, 0.8);
  for (int i = 0; i < 500; ++i) {
    const Vector3d p(u(rng), u(rng) * 0.55, 1.0 + std::abs(u(rng)) * 3);
    const Vector2d expected = ProjectOpencv8ByHand(kOpencv8, p);
    EXPECT_LT((cam.Project(p) - expected).norm(), 1e-9) << p.transpose();
  }
}

TEST(CameraModel, Opencv8UnprojectThenProjectIsIdentityAcrossTheImage) {
  const CameraModel cam = Opencv8Camera();
  // corners included
  const std::vector<Vector2d> pixels = PixelGrid(cam.width(), cam.height(), 40);
  double worst = 0;
  for (const Vector2d& px : pixels) {
    const Vector3d ray = cam.Unproject(px);
    ASSERT_TRUE(ray.allFinite()) << px.transpose();
    EXPECT_NEAR(ray.norm(), 1.0, 1e-14);
    EXPECT_GT(ray.z(), 0);
    worst = std::max(worst, (cam.Project(ray) - px).norm());
    worst = std::max(worst, (cam.Project(3.7 * ray) - px).norm());  // any point on the ray
  }
  EXPECT_LT(worst, 1e-6) << "pixel error after unproject -> project";
  // The batch forms give the same answers as the single-point ones.
  std::vector<Vector3d> rays(pixels.size());
  cam.UnprojectMany(pixels.data(), pixels.size(), rays.data());
  std::vector<Vector2d> back(pixels.size());
  cam.ProjectMany(rays.data(), rays.size(), back.data());
  for (size_t i = 0; i < pixels.size(); i += 97) {
    EXPECT_EQ(rays[i], cam.Unproject(pixels[i]));
    EXPECT_EQ(back[i], cam.Project(rays[i]));
  }
}

TEST(CameraModel, GroundPointProjectsToPixelWhoseRayHitsIt) {
  const CameraModel cam = Opencv8Camera();
  int seen = 0;
  double worst_m = 0;
  for (double x = -3; x <= 3; x += 0.1) {
    for (double y = -2; y <= 5; y += 0.1) {
      const Vector3d point_in_ground(x, y, 0.0);
      // Only points the lens really sees: beyond normalized radius ~2.2 this polynomial
      // folds back into the image (a model artefact, not a view of the point).
      const Vector3d p_cam = cam.cam_from_ground() * point_in_ground;
      if (p_cam.z() <= 0 || p_cam.head<2>().norm() / p_cam.z() > 1.8) continue;
      const Vector2d px = cam.ProjectGround(point_in_ground);
      if (!px.allFinite() || px.x() < 0 || px.y() < 0 || px.x() > cam.width() - 1 ||
          px.y() > cam.height() - 1) {
        continue;
      }
      ++seen;
      const Ray ray = cam.RayInGround(px);
      EXPECT_LT((ray.origin - Vector3d(0.2, -2.5, 1.6)).norm(), 1e-12);
      const auto hit = IntersectGround(ray);
      ASSERT_TRUE(hit.has_value()) << point_in_ground.transpose();
      worst_m = std::max(worst_m, (*hit - point_in_ground).norm());
    }
  }
  EXPECT_GT(seen, 500);
  EXPECT_LT(worst_m, 1e-6) << "ground position error, metres";
}

TEST(CameraModel, PinholeBehindTheCameraIsNaN) {
  const CameraModel cam("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, Rigid3{});
  EXPECT_TRUE(cam.Project(Vector3d(0.1, 0.2, 1.0)).allFinite());
  EXPECT_EQ(cam.Project(Vector3d(0.1, 0.2, 1.0)), Vector2d(320 + 50, 240 + 100));
  EXPECT_TRUE(cam.Project(Vector3d(0.1, 0.2, -1.0)).hasNaN());
  EXPECT_TRUE(cam.Project(Vector3d(0.1, 0.2, 0.0)).hasNaN());
  // A ground point behind a camera looking at the floor.
  const CameraModel floor_cam("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480,
                              LookAt(Vector3d(0, 0, 1.5), Vector3d(0, 2, 0)));
  EXPECT_TRUE(floor_cam.ProjectGround(Vector3d(0, -3, 0)).hasNaN());
  EXPECT_TRUE(floor_cam.ProjectGround(Vector3d(0, 3, 0)).allFinite());
}

struct LensCase {
  std::string name;
  std::vector<double> intrinsics;
};

TEST(CameraModel, EveryLensModelRoundTrips) {
  std::vector<double> splined = {600, 600, 639.5, 479.5};
  for (int i = 0; i < 2 * 11 * 8; ++i) splined.push_back(0.002 * std::sin(0.37 * i));
  const std::vector<LensCase> cases = {
      {"LENSMODEL_PINHOLE", {600, 610, 639.5, 479.5}},
      {"LENSMODEL_STEREOGRAPHIC", {600, 610, 639.5, 479.5}},
      {"LENSMODEL_LONLAT", {600, 610, 639.5, 479.5}},
      {"LENSMODEL_LATLON", {600, 610, 639.5, 479.5}},
      {"LENSMODEL_OPENCV4", {600, 610, 639.5, 479.5, -0.2, 0.05, 0.001, -0.001}},
      {"LENSMODEL_OPENCV5", {600, 610, 639.5, 479.5, -0.2, 0.05, 0.001, -0.001, -0.001}},
      {"LENSMODEL_OPENCV12",
       {600, 610, 639.5, 479.5, -0.2, 0.05, 0.001, -0.001, -0.001, 0.02, 0.003, 0.001, 1e-4, -1e-4,
        2e-4, 1e-5}},
      {"LENSMODEL_CAHVOR", {600, 610, 639.5, 479.5, 0.001, -0.002, 0.0, -0.05, 0.01}},
      {"LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=11_Ny=8_fov_x_deg=120", splined},
  };
  ScratchDir dir;
  for (const LensCase& c : cases) {
    SCOPED_TRACE(c.name);
    const CameraModel cam(c.name, c.intrinsics, 1280, 960,
                          LookAt(Vector3d(0, -2, 1.5), Vector3d(0, 0.5, 0)));
    EXPECT_EQ(cam.lensmodel(), c.name);
    double worst = 0;
    for (const Vector2d& px : PixelGrid(1280, 960, 80)) {
      // stay inside every model's domain
      const Vector2d inner = Vector2d(640, 480) + 0.8 * (px - Vector2d(640, 480));
      const Vector3d ray = cam.Unproject(inner);
      ASSERT_TRUE(ray.allFinite()) << inner.transpose();
      worst = std::max(worst, (cam.Project(ray) - inner).norm());
    }
    EXPECT_LT(worst, 1e-6);
    // And each survives a file round trip.
    cam.Write(dir / "cam.cameramodel");
    const CameraModel back = CameraModel::Read(dir / "cam.cameramodel");
    EXPECT_EQ(back.lensmodel(), cam.lensmodel());
    EXPECT_EQ(back.intrinsics(), cam.intrinsics());
  }
}

TEST(CameraModel, CahvoreProjectsButDoesNotUnproject) {
  // libmrcal 2.2 projects CAHVORE but has no unprojection for it: NaN, as documented.
  // With linearity 1 and no distortion it is a pinhole.
  const CameraModel cam("LENSMODEL_CAHVORE_linearity=1.00",
                        {600, 610, 639.5, 479.5, 0, 0, 0, 0, 0, 0, 0, 0}, 1280, 960, Rigid3{});
  EXPECT_LT((cam.Project(Vector3d(0.1, -0.2, 1.0)) - Vector2d(639.5 + 60, 479.5 - 122)).norm(),
            1e-9);
  EXPECT_TRUE(cam.Unproject(Vector2d(700, 400)).hasNaN());
  EXPECT_FALSE(IntersectGround(cam.RayInGround(Vector2d(700, 400))).has_value());
}

TEST(CameraModel, WriteReadIsBitExact) {
  ScratchDir dir;
  // Awkward doubles: 1/3, tiny, negative, many digits. mrcal's C writer (%f) would lose all of
  // these.
  std::vector<double> intrinsics = kOpencv8;
  intrinsics[0] = 1000.0 / 3.0;
  intrinsics[4] = -0.29999999999999993;
  intrinsics[7] = 1.2345678901234567e-9;
  intrinsics[11] = -std::nextafter(0.004, 1.0);
  const double rt[6] = {0.1234567890123456, -2.0 / 3.0, 0.3,
                        1.0 / 7.0,          -2.5e-7,    1.6000000000000003};
  const CameraModel cam("LENSMODEL_OPENCV8", intrinsics, 1920, 1080, Rigid3::FromRt(rt));
  const std::string path = dir / "cam0.cameramodel";
  cam.Write(path);

  const CameraModel back = CameraModel::Read(path);
  EXPECT_EQ(back.lensmodel(), "LENSMODEL_OPENCV8");
  EXPECT_EQ(back.intrinsics(), intrinsics);  // bit for bit
  EXPECT_EQ(back.width(), 1920);
  EXPECT_EQ(back.height(), 1080);
  // The file holds rt_cam_ref = ToRt(rotation) exactly; the translation is stored as is, the
  // rotation goes through Rodrigues twice (matrix -> r -> matrix), which rounds in the last bit.
  EXPECT_EQ(back.cam_from_ground().translation, cam.cam_from_ground().translation);
  EXPECT_LT(
      (back.cam_from_ground().rotation - cam.cam_from_ground().rotation).cwiseAbs().maxCoeff(),
      1e-15);

  // libmrcal's own reader sees exactly the numbers we meant.
  mrcal_cameramodel_t* m = mrcal_read_cameramodel_file(path.c_str());
  ASSERT_NE(m, nullptr);
  double expected_rt[6];
  cam.cam_from_ground().ToRt(expected_rt);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(m->rt_cam_ref[i], expected_rt[i]) << i;
  for (int i = 0; i < 12; ++i) EXPECT_EQ(m->intrinsics[i], intrinsics[i]) << i;
  EXPECT_EQ(m->imagersize[0], 1920u);
  EXPECT_EQ(m->imagersize[1], 1080u);
  mrcal_free_cameramodel(&m);

  // Writing what we read gives the same text again, up to the last bit of r.
  EXPECT_EQ(CameraModel::Parse(back.ToText(), "again").intrinsics(), intrinsics);
}

TEST(CameraModel, ReadsWhatLibmrcalWrites) {
  ScratchDir dir;
  const std::string path = dir / "mrcal.cameramodel";
  std::vector<unsigned char> storage(sizeof(mrcal_cameramodel_t) + 12 * sizeof(double));
  auto* m = reinterpret_cast<mrcal_cameramodel_t*>(storage.data());
  const double rt[6] = {0.01, -0.4, 0.2, 0.5, -0.25, 2.0};
  for (int i = 0; i < 6; ++i) m->rt_cam_ref[i] = rt[i];
  m->imagersize[0] = 1920;
  m->imagersize[1] = 1080;
  ASSERT_TRUE(mrcal_lensmodel_from_name(&m->lensmodel, "LENSMODEL_OPENCV8"));
  for (int i = 0; i < 12; ++i) m->intrinsics[i] = kOpencv8[i];
  ASSERT_TRUE(mrcal_write_cameramodel_file(path.c_str(), m));
  const CameraModel cam = CameraModel::Read(path);
  // mrcal's C writer prints 6 decimals; these values need no more, so they come back exactly.
  EXPECT_EQ(cam.intrinsics(), kOpencv8);
  double back[6];
  cam.cam_from_ground().ToRt(back);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(back[i], rt[i], 1e-15);
  // Written again, the file holds mrcal's extrinsics to the bit (not r -> R -> r).
  const std::string again = dir / "again.cameramodel";
  cam.Write(again);
  mrcal_cameramodel_t* back_model = mrcal_read_cameramodel_file(again.c_str());
  ASSERT_NE(back_model, nullptr);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(back_model->rt_cam_ref[i], rt[i]) << i;
  mrcal_free_cameramodel(&back_model);
}

TEST(CameraModel, APoseSetAfterReadingIsThePoseWritten) {
  // `calibrate ground` reads an intrinsics-only model (identity extrinsics) and poses it:
  // the file must hold the new pose, not the extrinsics as read.
  ScratchDir dir;
  const CameraModel unposed("LENSMODEL_OPENCV8", kOpencv8, 1920, 1080, Rigid3{});
  unposed.Write(dir / "intrinsics.cameramodel");
  CameraModel posed = CameraModel::Read(dir / "intrinsics.cameramodel");
  const double rt[6] = {2.57, -0.03, -0.02, -0.03, -0.02, 1.48};
  posed.set_cam_from_ground(Rigid3::FromRt(rt));
  posed.Write(dir / "posed.cameramodel");
  const CameraModel back = CameraModel::Read(dir / "posed.cameramodel");
  double got[6];
  back.cam_from_ground().ToRt(got);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(got[i], rt[i], 1e-12) << i;
}

TEST(CameraModel, ReadsACalibrationToolFile) {
  // The shape mrcal-calibrate-cameras writes: comments, extra keys, a bytes blob.
  ScratchDir dir;
  const std::string path = dir / "calibrated.cameramodel";
  WriteText(
      path,
      R"(# generated on 2024-01-01 with   mrcal-calibrate-cameras --lensmodel LENSMODEL_OPENCV4
{
    'lensmodel':  'LENSMODEL_OPENCV4',
    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....
    'intrinsics': [ 1812.41, 1811.99, 964.7, 539.1, -0.1, 0.02, 1e-4, -2e-4,],
    'valid_intrinsics_region': [
        [ 10, 20 ],
        [ 1900, 20 ],
        [ 10, 20 ],
    ],
    # extrinsics are rt_fromref
    'extrinsics': [ 0, 0, 0, 0, 0, 0,],
    'imagersize': [ 1920, 1080,],
    'icam_intrinsics': 0,
    'optimization_inputs': b'\x00\x01binary',
}
)");
  const CameraModel cam = CameraModel::Read(path);
  EXPECT_EQ(cam.lensmodel(), "LENSMODEL_OPENCV4");
  EXPECT_EQ(cam.intrinsics(),
            (std::vector<double>{1812.41, 1811.99, 964.7, 539.1, -0.1, 0.02, 1e-4, -2e-4}));
  EXPECT_EQ(cam.cam_from_ground().rotation, Eigen::Matrix3d::Identity());
}

// The python3 that has mrcal: Debian's, which may not be the first on PATH.
std::string PythonWithMrcal() {
  for (const char* python : {"/usr/bin/python3", "python3"}) {
    const std::string probe = std::string(python) + " -c 'import mrcal' >/dev/null 2>&1";
    if (testing::RunCommand(probe).exit_code == 0) return python;
  }
  return {};
}

TEST(CameraModel, MrcalPythonReadsWhatWeWriteAndProjectsTheSame) {
  const std::string python = PythonWithMrcal();
  if (python.empty()) GTEST_SKIP() << "python3-mrcal is not installed";
  ScratchDir dir;
  std::vector<double> intrinsics = kOpencv8;
  intrinsics[0] = 1000.0 / 3.0 * 3.3;
  const CameraModel cam("LENSMODEL_OPENCV8", intrinsics, 1920, 1080,
                        LookAt(Vector3d(0.2, -2.5, 1.6), Vector3d(0.0, 0.6, 0.0)));
  const std::string model = dir / "cam.cameramodel";
  cam.Write(model);
  WriteText(dir / "check.py", R"(import sys, mrcal, numpy as np
m = mrcal.cameramodel(sys.argv[1])
lens, intrinsics = m.intrinsics()
print(lens)
print(' '.join(repr(float(v)) for v in intrinsics))
print(' '.join(repr(float(v)) for v in m.extrinsics_rt_fromref()))
print(' '.join(str(int(v)) for v in m.imagersize()))
p = mrcal.transform_point_rt(m.extrinsics_rt_fromref(), np.array([0.3, 1.2, 0.0]))
print(' '.join(repr(float(v)) for v in mrcal.project(p, lens, intrinsics)))
)");
  const std::string out_path = dir / "out.txt";
  const std::string command =
      python + " " + (dir / "check.py") + " " + model + " > " + out_path + " 2>&1";
  ASSERT_EQ(testing::RunCommand(command).exit_code, 0) << ReadText(out_path);
  std::istringstream out(ReadText(out_path));
  std::string lens, line;
  std::getline(out, lens);
  EXPECT_EQ(lens, "LENSMODEL_OPENCV8");
  auto numbers = [&]() {
    std::getline(out, line);
    std::istringstream s(line);
    std::vector<double> v;
    for (std::string word; s >> word;) v.push_back(std::strtod(word.c_str(), nullptr));
    return v;
  };
  EXPECT_EQ(numbers(), intrinsics);  // Python's repr is exact: bit for bit
  const std::vector<double> rt = numbers();
  double expected_rt[6];
  cam.cam_from_ground().ToRt(expected_rt);
  ASSERT_EQ(rt.size(), 6u);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(rt[i], expected_rt[i]);
  EXPECT_EQ(numbers(), (std::vector<double>{1920, 1080}));
  const std::vector<double> px = numbers();
  ASSERT_EQ(px.size(), 2u);
  EXPECT_LT((Vector2d(px[0], px[1]) - cam.ProjectGround(Vector3d(0.3, 1.2, 0.0))).norm(), 1e-9);
}

TEST(CameraModel, BadFilesNameTheFileAndTheReason) {
  ScratchDir dir;
  const std::string missing = dir / "missing.cameramodel";
  std::string msg = InputErrorOf([&] { CameraModel::Read(missing); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
  EXPECT_NE(msg.find("cannot open"), std::string::npos) << msg;

  msg = InputErrorOf([&] { CameraModel::Read(dir.path().string()); });
  EXPECT_NE(msg.find("is a directory"), std::string::npos) << msg;

  struct Case {
    std::string file, text, reason;
  };
  const std::string good_tail = "'extrinsics': [0,0,0,0,0,0], 'imagersize': [640,480] }";
  const std::vector<Case> cases = {
      {"empty.cameramodel", "", "empty"},
      {"garbage.cameramodel", "hello, I am not a camera model\n\x01\x02", "not a .cameramodel"},
      {"short.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_OPENCV8', 'intrinsics': [1,2,3,4,5,6,7,8,9,10,11], " + good_tail,
       "LENSMODEL_OPENCV8 needs 12 intrinsics, the file has 11"},
      {"long.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1,2,3,4,5], " + good_tail,
       "LENSMODEL_PINHOLE needs 4 intrinsics, the file has 5"},
      {"unknown.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_OPENCV9', 'intrinsics': [1,2,3,4], " + good_tail,
       "unknown lens model 'LENSMODEL_OPENCV9'"},
      {"nosize.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1,2,3,4], 'extrinsics': [0,0,0,0,0,0] }",
       "missing key 'imagersize'"},
      {"rt5.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1,2,3,4], 'extrinsics': [0,0,0,0,0], "
       "'imagersize': [640,480] }",
       "'extrinsics' needs 6 values"},
      {"zerosize.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1,2,3,4], 'extrinsics': [0,0,0,0,0,0], "
       "'imagersize': [0,480] }",
       "imager size 0x480 is not positive"},
      {"zerofocal.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [0,500,320,240], " + good_tail,
       "focal lengths fx = 0.000000, fy = 500.000000 (intrinsics[0], [1]) must be positive"},
      {"negativefocal.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_OPENCV4', 'intrinsics': [500,-500,320,240,0,0,0,0], " + good_tail,
       "must be positive"},
      // A file cut short inside a string (libmrcal's parser read past the end of it: tests/fuzz).
      {"cut.cameramodel", "# SpriteStation camera model\n{\n    'lensmodel': 'LENSMODEL_PIN",
       "a quoted string at line 3 is not closed (is the file cut short?)"},
      {"cut2.cameramodel", "{ 'lensmodel': 'LENSMODEL_PINHOLE\\",
       "a quoted string at line 1 is not closed"},
  };
  for (const Case& c : cases) {
    const std::string path = dir / c.file;
    WriteText(path, c.text);
    msg = InputErrorOf([&] { CameraModel::Read(path); });
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;  // starts with the file
    EXPECT_NE(msg.find(c.reason), std::string::npos) << c.file << ": " << msg;
  }
}

TEST(CameraModel, ConstructorRefusesBadIntrinsics) {
  EXPECT_THROW(CameraModel("LENSMODEL_OPENCV8", {1, 2, 3, 4}, 640, 480, Rigid3{}), InputError);
  EXPECT_THROW(CameraModel("LENSMODEL_NOPE", {1, 2, 3, 4}, 640, 480, Rigid3{}), InputError);
  EXPECT_THROW(CameraModel("LENSMODEL_PINHOLE", {1, 2, NAN, 4}, 640, 480, Rigid3{}), InputError);
  EXPECT_THROW(CameraModel("LENSMODEL_PINHOLE", {1, 2, 3, 4}, 640, -1, Rigid3{}), InputError);
  const std::string msg = InputErrorOf([] {
    CameraModel("LENSMODEL_OPENCV4", {1, 2, 3}, 640, 480, Rigid3{});
  });
  EXPECT_NE(msg.find("LENSMODEL_OPENCV4 needs 8 intrinsics, got 3"), std::string::npos) << msg;
}

}  // namespace
}  // namespace ss
