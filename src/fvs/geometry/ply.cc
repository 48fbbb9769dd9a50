// PLY reading and writing. The reader loads the whole file once and decodes it in place:
// a 1 M-face binary mesh is ~30 MB, and one pass over memory is far faster than a stream.
// Every count in the header is checked against the bytes that remain before anything is
// allocated, so a corrupt count fails with a message instead of allocating gigabytes.
#include "fvs/geometry/ply.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "fvs/geometry/ply_format.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs {
namespace {

using ply_internal::Encoding;
using ply_internal::ParsePlyHeader;
using ply_internal::PlyElement;
using ply_internal::PlyHeader;
using ply_internal::PlyProperty;
using ply_internal::PlyType;
using ply_internal::TypeSize;

// Where each vertex property we understand sits in the element (-1: absent).
struct VertexLayout {
  int xyz[3] = {-1, -1, -1};
  int normal[3] = {-1, -1, -1};
  int color[3] = {-1, -1, -1};
};

VertexLayout FindVertexLayout(const std::string& path, const PlyElement& element) {
  VertexLayout layout;
  static const char* kXyz[3] = {"x", "y", "z"};
  static const char* kNormal[3] = {"nx", "ny", "nz"};
  static const char* kColor[3] = {"red", "green", "blue"};
  static const char* kDiffuse[3] = {"diffuse_red", "diffuse_green", "diffuse_blue"};
  for (int i = 0; i < static_cast<int>(element.properties.size()); ++i) {
    const PlyProperty& p = element.properties[i];
    for (int k = 0; k < 3; ++k) {
      int* slot = nullptr;
      if (p.name == kXyz[k]) slot = &layout.xyz[k];
      if (p.name == kNormal[k]) slot = &layout.normal[k];
      if (p.name == kColor[k] || p.name == kDiffuse[k]) slot = &layout.color[k];
      if (slot == nullptr) continue;
      if (p.is_list) {
        throw Error(path,
                    "vertex property '" + p.name + "' is a list, expected a scalar");
      }
      *slot = i;
    }
  }
  for (int k = 0; k < 3; ++k) {
    if (layout.xyz[k] < 0) {
      throw Error(path, std::string("vertex element has no '") + kXyz[k] + "' property");
    }
  }
  auto all_or_none = [&](const int* idx, const char* what) {
    const int present = (idx[0] >= 0) + (idx[1] >= 0) + (idx[2] >= 0);
    if (present != 0 && present != 3) {
      throw Error(path, std::string("vertex element has only some of the ") + what +
                            " properties");
    }
  };
  all_or_none(layout.normal, "normal (nx ny nz)");
  all_or_none(layout.color, "colour (red green blue)");
  return layout;
}

// Colours stored as integers are 0..255; stored as floats they are taken as 0..1.
uint8_t ToColorByte(double value, PlyType type) {
  const bool is_float = type == PlyType::kFloat32 || type == PlyType::kFloat64;
  const double scaled = is_float ? value * 255.0 : value;
  return static_cast<uint8_t>(std::clamp(std::round(scaled), 0.0, 255.0));
}

// Decodes scalar values from a binary or ASCII body, advancing a cursor; every read
// checks the end of the data and throws naming the file and the element being read.
class BodyReader {
 public:
  BodyReader(const std::string& path, const char* begin, const char* end,
             Encoding encoding)
      : path_(path), p_(begin), end_(end), encoding_(encoding) {}

  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  Encoding encoding() const { return encoding_; }

  double Read(PlyType type, const char* what, uint64_t index) {
    if (encoding_ == Encoding::kAscii) {
      const double value = ReadAscii(what, index);
      // A float property holds a float: "0.1" must read as 0.1f, as a binary file would.
      return type == PlyType::kFloat32 ? static_cast<float>(value) : value;
    }
    const int size = TypeSize(type);
    if (remaining() < static_cast<size_t>(size)) Truncated(what, index);
    unsigned char bytes[8];
    std::memcpy(bytes, p_, size);
    p_ += size;
    if (encoding_ != ply_internal::NativeBinaryEncoding())
      std::reverse(bytes, bytes + size);
    return ply_internal::DecodeNative(bytes, type);
  }

  [[noreturn]] void Truncated(const char* what, uint64_t index) const {
    throw Error(path_, "truncated or corrupt body: data ends inside " +
                           std::string(what) + " " + std::to_string(index));
  }

 private:
  double ReadAscii(const char* what, uint64_t index) {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\n' || *p_ == '\r')) ++p_;
    if (p_ >= end_) Truncated(what, index);
    double value = 0;
    // from_chars rejects a leading '+', which some writers emit.
    const char* start = (*p_ == '+') ? p_ + 1 : p_;
    const auto [next, ec] = std::from_chars(start, end_, value);
    if (ec != std::errc() || (next < end_ && *next != ' ' && *next != '\t' &&
                              *next != '\n' && *next != '\r')) {
      const char* stop = p_;
      while (stop < end_ && stop - p_ < 20 &&
             !std::isspace(static_cast<unsigned char>(*stop)))
        ++stop;
      throw Error(path_, "bad number '" + std::string(p_, stop) + "' in " + what + " " +
                             std::to_string(index));
    }
    p_ = next;
    return value;
  }

