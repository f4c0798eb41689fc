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
#include "core/posix.h"

namespace ss {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kMaxDrainBytes = 64 << 10;  // read and dropped before a connection is closed
// After a refused request, what the client still sends is read and dropped until it closes, for
// at most kLinger (nginx's lingering_time), and kMaxLingerBytes as a bound on the CPU it costs.
constexpr size_t kMaxLingerBytes = 64 << 20;
constexpr auto kLinger = std::chrono::seconds(1);
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
                   Clock::duration write_timeout, const HttpLimits& limits)
      : sock_(sock),
        listener_(listener),
        read_timeout_(read_timeout),
        write_timeout_(write_timeout),
        limits_(limits) {}

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
    line_in_ = false;
    header_bytes_ = 0;
    header_lines_ = 0;
    body_expected_ = false;
    body_bytes_ = 0;
    body_left_ = 0;
    written_ = 0;
  }

  // Its header is in (cpp-httplib's setup_request hook). A request without a body is whole
  // now; one with a Content-Length once that many more bytes are read. A chunked body, or one
  // without a length (read until the client closes), stays under the deadline to the end.
  // A declared length over the limit, or a framing that cannot be trusted, fails the body's
  // first read.
  void HeaderIn(const httplib::Request& req) {
    header_in_ = true;
    if (!HttpServer::AmbiguousFraming(req).empty()) {
      fault_ = HttpServer::RequestFault::kAmbiguousFraming;
      return;
    }
    if (!ExpectsBody(req.method)) {
      deadline_.reset();
      return;
    }
    body_expected_ = true;
    if (req.has_header("Transfer-Encoding")) return;  // chunked (AmbiguousFraming)
    const std::string length = req.get_header_value("Content-Length");
    uint64_t n = 0;
    const auto [end, error] = std::from_chars(length.data(), length.data() + length.size(), n);
    if (length.empty() || error != std::errc() || end != length.data() + length.size()) return;
    if (n > limits_.max_body_bytes) {
      fault_ = HttpServer::RequestFault::kBodyTooLarge;
      return;
    }
    body_left_ = n;
    if (n == 0) deadline_.reset();
  }

  // Bytes written since the request began: 0 when it got no answer.
  uint64_t written() const { return written_; }

  HttpServer::RequestFault fault() const { return fault_; }

  bool is_readable() const override { return off_ < len_ || Wait(POLLIN, read_timeout_); }
  bool is_writable() const override { return Wait(POLLOUT, write_timeout_); }

  ssize_t read(char* ptr, size_t size) override {
    // A fault ends the request's reading: what is still to come is never read.
    if (fault_ != HttpServer::RequestFault::kNone) return -1;
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
    // What this read may hand out: at most what the limits leave (the byte that passes one
    // is never read, so a body over the limit costs no more memory than the limit).
    size_t n = std::min(size, len_ - off_);
    if (!header_in_) {
      if (!CountHeader(buffer_.data() + off_, n)) return -1;
    } else if (body_expected_) {
      if (body_bytes_ + n > limits_.max_body_bytes) {
        fault_ = HttpServer::RequestFault::kBodyTooLarge;
        return -1;
      }
      body_bytes_ += n;
    }
    std::memcpy(ptr, buffer_.data() + off_, n);
    off_ += n;
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
    if (n > 0) written_ += static_cast<uint64_t>(n);
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
  // Counts `n` header bytes at `p` against the limits; false (the fault set) when one is passed.
  bool CountHeader(const char* p, size_t n) {
    header_bytes_ += n;
    for (size_t i = 0; i < n; ++i) {
      if (p[i] != '\n') continue;
      if (!line_in_) {
        line_in_ = true;
      } else {
        ++header_lines_;  // the empty line that ends the header counts too: one spare
      }
    }
    using Fault = HttpServer::RequestFault;
    if (!line_in_ && header_bytes_ > limits_.max_request_line_bytes) {
      fault_ = Fault::kRequestLineTooLong;
    } else if (header_bytes_ > limits_.max_header_bytes) {
      fault_ = Fault::kHeaderTooLarge;
    } else if (header_lines_ > limits_.max_header_lines + 1) {
      fault_ = Fault::kTooManyHeaderLines;
    }
    return fault_ == Fault::kNone;
  }

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
  const HttpLimits& limits_;
  std::array<char, 4096> buffer_{};
  size_t off_ = 0, len_ = 0;                   // the unread bytes of buffer_
  std::optional<Clock::time_point> deadline_;  // while a request is being read
  bool header_in_ = false;
  bool line_in_ = false;        // the request line's end has been read
  size_t header_bytes_ = 0;     // of the request line and header read so far
  int header_lines_ = 0;        // header lines read so far
  bool body_expected_ = false;  // the method takes a body: what is read after the header is one
  uint64_t body_bytes_ = 0;     // body bytes read so far, as sent
  uint64_t body_left_ = 0;      // Content-Length bytes still to read
  uint64_t written_ = 0;        // bytes written since the request began
  mutable HttpServer::RequestFault fault_ = HttpServer::RequestFault::kNone;
};

