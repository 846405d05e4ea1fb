"""Convergence plot of `unibeam study` (embedded in the binary by CMake, run with
python3 and Debian's python3-matplotlib): RMSE against seconds on log-log axes, one line
per technique, the fitted slope (summary.csv, fitted by the study) in the legend.

Usage: python3 study_plot.py DIR   (reads DIR/convergence.csv and DIR/summary.csv,
writes DIR/convergence.png)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(folder):
    series = {}
    with open(os.path.join(folder, "convergence.csv")) as f:
        for row in csv.DictReader(f):
            s = series.setdefault(row["technique"], ([], []))
            s[0].append(float(row["seconds"]))
            s[1].append(float(row["rmse"]))
    slopes = {}
    with open(os.path.join(folder, "summary.csv")) as f:
        for row in csv.DictReader(f):
            slopes[row["technique"]] = row["slope"]
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    for name, (x, y) in series.items():
        pts = [(a, b) for a, b in zip(x, y) if a > 0 and b > 0]
        if not pts:
            continue
        slope = slopes.get(name, "nan")
        label = name if slope == "nan" else "%s (slope %.2f)" % (name, float(slope))
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker="o", markersize=3,
                  label=label)
    ax.set_xlabel("seconds")
    ax.set_ylabel("RMSE against the reference")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Error against time (slope -0.5: unbiased Monte Carlo)")
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "convergence.png"))


if __name__ == "__main__":
    main(sys.argv[1])
