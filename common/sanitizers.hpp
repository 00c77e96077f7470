#pragma once
// Which sanitizer this translation unit is built with, the same under GCC (which defines
// __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__) and clang (which answers __has_feature instead).
// Used where a sanitizer changes what is possible (ASan reserves terabytes of shadow address space,
// so no address-space limit) or what a test can afford (a sanitized run is several times slower).

#if defined(__SANITIZE_ADDRESS__)
#define MUFRIC_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MUFRIC_ADDRESS_SANITIZER 1
#endif
#endif
#ifndef MUFRIC_ADDRESS_SANITIZER
#define MUFRIC_ADDRESS_SANITIZER 0
#endif

#if defined(__SANITIZE_THREAD__)
#define MUFRIC_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define MUFRIC_THREAD_SANITIZER 1
#endif
#endif
#ifndef MUFRIC_THREAD_SANITIZER
#define MUFRIC_THREAD_SANITIZER 0
#endif
