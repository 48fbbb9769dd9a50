// COLMAP 3.8's text sparse model (Reconstruction::ReadText / WriteText). Numbers are
// written with 17 significant digits (as COLMAP does) so that text round trips are exact.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <type_traits>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/model_checks.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

// Tokens of one data line with the file and line number for error messages.
class LineTokens {
 public:
  LineTokens(const std::string& path, int line_number, const std::string& line)
      : path_(path), line_number_(line_number) {
    // Split by hand: an istringstream per line is the slowest part of reading big models.
    size_t begin = line.find_first_not_of(" \t\r");
    while (begin != std::string::npos) {
      const size_t end = line.find_first_of(" \t\r", begin);
      tokens_.push_back(line.substr(begin, end == std::string::npos ? end : end - begin));
      begin = end == std::string::npos ? end : line.find_first_not_of(" \t\r", end);
    }
  }

  size_t size() const { return tokens_.size(); }
  bool done() const { return next_ >= tokens_.size(); }

  const std::string& Next(const char* what) {
    if (done()) Fail(std::string("missing ") + what);
    return tokens_[next_++];
  }
  double Double(const char* what) {
    const std::string& s = Next(what);
    errno = 0;
    char* end = nullptr;
    const double value = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || s.empty())
      Fail(std::string("bad ") + what + " '" + s + "'");
    return value;
  }
  uint64_t Unsigned(const char* what, uint64_t max_value) {
    const std::string& s = Next(what);
    errno = 0;
    char* end = nullptr;
    const unsigned long long value = std::strtoull(s.c_str(), &end, 10);
    if (end != s.c_str() + s.size() || s.empty() || s[0] == '-' || errno == ERANGE ||
        value > max_value) {
      Fail(std::string("bad ") + what + " '" + s + "'");
    }
    return value;
  }
  // A point3D id: -1 means none.
  uint64_t Point3DId() {
    const std::string& s = Next("point3D id");
    if (s == "-1") return kInvalidPoint3DId;
    --next_;
    return Unsigned("point3D id", kInvalidPoint3DId - 1);
  }
  void ExpectDone() {
    if (!done()) Fail("unexpected extra value '" + tokens_[next_] + "'");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error(path_, "line " + std::to_string(line_number_) + ": " + what);
  }

 private:
  std::string path_;
  int line_number_;
  std::vector<std::string> tokens_;
  size_t next_ = 0;
};

std::string TrimLine(std::string line) {
  const size_t begin = line.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const size_t end = line.find_last_not_of(" \t\r\n");
  return line.substr(begin, end - begin + 1);
}

std::ifstream OpenText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open");
  return in;
}

// Calls record(tokens, in, &line_number) for every line that is neither empty nor a
// comment; `record` may read further lines of the record from `in`.
template <typename Record>
void ForEachRecord(const std::string& path, Record record) {
  std::ifstream in = OpenText(path);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    line = TrimLine(line);
    if (line.empty() || line[0] == '#') continue;
    LineTokens tokens(path, line_number, line);
    record(tokens, in, &line_number);
  }
  if (in.bad()) throw Error(path, "read failed");
}

// Runs one of the internal::Check* validators and reports its complaint on the line.
template <typename Check>
void CheckOnLine(const LineTokens& tokens, const std::string& path, Check check) {
  try {
    check();
  } catch (const Error& e) {
    tokens.Fail(std::string(e.what()).substr(path.size() + 2));
  }
}

void ReadCameras(const std::string& path, Reconstruction* rec) {
  ForEachRecord(path, [&](LineTokens& tokens, std::ifstream&, int*) {
    Camera camera;
    camera.camera_id = tokens.Unsigned("camera id", UINT32_MAX);
    const std::string model = tokens.Next("camera model");
    camera.model_id = CameraModelIdFromName(model);
    if (camera.model_id < 0) tokens.Fail("unknown camera model '" + model + "'");
    camera.width = tokens.Unsigned("camera width", UINT64_MAX);
    camera.height = tokens.Unsigned("camera height", UINT64_MAX);
    while (!tokens.done()) camera.params.push_back(tokens.Double("camera parameter"));
    CheckOnLine(tokens, path, [&] { internal::CheckCamera(camera, path); });
    if (!rec->cameras.emplace(camera.camera_id, camera).second) {
      tokens.Fail("duplicate camera id " + std::to_string(camera.camera_id));
    }
  });
}

