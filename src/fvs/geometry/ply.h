// PLY meshes and point clouds, binary (little/big endian) and ASCII. Reads vertex x,y,z as
// float or double, optional nx,ny,nz and red,green,blue (uchar), faces as
// vertex_indices/vertex_index lists (triangles; quads and polygons are fan-triangulated).
// Throws fvs::Error naming the file on malformed headers, truncated bodies, indices out of
// range or non-finite coordinates.
#pragma once

#include <string>

#include "fvs/geometry/mesh.h"

namespace fvs {

enum class PlyFormat { kBinaryLittleEndian, kAscii };

struct PlyWriteOptions {
  PlyFormat format = PlyFormat::kBinaryLittleEndian;
  // COLMAP writes float coordinates; double keeps far-from-origin scenes exact.
  bool double_precision = false;
};

TriangleMesh ReadPlyMesh(const std::string& path);
PointCloud ReadPlyPointCloud(const std::string& path);
// Atomic (temp + rename). Point clouds are written as COLMAP's fused.ply is: x y z nx ny nz
// red green blue.
void WritePlyMesh(const std::string& path, const TriangleMesh& mesh,
                  const PlyWriteOptions& options = {});
void WritePlyPointCloud(const std::string& path, const PointCloud& cloud,
                        const PlyWriteOptions& options = {});

}  // namespace fvs
