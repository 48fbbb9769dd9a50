// Planar priors for what PatchMatch leaves empty: textureless walls, floors, table tops
// and backdrops, where NCC says nothing, and surfaces no second view confirmed. After the
// geometric pass, the confident pixels of a view (low cost, confirmed) and the SfM points
// it observes are the support; a coarse-to-fine lattice of support cells (8 px, 16 px,
// ... 256 px) spans holes of any size, and an empty pixel takes the plane through the
// supports of the cells around it, at the finest level where those supports are coplanar,
// enclose the pixel and face the camera, and where the sources agree: no source saw
// something behind the point (free space), and at least two sources either measured the
// same depth there or show the same grey as the reference. The idea of ACMP (Xu & Tao,
// AAAI 2020: planar priors from a triangulation of confident pixels); the lattice instead
// of a Delaunay triangulation keeps stereo free of CGAL, and the visibility test against
// the sources' depth maps replaces ACMP's prior-weighted cost.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fvs/mvs/patch_match.h"

namespace fvs::mvs {

struct PlanarPriorOptions {
  bool enabled = true;
  // Side of the finest support cell in pixels, and the number of levels (each doubles
  // the cell): 8 px x 2^5 = 256 px spans a wall across most of a 640 px photo.
  int cell_size = 8;
  int num_levels = 6;
  // A confirmed pixel supports a plane when its PatchMatch cost is at most this; SfM
  // points observed by the view always do (they count as this cost halved).
  double max_support_cost = 0.5;
  // The supports of a cell group must lie within this relative depth of their plane.
  double max_plane_residual = 0.01;
  // A plane seen at a grazing angle gives depths that a pixel of error moves far.
  double min_cos_incidence = 0.2;
  // The grey test: mean |reference - source| over a (2r + 1)^2 window, grey in [0, 1].
  int window_radius = 2;
  double max_grey_difference = 0.05;
  // Relative depth within which a source's depth map confirms the point; a source that
  // saw a surface farther than this behind the point vetoes it.
  double depth_tolerance = 0.01;
  int min_num_consistent = 2;

  // Throws fvs::Error("PlanarPrior", ...) for values out of range.
  void Check() const;
  // The options as text, for stage fingerprints.
  std::string ToString() const;
};

struct PlanarPriorStats {
  int64_t empty = 0;       // pixels without depth before
  int64_t candidates = 0;  // of those, pixels with a usable plane at some level
  int64_t filled = 0;      // of those, pixels the sources agreed on
};

// What the prior of one view is made from.
struct PlanarPriorInputs {
  int ref = 0;               // the view whose map is filled (an index into the views)
  std::vector<int> sources;  // its source views
  // One depth map per source (the sources' photometric maps, at their working
  // resolution; empty pixels are 0).
  std::vector<const Image*> source_depths;
  // World points the reference view observes (its SfM points).
  std::vector<Eigen::Vector3d> sparse_points;
  // The reference's photometric map, or null: a photometric depth that the geometric
  // filter removed but that agrees with the plane is kept when one source confirms it
  // (no second view needed).
  const Image* photometric = nullptr;
};

// Fills the pixels of `map` (views[in.ref]'s result of the geometric pass) that have no
// depth. Never writes a non-finite depth or normal.
PlanarPriorStats FillFromPlanarPriors(const std::vector<StereoView>& views,
                                      const PlanarPriorInputs& in,
                                      const PlanarPriorOptions& options,
                                      DepthNormalMap* map);

}  // namespace fvs::mvs
