// The V4L2 backend against a real V4L2 driver: boots Debian's kernel under
// qemu (software emulation) with a small initramfs holding busybox, the vivid
// virtual capture driver and the media modules it needs, and the statically
// linked probe (vivid_probe.cc), then checks every line the probe printed.
// Skips, naming what is missing, when qemu, the kernel or busybox is absent.
#include <elf.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes a cpio archive in the kernel's "newc" format.
class CpioWriter {
 public:
  explicit CpioWriter(const fs::path& path) : out_(path, std::ios::binary) {}
  void Dir(const std::string& name) { Entry(name, 040755, ""); }
  void File(const std::string& name, const std::string& data, bool executable) {
    Entry(name, executable ? 0100755 : 0100644, data);
  }
  void Finish() {
    Entry("TRAILER!!!", 0, "");
    out_.close();
  }
  bool ok() const { return out_.good(); }

 private:
  void Entry(const std::string& name, unsigned mode, const std::string& data) {
    char header[111];
    std::snprintf(header, sizeof header, "070701%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X", ino_++, mode,
                  0u, 0u, 1u, 0u, static_cast<unsigned>(data.size()), 0u, 0u, 0u, 0u,
                  static_cast<unsigned>(name.size() + 1), 0u);
    out_.write(header, 110);
    out_.write(name.c_str(), static_cast<std::streamsize>(name.size() + 1));
    Pad(110 + name.size() + 1);
    out_.write(data.data(), static_cast<std::streamsize>(data.size()));
    Pad(data.size());
  }
  void Pad(size_t n) {
    static const char zeros[4] = {0, 0, 0, 0};
    out_.write(zeros, static_cast<std::streamsize>((4 - n % 4) % 4));
  }
  std::ofstream out_;
  unsigned ino_ = 1;
};

// The newest kernel under /boot whose modules ship vivid.
bool FindKernel(fs::path* kernel, fs::path* modules) {
  std::error_code ec;
  std::vector<fs::path> kernels;
  for (const auto& e : fs::directory_iterator("/boot", ec)) {
    if (e.path().filename().string().rfind("vmlinuz-", 0) == 0) kernels.push_back(e.path());
  }
  std::sort(kernels.rbegin(), kernels.rend());
  for (const auto& k : kernels) {
    const std::string version = k.filename().string().substr(8);
    const fs::path mods = fs::path("/lib/modules") / version;
    if (fs::exists(mods / "modules.dep") && ReadFile(mods / "modules.dep").find("/vivid.ko") != std::string::npos) {
      *kernel = k;
      *modules = mods;
      return true;
    }
  }
  return false;
}

// Module paths (relative to the modules folder) in load order: every module after its dependencies.
std::vector<std::string> LoadOrder(const fs::path& modules, const std::string& target) {
  std::map<std::string, std::vector<std::string>> deps;
  std::string name_of_target;
  std::istringstream in(ReadFile(modules / "modules.dep"));
  for (std::string line; std::getline(in, line);) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string module = line.substr(0, colon);
    std::istringstream rest(line.substr(colon + 1));
    std::vector<std::string> list;
    for (std::string d; rest >> d;) list.push_back(d);
    deps[module] = list;
    if (fs::path(module).filename().string().rfind(target + ".ko", 0) == 0) name_of_target = module;
  }
  std::vector<std::string> order;
  std::set<std::string> done;
  std::function<void(const std::string&)> visit = [&](const std::string& m) {
    if (!done.insert(m).second) return;
    for (const auto& d : deps[m]) visit(d);
    order.push_back(m);
  };
  if (!name_of_target.empty()) visit(name_of_target);
  return order;
}

// A module's bytes, decompressed when the distribution ships it as .ko.xz / .ko.zst.
bool ModuleBytes(const fs::path& path, std::string* bytes) {
  const std::string p = path.string();
  std::string tool;
  if (p.size() > 3 && p.substr(p.size() - 3) == ".xz") tool = "xz -dc ";
  if (p.size() > 4 && p.substr(p.size() - 4) == ".zst") tool = "zstd -dc ";
  if (tool.empty()) {
    *bytes = ReadFile(path);
    return !bytes->empty();
  }
  FILE* pipe = popen((tool + "'" + p + "'").c_str(), "r");
  if (pipe == nullptr) return false;
  bytes->clear();
  char buf[65536];
  for (size_t n; (n = fread(buf, 1, sizeof buf, pipe)) > 0;) bytes->append(buf, n);
  return pclose(pipe) == 0 && !bytes->empty();
}

// True when the ELF file asks for no program interpreter (a statically linked executable).
bool IsStatic(const std::string& path) {
  const std::string bytes = ReadFile(path);
  if (bytes.size() < sizeof(Elf64_Ehdr) || bytes.compare(0, 4, ELFMAG) != 0) return false;
  Elf64_Ehdr eh;
  std::memcpy(&eh, bytes.data(), sizeof eh);
  for (int i = 0; i < eh.e_phnum; ++i) {
    const size_t at = eh.e_phoff + static_cast<size_t>(i) * eh.e_phentsize;
    if (at + sizeof(Elf64_Phdr) > bytes.size()) return false;
    Elf64_Phdr ph;
    std::memcpy(&ph, bytes.data() + at, sizeof ph);
    if (ph.p_type == PT_INTERP) return false;
  }
  return true;
}

