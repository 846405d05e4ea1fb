#!/usr/bin/env python3
"""Writes tests/data/mitsuba/principled_table.json: values of Mitsuba 3's own `principled` and
`principledthin` BSDFs (eval, which includes |cos wo|, and pdf) for parameter sets and direction pairs, in both
transport modes. tests/bsdf_principled_test.cpp checks unibeam's implementation
(kernels/shared/ub_principled.h) against them: an independent reference, made by Mitsuba.

Local shading frame: z the normal, x the tangent of anisotropy. Half of the wo are drawn
uniformly on the sphere, half by Mitsuba's own sample(), so that the lobes are covered.

Usage (not run by the tests; the output is committed):
    python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 numpy
    venv/bin/python tools/make_principled_table.py
"""
import json
import math
import pathlib
import random

import mitsuba as mi

mi.set_variant("scalar_rgb")

PARAMS = [
    {"base_color": [0.8, 0.3, 0.2], "roughness": 0.4},
    # the example of Mitsuba's documentation
    {"base_color": [1.0, 1.0, 1.0], "metallic": 0.7, "specular": 0.6, "roughness": 0.2,
     "spec_tint": 0.4, "anisotropic": 0.5, "sheen": 0.3, "sheen_tint": 0.2, "clearcoat": 0.6,
     "clearcoat_gloss": 0.3, "spec_trans": 0.4},
    {"base_color": [0.9, 0.95, 1.0], "spec_trans": 1.0, "eta": 1.33, "roughness": 0.3},
    {"base_color": [0.2, 0.6, 0.9], "flatness": 0.7, "sheen": 1.0, "sheen_tint": 0.5,
     "roughness": 0.8, "specular": 0.8},
    {"base_color": [0.9, 0.6, 0.2], "metallic": 1.0, "clearcoat": 1.0, "clearcoat_gloss": 0.9,
     "roughness": 0.1, "anisotropic": 0.8},
    {"base_color": [0.5, 0.5, 0.5], "spec_trans": 0.6, "metallic": 0.2, "roughness": 0.6,
     "eta": 1.6, "main_specular_sampling_rate": 0.5, "diffuse_reflectance_sampling_rate": 2.0,
     "clearcoat": 0.3, "clearcoat_sampling_rate": 0.5},
    # principledthin (the "type" key selects it)
    {"type": "principledthin", "base_color": [0.7, 0.1, 0.1], "roughness": 0.15,
     "spec_tint": 0.1, "anisotropic": 0.5, "spec_trans": 0.8, "diff_trans": 0.3, "eta": 1.33},
    {"type": "principledthin", "base_color": [0.3, 0.8, 0.4], "roughness": 0.5,
     "diff_trans": 1.4, "sheen": 0.7, "sheen_tint": 0.5, "flatness": 0.4},
    {"type": "principledthin", "base_color": [0.9, 0.9, 0.6], "roughness": 0.35, "spec_trans": 0.5,
     "diff_trans": 0.8, "eta": 1.6, "specular_transmittance_sampling_rate": 2.0,
     "diffuse_transmittance_sampling_rate": 0.5},
]
PAIRS = 48


def sphere(rng):
    z = 2.0 * rng.random() - 1.0
    phi = 2.0 * math.pi * rng.random()
    r = math.sqrt(max(0.0, 1.0 - z * z))
    return [r * math.cos(phi), r * math.sin(phi), z]


def bsdf_dict(p):
    d = {"type": "principled"}
    for k, v in p.items():
        d[k] = {"type": "rgb", "value": v} if isinstance(v, list) else v
    return d  # p's "type", where given, replaces the default


def main():
    rng = random.Random(7)
    rows = []
    for p in PARAMS:
        bsdf = mi.load_dict(bsdf_dict(p))
        for mode_name, mode in (("radiance", mi.TransportMode.Radiance),
                                ("importance", mi.TransportMode.Importance)):
            ctx = mi.BSDFContext(mode)
            for k in range(PAIRS):
                wi = sphere(rng)
                if abs(wi[2]) < 0.05:
                    continue
                si = mi.SurfaceInteraction3f()
                si.wi = mi.Vector3f(wi)
                if k % 2 == 0:
                    wo = sphere(rng)
                else:
                    bs, _ = bsdf.sample(ctx, si, rng.random(), mi.Point2f(rng.random(), rng.random()))
                    if not bs.pdf > 0:
                        continue
                    wo = [bs.wo[0], bs.wo[1], bs.wo[2]]
                if abs(wo[2]) < 0.05:
                    continue
                value = bsdf.eval(ctx, si, mi.Vector3f(wo))
                pdf = bsdf.pdf(ctx, si, mi.Vector3f(wo))
                rows.append({"params": p, "mode": mode_name, "wi": [float(x) for x in wi],
                             "wo": [float(x) for x in wo],
                             "value": [float(value[0]), float(value[1]), float(value[2])],
                             "pdf": float(pdf)})
    out = pathlib.Path(__file__).resolve().parent.parent / "tests/data/mitsuba/principled_table.json"
    out.write_text(json.dumps({"mitsuba": mi.__version__, "variant": "scalar_rgb",
                               "generator": "tools/make_principled_table.py", "rows": rows},
                              indent=0) + "\n")
    print(f"{out}: {len(rows)} rows")


if __name__ == "__main__":
    main()
