// The scan files written by `occupancy_peer gen` (per scan: origin as 3 x f64, point
// count as u64, points as 3 x f64, little-endian), and splitmix64, which draws the
// same lookup cells as the tesseral side.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <unistd.h>
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

// With LOOKUP_GATE=PATH and LOOKUP_TURNS=1 (run.sh's paired runs), the tools' loops
// take turns: loop k (from 0, the first timed one) waits for PATH.go (k = 0, see
// `lookup_gate`) or PATH.go<k>, and creates PATH.done<k> once timed, so that run.sh
// lets each tool's loop k run right after the others' loop k. Without, no waits.
inline const char* turn_gate() {
  const char* t = std::getenv("LOOKUP_TURNS");
  const char* g = std::getenv("LOOKUP_GATE");
  return t && std::string(t) == "1" && g && *g ? g : nullptr;
}

inline void touch(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) { std::perror(path.c_str()); std::exit(1); }
  std::fclose(f);
}

// Waits for loop k's turn (k >= 1: loop 0 waits in `lookup_gate`).
inline void turn_wait(int k) {
  const char* g = turn_gate();
  if (!g) return;
  std::string go = std::string(g) + ".go" + std::to_string(k);
  while (access(go.c_str(), F_OK) != 0) usleep(1000);
}

// Ends loop k's turn.
inline void turn_done(int k) {
  if (const char* g = turn_gate()) touch(std::string(g) + ".done" + std::to_string(k));
}

// Ends the first timed loop's turn, then loops over the lookups LOOKUP_LOOPS - 1 more
// times (default 5 loops in all), each in its turn (`turn_wait`; then the turn
// numbered LOOKUP_LOOPS for the rest of the run) after `before` (the keys read again,
// as before the first): each loop's process CPU ns per lookup, in order, so that a
// loop slowed by another process on the machine can be told from the tool's own
// time. `loop` runs the lookups once and returns the cells known.
template <class F, class G>
std::vector<double> repeat_lookups(F loop, size_t cells, G before) {
  const char* env = std::getenv("LOOKUP_LOOPS");
  int loops = env ? std::max(1, std::atoi(env)) : 5;
  std::vector<double> ns;
  turn_done(0);
  for (int i = 1; i < loops; i++) {
    turn_wait(i);
    before();
    double c = cpu_seconds();
    volatile size_t known = loop();
    (void)known;
    ns.push_back((cpu_seconds() - c) * 1e9 / double(cells));
    turn_done(i);
  }
  // The rest of the run (counting cells, exiting) in a turn of its own, after every
  // tool's loops, so that no tool's exit shares the core with another's work.
  turn_wait(loops);
  return ns;
}

// Appends `lookup_loops N lookup_min_cpu_ns X lookup_median_cpu_ns Y` (the first loop,
// `first_ns`, counted in) and `lookup_turns_cpu_ns A,B,...` (every loop in order, the
// first first) to a RESULT line.
inline void print_loops(const std::vector<double>& later, double first_ns) {
  std::vector<double> ns{first_ns};
  ns.insert(ns.end(), later.begin(), later.end());
  std::string turns;
  char one[32];
  for (double x : ns) {
    std::snprintf(one, sizeof one, "%s%.1f", turns.empty() ? "" : ",", x);
    turns += one;
  }
  std::sort(ns.begin(), ns.end());
  std::printf(" lookup_loops %zu lookup_min_cpu_ns %.1f lookup_median_cpu_ns %.1f lookup_turns_cpu_ns %s", ns.size(),
              ns.front(), ns[ns.size() / 2], turns.c_str());
}

// With LOOKUP_GATE=PATH (run.sh's paired runs): creates PATH.ready once the map is
// built and the cells drawn, then waits, idle, until PATH.go exists, so that the
// tools' lookups can be timed one right after another rather than minutes apart.
inline void lookup_gate() {
  const char* g = std::getenv("LOOKUP_GATE");
  if (!g || !*g) return;
  std::string base(g);
  touch(base + ".ready");
  while (access((base + ".go").c_str(), F_OK) != 0) usleep(10000);
}

// Reads a tool's keys before its lookups are timed (a byte of each cache line), so
// that no tool's loop streams its keys from memory: in the paired runs the other
// tools' work evicts them while one waits at its gate (occupancy_peer's `read_keys`
// does the same). The map is not touched.
template <class T>
void read_keys(const std::vector<T>& keys) {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(keys.data());
  size_t bytes = keys.size() * sizeof(T);
  unsigned long long s = 0;
  for (size_t i = 0; i < bytes; i += 64) s += p[i];
  asm volatile("" : : "r"(s));
}
