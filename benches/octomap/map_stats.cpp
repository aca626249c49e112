// Prints what OctoMap reads from a map: resolution, occupied/free leaves and volumes,
// and for a ColorOcTree the distinct colours of occupied leaves.
#include <octomap/octomap.h>
#include <octomap/ColorOcTree.h>
#include <cstdio>
#include <set>
#include <string>
int main(int argc, char** argv) {
  std::string path = argv[1];
  octomap::AbstractOcTree* t = (path.size() > 3 && path.substr(path.size() - 3) == ".bt")
      ? nullptr : octomap::AbstractOcTree::read(path);
  octomap::OcTree* tree = nullptr;
  if (!t) { tree = new octomap::OcTree(path); t = tree; }
  std::printf("%s: type %s res %g", path.c_str(), t->getTreeType().c_str(), t->getResolution());
  auto count = [](auto* tr) {
    size_t occ = 0, fr = 0; double vo = 0, vf = 0;
    for (auto it = tr->begin_leafs(); it != tr->end_leafs(); ++it) {
      double s = it.getSize(); double v = s * s * s;
      if (tr->isNodeOccupied(*it)) { occ++; vo += v; } else { fr++; vf += v; }
    }
    std::printf(" occupied %zu leaves %.6f m3, free %zu leaves %.6f m3", occ, vo, fr, vf);
  };
  if (auto* c = dynamic_cast<octomap::ColorOcTree*>(t)) {
    count(c);
    std::set<std::tuple<int,int,int>> cols;
    for (auto it = c->begin_leafs(); it != c->end_leafs(); ++it)
      if (c->isNodeOccupied(*it)) { auto k = it->getColor(); cols.insert({k.r, k.g, k.b}); }
    std::printf(" colours %zu", cols.size());
  } else if (auto* o = dynamic_cast<octomap::OcTree*>(t)) {
    count(o);
  }
  std::printf("\n");
  return 0;
}
