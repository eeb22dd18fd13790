// Gzipped inputs (internal/atomic_file.h, RegularFileReader; issue 39): a gzip file reads
// as its content whatever its name, concatenated members one after the other, and a
// truncated, corrupt or endlessly inflating file is refused by name; every reader (a
// dataset, a pose file) takes it.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "fastcal/dataset.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

// `text` as one gzip member (zlib's deflate with the gzip wrapper).
std::string Gzip(const std::string& text) {
  z_stream s{};
  EXPECT_EQ(deflateInit2(&s, Z_BEST_SPEED, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&s, text.size()), '\0');
  s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  s.avail_in = static_cast<uInt>(text.size());
  s.next_out = reinterpret_cast<Bytef*>(out.data());
  s.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&s, Z_FINISH), Z_STREAM_END);
  out.resize(s.total_out);
  deflateEnd(&s);
  return out;
}

class GzipReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fastcal_gzip_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  fs::path dir_;
};

// Text of a few MiB that does not compress to nothing (seeded digits).
std::string SomeText(size_t bytes) {
  std::mt19937 rng(7);
  std::string text;
  while (text.size() < bytes) text += std::to_string(rng()) + (rng() % 8 == 0 ? "\n" : ",");
  return text;
}

TEST_F(GzipReaderTest, ReadsTheContentWhateverTheName) {
  constexpr long long kLimit = 1LL << 30;
  const std::string text = SomeText(3 << 20);  // several 1 MiB reads, several members' worth
  std::string back, error;
  ASSERT_TRUE(internal::ReadRegularFile(Write("a.csv", Gzip(text)), kLimit, "dataset", &back,
                                        &error))
      << error;
  EXPECT_EQ(back, text);
  // Two members, as `cat a.gz b.gz` makes: both, in order.
  const std::string half = text.substr(0, text.size() / 2), rest = text.substr(text.size() / 2);
  ASSERT_TRUE(internal::ReadRegularFile(Write("b.gz", Gzip(half) + Gzip(rest)), kLimit,
                                        "dataset", &back, &error))
      << error;
  EXPECT_EQ(back, text);
  // A plain file is read as it is.
  ASSERT_TRUE(internal::ReadRegularFile(Write("c.csv", text), kLimit, "dataset", &back, &error));
  EXPECT_EQ(back, text);
}

TEST_F(GzipReaderTest, TruncatedCorruptAndInflatingFilesAreRefusedByName) {
  constexpr long long kLimit = 1LL << 30;
  const std::string gz = Gzip(SomeText(1 << 20));
  std::string back, error;
  EXPECT_FALSE(internal::ReadRegularFile(Write("t.csv.gz", gz.substr(0, gz.size() / 2)), kLimit,
                                         "dataset", &back, &error));
  EXPECT_NE(error.find("t.csv.gz: truncated gzip file"), std::string::npos) << error;
  std::string corrupt = gz;
  for (size_t i = gz.size() / 3; i < gz.size() / 3 + 64; ++i) corrupt[i] = static_cast<char>(~corrupt[i]);
  EXPECT_FALSE(internal::ReadRegularFile(Write("x.csv.gz", corrupt), kLimit, "dataset", &back,
                                         &error));
  EXPECT_NE(error.find("x.csv.gz: not a valid gzip file (zlib:"), std::string::npos) << error;
  // 64 MiB of zeros gzip to ~64 kB: under a 1 MiB limit it is refused as it inflates.
  const std::string bomb = Gzip(std::string(64 << 20, '\0'));
  ASSERT_LT(bomb.size(), 1u << 20);
  EXPECT_FALSE(internal::ReadRegularFile(Write("z.gz", bomb), 1 << 20, "pose", &back, &error));
  EXPECT_NE(error.find("z.gz: decompressed, it is larger than the limit for a pose file"),
            std::string::npos)
      << error;
}

TEST_F(GzipReaderTest, DatasetsAndPoseFilesReadGzipped) {
  const std::string csv =
      "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n"
      "0,70.96,4.65,156.73,0.35,-5.3,0.09,214,190.2,141.8,149.9,188.6,207.1\n"
      "1,70.96,4.65,156.73,0.35,-5.3,0.09,214,190.2,141.8,149.9,188.6,207.2\n";
  Dataset plain, gzipped;
  std::string error;
  ASSERT_TRUE(ReadDataset(Write("d.csv", csv), DatasetReadOptions(), &plain, &error)) << error;
  ASSERT_TRUE(ReadDataset(Write("d.csv.gz", Gzip(csv)), DatasetReadOptions(), &gzipped, &error)) << error;
  ASSERT_EQ(gzipped.samples.size(), plain.samples.size());
  EXPECT_EQ(gzipped.samples[1].tension_n, plain.samples[1].tension_n);
  std::vector<Pose> poses;
  ASSERT_TRUE(ReadPosesCsv(Write("p.csv.gz", Gzip("x_m,y_m,z_m\n0,0,150\n")), &poses, nullptr,
                           &error))
      << error;
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].position_m.z(), 150.0);
}

}  // namespace
}  // namespace fastcal
