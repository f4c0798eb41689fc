// The libcamera backend against a real kernel driver stack: boots Debian's
// kernel under qemu (software emulation) with an initramfs holding busybox,
// dummy_hcd (a USB host and device controller joined in software), gadgetfs,
// uvcvideo and their modules, the UVC camera served from userspace
// (uvc_gadget.cc) and the probe (uvc_probe.cc) with the shared libraries it
// needs. The guest's uvcvideo enumerates the gadget as a USB webcam; libcamera's
// UVC pipeline handler drives it. Checks every line the probe printed and the
// control values the camera received. Skips, naming what is missing, when qemu,
// the kernel, its modules or busybox is absent.
//
// One shim: libcamera's UVC handler names a camera after the firmware (ACPI or
// device tree) node of its USB controller, and dummy_hcd is a platform device
// without one. The guest mounts sysfs at /fw/sys (/sys is a symlink to it) and
// puts firmware_node/path in /fw, the first folder above the sysfs mount that
// libcamera looks in. Everything else is the real driver path.
#include <elf.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <opencv2/imgcodecs.hpp>
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
using ss::testing::ModuleBytes;
const auto& ReadFile = ss::testing::ReadFileBytes;
const auto& Interpreter = ss::testing::ElfInterpreter;

const std::vector<std::string> kModules = {"dummy_hcd", "gadgetfs", "uvcvideo"};

// The shared libraries `ldd` resolves for `binary` (absolute paths).
std::vector<std::string> SharedLibraries(const std::string& binary) {
  std::vector<std::string> out;
  FILE* pipe = popen(("ldd '" + binary + "'").c_str(), "r");
  if (pipe == nullptr) return out;
  char line[4096];
  while (fgets(line, sizeof line, pipe) != nullptr) {
    std::istringstream fields(line);
    std::string name, arrow, path;
    fields >> name >> arrow >> path;
    if (arrow == "=>" && !path.empty() && path[0] == '/') out.push_back(path);
  }
  pclose(pipe);
  return out;
}

// The guest's /init: modules, gadgetfs, the camera in its main layout and the
// probe, then the camera in its NV12 layout and the probe again.
std::string InitScript(const std::vector<std::string>& module_files) {
  std::string init =
      "#!/bin/busybox sh\n"
      "/bin/busybox mount -t proc proc /proc\n"
      "/bin/busybox mount -t sysfs sys /fw/sys\n"
      "/bin/busybox mount -t devtmpfs dev /dev\n"
      "/bin/busybox mkdir -p /dev/gadget /run/udev/data\n";
  // uvcvideo's streaming-control timeout from 5 s to 30 s: a loaded host slows the guest.
  for (const auto& m : module_files) {
    const bool uvc = m.find("_uvcvideo.ko") != std::string::npos;
    init += "/bin/busybox insmod /" + m + (uvc ? " timeout=30000" : "") +
            " || echo INSMOD_FAILED " + m + "\n";
  }
  init +=
      "/bin/busybox mount -t gadgetfs gadgetfs /dev/gadget || echo GADGETFS_MOUNT_FAILED\n"
      // No udevd in the guest: libcamera enumerates only devices udev has initialized, so mark
      // them.
      "udevdb() {\n"
      // uvcvideo registers the media device, then the video and metadata nodes.
      "  i=0; while [ ! -e /dev/media0 -o ! -e /dev/video0 -o ! -e /dev/video1 ] && [ $i -lt 600 "
      "]; do\n"
      "    /bin/busybox sleep 0.1; i=$((i+1))\n"
      "  done\n"
      "  [ -e /dev/video1 ] || { echo NO_VIDEO_DEVICE; /bin/busybox dmesg | /bin/busybox tail -n "
      "30; }\n"
      "  /bin/busybox sleep 0.5\n"
      "  for d in /sys/bus/media/devices/* /sys/class/video4linux/*; do\n"
      "    echo I:1 > /run/udev/data/c$(/bin/busybox cat $d/dev)\n"
      "  done\n"
      "}\n"
      "/gadget /frame.jpg &\n"
      "G=$!\n"
      "udevdb\n"
      "LD_LIBRARY_PATH=/lib /probe\n"
      "echo PROBE_EXIT $?\n"
      "kill $G\n"
      "i=0; while [ -e /dev/media0 -o -e /dev/video0 ] && [ $i -lt 300 ]; do /bin/busybox sleep "
      "0.1; i=$((i+1)); done\n"
      "/bin/busybox rm -f /run/udev/data/*\n"
      "/gadget /frame.jpg nv12 &\n"
      "udevdb\n"
      "LD_LIBRARY_PATH=/lib /probe nv12\n"
      "echo PROBE_EXIT $?\n"
      "/bin/busybox poweroff -f\n";
  return init;
}

