// Writes the generated seed corpora: make_seeds OUT_DIR fills OUT_DIR/<target>/ with
// small valid files made by our own writers (the formats as our stages write them, so
// the fuzzer starts from inputs that get through the readers), plus a few hand-made
// variants a writer does not produce (big-endian PLY, other image formats, a COLMAP
// database). Text seeds that need no writer are committed in tests/fuzz/seeds/.
#include <sqlite3.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "../support/tiled_tiff.h"
#include "colmap_ext/camera_models.h"
#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "fuzz_support.h"
#include "fvs/geometry/ply.h"
#include "fvs/net/model_config.h"
#include "fvs/path/camera_path.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/manifest.h"
#include "fvs/util/safetensors.h"

namespace fvs::fuzz {
namespace {

namespace fs = std::filesystem;

std::string g_out;

void Seed(const std::string& target, const std::string& name, const std::string& bytes) {
  fs::create_directories(g_out + "/" + target);
  std::ofstream out(g_out + "/" + target + "/" + name, std::ios::binary);
  out << bytes;
  if (!out) throw Error(g_out + "/" + target + "/" + name, "cannot write seed");
}

std::string Slurp(const std::string& path) { return ReadFileToString(path); }

// Two cameras (one distorted), three images with points, two 3D points.
colmap::Reconstruction SmallModel() {
  colmap::Reconstruction r;
  r.cameras[1] = {1, colmap::kPinhole, 8, 6, {8, 8, 4, 3}};
  r.cameras[2] = {2, colmap::kOpenCV, 8, 6, {8, 8, 4, 3, 0.01, -0.01, 0.001, 0.001}};
  for (uint32_t id = 1; id <= 3; ++id) {
    colmap::Image& image = r.images[id];
    image.image_id = id;
    image.camera_id = id == 3 ? 2 : 1;
    image.name = "frame_000" + std::to_string(id) + ".png";
    image.qvec = Eigen::Vector4d(0.99, 0.01 * id, 0, 0).normalized();
    image.tvec = Eigen::Vector3d(0.5 * id, 0, 0);
    image.points2D.resize(3);
    for (int p = 0; p < 3; ++p) image.points2D[p].xy = Eigen::Vector2d(p + 0.5, 2.5);
  }
  for (uint64_t p = 1; p <= 2; ++p) {
    colmap::Point3D& point = r.points3D[p];
    point.xyz = Eigen::Vector3d(0.1 * p, 0.2, 4);
    point.color = {10, 200, 30};
    point.error = 0.5;
    for (uint32_t id = 1; id <= 3; ++id) {
      r.images[id].points2D[p].point3D_id = p;
      point.track.push_back({id, static_cast<uint32_t>(p)});
    }
  }
  return r;
}

void SparseSeeds(const std::string& scratch) {
  const colmap::Reconstruction model = SmallModel();
  colmap::WriteSparseModelBinary(scratch + "/bin", model);
  colmap::WriteSparseModelText(scratch + "/txt", model);
  for (const auto& [ext, target] :
       {std::pair<std::string, std::string>{"bin", "sparse_binary"},
        {"txt", "sparse_text"}}) {
    const std::string dir = scratch + "/" + ext;
    Seed(target, "model",
         Slurp(dir + "/cameras." + ext) + kSeparator + Slurp(dir + "/images." + ext) +
             kSeparator + Slurp(dir + "/points3D." + ext));
  }
}

void DenseSeeds(const std::string& scratch) {
  fvs::Image depth(4, 3, 1);
  fvs::Image normals(3, 2, 3);
  for (size_t i = 0; i < depth.data.size(); ++i) depth.data[i] = 1.0f + 0.25f * i;
  for (size_t i = 0; i < normals.data.size(); ++i) normals.data[i] = i % 3 == 2 ? -1 : 0;
  colmap::WriteColmapArray(scratch + "/depth.bin", depth);
  colmap::WriteColmapArray(scratch + "/normal.bin", normals);
  Seed("dense_array", "depth", Slurp(scratch + "/depth.bin"));
  Seed("dense_array", "normal", Slurp(scratch + "/normal.bin"));
  colmap::WriteFusedVisibility(scratch + "/fused.ply.vis", {{0, 1}, {2}, {0, 1, 2}});
  Seed("fused_vis", "vis", Slurp(scratch + "/fused.ply.vis"));
}

void PlySeeds(const std::string& scratch) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1.5}};
  mesh.normals = {{0, 0, -1}, {0, 0, -1}, {0, 0, -1}, {0, 0, -1}};
  mesh.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {9, 9, 9}};
  mesh.faces = {{0, 1, 2}, {1, 3, 2}};
  PointCloud cloud;
  cloud.points = mesh.vertices;
  cloud.normals = mesh.normals;
  cloud.colors = mesh.colors;
  int n = 0;
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    for (const bool double_precision : {false, true}) {
      const PlyWriteOptions options{format, double_precision};
      const std::string mesh_path = scratch + "/mesh" + std::to_string(n) + ".ply";
      const std::string cloud_path = scratch + "/cloud" + std::to_string(n) + ".ply";
      WritePlyMesh(mesh_path, mesh, options);
      WritePlyPointCloud(cloud_path, cloud, options);
      Seed("ply", "mesh" + std::to_string(n), Slurp(mesh_path));
      Seed("ply", "cloud" + std::to_string(n), Slurp(cloud_path));
      ++n;
    }
  }
  // Big endian, float coordinates, a quad (fan-triangulated) with an int list count.
  std::string big =
      "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  auto put_be = [&big](const void* p, size_t bytes) {
    const auto* b = static_cast<const char*>(p);
    for (size_t i = 0; i < bytes; ++i) big += b[bytes - 1 - i];
  };
  for (const Eigen::Vector3d& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      const float f = static_cast<float>(v[k]);
      put_be(&f, 4);
    }
  }
  big += '\4';
  for (int32_t i = 0; i < 4; ++i) put_be(&i, 4);
  Seed("ply", "big_endian_quad", big);
}

