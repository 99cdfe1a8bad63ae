#!/usr/bin/env python3
"""speckle_fit.py -- which distribution fits the AquaScan pool's water and people: Rayleigh, Weibull, K or lognormal, by range band.

Usage: speckle_fit.py CSV TRUTH.json [--bands 2.1,3.9,6,9,12,15] [--per-band 20000] [--markdown]

Water cells: every sample of the beams between --sector gradians that lies outside each labelled
person's box (widened by 6 gradians and 0.5 m); person cells: the samples inside each box's core
(2 gradians and 0.1 m in from its edges). Each set is subsampled (fixed seed) and fitted by maximum
likelihood to each family of amplitude distributions, with the recorder's clipping below a level c
folded in (a zero sample is P(A <= c), a sample y > 0 is the density at c + y, so the zero bins do
not decide the fit), and the families compared by BIC (lower is better). The K family's shape nu
says how heavy the tail is: nu -> infinity is Rayleigh, nu ~ 1 or below is spiky clutter. The
fitted parameters are what tools/sim/scene.c's speckle-pool model was given.
"""
import argparse
import json
import os
import sys

import numpy as np
from scipy import optimize, special, stats

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figures  # noqa: E402


def ray_lpdf(a, p):
    return np.log(a / p[0] ** 2) - a ** 2 / (2 * p[0] ** 2)


def ray_lcdf(c, p):
    return np.log(-np.expm1(-c ** 2 / (2 * p[0] ** 2)) + 1e-300)


def wb_lpdf(a, p):
    return np.log(p[0] / p[1]) + (p[0] - 1) * np.log(a / p[1]) - (a / p[1]) ** p[0]


def wb_lcdf(c, p):
    return np.log(-np.expm1(-(c / p[1]) ** p[0]) + 1e-300)


def k_lpdf(a, p):
    """K-distributed amplitude, shape nu, mean power mu."""
    nu, mu = p[0], p[1]
    if nu < 0.05 or nu > 200:
        return np.full(np.shape(a), -1e6)
    b = 2 * np.sqrt(nu / mu)
    return (np.log(2 * b) - special.gammaln(nu) + nu * np.log(b * a / 2) + np.log(special.kve(nu - 1, b * a)) - b * a)


def k_lcdf(c, p):
    nu, mu = p[0], p[1]
    if nu < 0.05 or nu > 200:
        return -1e6
    b = 2 * np.sqrt(nu / mu)
    lccdf = np.log(2) - special.gammaln(nu) + nu * np.log(b * c / 2) + np.log(special.kve(nu, b * c)) - b * c
    return np.log(-np.expm1(min(lccdf, -1e-12)))


def ln_lpdf(a, p):
    return stats.lognorm.logpdf(a, p[1], scale=np.exp(p[0]))


def ln_lcdf(c, p):
    return stats.lognorm.logcdf(c, p[1], scale=np.exp(p[0]))


# name: (log density, log cdf, start [params..., clip level c], parameter names)
FAMILIES = {
    "Rayleigh": (ray_lpdf, ray_lcdf, [30.0, 20.0], ["sigma"]),
    "Weibull": (wb_lpdf, wb_lcdf, [1.5, 30.0, 20.0], ["k", "lambda"]),
    "K": (k_lpdf, k_lcdf, [1.0, 1500.0, 20.0], ["nu", "mu"]),
    "lognormal": (ln_lpdf, ln_lcdf, [3.0, 0.8, 20.0], ["m", "s"]),
}


