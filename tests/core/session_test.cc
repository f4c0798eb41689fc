#include "core/session.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::ScratchDir;

SessionInfo TwoCameras() {
  SessionInfo info;
  info.name = "studio A, take 3";
  info.created = "2024-05-01T10:00:00Z";
  info.synthetic = true;
  SessionCamera a;
  a.name = "cam0";
  a.video = "cam0.mkv";
  a.frames_csv = "cam0.frames.csv";
  a.model = "cam0.cameramodel";
  a.width = 1920;
  a.height = 1080;
  a.pixel_format = PixelFormat::kBayerGR8;
  a.codec = "ffv1";
  a.fps = 59.94;
  SessionCamera b = a;
  b.name = "cam1";
  b.video = "cam1.mkv";
  b.frames_csv = "cam1.frames.csv";
  b.model = "";
  b.width = 640;
  b.height = 480;
  b.pixel_format = PixelFormat::kMJPEG;
  b.codec = "mjpeg";
  b.fps = 30;
  info.cameras = {a, b};
  return info;
}

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Writes TwoCameras() as JSON after `edit` and returns the InputError message of reading it ("" if
// none).
std::string ReadEdited(const ScratchDir& dir, const std::function<void(nlohmann::json&)>& edit) {
  WriteSessionInfo(dir.path().string(), TwoCameras());
  nlohmann::json j;
  std::ifstream(dir / "session.json") >> j;
  edit(j);
  WriteFile(dir / "session.json", j.dump());
  try {
    ReadSessionInfo(dir.path().string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SessionInfo, RoundTrip) {
  ScratchDir dir;
  const SessionInfo info = TwoCameras();
  WriteSessionInfo(dir.path().string(), info);
  const SessionInfo back = ReadSessionInfo(dir.path().string());
  EXPECT_EQ(back.format_version, kSessionFormatVersion);
  EXPECT_EQ(back.name, info.name);
  EXPECT_EQ(back.created, info.created);
  EXPECT_EQ(back.synthetic, true);
  ASSERT_EQ(back.cameras.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const auto& a = info.cameras[i];
    const auto& b = back.cameras[i];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.video, a.video);
    EXPECT_EQ(b.frames_csv, a.frames_csv);
    EXPECT_EQ(b.model, a.model);
    EXPECT_EQ(b.width, a.width);
    EXPECT_EQ(b.height, a.height);
    EXPECT_EQ(b.pixel_format, a.pixel_format);
    EXPECT_EQ(b.codec, a.codec);
    EXPECT_DOUBLE_EQ(b.fps, a.fps);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "session.json.tmp"));
}

TEST(SessionInfo, ErrorsNameTheFileAndTheField) {
  ScratchDir dir;
  const std::string file = dir / "session.json";
  auto expect = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& message) {
    const std::string got = ReadEdited(dir, edit);
    EXPECT_EQ(got, file + ": " + message);
  };
  expect([](auto& j) { j["cameras"][1]["width"] = -640; },
         "field 'cameras[1].width': expected a positive integer");
  expect([](auto& j) { j["cameras"][1]["width"] = "640"; },
         "field 'cameras[1].width': expected a positive integer");
  expect([](auto& j) { j["cameras"][0]["height"] = 1.5; },
         "field 'cameras[0].height': expected a positive integer");
  expect([](auto& j) { j["cameras"][0].erase("fps"); }, "field 'cameras[0].fps': missing");
  expect([](auto& j) { j["cameras"][0]["fps"] = 0; },
         "field 'cameras[0].fps': expected a positive number");
  expect([](auto& j) { j["format_version"] = 2; },
         "field 'format_version': unsupported version 2 (this build reads version 1)");
  expect([](auto& j) { j["synthetic"] = "yes"; }, "field 'synthetic': expected true or false");
  expect([](auto& j) { j["cameras"] = nlohmann::json::object(); },
         "field 'cameras': expected an array");
  expect([](auto& j) { j["cameras"][1]["name"] = "cam0"; },
         "field 'cameras[1].name': camera 'cam0' appears twice");
  expect([](auto& j) { j["cameras"][0]["video"] = "../elsewhere.mkv"; },
         "field 'cameras[0].video': path '../elsewhere.mkv' leaves the session folder");
  expect([](auto& j) { j["cameras"][0]["frames_csv"] = "/etc/passwd"; },
         "field 'cameras[0].frames_csv': expected a path relative to the session folder, got "
         "'/etc/passwd'");
  expect(
      [](auto& j) { j["cameras"][0]["name"] = "a/b"; },
      "field 'cameras[0].name': 'a/b' is not a plain file stem (letters, digits, '_', '-', '.')");
  expect([](auto& j) { j["cameras"][1]["codec"] = "ffv1"; },
         "field 'cameras[1].codec': an mjpeg camera is stored as codec 'mjpeg', got 'ffv1'");
  expect([](auto& j) { j["cameras"][0]["codec"] = "vp9"; },
         "field 'cameras[0].codec': unknown codec 'vp9' (expected ffv1, ffvhuff, mjpeg or h264)");
  const std::string bad_format =
      ReadEdited(dir, [](auto& j) { j["cameras"][0]["pixel_format"] = "rgb16"; });
  EXPECT_NE(bad_format.find("field 'cameras[0].pixel_format': unknown pixel format 'rgb16'"),
            std::string::npos)
      << bad_format;
  expect(
      [](auto& j) {
        j["cameras"][0]["pixel_format"] = "nv12";
        j["cameras"][0]["height"] = 1081;
      },
      "field 'cameras[0].height': nv12 needs an even height, got 1081");
  EXPECT_EQ(ReadEdited(dir, [](auto& j) { j["unknown_future_field"] = 1; }), "");  // ignored
}

