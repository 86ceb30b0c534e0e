// Path safety of static serving and save/load: nothing outside the given folder is reachable.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "cleave/core/error.hpp"
#include "studio/bind_address.hpp"
#include "studio/path_safety.hpp"

namespace cleave::studio {
namespace {

class PathSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    base = std::filesystem::temp_directory_path() / ("cleave-path-test-" + std::to_string(::getpid()));
    std::filesystem::remove_all(base);
    root = base / "root";
    std::filesystem::create_directories(root / "js");
    std::ofstream(root / "index.html") << "x";
    std::ofstream(base / "secret.txt") << "secret";
    std::filesystem::create_symlink(base / "secret.txt", root / "link-out.txt");
    std::filesystem::create_symlink(root / "index.html", root / "link-in.html");
  }
  void TearDown() override { std::filesystem::remove_all(base); }
  std::filesystem::path base, root;
};

TEST_F(PathSafety, PlainNamesInsideTheFolderResolve) {
  EXPECT_EQ(resolve_inside(root, "index.html"), std::filesystem::canonical(root) / "index.html");
  EXPECT_EQ(resolve_inside(root, "js/main.js"), std::filesystem::canonical(root) / "js/main.js");  // need not exist
  EXPECT_EQ(resolve_inside(root, "link-in.html"), std::filesystem::canonical(root) / "index.html");
}

TEST_F(PathSafety, TraversalAbsoluteAndOddNamesAreRefused) {
  for (const char* bad : {"../secret.txt", "js/../../secret.txt", "/etc/passwd", "", ".", "js/./main.js",
                          "..", "js/..", "a\\..\\b", "link-out.txt"})
    EXPECT_FALSE(resolve_inside(root, bad)) << bad;
  EXPECT_FALSE(resolve_inside(root, std::string("index.html\0.png", 15)));
  EXPECT_FALSE(resolve_inside(root, std::string(2000, 'a')));
}

TEST_F(PathSafety, RequireInsideNamesTheFileAndTheRule) {
  try {
    require_inside(root, "../x.json", "save: file");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "save: file '../x.json' is outside the session folder; expected a file name such as design.json");
  }
}

TEST(PercentDecode, DecodesEscapesAndRefusesMalformedOnes) {
  EXPECT_EQ(percent_decode("/a%20b"), "/a b");
  EXPECT_EQ(percent_decode("/%2e%2E/x"), "/../x");  // then refused by resolve_inside
  EXPECT_FALSE(percent_decode("/%2"));
  EXPECT_FALSE(percent_decode("/%zz"));
  EXPECT_FALSE(percent_decode("/%00"));
}

TEST(BindAddress, LoopbackByDefaultOthersOnlyWhenExplicit) {
  EXPECT_TRUE(is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(is_loopback_address("127.3.2.1"));
  EXPECT_TRUE(is_loopback_address("::1"));
  EXPECT_TRUE(is_loopback_address("localhost"));
  EXPECT_FALSE(is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(is_loopback_address("192.168.1.4"));
  EXPECT_EQ(checked_bind_address("localhost", HostOrigin::default_loopback), "127.0.0.1");
  EXPECT_THROW(checked_bind_address("0.0.0.0", HostOrigin::default_loopback), InputError);
  EXPECT_EQ(checked_bind_address("0.0.0.0", HostOrigin::explicit_flag), "0.0.0.0");
  try {
    checked_bind_address("example.org", HostOrigin::explicit_flag);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--host 'example.org': expected an IP address such as 127.0.0.1 or ::1");
  }
}

}  // namespace
}  // namespace cleave::studio
