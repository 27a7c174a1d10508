#!/usr/bin/python3
"""Independent peer of analysis/qc/pod.h: the hit/miss POD of MIL-HDBK-1823A with SciPy.

Reads a CSV with columns size and hit (and optionally class: one fit per class) and prints
JSON {class: {b0, b1, a90, a90_95_lr, a90_95_wald, log_likelihood}} for the logit link on
x = a (or x = ln a with --log). Written from the handbook's statement, sharing no code with
eol: maximum likelihood by scipy.optimize.minimize (BFGS, then Nelder-Mead polish), the
covariance from the observed information of the logit model (X^T W X with W = p (1 - p),
which for the logit equals the expected one), the Wald bound where
b0 + b1 x - z sqrt(var) = logit 0.9, and the likelihood-ratio bound where the profile
deviance (b1 maximised with the curve through (x90, 0.9)) reaches chi2_1(0.90), found with
scipy.optimize.brentq.
"""
import argparse
import csv
import json
import sys
from collections import defaultdict

import numpy as np
from scipy import optimize, stats
from scipy.special import expit, log_expit


def nll(b, x, h):
    eta = b[0] + b[1] * x
    return -np.sum(h * log_expit(eta) + (1 - h) * log_expit(-eta))


def fit(x, h, gamma=0.95, level=0.9):
    p0 = h.mean()
    start = np.array([np.log(p0 / (1 - p0)), 0.0])
    r = optimize.minimize(nll, start, args=(x, h), method="BFGS", options={"gtol": 1e-10})
    r = optimize.minimize(nll, r.x, args=(x, h), method="Nelder-Mead",
                          options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 20000})
    b0, b1 = r.x
    ll = -r.fun
    p = expit(b0 + b1 * x)
    w = p * (1 - p)
    info = np.array([[w.sum(), (w * x).sum()], [(w * x).sum(), (w * x * x).sum()]])
    cov = np.linalg.inv(info)
    q = np.log(level / (1 - level))
    z = stats.norm.ppf(gamma)
    x90 = (q - b0) / b1
    span = x.max() - x.min()

    def wald(xx):
        v = cov[0, 0] + 2 * xx * cov[0, 1] + xx * xx * cov[1, 1]
        return b0 + b1 * xx - z * np.sqrt(v) - q

    def profile_dev(xp):
        f = lambda s: nll([q - s * xp, s], x, h)
        best = optimize.minimize_scalar(f, bounds=(1e-9, 50 * b1), method="bounded",
                                        options={"xatol": 1e-12})
        return 2 * (best.fun - r.fun) - stats.chi2.ppf(2 * gamma - 1, 1)

    def bound(g):
        hi = x90 + span / 16
        while g(hi) < 0:
            hi += (hi - x90)
            if hi - x90 > 1e3 * span:
                return None
        return optimize.brentq(g, x90, hi, xtol=1e-12)

    return {"b0": b0, "b1": b1, "log_likelihood": ll, "x90": x90,
            "x90_95_wald": bound(wald), "x90_95_lr": bound(profile_dev)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("hits")
    ap.add_argument("--log", action="store_true", help="x = ln a")
    a = ap.parse_args()
    groups = defaultdict(lambda: ([], []))
    with open(a.hits) as f:
        for row in csv.DictReader(f):
            size = float(row["size"])
            if size > 0:
                g = groups[row.get("class", "all")]
                g[0].append(size)
                g[1].append(float(row["hit"]))
    out = {}
    for cls, (size, hit) in groups.items():
        x = np.log(size) if a.log else np.array(size)
        r = fit(np.asarray(x, float), np.asarray(hit, float))
        back = (lambda v: None if v is None else float(np.exp(v))) if a.log else \
            (lambda v: None if v is None else float(v))
        out[cls] = {"b0": r["b0"], "b1": r["b1"], "log_likelihood": r["log_likelihood"],
                    "a90": back(r["x90"]), "a90_95_wald": back(r["x90_95_wald"]),
                    "a90_95_lr": back(r["x90_95_lr"])}
    json.dump(out, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
