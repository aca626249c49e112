// Compares two OctoMap trees cell by cell (occupied, free, unknown at the finest
// level), reading both with OctoMap's own reader, and explains the differences.
//
//   compare A.ot B.ot SCANS.graph MAXRANGE [SAMPLE]
//
// Both trees are walked together from the root: where one is a leaf and the other
// has children, the leaf's state stands for every cell below it, so the walk costs
// O(nodes), not O(cells). Prints a 3 x 3 table of cell counts (rows: A's state,
// columns: B's), then, for a sample of up to SAMPLE (500) differing cells, whether the scans
// explain the difference as float rounding on a cell boundary: some ray grazes the
// cell (touches it widened by EPS but not narrowed by EPS) or ends within EPS of its
// faces. A difference no ray comes near is reported as unexplained.
#include <algorithm>
#include <map>
#include <set>
#include <octomap/octomap.h>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

using namespace octomap;

enum State { UNKNOWN = 0, FREE = 1, OCCUPIED = 2 };
static const char* NAMES[3] = {"unknown", "free", "occupied"};

struct Diff { OcTreeKey key; unsigned size; State a, b; };

static unsigned long long counts[3][3];
static std::vector<Diff> diffs;
static unsigned long long diff_cells = 0;

static State state_of(const OcTree& t, OcTreeNode* n) {
  if (!n) return UNKNOWN;
  return t.isNodeOccupied(n) ? OCCUPIED : FREE;
}

// Walks the cell at `key` of side 2^(16 - depth); `na`/`nb` are the nodes there (or
// null), `sa`/`sb` the states inherited from a leaf above (when the node is null
// because an ancestor was a leaf).
static void walk(const OcTree& A, const OcTree& B, OcTreeNode* na, OcTreeNode* nb, bool la, bool lb,
                 State sa, State sb, OcTreeKey key, unsigned depth) {
  // la / lb: the state is fixed (a leaf or unknown was reached above or here).
  if (!la) {
    if (!na) { sa = UNKNOWN; la = true; }
    else if (!A.nodeHasChildren(na)) { sa = state_of(A, na); la = true; }
  }
  if (!lb) {
    if (!nb) { sb = UNKNOWN; lb = true; }
    else if (!B.nodeHasChildren(nb)) { sb = state_of(B, nb); lb = true; }
  }
  if (la && lb) {
    unsigned long long cells = 1ULL << (3 * (16 - depth));
    counts[sa][sb] += cells;
    if (sa != sb) {
      diff_cells += cells;
      if (diffs.size() < 2000000) diffs.push_back({key, 16 - depth, sa, sb});
    }
    return;
  }
  unsigned half = 1u << (16 - depth - 1);
  for (unsigned i = 0; i < 8; i++) {
    OcTreeKey k = key;
    if (i & 1) k[0] += half;
    if (i & 2) k[1] += half;
    if (i & 4) k[2] += half;
    OcTreeNode* ca = (!la && A.nodeChildExists(na, i)) ? A.getNodeChild(na, i) : nullptr;
    OcTreeNode* cb = (!lb && B.nodeChildExists(nb, i)) ? B.getNodeChild(nb, i) : nullptr;
    walk(A, B, ca, cb, la, lb, sa, sb, k, depth + 1);
  }
}

struct Ray { point3d o, e; bool cut; };

