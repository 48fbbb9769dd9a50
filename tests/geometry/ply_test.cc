#include "fvs/geometry/ply.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

#include "fvs/util/error.h"
#include "geometry/geometry_test_util.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::TempDir;

TriangleMesh RandomMesh(int num_vertices, int num_faces, bool normals, bool colors,
                        double offset = 0) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-10, 10);
  std::uniform_int_distribution<int> idx(0, num_vertices - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  TriangleMesh mesh;
  for (int i = 0; i < num_vertices; ++i) {
    mesh.vertices.emplace_back(offset + u(rng), offset + u(rng), offset + u(rng));
    if (normals) {
      mesh.normals.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized());
    }
    if (colors) mesh.colors.emplace_back(byte(rng), byte(rng), byte(rng));
  }
  for (int f = 0; f < num_faces; ++f)
    mesh.faces.emplace_back(idx(rng), idx(rng), idx(rng));
  return mesh;
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <typename T>
void AppendRaw(std::string* s, T value, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  s->append(b, sizeof(T));
}

// The exception message, for checks of what it says.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "<no fvs::Error thrown>";
}

void ExpectMeshesEqual(const TriangleMesh& a, const TriangleMesh& b,
                       bool float_positions) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double expected =
          float_positions ? static_cast<double>(static_cast<float>(a.vertices[i][k]))
                          : a.vertices[i][k];
      ASSERT_EQ(b.vertices[i][k], expected) << i;
    }
  }
  ASSERT_EQ(a.normals.size(), b.normals.size());
  for (size_t i = 0; i < a.normals.size(); ++i) ASSERT_EQ(a.normals[i], b.normals[i]);
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (size_t i = 0; i < a.colors.size(); ++i) ASSERT_EQ(a.colors[i], b.colors[i]);
  ASSERT_EQ(a.faces, b.faces);
}

TEST(PlyTest, MeshRoundTripsInEveryFormatAndPrecision) {
  TempDir dir;
  for (bool normals : {false, true}) {
    for (bool colors : {false, true}) {
      const TriangleMesh mesh = RandomMesh(300, 500, normals, colors, 1234.5);
      for (PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
        for (bool dbl : {false, true}) {
          SCOPED_TRACE(::testing::Message() << normals << colors << (int)format << dbl);
          PlyWriteOptions options;
          options.format = format;
          options.double_precision = dbl;
          WritePlyMesh(dir / "m.ply", mesh, options);
          ExpectMeshesEqual(mesh, ReadPlyMesh(dir / "m.ply"), !dbl);
        }
      }
    }
  }
}

TEST(PlyTest, PointCloudRoundTripsAndMatchesColmapLayout) {
  TempDir dir;
  const TriangleMesh m = RandomMesh(1000, 0, true, true);
  PointCloud cloud;
  cloud.points = m.vertices;
  cloud.normals = m.normals;
  cloud.colors = m.colors;
  for (PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    PlyWriteOptions options;
    options.format = format;
    options.double_precision = true;
    WritePlyPointCloud(dir / "fused.ply", cloud, options);
    const PointCloud back = ReadPlyPointCloud(dir / "fused.ply");
    ASSERT_EQ(back.points, cloud.points);
    ASSERT_EQ(back.normals, cloud.normals);
    ASSERT_EQ(back.colors, cloud.colors);
  }
  // Default options write exactly COLMAP's fused.ply layout: 27 bytes per point.
  WritePlyPointCloud(dir / "fused.ply", cloud);
  const std::string text = testing::ReadTextFile(dir / "fused.ply");
  const std::string expected_header =
      "ply\nformat binary_little_endian 1.0\ncomment written by colmap-fvs\n"
      "element vertex 1000\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nend_header\n";
  ASSERT_EQ(text.substr(0, expected_header.size()), expected_header);
  EXPECT_EQ(text.size(), expected_header.size() + 27 * 1000);
  // Without attributes only the positions are written and read back.
  PointCloud bare;
  bare.points = cloud.points;
  WritePlyPointCloud(dir / "bare.ply", bare);
  const PointCloud bare_back = ReadPlyPointCloud(dir / "bare.ply");
  EXPECT_EQ(bare_back.size(), 1000u);
  EXPECT_TRUE(bare_back.normals.empty());
  EXPECT_TRUE(bare_back.colors.empty());
}

