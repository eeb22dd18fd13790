// Reading telemetry through a column map against the canonical reader (column_map.h,
// docs/data-format.md, "Column maps"): the same N samples written twice into /tmp, once
// as the canonical CSV, once as a telescope's export (a title line and a unit row, ';'
// and decimal commas, ISO 8601 time stamps in Beijing time without a zone, positions in
// mm, tensions in N, the planned attitude, two channels fastcal does not read), each read
// by ReadDataset on two threads as the command line reads them (best wall time of
// several rounds, each reading every file once; wall and CPU time). Also: the export with Unix milliseconds instead of ISO time stamps, and
// the canonical file through an identity map, and the canonical file gzipped (zlib level 6,
// as gzip writes it), read by content (internal/atomic_file.h).
// Run: build/bench/dataset_read_bench [samples, default 1000000] [rounds, default 5]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <unistd.h>
#include <zlib.h>

#include "fastcal/column_map.h"
#include "fastcal/dataset.h"

namespace {

namespace fs = std::filesystem;

// The decimal text of `value` with `decimals` digits, the point made `mark`.
std::string Num(double value, int decimals, char mark = '.') {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  std::string s = buffer;
  if (mark != '.') {
    for (char& c : s) {
      if (c == '.') c = mark;
    }
  }
  return s;
}

struct Files {
  std::string canonical, iso, unix_ms;
};

Files Write(long long samples, const fs::path& dir) {
  Files f{(dir / "canonical.csv").string(), (dir / "export_iso.csv").string(),
          (dir / "export_unix_ms.csv").string()};
  std::ofstream canonical(f.canonical), iso(f.iso), ms(f.unix_ms);
  canonical << "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,planned_roll_deg,planned_pitch_"
               "deg,planned_yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n";
  const std::string names =
      "SDP_PhaPos_X;SDP_PhaPos_Y;SDP_PhaPos_Z;SDP_SwtDPose_Y;SDP_SwtDPose_P;SDP_SwtDPose_R;"
      "TRP_SwtDPose_Y;TRP_SwtDPose_P;TRP_SwtDPose_R;CableForce1;CableForce2;CableForce3;"
      "CableForce4;CableForce5;CableForce6;WindSpeed;AirTemp\n";
  const std::string units = ";mm;mm;mm;deg;deg;deg;deg;deg;deg;N;N;N;N;N;N;m/s;degC\n";
  iso << "FAST feed cabin telemetry\nSysTime;" << names << "(Beijing time)" << units;
  ms << "FAST feed cabin telemetry\nSysTime;" << names << "(ms)" << units;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr long long kStart = 1714564800;  // 2024-05-01T20:00:00+08:00
  for (long long k = 0; k < samples; ++k) {
    const double t = 0.1 * static_cast<double>(k);  // 10 Hz
    const double x = 60.0 * u(rng), y = 60.0 * u(rng), z = 150.0 + 5.0 * u(rng);
    double angle[6], tension[6];
    for (double& a : angle) a = 3.0 * u(rng);
    for (double& T : tension) T = 180.0 + 40.0 * u(rng);
    canonical << Num(t, 1) << "," << Num(x, 4) << "," << Num(y, 4) << "," << Num(z, 4);
    for (double a : angle) canonical << "," << Num(a, 4);
    for (double T : tension) canonical << "," << Num(T, 3);
    canonical << "\n";
    // The same numbers as the export writes them.
    const long long ms_since = kStart * 1000 + k * 100;
    const long long local_s = ms_since / 1000 + 8 * 3600;
    const long long day = local_s / 86400, second = local_s % 86400;
    const std::string fields = ";" + Num(x * 1e3, 1, ',') + ";" + Num(y * 1e3, 1, ',') + ";" +
                               Num(z * 1e3, 1, ',') + ";" + Num(angle[2], 4, ',') + ";" +
                               Num(angle[1], 4, ',') + ";" + Num(angle[0], 4, ',') + ";" +
                               Num(angle[5], 4, ',') + ";" + Num(angle[4], 4, ',') + ";" +
                               Num(angle[3], 4, ',');
    std::string forces;
    for (double T : tension) forces += ";" + Num(T * 1e3, 0, ',');
    const std::string extra = ";" + Num(2.0 + u(rng), 2, ',') + ";18,5\n";
    char stamp[64];
    // 2024-05-01 is day 19844 since the epoch; the survey stays within 2024-05.
    std::snprintf(stamp, sizeof(stamp), "2024-05-%02lld %02lld:%02lld:%02lld.%03lld",
                  1 + (day - 19844), second / 3600, second / 60 % 60, second % 60,
                  ms_since % 1000);
    iso << stamp << fields << forces << extra;
    ms << ms_since << fields << forces << extra;
  }
  return f;
}

// `path` gzipped to path + ".gz" (level 6, gzip's default).
std::string Gzipped(const std::string& path) {
  const std::string out = path + ".gz";
  gzFile gz = gzopen(out.c_str(), "wb6");
  std::ifstream in(path, std::ios::binary);
  std::vector<char> buffer(1 << 20);
  while (in.read(buffer.data(), static_cast<std::streamsize>(buffer.size())) || in.gcount() > 0) {
    if (gz == nullptr || gzwrite(gz, buffer.data(), static_cast<unsigned>(in.gcount())) <= 0) {
      std::fprintf(stderr, "cannot write %s\n", out.c_str());
      std::exit(1);
    }
  }
  gzclose(gz);
  return out;
}

std::string MapText(const std::string& time) {
  return "format: fastcal-columns-1\ndecimal: \",\"\nheader_line: 2\nskip_after_header: 1\n"
         "time: " +
         time +
         "\ncolumns:\n"
         "  x_m: {column: SDP_PhaPos_X, unit: mm}\n  y_m: {column: SDP_PhaPos_Y, unit: mm}\n"
         "  z_m: {column: SDP_PhaPos_Z, unit: mm}\n  yaw_deg: SDP_SwtDPose_Y\n"
         "  pitch_deg: SDP_SwtDPose_P\n  roll_deg: SDP_SwtDPose_R\n"
         "  planned_yaw_deg: TRP_SwtDPose_Y\n  planned_pitch_deg: TRP_SwtDPose_P\n"
         "  planned_roll_deg: TRP_SwtDPose_R\n"
         "  T1_kN: {column: CableForce1, unit: N}\n  T2_kN: {column: CableForce2, unit: N}\n"
         "  T3_kN: {column: CableForce3, unit: N}\n  T4_kN: {column: CableForce4, unit: N}\n"
         "  T5_kN: {column: CableForce5, unit: N}\n  T6_kN: {column: CableForce6, unit: N}\n"
         "unmapped: ignore\n";
}

std::shared_ptr<const fastcal::ColumnMap> Map(const std::string& text) {
  auto map = std::make_shared<fastcal::ColumnMap>();
  std::string error;
  if (!fastcal::ParseColumnMap(text, "bench map", map.get(), &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    std::exit(1);
  }
  return map;
}

struct Timing {
  double wall = 1e300, cpu = 1e300;  // best of the reads, seconds
};

// One read of `path` (through `map` when not null), keeping the best wall and CPU time.
void Read(const std::string& path, std::shared_ptr<const fastcal::ColumnMap> map,
          long long samples, Timing* timing) {
  fastcal::DatasetReadOptions options;
  options.threads = 2;
  options.columns = map;
  fastcal::Dataset data;
  std::string error;
  const std::clock_t cpu = std::clock();
  const auto start = std::chrono::steady_clock::now();
  if (!fastcal::ReadDataset(path, options, &data, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    std::exit(1);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  timing->wall = std::min(timing->wall, wall);
  timing->cpu = std::min(timing->cpu, static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC);
  if (static_cast<long long>(data.samples.size()) != samples) std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  const long long samples = argc > 1 ? std::atoll(argv[1]) : 1000000;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  const fs::path dir = fs::temp_directory_path() / ("fastcal_dataset_read_bench_" +
                                                    std::to_string(::getpid()));
  fs::create_directories(dir);
  const Files f = Write(samples, dir);
  const std::string identity =
      "format: fastcal-columns-1\ntime: time_s\ncolumns:\n  x_m: x_m\n  y_m: y_m\n  z_m: z_m\n"
      "  roll_deg: roll_deg\n  pitch_deg: pitch_deg\n  yaw_deg: yaw_deg\n"
      "  planned_roll_deg: planned_roll_deg\n  planned_pitch_deg: planned_pitch_deg\n"
      "  planned_yaw_deg: planned_yaw_deg\n  T1_kN: T1_kN\n  T2_kN: T2_kN\n  T3_kN: T3_kN\n"
      "  T4_kN: T4_kN\n  T5_kN: T5_kN\n  T6_kN: T6_kN\n";
  struct Case {
    const char* name;
    std::string path;
    std::shared_ptr<const fastcal::ColumnMap> map;
    Timing timing;
  };
  std::vector<Case> cases = {
      {"canonical CSV", f.canonical, nullptr, {}},
      {"canonical CSV through an identity map", f.canonical, Map(identity), {}},
      {"canonical CSV gzipped (.csv.gz)", Gzipped(f.canonical), nullptr, {}},
      {"export through a map: ISO 8601 (+08:00), mm, N, ';' and ','", f.iso,
       Map(MapText("{column: SysTime, format: iso8601, zone: \"+08:00\"}")), {}},
      {"export through a map: unix_ms, mm, N, ';' and ','", f.unix_ms,
       Map(MapText("{column: SysTime, format: unix_ms}")), {}}};
  // Rounds of one read of each, so that a machine busy with other work slows all alike.
  for (int r = 0; r < repeats; ++r) {
    for (Case& c : cases) Read(c.path, c.map, samples, &c.timing);
  }
  std::printf("reading %lld samples on 2 threads, ReadDataset, best of %d rounds:\n", samples,
              repeats);
  std::printf("  %-60s %8s %8s %7s %7s\n", "", "wall s", "cpu s", "us/row", "cpu x");
  for (const Case& c : cases) {
    std::printf("  %-60s %8.3f %8.3f %7.2f %7.2f\n", c.name, c.timing.wall, c.timing.cpu,
                1e6 * c.timing.wall / samples, c.timing.cpu / cases[0].timing.cpu);
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
  return 0;
}
