"""Collects K independent SmallUPBP renders of one bundled scene into a region reference.

SmallUPBP (github.com/PetrVevoda/smallupbp, public source) is built and run outside this
repository, for testing only; its code is not part of unibeam. Its UPBP renderers seed
iteration i with BASE + i, so runs are independent only when their -seed values lie more
than the iteration count apart (we use 10000 (k + 1)).

Writes SCENE_upbp_ref.exr (the mean image of the K runs) and SCENE_upbp_ref.json: the command
line, the seeds, and each run's RGB means over a 4 x 4 grid of image regions (row by row),
from which tests/smallupbp_reference_test.cpp takes the reference region means and their
standard errors.

Usage (PyPI: mitsuba, numpy):
    venv/bin/python tools/make_smallupbp_region_refs.py --scene bunny --iterations 256 \\
        --command "smallupbp -s -1 ... -seed {SEED} -o bunny_{k}.exr" --seconds S RUN_0.exr ...
"""
import argparse
import json

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[:, :, :3]


def region_means(img, grid=4):
    h, w, _ = img.shape
    out = []
    for ry in range(grid):
        for rx in range(grid):
            block = img[ry * h // grid:(ry + 1) * h // grid, rx * w // grid:(rx + 1) * w // grid]
            out.append([float(v) for v in block.mean(axis=(0, 1))])
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", required=True)
    ap.add_argument("--iterations", type=int, required=True)
    ap.add_argument("--command", required=True)
    ap.add_argument("--seconds", type=float, default=0.0)
    ap.add_argument("--out", default="tests/data/smallupbp-refs")
    ap.add_argument("runs", nargs="+")
    args = ap.parse_args()
    images = [load(p) for p in args.runs]
    mean = np.mean(images, axis=0)
    mi.Bitmap(mean.astype(np.float32)).write(f"{args.out}/{args.scene}_upbp_ref.exr")
    k = len(images)
    means = [im.mean(axis=(0, 1)) for im in images]
    info = {
        "scene": f"scenes/smallupbp/{args.scene}/{args.scene}.obj",
        "renderer": "SmallUPBP (public source, built locally on Debian 12 for this comparison "
                    "only; its code is not in this repository)",
        "smallupbp_commit": "cb655e846b46e0853e58fd9cc88c18ad1142227e",
        "command": args.command,
        "seeds": [10000 * (i + 1) for i in range(k)],
        "seed_rule": "SEED = 10000 (k + 1), k = 0..K-1: SmallUPBP's UPBP seeds iteration i "
                     "with SEED + i, so the runs share no iteration",
        "K": k,
        "iterations_per_run": args.iterations,
        "resolution": [int(mean.shape[1]), int(mean.shape[0])],
        "seconds": args.seconds,
        "image_mean_rgb": [float(v) for v in np.mean(means, axis=0)],
        "image_mean_rgb_stderr": [float(v) for v in np.std(means, axis=0, ddof=1) / np.sqrt(k)],
        "regions": "4 x 4 grid, row by row from the top left; RGB means per run",
        "region_means_per_run": [region_means(im) for im in images],
    }
    with open(f"{args.out}/{args.scene}_upbp_ref.json", "w") as f:
        json.dump(info, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