TEST(SessionInfo, NotJsonOrMissing) {
  ScratchDir dir;
  try {
    ReadSessionInfo((dir / "nowhere"));
    FAIL() << "no error for a missing folder";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "nowhere") + "/session.json: no such session folder");
  }
  WriteFile(dir / "session.json", "{\"format_version\": 1, ");
  try {
    ReadSessionInfo(dir.path().string());
    FAIL() << "no error for broken JSON";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir / "session.json") + ": not valid JSON", 0), 0u)
        << e.what();
  }
  WriteFile(dir / "session.json", "[1, 2]");
  EXPECT_THROW(ReadSessionInfo(dir.path().string()), InputError);
}

TEST(FrameCsv, RoundTrip) {
  ScratchDir dir;
  const std::string path = dir / "cam0.frames.csv";
  std::vector<FrameRecord> rows;
  for (int i = 0; i < 100; ++i) {
    FrameRecord r;
    r.index = i;
    r.timestamp_ns = -5'000'000'000LL + i * 16'666'667LL;  // device clocks may start anywhere
    r.sequence = 18'446'744'073'709'551'000ULL + static_cast<uint64_t>(i) * 2;
    r.drops_before = i % 7 == 0 ? 1 : 0;
    rows.push_back(r);
  }
  {
    FrameCsvWriter writer(path);
    for (const auto& r : rows) writer.Append(r);
    writer.Close();
  }
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "index,timestamp_ns,sequence,drops_before");
  const auto back = ReadFrameCsv(path);
  ASSERT_EQ(back.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back[i].index, rows[i].index);
    EXPECT_EQ(back[i].timestamp_ns, rows[i].timestamp_ns);
    EXPECT_EQ(back[i].sequence, rows[i].sequence);
    EXPECT_EQ(back[i].drops_before, rows[i].drops_before);
  }
}

TEST(FrameCsv, RowsAreOnDiskBeforeClose) {
  ScratchDir dir;
  const std::string path = dir / "a.csv";
  FrameCsvWriter writer(path);
  FrameRecord r;
  r.timestamp_ns = 42;
  writer.Append(r);
  const auto rows = ReadFrameCsv(path);  // the writer is still open
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].timestamp_ns, 42);
}

std::string CsvError(const ScratchDir& dir, const std::string& text) {
  const std::string path = dir / "bad.csv";
  WriteFile(path, text);
  try {
    ReadFrameCsv(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameCsv, MalformedRowsNameTheFileAndLine) {
  ScratchDir dir;
  const std::string p = dir / "bad.csv";
  const std::string h = "index,timestamp_ns,sequence,drops_before\n";
  EXPECT_EQ(
      CsvError(dir, ""),
      p + ": empty file, expected the header line 'index,timestamp_ns,sequence,drops_before'");
  EXPECT_EQ(CsvError(dir, "frame,time\n0,1\n"),
            p + ":1: expected the header line 'index,timestamp_ns,sequence,drops_before', got "
                "'frame,time'");
  EXPECT_EQ(CsvError(dir, h + "0,100,7,0\n1,200,8\n"),
            p + ":3: expected 4 comma-separated fields (index,timestamp_ns,sequence,drops_before), "
                "got 3");
  EXPECT_EQ(CsvError(dir, h + "0,1e9,7,0\n"),
            p + ":2: field 'timestamp_ns': expected an integer, got '1e9'");
  EXPECT_EQ(CsvError(dir, h + "0,100,-7,0\n"),
            p + ":2: field 'sequence': expected a non-negative integer, got '-7'");
  EXPECT_EQ(CsvError(dir, h + "0,100,7,\n"),
            p + ":2: field 'drops_before': expected a non-negative integer, got ''");
  EXPECT_EQ(CsvError(dir, h + "0,100,7,0\n2,200,8,0\n"),
            p + ":3: field 'index': expected 1 (rows count up from 0), got 2");
  EXPECT_EQ(CsvError(dir, h + "0,100,7,0\n\n1,200,8,0\n"),
            p + ":3: expected 4 comma-separated fields (index,timestamp_ns,sequence,drops_before), "
                "got 1");
  EXPECT_EQ(
      CsvError(dir, "\x89PNG\r\n\x1a\n garbage"),
      p + ":1: expected the header line 'index,timestamp_ns,sequence,drops_before', got '\x89PNG'");
}

TEST(FrameCsv, TornLastRowOfAKilledRecorderIsDropped) {
  ScratchDir dir;
  const std::string path = dir / "torn.csv";
  WriteFile(path, "index,timestamp_ns,sequence,drops_before\n0,100,7,0\n1,200,8,0\n2,30");
  const auto rows = ReadFrameCsv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].timestamp_ns, 200);
  // CRLF line ends are accepted.
  WriteFile(path, "index,timestamp_ns,sequence,drops_before\r\n0,100,7,0\r\n");
  EXPECT_EQ(ReadFrameCsv(path).size(), 1u);
}

}  // namespace
}  // namespace ss
