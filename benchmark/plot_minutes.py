#!/usr/bin/env python3
"""Quality against the wall minutes of per-scene training (issue 41, doc/refine.md): PSNR, SSIM
and LPIPS on the views held out of the geometry, ours (0 = ulr, then
view_synthesis_refine) beside the OpenSplat peer, one colour per scene, from a CSV with
the columns scene,method,minutes,wall_s,psnr,ssim,lpips. Plain SVG, no plotting library.

  benchmark/plot_minutes.py doc/refine_minutes.csv doc/images/refine_minutes.svg
"""
import csv
import sys

TICKS = [0, 1, 3, 10, 30, 90]  # minutes, evenly spaced on the axis
COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]
PANELS = [("psnr", "PSNR (dB)"), ("ssim", "SSIM"), ("lpips", "LPIPS (lower is better)")]
W, H, PAD = 300, 200, 52


def x_of(minutes):
    # Piecewise linear between the ticks, so that 1, 3, 10 and 30 stay readable.
    for i in range(len(TICKS) - 1):
        a, b = TICKS[i], TICKS[i + 1]
        if minutes <= b:
            return i + (minutes - a) / (b - a)
    return len(TICKS) - 1


def main(src, dst):
    rows = list(csv.DictReader(open(src)))
    scenes = sorted({r["scene"] for r in rows}, key=[r["scene"] for r in rows].index)
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
           'font-family="sans-serif" font-size="11">' % (len(PANELS) * W + 10,
                                                         len(scenes) * H + 50),
           '<rect width="100%" height="100%" fill="white"/>']
    # One row per scene (its own ranges), one column per metric.
    for s, scene in enumerate(scenes):
        colour = COLOURS[s % len(COLOURS)]
        mine = [r for r in rows if r["scene"] == scene]
        for p, (key, label) in enumerate(PANELS):
            values = [float(r[key]) for r in mine]
            lo, hi = min(values), max(values)
            margin = 0.08 * (hi - lo or 1)
            lo, hi = lo - margin, hi + margin
            ox, oy = p * W + PAD, s * H

            def px(m):
                return ox + x_of(m) / (len(TICKS) - 1) * (W - PAD - 10)

            def py(v):
                return oy + 22 + (hi - v) / (hi - lo) * (H - 62)

            out.append('<text x="%d" y="%d" font-weight="bold">%s: %s</text>' %
                       (ox, oy + 14, scene, label))
            out.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' %
                       (ox, oy + H - 40, ox + W - PAD - 10, oy + H - 40))
            out.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' %
                       (ox, oy + 22, ox, oy + H - 40))
            for t in TICKS:
                out.append('<text x="%.1f" y="%d" text-anchor="middle">%d</text>' %
                           (px(t), oy + H - 27, t))
            for k in range(5):
                v = lo + (hi - lo) * k / 4
                out.append('<text x="%d" y="%.1f" text-anchor="end">%.*f</text>' %
                           (ox - 3, py(v) + 4, 2 if key == "psnr" else 3, v))
            for method, dash in (("ours", ""), ("peer", ' stroke-dasharray="5,3"')):
                # At the wall time each run took (a budget can be missed: the peer's
                # step count is fitted from its previous run's rate).
                pts = sorted((float(r["wall_s"]) / 60, float(r[key])) for r in mine
                             if r["method"] == method)
                if not pts:
                    continue
                path = " ".join("%.1f,%.1f" % (px(m), py(v)) for m, v in pts)
                out.append('<polyline points="%s" fill="none" stroke="%s" stroke-width="1.6"%s/>'
                           % (path, colour, dash))
                for m, v in pts:
                    out.append('<circle cx="%.1f" cy="%.1f" r="2.5" fill="%s"/>' %
                               (px(m), py(v), colour))
    out.append('<text x="%d" y="%d">x: wall minutes each run took on the 2-core CPU. Solid: ours '
               '(0 = ulr, then view_synthesis_refine); dashed: OpenSplat. Views held out of '
               'the geometry.</text>' % (PAD, len(scenes) * H + 20))
    out.append("</svg>")
    open(dst, "w").write("\n".join(out) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot_minutes.py minutes.csv out.svg")
    main(sys.argv[1], sys.argv[2])
