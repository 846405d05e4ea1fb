#!/usr/bin/env python3
"""Counts how many scenes of Mitsuba's own data repository `unibeam info` loads (and, with
--render, how many of those `unibeam render` renders: 16x16, one iteration, the scene's own
integrator, exit status 0 and an image without NaN or infinite pixels).

The corpus: every .xml file under docs/scenes and tests/scenes of a checkout of
github.com/mitsuba-renderer/mitsuba-data, except files in include/ and fragments/
folders (pieces that other scenes include). Prints "N of M load", then one line per scene
(OK, or the exit status and its first errors). The corpus itself is not part of unibeam.

Usage: python3 tools/mitsuba_corpus_count.py build/unibeam PATH/TO/mitsuba-data [--render]
"""
import collections
import os
import subprocess
import sys
import tempfile


def renders(exe, scene):
    """Whether `unibeam render` renders the scene at 16x16 for one iteration, with finite
    pixels (`unibeam compare` of the image with itself reports NaN otherwise)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        try:
            p = subprocess.run([exe, "render", scene, "--resolution", "16x16", "-i", "1",
                                "-o", out], capture_output=True, text=True, timeout=600)
        except subprocess.TimeoutExpired:
            return False, "render timeout"
        if p.returncode != 0:
            return False, f"render rc{p.returncode}: " + " ".join(p.stderr.splitlines()[-2:])[:200]
        c = subprocess.run([exe, "compare", out, out], capture_output=True, text=True)
        if c.returncode != 0 or "nan" in c.stdout.lower() or "inf" in c.stdout.lower():
            return False, "non-finite pixels"
        return True, ""


def main():
    exe, root = sys.argv[1], sys.argv[2]
    render = "--render" in sys.argv[3:]
    rendered = 0
    files = []
    for sub in ("docs/scenes", "tests/scenes"):
        for d, _, names in os.walk(os.path.join(root, sub)):
            rel = os.path.relpath(d, root).split(os.sep)
            if "include" in rel or "fragments" in rel:
                continue
            files += [os.path.join(d, n) for n in names if n.endswith(".xml")]
    files.sort()
    loaded, lines, reasons = 0, [], collections.Counter()
    for f in files:
        try:
            p = subprocess.run([exe, "info", f], capture_output=True, text=True, timeout=300)
            rc, errors = p.returncode, [l for l in p.stderr.splitlines() if ": error: " in l]
        except subprocess.TimeoutExpired:
            rc, errors = -1, ["timeout"]
        name = os.path.relpath(f, root)
        if rc == 0:
            loaded += 1
            if not render:
                lines.append("OK   " + name)
                continue
            ok, why = renders(exe, f)
            rendered += ok
            lines.append(("OK   " if ok else "LOAD ") + name + ("" if ok else "  (" + why + ")"))
            continue
        lines.append(f"rc{rc}  " + name)
        for e in errors[:6]:
            lines.append("       " + e.split(": error: ", 1)[-1][:200])
        if errors:
            reasons[errors[0].split(": error: ", 1)[-1][:120]] += 1
    print(f"{loaded} of {len(files)} load" + (f", {rendered} render" if render else ""))
    print("\n".join(lines))
    print("\nfirst error of each failing scene, by count:")
    for r, n in reasons.most_common():
        print(f"{n:4d}  {r}")


if __name__ == "__main__":
    main()
