// The backdrop: what lies beyond the proxy mesh, fitted to the photos before falling back
// to infinity (issue 39, doc/real_scenes.md).
//
// Where the mesh has no surface, a view used to look at infinity (geometry/warp.h): right
// for sky and far hills, wrong for a black cloth or a white table behind an object, which
// stereo leaves empty because they carry no texture. Warped at infinity such a near
// background is painted with whatever the sources see in that direction, and where every
// source has the object there it is left to push-pull.
//
// The fit is a star-shaped surface around the scene's centre c (the median of the mesh's
// vertices): one radius per direction of a subdivided icosahedron. For each direction d
// it tries log-spaced radii r from min_radius to max_radius (in units of the mesh's
// radius and of the farthest camera's distance from c) and infinity, and scores each by
// the disagreement of the photos' colours where they see that point: photos compared at
// max_image_size, a photo counting when the point is inside it, in front of it and not
// behind the mesh (the mesh rendered into the small photo), and, for a finite point,
// when the photo sees the backdrop's inner side (a camera outside the surface sees only
// its far side). At infinity a photo sees direction d through the pixel of the ray d
// where its mesh is empty, as the warp's test. The cost of a hypothesis is the mean
// squared deviation of those colours from their mean (at least min_views photos). The
// backdrop is not at infinity unless infinity's colours agree better by more than
// infinity_margin: a textureless background agrees at every radius, and a finite surface
// close behind the object keeps the sources' occlusion test consistent there (the
// issue's "fit what the photos support before falling back to infinity, and let the
// infinity warp's own colour disagreement decide when it is wrong"). A finite radius is
// kept only where it explains the colours: they agree within max_colour_std at the
// typical (median) radius, a textureless background, or the best radius is a distinct
// minimum (at most half the typical std) within max_colour_std, a textured surface. A
// direction no radius explains, or that fewer than min_views photos see, is dropped and
// left to infinity. Hypotheses are
// compared only when seen by at least half as many photos as the most seen one (a
// point few photos see agrees by that alone), and the variance is the unbiased one.
// The log-radii are median-filtered over each vertex's neighbours; faces with a dropped
// vertex are removed.
//
// The backdrop's faces wind counter-clockwise seen from c: rendered with back faces
// culled (RenderWithBackdrop) a camera inside sees the surface around it, a camera
// outside only the far side. It is used only where the mesh has no surface.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/util/image.h"

namespace fvs {

struct BackdropOptions {
  bool enabled = true;
  int subdivisions = 4;           // icosahedron subdivisions: 10 * 4^s + 2 directions
  int max_image_size = 96;        // longest side of the photos compared
  int num_radii = 24;             // finite radii tried per direction
  double min_radius = 0.5;        // in units of the mesh's radius (90th percentile)
  double max_radius = 4.0;        // in units of the farthest camera's distance from c
  int min_views = 3;              // photos that must see a hypothesis
  double infinity_margin = 0.02;  // colour std (0-1) by which infinity must agree better
  double max_colour_std = 0.1;    // colour std (0-1) a finite fit may have (see the top)
  int smoothing_iterations = 2;   // median filters of the log-radius over neighbours
  int num_threads = 0;            // <= 0: DefaultNumThreads()
  void Check() const;
  // Every field that changes the fit, for prepare's fingerprint.
  std::string ToString() const;
};

struct BackdropView {
  PinholeCamera camera;  // the camera of the photo (any frame, the mesh's)
  Image photo;           // RGB in [0, 1], at any size (resized to max_image_size here)
};

struct BackdropFit {
  TriangleMesh mesh;  // empty when nothing was kept (or disabled)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double mesh_radius = 0;
  int num_directions = 0;
  int num_finite = 0;       // directions given a finite radius
  int num_infinity = 0;     // directions left to infinity because infinity agreed better
  int num_unexplained = 0;  // directions whose colours disagree at every radius
  int num_unseen = 0;       // directions fewer than min_views photos see beyond the mesh
  std::string Summary() const;  // one line for the log
};

// Fits the backdrop to `views` around `mesh` (same frame). Throws fvs::Error when the
// options are invalid; returns an empty mesh when the mesh is empty or nothing is seen.
BackdropFit FitBackdrop(const std::vector<BackdropView>& views, const TriangleMesh& mesh,
                        const BackdropOptions& options);

// The depth of `mesh` seen by `camera`, with the backdrop's depth (back faces culled)
// where the mesh has no surface. backdrop may be empty.
Image RenderWithBackdrop(const TriangleMesh& mesh, const TriangleMesh& backdrop,
                         const PinholeCamera& camera, int num_threads = 0);

// The unit icosphere: 10 * 4^subdivisions + 2 vertices, faces counter-clockwise seen
// from outside.
TriangleMesh Icosphere(int subdivisions);

}  // namespace fvs
