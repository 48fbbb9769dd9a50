#include "fvs/eval/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "fvs/eval/draw.h"
#include "fvs/util/error.h"

namespace fvs::eval {
namespace {

const Rgb kInk{0.1f, 0.1f, 0.1f};
const Rgb kGrid{0.88f, 0.88f, 0.88f};
// Colour-blind-safe palette (Okabe-Ito), one per method.
const Rgb kPalette[] = {{0.0f, 0.45f, 0.70f},  {0.90f, 0.62f, 0.0f},
                        {0.0f, 0.62f, 0.45f},  {0.80f, 0.47f, 0.65f},
                        {0.34f, 0.71f, 0.91f}, {0.84f, 0.37f, 0.0f},
                        {0.94f, 0.89f, 0.26f}, {0.4f, 0.4f, 0.4f}};
const Marker kMarkers[] = {Marker::kCircle, Marker::kSquare, Marker::kTriangle,
                           Marker::kDiamond};

std::string Format(const char* format, double v) {
  char text[64];
  std::snprintf(text, sizeof(text), format, v);
  return text;
}

std::string SecondsLabel(double s) {
  if (s >= 1) return Format("%g s", s);
  if (s >= 1e-3) return Format("%g ms", s * 1e3);
  return Format("%g us", s * 1e6);
}

}  // namespace

std::vector<double> NiceTicks(double lo, double hi, int target_count) {
  if (!(hi > lo)) hi = lo + 1;
  const double raw = (hi - lo) / std::max(1, target_count);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * magnitude;
    if (step >= raw) break;
  }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + 1e-9 * step; t += step) {
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  }
  return ticks;
}

