// Bonxai's ProbabilisticMap::insertPointCloud on the scans of `occupancy_peer gen`,
// then 10^6 random lookups with a const accessor (the cells the tesseral side draws).
// Usage: bonxai_driver FILE MAX_RANGE
#include <chrono>
#include "bonxai_map/probabilistic_map.hpp"
#include "scans.hpp"

int main(int argc, char** argv) {
  if (argc < 3) { std::fprintf(stderr, "usage: bonxai_driver FILE MAX_RANGE\n"); return 2; }
  auto raw = read_scans(argv[1]);
  double max_range = std::atof(argv[2]);
  std::vector<std::vector<Eigen::Vector3d>> pts(raw.size());
  size_t rays = 0;
  for (size_t i = 0; i < raw.size(); i++) {
    for (auto& p : raw[i].points) pts[i].emplace_back(p[0], p[1], p[2]);
    rays += raw[i].points.size();
  }
  Bonxai::ProbabilisticMap map(0.05);
  auto t0 = std::chrono::steady_clock::now();
  double c0 = cpu_seconds();
  for (size_t i = 0; i < raw.size(); i++) {
    Eigen::Vector3d o(raw[i].origin[0], raw[i].origin[1], raw[i].origin[2]);
    map.insertPointCloud(pts[i], o, max_range);
  }
  double cpu = cpu_seconds() - c0;
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<Bonxai::CoordT> occ, fr;
  map.getOccupiedVoxels(occ);
  map.getFreeVoxels(fr);
  SplitMix64 r{7};
  std::vector<Bonxai::CoordT> cells;
  for (int i = 0; i < 1000000; i++) {
    auto& s = raw[r.next() % raw.size()];
    auto& p = s.points[r.next() % s.points.size()];
    cells.push_back(map.grid().posToCoord(p[0], p[1], p[2]));
  }
  auto acc = map.grid().createConstAccessor();
  // One lookup per cell, the cells known counted: timed once here, then again in
  // `repeat_lookups`.
  auto count_known = [&] {
    size_t n = 0;
    for (auto& c : cells) n += acc.value(c) != nullptr;
    return n;
  };
  lookup_gate();
  read_keys(cells);
  auto t1 = std::chrono::steady_clock::now();
  double c1 = cpu_seconds();
  size_t known = count_known();
  double lookup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  double lookup_cpu = cpu_seconds() - c1;
  auto loops = repeat_lookups(count_known, cells.size(), [&] { read_keys(cells); });
  std::printf("RESULT bonxai scans %zu rays %zu insert_s %.3f cpu_s %.3f rays_per_s %.4e bytes %zu occupied %zu free %zu lookup_ns %.1f known %zu lookup_cpu_ns %.1f",
              raw.size(), rays, wall, cpu, rays / wall, map.grid().memUsage(), occ.size(), fr.size(),
              lookup * 1e3, known, lookup_cpu * 1e3);
  print_loops(loops, lookup_cpu * 1e9 / double(cells.size()));
  std::printf("\n");
}
