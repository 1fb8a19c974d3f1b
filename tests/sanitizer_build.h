#pragma once
/// Whether this test binary runs under AddressSanitizer: heavy tests shrink their
/// loops there (ASan is about 20x slower) but keep every case they check.

namespace sahara::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

/// Ray counts are divided by this under ASan (roughly its slowdown), to keep tests short.
inline constexpr int kSanitizerDivisor = kSanitized ? 20 : 1;

}  // namespace sahara::test
