// Tests of the file digest (file_digest.h): the FIPS 180-4 test vectors, files larger
// than one read, binary bytes, and agreement with sha256sum, which is what a person checks
// summary.json's provenance with.
#include "fastcal/file_digest.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bounded_process.h"
#include "temp_path.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

class FileDigestTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(test::TempPath("fastcal_file_digest_test"));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  fs::path dir_;
};

std::string Sha256(const std::string& path) {
  std::string hex, error;
  EXPECT_TRUE(FileSha256(path, &hex, &error)) << error;
  return hex;
}

TEST_F(FileDigestTest, FipsTestVectors) {
  EXPECT_EQ(Sha256(Write("empty", "")),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256(Write("abc", "abc")),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256(Write("two_blocks", "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // A million 'a': many reads of the file.
  EXPECT_EQ(Sha256(Write("million", std::string(1000000, 'a'))),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// What `sha256sum FILE` prints before the file name, for a file with every byte value.
TEST_F(FileDigestTest, AgreesWithSha256sum) {
  std::string bytes;
  for (int repeat = 0; repeat < 300; ++repeat) {
    for (int b = 0; b < 256; ++b) bytes += static_cast<char>(b);
  }
  const std::string path = Write("binary", bytes);
  FILE* pipe = popen(("sha256sum '" + path + "' 2>/dev/null").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char line[256] = {};
  const bool read = std::fgets(line, sizeof(line), pipe) != nullptr;
  const int status = pclose(pipe);
  if (!read || status != 0) GTEST_SKIP() << "sha256sum (coreutils) is not available";
  EXPECT_EQ(Sha256(path), std::string(line).substr(0, 64));
}

// A prefix's digest is the digest of a file holding those bytes alone (a track's store
// checked up to its committed length, issue 37), across many reads; a file shorter than
// the prefix is an error naming both lengths.
TEST_F(FileDigestTest, APrefixDigestIsTheDigestOfThoseBytes) {
  const std::string bytes(200000, 'a');
  const std::string whole = Write("whole", bytes + "appended later");
  std::string hex, error;
  for (long long n : {0LL, 3LL, 65536LL, 65537LL, 200000LL}) {
    ASSERT_TRUE(FileSha256Prefix(whole, n, &hex, &error)) << error;
    EXPECT_EQ(hex, Sha256(Write("prefix", bytes.substr(0, n)))) << n << " bytes";
  }
  hex = "untouched";
  EXPECT_FALSE(FileSha256Prefix(whole, 300000, &hex, &error));
  EXPECT_NE(error.find("200014 bytes where 300000 were expected"), std::string::npos) << error;
  EXPECT_EQ(hex, "untouched");
  EXPECT_FALSE(FileSha256Prefix(whole, -1, &hex, &error));
}

TEST_F(FileDigestTest, MissingFileOrDirectoryIsAnErrorNamingIt) {
  std::string hex = "untouched", error;
  EXPECT_FALSE(FileSha256((dir_ / "absent.csv").string(), &hex, &error));
  EXPECT_NE(error.find("absent.csv: cannot open"), std::string::npos) << error;
  EXPECT_EQ(hex, "untouched");
  EXPECT_FALSE(FileSha256(dir_.string(), &hex, &error));
  EXPECT_NE(error.find(dir_.string() + ": is a directory"), std::string::npos) << error;
  EXPECT_FALSE(FileSha256((dir_ / "absent.csv").string(), &hex, nullptr));
}

// A device is refused before reading (issue 29: calibrate --data=/dev/zero hashed it on a
// thread of its own, which never ended, and the command never exited). In a child process
// under a time limit, so that a regression fails instead of hanging the suite.
void HashDevZeroAndExit() {
  test::LimitThisProcess();
  std::string hex, error;
  const bool refused = !FileSha256("/dev/zero", &hex, &error) &&
                       error.find("/dev/zero: not a regular file") != std::string::npos;
  std::exit(refused ? 0 : 1);
}

TEST(FileDigestDeathTest, ADeviceIsRefusedAtOnce) {
  if (!std::filesystem::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero";
  EXPECT_EXIT(HashDevZeroAndExit(), ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace fastcal
