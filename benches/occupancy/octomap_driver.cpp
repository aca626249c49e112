// OctoMap's OcTree::insertPointCloud on the scans of `occupancy_peer gen` (the first
// LIMIT scans), then 10^6 random lookups with OcTree::search on keys computed before
// the clock (the cells the tesseral side draws).
// Usage: octomap_driver FILE MAX_RANGE [LIMIT]
#include <chrono>
#include <octomap/octomap.h>
#include "scans.hpp"

int main(int argc, char** argv) {
  if (argc < 3) { std::fprintf(stderr, "usage: octomap_driver FILE MAX_RANGE [LIMIT]\n"); return 2; }
  auto raw = read_scans(argv[1]);
  double max_range = std::atof(argv[2]);
  if (argc > 3 && size_t(std::atoi(argv[3])) < raw.size()) raw.resize(std::atoi(argv[3]));
  std::vector<octomap::Pointcloud> clouds(raw.size());
  size_t rays = 0;
  for (size_t i = 0; i < raw.size(); i++) {
    for (auto& p : raw[i].points) clouds[i].push_back(p[0], p[1], p[2]);
    rays += raw[i].points.size();
  }
  octomap::OcTree tree(0.05);
  auto t0 = std::chrono::steady_clock::now();
  double c0 = cpu_seconds();
  for (size_t i = 0; i < raw.size(); i++) {
    octomap::point3d o(raw[i].origin[0], raw[i].origin[1], raw[i].origin[2]);
    tree.insertPointCloud(clouds[i], o, max_range);
  }
  double cpu = cpu_seconds() - c0;
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SplitMix64 r{7};
  std::vector<octomap::OcTreeKey> keys;
  for (int i = 0; i < 1000000; i++) {
    auto& s = raw[r.next() % raw.size()];
    auto& p = s.points[r.next() % s.points.size()];
    keys.push_back(tree.coordToKey(p[0], p[1], p[2]));
  }
  // One lookup per key, the cells known counted: timed once here, then again in
  // `repeat_lookups`.
  auto count_known = [&] {
    size_t n = 0;
    for (auto& k : keys) n += tree.search(k) != nullptr;
    return n;
  };
  lookup_gate();
  read_keys(keys);
  auto t1 = std::chrono::steady_clock::now();
  double c1 = cpu_seconds();
  size_t known = count_known();
  double lookup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  double lookup_cpu = cpu_seconds() - c1;
  auto loops = repeat_lookups(count_known, keys.size(), [&] { read_keys(keys); });
  size_t occ = 0, fr = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    size_t c = size_t(1) << (3 * (16 - it.getDepth()));
    (tree.isNodeOccupied(*it) ? occ : fr) += c;
  }
  std::printf("RESULT octomap scans %zu rays %zu insert_s %.3f cpu_s %.3f rays_per_s %.4e bytes %zu occupied %zu free %zu lookup_ns %.1f known %zu lookup_cpu_ns %.1f",
              raw.size(), rays, wall, cpu, rays / wall, tree.memoryUsage(), occ, fr, lookup * 1e3, known, lookup_cpu * 1e3);
  print_loops(loops, lookup_cpu * 1e9 / double(keys.size()));
  std::printf("\n");
}
