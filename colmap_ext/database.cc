// COLMAP 3.8's database.db through the sqlite3 C API, read-only.
#include "colmap_ext/database.h"

#include <sqlite3.h>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/model_checks.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct StmtFinalizer {
  void operator()(sqlite3_stmt* stmt) const { sqlite3_finalize(stmt); }
};
using DbPtr = std::unique_ptr<sqlite3, DbCloser>;
using StmtPtr = std::unique_ptr<sqlite3_stmt, StmtFinalizer>;

StmtPtr Prepare(sqlite3* db, const std::string& path, const std::string& sql) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
    throw Error(path, std::string("not a COLMAP database (") + sqlite3_errmsg(db) + ")");
  }
  return StmtPtr(stmt);
}

// Steps through all rows, calling fn for each; throws on sqlite errors.
template <typename Fn>
void ForEachRow(sqlite3* db, const std::string& path, const std::string& sql, Fn fn) {
  StmtPtr stmt = Prepare(db, path, sql);
  while (true) {
    const int rc = sqlite3_step(stmt.get());
    if (rc == SQLITE_DONE) break;
    if (rc != SQLITE_ROW) {
      throw Error(path, std::string("database read failed (") + sqlite3_errmsg(db) + ")");
    }
    fn(stmt.get());
  }
}

int64_t NonNegative(sqlite3_stmt* stmt, int column, const std::string& path,
                    const char* what) {
  const int64_t v = sqlite3_column_int64(stmt, column);
  if (v < 0) throw Error(path, std::string("negative ") + what + " in the database");
  return v;
}

// An id (COLMAP's are uint32) or a count that must fit `max`: a larger value would wrap
// in the cast and alias another camera or image silently.
int64_t InRange(sqlite3_stmt* stmt, int column, const std::string& path, const char* what,
                int64_t max) {
  const int64_t v = NonNegative(stmt, column, path, what);
  if (v > max) {
    throw Error(path, std::string(what) + " " + std::to_string(v) +
                          " in the database is out of range (at most " +
                          std::to_string(max) + ")");
  }
  return v;
}

constexpr int64_t kMaxId = std::numeric_limits<uint32_t>::max();

// Seven columns from `first`: qw, qx, qy, qz, tx, ty, tz; NULL or NaN when unknown.
void ReadPosePrior(sqlite3_stmt* s, int first, DatabaseImage* image) {
  double prior[7];
  bool complete = true;
  for (int k = 0; k < 7; ++k) {
    complete = complete && sqlite3_column_type(s, first + k) != SQLITE_NULL;
    prior[k] = sqlite3_column_double(s, first + k);
    complete = complete && std::isfinite(prior[k]);
  }
  const Eigen::Vector4d qvec(prior[0], prior[1], prior[2], prior[3]);
  image->has_prior_pose = complete && qvec.squaredNorm() > 0;
  if (image->has_prior_pose) {
    image->prior_qvec = qvec;
    image->prior_tvec = Eigen::Vector3d(prior[4], prior[5], prior[6]);
  }
}

}  // namespace

DatabaseContents ReadDatabase(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
    throw Error(path, "database file does not exist");
  }
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  DbPtr db(raw);
  if (rc != SQLITE_OK) {
    throw Error(path, std::string("cannot open database (") +
                          (raw ? sqlite3_errmsg(raw) : "out of memory") + ")");
  }
  DatabaseContents contents;
  ForEachRow(db.get(), path,
             "SELECT camera_id, model, width, height, params FROM cameras",
             [&](sqlite3_stmt* s) {
               Camera camera;
               camera.camera_id =
                   static_cast<uint32_t>(InRange(s, 0, path, "camera id", kMaxId));
               camera.model_id = sqlite3_column_int(s, 1);
               camera.width = NonNegative(s, 2, path, "camera width");
               camera.height = NonNegative(s, 3, path, "camera height");
               // COLMAP stores the parameters as a blob of little-endian doubles.
               const int bytes = sqlite3_column_bytes(s, 4);
               const void* blob = sqlite3_column_blob(s, 4);
               if (bytes % sizeof(double) != 0) {
                 throw Error(path, "camera " + std::to_string(camera.camera_id) +
                                       ": parameter blob of " + std::to_string(bytes) +
                                       " bytes is not a list of doubles");
               }
               camera.params.resize(bytes / sizeof(double));
               if (bytes > 0) std::memcpy(camera.params.data(), blob, bytes);
               internal::CheckCamera(camera, path);
               contents.cameras[camera.camera_id] = camera;
             });
  // COLMAP 3.8 keeps pose priors in the images table; later versions moved them out.
  bool has_prior_columns = false;
  ForEachRow(db.get(), path, "PRAGMA table_info(images)", [&](sqlite3_stmt* s) {
    const unsigned char* column = sqlite3_column_text(s, 1);
    if (column && std::strcmp(reinterpret_cast<const char*>(column), "prior_tz") == 0) {
      has_prior_columns = true;
    }
  });
  const std::string image_query =
      has_prior_columns
          ? "SELECT image_id, name, camera_id, prior_qw, prior_qx, prior_qy, "
            "prior_qz, prior_tx, prior_ty, prior_tz FROM images"
          : "SELECT image_id, name, camera_id FROM images";
  ForEachRow(db.get(), path, image_query, [&](sqlite3_stmt* s) {
    DatabaseImage image;
    image.image_id = static_cast<uint32_t>(InRange(s, 0, path, "image id", kMaxId));
    const unsigned char* name = sqlite3_column_text(s, 1);
    image.name = name ? reinterpret_cast<const char*>(name) : "";
    image.camera_id = static_cast<uint32_t>(InRange(s, 2, path, "camera id", kMaxId));
    if (contents.cameras.count(image.camera_id) == 0) {
      throw Error(path, "image " + image.name + " refers to missing camera " +
                            std::to_string(image.camera_id));
    }
    if (has_prior_columns) ReadPosePrior(s, 3, &image);
    contents.images[image.image_id] = image;
  });
  ForEachRow(
      db.get(), path, "SELECT image_id, rows FROM keypoints", [&](sqlite3_stmt* s) {
        const auto it = contents.images.find(
            static_cast<uint32_t>(InRange(s, 0, path, "image id", kMaxId)));
        if (it != contents.images.end()) {
          it->second.num_keypoints = static_cast<int>(
              InRange(s, 1, path, "keypoint count", std::numeric_limits<int>::max()));
        }
      });
  ForEachRow(
      db.get(), path, "SELECT COUNT(*) FROM matches WHERE rows > 0",
      [&](sqlite3_stmt* s) { contents.num_matched_pairs = sqlite3_column_int(s, 0); });
  ForEachRow(
      db.get(), path, "SELECT COUNT(*) FROM two_view_geometries WHERE rows > 0",
      [&](sqlite3_stmt* s) { contents.num_verified_pairs = sqlite3_column_int(s, 0); });
  return contents;
}

}  // namespace fvs::colmap