TEST(Uvc, LibcameraBackendStreamsFromAUsbCameraUnderQemu) {
  const std::string qemu =
      FindProgram({"/usr/bin/qemu-system-x86_64", "/usr/local/bin/qemu-system-x86_64"});
  if (qemu.empty())
    GTEST_SKIP() << "qemu-system-x86_64 not installed (Debian package qemu-system-x86)";
  fs::path kernel, modules;
  if (!ss::testing::FindKernelWithModules(kModules, &kernel, &modules)) {
    GTEST_SKIP() << "no kernel under /boot with dummy_hcd, gadgetfs and uvcvideo modules (Debian "
                    "linux-image-amd64)";
  }
  const std::string busybox = FindProgram({"/bin/busybox", "/usr/bin/busybox"});
  if (busybox.empty() || !Interpreter(busybox).empty()) {
    GTEST_SKIP() << "static busybox not installed (Debian package busybox-static)";
  }
  const std::string gadget = UVC_GADGET_PATH;
  const std::string probe = UVC_PROBE_PATH;
  ASSERT_TRUE(Interpreter(gadget).empty()) << gadget << " must be statically linked";
  const std::string interpreter = Interpreter(probe);
  ASSERT_FALSE(interpreter.empty()) << probe;
  const std::vector<std::string> libraries = SharedLibraries(probe);
  ASSERT_FALSE(libraries.empty()) << "ldd found no libraries for " << probe;

  ss::testing::ScratchDir dir;
  const fs::path initrd = dir.path() / "initrd.cpio";
  CpioWriter cpio(initrd);
  for (const char* d :
       {"bin", "dev", "proc", "run", "tmp", "lib", "mods", "fw", "fw/sys", "fw/firmware_node"}) {
    cpio.Dir(d);
  }
  cpio.Symlink("sys", "/fw/sys");
  cpio.File("fw/firmware_node/path", "\\_SB_.PCI0.USB0\n", false);
  cpio.File("bin/busybox", ReadFile(busybox), true);
  cpio.File("gadget", ReadFile(gadget), true);
  cpio.File("probe", ReadFile(probe), true);
  const std::string interp_dir = fs::path(interpreter).parent_path().string().substr(1);
  if (interp_dir != "lib") cpio.Dir(interp_dir);
  cpio.File(interpreter.substr(1), ReadFile(fs::canonical(interpreter)), true);
  for (const auto& lib : libraries) {
    cpio.File("lib/" + fs::path(lib).filename().string(), ReadFile(fs::canonical(lib)), false);
  }
  // The MJPEG frame: left half green, right half magenta.
  cv::Mat image(240, 320, CV_8UC3, cv::Scalar(255, 0, 255));
  image(cv::Rect(0, 0, 160, 240)).setTo(cv::Scalar(0, 255, 0));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", image, jpeg));
  cpio.File("frame.jpg", std::string(jpeg.begin(), jpeg.end()), false);

  const auto order = ss::testing::ModuleLoadOrder(modules, kModules);
  ASSERT_GE(order.size(), kModules.size()) << modules / "modules.dep";
  std::vector<std::string> module_files;
  for (size_t i = 0; i < order.size(); ++i) {
    std::string bytes;
    ASSERT_TRUE(ModuleBytes(modules / order[i], &bytes)) << "cannot read " << modules / order[i];
    const std::string file = fs::path(order[i]).filename().string();
    module_files.push_back("mods/" + std::to_string(i) + "_" + file.substr(0, file.find(".ko")) +
                           ".ko");
    cpio.File(module_files.back(), bytes, false);
  }
  cpio.File("init", InitScript(module_files), true);
  cpio.Finish();
  ASSERT_TRUE(cpio.ok());

  const fs::path log = dir.path() / "console.txt";
  const std::string command =
      "timeout -k 5 170 " + qemu +
      " -accel tcg -m 768 -smp 1 -nographic -no-reboot -nic none -kernel " + kernel.string() +
      " -initrd " + initrd.string() +
      " -append 'console=ttyS0 panic=-1 loglevel=3 no_timer_check mitigations=off "
      "rdinit=/init' < /dev/null > " +
      log.string() + " 2>&1";
  const int rc = ss::testing::RunCommand(command).exit_code;
  const std::string console = ReadFile(log);
  ASSERT_NE(console.find("PROBE_DONE_NV12"), std::string::npos)
      << "the probe did not finish (qemu exit " << rc << "); console:\n"
      << console;
  EXPECT_EQ(console.find("INSMOD_FAILED"), std::string::npos) << console;

  std::map<std::string, std::string> checks;
  std::map<std::string, std::string> controls_received;  // "entity/selector" -> last value
  std::istringstream lines(console);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (const auto at = line.find("CHECK "); at != std::string::npos) {
      std::istringstream fields(line.substr(at + 6));
      std::string name, verdict, detail;
      fields >> name >> verdict;
      std::getline(fields, detail);
      checks[name] = verdict + detail;
      EXPECT_EQ(verdict, "ok") << name << ":" << detail;
    } else if (const auto m = line.find("MEASURE "); m != std::string::npos) {
      std::istringstream fields(line.substr(m + 8));
      std::string name, value;
      fields >> name >> value;
      ::testing::Test::RecordProperty(name, value);
      std::printf("%s = %s\n", name.c_str(), value.c_str());
    } else if (const auto g = line.find("GADGET SET "); g != std::string::npos) {
      unsigned entity = 0, selector = 0;
      int value = 0;
      if (std::sscanf(line.c_str() + g, "GADGET SET entity=%u selector=%u value=%d", &entity,
                      &selector, &value) == 3) {
        controls_received[std::to_string(entity) + "/" + std::to_string(selector)] =
            std::to_string(value);
      }
    }
  }
  for (const char* expected :
       {"list_cameras", "unknown_camera", "unsupported_format", "unsupported_size",
        "exposure_out_of_range", "controls_listed", "controls_ignored", "yuyv_format",
        "busy_camera", "yuyv_frames", "yuyv_sequence", "yuyv_timestamps", "yuyv_colour_bars",
        "stop", "yuyv_160x120", "mjpeg_frames", "nv12_list_cameras", "nv12_frames"}) {
    EXPECT_TRUE(checks.count(expected)) << "the probe never reported " << expected << "; console:\n"
                                        << console;
  }
  // What the camera received: auto exposure off (UVC AE mode 1 = manual), 8000 us
  // exposure (80 in 100 us units), and a gain above its default of 100 for AnalogueGain 2.
  EXPECT_EQ(controls_received["1/2"], "1") << console;
  EXPECT_EQ(controls_received["1/4"], "80") << console;
  ASSERT_TRUE(controls_received.count("3/4")) << console;
  EXPECT_GT(std::stoi(controls_received["3/4"]), 100) << console;
  EXPECT_EQ(console.find("PROBE_EXIT 1"), std::string::npos) << console;
}

}  // namespace
