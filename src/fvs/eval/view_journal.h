// The views an evaluation has finished, kept on disk as it goes, so that a killed or
// repeated `view_synthesis_eval` goes on where it stopped instead of rendering them again
// (issue 18: kill -9 anywhere). One small file per (configuration, target) in the
// journal's folder, written atomically once the view's row is final, with the contact
// sheet's thumbnail of the render beside it (float TIFF: the sheet of a resumed run is
// the sheet of an uninterrupted one). Every number is kept at full precision, so the
// reports of a resumed run equal an uninterrupted run's.
//
// The journal belongs to one set of settings (what decides a view's result: workspace
// content, weights, protocol, render options, LPIPS weights); opening it with other
// settings empties it first. Only evaluated views are kept: a view that failed is tried
// again.
#pragma once

#include <string>

#include "fvs/eval/evaluate.h"
#include "fvs/util/image.h"

namespace fvs::eval {

class ViewJournal {
 public:
  // Opens (creates) the journal in `dir` for `settings` (any text; compared whole).
  // Entries of other settings, or all of them with `discard` (--overwrite), are removed.
  // Throws fvs::Error naming `dir` when it cannot be created or written.
  ViewJournal(const std::string& dir, const std::string& settings, bool discard);

  // The earlier result of `target` under `config`, and its thumbnail when `thumbnail` is
  // not null and one was kept (else *thumbnail is left empty). False when there is none
  // or it cannot be read (a damaged entry is evaluated again).
  bool Find(const EvalConfig& config, const std::string& target, ViewResult* result,
            Image* thumbnail) const;

  // Keeps an evaluated view's result (and its render's thumbnail, when not empty).
  // Failed or skipped views are not kept.
  void Record(const ViewResult& result, const Image& thumbnail) const;

  const std::string& dir() const { return dir_; }

 private:
  std::string EntryStem(const EvalConfig& config, const std::string& target) const;

  std::string dir_;
};

}  // namespace fvs::eval