void ReadImages(const std::string& path, Reconstruction* rec) {
  ForEachRecord(path, [&](LineTokens& tokens, std::ifstream& in, int* line_number) {
    Image image;
    image.image_id = tokens.Unsigned("image id", UINT32_MAX);
    for (int k = 0; k < 4; ++k) image.qvec(k) = tokens.Double("qvec");
    for (int k = 0; k < 3; ++k) image.tvec(k) = tokens.Double("tvec");
    image.camera_id = tokens.Unsigned("camera id", UINT32_MAX);
    image.name = tokens.Next("image name");
    tokens.ExpectDone();
    // The 2D points are on the next line, which is empty for an image without any.
    std::string line;
    if (!std::getline(in, line)) {
      tokens.Fail("missing the 2D points line of image " +
                  std::to_string(image.image_id));
    }
    ++*line_number;
    LineTokens points(path, *line_number, TrimLine(line));
    if (points.size() % 3 != 0) {
      points.Fail("2D points need 3 values each (X, Y, POINT3D_ID), got " +
                  std::to_string(points.size()));
    }
    image.points2D.resize(points.size() / 3);
    for (Point2D& p : image.points2D) {
      p.xy.x() = points.Double("2D point x");
      p.xy.y() = points.Double("2D point y");
      p.point3D_id = points.Point3DId();
    }
    CheckOnLine(tokens, path, [&] { internal::CheckImage(image, path); });
    if (!rec->images.emplace(image.image_id, std::move(image)).second) {
      tokens.Fail("duplicate image id");
    }
  });
}

void ReadPoints3D(const std::string& path, Reconstruction* rec) {
  ForEachRecord(path, [&](LineTokens& tokens, std::ifstream&, int*) {
    const uint64_t id = tokens.Unsigned("point3D id", kInvalidPoint3DId - 1);
    Point3D point;
    for (int k = 0; k < 3; ++k) point.xyz(k) = tokens.Double("point3D position");
    for (int k = 0; k < 3; ++k) point.color[k] = tokens.Unsigned("colour", 255);
    point.error = tokens.Double("error");
    if ((tokens.size() - 8) % 2 != 0)
      tokens.Fail("track needs (IMAGE_ID, POINT2D_IDX) pairs");
    while (!tokens.done()) {
      TrackElement el;
      el.image_id = tokens.Unsigned("track image id", UINT32_MAX);
      el.point2D_idx = tokens.Unsigned("track point2D index", UINT32_MAX);
      point.track.push_back(el);
    }
    CheckOnLine(tokens, path, [&] { internal::CheckPoint3D(id, point, path); });
    if (!rec->points3D.emplace(id, std::move(point)).second) {
      tokens.Fail("duplicate point3D id " + std::to_string(id));
    }
  });
}

// One line of output. Doubles are printed as printf("%.17g") (what COLMAP's streams with
// precision 17 print) through std::to_chars, which is several times faster than a stream.
class LineWriter {
 public:
  LineWriter& operator<<(double v) {
    char buffer[32];
    const auto result =
        std::to_chars(buffer, buffer + sizeof(buffer), v, std::chars_format::general, 17);
    text_.append(buffer, result.ptr);
    return *this;
  }
  template <typename T, typename = std::enable_if_t<std::is_integral<T>::value>>
  LineWriter& operator<<(T v) {
    char buffer[24];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
    text_.append(buffer, result.ptr);
    return *this;
  }
  LineWriter& operator<<(const std::string& s) {
    text_ += s;
    return *this;
  }
  LineWriter& operator<<(const char* s) {
    text_ += s;
    return *this;
  }
  const std::string& str() const { return text_; }

