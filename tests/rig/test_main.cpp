// Entry point of the rig test binaries: umockdev intercepts device access through an LD_PRELOAD
// library, so the binary re-executes itself with it when started without (plain ./test_rig, ctest,
// gtest discovery all work the same).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

int main(int argc, char** argv) {
  const char* preload = std::getenv("LD_PRELOAD");
  if (!preload || !std::strstr(preload, "libumockdev-preload")) {
    std::string value = "libumockdev-preload.so.0";
    if (preload && *preload) value += std::string(":") + preload;
    setenv("LD_PRELOAD", value.c_str(), 1);
    // The testbed's ioctl sockets live under TMPDIR; a long one overflows sun_path (108 bytes).
    const char* tmp = std::getenv("TMPDIR");
    if (!tmp || std::strlen(tmp) > 24) setenv("TMPDIR", "/tmp", 1);
    // The preload library comes before the ASan runtime in sanitizer builds.
    std::string asan = std::getenv("ASAN_OPTIONS") ? std::getenv("ASAN_OPTIONS") : "";
    setenv("ASAN_OPTIONS", (asan.empty() ? "" : asan + ":").append("verify_asan_link_order=0").c_str(), 1);
    execv("/proc/self/exe", argv);
    std::perror("re-executing under libumockdev-preload.so.0");
    return 1;
  }
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