// Does the segment o..e meet the box [lo, hi]? (slab test)
static bool meets(const point3d& o, const point3d& e, const double lo[3], const double hi[3]) {
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; k++) {
    double d = double(e(k)) - double(o(k));
    if (d == 0) {
      if (o(k) < lo[k] || o(k) > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - o(k)) / d, b = (hi[k] - o(k)) / d;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) {
    fprintf(stderr, "usage: %s A.ot B.ot SCANS.graph MAXRANGE [SAMPLE]\n", argv[0]);
    return 2;
  }
  std::unique_ptr<AbstractOcTree> ra(AbstractOcTree::read(argv[1]));
  std::unique_ptr<AbstractOcTree> rb(AbstractOcTree::read(argv[2]));
  OcTree* A = dynamic_cast<OcTree*>(ra.get());
  OcTree* B = dynamic_cast<OcTree*>(rb.get());
  if (!A || !B) { fprintf(stderr, "cannot read both trees as OcTree\n"); return 1; }
  if (A->getResolution() != B->getResolution()) { fprintf(stderr, "resolutions differ\n"); return 1; }
  double res = A->getResolution();
  walk(*A, *B, A->getRoot(), B->getRoot(), false, false, UNKNOWN, UNKNOWN, OcTreeKey(0, 0, 0), 0);
  printf("cells (rows: %s, columns: %s)\n", argv[1], argv[2]);
  printf("%-10s %14s %14s %14s\n", "", NAMES[0], NAMES[1], NAMES[2]);
  for (int a = 0; a < 3; a++)
    printf("%-10s %14llu %14llu %14llu\n", NAMES[a], counts[a][0], counts[a][1], counts[a][2]);
  unsigned long long known = 0;
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++)
      if (a || b) known += counts[a][b];
  printf("RESULT known_cells %llu\nRESULT differing_cells %llu\n", known, diff_cells);
  printf("RESULT agreement %.9f\n", known ? 1.0 - double(diff_cells) / known : 1.0);
  if (diffs.empty()) return 0;

  // The rays, as graph2tree casts them: points moved by the pose, from its translation.
  ScanGraph graph;
  if (!graph.readBinary(argv[3])) return 1;
  double maxrange = atof(argv[4]);
  std::vector<std::vector<Ray>> scans;
  for (ScanNode* n : graph) {
    scans.emplace_back();
    point3d o = n->pose.trans();
    for (const point3d& p : *n->scan) {
      point3d e = n->pose.transform(p);
      bool cut = false;
      if (maxrange > 0 && (e - o).norm() > maxrange) {
        e = o + (e - o).normalized() * maxrange;
        cut = true;
      }
      scans.back().push_back({o, e, cut});
    }
  }
  // For a sample of differing cells (spread over the list), the states the exact
  // geometry allows: each ray is classified against the cell widened and narrowed by
  // EPS; a ray that ends or passes within EPS of the cell's boundary may go either
  // way. Per scan the cell is hit (a ray ends in it), else missed (a ray crosses it;
  // a cut ray's last cell is neither, as OctoMap's computeRayKeys), else untouched;
  // the reachable log-odds after all scans (OctoMap's default sensor model, float)
  // give the reachable states. A difference is float rounding on a cell boundary
  // when both trees' states are reachable; otherwise the tree whose state is not
  // reachable is wrong.
  // EPS: a few float roundings of the largest coordinate involved (OctoMap moves the
  // points in float, tesseral in double), at least 1e-5 of a cell.
  double reach_m = 0;
  for (const auto& rays : scans)
    for (const Ray& r : rays)
      for (int k = 0; k < 3; k++) reach_m = std::max({reach_m, (double)std::fabs(r.o(k)), (double)std::fabs(r.e(k))});
  const double eps = std::max(1e-5 * res, 8 * 1.2e-7 * reach_m);
  printf("RESULT eps_m %.3g\n", eps);
  const float hit = A->getProbHitLog(), miss = A->getProbMissLog();
  const float lo_clamp = A->getClampingThresMinLog(), hi_clamp = A->getClampingThresMaxLog();
  const float thres = A->getOccupancyThresLog();
  // Every difference is classified unless a smaller sample is asked for (argv[5]).
  size_t sample = std::min<size_t>(argc == 6 ? atol(argv[5]) : diffs.size(), diffs.size());
  // The cell faces that decide the differences: for each differing cell, the faces
  // (axis, world coordinate) within EPS of a ray's end point in or beside it.
  std::map<std::pair<int, long long>, unsigned> planes;
  unsigned boundary = 0, a_wrong = 0, b_wrong = 0, both_wrong = 0, shown = 0;
  for (size_t s = 0; s < sample; s++) {
    const Diff& d = diffs[s * diffs.size() / sample];
    double lo[3], hi[3], wlo[3], whi[3], nlo[3], nhi[3];
    for (int k = 0; k < 3; k++) {
      lo[k] = (double(d.key[k]) - 32768.0) * res;
      hi[k] = lo[k] + res;  // the first cell of the differing block
      wlo[k] = lo[k] - eps; whi[k] = hi[k] + eps;
      nlo[k] = lo[k] + eps; nhi[k] = hi[k] - eps;
    }
    auto inside = [](const point3d& p, const double* l, const double* h) {
      for (int k = 0; k < 3; k++)
        if (p(k) < l[k] || p(k) > h[k]) return false;
      return true;
    };
    // Reachable log-odds; NAN is unknown.
    std::vector<float> reach = {NAN};
    std::set<std::pair<int, long long>> face_keys;
    for (const auto& rays : scans) {
      bool end_sure = false, end_maybe = false, cross_sure = false, cross_maybe = false;
      for (const Ray& r : rays) {
        if (!meets(r.o, r.e, wlo, whi)) continue;
        if (inside(r.e, wlo, whi) && !inside(r.e, nlo, nhi))
          for (int k = 0; k < 3; k++)
            for (double f : {lo[k], hi[k]})
              if (std::fabs(r.e(k) - f) <= eps) face_keys.insert({k, std::llround(f / res)});
        bool e_in = inside(r.e, nlo, nhi), e_near = inside(r.e, wlo, whi);
        bool through = meets(r.o, r.e, nlo, nhi);
        if (!r.cut && e_in) { end_sure = true; continue; }
        if (!r.cut && e_near) end_maybe = true;
        // The segment short of its end cell: crosses the cell for sure when it
        // passes through the narrowed box and does not end near it.
        if (through && !e_near) cross_sure = true;
        else cross_maybe = true;
      }
      // The options for this scan: 0 none, 1 hit, 2 miss.
      bool opt[3] = {false, false, false};
      if (end_sure) opt[1] = true;
      else {
        if (end_maybe) opt[1] = true;
        if (cross_sure) opt[2] = true;
        else {
          if (cross_maybe || end_maybe) { opt[2] = true; opt[0] = true; }
          else opt[0] = true;
        }
      }
      std::vector<float> next;
      for (float l : reach)
        for (int o = 0; o < 3; o++) {
          if (!opt[o]) continue;
          float v = l;
          if (o == 1) v = std::min(hi_clamp, (std::isnan(l) ? 0.f : l) + hit);
          if (o == 2) v = std::max(lo_clamp, (std::isnan(l) ? 0.f : l) + miss);
          bool seen = false;
          for (float x : next) seen = seen || (x == v) || (std::isnan(x) && std::isnan(v));
          if (!seen && next.size() < 4096) next.push_back(v);
        }
      reach.swap(next);
    }
    for (const auto& f : face_keys) planes[f]++;
    bool can[3] = {false, false, false};
    for (float l : reach) can[std::isnan(l) ? UNKNOWN : (l > thres ? OCCUPIED : FREE)] = true;
    if (can[d.a] && can[d.b]) boundary++;
    else if (can[d.a]) b_wrong++;
    else if (can[d.b]) a_wrong++;
    else both_wrong++;
    if (!(can[d.a] && can[d.b]) && shown++ < 10)
      fprintf(stderr, "not a boundary case: key (%u %u %u) size 2^%u: %s in A, %s in B; reachable:%s%s%s\n",
              d.key[0], d.key[1], d.key[2], d.size, NAMES[d.a], NAMES[d.b], can[0] ? " unknown" : "",
              can[1] ? " free" : "", can[2] ? " occupied" : "");
  }
  printf("RESULT sampled_differences %zu\n", sample);
  // The faces most differences sit on, largest first: "x|y|z = metres (cells)".
  std::vector<std::pair<unsigned, std::pair<int, long long>>> top;
  for (const auto& [f, n] : planes) top.push_back({n, f});
  std::sort(top.rbegin(), top.rend());
  for (size_t i = 0; i < top.size() && i < 5; i++)
    printf("RESULT face %c = %.4f m (cell face %lld): %u differing cells\n", "xyz"[top[i].second.first],
           top[i].second.second * res, top[i].second.second, top[i].first);
  printf("RESULT boundary_rounding %u\nRESULT only_A_reachable %u\nRESULT only_B_reachable %u\nRESULT neither_reachable %u\n",
         boundary, b_wrong, a_wrong, both_wrong);
  return 0;
}
