// The scan files written by `occupancy_peer gen` (per scan: origin as 3 x f64, point
// count as u64, points as 3 x f64, little-endian), and splitmix64, which draws the
// same lookup cells as the tesseral side.
#pragma once
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>

struct ScanFile {
  std::array<double, 3> origin;
  std::vector<std::array<double, 3>> points;
};

inline std::vector<ScanFile> read_scans(const char* path) {
  FILE* f = std::fopen(path, "rb");
  if (!f) { std::perror(path); std::exit(1); }
  std::vector<ScanFile> scans;
  double o[3];
  uint64_t n;
  while (std::fread(o, 8, 3, f) == 3) {
    if (std::fread(&n, 8, 1, f) != 1) { std::fprintf(stderr, "%s: truncated\n", path); std::exit(1); }
    ScanFile s;
    s.origin = {o[0], o[1], o[2]};
    s.points.resize(n);
    if (n && std::fread(s.points.data(), 24, n, f) != n) { std::fprintf(stderr, "%s: truncated\n", path); std::exit(1); }
    scans.push_back(std::move(s));
  }
  std::fclose(f);
  return scans;
}

struct SplitMix64 {
  uint64_t s;
  uint64_t next() {
    s += 0x9E3779B97F4A7C15ull;
    uint64_t z = s;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
};

// The process's CPU time in seconds.
inline double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}
