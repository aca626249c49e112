// Synthetic range scans as an OctoMap text log (`NODE x y z roll pitch yaw`, then the
// scan's points in the sensor frame), the input of `log2graph`.
//
//   gen_scans indoor|outdoor SCANS RAYS SEED > scans.log
//
// indoor:  a 16 x 10 x 3 m room with pillars and tables, the sensor walking through
//          it at 1.2 m; ranges up to about 10 m.
// outdoor: flat ground with 60 buildings in a 200 x 200 m block, the sensor at 1.8 m
//          driving along a street; rays that hit nothing within 80 m are dropped,
//          hits beyond 50 m are kept (cut by the 50 m max range of both tools).
// Rays are a lidar-like fan: azimuth uniform in [0, 2 pi), elevation in
// [-25, 25] degrees, from a splitmix64 generator, so runs are reproducible.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

struct Box { double lo[3], hi[3]; bool inside; };  // inside: the room seen from within

static uint64_t state;
static uint64_t next_u64() {
  uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
static double uniform(double a, double b) { return a + (b - a) * (next_u64() >> 11) * 0x1.0p-53; }

// Distance along o + t d to the first surface of `b` (t > 1e-9), or INFINITY.
static double hit(const Box& b, const double o[3], const double d[3]) {
  double t0 = -INFINITY, t1 = INFINITY;
  for (int k = 0; k < 3; k++) {
    if (d[k] == 0) {
      if (o[k] < b.lo[k] || o[k] > b.hi[k]) return INFINITY;
      continue;
    }
    double a = (b.lo[k] - o[k]) / d[k], c = (b.hi[k] - o[k]) / d[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
  }
  if (t0 > t1) return INFINITY;
  if (b.inside) return t1 > 1e-9 ? t1 : INFINITY;
  return t0 > 1e-9 ? t0 : INFINITY;
}

int main(int argc, char** argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: %s indoor|outdoor SCANS RAYS SEED\n", argv[0]);
    return 2;
  }
  bool indoor = strcmp(argv[1], "indoor") == 0;
  int scans = atoi(argv[2]);
  long rays = atol(argv[3]);
  state = strtoull(argv[4], nullptr, 10);
  std::vector<Box> boxes;
  if (indoor) {
    // Walls off the lattice of any round resolution, so that points on them are not
    // all on cell faces (where float rounding decides the cell).
    boxes.push_back({{-0.0137, -0.0219, -0.0071}, {16.0173, 10.0291, 3.0113}, true});
    for (int i = 0; i < 12; i++) {
      double x = uniform(1, 15), y = uniform(1, 9);
      bool pillar = i < 4;
      double w = pillar ? 0.4 : uniform(0.6, 1.6), h = pillar ? 3 : 0.75;
      boxes.push_back({{x, y, 0}, {x + w, y + (pillar ? 0.4 : uniform(0.5, 1.0)), h}, false});
    }
  } else {
    boxes.push_back({{-100, -100, -5}, {100, 100, -0.0187}, false});  // the ground, off the lattice
    for (int i = 0; i < 60; i++) {
      double x = uniform(-95, 85), y = uniform(-95, 85);
      if (std::fabs(y) < 12) y += y < 0 ? -12 : 12;  // keep the street clear
      boxes.push_back({{x, y, 0}, {x + uniform(5, 15), y + uniform(5, 15), uniform(4, 25)}, false});
    }
  }
  printf("# tesseral benches/octomap-map: %s, %d scans of %ld rays, seed %s\n", argv[1], scans, rays, argv[4]);
  std::vector<char> line(128);
  for (int s = 0; s < scans; s++) {
    double f = scans > 1 ? double(s) / (scans - 1) : 0.5;
    double t[3], rpy[3];
    if (indoor) {
      t[0] = 2 + 12 * f; t[1] = 5 + 2.5 * std::sin(6.28 * f); t[2] = 1.2;
    } else {
      t[0] = -60 + 120 * f; t[1] = 3 * std::sin(3.14 * f); t[2] = 1.8;
    }
    rpy[0] = uniform(-0.05, 0.05); rpy[1] = uniform(-0.05, 0.05); rpy[2] = uniform(-3.1, 3.1);
    t[0] += 0.0131; t[1] += 0.0173; t[2] += 0.0117;  // off the lattice too
    // The pose as OctoMap reads it (floats).
    for (int k = 0; k < 3; k++) { t[k] = (float)t[k]; rpy[k] = (float)rpy[k]; }
    printf("NODE %.9g %.9g %.9g %.9g %.9g %.9g\n", t[0], t[1], t[2], rpy[0], rpy[1], rpy[2]);
    double sr = std::sin(rpy[0]), cr = std::cos(rpy[0]), sp = std::sin(rpy[1]), cp = std::cos(rpy[1]);
    double sy = std::sin(rpy[2]), cy = std::cos(rpy[2]);
    double m[3][3] = {{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
                      {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
                      {-sp, cp * sr, cp * cr}};
    for (long r = 0; r < rays; r++) {
      double az = uniform(0, 6.283185307179586), el = uniform(-0.436, 0.436);
      double ds[3] = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
      double dw[3];
      for (int k = 0; k < 3; k++) dw[k] = m[k][0] * ds[0] + m[k][1] * ds[1] + m[k][2] * ds[2];
      double best = INFINITY;
      for (const Box& b : boxes) best = std::min(best, hit(b, t, dw));
      if (!(best < 80)) continue;  // nothing hit: no return
      // The point in the sensor frame, at the measured range.
      printf("%.9g %.9g %.9g\n", (float)(ds[0] * best), (float)(ds[1] * best), (float)(ds[2] * best));
    }
  }
  return 0;
}
