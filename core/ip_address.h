#pragma once
// Whether a text is an IPv4 or IPv6 address (inet_pton), for config keys that take one: the
// control server's address and a GigE Vision camera's.
#include <arpa/inet.h>

#include <string>

namespace ss {

inline bool IsIpAddress(const std::string& text) {
  unsigned char buf[16];
  return inet_pton(AF_INET, text.c_str(), buf) == 1 || inet_pton(AF_INET6, text.c_str(), buf) == 1;
}

}  // namespace ss
