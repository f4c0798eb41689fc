#include "station/http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <optional>

#include <nlohmann/json.hpp>

#include "core/log.h"

namespace ss {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kMaxDrainBytes = 64 << 10;  // read and dropped before a connection is closed
// waits notice a stopping server this often
constexpr auto kStopCheck = std::chrono::milliseconds(100);

// The numeric address and port of a socket's peer (`peer`) or its own end; false when unknown.
bool AddressOf(int sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  auto* any = reinterpret_cast<sockaddr*>(&addr);
  if ((peer ? ::getpeername(sock, any, &len) : ::getsockname(sock, any, &len)) != 0) return false;
  char text[INET6_ADDRSTRLEN] = "";
  if (addr.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<const sockaddr_in*>(&addr);
    ::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
    port = ntohs(in->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* in6 = reinterpret_cast<const sockaddr_in6*>(&addr);
    ::inet_ntop(AF_INET6, &in6->sin6_addr, text, sizeof text);
    port = ntohs(in6->sin6_port);
  } else {
    return false;
  }
  ip = text;
  return true;
}

// Methods whose body cpp-httplib reads (its detail::expect_content).
bool ExpectsBody(const std::string& method) {
  return method == "POST" || method == "PUT" || method == "PATCH" || method == "DELETE" ||
         method == "PRI";
}

// One connection's socket as cpp-httplib reads and writes it, kept across the requests of a
// keep-alive connection. A read waits at most the read timeout and, while a request is being
// received, no later than its deadline; every wait ends within 100 ms of the server stopping.
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(int sock, const std::atomic<socket_t>& listener, Clock::duration read_timeout,
                   Clock::duration write_timeout, size_t max_header_bytes)
      : sock_(sock),
        listener_(listener),
        read_timeout_(read_timeout),
        write_timeout_(write_timeout),
        max_header_bytes_(max_header_bytes) {}

  // Waits up to `idle` for the next request's first byte; false when none came.
  bool WaitForRequest(Clock::duration idle) {
    deadline_.reset();
    return off_ < len_ || Wait(POLLIN, idle);
  }

  // A request's first byte is here: all of it must be read by `deadline`.
  void BeginRequest(Clock::time_point deadline) {
    deadline_ = deadline;
    fault_ = HttpServer::RequestFault::kNone;
    header_in_ = false;
    header_bytes_ = 0;
    body_left_ = 0;
  }

  // Its header is in (cpp-httplib's setup_request hook). A request without a body is whole
  // now; one with a Content-Length once that many more bytes are read. A chunked body, or one
  // without a length (read until the client closes), stays under the deadline to the end.
  void HeaderIn(const httplib::Request& req) {
    header_in_ = true;
    if (!ExpectsBody(req.method)) {
      deadline_.reset();
      return;
    }
    if (strcasecmp(req.get_header_value("Transfer-Encoding").c_str(), "chunked") == 0) return;
    const std::string length = req.get_header_value("Content-Length");
    uint64_t n = 0;
    const auto [end, error] = std::from_chars(length.data(), length.data() + length.size(), n);
    if (length.empty() || error != std::errc() || end != length.data() + length.size()) return;
    body_left_ = n;
    if (n == 0) deadline_.reset();
  }

  HttpServer::RequestFault fault() const { return fault_; }

  bool is_readable() const override { return off_ < len_ || Wait(POLLIN, read_timeout_); }
  bool is_writable() const override { return Wait(POLLOUT, write_timeout_); }

  ssize_t read(char* ptr, size_t size) override {
    if (off_ == len_) {
      if (!Wait(POLLIN, read_timeout_)) return -1;
      ssize_t n = 0;
      do {
        n = ::recv(sock_, buffer_.data(), buffer_.size(), 0);
      } while (n < 0 && errno == EINTR);
      if (n <= 0) return n;
      off_ = 0;
      len_ = static_cast<size_t>(n);
    }
    const size_t n = std::min(size, len_ - off_);
    std::memcpy(ptr, buffer_.data() + off_, n);
    off_ += n;
    if (!header_in_ && (header_bytes_ += n) > max_header_bytes_) {
      fault_ = HttpServer::RequestFault::kHeaderTooLarge;
      return -1;
    }
    if (header_in_ && body_left_ > 0) {
      body_left_ -= std::min<uint64_t>(body_left_, n);
      if (body_left_ == 0) deadline_.reset();
    }
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    ssize_t n = 0;
    do {
      n = ::send(sock_, ptr, size, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    AddressOf(sock_, true, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    AddressOf(sock_, false, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  // Waits for `events` up to `timeout` (reads: no later than the deadline, which then counts
  // as the request's fault); false on timeout, a poll error or the server stopping.
  bool Wait(short events, Clock::duration timeout) const {
    Clock::time_point until = Clock::now() + timeout;
    const bool deadline = (events & POLLIN) && deadline_ && *deadline_ < until;
    if (deadline) until = *deadline_;
    while (listener_ != INVALID_SOCKET) {
      const Clock::time_point now = Clock::now();
      if (now >= until) {
        if (deadline) fault_ = HttpServer::RequestFault::kTimedOut;
        return false;
      }
      const auto slice = std::min<Clock::duration>(until - now, kStopCheck);
      pollfd p{sock_, events, 0};
      const int n = ::poll(
          &p, 1, static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(slice).count()));
      if (n > 0) return true;  // ready, or an error or hang-up that recv/send then reports
      if (n < 0 && errno != EINTR) return false;
    }
    return false;
  }

  const int sock_;
  const std::atomic<socket_t>& listener_;  // INVALID_SOCKET once the server stops
  const Clock::duration read_timeout_, write_timeout_;
  const size_t max_header_bytes_;
  std::array<char, 4096> buffer_{};
  size_t off_ = 0, len_ = 0;                   // the unread bytes of buffer_
  std::optional<Clock::time_point> deadline_;  // while a request is being read
  bool header_in_ = false;
  size_t header_bytes_ = 0;  // of the request line and header read so far
  uint64_t body_left_ = 0;   // Content-Length bytes still to read
  mutable HttpServer::RequestFault fault_ = HttpServer::RequestFault::kNone;
};

thread_local const ConnectionStream* t_stream = nullptr;  // the connection this thread serves

// Closes a connection after its last answer. What the client sent and the server did not read
// (the rest of a refused request) is read and dropped first, up to 64 KiB, so that the close
// sends FIN rather than a reset, which could discard the answer at the client.
void Close(int sock) {
  ::shutdown(sock, SHUT_WR);
  std::array<char, 4096> sink;
  for (size_t drained = 0; drained < kMaxDrainBytes;) {
    const ssize_t n = ::recv(sock, sink.data(), sink.size(), MSG_DONTWAIT);
    if (n <= 0) break;
    drained += static_cast<size_t>(n);
  }
  ::close(sock);
}

// The 503 for a connection over the per-client limit, then closed.
void Refuse(int sock, const std::string& address, int limit) {
  const std::string body =
      nlohmann::json{{"error", "connections: " + std::to_string(limit) + " are open from " +
                                   address + " already (the limit per client address)"}}
          .dump() +
      "\n";
  const std::string reply =
      "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nContent-Length: " +
      std::to_string(body.size()) + "\r\nConnection: close\r\nRetry-After: 5\r\n\r\n" + body;
  (void)::send(sock, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  Close(sock);
}

}  // namespace

HttpServer::HttpServer(HttpLimits limits) : limits_(limits) {}

HttpCounters HttpServer::counters() const {
  return {open_.load(), refused_.load(), timed_out_.load()};
}

HttpServer::RequestFault HttpServer::CurrentFault() {
  return t_stream ? t_stream->fault() : RequestFault::kNone;
}

bool HttpServer::Admit(const std::string& address) {
  std::lock_guard lock(mutex_);
  int& open = open_by_address_[address];
  if (open >= limits_.max_connections_per_client) {
    if (open == 0) open_by_address_.erase(address);
    ++refused_;
    return false;
  }
  ++open;
  ++open_;
  return true;
}

void HttpServer::Release(const std::string& address) {
  std::lock_guard lock(mutex_);
  const auto it = open_by_address_.find(address);
  if (it != open_by_address_.end() && --it->second <= 0) open_by_address_.erase(it);
  --open_;
}

bool HttpServer::process_and_close_socket(socket_t sock) {
  std::string address;  // "" when unknown: such connections share one count
  int port = 0;
  AddressOf(sock, true, address, port);
  if (!Admit(address)) {
    Log("station.control")
        ->debug("{}:{}: refused, {} connections are open from there", address, port,
                limits_.max_connections_per_client);
    Refuse(sock, address, limits_.max_connections_per_client);
    return false;
  }
  ConnectionStream stream(
      sock, svr_sock_,
      std::chrono::seconds(read_timeout_sec_) + std::chrono::microseconds(read_timeout_usec_),
      std::chrono::seconds(write_timeout_sec_) + std::chrono::microseconds(write_timeout_usec_),
      limits_.max_header_bytes);
  t_stream = &stream;
  bool ret = false;
  // cpp-httplib's keep-alive loop (detail::process_server_socket_core), with the deadline.
  for (size_t left = keep_alive_max_count_; left > 0 && svr_sock_ != INVALID_SOCKET; --left) {
    if (!stream.WaitForRequest(std::chrono::seconds(keep_alive_timeout_sec_))) break;
    stream.BeginRequest(Clock::now() + limits_.request_deadline);
    bool connection_closed = false;
    ret = process_request(stream, left == 1, connection_closed,
                          [&stream](httplib::Request& req) { stream.HeaderIn(req); });
    if (stream.fault() != RequestFault::kNone) {
      if (stream.fault() == RequestFault::kTimedOut) ++timed_out_;
      Log("station.control")
          ->debug("{}:{}: closed, its request {}", address, port,
                  stream.fault() == RequestFault::kTimedOut ? "was not in whole by the deadline"
                                                            : "header was too large");
      break;
    }
    if (!ret || connection_closed) break;
  }
  t_stream = nullptr;
  Close(sock);
  Release(address);
  return ret;
}

}  // namespace ss