def fit(y):
    """-> {family: (BIC, params incl. clip level c last)} for integer samples y."""
    y = y.astype(float) + 0.5 * (y > 0)  # a level stands for the middle of its bin
    zero = y == 0
    out = {}
    for name, (lpdf, lcdf, p0, _) in FAMILIES.items():
        def nll(p, lpdf=lpdf, lcdf=lcdf):
            if np.any(np.asarray(p) <= 0):
                return 1e12
            c = p[-1]
            v = -(zero.sum() * lcdf(c, p) + lpdf(c + y[~zero], p).sum())
            return v if np.isfinite(v) else 1e12
        res = optimize.minimize(nll, p0, method="Nelder-Mead",
                                options={"maxiter": 4000, "xatol": 1e-4, "fatol": 1e-3})
        out[name] = (2 * res.fun + len(p0) * np.log(len(y)), res.x)
    return out


def cells(csv_path, truth_path, sector):
    angles, m, rng, _ = figures.load_csv(csv_path)
    truth = json.load(open(truth_path))
    rng = rng or truth["range_m"]
    sw = figures.sweeps_of(angles)
    n = m.shape[1]
    r = (np.arange(n) + 0.5) * rng / n
    water, person = [], []
    for i, (a, k) in enumerate(zip(angles, sw)):
        if k >= len(truth["sweeps"]):
            continue
        near = np.zeros(n, bool)
        for o in truth["sweeps"][k]["objects"]:
            g0, g1 = o["box_gradians"]
            r0, r1 = o["box_range_m"]
            if g0 - 6 <= a <= g1 + 6:
                near |= (r >= r0 - 0.5) & (r <= r1 + 0.5)
            if g0 + 2 <= a <= g1 - 2:
                person.append(m[i][(r >= r0 + 0.1) & (r <= r1 - 0.1)])
        if sector[0] < a < sector[1]:
            water.append(np.where(near, -1, m[i].astype(int)))
    return np.array(water), np.concatenate(person), r, rng


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("truth")
    ap.add_argument("--bands", default="2.1,3.9,6,9,12,15", help="range band edges, metres")
    ap.add_argument("--sector", default="110,290", help="gradians whose beams give water cells (the pool)")
    ap.add_argument("--per-band", type=int, default=20000, help="cells fitted per band (subsampled, seed 0)")
    ap.add_argument("--markdown", action="store_true", help="a markdown table, for docs/results.md")
    a = ap.parse_args()
    sector = [float(v) for v in a.sector.split(",")]
    edges = [float(v) for v in a.bands.split(",")]
    water, person, r, rng = cells(a.csv, a.truth, sector)
    gen = np.random.default_rng(0)
    rows = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        b = water[:, (r >= lo) & (r < hi)].ravel()
        b = b[b >= 0]
        if len(b) == 0:
            continue
        b = gen.choice(b, min(a.per_band, len(b)), replace=False)
        rows.append((f"water {lo:g}-{hi:g} m", b, fit(b)))
    p = gen.choice(person, min(a.per_band, len(person)), replace=False)
    rows.append(("person cells", p, fit(p)))
    names = list(FAMILIES)
    if a.markdown:
        print(f"| cells (range {rng:g} m) | n | zero | p99 | " + " | ".join(f"BIC {k}" for k in names) +
              " | best | K shape nu | Weibull k |")
        print("|---" * (6 + len(names)) + "|")
    for label, y, o in rows:
        best = min(o, key=lambda k: o[k][0])
        base = min(v[0] for v in o.values())
        if a.markdown:
            print(f"| {label} | {len(y)} | {np.mean(y == 0):.2f} | {np.percentile(y, 99):.0f} | " +
                  " | ".join(f"{o[k][0] - base:+.0f}" for k in names) +
                  f" | {best} | {o['K'][1][0]:.2f} | {o['Weibull'][1][0]:.2f} |")
        else:
            fams = "  ".join(f"{k} BIC {o[k][0]:.0f} ({', '.join(f'{pn} {v:.3g}' for pn, v in zip(FAMILIES[k][3] + ['c'], o[k][1]))})"
                             for k in names)
            print(f"{label}: n {len(y)}, zero {np.mean(y == 0):.2f}: {fams} -> {best}")


if __name__ == "__main__":
    main()