 private:
  std::string text_;
};

// COLMAP ends each value with a space and then drops the last one.
std::string FormatLine(const LineWriter& line) {
  std::string s = line.str();
  if (!s.empty() && s.back() == ' ') s.pop_back();
  s += '\n';
  return s;
}

size_t NumObservations(const Reconstruction& rec) {
  size_t n = 0;
  for (const auto& [id, image] : rec.images) {
    for (const Point2D& p : image.points2D) n += p.point3D_id != kInvalidPoint3DId;
  }
  return n;
}

}  // namespace

Reconstruction ReadSparseModelText(const std::string& dir) {
  Reconstruction rec;
  ReadCameras(dir + "/cameras.txt", &rec);
  ReadImages(dir + "/images.txt", &rec);
  ReadPoints3D(dir + "/points3D.txt", &rec);
  internal::CheckReferences(rec, dir + "/images.txt", dir + "/points3D.txt");
  return rec;
}

void WriteSparseModelText(const std::string& dir, const Reconstruction& rec) {
  rec.Check(dir);
  for (const auto& [id, image] : rec.images) {
    if (image.name.find_first_of(" \t\r\n") != std::string::npos) {
      throw Error(dir,
                  "image name '" + image.name +
                      "' contains white space, which COLMAP's text format cannot hold");
    }
  }
  CreateDirectories(dir);
  const size_t num_observations = NumObservations(rec);
  // Renamed into place only when all three files are complete (see the binary writer).
  AtomicFile cameras_file(dir + "/cameras.txt");
  AtomicFile images_file(dir + "/images.txt");
  AtomicFile points_file(dir + "/points3D.txt");
  {
    std::ostream& out = cameras_file.stream();
    out.precision(17);
    out << "# Camera list with one line of data per camera:\n"
        << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        << "# Number of cameras: " << rec.cameras.size() << "\n";
    for (const auto& [id, camera] : rec.cameras) {
      LineWriter line;
      line << id << " " << CameraModelName(camera.model_id) << " " << camera.width << " "
           << camera.height << " ";
      for (const double p : camera.params) line << p << " ";
      out << FormatLine(line);
    }
  }
  {
    std::ostream& out = images_file.stream();
    out.precision(17);
    const double mean_observations =
        rec.images.empty() ? 0.0
                           : num_observations / static_cast<double>(rec.images.size());
    out << "# Image list with two lines of data per image:\n"
        << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
        << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
        << "# Number of images: " << rec.images.size()
        << ", mean observations per image: " << mean_observations << "\n";
    for (const auto& [id, image] : rec.images) {
      LineWriter line;
      line << id << " ";
      for (int k = 0; k < 4; ++k) line << image.qvec(k) << " ";
      for (int k = 0; k < 3; ++k) line << image.tvec(k) << " ";
      line << image.camera_id << " " << image.name << " ";
      out << FormatLine(line);
      LineWriter points;
      for (const Point2D& p : image.points2D) {
        points << p.xy.x() << " " << p.xy.y() << " ";
        if (p.point3D_id == kInvalidPoint3DId) {
          points << -1 << " ";
        } else {
          points << p.point3D_id << " ";
        }
      }
      out << FormatLine(points);
    }
  }
  {
    std::ostream& out = points_file.stream();
    out.precision(17);
    const double mean_track_length =
        rec.points3D.empty()
            ? 0.0
            : num_observations / static_cast<double>(rec.points3D.size());
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << "# Number of points: " << rec.points3D.size()
        << ", mean track length: " << mean_track_length << "\n";
    for (const auto& [id, point] : rec.points3D) {
      LineWriter line;
      line << id << " ";
      for (int k = 0; k < 3; ++k) line << point.xyz(k) << " ";
      for (int k = 0; k < 3; ++k) line << static_cast<int>(point.color[k]) << " ";
      line << point.error << " ";
      for (const TrackElement& el : point.track) {
        line << el.image_id << " " << el.point2D_idx << " ";
      }
      out << FormatLine(line);
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
