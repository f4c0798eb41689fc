#pragma once
// A private PostgreSQL server for one test (Debian's postgresql, installed by
// scripts/install-deps.sh): initdb in a fresh folder under /tmp, listening on a free port of
// 127.0.0.1 only, run as `nobody` when the test runs as root (PostgreSQL refuses root), with
// trust authentication for its superuser `spritestation`. Stopped, and its folder removed, when
// the object dies. Start failures are test failures (ADD_FAILURE with the server's log): the
// README's test command installs the server, so a missing one is a broken set-up, not a skip.
#include <cstdint>
#include <string>

namespace ss::testing {

class PostgresServer {
 public:
  PostgresServer();
  ~PostgresServer();
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

  bool ok() const { return pid_ > 0; }
  int port() const { return port_; }
  // Creates database `name` and returns its address,
  // postgresql://spritestation@127.0.0.1:PORT/name.
  std::string CreateDatabase(const std::string& name);
  // The address of database `name` (without creating it).
  std::string Address(const std::string& name) const;

  // Stops the server (fast shutdown: connections are cut) and starts it again on the same port
  // and data: what a studio sees when its database host restarts.
  void Stop();
  bool Start();
  std::string log() const;

 private:
  std::string dir_;  // the server's folder: data/, socket, log
  std::string bin_;  // /usr/lib/postgresql/<version>/bin
  int port_ = 0;
  int pid_ = -1;
};

// The single integer `sql` returns from database `address` (a test failure and -1 when the
// query fails or returns no row): straight libpq, bypassing the bank's code.
int64_t QueryInt(const std::string& address, const std::string& sql);

}  // namespace ss::testing
