#pragma once
// Pieces for tests that boot Debian's kernel under qemu with a small initramfs
// (tests/vivid: the V4L2 backend against vivid; tests/libcamera/uvc: libcamera
// against a USB camera): the cpio writer, the kernel and its modules in load
// order, and what a binary needs in the guest.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace ss::testing {

// The whole file ("" when it cannot be read).
std::string ReadFileBytes(const std::filesystem::path& path);

// Writes a cpio archive in the kernel's "newc" format.
class CpioWriter {
 public:
  explicit CpioWriter(const std::filesystem::path& path) : out_(path, std::ios::binary) {}
  void Dir(const std::string& name) { Entry(name, 040755, ""); }
  void File(const std::string& name, const std::string& data, bool executable) {
    Entry(name, executable ? 0100755 : 0100644, data);
  }
  void Symlink(const std::string& name, const std::string& target) { Entry(name, 0120777, target); }
  void Finish();
  bool ok() const { return out_.good(); }

 private:
  void Entry(const std::string& name, unsigned mode, const std::string& data);
  void Pad(size_t n);
  std::ofstream out_;
  unsigned ino_ = 1;
};

// The newest kernel under /boot whose modules (/lib/modules/VERSION) include every one of
// `module_names` ("vivid", "dummy_hcd"...); false when there is none.
bool FindKernelWithModules(const std::vector<std::string>& module_names,
                           std::filesystem::path* kernel, std::filesystem::path* modules_dir);

// Module paths (relative to `modules_dir`) in load order: each module after its
// dependencies (modules.dep), for every one of `module_names`.
std::vector<std::string> ModuleLoadOrder(const std::filesystem::path& modules_dir,
                                         const std::vector<std::string>& module_names);

// A module's bytes, decompressed when the distribution ships it as .ko.xz / .ko.zst.
bool ModuleBytes(const std::filesystem::path& path, std::string* bytes);

// The ELF file's program interpreter ("" for a statically linked executable or not ELF).
std::string ElfInterpreter(const std::string& path);
// True when `path` is an ELF executable that asks for no interpreter.
bool IsStaticExecutable(const std::string& path);

// The first of `candidates` that is executable ("" when none is).
std::string FindProgram(const std::vector<std::string>& candidates);

}  // namespace ss::testing
