// PLY writing: the header COLMAP writes (x y z [nx ny nz] [red green blue], faces as
// "list uchar int vertex_indices"), body built in memory and committed atomically.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "fvs/geometry/ply.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs {
namespace {

// Appends values to a body buffer, binary little endian or ASCII.
class BodyWriter {
 public:
  explicit BodyWriter(PlyFormat format) : ascii_(format == PlyFormat::kAscii) {}

  template <typename T>
  void Put(T value) {
    if (ascii_) {
      char buffer[64];
      const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
      data_.append(buffer, result.ptr);
      data_.push_back(' ');
      return;
    }
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    std::reverse(bytes, bytes + sizeof(T));
#endif
    data_.append(bytes, sizeof(T));
  }
  void PutByte(uint8_t value) {
    if (ascii_) {
      Put(static_cast<int>(value));
    } else {
      data_.push_back(static_cast<char>(value));
    }
  }
  void EndRecord() {
    if (ascii_) data_.back() = '\n';
  }
  void Reserve(size_t bytes) { data_.reserve(bytes); }
  const std::string& data() const { return data_; }

 private:
  bool ascii_;
  std::string data_;
};

void CheckAttributes(const std::string& path, size_t n, size_t num_normals,
                     size_t num_colors) {
  if (num_normals != 0 && num_normals != n) {
    throw Error(path, "cannot write: " + std::to_string(num_normals) + " normals for " +
                          std::to_string(n) + " vertices");
  }
  if (num_colors != 0 && num_colors != n) {
    throw Error(path, "cannot write: " + std::to_string(num_colors) + " colours for " +
                          std::to_string(n) + " vertices");
  }
}

std::string VertexHeader(size_t n, bool normals, bool colors, const PlyWriteOptions& o) {
  const std::string type = o.double_precision ? "double" : "float";
  std::string h = "element vertex " + std::to_string(n) + "\n";
  for (const char* axis : {"x", "y", "z"}) h += "property " + type + " " + axis + "\n";
  if (normals) h += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  return h;
}

std::string HeaderStart(const PlyWriteOptions& options) {
  return std::string("ply\nformat ") +
         (options.format == PlyFormat::kAscii ? "ascii" : "binary_little_endian") +
         " 1.0\ncomment written by colmap-fvs\n";
}

void WriteVertices(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector3f>& normals,
                   const std::vector<Vector3ub>& colors, const PlyWriteOptions& options,
                   BodyWriter& body) {
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& x = points[i];
    if (!x.allFinite()) {
      throw Error(path, "cannot write: vertex " + std::to_string(i) + " is not finite");
    }
    if (options.double_precision) {
      for (int k = 0; k < 3; ++k) body.Put(x[k]);
    } else {
      if (x.cwiseAbs().maxCoeff() > kFloatMax) {
        throw Error(path, "cannot write: vertex " + std::to_string(i) +
                              " does not fit in float (use double_precision)");
      }
      for (int k = 0; k < 3; ++k) body.Put(static_cast<float>(x[k]));
    }
    if (!normals.empty()) {
      if (!normals[i].allFinite()) {
        throw Error(path, "cannot write: normal " + std::to_string(i) + " is not finite");
      }
      for (int k = 0; k < 3; ++k) body.Put(normals[i][k]);
    }
    if (!colors.empty()) {
      for (int k = 0; k < 3; ++k) body.PutByte(colors[i][k]);
    }
    body.EndRecord();
  }
}

void Commit(const std::string& path, const std::string& header, const BodyWriter& body) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(body.data().data(), static_cast<std::streamsize>(body.data().size()));
  });
}

}  // namespace

void WritePlyMesh(const std::string& path, const TriangleMesh& mesh,
                  const PlyWriteOptions& options) {
  const size_t n = mesh.vertices.size();
  CheckAttributes(path, n, mesh.normals.size(), mesh.colors.size());
  std::string header =
      HeaderStart(options) +
      VertexHeader(n, !mesh.normals.empty(), !mesh.colors.empty(), options) +
      "element face " + std::to_string(mesh.faces.size()) +
      "\nproperty list uchar int vertex_indices\nend_header\n";
  BodyWriter body(options.format);
  body.Reserve(n * (options.double_precision ? 24 : 12) + mesh.faces.size() * 13);
  WriteVertices(path, mesh.vertices, mesh.normals, mesh.colors, options, body);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    for (int k = 0; k < 3; ++k) {
      if (face[k] < 0 || static_cast<size_t>(face[k]) >= n) {
        throw Error(path, "cannot write: face " + std::to_string(f) +
                              " refers to vertex " + std::to_string(face[k]) + " of " +
                              std::to_string(n));
      }
    }
    body.PutByte(3);
    for (int k = 0; k < 3; ++k) body.Put(static_cast<int32_t>(face[k]));
    body.EndRecord();
  }
  Commit(path, header, body);
}

void WritePlyPointCloud(const std::string& path, const PointCloud& cloud,
                        const PlyWriteOptions& options) {
  const size_t n = cloud.points.size();
  CheckAttributes(path, n, cloud.normals.size(), cloud.colors.size());
  const std::string header =
      HeaderStart(options) +
      VertexHeader(n, !cloud.normals.empty(), !cloud.colors.empty(), options) +
      "end_header\n";
  BodyWriter body(options.format);
  body.Reserve(n * 27);
  WriteVertices(path, cloud.points, cloud.normals, cloud.colors, options, body);
  Commit(path, header, body);
}

}  // namespace fvs
