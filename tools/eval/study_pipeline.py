#!/usr/bin/env python3
"""study_pipeline.py -- the Luna et al. (2025) pipeline as the paper describes it, for timing and as the detection anchor.

pandas load -> combine timestamps -> clean and merge the scan data -> numpy matrix -> scipy
median_filter (5 x 5) -> background = median across the scans of each range bin, subtracted and
clamped at 0 -> threshold mean + k std -> sklearn KMeans -> scipy ConvexHull per cluster of at
least min_cluster_size points. Prints the time from load to detections (and to the end of
filtering, the paper's own definition), or, with --json, one JSON line per sweep of --beams rows.
"""
import argparse
import json
import sys
import time

import numpy as np
import pandas as pd
from scipy.ndimage import median_filter
from scipy.spatial import ConvexHull
from sklearn.cluster import KMeans


def load(path):
    df = pd.read_csv(path, header=None, dtype=str, comment="#")
    if not df.iloc[0, 0].replace(".", "").isdigit():
        df = df.iloc[1:]
    # combined sec.nsec timestamps, as the paper's preprocessing does
    if df[0].str.contains(".", regex=False).all():
        angle_col, data_cols = 1, df.columns[2:]
    else:
        df["ts"] = df[0] + "." + df[1].str.zfill(9)
        angle_col, data_cols = 2, [c for c in df.columns[3:] if c != "ts"]
    text = df[data_cols].fillna("").astype(str).agg(" ".join, axis=1)
    text = text.str.replace("...", " ", regex=False).str.replace(r"[\[\]]|\w+=\S+", " ", regex=True)
    scans = text.str.split()
    matrix = np.array(scans.tolist(), dtype=np.uint8)
    return df[angle_col].astype(int).to_numpy(), matrix


def detect(fg, angles, range_m, k, n_clusters, min_cluster_size):
    thr = fg.mean() + k * fg.std()
    idx = np.argwhere(fg > thr)
    dets = []
    if len(idx) < n_clusters:
        return thr, dets
    n = fg.shape[1]
    r = (idx[:, 1] + 0.5) * range_m / n
    th = angles[idx[:, 0]] * np.pi / 200.0
    xy = np.column_stack([r * np.cos(th), r * np.sin(th)])
    labels = KMeans(n_clusters=n_clusters, n_init="auto", random_state=0).fit_predict(xy)
    for c in range(n_clusters):
        pts = xy[labels == c]
        if len(pts) < min_cluster_size:
            continue
        try:
            hull = ConvexHull(pts)
            area, verts = hull.volume, pts[hull.vertices]
        except Exception:  # collinear or too few points
            area, verts = 0.0, pts[:1]
        cx, cy = pts.mean(axis=0)
        dets.append({"x_m": float(cx), "y_m": float(cy), "points": int(len(pts)), "area_m2": float(area),
                     "hull": verts.round(3).tolist()})
    return thr, dets


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--range", type=float, default=12.0, help="metres (default 12)")
    ap.add_argument("--threshold", type=float, default=3.0, help="k of mean + k std (default 3)")
    ap.add_argument("--clusters", type=int, default=3, help="KMeans n_clusters (default 3)")
    ap.add_argument("--min-cluster-size", type=int, default=20)
    ap.add_argument("--beams", type=int, default=0, help="rows per sweep; 0 = the whole file is one scan matrix")
    ap.add_argument("--json", action="store_true", help="one line per sweep, like sonard --json")
    a = ap.parse_args()
    t0 = time.perf_counter()
    angles, m = load(a.csv)
    t_load = time.perf_counter()
    step = a.beams or len(m)
    filtered_at = None
    out = []
    for s, start in enumerate(range(0, len(m), step)):
        block, ang = m[start:start + step], angles[start:start + step]
        filt = median_filter(block, size=5)
        bg = np.median(filt, axis=0)
        fg = np.clip(filt.astype(np.int16) - bg, 0, None)
        if filtered_at is None:
            filtered_at = time.perf_counter()
        thr, dets = detect(fg, ang, a.range, a.threshold, a.clusters, a.min_cluster_size)
        out.append({"sweep": s, "beams": len(block), "threshold": float(thr), "detections": dets})
    t1 = time.perf_counter()
    if a.json:
        for o in out:
            print(json.dumps(o))
    else:
        print(f"rows {len(m)} samples {m.shape[1]} load_s {t_load - t0:.4f} "
              f"load_to_filtered_s {filtered_at - t0:.4f} total_s {t1 - t0:.4f}")


if __name__ == "__main__":
    sys.exit(main())
