#pragma once
// The station's HTTP server: cpp-httplib's, with two limits its 0.11 (Debian 12's) lacks
// (docs/daemon.md, "Limits of the HTTP server"):
//  - connections per client address and in total: a connection beyond
//    `max_connections_per_client` open from the same address, or beyond `max_connections_total`
//    open in all, is answered 503 and closed at once, so that one client cannot hold every
//    HTTP thread, and many (an IPv6 client's many addresses) get an answer rather than a wait
//    for a thread. A long stream (the console's event stream) is counted apart once its route
//    says so (CountApart), under that route's own limit: an open console costs no request slot;
//  - a deadline for each request: its request line, header and body must have arrived within
//    `request_deadline` of its first byte, else the connection is closed (with a 408 when the
//    request line was in). cpp-httplib restarts its read timeout with every byte, so without
//    it a client that trickles its header a byte at a time held a thread for ever. Once the
//    request is in, the deadline no longer applies: an event stream or a download takes as long
//    as it needs (the write timeout still drops a reader that stalls). Between requests of a
//    keep-alive connection the keep-alive timeout applies, as before;
//  - the request line at most `max_request_line_bytes` (else 414), the request line and header
//    together at most `max_header_bytes` in at most `max_header_lines` lines (cpp-httplib
//    limits each line, not their number; else 431); either way the connection is closed;
//  - a body at most `max_body_bytes` as sent, however it is framed (Content-Length, chunked,
//    multipart, or read until the client closes): counted while it is read, and the read
//    fails the byte it passes the limit (a declared Content-Length over it at once), so the
//    answer is a 413 and the connection is closed; cpp-httplib 0.11 checks a Content-Length
//    only, and reads a chunked body whole into memory, however large;
//  - a request whose framing is ambiguous (Content-Length twice, or with Transfer-Encoding; a
//    Transfer-Encoding other than chunked) is answered 400 and the connection closed, since
//    where its body ends cannot be known (request smuggling).
// A request refused before cpp-httplib could read its request line (too long, or not in by
// the deadline) gets its answer here, as a JSON error; cpp-httplib would send none.
// It replaces the server's connection loop (Server::process_and_close_socket, the one virtual
// step between accept and the request; the base's is private, so it cannot be wrapped): its
// own keep-alive loop over its own Stream, which reads under the deadline, and cpp-httplib's
// process_request for everything else. Timeouts and keep-alive come from the usual setters.
//
// Include after any Eigen header (<resolv.h>, through httplib, defines `_res`).
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>

#include <httplib.h>

namespace ss {

struct HttpLimits {
  int max_connections_per_client = 64;  // open at once from one address
  int max_connections_total = 512;  // open at once in all: fewer than the threads, so some refuse
  std::chrono::milliseconds request_deadline{10'000};  // first byte of a request -> all of it read
  size_t max_request_line_bytes = 8 << 10;  // "GET /path?query HTTP/1.1" (cpp-httplib's URI limit)
  size_t max_header_bytes = 64 << 10;       // request line and header together
  int max_header_lines = 100;               // header fields, the request line aside
  size_t max_body_bytes = 1 << 20;          // as sent: chunk framing counts
};

struct HttpCounters {
  uint64_t connections_open = 0;     // served now (a connection waiting for a thread is not)
  uint64_t connections_refused = 0;  // over the per-client or total limit, since start
  uint64_t requests_timed_out = 0;   // not in whole by the deadline, since start
};

class HttpServer : public httplib::Server {
 public:
  explicit HttpServer(HttpLimits limits = {});

  // Binds to `host`:`port` (0: any free port) and listens with a backlog of `backlog`
  // connections not yet accepted; the port bound, or -1. cpp-httplib listens with 5
  // (CPPHTTPLIB_LISTEN_BACKLOG, compiled into Debian's libcpp-httplib): 32 clients connecting at
  // once lost SYNs and each waited the kernel's 1 s retransmit. listen_after_bind() serves it.
  int Bind(const std::string& host, int port, int backlog = 128);

  const HttpLimits& limits() const { return limits_; }
  // Before listening only.
  void set_limits(const HttpLimits& limits);
  HttpCounters counters() const;

  // Why the request served on the calling thread could not be read whole, for the error
  // handler to name the limit (cpp-httplib answers any header cut short with a bare 400).
  enum class RequestFault {
    kNone,
    kTimedOut,
    kRequestLineTooLong,
    kHeaderTooLarge,
    kTooManyHeaderLines,
    kBodyTooLarge,
    kAmbiguousFraming,
  };
  static RequestFault CurrentFault();
  // The answer to a request with `fault`: its status and the error's text, naming the limit.
  static std::pair<int, std::string> FaultAnswer(RequestFault fault, const HttpLimits& limits);
  // Why the framing of `req`'s body cannot be trusted ("" when it can): Content-Length given
  // twice or beside Transfer-Encoding, or a Transfer-Encoding other than chunked.
  static std::string AmbiguousFraming(const httplib::Request& req);
  // Called by a route on the thread serving its request: this connection is a long stream
  // limited by the route itself (the event stream), no longer counted in the connection
  // limits; it is closed once the request ends. No effect outside a request.
  static void CountApart();

 private:
  bool process_and_close_socket(socket_t sock) override;
  // Counts a connection from `address` in; "" when admitted, else the 503's text (and the
  // connection counted as refused).
  std::string Admit(const std::string& address);
  void Release(const std::string& address);

  HttpLimits limits_;
  std::mutex mutex_;
  std::unordered_map<std::string, int> open_by_address_;  // guarded by mutex_
  std::atomic<uint64_t> open_{0}, refused_{0}, timed_out_{0};
};

}  // namespace ss