void CameraPathSeeds(const std::string& scratch) {
  CameraPathKeyframe a, b;
  a.name = "frame_0001.png";
  a.camera.width = 8;
  a.camera.height = 6;
  a.camera.fx = a.camera.fy = 8;
  a.camera.cx = 4;
  a.camera.cy = 3;
  b = a;
  b.name = "frame_0002.png";
  b.camera.t = Eigen::Vector3d(0.5, 0, 0);
  std::vector<TargetCamera> frames = {{"frame_00000", a.camera, ""},
                                      {"frame_00001", b.camera, ""}};
  WriteNerfstudioCameraPath(scratch + "/path.json", {a, b}, frames, {});
  Seed("camera_path", "written", Slurp(scratch + "/path.json"));
  WriteTargetImagesTxt(scratch + "/targets/images.txt", frames);
  Seed("target_images", "written",
       Slurp(scratch + "/targets/images.txt") + kSeparator +
           Slurp(scratch + "/targets/cameras.txt"));
  Seed("target_images", "workspace_camera", Slurp(scratch + "/targets/images.txt"));
}

void SafetensorsSeeds(const std::string& scratch) {
  SafeTensorsFile file;
  const float values[6] = {1, -2, 3.5f, 0, 1e-3f, 65504};
  file.Add(SafeTensor::FromFloats("conv.weight", {2, 3}, values));
  SafeTensor half;
  half.name = "half";
  half.dtype = SafeDtype::kF16;
  half.shape = {2};
  for (const float v : {1.5f, -0.25f}) {
    const uint16_t h = FloatToHalf(v);
    half.data.push_back(h & 0xff);
    half.data.push_back(h >> 8);
  }
  file.Add(half);
  SafeTensor bf = half;
  bf.name = "bfloat";
  bf.dtype = SafeDtype::kBF16;
  file.Add(bf);
  SafeTensor bytes;
  bytes.name = "images";
  bytes.dtype = SafeDtype::kU8;
  bytes.shape = {1, 3, 2, 2};
  bytes.data.assign(12, 7);
  file.Add(bytes);
  SafeTensor scalar;
  scalar.name = "step";
  scalar.dtype = SafeDtype::kI64;
  scalar.data.assign(8, 0);
  scalar.data[0] = 42;
  file.Add(scalar);
  file.metadata["fvs_config"] = ModelConfig::ForVariant("fvs_fast").ToJson();
  file.metadata["names"] = "[\"frame_0001.png\", \"frame_0002.png\"]";
  Seed("safetensors", "weights", SerializeSafeTensors(file));
  SafeTensorsFile empty;
  Seed("safetensors", "empty", SerializeSafeTensors(empty));
}