std::string FindProgram(const std::vector<std::string>& candidates) {
  for (const auto& c : candidates) {
    if (access(c.c_str(), X_OK) == 0) return c;
  }
  return "";
}

TEST(Vivid, V4l2BackendStreamsFromTheRealDriverUnderQemu) {
  const std::string qemu = FindProgram({"/usr/bin/qemu-system-x86_64", "/usr/local/bin/qemu-system-x86_64"});
  if (qemu.empty()) GTEST_SKIP() << "qemu-system-x86_64 not installed (Debian package qemu-system-x86)";
  fs::path kernel, modules;
  if (!FindKernel(&kernel, &modules)) {
    GTEST_SKIP() << "no kernel with the vivid module under /boot and /lib/modules (Debian package linux-image-amd64)";
  }
  const std::string busybox = FindProgram({"/bin/busybox", "/usr/bin/busybox"});
  if (busybox.empty()) GTEST_SKIP() << "busybox not installed (Debian package busybox-static)";
  if (!IsStatic(busybox)) {
    GTEST_SKIP() << busybox << " is not the static build (Debian package busybox-static)";
  }
  const std::string probe = VIVID_PROBE_PATH;
  ASSERT_TRUE(fs::exists(probe)) << probe;
  ASSERT_TRUE(IsStatic(probe)) << probe << " must be statically linked to run in the guest";

  ss::testing::ScratchDir dir;
  const fs::path initrd = dir.path() / "initrd.cpio";
  CpioWriter cpio(initrd);
  for (const char* d : {"bin", "dev", "proc", "sys", "lib", "lib/modules"}) cpio.Dir(d);
  cpio.File("bin/busybox", ReadFile(busybox), true);
  cpio.File("probe", ReadFile(probe), true);
  std::string init =
      "#!/bin/busybox sh\n"
      "/bin/busybox mount -t proc proc /proc\n"
      "/bin/busybox mount -t sysfs sys /sys\n"
      "/bin/busybox mount -t devtmpfs dev /dev\n";
  const auto order = LoadOrder(modules, "vivid");
  ASSERT_FALSE(order.empty()) << "vivid not in " << modules / "modules.dep";
  for (size_t i = 0; i < order.size(); ++i) {
    std::string bytes;
    ASSERT_TRUE(ModuleBytes(modules / order[i], &bytes)) << "cannot read " << modules / order[i];
    const std::string name = "lib/modules/" + std::to_string(i) + "_" +
                             fs::path(order[i]).filename().string().substr(
                                 0, fs::path(order[i]).filename().string().find(".ko")) + ".ko";
    cpio.File(name, bytes, false);
    const bool is_vivid = i + 1 == order.size();
    init += "/bin/busybox insmod /" + name + (is_vivid ? " n_devs=1 node_types=0x1" : "") +
            " || echo INSMOD_FAILED " + name + "\n";
  }
  init +=
      "i=0; while [ ! -e /dev/video0 ] && [ $i -lt 100 ]; do /bin/busybox sleep 0.1; i=$((i+1)); done\n"
      "/probe\n"
      "echo PROBE_EXIT $?\n"
      "/bin/busybox poweroff -f\n";
  cpio.File("init", init, true);
  cpio.Finish();
  ASSERT_TRUE(cpio.ok());

  const fs::path log = dir.path() / "console.txt";
  const std::string command = "timeout -k 5 170 " + qemu + " -accel tcg -m 512 -smp 1 -nographic -no-reboot -nic none" +
                              " -kernel " + kernel.string() + " -initrd " + initrd.string() +
                              " -append 'console=ttyS0 panic=-1 loglevel=3 no_timer_check mitigations=off rdinit=/init' < /dev/null > " +
                              log.string() + " 2>&1";
  const int rc = std::system(command.c_str());
  const std::string console = ReadFile(log);
  ASSERT_NE(console.find("PROBE_DONE"), std::string::npos)
      << "the probe did not finish (qemu exit " << rc << "); console:\n" << console;
  EXPECT_EQ(console.find("INSMOD_FAILED"), std::string::npos) << console;

  std::map<std::string, std::string> checks;
  std::istringstream lines(console);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto at = line.find("CHECK ");
    if (at == std::string::npos) continue;
    std::istringstream fields(line.substr(at + 6));
    std::string name, verdict;
    fields >> name >> verdict;
    std::string detail;
    std::getline(fields, detail);
    checks[name] = verdict + detail;
    EXPECT_EQ(verdict, "ok") << name << ":" << detail;
  }
  for (const char* expected :
       {"list_devices", "yuyv_format", "gain_locked", "busy_device", "yuyv_frames", "yuyv_sequence",
        "yuyv_timestamps", "yuyv_colour_bars", "nv12_frames", "grey_frames", "rgb24_frames", "bgr24_frames",
        "unsupported_format", "unsupported_size", "missing_exposure_control", "missing_device", "not_v4l2"}) {
    EXPECT_TRUE(checks.count(expected)) << "the probe never reported " << expected << "; console:\n" << console;
  }
  EXPECT_NE(console.find("PROBE_EXIT 0"), std::string::npos);
}

}  // namespace
