#!/usr/bin/env python3
"""Times the network's forward pass in PyTorch with the layer shapes of our LibTorch
FvsNet (src/fvs/net/net.cc, ModelConfig in src/fvs/net/model_config.h): the same
encoder (VGG16-like stages + U-Net decoder), feature warp (grid_sample) and recurrent
blending U-Net (ConvGRU per stage, per-source RGB + confidence heads, softmax over the
sources). Written for this project from our own C++ code, random weights: timing only,
the "same architecture timed on the same GPU in the same run" beside the C++ benchmark
(fvs_train_main --Train.benchmark 1).

  torch_forward_bench.py [--config model.json] [--sizes 480x270,960x540] [--ks 1,2,...]
                         [--precisions fp32,bf16,fp16] [--device cuda|cpu]
                         [--seconds 60] [--csv out.csv]

--config: a model card (model.json: its "config") or a bare ModelConfig JSON; default
the reference `fvs` layout. Seconds per view: encode (K sources), warp (grid_sample of the
features, fp32 as the C++ code), blend; after one untimed warm-up per size and
precision; a CUDA synchronisation ends each part.
"""
import argparse
import csv
import json
import sys
import time

import torch
import torch.nn.functional as F
from torch import nn

FVS = dict(feature_channels=64, use_masks=True, use_gru=True, soft_argmax=True,
           encoder_channels=[64, 128, 256], encoder_convs=[2, 2, 3],
           blend_channels=[64, 128, 256, 512], blend_convs_per_stage=3, rgb_skip=False)


def conv(cin, cout):
    return nn.Conv2d(cin, cout, 3, padding=1)


class Gru(nn.Module):
    def __init__(self, cin, hidden):
        super().__init__()
        self.hidden = hidden
        self.gates = conv(cin + hidden, 2 * hidden)
        self.candidate = conv(cin + hidden, hidden)

    def forward(self, x, h):
        if h is None:
            h = x.new_zeros(x.shape[0], self.hidden, x.shape[2], x.shape[3])
        z, r = torch.sigmoid(self.gates(torch.cat([x, h], 1))).chunk(2, 1)
        c = torch.relu(self.candidate(torch.cat([x, r * h], 1)))
        return (1 - z) * h + z * c


