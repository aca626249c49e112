// bt_read: OctoMap's own reader, for side-by-side checks against tesseral.
//
//   bt_read FILE.bt|FILE.ot [--repeat N] [--dump OUT.xyz]
//
// Loads the file into memory once, then times OcTree::readBinary (for .bt) from an
// in-memory stream N times and prints the best and median time. --dump writes every
// occupied voxel as "x y z" with x = key - 32768, which is tesseral's voxel index, so
// the output compares directly with `tesseral convert FILE OUT.xyz`.
#include <octomap/AbstractOcTree.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

template <class TREE>
static size_t dump(const TREE& tree, const char* out_path, size_t* leaves) {
  std::vector<std::array<long, 3>> voxels;
  *leaves = 0;
  const double res = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    ++*leaves;
    const double size = it.getSize();
    const long n = std::lround(size / res);
    const octomap::point3d c = it.getCoordinate();
    const double lo[3] = {c.x() - size / 2, c.y() - size / 2, c.z() - size / 2};
    for (long i = 0; i < n; ++i)
      for (long j = 0; j < n; ++j)
        for (long k = 0; k < n; ++k) {
          octomap::OcTreeKey key;
          if (!tree.coordToKeyChecked(lo[0] + (i + 0.5) * res, lo[1] + (j + 0.5) * res,
                                      lo[2] + (k + 0.5) * res, key)) {
            std::cerr << "voxel outside the key range\n";
            std::exit(1);
          }
          voxels.push_back(std::array<long, 3>{long(key[0]) - 32768, long(key[1]) - 32768, long(key[2]) - 32768});
        }
  }
  std::sort(voxels.begin(), voxels.end());
  if (out_path) {
    std::ofstream out(out_path);
    for (const auto& v : voxels) out << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
  }
  return voxels.size();
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: bt_read FILE.bt|FILE.ot [--repeat N] [--dump OUT.xyz]\n";
    return 2;
  }
  const std::string path = argv[1];
  int repeat = 1;
  const char* dump_path = nullptr;
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) dump_path = argv[++i];
  }
  const bool is_ot = path.size() > 3 && path.substr(path.size() - 3) == ".ot";
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    std::cerr << path << ": cannot open\n";
    return 2;
  }
  std::stringstream buffer;
  buffer << file.rdbuf();
  const std::string bytes = buffer.str();

  if (is_ot) {
    std::istringstream s(bytes);
    std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(s));
    if (!tree) {
      std::cerr << path << ": OctoMap could not read it\n";
      return 1;
    }
    size_t leaves = 0, voxels = 0;
    if (auto* t = dynamic_cast<octomap::ColorOcTree*>(tree.get())) voxels = dump(*t, dump_path, &leaves);
    else if (auto* t = dynamic_cast<octomap::OcTree*>(tree.get())) voxels = dump(*t, dump_path, &leaves);
    else {
      std::cerr << path << ": tree type " << tree->getTreeType() << " not handled\n";
      return 1;
    }
    std::printf("type %s nodes %zu res %g occupied_leaves %zu voxels %zu\n",
                tree->getTreeType().c_str(), tree->size(), tree->getResolution(), leaves, voxels);
    return 0;
  }

  std::vector<double> ms;
  std::unique_ptr<octomap::OcTree> last;
  for (int r = 0; r < std::max(repeat, 1); ++r) {
    std::istringstream s(bytes);
    auto tree = std::make_unique<octomap::OcTree>(0.1);
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = tree->readBinary(s);
    const auto t1 = std::chrono::steady_clock::now();
    if (!ok) {
      std::cerr << path << ": OctoMap readBinary failed\n";
      return 1;
    }
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    last = std::move(tree);
  }
  std::sort(ms.begin(), ms.end());
  size_t leaves = 0;
  const size_t voxels = dump(*last, dump_path, &leaves);
  std::printf("nodes %zu res %g occupied_leaves %zu voxels %zu readBinary_ms best %.3f median %.3f (%zu runs)\n",
              last->size(), last->getResolution(), leaves, voxels, ms.front(), ms[ms.size() / 2], ms.size());
  return 0;
}