  const std::string& path_;
  const char* p_;
  const char* end_;
  Encoding encoding_;
};

// Smallest number of bytes one record of `element` can take; used to reject counts that
// cannot fit in the file before allocating for them.
size_t MinRecordBytes(const PlyElement& element, Encoding encoding) {
  size_t bytes = 0;
  for (const PlyProperty& p : element.properties) {
    if (encoding == Encoding::kAscii) {
      bytes += 2;  // a digit and a separator, at least
    } else {
      bytes += TypeSize(p.is_list ? p.count_type : p.type);
    }
  }
  return bytes;
}

void CheckCountFits(const std::string& path, const PlyElement& element,
                    const BodyReader& reader) {
  const size_t min_bytes = MinRecordBytes(element, reader.encoding());
  if (min_bytes == 0) return;
  // ASCII: the last value of the file needs no separator.
  const size_t available = reader.remaining() + (reader.encoding() == Encoding::kAscii);
  if (element.count > available / min_bytes) {
    throw Error(path,
                "element '" + element.name + "' claims " + std::to_string(element.count) +
                    " records, which needs at least " + std::to_string(element.count) +
                    " x " + std::to_string(min_bytes) + " bytes, but only " +
                    std::to_string(reader.remaining()) +
                    " remain (truncated file or corrupt count)");
  }
}

struct PlyContents {
  bool has_vertex_element = false;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Vector3ub> colors;
  bool has_face_element = false;
  std::vector<Eigen::Vector3i> faces;
};

// A list length must fit the bytes left before it is allocated for or cast to an
// integer: an ASCII value takes at least one character. (A length of 1e15 in a text file
// asked for 8 PB in a face, and 1e150 in a skipped element overflowed the int64_t cast,
// undefined behaviour: both reproduced by tests/fuzz/ply_fuzzer, the second found by it.)
void CheckListFits(BodyReader& reader, const PlyProperty& list, double count,
                   const char* what, uint64_t index) {
  const double min_bytes =
      reader.encoding() == Encoding::kAscii ? 1.0 : TypeSize(list.type);
  if (count * min_bytes > static_cast<double>(reader.remaining())) {
    reader.Truncated(what, index);
  }
}

void ReadVertexElement(const std::string& path, const PlyElement& element,
                       BodyReader& reader, PlyContents& out) {
  const VertexLayout layout = FindVertexLayout(path, element);
  const bool has_normals = layout.normal[0] >= 0;
  const bool has_colors = layout.color[0] >= 0;
  CheckCountFits(path, element, reader);
  const size_t n = element.count;
  out.has_vertex_element = true;
  out.points.resize(n);
  if (has_normals) out.normals.resize(n);
  if (has_colors) out.colors.resize(n);
  const size_t num_props = element.properties.size();
  std::vector<double> values(num_props);
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k < num_props; ++k) {
      const PlyProperty& p = element.properties[k];
      if (p.is_list) {
        const double count = reader.Read(p.count_type, "vertex", i);
        if (!(count >= 0) || count > 1e9) {
          throw Error(path, "vertex " + std::to_string(i) + ": bad list length");
        }
        for (int64_t j = 0; j < static_cast<int64_t>(count); ++j) {
          reader.Read(p.type, "vertex", i);
        }
        continue;
      }
      values[k] = reader.Read(p.type, "vertex", i);
    }
    Eigen::Vector3d& x = out.points[i];
    for (int k = 0; k < 3; ++k) x[k] = values[layout.xyz[k]];
    if (!x.allFinite()) {
      throw Error(path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
    }
    if (has_normals) {
      Eigen::Vector3f& nrm = out.normals[i];
      for (int k = 0; k < 3; ++k) nrm[k] = static_cast<float>(values[layout.normal[k]]);
      if (!nrm.allFinite()) {
        throw Error(path, "vertex " + std::to_string(i) + " has a non-finite normal");
      }
    }
    if (has_colors) {
      for (int k = 0; k < 3; ++k) {
        const double c = values[layout.color[k]];
        if (!std::isfinite(c)) {
          throw Error(path, "vertex " + std::to_string(i) + " has a non-finite colour");
        }
        out.colors[i][k] = ToColorByte(c, element.properties[layout.color[k]].type);
      }
    }
  }
}

