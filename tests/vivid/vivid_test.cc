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

#include "tests/support/qemu_guest.h"
#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;

using ss::testing::CpioWriter;
using ss::testing::FindProgram;
using ss::testing::IsStaticExecutable;
using ss::testing::ModuleBytes;
const auto& ReadFile = ss::testing::ReadFileBytes;

TEST(Vivid, V4l2BackendStreamsFromTheRealDriverUnderQemu) {
  const std::string qemu =
      FindProgram({"/usr/bin/qemu-system-x86_64", "/usr/local/bin/qemu-system-x86_64"});
  if (qemu.empty())
    GTEST_SKIP() << "qemu-system-x86_64 not installed (Debian package qemu-system-x86)";
  fs::path kernel, modules;
  if (!ss::testing::FindKernelWithModules({"vivid"}, &kernel, &modules)) {
    GTEST_SKIP() << "no kernel with the vivid module under /boot and /lib/modules (Debian package "
                    "linux-image-amd64)";
  }
  const std::string busybox = FindProgram({"/bin/busybox", "/usr/bin/busybox"});
  if (busybox.empty()) GTEST_SKIP() << "busybox not installed (Debian package busybox-static)";
  if (!IsStaticExecutable(busybox)) {
    GTEST_SKIP() << busybox << " is not the static build (Debian package busybox-static)";
  }
  const std::string probe = VIVID_PROBE_PATH;
  ASSERT_TRUE(fs::exists(probe)) << probe;
  ASSERT_TRUE(IsStaticExecutable(probe))
      << probe << " must be statically linked to run in the guest";

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
  const auto order = ss::testing::ModuleLoadOrder(modules, {"vivid"});
  ASSERT_FALSE(order.empty()) << "vivid not in " << modules / "modules.dep";
  for (size_t i = 0; i < order.size(); ++i) {
    std::string bytes;
    ASSERT_TRUE(ModuleBytes(modules / order[i], &bytes)) << "cannot read " << modules / order[i];
    const std::string name = "lib/modules/" + std::to_string(i) + "_" +
                             fs::path(order[i]).filename().string().substr(
                                 0, fs::path(order[i]).filename().string().find(".ko")) +
                             ".ko";
    cpio.File(name, bytes, false);
    const bool is_vivid = i + 1 == order.size();
    init += "/bin/busybox insmod /" + name + (is_vivid ? " n_devs=1 node_types=0x1" : "") +
            " || echo INSMOD_FAILED " + name + "\n";
  }
  init +=
      "i=0; while [ ! -e /dev/video0 ] && [ $i -lt 100 ]; do /bin/busybox sleep 0.1; i=$((i+1)); "
      "done\n"
      "/probe\n"
      "echo PROBE_EXIT $?\n"
      "/bin/busybox poweroff -f\n";
  cpio.File("init", init, true);
  cpio.Finish();
  ASSERT_TRUE(cpio.ok());

  const fs::path log = dir.path() / "console.txt";
  const std::string command = "timeout -k 5 170 " + qemu +
                              " -accel tcg -m 512 -smp 1 -nographic -no-reboot -nic none" +
                              " -kernel " + kernel.string() + " -initrd " + initrd.string() +
                              " -append 'console=ttyS0 panic=-1 loglevel=3 no_timer_check "
                              "mitigations=off rdinit=/init' < /dev/null > " +
                              log.string() + " 2>&1";
  const int rc = ss::testing::RunCommand(command).exit_code;
  const std::string console = ReadFile(log);
  ASSERT_NE(console.find("PROBE_DONE"), std::string::npos)
      << "the probe did not finish (qemu exit " << rc << "); console:\n"
      << console;
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
        "yuyv_timestamps", "yuyv_colour_bars", "nv12_frames", "grey_frames", "rgb24_frames",
        "bgr24_frames", "unsupported_format", "unsupported_size", "missing_exposure_control",
        "missing_device", "not_v4l2"}) {
    EXPECT_TRUE(checks.count(expected)) << "the probe never reported " << expected << "; console:\n"
                                        << console;
  }
  EXPECT_NE(console.find("PROBE_EXIT 0"), std::string::npos);
}

}  // namespace
