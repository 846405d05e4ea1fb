#!/usr/bin/env python3
"""Seed corpora for the fuzz targets (fuzz/, docs/fuzzing.md), made at run time from the files
already in the repository (scenes/, tests/data/): nothing is duplicated into git.

Usage: scripts/fuzz_corpus.py OUTDIR   -> OUTDIR/<target>/ seed files (OUTDIR is emptied first)

Files a loader takes together are joined with one NUL byte between them, in the order the
target splits them (fuzz/fuzz_common.h, splitParts): Mitsuba main.xml NUL inc.xml (its include
renamed inc.xml), SmallUPBP scene.obj NUL scene.obj.aux NUL scene.mtl (the OBJ cut down to its
groups, each made a closed tetrahedron, its mtllib renamed scene.mtl). Big files are left out (> 128 KiB):
libFuzzer's speed falls with the input size.
"""
import os
import re
import shutil
import struct
import sys
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MAX_SEED = 128 * 1024


def files(pattern_dirs, suffixes):
    for d in pattern_dirs:
        for p in sorted((ROOT / d).rglob("*")):
            if p.is_file() and p.suffix.lower() in suffixes and p.stat().st_size <= MAX_SEED:
                yield p


def put(out, target, name, data):
    d = out / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data)


def small_obj(path):
    """The OBJ with every group replaced by a closed tetrahedron spanning the group's bounding
    box (medium boundaries must be closed): a few hundred bytes instead of megabytes."""
    verts, lines, groups = [], [], []  # groups: [header lines, vertex indices]
    current = None
    for line in path.read_text(errors="replace").splitlines():
        s = line.strip()
        if s.startswith("v "):
            verts.append([float(x) for x in s.split()[1:4]])
        elif s.startswith("mtllib "):
            lines.append("mtllib scene.mtl")
        elif s.startswith(("g ", "o ")):
            current = [[s], []]
            groups.append(current)
        elif s.startswith("usemtl "):
            if current is None or current[1]:
                current = [[], []]
                groups.append(current)
            current[0].append(s)
        elif s.startswith("f ") and current is not None:
            for corner in s.split()[1:]:
                k = int(corner.split("/")[0])
                current[1].append(k - 1 if k > 0 else len(verts) + k)
    out_v, out_f = [], []
    for header, idx in groups:
        if not idx:
            continue
        lo = [min(verts[i][a] for i in idx) for a in range(3)]
        hi = [max(verts[i][a] for i in idx) for a in range(3)]
        pad = max(1e-3, 0.01 * max(h - l for l, h in zip(lo, hi)))
        hi = [h if h - l > pad else l + pad for l, h in zip(lo, hi)]
        base = len(out_v)
        out_v += [lo, [hi[0], lo[1], lo[2]], [lo[0], hi[1], lo[2]], [lo[0], lo[1], hi[2]]]
        a, b, c, d = (base + 1, base + 2, base + 3, base + 4)
        out_f += header + [f"f {a} {c} {b}", f"f {a} {b} {d}", f"f {a} {d} {c}", f"f {b} {c} {d}"]
    vlines = ["v %.4f %.4f %.4f" % tuple(v) for v in out_v]
    return "\n".join(lines + vlines + out_f) + "\n"


