// The control server's HTTP surface (station/http_server.h, station/control_server.h): the bytes
// are what one client sends on one connection (request lines, headers, bodies, more requests
// behind them), sent over loopback to a ControlServer of this process with every route of the
// API and the console behind it (no station runs: a route that needs one answers 500 after
// every check before it). The connection must end within its deadline, and every answer must
// be an HTTP/1.1 status line with a JSON error or a page, never a file outside the pages.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <system_error>
#include <thread>

#include "core/log.h"
#include "station/control_server.h"
#include "station/station_host.h"
#include "tests/fuzz/fuzz_support.h"
#include "web/web_files.h"

namespace {

using Clock = std::chrono::steady_clock;

// The server, started once per process and never stopped (its threads outlive the inputs);
// held by globals, so that LeakSanitizer sees it reachable at exit.
ss::StationHost* g_host = nullptr;
ss::ControlServer* g_server = nullptr;

int Port() {
  static const int port = [] {
    ss::SetLogLevel("off");
    g_host = new ss::StationHost(ss::StationOptions{}, {});
    ss::ControlServerOptions options;
    options.config.address = "127.0.0.1";
    options.config.port = 0;
    options.embedded = ss::FindEmbeddedWebFile;
    options.http_threads = 32;  // more than the 16 event streams that may be open at once
    g_server = new ss::ControlServer(*g_host, options);
    return g_server->Start();
  }();
  return port;
}

// True when one of the answers read so far is an event stream: a status line at the start or
// after an answer's end whose header names text/event-stream. (Answers are walked by their
// Content-Length; a header without one ends the walk.)
bool AnswersAnEventStream(const std::string& answer) {
  size_t at = 0;
  while (at < answer.size()) {
    const size_t head_end = answer.find("\r\n\r\n", at);
    if (head_end == std::string::npos) return false;
    const std::string head = answer.substr(at, head_end - at);
    if (head.find("Content-Type: text/event-stream") != std::string::npos) return true;
    const size_t length = head.find("Content-Length: ");
    if (length == std::string::npos) return false;
    at = head_end + 4 + std::strtoull(head.c_str() + length + 16, nullptr, 10);
  }
  return false;
}

// The first line of /etc/passwd (the usual one when it cannot be read).
const std::string& PasswdFirstLine() {
  static const std::string line = [] {
    std::ifstream file("/etc/passwd");
    std::string first;
    std::getline(file, first);
    return first.size() >= 10 ? first : std::string("root:x:0:0:root:/root:");
  }();
  return line;
}

// A connection to the server, or -1 with errno. libFuzzer's timer (SIGALRM, no SA_RESTART) may
// interrupt a connect that waits for room in the server's accept queue on a loaded machine
// (CI's run found it so: "cannot connect" after 1,425 inputs, not reproducible alone), so an
// interrupted or refused attempt is tried again, for up to 5 s.
int Connect(int port) {
  sockaddr_in server{};
  server.sin_family = AF_INET;
  server.sin_port = htons(static_cast<uint16_t>(port));
  server.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  int error = 0;
  do {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return -1;
    if (::connect(fd, reinterpret_cast<sockaddr*>(&server), sizeof server) == 0) return fd;
    error = errno;
    ::close(fd);
    if (error != EINTR && error != ECONNREFUSED && error != EAGAIN) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  } while (Clock::now() < deadline);
  errno = error;
  return -1;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const int port = Port();
  const int fd = Connect(port);
  if (fd < 0) {
    std::fprintf(stderr, "http_request: cannot connect to the server: %s\n",
                 std::error_code(errno, std::generic_category()).message().c_str());
    std::abort();
  }
  // Send it all (the server may close early: a refused request), then say that is all.
  for (size_t sent = 0; sent < size;) {
    const ssize_t n = ::send(fd, data + sent, size - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;  // libFuzzer's timer (Connect)
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  ::shutdown(fd, SHUT_WR);
  // Everything the server answers, until it closes, within 8 s (libFuzzer's -timeout is 10):
  // never a connection left open. An event stream (GET /api/events) stays open by design: once
  // its header is in, the client closes it, whether it answers the first request or one
  // pipelined behind others (a refused request line may be followed by `GET /api/events`).
  std::string answer;
  const auto deadline = Clock::now() + std::chrono::seconds(8);
  bool closed = false;
  while (!closed && Clock::now() < deadline) {
    if (AnswersAnEventStream(answer)) {
      closed = true;
      break;
    }
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    char buf[16384];
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;  // libFuzzer's timer (Connect)
    if (n <= 0) {
      closed = true;
    } else if (answer.size() < (4u << 20)) {
      answer.append(buf, static_cast<size_t>(n));
    }
  }
  ::close(fd);
  if (!closed) {
    std::fprintf(stderr,
                 "http_request: the server kept the connection open past 8 s; it said:\n%s\n",
                 answer.substr(0, 600).c_str());
    std::abort();
  }
  if (!answer.empty() && answer.rfind("HTTP/1.1 ", 0) != 0) {
    std::fprintf(stderr, "http_request: an answer that is not HTTP/1.1: %.80s\n", answer.c_str());
    std::abort();
  }
  // /etc/passwd's first line, whole, in the answer and not quoted from the request. An error may
  // quote what the request sent, escaped: a CR before "oot:x:0:0" reads "\root:x:0:0" (CI found
  // that), so the line's start alone is not enough; and a CR before the rest of the whole line
  // reads as the whole line (CI found that too), so a request that sent the line less its first
  // letter is not read as a leak either. A path traversal names the file, never its lines.
  const std::string& passwd = PasswdFirstLine();
  const std::string sent(reinterpret_cast<const char*>(data), size);
  if (const size_t at = answer.find(passwd);
      at != std::string::npos && sent.find(passwd.substr(1)) == std::string::npos) {
    std::fprintf(stderr, "http_request: /etc/passwd was served: ...%s...\n",
                 answer.substr(at > 80 ? at - 80 : 0, 200).c_str());
    std::abort();
  }
  return 0;
}
