// Bad input to one camera's live pipeline: a clear error naming the camera and
// the frame, never a crash, and nothing lost that was already handed out.
#include "pipeline/run/camera_pipeline.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace ss {
namespace {

CameraModel DownCamera() {
  Rigid3 cam_from_ground;
  cam_from_ground.rotation << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  cam_from_ground.translation = Eigen::Vector3d(0, 0, 1.0);
  return CameraModel("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, cam_from_ground);
}

GroundPolygon Floor() {
  return GroundPolygon({{-0.3, -0.2}, {0.3, -0.2}, {0.3, 0.2}, {-0.3, 0.2}});
}

// An evenly lit green screen.
Frame Green(int width, int height, uint64_t sequence) {
  std::vector<uint8_t> pixels(static_cast<size_t>(width) * height * 3);
  for (size_t i = 0; i < pixels.size(); i += 3) {
    pixels[i] = 40;       // B
    pixels[i + 1] = 170;  // G
    pixels[i + 2] = 50;   // R
  }
  Frame f = Frame::Owned(PixelFormat::kBGR8, width, height, std::move(pixels));
  f.sequence = sequence;
  f.timestamp_ns = static_cast<int64_t>(sequence) * 33'333'333;
  return f;
}

CameraPipeline Trained() {
  CameraPipeline p("cam0", 1, DownCamera(), Floor(), CameraPipelineOptions{});
  std::vector<cv::Mat> empty;
  empty.reserve(5);
  for (int i = 0; i < 5; ++i) empty.push_back(ToBgr(Green(640, 480, i)));
  p.Train(empty);
  return p;
}

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CameraPipelineInput, AMissingModelIsRefusedNamingTheCamera) {
  const std::string message = MessageOf(
      [] { CameraPipeline p("side", 1, CameraModel(), Floor(), CameraPipelineOptions{}); });
  EXPECT_NE(message.find("side"), std::string::npos) << message;
  EXPECT_NE(message.find("no model"), std::string::npos) << message;
}

TEST(CameraPipelineInput, OptionsOutOfRangeAreRefusedNamingTheField) {
  CameraPipelineOptions o;
  o.rectify.margin_m = -0.5;
  const std::string message =
      MessageOf([&] { CameraPipeline p("side", 1, DownCamera(), Floor(), o); });
  EXPECT_EQ(message,
            "pipeline options: rectify.margin_m: expected a number of metres >= 0, got -0.5");
  o = {};
  o.rectify.px_per_m = 0;  // auto, not resolved
  EXPECT_NE(MessageOf([&] {
              CameraPipeline p("side", 1, DownCamera(), Floor(), o);
            }).find("pipeline.px_per_m"),
            std::string::npos);
}

TEST(CameraPipelineInput, AFrameSizeChangingMidStreamIsRefusedNamingCameraAndFrame) {
  CameraPipeline p = Trained();
  std::vector<ClipBatch> out;
  p.Process(Green(640, 480, 10), &out);
  const std::string message = MessageOf([&] { p.Process(Green(320, 240, 11), &out); });
  EXPECT_NE(message.find("cam0 frame 11"), std::string::npos) << message;
  EXPECT_NE(message.find("320x240"), std::string::npos) << message;
  // The pipeline goes on with frames of the right size.
  EXPECT_NO_THROW(p.Process(Green(640, 480, 12), &out));
  EXPECT_EQ(p.stats().frames, 5u + 2u);
}

TEST(CameraPipelineInput, ACorruptFrameIsRefusedNamingCameraAndFrame) {
  CameraPipeline p = Trained();
  std::vector<ClipBatch> out;
  // A frame whose bytes are fewer than its size needs, and a JPEG that is not one.
  Frame short_frame = Green(640, 480, 20);
  short_frame.size /= 2;
  const std::string short_message = MessageOf([&] { p.Process(short_frame, &out); });
  EXPECT_NE(short_message.find("cam0 frame 20"), std::string::npos) << short_message;
  Frame jpeg = Frame::Owned(PixelFormat::kMJPEG, 640, 480, std::vector<uint8_t>(1000, 0x55));
  jpeg.sequence = 21;
  const std::string jpeg_message = MessageOf([&] { p.Process(jpeg, &out); });
  EXPECT_NE(jpeg_message.find("cam0 frame 21"), std::string::npos) << jpeg_message;
  EXPECT_NE(jpeg_message.find("MJPEG"), std::string::npos) << jpeg_message;
  EXPECT_NO_THROW(p.Process(Green(640, 480, 22), &out));
}

TEST(CameraPipelineInput, AnUntrainedKeyerSaysSo) {
  CameraPipeline p("cam0", 1, DownCamera(), Floor(), CameraPipelineOptions{});
  std::vector<ClipBatch> out;
  try {
    p.Process(Green(640, 480, 0), &out);
    FAIL() << "processed a frame before learning the enclosure";
  } catch (const WorkError& e) {
    EXPECT_NE(std::string(e.what()).find("empty enclosure"), std::string::npos) << e.what();
  }
}

TEST(CameraPipelineInput, AnUnknownPixelFormatNameIsNotAFormat) {
  EXPECT_FALSE(ParsePixelFormat("rgb10p").has_value());
  EXPECT_EQ(ParsePixelFormat("bayer_rg8"), PixelFormat::kBayerRG8);
}

}  // namespace
}  // namespace ss
