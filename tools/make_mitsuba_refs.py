#!/usr/bin/env python3
"""Renders the reference images of the hand-written Mitsuba scenes in tests/data/mitsuba
with Mitsuba 3 itself (an independent renderer: unibeam's code never makes a reference).

For each SCENE.xml it writes SCENE_ref.exr (mean of SPP samples per pixel) and
SCENE_ref_var.exr (per-sample variance, estimated from the spread of batch means:
var_sample = B * var(batch means of B samples)), 48x48, Mitsuba's `scalar_rgb` variant,
and SCENE_ref.json with the Mitsuba version, sample count and batches.

Usage (not run by the tests; the outputs are committed):
    python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 numpy
    venv/bin/python tools/make_mitsuba_refs.py [--spp 4096] [SCENE.xml ...]
"""
import argparse
import json
import pathlib
import time

import mitsuba as mi
import numpy as np

BATCH = 16  # samples per batch; the variance is estimated from SPP / BATCH batch means


def render_reference(path, spp, res):
    scene = mi.load_file(str(path), res=res, spp=BATCH)
    batches = spp // BATCH
    total = np.zeros((res, res, 3))
    total2 = np.zeros((res, res, 3))
    start = time.time()
    for b in range(batches):
        img = np.array(mi.render(scene, spp=BATCH, seed=b), dtype=np.float64)[:, :, :3]
        total += img
        total2 += img * img
    mean = total / batches
    var_batch = (total2 / batches - mean * mean) * batches / (batches - 1)
    var_sample = np.maximum(var_batch * BATCH, 0.0)
    return mean, var_sample, time.time() - start


def main():
    here = pathlib.Path(__file__).resolve().parent.parent / "tests" / "data" / "mitsuba"
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--res", type=int, default=48)
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args()
    mi.set_variant("scalar_rgb")
    scenes = [pathlib.Path(s) for s in args.scenes] or sorted(
        p for p in here.glob("*.xml") if not p.name.startswith("include_"))
    for path in scenes:
        mean, var, secs = render_reference(path, args.spp, args.res)
        stem = path.with_suffix("")
        mi.Bitmap(mean.astype(np.float32)).write(str(stem) + "_ref.exr")
        mi.Bitmap(var.astype(np.float32)).write(str(stem) + "_ref_var.exr")
        meta = {"renderer": "Mitsuba " + mi.__version__, "variant": "scalar_rgb",
                "spp": args.spp, "batch": BATCH, "resolution": args.res,
                "seconds": round(secs, 1)}
        (pathlib.Path(str(stem) + "_ref.json")).write_text(json.dumps(meta, indent=1) + "\n")
        print(f"{path.name}: {secs:.1f} s, image mean {mean.mean((0, 1))}")


if __name__ == "__main__":
    main()