class Net(nn.Module):
    def __init__(self, c):
        super().__init__()
        self.c = c
        ec = c["encoder_channels"]
        ch = 3
        self.enc_down = nn.ModuleList()
        for s, w in enumerate(ec):
            stage = nn.ModuleList()
            for _ in range(c["encoder_convs"][s]):
                stage.append(conv(ch, w))
                ch = w
            self.enc_down.append(stage)
        self.enc_up = nn.ModuleList()
        for s in range(len(ec) - 2, -1, -1):
            out = c["feature_channels"] if s == 0 else ec[s]
            self.enc_up.append(nn.ModuleList([conv(ch + ec[s], out), conv(out, out)]))
            ch = out
        enc_out = c["feature_channels"] + (3 if c["rgb_skip"] else 0)
        bc = c["blend_channels"]
        levels = list(range(len(bc))) + list(range(len(bc) - 2, -1, -1))
        ch = enc_out + (2 if c["use_masks"] else 0)
        self.stages = nn.ModuleList()
        self.levels = len(bc)
        for i, l in enumerate(levels):
            cin = ch + bc[l] if i >= len(bc) else ch
            plain = nn.ModuleList()
            for _ in range(c["blend_convs_per_stage"] - (1 if c["use_gru"] else 0)):
                plain.append(conv(cin, bc[l]))
                cin = bc[l]
            stage = nn.Module()
            stage.plain = plain
            stage.gru = Gru(cin, bc[l]) if c["use_gru"] else None
            self.stages.append(stage)
            ch = bc[l]
        self.rgb = nn.Conv2d(bc[0], 3, 1)
        self.conf = nn.Conv2d(bc[0], 1, 1)
        self.enc_stride = 2 ** (len(ec) - 1)
        self.blend_stride = 2 ** (len(bc) - 1)

    @staticmethod
    def pad(x, stride, mode):
        h, w = x.shape[2], x.shape[3]
        ph, pw = (-h) % stride, (-w) % stride
        if ph == 0 and pw == 0:
            return x
        if mode == "replicate" and x.dtype not in (torch.float32, torch.float64) and x.is_cpu:
            return F.pad(x.float(), (0, pw, 0, ph), mode=mode).to(x.dtype)
        return F.pad(x, (0, pw, 0, ph), mode=mode)

    def encode(self, images):
        h, w = images.shape[2], images.shape[3]
        x = self.pad(images, self.enc_stride, "replicate")
        skips = []
        for s, stage in enumerate(self.enc_down):
            if s > 0:
                x = F.avg_pool2d(x, 2)
            for cv in stage:
                x = torch.relu(cv(x))
            skips.append(x)
        for i, stage in enumerate(self.enc_up):
            skip = skips[len(skips) - 2 - i]
            x = torch.cat([F.interpolate(x, size=skip.shape[2:], mode="nearest"), skip], 1)
            for cv in stage:
                x = torch.relu(cv(x))
        x = x[:, :, :h, :w]
        return torch.cat([x, images], 1) if self.c["rgb_skip"] else x

    def blend_pass(self, x, state):
        skips = []
        for i, stage in enumerate(self.stages):
            if i < self.levels:
                if i > 0:
                    x = F.avg_pool2d(x, 2)
            else:
                skip = skips[2 * (self.levels - 1) - i]
                x = torch.cat([F.interpolate(x, size=skip.shape[2:], mode="nearest"), skip], 1)
            for cv in stage.plain:
                x = torch.relu(cv(x))
            if stage.gru is not None:
                x = stage.gru(x, state[i])
                state[i] = x
            if i < self.levels - 1:
                skips.append(x)
        return x

    def blend(self, warped, valid_depth, valid_warp):
        k, _, h, w = warped.shape
        state = [None] * len(self.stages)
        rgbs, confs = [], []
        for i in range(k):
            x = warped[i:i + 1]
            if self.c["use_masks"]:
                x = torch.cat([x, valid_depth.to(x.dtype), valid_warp[i:i + 1].to(x.dtype)], 1)
            top = self.blend_pass(self.pad(x, self.blend_stride, "constant"), state)[:, :, :h, :w]
            rgbs.append(self.rgb(top))
            confs.append(self.conf(top))
        c = torch.cat(confs, 0).float()
        weights = torch.softmax(c, 0)
        return (weights * torch.cat(rgbs, 0).float()).sum(0, keepdim=True).clamp(-1, 1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config")
    ap.add_argument("--sizes", default="480x270,960x540")
    ap.add_argument("--ks", default="1,2,3,4,5,6,7,8")
    ap.add_argument("--precisions", default="fp32,bf16,fp16")
    ap.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--csv")
    a = ap.parse_args()
    c = dict(FVS)
    if a.config:
        j = json.load(open(a.config))
        j = j.get("config", j)
        if j.get("blender", "unet") != "unet":
            sys.exit("torch_forward_bench: only the U-Net blender (not %s)" % j.get("blender"))
        if j.get("depthwise_separable"):
            sys.exit("torch_forward_bench: depthwise-separable layouts are not mirrored")
        c.update({k: j[k] for k in FVS if k in j})
    if not c["soft_argmax"]:
        sys.exit("torch_forward_bench: only soft-argmax layouts are mirrored")
    dev = torch.device(a.device)
    dtypes = {"fp32": torch.float32, "bf16": torch.bfloat16, "fp16": torch.float16}
    torch.backends.cudnn.benchmark = True
    torch.manual_seed(0)
    base = Net(c).eval()
    print("torch %s on %s (%s), %d parameters, config %s" % (
        torch.__version__, dev, torch.cuda.get_device_name(0) if dev.type == "cuda" else "CPU",
        sum(p.numel() for p in base.parameters()), json.dumps(c)))
    print("%9s %2s %5s %9s %9s %9s %9s" % ("size", "K", "prec", "encode_s", "warp_s", "blend_s", "total_s"))
    rows, start = [], time.time()
    sizes = [tuple(int(v) for v in s.split("x")) for s in a.sizes.split(",")]

    def sync():
        if dev.type == "cuda":
            torch.cuda.synchronize()

    for si, (w, h) in enumerate(sizes):
        share = (a.seconds - (time.time() - start)) / (len(sizes) - si)
        size_start = time.time()
        for k in [int(v) for v in a.ks.split(",")]:
            for p in a.precisions.split(","):
                if p == "fp16" and dev.type != "cuda":
                    continue
                if time.time() - size_start > share:
                    print("skipped: %dx%d K=%d %s (time bound)" % (w, h, k, p))
                    continue
                net = Net(c).eval()
                net.load_state_dict(base.state_dict())
                net = net.to(dev, dtypes[p]).to(memory_format=torch.channels_last)
                with torch.inference_mode():
                    images = (torch.rand(k, 3, h, w, device=dev) * 2 - 1).to(dtypes[p])
                    images = images.contiguous(memory_format=torch.channels_last)
                    grid = torch.rand(k, h, w, 2, device=dev) * 2 - 1
                    vd = torch.ones(1, 1, h, w, device=dev)
                    vw = (torch.rand(k, 1, h, w, device=dev) > 0.2).float()
                    times = None
                    for rep in range(2):  # the first is the warm-up
                        sync(); t0 = time.time()
                        feats = net.encode(images)
                        sync(); t1 = time.time()
                        warped = F.grid_sample(feats.float(), grid, align_corners=False).to(dtypes[p])
                        sync(); t2 = time.time()
                        net.blend(warped.contiguous(memory_format=torch.channels_last), vd, vw)
                        sync(); t3 = time.time()
                        times = (t1 - t0, t2 - t1, t3 - t2)
                row = dict(width=w, height=h, k=k, precision=p, encode_s=times[0],
                           warp_s=times[1], blend_s=times[2], total_s=sum(times))
                rows.append(row)
                print("%4dx%-4d %2d %5s %9.4f %9.4f %9.4f %9.4f" % (
                    w, h, k, p, times[0], times[1], times[2], sum(times)))
                sys.stdout.flush()
                if a.csv:
                    with open(a.csv, "w", newline="") as f:
                        wr = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
                        wr.writeheader()
                        wr.writerows(rows)


if __name__ == "__main__":
    main()