void ReadFaceElement(const std::string& path, const PlyElement& element,
                     BodyReader& reader, PlyContents& out) {
  int index_property = -1;
  for (int k = 0; k < static_cast<int>(element.properties.size()); ++k) {
    const PlyProperty& p = element.properties[k];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      index_property = k;
    }
  }
  if (index_property < 0) {
    throw Error(path, "face element has no 'vertex_indices' (or 'vertex_index') list");
  }
  CheckCountFits(path, element, reader);
  out.has_face_element = true;
  out.faces.reserve(out.faces.size() + element.count);
  std::vector<int64_t> polygon;
  for (uint64_t i = 0; i < element.count; ++i) {
    for (int k = 0; k < static_cast<int>(element.properties.size()); ++k) {
      const PlyProperty& p = element.properties[k];
      if (!p.is_list) {
        reader.Read(p.type, "face", i);
        continue;
      }
      const double count = reader.Read(p.count_type, "face", i);
      if (!(count >= 0) || count != std::floor(count)) {
        throw Error(path, "face " + std::to_string(i) + ": bad list length " +
                              std::to_string(count));
      }
      CheckListFits(reader, p, count, "face", i);
      const int64_t n = static_cast<int64_t>(count);
      if (k != index_property) {
        for (int64_t j = 0; j < n; ++j) reader.Read(p.type, "face", i);
        continue;
      }
      if (n < 3) {
        throw Error(path, "face " + std::to_string(i) + " has " + std::to_string(n) +
                              " vertices (at least 3 needed)");
      }
      polygon.resize(n);
      for (int64_t j = 0; j < n; ++j) {
        const double v = reader.Read(p.type, "face", i);
        if (!(v >= 0) || v != std::floor(v) || v > std::numeric_limits<int32_t>::max()) {
          throw Error(path, "face " + std::to_string(i) + " has a bad vertex index " +
                                std::to_string(v));
        }
        polygon[j] = static_cast<int64_t>(v);
      }
      // Polygons become a fan around their first vertex.
      for (int64_t j = 1; j + 1 < n; ++j) {
        out.faces.emplace_back(static_cast<int>(polygon[0]), static_cast<int>(polygon[j]),
                               static_cast<int>(polygon[j + 1]));
      }
    }
  }
}

void SkipElement(const std::string& path, const PlyElement& element, BodyReader& reader) {
  // Records without properties take no bytes, so no count is too large for the file,
  // and looping over one of 4.7e13 hung the reader (ply_fuzzer, 2026-12-04).
  if (element.properties.empty()) return;
  CheckCountFits(path, element, reader);
  const char* what = element.name.c_str();
  for (uint64_t i = 0; i < element.count; ++i) {
    for (const PlyProperty& p : element.properties) {
      if (!p.is_list) {
        reader.Read(p.type, what, i);
        continue;
      }
      const double count = reader.Read(p.count_type, what, i);
      if (!(count >= 0) || count != std::floor(count)) {
        throw Error(path, element.name + " " + std::to_string(i) + ": bad list length");
      }
      CheckListFits(reader, p, count, what, i);
      for (int64_t j = 0; j < static_cast<int64_t>(count); ++j)
        reader.Read(p.type, what, i);
    }
  }
}

PlyContents ReadPly(const std::string& path, bool want_faces) {
  const std::string data = ReadFileToString(path);
  const PlyHeader header = ParsePlyHeader(path, data);
  BodyReader reader(path, data.data() + header.body_offset, data.data() + data.size(),
                    header.encoding);
  PlyContents out;
  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") {
      if (out.has_vertex_element) throw Error(path, "more than one vertex element");
      ReadVertexElement(path, element, reader, out);
    } else if (element.name == "face" && want_faces) {
      ReadFaceElement(path, element, reader, out);
    } else {
      SkipElement(path, element, reader);
    }
  }
  if (!out.has_vertex_element) throw Error(path, "no vertex element");
  const int64_t num_vertices = static_cast<int64_t>(out.points.size());
  for (size_t f = 0; f < out.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (out.faces[f][k] >= num_vertices) {
        throw Error(path, "face " + std::to_string(f) + " refers to vertex " +
                              std::to_string(out.faces[f][k]) + " but there are only " +
                              std::to_string(num_vertices) + " vertices");
      }
    }
  }
  return out;
}

}  // namespace

TriangleMesh ReadPlyMesh(const std::string& path) {
  PlyContents contents = ReadPly(path, /*want_faces=*/true);
  TriangleMesh mesh;
  mesh.vertices = std::move(contents.points);
  mesh.normals = std::move(contents.normals);
  mesh.colors = std::move(contents.colors);
  mesh.faces = std::move(contents.faces);
  return mesh;
}

PointCloud ReadPlyPointCloud(const std::string& path) {
  PlyContents contents = ReadPly(path, /*want_faces=*/false);
  PointCloud cloud;
  cloud.points = std::move(contents.points);
  cloud.normals = std::move(contents.normals);
  cloud.colors = std::move(contents.colors);
  return cloud;
}

}  // namespace fvs
