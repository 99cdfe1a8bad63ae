#!/usr/bin/env python3
"""figures.py -- figures from any recording in the study's CSV: waterfalls, Cartesian detections with hulls,
difference maps, clusters before and after. Used by `make eval`; alone: figures.py FILE.csv --out DIR [-- sonard options].

Runs sonard on the file (--csv-out of the median and foreground stages, --json detections), so
what is drawn is what the daemon computes. Axes in degrees and metres, colour bars in grey levels.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load_csv(path):
    """-> angles (gradians), matrix uint8 (rows x samples), range_m (from metadata, or None), times."""
    angles, rows, rng, times = [], [], None, []
    with open(path) as f:
        for row in csv.reader(f):
            if not row or not row[0][:1].isdigit():
                continue
            if "." in row[0]:
                t, a, rest = float(row[0]), int(row[1]), row[2:]
            else:
                t, a, rest = int(row[0]) + int(row[1]) * 1e-9, int(row[2]), row[3:]
            vals = []
            for field in rest:
                for tok in field.replace("[", " ").replace("]", " ").split():
                    if tok.startswith("range_m="):
                        rng = float(tok.split("=")[1])
                    elif "=" in tok or set(tok) == {"."}:
                        continue
                    else:
                        vals.append(int(tok))
            angles.append(a)
            rows.append(vals)
            times.append(t)
    return np.array(angles), np.array(rows, dtype=np.uint8), rng, np.array(times)


def sweeps_of(angles, max_step=20):
    """Sweep index per row, cut as sonard cuts (wrap, reversal, jump)."""
    out, k, last, d, trav = [], 0, None, 0, 0
    for a in angles:
        if last is not None:
            delta = ((a - last + 600) % 400) - 200
            if delta != 0:
                s = 1 if delta > 0 else -1
                if abs(delta) > max_step or (d != 0 and s != d) or trav + abs(delta) >= 400:
                    k, d, trav = k + 1, 0, 0
                else:
                    d, trav = s, trav + abs(delta)
        out.append(k)
        last = a
    return np.array(out)


def run_sonard(build, path, args, work):
    """sonard on the file: median and foreground exports plus detections."""
    med, fg = os.path.join(work, "median.csv"), os.path.join(work, "fg.csv")
    subprocess.run([f"{build}/sonard", "--replay", path, "--quiet", "--csv-out", med, "--stage", "median", *args], check=True)
    out = subprocess.run([f"{build}/sonard", "--replay", path, "--quiet", "--json", "--csv-out", fg, "--stage", "foreground",
                          *args], check=True, capture_output=True, text=True).stdout
    dets = {d["sweep"]: d for d in map(json.loads, out.splitlines())}
    return load_csv(med)[1], load_csv(fg)[1], dets


def waterfall(ax, m, angles, rng, title):
    deg = angles * 0.9
    im = ax.imshow(m.T, aspect="auto", origin="lower", cmap="viridis", vmin=0, vmax=255,
                   extent=[0, len(m), 0, rng])
    ax.set_xlabel(f"beam (angle {deg.min():.0f}..{deg.max():.0f} deg)")
    ax.set_ylabel("range (m)")
    ax.set_title(title)
    return im


def cartesian(ax, m, angles, rng, title, dets=None, truth=None, vmax=255, cmap="viridis"):
    n = m.shape[1]
    r = (np.arange(n) + 0.5) * rng / n
    th = np.radians(angles * 0.9)
    # draw each beam as a thin wedge of coloured points (cheap stand-in for a fan image)
    X = np.outer(np.cos(th), r)
    Y = np.outer(np.sin(th), r)
    keep = m > 0
    sc = ax.scatter(X[keep], Y[keep], c=m[keep], s=0.3, cmap=cmap, vmin=0, vmax=vmax, linewidths=0)
    if dets:
        for d in dets.get("detections", []):
            h = np.array(d["hull"] + d["hull"][:1])
            ax.plot(h[:, 0], h[:, 1], "r-", lw=1)
            ax.plot(d["x_m"], d["y_m"], "r+", ms=8)
    if truth:
        for o in truth:
            ax.add_patch(plt.Circle((o["x"], o["y"]), max(o.get("radius", 0.2), 0.15), fill=False, color="k", lw=1.0, ls="--"))
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    return sc


KIND_COLOUR = {"object": "lime", "static since start": "white", "structure": "cyan", "wall echo": "deepskyblue"}


def fan(ax, m, angles, rng, title, dets=None, offset_grad=0.0):
    """One sweep as the sonar saw it (each beam a wedge of 1 step, each sample a ring) and sonard's hulls coloured by
    kind (KIND_COLOUR): m rows x samples, angles in gradians, rng metres, offset_grad as sonard's --angle-offset."""
    if len(angles) == 0:
        return
    # Gradians in [-200, 200): a sector across the output frame's 0 stays in one piece.
    a = (np.asarray(angles, float) + offset_grad + 200.0) % 400.0 - 200.0
    order = np.argsort(a)
    a, m = a[order], np.asarray(m, float)[order]
    step = float(np.median(np.diff(a))) if len(a) > 1 else 1.0
    edges = np.radians(np.concatenate([a - step / 2, [a[-1] + step / 2]]) * 0.9)
    r = np.arange(m.shape[1] + 1) * rng / m.shape[1]
    T, R = np.meshgrid(edges, r, indexing="ij")
    ax.pcolormesh(R * np.cos(T), R * np.sin(T), m, cmap="inferno", vmin=0, vmax=max(1.0, np.percentile(m, 99.5)),
                  shading="flat")
    for d in (dets or {}).get("detections", []):
        h = np.array(d["hull"] + d["hull"][:1])
        ax.plot(h[:, 0], h[:, 1], color=KIND_COLOUR.get(d.get("kind", "object"), "red"), lw=1.0)
    ax.set_aspect("equal")
    ax.set_facecolor("black")
    ax.set_title(title, fontsize=7)
    ax.tick_params(labelsize=6)


