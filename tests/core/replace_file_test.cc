#include "core/replace_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path Scratch(const std::string& name) {
  fs::path dir =
      fs::temp_directory_path() / ("ss-replace-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(ReplaceFile, AFileIsReplacedWholeAndNoTemporaryStays) {
  const fs::path dir = Scratch("file");
  const std::string path = (dir / "out.json").string();
  ReplaceFile(path, "first\n", "the test");
  ReplaceFile(path, "second\n", "the test");
  EXPECT_EQ(Slurp(path), "second\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "the temporary is gone";
  fs::remove_all(dir);
}

// `animate --out /dev/null` once replaced the device with a file: a path that is not a regular
// file (here a FIFO, as /dev/null is a device) is written into and stays what it was.
TEST(ReplaceFile, AFifoIsWrittenIntoNotReplaced) {
  const fs::path dir = Scratch("fifo");
  const std::string path = (dir / "pipe").string();
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  std::string read;
  std::thread reader([&] { read = Slurp(path); });
  ReplaceFile(path, "through the pipe\n", "the test");
  reader.join();
  EXPECT_EQ(read, "through the pipe\n");
  EXPECT_TRUE(fs::is_fifo(path));
  fs::remove_all(dir);
}

TEST(ReplaceFile, ADirectoryOrAMissingFolderIsAnErrorNamingThePath) {
  const fs::path dir = Scratch("errors");
  try {
    ReplaceFile(dir.string(), "x", "the sequences");
    ADD_FAILURE() << "wrote over a directory";
  } catch (const WorkError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write the sequences: it is a directory"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ReplaceFile((dir / "no" / "such" / "out.json").string(), "x", "the test"),
               WorkError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ss
