#include "studio/bind_address.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave::studio {
namespace {

constexpr unsigned kLoopbackFirstOctet = 127;

}  // namespace

bool is_loopback_address(const std::string& host) {
  if (host == "localhost" || host == "::1") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == kLoopbackFirstOctet;
  return false;
}

std::string checked_bind_address(const std::string& host, HostOrigin origin) {
  std::string numeric = host == "localhost" ? std::string(kDefaultHost) : host;
  in_addr v4{};
  in6_addr v6{};
  if (inet_pton(AF_INET, numeric.c_str(), &v4) != 1 && inet_pton(AF_INET6, numeric.c_str(), &v6) != 1)
    throw InputError(fmt::format("--host '{}': expected an IP address such as 127.0.0.1 or ::1", host.substr(0, 100)));
  if (!is_loopback_address(numeric) && origin != HostOrigin::explicit_flag)
    throw InputError(fmt::format("address '{}' is not loopback; the studio binds to other addresses only when told "
                                 "with --host",
                                 host));
  return numeric;
}

}  // namespace cleave::studio
