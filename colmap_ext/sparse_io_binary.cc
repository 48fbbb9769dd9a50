// COLMAP 3.8's binary sparse model (Reconstruction::ReadBinary / WriteBinary).
#include <sys/stat.h>

#include <fstream>

#include "colmap_ext/binary_buffer.h"
#include "colmap_ext/camera_models.h"
#include "colmap_ext/model_checks.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

using internal::BinaryReader;
using internal::WriteLE;

// Smallest encodings, to bound counts against the bytes left in the file.
constexpr size_t kMinCameraBytes = 4 + 4 + 8 + 8 + 3 * 8;
constexpr size_t kMinImageBytes = 4 + 7 * 8 + 4 + 1 + 8;
constexpr size_t kPoint2DBytes = 8 + 8 + 8;
constexpr size_t kMinPoint3DBytes = 8 + 3 * 8 + 3 + 8 + 8;
constexpr size_t kTrackElementBytes = 4 + 4;

BinaryReader OpenBinary(const std::string& path) {
  return BinaryReader(path, ReadFileToString(path));
}

void ReadCameras(const std::string& path, Reconstruction* rec) {
  BinaryReader in = OpenBinary(path);
  const uint64_t num = in.ReadCount("number of cameras", kMinCameraBytes);
  for (uint64_t i = 0; i < num; ++i) {
    Camera camera;
    camera.camera_id = in.Read<uint32_t>("camera id");
    camera.model_id = in.Read<int32_t>("camera model");
    if (!IsKnownCameraModel(camera.model_id)) {
      in.Fail("camera " + std::to_string(camera.camera_id) +
              ": unknown camera model id " + std::to_string(camera.model_id));
    }
    camera.width = in.Read<uint64_t>("camera width");
    camera.height = in.Read<uint64_t>("camera height");
    camera.params.resize(CameraModelNumParams(camera.model_id));
    for (double& p : camera.params) p = in.Read<double>("camera parameters");
    internal::CheckCamera(camera, path);
    if (!rec->cameras.emplace(camera.camera_id, camera).second) {
      in.Fail("duplicate camera id " + std::to_string(camera.camera_id));
    }
  }
  in.ExpectEnd();
}

void ReadImages(const std::string& path, Reconstruction* rec) {
  BinaryReader in = OpenBinary(path);
  const uint64_t num = in.ReadCount("number of images", kMinImageBytes);
  for (uint64_t i = 0; i < num; ++i) {
    Image image;
    image.image_id = in.Read<uint32_t>("image id");
    for (int k = 0; k < 4; ++k) image.qvec(k) = in.Read<double>("image qvec");
    for (int k = 0; k < 3; ++k) image.tvec(k) = in.Read<double>("image tvec");
    image.camera_id = in.Read<uint32_t>("image camera id");
    image.name = in.ReadCString("image name");
    const uint64_t num_points2D = in.ReadCount("number of 2D points", kPoint2DBytes);
    image.points2D.resize(num_points2D);
    for (Point2D& p : image.points2D) {
      p.xy.x() = in.Read<double>("2D point");
      p.xy.y() = in.Read<double>("2D point");
      p.point3D_id = in.Read<uint64_t>("2D point's point3D id");
    }
    internal::CheckImage(image, path);
    if (!rec->images.emplace(image.image_id, std::move(image)).second) {
      in.Fail("duplicate image id");
    }
  }
  in.ExpectEnd();
}