def png(width, height, color_type, bit_depth, pixel_bytes, palette=None):
    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body))

    raw = b"".join(b"\0" + pixel_bytes(y) for y in range(height))
    data = b"\x89PNG\r\n\x1a\n" + chunk(
        b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0))
    if palette:
        data += chunk(b"PLTE", palette)
    return data + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)

    for p in files(["scenes", "tests/data/scenes"], {".json"}):
        put(out, "fuzz_json_scene", p.name, p.read_bytes())

    inc = re.compile(rb'(<include\s+filename=")([^"]*)(")')
    for p in files(["tests/data/mitsuba", "tests/data/mitsuba-data"], {".xml"}):
        text = p.read_bytes()
        m = inc.search(text)
        included = b""
        if m:
            target = (p.parent / m.group(2).decode()).resolve()
            if target.is_file():
                included = target.read_bytes()
            text = inc.sub(rb'\1inc.xml\3', text, count=1)
        put(out, "fuzz_mitsuba_scene", p.name, text + b"\0" + included)

    for obj in sorted((ROOT / "scenes/smallupbp").rglob("*.obj")):
        aux = obj.with_name(obj.name + ".aux")
        mtl = obj.with_suffix(".mtl")
        if aux.is_file() and mtl.is_file():
            seed = small_obj(obj).encode() + b"\0" + aux.read_bytes() + b"\0" + mtl.read_bytes()
            put(out, "fuzz_smallupbp_scene", obj.stem, seed)

    for p in files(["tests/data"], {".vol"}):
        put(out, "fuzz_vol_grid", p.name, p.read_bytes())
    for p in files(["tests/data"], {".obj"}):
        put(out, "fuzz_mesh_obj", p.parent.name + "_" + p.name, p.read_bytes())
    for p in files(["tests/data"], {".ply"}):
        put(out, "fuzz_mesh_ply", p.parent.name + "_" + p.name, p.read_bytes())
    for p in files(["tests/data"], {".serialized"}):
        put(out, "fuzz_serialized_mesh", p.name, p.read_bytes())
    for p in files(["tests/data"], {".jpg", ".jpeg"}):
        put(out, "fuzz_jpeg_image", p.parent.name + "_" + p.name, p.read_bytes())
    for p in files(["scenes", "tests/data"], {".exr"}):
        put(out, "fuzz_exr_image", p.parent.name + "_" + p.name, p.read_bytes())
    for p in files(["scenes", "tests/data"], {".png"}):
        put(out, "fuzz_png_image", p.parent.name + "_" + p.name, p.read_bytes())
    # fuzz_stb_image: a format byte (0 bmp, 1 tga, 2 hdr, 3 ppm), then the file; 2x2 each.
    bmp_rows = b"".join(bytes([0, 0, 255, 128, 128, 128]) + b"\0\0" for _ in range(2))
    bmp = (b"BM" + struct.pack("<IHHI", 54 + len(bmp_rows), 0, 0, 54) +
           struct.pack("<IiiHHIIiiII", 40, 2, 2, 1, 24, 0, len(bmp_rows), 2835, 2835, 0, 0) +
           bmp_rows)
    put(out, "fuzz_stb_image", "gen_rgb24.bmp", b"\0" + bmp)
    tga = struct.pack("<BBBHHBHHHHBB", 0, 0, 2, 0, 0, 0, 0, 0, 2, 2, 24, 0) + bytes(12)
    put(out, "fuzz_stb_image", "gen_rgb24.tga", b"\1" + tga)
    tga_rle = struct.pack("<BBBHHBHHHHBB", 0, 0, 10, 0, 0, 0, 0, 0, 2, 2, 24, 0) + \
        bytes([0x83, 10, 20, 30])
    put(out, "fuzz_stb_image", "gen_rle24.tga", b"\1" + tga_rle)
    hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n" + bytes([128, 64, 32, 129] * 4)
    put(out, "fuzz_stb_image", "gen_flat.hdr", b"\2" + hdr)
    put(out, "fuzz_stb_image", "gen_rgb8.ppm", b"\3" + b"P6\n2 2\n255\n" + bytes(range(12)))
    put(out, "fuzz_stb_image", "gen_grey8.pgm", b"\3" + b"P5\n2 2\n255\n" + bytes(range(4)))
    # PNG colour types and depths the reader handles (core/image.h), 4x3 each.
    w, h = 4, 3
    put(out, "fuzz_png_image", "gen_grey8.png", png(w, h, 0, 8, lambda y: bytes(range(y, y + w))))
    put(out, "fuzz_png_image", "gen_grey_alpha8.png", png(w, h, 4, 8, lambda y: bytes(2 * w)))
    put(out, "fuzz_png_image", "gen_rgb16.png", png(w, h, 2, 16, lambda y: bytes(6 * w)))
    put(out, "fuzz_png_image", "gen_rgba8.png", png(w, h, 6, 8, lambda y: bytes(4 * w)))
    put(out, "fuzz_png_image", "gen_palette8.png",
        png(w, h, 3, 8, lambda y: bytes([0, 1, 2, 1]), palette=bytes(range(9))))
    put(out, "fuzz_png_image", "gen_grey1.png", png(8, 2, 0, 1, lambda y: b"\xa5"))

    for d in sorted(out.iterdir()):
        n = len(list(d.iterdir()))
        print(f"fuzz_corpus: {d.name}: {n} seeds")


if __name__ == "__main__":
    main()