thread_local const ConnectionStream* t_stream = nullptr;  // the connection this thread serves
// The connection this thread serves, as counted (null: none); CountApart releases it early.
thread_local HttpServer* t_server = nullptr;
thread_local const std::string* t_address = nullptr;
thread_local bool t_counted_apart = false;

// Closes a connection after its last answer. What the client sent and the server did not read
// (the rest of a refused request) is read and dropped first, so that the close sends FIN rather
// than a reset, which could discard the answer at the client: what is there already, up to
// 64 KiB, or, after a refused request (`linger`), all it sends until it closes, bounded by time
// (kLinger) as nginx's lingering close is. A byte bound alone (4 MiB once) was spent within
// milliseconds by a client streaming a body over the limit, whose 413 the reset then discarded
// when the client had not read it yet: the sockets' own buffers hold some 10 MiB in flight.
void Close(int sock, bool linger = false) {
  ::shutdown(sock, SHUT_WR);
  std::array<char, 4096> sink;
  const size_t most = linger ? kMaxLingerBytes : kMaxDrainBytes;
  const Clock::time_point until = Clock::now() + (linger ? kLinger : Clock::duration::zero());
  for (size_t drained = 0; drained < most;) {
    if (linger) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(until - Clock::now());
      pollfd p{sock, POLLIN, 0};
      if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    }
    const ssize_t n = ::recv(sock, sink.data(), sink.size(), MSG_DONTWAIT);
    if (n <= 0) break;
    drained += static_cast<size_t>(n);
  }
  ::close(sock);
}

