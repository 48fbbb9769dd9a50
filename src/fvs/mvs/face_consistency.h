// Faces the photos contradict (issue 39): the Delaunay graph cut closes what no ray
// carved, so a surface spans the gaps between a temple's columns, the space between a
// table top's rim and the floor, or the ragged edge of an object against a backdrop that
// has no points. Rendered, such a face paints whatever each source sees along its ray
// (the back wall through the gap in one, a column in another): doubled, smeared images.
// A face on the true surface shows the same colour in every photo that sees it; a face
// across empty space shows different things in different photos.
//
// The test, per photo i (at max_image_size) and pixel p of it where the mesh has face f:
// the point X of p on f is projected into each of num_neighbors other photos j; where j
// sees X (inside, in front, and j's own mesh depth there agrees with X's depth within
// depth_tolerance, so j is not occluded and looks at the same face or its neighbours),
// the colour difference |c_i(p) - c_j(X)| (mean over RGB, both photos box-blurred by one
// pixel, so that half a pixel of misregistration on texture costs little) counts for f.
// A face is judged when at least min_samples pairs have counted; it is inconsistent when
// their mean difference exceeds max_colour_difference, and such faces are removed. A face
// no photo pair sees often enough is kept. Removing a face leaves a hole that the
// backdrop (scene/backdrop.h) or the warp at infinity fills, or, where more mesh lies
// behind, that mesh: what the photos show through a false surface.
//
// Neighbours of photo i: the num_neighbors photos whose centres are nearest to i's among
// those whose viewing directions are within 60 degrees of i's (they see the same side of
// a surface).
//
// Stable numbers: depths and points in double precision; a pixel whose point or
// projection is not finite is skipped; faces with a non-finite vertex are kept as they
// are (the rasteriser skips them) and the mesh's vertices are not changed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/mvs/mesh_refinement.h"
#include "fvs/util/image.h"

namespace fvs::mvs {

struct FaceConsistencyOptions {
  // Off by default until it pays on held-out views (doc/real_scenes.md, session 29).
  bool enabled = false;
  int max_image_size = 400;             // longest side of the photos compared
  int num_neighbors = 4;                // photos each photo is compared with
  double depth_tolerance = 0.01;        // relative depth agreement for "j sees X"
  double max_colour_difference = 0.15;  // mean |RGB difference| (0-1) of a kept face
  int min_samples = 16;                 // pixel pairs a face needs to be judged
  int num_threads = 0;                  // <= 0: DefaultNumThreads()
  // Throws fvs::Error("face consistency", ...) naming the bad option.
  void Check() const;
  // Every field that changes the result, for prepare's fingerprint (not num_threads).
  std::string ToString() const;
};

// A photo with its camera in the mesh's frame, as the vertex refinement takes it (so the
// mesh_refinement stage reads the photos once for both); the photo must have 3 channels
// here.
using FaceConsistencyView = MeshRefinementView;

struct FaceConsistencyResult {
  TriangleMesh mesh;      // the input without its inconsistent faces (vertices unchanged)
  size_t num_faces = 0;   // of the input
  size_t num_judged = 0;  // faces with at least min_samples pairs
  size_t num_removed = 0;         // judged inconsistent
  double removed_area_share = 0;  // of the judged faces' pixels (sum over photos)
  double median_difference = 0;   // of the judged faces
  double seconds = 0;
  std::string Summary() const;  // one line for the log
};

// Per face of `mesh`, the mean colour difference of the photo pairs that see it, and the
// number of pairs (0: not seen by a pair; its difference is 0). Exposed for tests.
struct FaceDifferences {
  std::vector<double> mean_difference;
  std::vector<size_t> num_samples;
};
FaceDifferences MeasureFaceDifferences(const std::vector<FaceConsistencyView>& views,
                                       const TriangleMesh& mesh,
                                       const FaceConsistencyOptions& options);

// Removes the faces of `mesh` that `views` contradict (above). Fewer than two views, or
// options.enabled false: the mesh as it is. Throws fvs::Error for invalid options or a
// view whose photo is not 3-channel.
FaceConsistencyResult RemoveInconsistentFaces(
    const std::vector<FaceConsistencyView>& views, const TriangleMesh& mesh,
    const FaceConsistencyOptions& options);

}  // namespace fvs::mvs
