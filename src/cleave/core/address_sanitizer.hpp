#pragma once
// Whether this translation unit is built with AddressSanitizer (GCC: __SANITIZE_ADDRESS__, clang:
// __has_feature(address_sanitizer)). ASan brings its own allocator, so the allocator tuning and
// the checks of it step aside under it.
#if defined(__SANITIZE_ADDRESS__)
#define CLEAVE_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CLEAVE_ADDRESS_SANITIZER 1
#endif
#endif

namespace cleave {

#if defined(CLEAVE_ADDRESS_SANITIZER)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif

}  // namespace cleave
