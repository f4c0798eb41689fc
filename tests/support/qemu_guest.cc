#include "tests/support/qemu_guest.h"

#include <elf.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace ss::testing {

namespace fs = std::filesystem;

std::string ReadFileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void CpioWriter::Finish() {
  Entry("TRAILER!!!", 0, "");
  out_.close();
}

void CpioWriter::Entry(const std::string& name, unsigned mode, const std::string& data) {
  char header[111];
  std::snprintf(header, sizeof header, "070701%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X%08X",
                ino_++, mode, 0u, 0u, 1u, 0u, static_cast<unsigned>(data.size()), 0u, 0u, 0u, 0u,
                static_cast<unsigned>(name.size() + 1), 0u);
  out_.write(header, 110);
  out_.write(name.c_str(), static_cast<std::streamsize>(name.size() + 1));
  Pad(110 + name.size() + 1);
  out_.write(data.data(), static_cast<std::streamsize>(data.size()));
  Pad(data.size());
}

void CpioWriter::Pad(size_t n) {
  static const char zeros[4] = {0, 0, 0, 0};
  out_.write(zeros, static_cast<std::streamsize>((4 - n % 4) % 4));
}

bool FindKernelWithModules(const std::vector<std::string>& module_names, fs::path* kernel,
                           fs::path* modules_dir) {
  std::error_code ec;
  std::vector<fs::path> kernels;
  for (const auto& e : fs::directory_iterator("/boot", ec)) {
    if (e.path().filename().string().rfind("vmlinuz-", 0) == 0) kernels.push_back(e.path());
  }
  std::sort(kernels.rbegin(), kernels.rend());
  for (const auto& k : kernels) {
    const fs::path mods = fs::path("/lib/modules") / k.filename().string().substr(8);
    const std::string dep =
        fs::exists(mods / "modules.dep") ? ReadFileBytes(mods / "modules.dep") : "";
    bool all = !dep.empty();
    for (const auto& m : module_names) all = all && dep.find("/" + m + ".ko") != std::string::npos;
    if (all) {
      *kernel = k;
      *modules_dir = mods;
      return true;
    }
  }
  return false;
}

std::vector<std::string> ModuleLoadOrder(const fs::path& modules_dir,
                                         const std::vector<std::string>& module_names) {
  std::map<std::string, std::vector<std::string>> deps;
  std::map<std::string, std::string> path_of;
  std::istringstream in(ReadFileBytes(modules_dir / "modules.dep"));
  for (std::string line; std::getline(in, line);) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string module = line.substr(0, colon);
    std::istringstream rest(line.substr(colon + 1));
    std::vector<std::string> list;
    for (std::string d; rest >> d;) list.push_back(d);
    deps[module] = list;
    const std::string file = fs::path(module).filename().string();
    path_of[file.substr(0, file.find(".ko"))] = module;
  }
  std::vector<std::string> order;
  std::set<std::string> done;
  std::function<void(const std::string&)> visit = [&](const std::string& m) {
    if (!done.insert(m).second) return;
    for (const auto& d : deps[m]) visit(d);
    order.push_back(m);
  };
  for (const auto& name : module_names) {
    if (path_of.count(name)) visit(path_of[name]);
  }
  return order;
}

bool ModuleBytes(const fs::path& path, std::string* bytes) {
  const std::string p = path.string();
  std::string tool;
  if (p.size() > 3 && p.substr(p.size() - 3) == ".xz") tool = "xz -dc ";
  if (p.size() > 4 && p.substr(p.size() - 4) == ".zst") tool = "zstd -dc ";
  if (tool.empty()) {
    *bytes = ReadFileBytes(path);
    return !bytes->empty();
  }
  FILE* pipe = popen((tool + "'" + p + "'").c_str(), "r");
  if (pipe == nullptr) return false;
  bytes->clear();
  char buf[65536];
  for (size_t n; (n = fread(buf, 1, sizeof buf, pipe)) > 0;) bytes->append(buf, n);
  return pclose(pipe) == 0 && !bytes->empty();
}

namespace {

// Reads the ELF header; false when `bytes` is not a 64-bit ELF file.
bool ElfHeader(const std::string& bytes, Elf64_Ehdr* eh) {
  if (bytes.size() < sizeof(Elf64_Ehdr) || bytes.compare(0, 4, ELFMAG) != 0) return false;
  std::memcpy(eh, bytes.data(), sizeof *eh);
  return true;
}

}  // namespace

std::string ElfInterpreter(const std::string& path) {
  const std::string bytes = ReadFileBytes(path);
  Elf64_Ehdr eh;
  if (!ElfHeader(bytes, &eh)) return "";
  for (int i = 0; i < eh.e_phnum; ++i) {
    const size_t at = eh.e_phoff + static_cast<size_t>(i) * eh.e_phentsize;
    if (at + sizeof(Elf64_Phdr) > bytes.size()) return "";
    Elf64_Phdr ph;
    std::memcpy(&ph, bytes.data() + at, sizeof ph);
    if (ph.p_type == PT_INTERP && ph.p_offset + ph.p_filesz <= bytes.size()) {
      return std::string(bytes.data() + ph.p_offset,
                         strnlen(bytes.data() + ph.p_offset, ph.p_filesz));
    }
  }
  return "";
}

bool IsStaticExecutable(const std::string& path) {
  Elf64_Ehdr eh;
  return ElfHeader(ReadFileBytes(path), &eh) && ElfInterpreter(path).empty();
}

std::string FindProgram(const std::vector<std::string>& candidates) {
  for (const auto& c : candidates) {
    if (access(c.c_str(), X_OK) == 0) return c;
  }
  return "";
}

}  // namespace ss::testing
