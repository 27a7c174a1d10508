#!/usr/bin/python3
"""Independent peer of FitMotionalResonance (analysis/fit/resonance_fit.h) in SciPy.

Fits Z(f) = R + j w L + Rp / (1 + Q (j w/w0 + w0/(j w))) to a CSV frequency response with
scipy.optimize.least_squares(method='lm') (MINPACK lmdif, finite-difference Jacobian), in
theta = ln(R, L, Rp, f0, Q), with the same weighting as the C++ fit: the real residual is
Re and Im of sqrt(2) (Z(f_k) - Z_k) / sigma_k, so chi2 = |r|^2 has 2K - 5 degrees of freedom.
The covariance is (J^T J)^-1 with J from central differences at the optimum, mapped to natural
units as diag(p) C diag(p).

Usage: fit_scipy_peer.py FRF.csv R_OHM L_H RP_OHM F0_HZ Q
  FRF.csv has the header freq_hz,re_ohm,im_ohm,sigma_ohm. The start is the given truth
  perturbed by 1 % (alternately up and down). Prints one JSON object on stdout.
Exit status 0 on success; 2 when SciPy or NumPy is missing (a declared dependency);
3 on bad input or a failed fit. Errors are printed as {"error": "..."}.
"""

import csv
import json
import math
import sys

NAMES = ["R_ohm", "L_h", "Rp_ohm", "f0_hz", "Q"]


def fail(code, message):
    print(json.dumps({"error": message}))
    sys.exit(code)


try:
    import numpy as np
    import scipy
    from scipy.optimize import least_squares
except ImportError as e:  # python3-scipy is a declared dependency: say so, loudly.
    fail(2, "cannot import scipy/numpy with %s: %s (install python3-scipy)" % (sys.executable, e))


def model(theta, f):
    r, l, rp, f0, q = np.exp(theta)
    w = 2.0 * np.pi * f
    w0 = 2.0 * np.pi * f0
    s = 1j * w
    return r + s * l + rp / (1.0 + q * (s / w0 + w0 / s))


def main(argv):
    if len(argv) != 7:
        fail(3, "usage: fit_scipy_peer.py FRF.csv R_OHM L_H RP_OHM F0_HZ Q")
    with open(argv[1], newline="") as fh:
        rows = list(csv.DictReader(fh))
    f = np.array([float(r["freq_hz"]) for r in rows])
    z = np.array([complex(float(r["re_ohm"]), float(r["im_ohm"])) for r in rows])
    sigma = np.array([float(r["sigma_ohm"]) for r in rows])
    truth = np.array([float(a) for a in argv[2:7]])
    if len(f) < 10 or np.any(truth <= 0.0) or np.any(sigma <= 0.0):
        fail(3, "bad input: %d lines, truth %s" % (len(f), truth.tolist()))
    scale = math.sqrt(2.0) / sigma

    def residual(theta):
        e = (model(theta, f) - z) * scale
        return np.concatenate([e.real, e.imag])

    start = np.log(truth * np.array([1.01, 0.99, 1.01, 0.99, 1.01]))
    res = least_squares(residual, start, method="lm", ftol=1e-14, xtol=1e-14, gtol=1e-14,
                        max_nfev=20000)
    if not res.success:
        fail(3, "least_squares failed: status %d, %s" % (res.status, res.message))

    # Covariance from a central-difference Jacobian at the optimum (more accurate than the
    # forward differences MINPACK used while iterating).
    theta = res.x
    jac = np.empty((2 * len(f), 5))
    for i in range(5):
        h = 1e-6
        tp = theta.copy()
        tm = theta.copy()
        tp[i] += h
        tm[i] -= h
        jac[:, i] = (residual(tp) - residual(tm)) / (2.0 * h)
    c_log = np.linalg.inv(jac.T @ jac)
    p = np.exp(theta)
    c_nat = np.diag(p) @ c_log @ np.diag(p)
    r = residual(theta)
    chi2 = float(r @ r)
    dof = 2 * len(f) - 5
    out = {
        "scipy_version": scipy.__version__,
        "method": "lm",
        "status": int(res.status),
        "message": str(res.message),
        "nfev": int(res.nfev),
        "chi2": chi2,
        "dof": dof,
        "chi2_per_dof": chi2 / dof,
        "params": {n: float(v) for n, v in zip(NAMES, p)},
        "sigma": {n: float(math.sqrt(c_nat[i, i])) for i, n in enumerate(NAMES)},
    }
    print(json.dumps(out))


if __name__ == "__main__":
    try:
        main(sys.argv)
    except (OSError, ValueError, KeyError, np.linalg.LinAlgError) as e:
        fail(3, "%s: %s" % (type(e).__name__, e))