def make_all(build, path, out, args=(), sweep=None, truth=None, image_fg=None, tag=""):
    """Writes the figure set for one sweep of path into out; returns the file names."""
    os.makedirs(out, exist_ok=True)
    work = os.path.join(out, ".work" + tag)
    os.makedirs(work, exist_ok=True)
    angles, raw, rng, _ = load_csv(path)
    rng = rng or 2.0
    med, fg, dets = run_sonard(build, path, list(args), work)
    sw = sweeps_of(angles)
    k = sweep if sweep is not None else int(sw.max())
    sel = sw == k
    a, R, M, F = angles[sel], raw[sel], med[sel], fg[sel]
    names = []
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.2))
    ims = [waterfall(axs[0], R, a, rng, "raw"), waterfall(axs[1], M, a, rng, "median (sonard)"),
           waterfall(axs[2], F, a, rng, "foreground (sonard)")]
    fig.colorbar(ims[-1], ax=axs, label="echo (grey level 0..255)")
    names.append(f"waterfall{tag}.png")
    fig.savefig(os.path.join(out, names[-1]), dpi=90)
    plt.close(fig)
    fig, axs = plt.subplots(1, 2, figsize=(13, 6))
    cartesian(axs[0], R, a, rng, f"raw, sweep {k}", truth=truth)
    sc = cartesian(axs[1], F, a, rng, f"foreground + detections (red), truth (black dashed), sweep {k}", dets.get(k), truth)
    fig.colorbar(sc, ax=axs, label="grey level")
    names.append(f"detections{tag}.png")
    fig.savefig(os.path.join(out, names[-1]), dpi=90)
    plt.close(fig)
    diffs = [("CSV approach (sonard): original - filtered", R.astype(int) - F.astype(int))]
    if image_fg is not None:
        diffs.append(("image approach (PNG + medianBlur): original - filtered", R.astype(int) - image_fg[sel].astype(int)))
    fig, axs = plt.subplots(1, len(diffs), figsize=(7 * len(diffs), 4.2), squeeze=False)
    for ax, (title, dm) in zip(axs[0], diffs):
        im = ax.imshow(dm.T, aspect="auto", origin="lower", cmap="RdBu_r", vmin=-128, vmax=128, extent=[0, len(dm), 0, rng])
        ax.set_xlabel("beam")
        ax.set_ylabel("range (m)")
        ax.set_title(title)
    fig.colorbar(im, ax=axs, label="difference (grey levels)")
    names.append(f"difference{tag}.png")
    fig.savefig(os.path.join(out, names[-1]), dpi=90)
    plt.close(fig)
    # clusters: cells above the sweep's threshold before clustering; after: coloured by detection, hulls drawn
    fig, axs = plt.subplots(1, 2, figsize=(13, 6))
    d = dets.get(k, {"detections": [], "threshold": 0})
    n = F.shape[1]
    r = (np.arange(n) + 0.5) * rng / n
    th = np.radians(a * 0.9)
    X, Y = np.outer(np.cos(th), r), np.outer(np.sin(th), r)
    hot = F > d.get("threshold", 0)
    axs[0].scatter(X[hot], Y[hot], s=1, c="k")
    axs[0].set_title(f"before: {hot.sum()} cells above the threshold ({d.get('threshold', 0)})")
    axs[1].scatter(X[hot], Y[hot], s=1, c="lightgrey")
    for i, det in enumerate(d["detections"]):
        h = np.array(det["hull"] + det["hull"][:1])
        from matplotlib.path import Path
        inside = Path(h).contains_points(np.column_stack([X[hot], Y[hot]]), radius=0.05)
        axs[1].scatter(X[hot][inside], Y[hot][inside], s=2, color=plt.cm.tab10(i % 10))
        axs[1].plot(h[:, 0], h[:, 1], color=plt.cm.tab10(i % 10), lw=1.2)
        axs[1].plot(det["x_m"], det["y_m"], "k+", ms=8)
    axs[1].set_title(f"after: {len(d['detections'])} clusters (k-means seeded by groups), hulls")
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    names.append(f"clusters{tag}.png")
    fig.savefig(os.path.join(out, names[-1]), dpi=90)
    plt.close(fig)
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--out", required=True)
    ap.add_argument("--build", default="build")
    ap.add_argument("--sweep", type=int, help="sweep to draw (default: the last)")
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    for n in make_all(a.build, a.csv, a.out, extra, a.sweep):
        print(os.path.join(a.out, n))


if __name__ == "__main__":
    sys.exit(main())
