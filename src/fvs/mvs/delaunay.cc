// The CGAL / Boost.Graph part of the Delaunay graph-cut mesher (see delaunay.h). This is
// the only translation unit that includes CGAL: it compiles slowly and needs much memory.
#include "fvs/mvs/delaunay.h"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <array>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <utility>
#include <vector>

#include "fvs/mvs/isolated_points.h"
#include "fvs/util/check.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace fvs::mvs {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<uint32_t, K>;
using CellBase = CGAL::Triangulation_cell_base_with_info_3<
    uint32_t, K, CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Tds = CGAL::Triangulation_data_structure_3<VertexBase, CellBase>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;
using Point = K::Point_3;
using VertexHandle = Delaunay::Vertex_handle;
using CellHandle = Delaunay::Cell_handle;

constexpr uint32_t kNoVertex = std::numeric_limits<uint32_t>::max();

Eigen::Vector3d ToEigen(const Point& p) { return {p.x(), p.y(), p.z()}; }
Point ToCgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

// COLMAP's Percentile: the element at round(p/100 * (n-1)) of the sorted values.
double Percentile(std::vector<double> values, double percent) {
  if (values.empty()) return 0;
  const size_t index = static_cast<size_t>(
      std::llround(percent / 100.0 * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + index, values.end());
  return values[index];
}

// 1 - exp(-x^2 / (2 sigma^2)), saturated at 1 beyond 5 sigma (as COLMAP).
struct GaussianRamp {
  double sigma = 1;
  double operator()(double x) const {
    if (x >= 5 * sigma) return 1.0;
    return std::max(0.0, 1.0 - std::exp(-0.5 * x * x / (sigma * sigma)));
  }
};

// A vertex's rays: the images that see it and the summed weight of its points per image.
struct VertexRays {
  std::vector<uint32_t> offsets;                 // per vertex, into `rays`
  std::vector<std::pair<uint32_t, float>> rays;  // (camera index, weight)
};

// Per-cell accumulators of the s-t graph. in_weight[4c+i]: capacity of the directed edge
// from the neighbour across facet i into cell c (a ray crossed that facet towards the
// camera).
struct CellWeights {
  std::vector<float> in_weight;
  std::vector<float> source;
  std::vector<float> sink;
  uint64_t steps = 0;  // facets crossed, for the statistics
  explicit CellWeights(size_t num_cells = 0)
      : in_weight(4 * num_cells, 0.f), source(num_cells, 0.f), sink(num_cells, 0.f) {}
};

class Mesher {
 public:
  Mesher(const DelaunayMeshingInput& input, const DelaunayMeshingOptions& options)
      : input_(input), options_(options) {
    num_threads_ = options.num_threads > 0 ? options.num_threads : DefaultNumThreads();
  }

  TriangleMesh Run(DelaunayMeshingStats* stats) {
    Timer total;
    Timer timer;
    CentreCoordinates();
    Triangulate();
    stats->seconds_triangulation = timer.Seconds();
    timer.Restart();
    IndexCells();
    ComputeDistanceSigma();
    CollectRays();
    CastRays();
    stats->seconds_visibility = timer.Seconds();
    timer.Restart();
    CutGraph();
    stats->seconds_graph = timer.Seconds();
    timer.Restart();
    TriangleMesh mesh = ExtractSurface(stats);
    stats->seconds_extraction = timer.Seconds();
    stats->num_input_points = input_.points.size();
    stats->num_vertices = vertices_.size();
    stats->num_cells = cells_.size();
    stats->num_rays = rays_.rays.size();
    stats->num_ray_steps = num_steps_;
    stats->distance_sigma = distance_sigma_;
    stats->num_faces = mesh.faces.size();
    stats->num_mesh_vertices = mesh.vertices.size();
    stats->seconds_total = total.Seconds();
    return mesh;
  }

 private:
  // Scene-centred coordinates: a scene 10 km from the origin keeps its precision.
  void CentreCoordinates() {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& p : input_.points) sum += p;
    centre_ = sum / static_cast<double>(input_.points.size());
    points_.resize(input_.points.size());
    for (size_t i = 0; i < points_.size(); ++i) points_[i] = input_.points[i] - centre_;
    cameras_ = input_.cameras;
    camera_centres_.resize(cameras_.size());
    for (size_t k = 0; k < cameras_.size(); ++k) {
      // x_cam = R (x_c + centre) + t = R x_c + (t + R centre).
      cameras_[k].t = cameras_[k].t + cameras_[k].R * centre_;
      camera_centres_[k] = cameras_[k].Center();
    }
  }

  // COLMAP's sub-sampled triangulation: skip a point when all vertices of the cell it
  // falls in reproject close to it (pixels and relative depth) in every image that sees
  // it.
  bool CloseToCellInAllViews(size_t point_index, const CellHandle& cell) const {
    const Eigen::Vector3d& p = points_[point_index];
    const double max_sq = options_.max_proj_dist * options_.max_proj_dist;
    const double min_ratio = 1.0 - options_.max_depth_dist;
    const double max_ratio = 1.0 + options_.max_depth_dist;
    for (const uint32_t k : input_.visibility[point_index]) {
      const PinholeCamera& camera = cameras_[k];
      const Eigen::Vector3d pc = camera.WorldToCamera(p);
      if (pc.z() <= 0) return false;
      const Eigen::Vector2d pp = camera.CameraToPixel(pc);
      for (int i = 0; i < 4; ++i) {
        const Eigen::Vector3d vc =
            camera.WorldToCamera(ToEigen(cell->vertex(i)->point()));
        if (vc.z() <= 0) return false;
        const double ratio = pc.z() / vc.z();
        if (ratio < min_ratio || ratio > max_ratio) return false;
        if ((camera.CameraToPixel(vc) - pp).squaredNorm() > max_sq) return false;
      }
    }
    return true;
  }

  void Triangulate() {
    const size_t n = points_.size();
    std::vector<Point> cgal_points(n);
    for (size_t i = 0; i < n; ++i) cgal_points[i] = ToCgal(points_[i]);
    // Insertion in (randomised) Hilbert order with the last cell as hint: each location
    // is a short walk, as in CGAL's bulk insertion, and merged points still reach their
    // cell.
    std::vector<std::size_t> order(n);  // the property map's key type
    std::iota(order.begin(), order.end(), std::size_t{0});
    using SortTraits =
        CGAL::Spatial_sort_traits_adapter_3<K, CGAL::Pointer_property_map<Point>::type>;
    CGAL::spatial_sort(order.begin(), order.end(),
                       SortTraits(CGAL::make_property_map(cgal_points)));

    point_vertex_.assign(n, kNoVertex);
    Progress progress("Delaunay triangulation", static_cast<int64_t>(n));
    CellHandle hint;
    const bool merge = options_.max_proj_dist > 0;
    for (size_t j = 0; j < n; ++j) {
      const size_t i = order[j];
      const Point& p = cgal_points[i];
      VertexHandle vertex;
      if (triangulation_.dimension() < 3) {
        vertex = triangulation_.insert(p, hint);
      } else {
        Delaunay::Locate_type lt;
        int li = 0, lj = 0;
        const CellHandle cell = triangulation_.locate(p, lt, li, lj, hint);
        if (lt == Delaunay::VERTEX) {
          vertex = cell->vertex(li);  // duplicate point
        } else if (merge && !triangulation_.is_infinite(cell) &&
                   CloseToCellInAllViews(i, cell)) {
          // Merged: its rays start at the nearest vertex of the cell.
          int best = 0;
          double best_sq = std::numeric_limits<double>::max();
          for (int v = 0; v < 4; ++v) {
            const double sq =
                (ToEigen(cell->vertex(v)->point()) - points_[i]).squaredNorm();
            if (sq < best_sq) best_sq = sq, best = v;
          }
          point_vertex_[i] = cell->vertex(best)->info();
          hint = cell;
          if ((j & 0xFFF) == 0) progress.Set(static_cast<int64_t>(j));
          continue;
        } else {
          vertex = triangulation_.insert(p, lt, cell, li, lj);
        }
      }
      if (vertex->info() == kNoVertex || vertices_.empty() ||
          vertex->info() >= vertices_.size() || vertices_[vertex->info()] != vertex) {
        vertex->info() = static_cast<uint32_t>(vertices_.size());
        vertices_.push_back(vertex);
      }
      point_vertex_[i] = vertex->info();
      hint = vertex->cell();
      if ((j & 0xFFF) == 0) progress.Set(static_cast<int64_t>(j));
    }
    progress.Finish();
    if (triangulation_.dimension() < 3) {
      throw Error(input_.points_subject,
                  "degenerate point cloud: the " + std::to_string(n) +
                      " points are all coplanar, collinear or equal, so they enclose no "
                      "volume to mesh");
    }
  }

  // Numbers the cells and copies what the ray walks read into flat arrays (positions,
  // neighbours, mirror indices, vertex ids): the walks then touch no CGAL handles, and
  // the arrays are read-only, so threads share them freely.
  void IndexCells() {
    cells_.reserve(triangulation_.number_of_cells());
    for (auto it = triangulation_.all_cells_begin(); it != triangulation_.all_cells_end();
         ++it) {
      it->info() = static_cast<uint32_t>(cells_.size());
      cells_.push_back(it);
    }
    const size_t n = cells_.size();
    infinite_.assign(n, 0);
    cell_points_.resize(n);
    neighbors_.resize(n);
    mirrors_.resize(n);
    cell_vertices_.resize(n);
    ParallelFor(
        0, static_cast<int64_t>(n),
        [&](int64_t c) {
          const CellHandle& cell = cells_[c];
          for (int i = 0; i < 4; ++i) {
            const VertexHandle v = cell->vertex(i);
            if (triangulation_.is_infinite(v)) {
              infinite_[c] = 1;
              cell_points_[c][i].setZero();
              cell_vertices_[c][i] = kNoVertex;
            } else {
              cell_points_[c][i] = ToEigen(v->point());
              cell_vertices_[c][i] = v->info();
            }
            const CellHandle neighbor = cell->neighbor(i);
            neighbors_[c][i] = neighbor->info();
            mirrors_[c][i] = static_cast<uint8_t>(neighbor->index(cell));
          }
        },
        num_threads_);
  }

  void ComputeDistanceSigma() {
    std::vector<double> squared_lengths;
    squared_lengths.reserve(triangulation_.number_of_finite_edges());
    for (auto it = triangulation_.finite_edges_begin();
         it != triangulation_.finite_edges_end(); ++it) {
      squared_lengths.push_back(CGAL::squared_distance(
          it->first->vertex(it->second)->point(), it->first->vertex(it->third)->point()));
    }
    distance_sigma_ =
        options_.distance_sigma_factor *
        std::max(std::sqrt(Percentile(std::move(squared_lengths), 25)), 1e-12);
  }

  // Groups the visibility of the input points by triangulation vertex: one ray per
  // (vertex, image) with the summed weight 1 - exp(-n^2 / (2 visibility_sigma^2)) of its
  // points.
  void CollectRays() {
    const GaussianRamp visibility_prob{options_.visibility_sigma};
    const size_t num_vertices = vertices_.size();
    std::vector<uint32_t> counts(num_vertices + 1, 0);
    for (size_t i = 0; i < points_.size(); ++i) {
      counts[point_vertex_[i] + 1] += static_cast<uint32_t>(input_.visibility[i].size());
    }
    std::partial_sum(counts.begin(), counts.end(), counts.begin());
    std::vector<std::pair<uint32_t, float>> all(counts.back());
    std::vector<uint32_t> fill(counts.begin(), counts.end() - 1);
    for (size_t i = 0; i < points_.size(); ++i) {
      const double n = static_cast<double>(input_.visibility[i].size());
      const float alpha = static_cast<float>(visibility_prob(n));
      for (const uint32_t k : input_.visibility[i]) {
        all[fill[point_vertex_[i]]++] = {k, alpha};
      }
    }
    rays_.offsets.assign(num_vertices + 1, 0);
    rays_.rays.clear();
    rays_.rays.reserve(all.size());
    for (size_t v = 0; v < num_vertices; ++v) {
      auto begin = all.begin() + counts[v];
      auto end = all.begin() + counts[v + 1];
      std::sort(begin, end);
      for (auto it = begin; it != end; ++it) {
        if (!rays_.rays.empty() && rays_.rays.size() > rays_.offsets[v] &&
            rays_.rays.back().first == it->first) {
          rays_.rays.back().second += it->second;
        } else if (it->second > 0) {
          rays_.rays.push_back(*it);
        }
      }
      rays_.offsets[v + 1] = static_cast<uint32_t>(rays_.rays.size());
    }
  }

  // The facet of finite cell c (other than `entry`) through which the ray origin + t *
  // dir leaves it, and the t where it does. With start_vertex_index >= 0 the ray starts
  // at that vertex and leaves through the opposite facet (exact: all others contain the
  // origin).
  std::pair<int, double> ExitFacet(uint32_t c, const Eigen::Vector3d& origin,
                                   const Eigen::Vector3d& dir, int entry,
                                   int start_vertex_index) const {
    const auto& v = cell_points_[c];
    int best = -1;
    double best_t = std::numeric_limits<double>::max();
    for (int i = 0; i < 4; ++i) {
      if (i == entry) continue;
      if (start_vertex_index >= 0 && i != start_vertex_index) continue;
      const Eigen::Vector3d& a = v[(i + 1) & 3];
      const Eigen::Vector3d& b = v[(i + 2) & 3];
      const Eigen::Vector3d& d = v[(i + 3) & 3];
      Eigen::Vector3d normal = (b - a).cross(d - a);
      if (normal.dot(v[i] - a) > 0) normal = -normal;  // outward
      const double denom = normal.dot(dir);
      if (!(denom > 0) && start_vertex_index < 0) continue;
      const double t = denom > 0 ? normal.dot(a - origin) / denom : 0.0;
      if (t < best_t) best_t = t, best = i;
    }
    if (best < 0) {
      // Numerically parallel to every remaining facet (a sliver): leave through any facet
      // other than the entry; the walk still advances cell by cell.
      best = entry == 0 ? 1 : 0;
      best_t = 0;
    }
    return {best, best_t};
  }

  // A finite cell around a vertex with the unit outward normals of its three facets
  // through the vertex: a direction d leaves the vertex into this cell when every normal
  // . d < 0.
  struct StarCell {
    uint32_t cell;
    int vertex_index;
    std::array<Eigen::Vector3d, 3> normals;
  };

  void GatherStar(uint32_t vid, std::vector<StarCell>* star,
                  std::vector<uint32_t>* visited) const {
    star->clear();
    visited->clear();
    visited->push_back(vertices_[vid]->cell()->info());
    for (size_t k = 0; k < visited->size(); ++k) {
      const uint32_t c = (*visited)[k];
      int iv = 0;
      while (iv < 4 && cell_vertices_[c][iv] != vid) ++iv;
      if (iv == 4) continue;  // cannot happen in a valid triangulation
      for (int i = 0; i < 4; ++i) {
        if (i == iv) continue;
        const uint32_t m = neighbors_[c][i];  // shares the facet through the vertex
        if (std::find(visited->begin(), visited->end(), m) == visited->end()) {
          visited->push_back(m);
        }
      }
      if (infinite_[c]) continue;
      StarCell sc{c, iv, {}};
      const auto& v = cell_points_[c];
      int n = 0;
      for (int j = 0; j < 4; ++j) {
        if (j == iv) continue;
        const Eigen::Vector3d& a = v[(j + 1) & 3];
        const Eigen::Vector3d& b = v[(j + 2) & 3];
        const Eigen::Vector3d& d = v[(j + 3) & 3];
        Eigen::Vector3d normal = (b - a).cross(d - a);
        if (normal.dot(v[j] - a) > 0) normal = -normal;
        const double norm = normal.norm();
        sc.normals[n++] =
            norm > 0 ? Eigen::Vector3d(normal / norm) : Eigen::Vector3d::Zero();
      }
      star->push_back(sc);
    }
  }

  // The star cell that `unit` points into from the vertex (the most interior one when the
  // direction grazes a facet), or nullptr when it points out of the hull.
  const StarCell* FindCone(const std::vector<StarCell>& star,
                           const Eigen::Vector3d& unit) const {
    const StarCell* best = nullptr;
    double best_score = -1e-12;
    for (const StarCell& sc : star) {
      const double score = -std::max(
          {sc.normals[0].dot(unit), sc.normals[1].dot(unit), sc.normals[2].dot(unit)});
      if (score > best_score) best_score = score, best = &sc;
    }
    return best;
  }

  // The cell the ray from vertex vid along `unit` enters first, and the index of the
  // vertex in it (-1 when located generally: an infinite cell, or no cone found).
  std::pair<uint32_t, int> FirstCell(uint32_t vid, const std::vector<StarCell>& star,
                                     const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& unit) const {
    if (const StarCell* sc = FindCone(star, unit)) return {sc->cell, sc->vertex_index};
    const double epsilon = 1e-3 * distance_sigma_;
    const CellHandle cell =
        triangulation_.locate(ToCgal(origin + epsilon * unit), vertices_[vid]->cell());
    int index = -1;
    cell->has_vertex(vertices_[vid], index);
    return {cell->info(), infinite_[cell->info()] ? -1 : index};
  }

  // Walks from vertex vid towards camera k, accumulating free-space weights, the source
  // weight of the camera's cell, and the sink weight behind the vertex.
  void CastRay(uint32_t vid, const std::vector<StarCell>& star, uint32_t k, float alpha,
               CellWeights* w) const {
    const GaussianRamp distance_prob{distance_sigma_};
    const Eigen::Vector3d& origin = vertex_points_[vid];
    const Eigen::Vector3d dir = camera_centres_[k] - origin;
    const double length = dir.norm();
    if (!(length > 0)) return;
    const Eigen::Vector3d unit = dir / length;

    // In front of the point: free space up to the camera.
    auto [c, start_index] = FirstCell(vid, star, origin, unit);
    int entry = -1;
    double t_now = 0;
    const size_t max_steps = cells_.size() + 16;
    for (size_t step = 0;; ++step) {
      if (infinite_[c] || step > max_steps) {
        // Left the (convex) hull: the rest of the way is outside.
        w->source[c] += alpha;
        break;
      }
      auto [facet, t] = ExitFacet(c, origin, dir, entry, step == 0 ? start_index : -1);
      t = std::max(t, t_now);
      if (t >= 1.0) {
        w->source[c] += alpha;  // the camera is in this cell
        break;
      }
      w->in_weight[4 * c + facet] +=
          alpha * static_cast<float>(distance_prob(t * length));
      ++w->steps;
      entry = mirrors_[c][facet];
      c = neighbors_[c][facet];
      t_now = t;
    }

    // Behind the point: the cell right behind it, the facet the line leaves it through
    // (penalised with the distance weight) and the cell beyond, which gets the sink
    // weight.
    const auto [behind, behind_index] = FirstCell(vid, star, origin, -unit);
    if (infinite_[behind]) {
      w->sink[behind] += alpha;
      return;
    }
    const auto [facet, t] = ExitFacet(behind, origin, -dir, -1, behind_index);
    const uint32_t beyond = neighbors_[behind][facet];
    w->in_weight[4 * beyond + mirrors_[behind][facet]] +=
        alpha * static_cast<float>(distance_prob(std::max(t, 0.0) * length));
    w->sink[beyond] += alpha;
  }

  void CastRays() {
    const size_t num_cells = cells_.size();
    vertex_points_.resize(vertices_.size());
    for (size_t v = 0; v < vertices_.size(); ++v) {
      vertex_points_[v] = ToEigen(vertices_[v]->point());
    }
    const int threads = static_cast<int>(
        std::min<size_t>(num_threads_, std::max<size_t>(vertices_.size(), 1)));
    std::vector<CellWeights> per_thread(threads);
    Progress progress("Delaunay visibility rays", static_cast<int64_t>(vertices_.size()));
    ParallelForRanges(
        0, static_cast<int64_t>(vertices_.size()),
        [&](int64_t begin, int64_t end, int thread) {
          CellWeights& w = per_thread.at(thread);
          w = CellWeights(num_cells);
          std::vector<StarCell> star;
          std::vector<uint32_t> visited;
          for (int64_t v = begin; v < end; ++v) {
            if (rays_.offsets[v] == rays_.offsets[v + 1]) continue;
            GatherStar(static_cast<uint32_t>(v), &star, &visited);
            for (uint32_t r = rays_.offsets[v]; r < rays_.offsets[v + 1]; ++r) {
              CastRay(static_cast<uint32_t>(v), star, rays_.rays[r].first,
                      rays_.rays[r].second, &w);
            }
            if (((v - begin) & 0x3FF) == 0x3FF) progress.Advance(0x400);
          }
        },
        threads);
    progress.Finish();
    num_steps_ = 0;
    for (const auto& o : per_thread) num_steps_ += o.steps;
    weights_ = std::move(per_thread[0]);
    for (size_t t = 1; t < per_thread.size(); ++t) {
      const CellWeights& o = per_thread[t];
      if (o.source.empty()) continue;
      for (size_t i = 0; i < weights_.in_weight.size(); ++i) {
        weights_.in_weight[i] += o.in_weight[i];
      }
      for (size_t c = 0; c < num_cells; ++c) {
        weights_.source[c] += o.source[c];
        weights_.sink[c] += o.sink[c];
      }
    }
    if (weights_.source.empty()) weights_ = CellWeights(num_cells);
  }

  // cos of the angle between facet (cell, i)'s normal towards the cell and the direction
  // to the cell's circumcentre (Labatut et al. 2009, Fig. 9); 1 for infinite cells.
  double CosFacetCellAngle(uint32_t c, int i) const {
    if (infinite_[c]) return 1.0;
    const auto& v = cell_points_[c];
    const Eigen::Vector3d& a = v[(i + 1) & 3];
    const Eigen::Vector3d& b = v[(i + 2) & 3];
    const Eigen::Vector3d& d = v[(i + 3) & 3];
    const Eigen::Vector3d& opposite = v[i];
    Eigen::Vector3d normal = (b - a).cross(d - a);
    if (normal.dot(opposite - a) < 0) normal = -normal;  // towards the cell
    const Eigen::Vector3d to_centre = circumcentres_[c] - a;
    const double nn = normal.squaredNorm();
    const double cc = to_centre.squaredNorm();
    if (!(nn > 0) || !(cc > 0) || !std::isfinite(cc)) return 0.5;
    return std::clamp(normal.dot(to_centre) / std::sqrt(nn * cc), -1.0, 1.0);
  }

  void CutGraph() {
    using Graph =
        boost::compressed_sparse_row_graph<boost::directedS, boost::no_property,
                                           boost::no_property, boost::no_property,
                                           uint32_t, uint32_t>;
    using Edge = Graph::edge_descriptor;
    const size_t n = cells_.size();
    Require(8 * n + 2 < std::numeric_limits<uint32_t>::max(), input_.points_subject,
            "too many Delaunay cells for the graph cut");

    circumcentres_.resize(n);
    ParallelFor(
        0, static_cast<int64_t>(n),
        [&](int64_t c) {
          if (infinite_[c]) return;
          const CellHandle& cell = cells_[c];
          circumcentres_[c] = ToEigen(
              CGAL::circumcenter(cell->vertex(0)->point(), cell->vertex(1)->point(),
                                 cell->vertex(2)->point(), cell->vertex(3)->point()));
        },
        num_threads_);

    // Nodes: cells 0..n-1, source n, sink n+1. Edges, sorted by source node: cell c has
    // 6c+i (i < 4: to the neighbour across facet i), 6c+4 (to the sink), 6c+5 (to the
    // source, capacity 0); the source has 6n+c (to cell c), the sink 7n+c (to cell c,
    // capacity 0).
    const uint32_t source = static_cast<uint32_t>(n);
    const uint32_t sink = static_cast<uint32_t>(n + 1);
    const size_t num_edges = 8 * n;
    std::vector<float> capacity(num_edges, 0.f);
    std::vector<Edge> reverse(num_edges);
    {
      std::vector<std::pair<uint32_t, uint32_t>> edges(num_edges);
      const double quality = options_.quality_regularization;
      ParallelFor(
          0, static_cast<int64_t>(n),
          [&](int64_t c64) {
            const uint32_t c = static_cast<uint32_t>(c64);
            for (int i = 0; i < 4; ++i) {
              const uint32_t m = neighbors_[c][i];
              const int j = mirrors_[c][i];
              edges[6 * c + i] = {c, m};
              reverse[6 * c + i] = Edge(m, 6 * m + j);
              const double shape = quality * (1.0 - std::min(CosFacetCellAngle(c, i),
                                                             CosFacetCellAngle(m, j)));
              // Edge c -> m: cutting it puts the surface between an outside c and an
              // inside m; the rays that crossed from m into c towards a camera say m is
              // empty.
              capacity[6 * c + i] = weights_.in_weight[4 * m + j] +
                                    static_cast<float>(std::max(shape, 0.0));
            }
            edges[6 * c + 4] = {c, sink};
            capacity[6 * c + 4] = weights_.sink[c];
            reverse[6 * c + 4] = Edge(sink, static_cast<uint32_t>(7 * n + c));
            edges[6 * c + 5] = {c, source};
            reverse[6 * c + 5] = Edge(source, static_cast<uint32_t>(6 * n + c));
            edges[6 * n + c] = {source, c};
            capacity[6 * n + c] = weights_.source[c];
            reverse[6 * n + c] = Edge(c, 6 * c + 5);
            edges[7 * n + c] = {sink, c};
            reverse[7 * n + c] = Edge(c, 6 * c + 4);
          },
          num_threads_);
      weights_ = CellWeights();
      graph_ = Graph(boost::edges_are_sorted, edges.begin(), edges.end(), n + 2);
    }
    std::vector<float> residual(num_edges, 0.f);
    std::vector<Edge> predecessor(n + 2);
    std::vector<boost::default_color_type> color(n + 2);
    std::vector<long> distance(n + 2, 0);
    const auto edge_index = get(boost::edge_index, graph_);
    const auto vertex_index = get(boost::vertex_index, graph_);
    boost::boykov_kolmogorov_max_flow(
        graph_, boost::make_iterator_property_map(capacity.begin(), edge_index),
        boost::make_iterator_property_map(residual.begin(), edge_index),
        boost::make_iterator_property_map(reverse.begin(), edge_index),
        boost::make_iterator_property_map(predecessor.begin(), vertex_index),
        boost::make_iterator_property_map(color.begin(), vertex_index),
        boost::make_iterator_property_map(distance.begin(), vertex_index), vertex_index,
        source, sink);
    // Cells in the sink tree are inside; free cells count as outside (as COLMAP).
    inside_.resize(n);
    for (size_t c = 0; c < n; ++c) inside_[c] = color[c] == boost::white_color;
    graph_ = Graph();
  }

  TriangleMesh ExtractSurface(DelaunayMeshingStats* stats) const {
    struct Face {
      std::array<uint32_t, 3> v;
      double longest;
    };
    std::vector<Face> faces;
    for (size_t c = 0; c < cells_.size(); ++c) {
      const CellHandle& cell = cells_[c];
      for (int i = 0; i < 4; ++i) {
        const CellHandle neighbor = cell->neighbor(i);
        const uint32_t m = neighbor->info();
        if (m < c || inside_[c] == inside_[m]) continue;
        if (triangulation_.is_infinite(cell, i)) continue;
        std::array<VertexHandle, 3> tri = {cell->vertex((i + 1) & 3),
                                           cell->vertex((i + 2) & 3),
                                           cell->vertex((i + 3) & 3)};
        const Eigen::Vector3d a = ToEigen(tri[0]->point());
        const Eigen::Vector3d b = ToEigen(tri[1]->point());
        const Eigen::Vector3d d = ToEigen(tri[2]->point());
        const Eigen::Vector3d normal = (b - a).cross(d - a);
        // Outward = towards the outside cell's opposite vertex (or away from the inside
        // cell's when the outside cell is infinite).
        const bool c_outside = !inside_[c];
        const CellHandle& outside_cell = c_outside ? cell : neighbor;
        const int outside_index = c_outside ? i : neighbor->index(cell);
        const CellHandle& inside_cell = c_outside ? neighbor : cell;
        const int inside_index = c_outside ? neighbor->index(cell) : i;
        bool flip;
        if (!triangulation_.is_infinite(outside_cell->vertex(outside_index))) {
          flip =
              normal.dot(ToEigen(outside_cell->vertex(outside_index)->point()) - a) < 0;
        } else {
          flip = normal.dot(ToEigen(inside_cell->vertex(inside_index)->point()) - a) > 0;
        }
        if (flip) std::swap(tri[1], tri[2]);
        const double longest = std::sqrt(std::max(
            {(a - b).squaredNorm(), (a - d).squaredNorm(), (b - d).squaredNorm()}));
        faces.push_back({{tri[0]->info(), tri[1]->info(), tri[2]->info()}, longest});
      }
    }
    stats->num_surface_facets = faces.size();

    TriangleMesh mesh;
    if (faces.empty()) return mesh;
    std::vector<double> longest(faces.size());
    for (size_t f = 0; f < faces.size(); ++f) longest[f] = faces[f].longest;
    const double max_side =
        options_.max_side_length_factor *
        Percentile(std::move(longest), options_.max_side_length_percentile);
    stats->max_side_length = max_side;

    std::vector<double> spacing;
    if (options_.max_side_spacing_factor > 0) {
      spacing = MeanNeighborDistances(vertex_points_, 8, num_threads_);
    }
    std::vector<int> new_index(vertices_.size(), -1);
    for (const Face& face : faces) {
      if (face.longest > max_side) continue;
      if (!spacing.empty()) {
        const double local =
            std::max({spacing[face.v[0]], spacing[face.v[1]], spacing[face.v[2]]});
        if (face.longest > options_.max_side_spacing_factor * local) {
          ++stats->num_spacing_filtered;
          continue;
        }
      }
      Eigen::Vector3i out;
      for (int j = 0; j < 3; ++j) {
        int& index = new_index[face.v[j]];
        if (index < 0) {
          index = static_cast<int>(mesh.vertices.size());
          mesh.vertices.push_back(ToEigen(vertices_[face.v[j]]->point()) + centre_);
        }
        out[j] = index;
      }
      mesh.faces.push_back(out);
    }
    return mesh;
  }

  const DelaunayMeshingInput& input_;
  const DelaunayMeshingOptions& options_;
  int num_threads_ = 1;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> points_;  // centred
  std::vector<PinholeCamera> cameras_;   // centred
  std::vector<Eigen::Vector3d> camera_centres_;
  Delaunay triangulation_;
  std::vector<VertexHandle> vertices_;  // by vertex info
  std::vector<uint32_t> point_vertex_;  // input point -> vertex info
  std::vector<CellHandle> cells_;       // by cell info
  std::vector<uint8_t> infinite_;       // not vector<bool>: written from threads
  std::vector<std::array<Eigen::Vector3d, 4>> cell_points_;  // infinite vertex: zero
  std::vector<std::array<uint32_t, 4>> neighbors_;
  std::vector<std::array<uint8_t, 4>> mirrors_;  // index of this cell in the neighbour
  std::vector<std::array<uint32_t, 4>> cell_vertices_;  // vertex ids; kNoVertex: infinite
  std::vector<Eigen::Vector3d> vertex_points_;
  double distance_sigma_ = 1;
  VertexRays rays_;
  uint64_t num_steps_ = 0;
  CellWeights weights_;
  std::vector<Eigen::Vector3d> circumcentres_;
  boost::compressed_sparse_row_graph<boost::directedS, boost::no_property,
                                     boost::no_property, boost::no_property, uint32_t,
                                     uint32_t>
      graph_;
  std::vector<bool> inside_;
};

}  // namespace