TEST(PlyTest, EmptyMeshRoundTrips) {
  TempDir dir;
  WritePlyMesh(dir / "e.ply", TriangleMesh());
  const TriangleMesh back = ReadPlyMesh(dir / "e.ply");
  EXPECT_TRUE(back.vertices.empty());
  EXPECT_TRUE(back.faces.empty());
  PlyWriteOptions ascii;
  ascii.format = PlyFormat::kAscii;
  WritePlyMesh(dir / "e.ply", TriangleMesh(), ascii);
  EXPECT_TRUE(ReadPlyMesh(dir / "e.ply").vertices.empty());
}

// A header in the other order, unknown properties and elements, big endian, other type
// names, quads and extra face properties: everything a foreign writer may do.
TEST(PlyTest, ReadsBigEndianWithUnknownPropertiesAndPolygons) {
  TempDir dir;
  std::string s =
      "ply\r\nformat binary_big_endian 1.0\r\ncomment from elsewhere\r\n"
      "obj_info whatever\r\nelement camera 1\r\nproperty float32 fov\r\n"
      "element vertex 4\r\nproperty uint16 quality\r\nproperty float64 z\r\n"
      "property float32 x\r\nproperty list uint8 int32 junk\r\nproperty float y\r\n"
      "property uint8 blue\r\nproperty uint8 green\r\nproperty uint8 red\r\n"
      "property float nx\r\nproperty float ny\r\nproperty float nz\r\n"
      "element face 2\r\nproperty int8 flags\r\nproperty list int uint vertex_index\r\n"
      "property double area\r\nend_header\r\n";
  AppendRaw<float>(&s, 60.0f, true);
  const double xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5}, {0, 1, -1e-3}};
  for (int i = 0; i < 4; ++i) {
    AppendRaw<uint16_t>(&s, 7, true);
    AppendRaw<double>(&s, xyz[i][2], true);
    AppendRaw<float>(&s, static_cast<float>(xyz[i][0]), true);
    s.push_back(2);  // two junk ints
    AppendRaw<int32_t>(&s, -5, true);
    AppendRaw<int32_t>(&s, 9, true);
    AppendRaw<float>(&s, static_cast<float>(xyz[i][1]), true);
    s.push_back(static_cast<char>(10 * i + 3));  // blue
    s.push_back(static_cast<char>(10 * i + 2));  // green
    s.push_back(static_cast<char>(10 * i + 1));  // red
    AppendRaw<float>(&s, 0.f, true);
    AppendRaw<float>(&s, 0.f, true);
    AppendRaw<float>(&s, 1.f, true);
  }
  // A quad (fan-triangulated) and a triangle.
  s.push_back(1);
  AppendRaw<int32_t>(&s, 4, true);
  for (uint32_t v : {0u, 1u, 2u, 3u}) AppendRaw<uint32_t>(&s, v, true);
  AppendRaw<double>(&s, 1.0, true);
  s.push_back(0);
  AppendRaw<int32_t>(&s, 3, true);
  for (uint32_t v : {3u, 2u, 1u}) AppendRaw<uint32_t>(&s, v, true);
  AppendRaw<double>(&s, 0.5, true);
  WriteBytes(dir / "foreign.ply", s);

  const TriangleMesh mesh = ReadPlyMesh(dir / "foreign.ply");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.vertices[i][k], xyz[i][k]);
    EXPECT_EQ(mesh.colors[i], Vector3ub(10 * i + 1, 10 * i + 2, 10 * i + 3));
    EXPECT_EQ(mesh.normals[i], Eigen::Vector3f(0, 0, 1));
  }
  ASSERT_EQ(mesh.faces.size(), 3u);
  EXPECT_EQ(mesh.faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.faces[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(mesh.faces[2], Eigen::Vector3i(3, 2, 1));
  // The same file read as a point cloud.
  const PointCloud cloud = ReadPlyPointCloud(dir / "foreign.ply");
  EXPECT_EQ(cloud.size(), 4u);
  EXPECT_EQ(cloud.colors.size(), 4u);
}

TEST(PlyTest, ReadsAsciiWithFloatColoursAndOddSpacing) {
  TempDir dir;
  testing::WriteTextFile(dir / "a.ply",
                         "ply\nformat ascii 1.0\nelement vertex 3\n"
                         "property double x\nproperty double y\nproperty double z\n"
                         "property float red\nproperty float green\nproperty float blue\n"
                         "element face 1\nproperty list uchar int vertex_indices\n"
                         "end_header\n"
                         "  1.5 -2 +3e2 1 0.5 0\n\t0 0 0 0 0 0\n1e-300 1 1 0.2 0.2 0.2\n"
                         "3 0 1 2");  // no final newline
  const TriangleMesh mesh = ReadPlyMesh(dir / "a.ply");
  ASSERT_EQ(mesh.vertices.size(), 3u);
  EXPECT_EQ(mesh.vertices[0], Eigen::Vector3d(1.5, -2, 300));
  EXPECT_EQ(mesh.vertices[2].x(), 1e-300);
  EXPECT_EQ(mesh.colors[0], Vector3ub(255, 128, 0));
  EXPECT_EQ(mesh.colors[2], Vector3ub(51, 51, 51));
  EXPECT_EQ(mesh.faces.size(), 1u);
}

// A binary mesh as COLMAP's delaunay_mesher writes it, cut at every possible length: each
// cut must fail with a message naming the file, never crash or read garbage.
TEST(PlyTest, TruncatedFilesFailWithTheFileName) {
  TempDir dir;
  TriangleMesh mesh = RandomMesh(20, 30, false, true);
  for (PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    PlyWriteOptions options;
    options.format = format;
    WritePlyMesh(dir / "full.ply", mesh, options);
    const std::string full = testing::ReadTextFile(dir / "full.ply");
    const std::string path = dir / "cut.ply";
    int failures = 0;
    // Every length through the header, then a spread through the body.
    for (size_t len = 0; len < full.size(); len += (len < 400 ? 1 : 7)) {
      // ASCII may end in a record's last number that still parses when cut after a digit
      // of it; the end of the final record is that case, so stop before it.
      if (format == PlyFormat::kAscii && len + 8 >= full.size()) break;
      WriteBytes(path, full.substr(0, len));
      const std::string message = ErrorOf([&] { ReadPlyMesh(path); });
      ASSERT_NE(message.find(path), std::string::npos) << len << ": " << message;
      ++failures;
    }
    EXPECT_GT(failures, 100);
    const std::string binary_cut = ErrorOf([&] {
      WriteBytes(path, full.substr(0, full.size() - 5));
      ReadPlyMesh(path);
    });
    EXPECT_NE(binary_cut.find("truncated"), std::string::npos) << binary_cut;
  }
}

TEST(PlyTest, BadInputsNameTheFault) {
  TempDir dir;
  const std::string path = dir / "bad.ply";
  auto error_for = [&](const std::string& contents) {
    WriteBytes(path, contents);
    const std::string message = ErrorOf([&] { ReadPlyMesh(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    return message;
  };
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  EXPECT_NE(error_for("PLY\nformat ascii 1.0\nend_header\n").find("magic"),
            std::string::npos);
  EXPECT_NE(error_for("").find("magic"), std::string::npos);
  EXPECT_NE(error_for("\x89PNG\r\n").find("magic"), std::string::npos);
  EXPECT_NE(error_for("ply\nformat ascii 1.0\nelement vertex 1\n").find("end_header"),
            std::string::npos);
  EXPECT_NE(
      error_for("ply\nformat binary_middle_endian 1.0\nend_header\n").find("encoding"),
      std::string::npos);
  EXPECT_NE(error_for("ply\nelement vertex 0\nend_header\n").find("format"),
            std::string::npos);
  EXPECT_NE(
      error_for("ply\nformat ascii 1.0\nelement vertex -3\nend_header\n").find("count"),
      std::string::npos);
  EXPECT_NE(error_for("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\n"
                      "end_header\n")
                .find("unknown type"),
            std::string::npos);
  EXPECT_NE(error_for("ply\nformat ascii 1.0\nproperty float x\nend_header\n")
                .find("before any element"),
            std::string::npos);
  EXPECT_NE(error_for("ply\nformat ascii 1.0\nelement vertex 0\nbanana\nend_header\n")
                .find("unknown keyword"),
            std::string::npos);
  EXPECT_NE(error_for("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                      "property float y\nend_header\n1 2\n")
                .find("'z'"),
            std::string::npos);
  EXPECT_NE(error_for("ply\nformat ascii 1.0\nelement face 0\n"
                      "property list uchar int vertex_indices\nend_header\n")
                .find("no vertex element"),
            std::string::npos);
  EXPECT_NE(
      error_for(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").find("refers to vertex 3"),
      std::string::npos);
  EXPECT_NE(
      error_for(header + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n").find("bad vertex index"),
      std::string::npos);
  EXPECT_NE(error_for(header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n").find("at least 3"),
            std::string::npos);
  EXPECT_NE(error_for(header + "0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n").find("bad number"),
            std::string::npos);
  EXPECT_NE(error_for(header + "0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n").find("non-finite"),
            std::string::npos);
  EXPECT_NE(error_for(header + "0 0 0\n1 0 0\n0 1 0\n").find("truncated"),
            std::string::npos);
  // Missing file.
  const std::string missing = ErrorOf([&] { ReadPlyMesh(dir / "nope.ply"); });
  EXPECT_NE(missing.find("nope.ply"), std::string::npos);
}

// Counts far larger than the file must be refused before anything is allocated.
TEST(PlyTest, HugeCountsAreRefusedBeforeAllocating) {
  TempDir dir;
  const std::string path = dir / "huge.ply";
  for (const char* format : {"binary_little_endian", "ascii"}) {
    std::string s = std::string("ply\nformat ") + format +
                    " 1.0\nelement vertex 4000000000000\nproperty float x\n"
                    "property float y\nproperty float z\nend_header\n";
    s += std::string(24, '1');
    WriteBytes(path, s);
    const std::string message = ErrorOf([&] { ReadPlyPointCloud(path); });
    EXPECT_NE(message.find("claims 4000000000000"), std::string::npos) << message;
    s = std::string("ply\nformat ") + format +
        " 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 18446744073709551615\nproperty list uchar int vertex_indices\n"
        "end_header\n3 0 1 2\n";
    WriteBytes(path, s);
    EXPECT_NE(ErrorOf([&] { ReadPlyMesh(path); }).find("claims"), std::string::npos);
  }
  // A face whose list length runs past the end of a binary file.
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list int int vertex_indices\nend_header\n";
  for (int k = 0; k < 3; ++k) AppendRaw<float>(&s, 0.f);
  AppendRaw<int32_t>(&s, 2000000000);
  AppendRaw<int32_t>(&s, 0);
  WriteBytes(path, s);
  EXPECT_NE(ErrorOf([&] { ReadPlyMesh(path); }).find("truncated"), std::string::npos);
  // The same in ASCII, where the length is a number of any size (tests/fuzz/ply_fuzzer).
  WriteBytes(
      path,
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n1e15 0 1 2\n");
  EXPECT_NE(ErrorOf([&] { ReadPlyMesh(path); }).find("truncated"), std::string::npos);
  // A point cloud skips the faces, and skipped a length of 1e150 through an int64_t cast
  // (undefined behaviour, found by tests/fuzz/ply_fuzzer).
  WriteBytes(
      path,
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n1e150 0 1 2\n");
  EXPECT_NE(ErrorOf([&] { ReadPlyPointCloud(path); }).find("truncated"),
            std::string::npos);
}

// An element without properties has records of no bytes: any count fits the file, and
// skipping 4.7e13 of them one by one hung the reader (tests/fuzz/ply_fuzzer). Its records
// are skipped at once, in every encoding; the vertices after it are read.
TEST(PlyTest, ElementsWithoutPropertiesAreSkippedWhateverTheirCount) {
  TempDir dir;
  const std::string path = dir / "empty_records.ply";
  for (const char* format : {"binary_big_endian", "binary_little_endian", "ascii"}) {
    std::string s = std::string("ply\nformat ") + format +
                    " 1.0\nelement junk 18446744073709551615\nelement vertex 1\n"
                    "property uchar x\nproperty uchar y\nproperty uchar z\nend_header\n";
    s += std::string(format) == "ascii" ? "1 2 3\n" : "\x01\x02\x03";
    WriteBytes(path, s);
    const PointCloud cloud = ReadPlyPointCloud(path);
    ASSERT_EQ(cloud.points.size(), 1u) << format;
    EXPECT_EQ(cloud.points[0], Eigen::Vector3d(1, 2, 3)) << format;
  }
}

TEST(PlyTest, WriterRefusesWhatItCannotWrite) {
  TempDir dir;
  TriangleMesh mesh = RandomMesh(10, 5, true, true);
  mesh.faces.push_back({0, 1, 10});
  EXPECT_NE(ErrorOf([&] { WritePlyMesh(dir / "w.ply", mesh); }).find("face 5"),
            std::string::npos);
  mesh.faces.pop_back();
  mesh.normals.pop_back();
  EXPECT_NE(ErrorOf([&] { WritePlyMesh(dir / "w.ply", mesh); }).find("normals"),
            std::string::npos);
  mesh.normals.clear();
  mesh.vertices[3].x() = std::nan("");
  EXPECT_NE(ErrorOf([&] { WritePlyMesh(dir / "w.ply", mesh); }).find("not finite"),
            std::string::npos);
  mesh.vertices[3].x() = 1e300;
  EXPECT_NE(ErrorOf([&] { WritePlyMesh(dir / "w.ply", mesh); }).find("float"),
            std::string::npos);
  PlyWriteOptions dbl;
  dbl.double_precision = true;
  WritePlyMesh(dir / "w.ply", mesh, dbl);
  EXPECT_EQ(ReadPlyMesh(dir / "w.ply").vertices[3].x(), 1e300);
  // Failed writes leave no file (and no temporary) behind.
  std::string listing;
  testing::RunShell("ls " + dir.path(), &listing);
  EXPECT_EQ(listing, "w.ply\n");
}

TEST(PlyTest, ReadsAMillionFaceBinaryMesh) {
  TempDir dir;
  const TriangleMesh sphere = testing::MakeSphere(7);  // 327680 faces
  TriangleMesh mesh = sphere;
  for (int copy = 1; copy < 3; ++copy) {
    const int base = static_cast<int>(mesh.vertices.size());
    for (const auto& v : sphere.vertices)
      mesh.vertices.push_back(v + Eigen::Vector3d(3 * copy, 0, 0));
    for (const auto& f : sphere.faces)
      mesh.faces.push_back(f + Eigen::Vector3i::Constant(base));
  }
  WritePlyMesh(dir / "big.ply", mesh);
  const TriangleMesh back = ReadPlyMesh(dir / "big.ply");
  EXPECT_EQ(back.faces, mesh.faces);
  EXPECT_EQ(back.vertices.size(), mesh.vertices.size());
}

}  // namespace
}  // namespace fvs