Image PlotErrorAgainstTime(const std::vector<ConfigSummary>& summary,
                           const PlotOptions& options) {
  std::vector<const ConfigSummary*> points;
  for (const ConfigSummary& s : summary) {
    if (std::isfinite(s.psnr) && std::isfinite(s.Time(options.time)) &&
        s.Time(options.time) > 0) {
      points.push_back(&s);
    }
  }
  Require(!points.empty(), "plot", "no configuration has both a PSNR and a time");

  // Series: one per (method, scale, precision), through its K values in order.
  std::map<std::string, int> method_colour;
  std::map<std::string, int> scale_marker;
  std::vector<std::pair<std::string, std::vector<const ConfigSummary*>>> series;
  for (const ConfigSummary* p : points) {
    method_colour.emplace(p->config.method, static_cast<int>(method_colour.size()));
    const std::string scale_key = Format("%g", p->config.scale) + p->config.precision;
    scale_marker.emplace(scale_key, static_cast<int>(scale_marker.size()));
    std::string name = p->config.method;
    if (p->config.scale != 1.0) name += Format(" scale %g", p->config.scale);
    if (p->config.precision != "fp32") name += " " + p->config.precision;
    if (p->config.num_sources == 0) name += " adaptive K";  // a point of its own
    auto it = std::find_if(series.begin(), series.end(),
                           [&](const auto& s) { return s.first == name; });
    if (it == series.end()) {
      series.push_back({name, {}});
      it = series.end() - 1;
    }
    it->second.push_back(p);
  }
  for (auto& s : series) {
    std::sort(s.second.begin(), s.second.end(), [](const auto* a, const auto* b) {
      return a->config.num_sources < b->config.num_sources;
    });
  }

  // Axes: decades of time (log10), 1-2-5 steps of PSNR.
  double tmin = 1e300, tmax = 0, pmin = 1e300, pmax = -1e300;
  for (const ConfigSummary* p : points) {
    tmin = std::min(tmin, p->Time(options.time));
    tmax = std::max(tmax, p->Time(options.time));
    pmin = std::min(pmin, p->psnr);
    pmax = std::max(pmax, p->psnr);
  }
  double x_lo = std::floor(std::log10(tmin)), x_hi = std::ceil(std::log10(tmax));
  if (x_hi <= x_lo) x_hi = x_lo + 1;
  const double pad = std::max(0.5, 0.08 * (pmax - pmin));
  const std::vector<double> y_ticks = NiceTicks(pmin - pad, pmax + pad, 6);
  const double y_lo = std::min(pmin - pad, y_ticks.front());
  const double y_hi = std::max(pmax + pad, y_ticks.back());

  Image image(options.width, options.height, 3, 1.0f);
  const int left = 80, right = 230, top = 44, bottom = 70;
  const int pw = options.width - left - right, ph = options.height - top - bottom;
  Require(pw > 50 && ph > 50, "plot", "image too small");
  auto px = [&](double seconds) {
    return left + pw * (std::log10(seconds) - x_lo) / (x_hi - x_lo);
  };
  auto py = [&](double psnr) { return top + ph * (y_hi - psnr) / (y_hi - y_lo); };

  // Grid and ticks.
  for (int d = static_cast<int>(x_lo); d <= static_cast<int>(x_hi); ++d) {
    for (int m = 1; m <= 9; ++m) {
      const double s = m * std::pow(10.0, d);
      if (std::log10(s) > x_hi + 1e-9) break;
      const double x = px(s);
      DrawLine(&image, x, top, x, top + ph, kGrid, m == 1 ? 1.5 : 0.7);
      if (m == 1 || (m == 2 || m == 5)) {
        const std::string label = SecondsLabel(s);
        DrawText(&image, static_cast<int>(x) - TextWidth(label) / 2, top + ph + 8, label,
                 kInk);
      }
    }
  }
  for (double t : y_ticks) {
    if (t < y_lo - 1e-9 || t > y_hi + 1e-9) continue;
    const double y = py(t);
    DrawLine(&image, left, y, left + pw, y, kGrid, 1.0);
    const std::string label = Format("%g", t);
    DrawText(&image, left - 8 - TextWidth(label), static_cast<int>(y) - kGlyphHeight / 2,
             label, kInk);
  }
  DrawLine(&image, left, top + ph, left + pw, top + ph, kInk, 1.5);
  DrawLine(&image, left, top, left, top + ph, kInk, 1.5);
  DrawText(&image, left + (pw - TextWidth(options.title, 2)) / 2, 10, options.title, kInk,
           2);
  const std::string x_title = options.time == TimeMeasure::kWall
                                  ? "seconds per view, wall clock (log scale)"
                                  : "CPU seconds per view, all threads (log scale)";
  DrawText(&image, left + (pw - TextWidth(x_title)) / 2, top + ph + 26, x_title, kInk);
  const std::string y_title = "PSNR (dB), higher is better";
  DrawTextVertical(&image, 16, top + (ph - TextWidth(y_title)) / 2, y_title, kInk);
  if (!options.footer.empty()) {
    DrawText(&image, left, options.height - kGlyphHeight - 8, options.footer,
             {0.35f, 0.35f, 0.35f});
  }

  // Curves, markers, Pareto rings with their K (a label that would overlap one already
  // drawn is left out), legend.
  struct Box {
    int x0, y0, x1, y1;
  };
  std::vector<Box> labels;
  auto label_fits = [&](const Box& b) {
    for (const Box& o : labels) {
      if (b.x0 < o.x1 && o.x0 < b.x1 && b.y0 < o.y1 && o.y0 < b.y1) return false;
    }
    labels.push_back(b);
    return true;
  };
  int legend_y = top + 4;
  for (const auto& [name, members] : series) {
    const ConfigSummary* first = members.front();
    const Rgb colour = kPalette[method_colour[first->config.method] % 8];
    const Marker marker = kMarkers
        [scale_marker[Format("%g", first->config.scale) + first->config.precision] % 4];
    for (size_t i = 1; i < members.size(); ++i) {
      DrawLine(&image, px(members[i - 1]->Time(options.time)), py(members[i - 1]->psnr),
               px(members[i]->Time(options.time)), py(members[i]->psnr), colour, 2.0);
    }
    for (const ConfigSummary* p : members) {
      if (p->pareto) {
        DrawMarker(&image, px(p->Time(options.time)), py(p->psnr), Marker::kCircle, 8.5,
                   kInk);
        DrawMarker(&image, px(p->Time(options.time)), py(p->psnr), Marker::kCircle, 7.0,
                   {1.0f, 1.0f, 1.0f});
        const std::string k = "K" + FormatNumSources(p->config.num_sources);
        const int lx = static_cast<int>(px(p->Time(options.time))) + 9;
        const int ly = static_cast<int>(py(p->psnr)) - kGlyphHeight - 2;
        if (label_fits({lx - 1, ly - 1, lx + TextWidth(k) + 1, ly + kGlyphHeight + 1})) {
          DrawText(&image, lx, ly, k, kInk);
        }
      }
      DrawMarker(&image, px(p->Time(options.time)), py(p->psnr), marker, 5.0, colour);
    }
    const int lx = left + pw + 16;
    DrawLine(&image, lx, legend_y + 5, lx + 28, legend_y + 5, colour, 2.0);
    DrawMarker(&image, lx + 14, legend_y + 5, marker, 5.0, colour);
    DrawText(&image, lx + 36, legend_y, name, kInk);
    legend_y += 18;
  }
  const int lx = left + pw + 16;
  DrawMarker(&image, lx + 14, legend_y + 5, Marker::kCircle, 8.5, kInk);
  DrawMarker(&image, lx + 14, legend_y + 5, Marker::kCircle, 7.0, {1.0f, 1.0f, 1.0f});
  DrawText(&image, lx + 36, legend_y, "Pareto front (K)", kInk);
  legend_y += 18;
  DrawText(&image, lx, legend_y + 4, "points along a curve:", {0.35f, 0.35f, 0.35f});
  DrawText(&image, lx, legend_y + 18, "K = 1, 2, ... sources", {0.35f, 0.35f, 0.35f});
  return image;
}

}  // namespace fvs::eval
