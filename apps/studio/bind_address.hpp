#pragma once
// Where the studio listens. Loopback (127.0.0.1) unless the user names another address with
// --host: the studio exposes the session folder and must not open the machine to others by
// accident.
#include <string>

namespace cleave::studio {

enum class HostOrigin {
  default_loopback,  ///< no --host given: must be a loopback address
  explicit_flag,     ///< the user typed --host ADDR: any address is allowed (with a warning)
};

inline constexpr const char* kDefaultHost = "127.0.0.1";

/// True for 127.0.0.0/8, ::1 and "localhost".
bool is_loopback_address(const std::string& host);

/// Throws InputError "--host '<h>' ..." for an address that is not an IPv4/IPv6 literal or
/// "localhost", or for a non-loopback address that did not come from an explicit --host.
/// Returns the numeric address to bind.
std::string checked_bind_address(const std::string& host, HostOrigin origin);

}  // namespace cleave::studio