void ManifestSeeds(const std::string& scratch) {
  const std::string root = scratch + "/ws";
  fs::create_directories(root + "/sparse");
  WriteFileAtomic(root + "/sparse/cameras.bin", [](std::ostream& out) { out << "x"; });
  Manifest manifest = Manifest::Load(root + "/manifest.json", root);
  manifest.Record("feature_extraction",
                  Manifest::Fingerprint({root + "/sparse"}, "opt", root),
                  {root + "/database.db"}, 1.5);
  manifest.Record("mapper", "fingerprint", {root + "/sparse", "/elsewhere/photos"}, 2);
  manifest.Save();
  Seed("manifest", "manifest", Slurp(root + "/manifest.json"));
}

std::string FromHex(const std::string& hex) {
  std::string bytes;
  for (size_t i = 0; i + 1 < hex.size(); i += 2) {
    bytes += static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16));
  }
  return bytes;
}

void ImageSeeds(const std::string& scratch) {
  fvs::Image rgb(8, 6, 3);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = (i % 17) / 16.0f;
  fvs::Image grey(5, 4, 1, 0.5f);
  // The first byte selects the extension in image_fuzzer.cc's table.
  const struct {
    const char* name;
    char selector;
    const fvs::Image* image;
    int bits;
  } kImages[] = {{"png8.png", 0, &rgb, 8},  {"png16.png", 0, &rgb, 16},
                 {"grey.png", 0, &grey, 8}, {"jpeg.jpg", 1, &rgb, 8},
                 {"tiff.tif", 2, &rgb, 32}, {"exr.exr", 3, &rgb, 32},
                 {"bmp.bmp", 4, &rgb, 8},   {"ppm.ppm", 5, &rgb, 8},
                 {"hdr.hdr", 6, &rgb, 8},   {"tga.tga", 7, &rgb, 8}};
  for (const auto& image : kImages) {
    const std::string path = scratch + "/" + image.name;
    try {
      colmap::WriteImage(path, *image.image, image.bits);
    } catch (const Error& e) {
      std::cerr << "make_seeds: skipping " << image.name << ": " << e.what() << "\n";
      continue;
    }
    Seed("image", image.name, std::string(1, image.selector) + Slurp(path));
  }
  // The headers image_fuzzer found claiming absurd sizes (doc/reliability.md, findings),
  // as .ppm (selector 5) or .tif (selector 2): the CI smoke step runs them.
  Seed("image", "pbm_51gb",
       std::string(1, 5) + "P4\n066666666666 6\n" + std::string(16, '\x66'));
  Seed("image", "pbm_grey_as_rgb", std::string(1, 5) + "P4\n077777777 6\n");
  Seed("image", "tiff_huge_tiles",
       std::string(1, 2) + fvs::testing::TiledTiffBytes(65536));
  Seed("image", "tiff_tiles", std::string(1, 2) + fvs::testing::TiledTiffBytes(64));
  Seed("image", "tiff_missing_strips",
       std::string(1, 2) + fvs::testing::StrippedTiffBytes(16396, 13408));
  Seed("image", "pbm_wide", std::string(1, 5) + "P4\n21474837 7 21474836477");
  Seed("image", "pbm_2_to_62_pixels", std::string(1, 5) + "P4\n2147483647 2147483647\n");
  // 185 bytes that OpenImageIO decodes as 8 x 65 293 pixels of 512 channels (zeros where
  // the strips are missing): read as RGB it held 1 GiB of floats before the channels were
  // converted band by band.
  Seed("image", "tiff_512_channels",
       std::string(1, 2) +
           FromHex(
               "49492a00080000000e0000010300010000000800000001010300010000000dffffffffff"
               "ffffff000000b6005a420300030001000000080000000601030001000000055034323137"
               "333837203634362037950a01030001000000080000000601030001000000020000001101"
               "040001000000d60000000b01030001000000010000001501030001000000000200000016"
               "0103000100000020000000170104000100000000003d32333a33351c1c1c1c1c1c1c1c1c"
               "1c1c1c0335"));
}

