// OctoMap side of the dynamic-octree benchmark: the same workloads as
// crates/tesseral/benches/dynamic.rs (same generator, same cells, same order).
// Prints lines "RESULT octomap <workload> <measure> <value>".
#include <octomap/OcTree.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

struct Cell { int64_t x, y, z; };

struct SplitMix64 {
  uint64_t s;
  explicit SplitMix64(uint64_t seed) : s(seed) {}
  uint64_t next() {
    s += 0x9E3779B97F4A7C15ULL;
    uint64_t z = s;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // A cell in [-256, 256)^3: 9 random bits per axis, x then y then z.
  Cell cell() {
    int64_t x = int64_t(next() >> 55) - 256;
    int64_t y = int64_t(next() >> 55) - 256;
    int64_t z = int64_t(next() >> 55) - 256;
    return {x, y, z};
  }
};

static std::vector<Cell> random_cells(uint64_t seed, size_t n) {
  SplitMix64 r(seed);
  std::vector<Cell> v;
  v.reserve(n);
  for (size_t i = 0; i < n; ++i) v.push_back(r.cell());
  return v;
}

// Cells whose centre lies at distance [200, 230) from the origin, in z, y, x order.
static std::vector<Cell> shell_cells() {
  std::vector<Cell> v;
  const int64_t lo = 4 * 200 * 200, hi = 4 * 230 * 230;
  for (int64_t z = -256; z < 256; ++z)
    for (int64_t y = -256; y < 256; ++y)
      for (int64_t x = -256; x < 256; ++x) {
        int64_t d = (2 * x + 1) * (2 * x + 1) + (2 * y + 1) * (2 * y + 1) + (2 * z + 1) * (2 * z + 1);
        if (d >= lo && d < hi) v.push_back({x, y, z});
      }
  return v;
}

// The first min(n, 1M) cells of a Fisher-Yates shuffle with seed 3.
static std::vector<Cell> occupied_queries(std::vector<Cell> v) {
  SplitMix64 r(3);
  for (size_t i = v.size() - 1; i >= 1; --i) std::swap(v[i], v[r.next() % (i + 1)]);
  if (v.size() > 1000000) v.resize(1000000);
  return v;
}

static double now_ns() {
  return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static long rss_bytes() {
  std::ifstream f("/proc/self/statm");
  long size = 0, res = 0;
  f >> size >> res;
  return res * sysconf(_SC_PAGESIZE);
}

static octomap::point3d centre(const Cell& c) {
  return octomap::point3d(float(c.x) + 0.5f, float(c.y) + 0.5f, float(c.z) + 0.5f);
}

static void run(const char* name, const std::vector<Cell>& cells, size_t stored) {
  const std::vector<Cell> rq = random_cells(2, 1000000);
  const std::vector<Cell> oq = occupied_queries(cells);
  printf("RESULT octomap %s cells %zu\n", name, cells.size());
  printf("RESULT octomap %s stored %zu\n", name, stored);

  // insert with updateNode(point3d, true): the call the issue quotes.
  long rss0 = rss_bytes();
  auto* tree = new octomap::OcTree(1.0);
  double t0 = now_ns();
  for (const Cell& c : cells) tree->updateNode(centre(c), true);
  double t1 = now_ns();
  long rss1 = rss_bytes();
  printf("RESULT octomap %s insert_ns %.1f\n", name, (t1 - t0) / cells.size());

  // insert with updateNode(key, true): the cheaper key-based call, for reference.
  {
    octomap::OcTree t2(1.0);
    double a = now_ns();
    for (const Cell& c : cells) t2.updateNode(t2.coordToKey(centre(c)), true);
    double b = now_ns();
    printf("RESULT octomap %s insert_key_ns %.1f\n", name, (b - a) / cells.size());
  }

  // lookups with search(point3d)
  size_t hits = 0;
  double a = now_ns();
  for (const Cell& c : rq) {
    octomap::OcTreeNode* n = tree->search(centre(c));
    hits += (n != nullptr && tree->isNodeOccupied(n));
  }
  double b = now_ns();
  printf("RESULT octomap %s lookup_random_ns %.1f\n", name, (b - a) / rq.size());
  printf("RESULT octomap %s lookup_random_hits %zu\n", name, hits);
  hits = 0;
  a = now_ns();
  for (const Cell& c : oq) {
    octomap::OcTreeNode* n = tree->search(centre(c));
    hits += (n != nullptr && tree->isNodeOccupied(n));
  }
  b = now_ns();
  printf("RESULT octomap %s lookup_occupied_ns %.1f\n", name, (b - a) / oq.size());
  printf("RESULT octomap %s lookup_occupied_hits %zu\n", name, hits);

  size_t mem = tree->memoryUsage();
  size_t leaves = tree->getNumLeafNodes();
  printf("RESULT octomap %s leaves %zu\n", name, leaves);
  printf("RESULT octomap %s bytes %zu\n", name, mem);
  printf("RESULT octomap %s bytes_per_voxel %.2f\n", name, double(mem) / stored);
  printf("RESULT octomap %s bytes_per_leaf %.2f\n", name, double(mem) / leaves);
  printf("RESULT octomap %s rss_bytes_per_voxel %.2f\n", name, double(rss1 - rss0) / stored);
  delete tree;
}

int main() {
  std::vector<Cell> random = random_cells(1, 1000000);
  // Duplicates are kept in the insert stream (both sides insert the same 1M calls);
  // "cells" for bytes per voxel is the number of distinct cells.
  std::vector<Cell> distinct = random;
  std::sort(distinct.begin(), distinct.end(), [](const Cell& p, const Cell& q) {
    return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z < q.z;
  });
  distinct.erase(std::unique(distinct.begin(), distinct.end(), [](const Cell& p, const Cell& q) {
    return p.x == q.x && p.y == q.y && p.z == q.z;
  }), distinct.end());
  run("random", random, distinct.size());
  std::vector<Cell> shell = shell_cells();
  run("shell", shell, shell.size());
  return 0;
}
