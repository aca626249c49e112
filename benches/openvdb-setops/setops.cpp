// OpenVDB side of the set-operation benchmark (issue 17 §1). Reads the operand
// pairs that the tesseral side exported (examples/setops_peer.rs, `export`): per
// workload two files of leaves, each leaf four little-endian int32 (x, y, z of its
// lowest voxel, log2 of its side). Each operand becomes a pruned BoolGrid (the leaf
// boxes filled active, then pruneGrid). On one thread (TBB limited to 1), for union,
// intersection and difference: the first grid is deep-copied outside the clock (the
// topology operations work in place), then only topologyUnion /
// topologyIntersection / topologyDifference is timed; best of REPS. A second figure
// adds pruneGrid() of the result (the canonical form tesseral always returns), a
// third the deep copy as well (a new canonical tree, which is what tesseral returns).
// Prints one line per workload and operation:
//   RESULT <workload> <op> <ms op> <ms op+prune> <ms copy+op+prune> <voxels> <bytes/voxel>
// with bytes/voxel = memUsage() of the result tree (pruned) / its active voxels.
#include <openvdb/openvdb.h>
#include <tbb/global_control.h>
#include <ctime>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

// The process's CPU time in milliseconds (all threads): the machine is shared, so
// wall time would count other processes' turns on the core.
static double cpu_ms() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static openvdb::BoolGrid::Ptr load(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        std::fprintf(stderr, "cannot read %s\n", path.c_str());
        std::exit(2);
    }
    std::vector<int32_t> v;
    int32_t rec[4];
    while (in.read(reinterpret_cast<char*>(rec), sizeof rec)) v.insert(v.end(), rec, rec + 4);
    auto grid = openvdb::BoolGrid::create(false);
    for (size_t i = 0; i < v.size(); i += 4) {
        const int32_t s = 1 << v[i + 3];
        openvdb::Coord lo(v[i], v[i + 1], v[i + 2]);
        if (s == 1) {
            grid->tree().setValueOn(lo, true);
        } else {
            grid->fill(openvdb::CoordBBox(lo, lo.offsetBy(s - 1)), true, true);
        }
    }
    grid->pruneGrid();
    return grid;
}

template <class F>
static void bench(const char* workload, const char* op, const openvdb::BoolGrid& a,
                  const openvdb::BoolGrid& b, int reps, F f) {
    double best = 1e30, best_pruned = 1e30, best_new = 1e30;
    openvdb::BoolGrid::Ptr out;
    for (int i = 0; i < reps; ++i) {
        auto c = a.deepCopy();
        double t0 = cpu_ms();
        f(*c, b);
        double ms = cpu_ms() - t0;
        best = std::min(best, ms);
        c = a.deepCopy();
        t0 = cpu_ms();
        f(*c, b);
        c->pruneGrid();
        ms = cpu_ms() - t0;
        best_pruned = std::min(best_pruned, ms);
        // A new canonical result, as tesseral returns: copy, op and prune.
        t0 = cpu_ms();
        c = a.deepCopy();
        f(*c, b);
        c->pruneGrid();
        ms = cpu_ms() - t0;
        best_new = std::min(best_new, ms);
        out = c;
    }
    const double voxels = double(out->activeVoxelCount());
    std::printf("RESULT %s %s %.4f %.4f %.4f %llu %.4f\n", workload, op, best, best_pruned, best_new,
                (unsigned long long)out->activeVoxelCount(),
                voxels > 0 ? double(out->memUsage()) / voxels : 0.0);
}

int main(int argc, char** argv) {
    if (argc < 4 || (argc - 2) % 2 != 0) {
        std::fprintf(stderr, "usage: setops REPS DIR WORKLOAD [DIR WORKLOAD ...]\n");
        return 2;
    }
    openvdb::initialize();
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const int reps = std::atoi(argv[1]);
    for (int w = 2; w + 1 < argc; w += 2) {
        const std::string dir = argv[w], name = argv[w + 1];
        auto a = load(dir + "/" + name + ".a.leaves");
        auto b = load(dir + "/" + name + ".b.leaves");
        std::printf("INPUT %s %llu %llu %llu %llu\n", name.c_str(),
                    (unsigned long long)a->activeVoxelCount(), (unsigned long long)b->activeVoxelCount(),
                    (unsigned long long)a->tree().leafCount(), (unsigned long long)b->tree().leafCount());
        bench(name.c_str(), "union", *a, *b, reps,
              [](openvdb::BoolGrid& x, const openvdb::BoolGrid& y) { x.topologyUnion(y); });
        bench(name.c_str(), "intersection", *a, *b, reps,
              [](openvdb::BoolGrid& x, const openvdb::BoolGrid& y) { x.topologyIntersection(y); });
        bench(name.c_str(), "difference", *a, *b, reps,
              [](openvdb::BoolGrid& x, const openvdb::BoolGrid& y) { x.topologyDifference(y); });
    }
    return 0;
}