// An SQL blob literal of little-endian doubles (COLMAP's camera parameters).
std::string DoublesBlob(const std::vector<double>& values) {
  std::string hex = "X'";
  for (const double v : values) {
    unsigned char bytes[sizeof(double)];
    std::memcpy(bytes, &v, sizeof(double));
    for (const unsigned char b : bytes) {
      hex += "0123456789ABCDEF"[b >> 4];
      hex += "0123456789ABCDEF"[b & 15];
    }
  }
  return hex + "'";
}

// COLMAP 3.8's schema (the columns ReadDatabase reads), two cameras, three images with
// keypoints and pose priors, one match and one verified pair; 512-byte pages keep it
// small.
void DatabaseSeeds(const std::string& scratch) {
  const std::string path = scratch + "/database.db";
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw Error(path, "cannot create");
  const std::string sql =
      std::string("PRAGMA page_size=512;") +
      "CREATE TABLE cameras (camera_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL, "
      "model INTEGER NOT NULL, width INTEGER NOT NULL, height INTEGER NOT NULL, "
      "params BLOB, prior_focal_length INTEGER NOT NULL);"
      "CREATE TABLE images (image_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL, "
      "name TEXT NOT NULL UNIQUE, camera_id INTEGER NOT NULL, prior_qw REAL, prior_qx "
      "REAL, prior_qy REAL, prior_qz REAL, prior_tx REAL, prior_ty REAL, prior_tz REAL);"
      "CREATE TABLE keypoints (image_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT "
      "NULL, cols INTEGER NOT NULL, data BLOB);"
      "CREATE TABLE matches (pair_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT "
      "NULL, cols INTEGER NOT NULL, data BLOB);"
      "CREATE TABLE two_view_geometries (pair_id INTEGER PRIMARY KEY NOT NULL, rows "
      "INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB, config INTEGER NOT NULL);" +
      "INSERT INTO cameras VALUES (1, 1, 8, 6, " + DoublesBlob({8, 8, 4, 3}) + ", 0);" +
      "INSERT INTO cameras VALUES (2, 0, 8, 6, " + DoublesBlob({8, 4, 3}) + ", 1);" +
      "INSERT INTO images VALUES (1, 'a.png', 1, 1, 0, 0, 0, 0.5, 0, 0);"
      "INSERT INTO images VALUES (2, 'b.png', 1, NULL, NULL, NULL, NULL, NULL, NULL, "
      "NULL);"
      "INSERT INTO images VALUES (3, 'sub/c.png', 2, 1, 0, 0, 0, 1, 2, 3);"
      "INSERT INTO keypoints VALUES (1, 12, 6, NULL);"
      "INSERT INTO keypoints VALUES (2, 7, 6, NULL);"
      "INSERT INTO matches VALUES (2147483650, 5, 2, NULL);"
      "INSERT INTO two_view_geometries VALUES (2147483650, 4, 2, NULL, 2);";
  char* message = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string what = message ? message : "sqlite error";
    sqlite3_free(message);
    sqlite3_close(db);
    throw Error(path, what);
  }
  sqlite3_close(db);
  Seed("database", "colmap38", Slurp(path));
}

}  // namespace
}  // namespace fvs::fuzz

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_seeds OUT_DIR\n";
    return 2;
  }
  using namespace fvs::fuzz;
  g_out = argv[1];
  try {
    const std::string scratch = ScratchDir();
    SparseSeeds(scratch);
    DenseSeeds(scratch);
    PlySeeds(scratch);
    CameraPathSeeds(scratch);
    SafetensorsSeeds(scratch);
    ManifestSeeds(scratch);
    ImageSeeds(scratch);
    DatabaseSeeds(scratch);
  } catch (const std::exception& e) {
    std::cerr << "make_seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
