// OpenVDB side of the rotation benchmark (issue 16 §3): a solid sphere of radius R
// (voxel centres inside, as tesseral builds it) as a pruned BoolGrid, rotated by
// 30° about z through the origin with GridTransformer and PointSampler on one
// thread. Prints the time (best of 5, wall clock and process CPU time), the active
// voxels and the leaf nodes.
#include <openvdb/openvdb.h>
#include <openvdb/tools/GridTransformer.h>
#include <tbb/global_control.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>

static double cpu_ms() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

int main(int argc, char** argv) {
    const int r = argc > 1 ? std::atoi(argv[1]) : 100;
    const double degrees = argc > 2 ? std::atof(argv[2]) : 30.0;
    openvdb::initialize();
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    auto grid = openvdb::BoolGrid::create(false);
    auto acc = grid->getAccessor();
    const long long rr = (long long)r * r;
    for (int x = -r - 1; x <= r; ++x)
        for (int y = -r - 1; y <= r; ++y)
            for (int z = -r - 1; z <= r; ++z) {
                // The centre (x + 1/2, ...) inside: 4|c|^2 < 4 r^2 in integers.
                long long cx = 2 * x + 1, cy = 2 * y + 1, cz = 2 * z + 1;
                if (cx * cx + cy * cy + cz * cz <= 4 * rr) acc.setValue(openvdb::Coord(x, y, z), true);
            }
    grid->pruneGrid();
    openvdb::math::Mat4d mat = openvdb::math::Mat4d::identity();
    mat.postRotate(openvdb::math::Z_AXIS, degrees * M_PI / 180.0);
    double best = 1e30, best_cpu = 1e30;
    openvdb::BoolGrid::Ptr out;
    for (int i = 0; i < 5; ++i) {
        out = openvdb::BoolGrid::create(false);
        openvdb::tools::GridTransformer t(mat);
        t.setThreaded(false);
        auto start = std::chrono::steady_clock::now();
        double cpu = cpu_ms();
        t.transformGrid<openvdb::tools::PointSampler, openvdb::BoolGrid>(*grid, *out);
        out->pruneGrid();
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (ms < best) best = ms;
        if (cpu_ms() - cpu < best_cpu) best_cpu = cpu_ms() - cpu;
    }
    std::printf("openvdb: sphere r=%d (%llu voxels) rotated %.0f deg about z, one thread: %.1f ms (cpu %.1f ms), %llu voxels, %llu leaf nodes\n",
                r, (unsigned long long)grid->activeVoxelCount(), degrees, best, best_cpu,
                (unsigned long long)out->activeVoxelCount(), (unsigned long long)out->tree().leafCount());
    return 0;
}