TriangleMesh DelaunayMeshing(const DelaunayMeshingInput& input,
                             const DelaunayMeshingOptions& options,
                             DelaunayMeshingStats* stats) {
  options.Check();
  input.Check();
  DelaunayMeshingStats local_stats;
  if (!stats) stats = &local_stats;
  IsolatedPointOptions isolated_options;
  isolated_options.num_neighbors = options.isolated_point_neighbors;
  isolated_options.factor = options.isolated_point_factor;
  isolated_options.num_threads = options.num_threads;
  // Only the fused points are tested; the SfM points after them are kept (delaunay.h).
  const size_t num_fused = input.points.size() - input.num_sparse_points;
  std::vector<bool> isolated = FindIsolatedPoints(
      {input.points.begin(), input.points.begin() + num_fused}, isolated_options);
  isolated.resize(input.points.size(), false);
  const size_t num_isolated = std::count(isolated.begin(), isolated.end(), true);
  DelaunayMeshingInput kept;
  if (num_isolated > 0) {
    kept.cameras = input.cameras;
    kept.points_subject = input.points_subject;
    kept.visibility_subject = input.visibility_subject;
    for (size_t i = 0; i < input.points.size(); ++i) {
      if (isolated[i]) continue;
      kept.points.push_back(input.points[i]);
      kept.visibility.push_back(input.visibility[i]);
    }
    kept.Check();
  }
  Mesher mesher(num_isolated > 0 ? kept : input, options);
  TriangleMesh mesh = mesher.Run(stats);
  stats->num_input_points = input.points.size();
  stats->num_isolated_points = num_isolated;
  stats->num_sparse_points = input.num_sparse_points;
  for (const auto& v : mesh.vertices) {
    FVS_CHECK(v.allFinite(), "non-finite mesh vertex from " + input.points_subject);
  }
  return mesh;
}

}  // namespace fvs::mvs