void ReadPoints3D(const std::string& path, Reconstruction* rec) {
  BinaryReader in = OpenBinary(path);
  const uint64_t num = in.ReadCount("number of 3D points", kMinPoint3DBytes);
  for (uint64_t i = 0; i < num; ++i) {
    const uint64_t id = in.Read<uint64_t>("point3D id");
    Point3D point;
    for (int k = 0; k < 3; ++k) point.xyz(k) = in.Read<double>("point3D position");
    for (int k = 0; k < 3; ++k) point.color[k] = in.Read<uint8_t>("point3D colour");
    point.error = in.Read<double>("point3D error");
    const uint64_t track_length = in.ReadCount("track length", kTrackElementBytes);
    point.track.resize(track_length);
    for (TrackElement& el : point.track) {
      el.image_id = in.Read<uint32_t>("track image id");
      el.point2D_idx = in.Read<uint32_t>("track point2D index");
    }
    internal::CheckPoint3D(id, point, path);
    if (!rec->points3D.emplace(id, std::move(point)).second) {
      in.Fail("duplicate point3D id " + std::to_string(id));
    }
  }
  in.ExpectEnd();
}

}  // namespace

Reconstruction ReadSparseModelBinary(const std::string& dir) {
  Reconstruction rec;
  ReadCameras(dir + "/cameras.bin", &rec);
  ReadImages(dir + "/images.bin", &rec);
  ReadPoints3D(dir + "/points3D.bin", &rec);
  internal::CheckReferences(rec, dir + "/images.bin", dir + "/points3D.bin");
  return rec;
}

void WriteSparseModelBinary(const std::string& dir, const Reconstruction& rec) {
  rec.Check(dir);
  CreateDirectories(dir);
  // All three files are written to temporaries first and renamed only when all are
  // complete, so a failure (disk full) never mixes an old and a new file.
  AtomicFile cameras_file(dir + "/cameras.bin");
  AtomicFile images_file(dir + "/images.bin");
  AtomicFile points_file(dir + "/points3D.bin");
  {
    std::ostream& out = cameras_file.stream();
    WriteLE<uint64_t>(out, rec.cameras.size());
    for (const auto& [id, camera] : rec.cameras) {
      WriteLE<uint32_t>(out, id);
      WriteLE<int32_t>(out, camera.model_id);
      WriteLE<uint64_t>(out, camera.width);
      WriteLE<uint64_t>(out, camera.height);
      for (const double p : camera.params) WriteLE<double>(out, p);
    }
  }
  {
    std::ostream& out = images_file.stream();
    WriteLE<uint64_t>(out, rec.images.size());
    for (const auto& [id, image] : rec.images) {
      WriteLE<uint32_t>(out, id);
      for (int k = 0; k < 4; ++k) WriteLE<double>(out, image.qvec(k));
      for (int k = 0; k < 3; ++k) WriteLE<double>(out, image.tvec(k));
      WriteLE<uint32_t>(out, image.camera_id);
      out.write(image.name.c_str(), image.name.size() + 1);
      WriteLE<uint64_t>(out, image.points2D.size());
      for (const Point2D& p : image.points2D) {
        WriteLE<double>(out, p.xy.x());
        WriteLE<double>(out, p.xy.y());
        WriteLE<uint64_t>(out, p.point3D_id);
      }
    }
  }
  {
    std::ostream& out = points_file.stream();
    WriteLE<uint64_t>(out, rec.points3D.size());
    for (const auto& [id, point] : rec.points3D) {
      WriteLE<uint64_t>(out, id);
      for (int k = 0; k < 3; ++k) WriteLE<double>(out, point.xyz(k));
      for (int k = 0; k < 3; ++k) WriteLE<uint8_t>(out, point.color[k]);
      WriteLE<double>(out, point.error);
      WriteLE<uint64_t>(out, point.track.size());
      for (const TrackElement& el : point.track) {
        WriteLE<uint32_t>(out, el.image_id);
        WriteLE<uint32_t>(out, el.point2D_idx);
      }
    }
  }
  for (std::ostream* out :
       {&cameras_file.stream(), &images_file.stream(), &points_file.stream()}) {
    if (!out->flush()) throw Error(dir, "writing the sparse model failed (disk full?)");
  }
  cameras_file.Commit();
  images_file.Commit();
  points_file.Commit();
}

}  // namespace fvs::colmap
