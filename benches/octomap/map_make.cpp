// Makes OctoMap maps with free space: a wall scanned from a sensor, at 0.05 m.
#include <octomap/octomap.h>
#include <octomap/ColorOcTree.h>
#include <cstdio>
int main(int argc, char** argv) {
  const char* dir = argc > 1 ? argv[1] : ".";
  octomap::Pointcloud cloud;
  for (int i = -20; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j)
      cloud.push_back(2.0f, i * 0.05f, j * 0.05f);
  octomap::OcTree tree(0.05);
  tree.insertPointCloud(cloud, octomap::point3d(0, 0, 0.5));
  std::string d(dir);
  tree.writeBinary(d + "/scan.bt");
  tree.write(d + "/scan.ot");
  octomap::ColorOcTree ct(0.05);
  ct.insertPointCloud(cloud, octomap::point3d(0, 0, 0.5));
  for (auto it = ct.begin_leafs(); it != ct.end_leafs(); ++it)
    if (ct.isNodeOccupied(*it)) {
      auto p = it.getCoordinate();
      ct.setNodeColor(it.getKey(), p.y() > 0 ? 255 : 0, 0, p.y() > 0 ? 0 : 255);
    }
  ct.updateInnerOccupancy();
  ct.write(d + "/color.ot");
  size_t occ = 0, fr = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it)
    (tree.isNodeOccupied(*it) ? occ : fr) += 1;
  std::printf("made scan.bt/.ot: %zu occupied leaves, %zu free leaves, res %g\n", occ, fr, tree.getResolution());
  return 0;
}