// The reason phrase of the statuses this file sends itself.
const char* ReasonPhrase(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 408:
      return "Request Timeout";
    case 413:
      return "Payload Too Large";
    case 414:
      return "URI Too Long";
    case 431:
      return "Request Header Fields Too Large";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

// A whole answer written straight to the socket: `status` with {"error": message}, closing.
void SendError(int sock, int status, const char* reason, const std::string& message,
               const std::string& extra_headers = "") {
  const std::string body = nlohmann::json{{"error", message}}.dump() + "\n";
  const std::string reply =
      "HTTP/1.1 " + std::to_string(status) + " " + reason +
      "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
      "\r\nConnection: close\r\n" + extra_headers + "\r\n" + body;
  (void)::send(sock, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

// The 503 for a connection over a connection limit, then closed.
void Refuse(int sock, const std::string& message) {
  SendError(sock, 503, ReasonPhrase(503), message, "Retry-After: 5\r\n");
  Close(sock);
}

std::string Seconds(std::chrono::milliseconds ms) {
  return ms.count() % 1000 == 0 ? std::to_string(ms.count() / 1000) + " s"
                                : std::to_string(ms.count()) + " ms";
}

}  // namespace

HttpServer::HttpServer(HttpLimits limits) : limits_(limits) {
  set_payload_max_length(limits_.max_body_bytes);  // a Content-Length over it: 413 at once
}

int HttpServer::Bind(const std::string& host, int port, int backlog) {
  const int bound = port == 0 ? bind_to_any_port(host) : bind_to_port(host, port) ? port : -1;
  // listen() again on a listening socket sets its backlog anew (Linux, POSIX alike).
  if (bound > 0 && ::listen(svr_sock_, backlog) != 0) {
    Log("station.control")
        ->warn("{}:{}: listen backlog stays cpp-httplib's: {}", host, bound, ErrnoText(errno));
  }
  return bound;
}

void HttpServer::set_limits(const HttpLimits& limits) {
  limits_ = limits;
  set_payload_max_length(limits_.max_body_bytes);
}

HttpCounters HttpServer::counters() const {
  return {open_.load(), refused_.load(), timed_out_.load()};
}

HttpServer::RequestFault HttpServer::CurrentFault() {
  return t_stream ? t_stream->fault() : RequestFault::kNone;
}

std::pair<int, std::string> HttpServer::FaultAnswer(RequestFault fault, const HttpLimits& limits) {
  switch (fault) {
    case RequestFault::kNone:
      break;
    case RequestFault::kTimedOut:
      return {408, "request: not received whole within " + Seconds(limits.request_deadline) +
                       " of its first byte"};
    case RequestFault::kRequestLineTooLong:
      return {414, "request line: longer than " + std::to_string(limits.max_request_line_bytes) +
                       " bytes"};
    case RequestFault::kHeaderTooLarge:
      return {431, "header: larger than " + std::to_string(limits.max_header_bytes) + " bytes"};
    case RequestFault::kTooManyHeaderLines:
      return {431, "header: more than " + std::to_string(limits.max_header_lines) + " fields"};
    case RequestFault::kBodyTooLarge:
      return {413, "body: larger than " + std::to_string(limits.max_body_bytes) + " bytes"};
    case RequestFault::kAmbiguousFraming:
      return {400, "header: where the body ends is ambiguous"};
  }
  return {500, "request: no fault"};
}

std::string HttpServer::AmbiguousFraming(const httplib::Request& req) {
  const size_t lengths = req.get_header_value_count("Content-Length");
  const size_t encodings = req.get_header_value_count("Transfer-Encoding");
  if (lengths > 1) return "Content-Length: given " + std::to_string(lengths) + " times";
  if (encodings > 1) return "Transfer-Encoding: given " + std::to_string(encodings) + " times";
  if (encodings == 1) {
    if (strcasecmp(req.get_header_value("Transfer-Encoding").c_str(), "chunked") != 0)
      return "Transfer-Encoding: only chunked is taken";
    if (lengths == 1) return "Content-Length: given with Transfer-Encoding";
  }
  return "";
}

std::string HttpServer::Admit(const std::string& address) {
  std::lock_guard lock(mutex_);
  if (open_ >= static_cast<uint64_t>(limits_.max_connections_total)) {
    ++refused_;
    return "connections: " + std::to_string(limits_.max_connections_total) +
           " are open already (the limit in total)";
  }
  int& open = open_by_address_[address];
  if (open >= limits_.max_connections_per_client) {
    if (open == 0) open_by_address_.erase(address);
    ++refused_;
    return "connections: " + std::to_string(limits_.max_connections_per_client) +
           " are open from " + address + " already (the limit per client address)";
  }
  ++open;
  ++open_;
  return "";
}

void HttpServer::CountApart() {
  if (t_server == nullptr || t_counted_apart) return;
  t_server->Release(*t_address);
  t_counted_apart = true;
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
  if (const std::string refused = Admit(address); !refused.empty()) {
    Log("station.control")->debug("{}:{}: refused, {}", address, port, refused);
    Refuse(sock, refused);
    return false;
  }
  t_server = this;
  t_address = &address;
  t_counted_apart = false;
  ConnectionStream stream(
      sock, svr_sock_,
      std::chrono::seconds(read_timeout_sec_) + std::chrono::microseconds(read_timeout_usec_),
      std::chrono::seconds(write_timeout_sec_) + std::chrono::microseconds(write_timeout_usec_),
      limits_);
  t_stream = &stream;
  bool ret = false;
  bool refused = false;  // the last request broke a limit: the connection closes after its answer
  // cpp-httplib's keep-alive loop (detail::process_server_socket_core), with the deadline.
  for (size_t left = keep_alive_max_count_; left > 0 && svr_sock_ != INVALID_SOCKET; --left) {
    if (!stream.WaitForRequest(std::chrono::seconds(keep_alive_timeout_sec_))) break;
    stream.BeginRequest(Clock::now() + limits_.request_deadline);
    bool connection_closed = false;
    ret = process_request(stream, left == 1, connection_closed,
                          [&stream](httplib::Request& req) { stream.HeaderIn(req); });
    if (stream.fault() != RequestFault::kNone) {
      refused = true;
      if (stream.fault() == RequestFault::kTimedOut) ++timed_out_;
      const auto [status, message] = FaultAnswer(stream.fault(), limits_);
      // Refused before its request line was read whole, the request got no answer from
      // cpp-httplib: it gets its own here.
      if (stream.written() == 0) SendError(sock, status, ReasonPhrase(status), message);
      Log("station.control")->debug("{}:{}: closed, {} ({})", address, port, message, status);
      break;
    }
    // A stream counted apart ends its connection: a next request would be counted nowhere.
    if (!ret || connection_closed || t_counted_apart) break;
  }
  t_stream = nullptr;
  Close(sock, refused);
  if (!t_counted_apart) Release(address);
  t_server = nullptr;
  t_address = nullptr;
  t_counted_apart = false;
  return ret;
}

}  // namespace ss
