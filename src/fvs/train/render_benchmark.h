// The render benchmark of the trainer-only build (`fvs_train_main --Train.benchmark 1`),
// for a machine that cannot build benchmark/render_benchmark (no COLMAP, OIIO, CGAL):
// validation views of the packed validation scenes rendered with the network and with
// ulr, as the trainer's validation renders them (train/packed_render.h), at each size of
// --Train.bench_sizes (the packs resized: ResizePackedScene), each K of --Train.bench_ks
// and each precision of --Train.bench_precisions (fp16 on CUDA only). Prints a table and
// writes M/render_benchmark.csv (rewritten after every row, so a run cut short keeps
// what it measured):
//   width,height,k,precision,views,warp_s,cpu_warp_s,network_s,rest_s,total_s,psnr,ulr_psnr
// Seconds are per view: warp_s is the warp and gather (the CPU warp of MakeSample, which
// cpu_warp_s repeats, the copy to the device and the feature grid_sample), network_s
// Encode + Blend, rest_s hole filling; PSNR (dB) of the network and of ulr against the
// (resized) photo, in [0, 1] without quantisation, as the validation. The grid is bounded
// by --Train.bench_seconds: each size gets an equal share of what is left, and a cell
// whose predicted time (the last cell of that precision, scaled by K and pixels) would pass
// its share is skipped and printed as such. Each size and precision first renders one
// untimed view (cuDNN's algorithm search, oneDNN's primitives, lazy initialisation).
#pragma once

#include "fvs/train/train_options.h"

namespace fvs {

TrainSummary RunRenderBenchmark(const TrainOptions& options);

}  // namespace fvs
