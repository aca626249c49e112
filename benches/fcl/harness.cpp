// FCL side of the interference benchmark: the same pairs of objects as
// crates/tesseral/benches/collide.rs, read from the .xyz files and manifest that the
// Rust bench writes (TESSERAL_FCL_PAIRS=DIR). Each voxel (x, y, z) is an occupied
// OctoMap cell of resolution 1 centred at (x + 0.5, y + 0.5, z + 0.5); object B is
// an fcl::CollisionObject translated by the pair's integer offset, and the query is
// fcl::collide(OcTree, OcTree) with the default request (one contact, no contact
// details), which stops at the first overlapping pair of occupied boxes.
// Prints "RESULT fcl <pair> <state> ns <value>" and checks every answer.
#include <fcl/fcl.h>
#include <octomap/OcTree.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using Clock = std::chrono::steady_clock;

static std::shared_ptr<octomap::OcTree> read_xyz(const std::string& path) {
  auto tree = std::make_shared<octomap::OcTree>(1.0);
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "cannot read %s\n", path.c_str());
    std::exit(2);
  }
  long x, y, z;
  while (in >> x >> y >> z) {
    tree->updateNode(octomap::point3d(x + 0.5f, y + 0.5f, z + 0.5f), true, true);
  }
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s PAIRS_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  std::ifstream manifest(dir + "/pairs.txt");
  std::map<std::string, std::shared_ptr<fcl::OcTree<double>>> trees;
  auto tree_of = [&](const std::string& name) {
    auto it = trees.find(name);
    if (it != trees.end()) return it->second;
    auto t = read_xyz(dir + "/" + name + ".xyz");
    std::printf("INFO fcl %s octree_nodes %zu leaves %zu\n", name.c_str(), t->calcNumNodes(),
                t->getNumLeafNodes());
    auto f = std::make_shared<fcl::OcTree<double>>(t);
    trees[name] = f;
    return f;
  };
  std::string line;
  int failures = 0;
  while (std::getline(manifest, line)) {
    std::istringstream ls(line);
    std::string pair, state;
    long ox, oy, oz;
    int expect;
    if (!(ls >> pair >> state >> ox >> oy >> oz >> expect)) continue;
    auto ta = tree_of(pair + "_a");
    auto tb = tree_of(pair + "_b");
    fcl::CollisionObjectd a(ta, fcl::Transform3d::Identity());
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = fcl::Vector3d(double(ox), double(oy), double(oz));
    fcl::CollisionObjectd b(tb, tf);
    fcl::CollisionRequestd request;  // one contact, no contact details
    auto query = [&]() {
      fcl::CollisionResultd result;
      fcl::collide(&a, &b, request, result);
      return result.isCollision();
    };
    bool got = query();
    if (got != (expect != 0)) {
      std::fprintf(stderr, "MISMATCH %s %s: fcl says %d, tesseral %d\n", pair.c_str(),
                   state.c_str(), int(got), expect);
      ++failures;
    }
    // Best of 5 batches of at least 0.2 s each.
    double best = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
      auto t0 = Clock::now();
      long n = 0;
      double elapsed = 0;
      volatile bool sink = false;
      do {
        for (int i = 0; i < 4; ++i) sink = query();
        n += 4;
        elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
      } while (elapsed < 0.2);
      (void)sink;
      best = std::min(best, elapsed * 1e9 / double(n));
    }
    std::printf("RESULT fcl %s %s ns %.1f\n", pair.c_str(), state.c_str(), best);
    std::fflush(stdout);
  }
  return failures == 0 ? 0 : 1;
}
