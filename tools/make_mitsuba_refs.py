#!/usr/bin/env python3
"""Renders the reference images of the hand-written Mitsuba scenes in tests/data/mitsuba
with Mitsuba 3 itself (an independent renderer: unibeam's code never makes a reference).

For each SCENE.xml it writes SCENE_ref.exr (mean of SPP samples per pixel) and
SCENE_ref_var.exr (per-sample variance, estimated from the spread of batch means:
var_sample = B * var(batch means of B samples)), 48x48, Mitsuba's `scalar_rgb` variant,
and SCENE_ref.json with the Mitsuba version, sample count and batches.

The scenes' inputs (textures/tiles.png, stripes.jpg, normalmap.png, heights.png, slide.png,
volumes/density.vol, volumes/albedo.vol, volumes/chromatic.vol, volumes/sdf.vol,
meshes/attributes.ply) are
written by --make-inputs, with Mitsuba's own writers.

Usage (not run by the tests; the outputs are committed):
    python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 numpy
    venv/bin/python tools/make_mitsuba_refs.py [--make-inputs] [--spp 4096] [SCENE.xml ...]
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


def make_jpeg(folder):
    """A 16x16 JPEG texture (baseline, Mitsuba's own writer, quality 95)."""
    x = np.linspace(0, 1, 16)
    X, Y = np.meshgrid(x, x)
    img = np.stack([0.9 - 0.7 * Y, 0.2 + 0.7 * X, 0.3 + 0.3 * X * Y], -1)
    img[:, ::4, :] *= 0.25
    mi.Bitmap((img * 255).astype(np.uint8), pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        str(folder / "textures" / "stripes.jpg"), quality=95)


def make_perturbation_maps(folder):
    """normalmap.xml's inputs, 32x32, read raw: a normal map of domes and dents (the
    tangent-space normals n of the height (0.6 / 2 pi) sin(2 pi u) sin(2 pi v), slopes up to
    0.6, stored as (n + 1) / 2) and a grey height field of bumps in [0, 1]."""
    c = (np.arange(32) + 0.5) / 32  # pixel centres; row y is v = c[y]
    U, V = np.meshgrid(c, c)
    a = 0.6
    n = np.stack([-a * np.cos(2 * np.pi * U) * np.sin(2 * np.pi * V),
                  -a * np.sin(2 * np.pi * U) * np.cos(2 * np.pi * V), np.ones_like(U)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgb = np.round((n + 1) / 2 * 255).astype(np.uint8)
    mi.Bitmap(rgb, pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        str(folder / "textures" / "normalmap.png"))
    h = 0.5 + 0.5 * np.sin(4 * np.pi * U) * np.cos(4 * np.pi * V)
    grey = np.round(np.repeat(h[..., None], 3, -1) * 255).astype(np.uint8)
    mi.Bitmap(grey, pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        str(folder / "textures" / "heights.png"))


def make_inputs(folder):
    """A 16x16 sRGB texture and a 12^3 density grid with a 3-channel albedo grid."""
    (folder / "textures").mkdir(exist_ok=True)
    (folder / "volumes").mkdir(exist_ok=True)
    x = np.linspace(0, 1, 16)
    X, Y = np.meshgrid(x, x)
    img = np.stack([0.2 + 0.6 * X, 0.3 + 0.5 * Y, 0.6 - 0.4 * X * Y], -1)
    img[::4, :, :] *= 0.3
    mi.Bitmap((img * 255).astype(np.uint8), pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        str(folder / "textures" / "tiles.png"))
    make_jpeg(folder)
    make_perturbation_maps(folder)
    n = 12
    c = (np.arange(n) + 0.5) / n
    Z, Yv, Xv = np.meshgrid(c, c, c, indexing="ij")  # VolumeGrid data is [z][y][x][channel]
    dens = np.exp(-((Xv - 0.45) ** 2 + (Yv - 0.55) ** 2 + (Z - 0.5) ** 2) / 0.08) + 0.15 * Yv
    mi.VolumeGrid(dens[..., None].astype(np.float32)).write(str(folder / "volumes" / "density.vol"))
    alb = np.stack([0.95 - 0.6 * Xv, 0.4 + 0.5 * Yv, 0.9 * np.ones_like(Xv)], -1)
    mi.VolumeGrid(alb.astype(np.float32)).write(str(folder / "volumes" / "albedo.vol"))
    make_chromatic_volume(folder)
    make_slide(folder)
    make_attribute_mesh(folder)
    make_sdf(folder)


def make_sdf(folder):
    """sdfgrid.xml's distances: a torus and a sphere blended by min (a surface with saddles,
    a thin hole and convex parts), sampled at 14^3 points over [0, 1]^3 (sample i at
    i / 13, Mitsuba's sdfgrid convention; coarse, so that the analytic normals' facets and
    the smooth normals differ visibly), one channel."""
    n = 14
    c = np.arange(n) / (n - 1)
    Z, Y, X = np.meshgrid(c, c, c, indexing="ij")
    qx, qy, qz = X - 0.5, Y - 0.45, Z - 0.5
    torus = np.sqrt((np.sqrt(qx ** 2 + qz ** 2) - 0.27) ** 2 + qy ** 2) - 0.09
    sphere = np.sqrt((X - 0.5) ** 2 + (Y - 0.68) ** 2 + (Z - 0.5) ** 2) - 0.17
    d = np.minimum(torus, sphere)
    mi.VolumeGrid(d[..., None].astype(np.float32)).write(str(folder / "volumes" / "sdf.vol"))


def make_slide(folder):
    """projected.xml's projector slide: 24x12 sRGB (non-square, so the projector's aspect
    ratio matters), colour ramps with a black frame column and black pixel blocks, so that the
    sampling density must cover the bilinear footprint of lit pixels next to black ones."""
    x = (np.arange(24) + 0.5) / 24
    y = (np.arange(12) + 0.5) / 12
    X, Y = np.meshgrid(x, y)
    img = np.stack([0.2 + 0.8 * X, 0.9 - 0.7 * Y, 0.5 + 0.5 * np.sin(6 * X) * Y], -1)
    img[:, 0, :] = 0.0
    img[3:6, 8:12, :] = 0.0
    img[8, :, :] = 0.0
    img[2, 18, :] = 1.0
    mi.Bitmap(np.round(np.clip(img, 0, 1) * 255).astype(np.uint8),
              pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(folder / "textures" / "slide.png"))


def make_attribute_mesh(folder):
    """mesh_attributes.xml's mesh: Mitsuba's own unit cube (24 vertices, 12 triangles) with
    the mesh attributes vertex_color (3 channels per vertex), face_color (3 per triangle) and
    face_weight (1 per triangle), written by Mitsuba's PLY writer."""
    (folder / "meshes").mkdir(exist_ok=True)
    mesh = mi.load_dict({"type": "cube"})
    rng = np.random.default_rng(7)
    mesh.add_attribute("vertex_color", 3, (0.1 + 0.85 * rng.random(3 * 24)).tolist())
    mesh.add_attribute("face_color", 3, (0.1 + 0.85 * rng.random(3 * 12)).tolist())
    mesh.add_attribute("face_weight", 1, rng.random(12).tolist())
    mesh.write_ply(str(folder / "meshes" / "attributes.ply"))


def make_chromatic_volume(folder):
    """A 12^3 sigma_t grid with 3 channels (chromatic.xml): the red, green and blue densities
    peak in different places, and blue has a thin floor everywhere."""
    n = 12
    c = (np.arange(n) + 0.5) / n
    Z, Y, X = np.meshgrid(c, c, c, indexing="ij")
    blob = lambda x, y, z, w: np.exp(-((X - x) ** 2 + (Y - y) ** 2 + (Z - z) ** 2) / w)
    st = np.stack([1.2 * blob(0.3, 0.5, 0.5, 0.05), 1.0 * blob(0.65, 0.4, 0.5, 0.06),
                   0.6 * blob(0.5, 0.7, 0.4, 0.04) + 0.1], -1)
    mi.VolumeGrid(st.astype(np.float32)).write(str(folder / "volumes" / "chromatic.vol"))


def main():
    here = pathlib.Path(__file__).resolve().parent.parent / "tests" / "data" / "mitsuba"
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--res", type=int, default=48)
    ap.add_argument("--make-inputs", action="store_true")
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args()
    mi.set_variant("scalar_rgb")
    if args.make_inputs:
        make_inputs(here)
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
