#include "tests/support/postgres_server.h"

#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <libpq-fe.h>
#include <netinet/in.h>
#include <pwd.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

namespace ss::testing {
namespace {

namespace fs = std::filesystem;

// The user "nobody" (postgres refuses to run as root), looked up once with getpwnam_r (getpwnam's
// entry is shared by every thread); nullptr when there is none.
const passwd* NobodyUser() {
  struct Entry {
    passwd user{};
    std::array<char, 4096> text{};
    bool found = false;
  };
  static const Entry* const entry = [] {
    auto* e = new Entry;  // lives as long as the process, like getpwnam's own
    passwd* result = nullptr;
    e->found = ::getpwnam_r("nobody", &e->user, e->text.data(), e->text.size(), &result) == 0 &&
               result != nullptr;
    return e;
  }();
  return entry->found ? &entry->user : nullptr;
}

// The newest installed server's bin folder ("" when none).
std::string FindBin() {
  std::string best;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/usr/lib/postgresql", ec)) {
    const fs::path bin = entry.path() / "bin";
    if (fs::exists(bin / "postgres") && (best.empty() || bin.string() > best)) best = bin.string();
  }
  return best;
}

// A port of 127.0.0.1 that nothing listens on now (the kernel's pick for port 0).
int FreePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof(addr);
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port = ntohs(addr.sin_port);
  }
  ::close(fd);
  return port;
}

// Runs `argv` as the server's user with stdout and stderr appended to `log`; returns the pid.
int Spawn(const std::vector<std::string>& argv, const std::string& log) {
  const passwd* nobody = ::geteuid() == 0 ? NobodyUser() : nullptr;
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  if (nobody) {
    ::setgroups(0, nullptr);
    if (::setgid(nobody->pw_gid) != 0 || ::setuid(nobody->pw_uid) != 0) ::_exit(126);
  }
  const int out = ::open(log.c_str(), O_WRONLY | O_APPEND | O_CREAT, 0644);
  ::dup2(out, 1);
  ::dup2(out, 2);
  std::vector<char*> args;
  args.reserve(argv.size());
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  ::execv(args[0], args.data());
  ::_exit(127);
}

int WaitExit(int pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

PostgresServer::PostgresServer() {
  bin_ = FindBin();
  if (bin_.empty()) {
    ADD_FAILURE() << "PostgreSQL's server is not installed (/usr/lib/postgresql/*/bin/postgres): "
                     "run scripts/install-deps.sh";
    return;
  }
  char tmpl[] = "/tmp/spritestation-pg-XXXXXX";
  if (!::mkdtemp(tmpl)) {
    ADD_FAILURE() << "mkdtemp failed";
    return;
  }
  dir_ = tmpl;
  if (::geteuid() == 0) {
    const passwd* nobody = NobodyUser();
    if (!nobody || ::chown(dir_.c_str(), nobody->pw_uid, nobody->pw_gid) != 0) {
      ADD_FAILURE() << "cannot hand " << dir_ << " to user nobody";
      return;
    }
  }
  const int code =
      WaitExit(Spawn({bin_ + "/initdb", "--pgdata=" + dir_ + "/data", "--username=spritestation",
                      "--auth=trust", "--encoding=UTF8", "--locale=C", "--no-sync"},
                     dir_ + "/log"));
  if (code != 0) {
    ADD_FAILURE() << "initdb failed (exit " << code << "):\n" << log();
    return;
  }
  // Another process may take the free port between our look and the server's bind: try again.
  for (int attempt = 0; attempt < 5 && !ok(); ++attempt) {
    port_ = FreePort();
    Start();
  }
  if (!ok()) ADD_FAILURE() << "the PostgreSQL server did not start:\n" << log();
}

PostgresServer::~PostgresServer() {
  Stop();
  std::error_code ec;
  if (!dir_.empty()) fs::remove_all(dir_, ec);
}

bool PostgresServer::Start() {
  if (ok()) return true;
  // fsync off: a test's server need not survive a power cut; it does survive a crash of ours.
  pid_ = Spawn({bin_ + "/postgres", "-D", dir_ + "/data", "-p", std::to_string(port_), "-k", dir_,
                "-c", "listen_addresses=127.0.0.1", "-c", "fsync=off", "-c", "max_connections=100"},
               dir_ + "/log");
  const std::string address = Address("postgres");
  for (int i = 0; i < 300; ++i) {  // up to 30 s on a loaded machine
    if (PQping(address.c_str()) == PQPING_OK) return true;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) break;  // it gave up (the port was taken)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ::kill(pid_, SIGKILL);
  ::waitpid(pid_, nullptr, 0);
  pid_ = -1;
  return false;
}

void PostgresServer::Stop() {
  if (!ok()) return;
  ::kill(pid_, SIGINT);  // fast shutdown
  ::waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

std::string PostgresServer::Address(const std::string& name) const {
  return "postgresql://spritestation@127.0.0.1:" + std::to_string(port_) + "/" + name;
}

std::string PostgresServer::CreateDatabase(const std::string& name) {
  PGconn* conn = PQconnectdb(Address("postgres").c_str());
  PGresult* r = PQexec(conn, ("CREATE DATABASE \"" + name + "\"").c_str());
  if (PQresultStatus(r) != PGRES_COMMAND_OK)
    ADD_FAILURE() << "CREATE DATABASE " << name << ": " << PQerrorMessage(conn);
  PQclear(r);
  PQfinish(conn);
  return Address(name);
}

std::string PostgresServer::log() const {
  std::ifstream in(dir_ + "/log");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int64_t QueryInt(const std::string& address, const std::string& sql) {
  PGconn* conn = PQconnectdb(address.c_str());
  PGresult* r = PQexec(conn, sql.c_str());
  const bool ok = PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) > 0;
  if (!ok) ADD_FAILURE() << sql << ": " << PQerrorMessage(conn);
  const int64_t value = ok ? std::atoll(PQgetvalue(r, 0, 0)) : -1;
  PQclear(r);
  PQfinish(conn);
  return value;
}

}  // namespace ss::testing
