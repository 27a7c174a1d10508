#!/usr/bin/python3
"""The station's identification pipeline in NumPy/SciPy, timed, for `eol fit-bench`.

Per recording (float64 little-endian binary: all voltage samples, then all current samples):
  1. periodic errors-in-variables estimate (analysis/signal/periodic_frf.h): drop the first
     `transient_periods` periods, DFT lines of each period (numpy.fft.rfft, scaled 2/N), means
     U, I, Z = U / I, period-to-period (co)variances pooled over +-h neighbouring lines,
     var Z = (s_U^2 + |Z|^2 s_I^2 - 2 Re(conj(Z) s_UI)) / (P |I|^2);
  2. weighted ML fit of Z = R + j w L + Rp / (1 + Q (j w/w0 + w0/(j w))) (resonance_fit.h):
     a log grid over (f0, Q) with R, L, Rp from weighted linear least squares (NumPy, vectorised
     over Q), two 21 x 21 refinements, then scipy.optimize.least_squares(method='lm') on
     ln(R, L, Rp, f0, Q) with the residual Re, Im of sqrt(2) (Z_model - Z) / sigma.
Transient-period detection is not repeated (the benchmark's recordings are steady state).

Usage: fit_pipeline_scipy.py MANIFEST.json
  MANIFEST: {"sample_rate_hz", "period_samples", "lines": [bins], "transient_periods",
             "noise_smoothing_lines", "f0_min_hz", "f0_max_hz", "q_min", "q_max",
             "grid_f0", "grid_q", "recordings": [paths]}
Prints one JSON object: scipy version, per-recording f0 and sigma, analysis time per test (ms).
Exit status 0; 2 when SciPy or NumPy is missing; 3 on bad input.
"""

import json
import math
import sys
import time


def fail(code, message):
    print(json.dumps({"error": message}))
    sys.exit(code)


try:
    import numpy as np
    import scipy
    from scipy.optimize import least_squares
except ImportError as e:
    fail(2, "cannot import scipy/numpy with %s: %s (install python3-scipy)" % (sys.executable, e))


def estimate(u, i, n, lines, transient, h):
    p_all = len(u) // n
    U = np.fft.rfft(u[transient * n:p_all * n].reshape(-1, n), axis=1)[:, lines] * (2.0 / n)
    I = np.fft.rfft(i[transient * n:p_all * n].reshape(-1, n), axis=1)[:, lines] * (2.0 / n)
    p = U.shape[0]
    um, im = U.mean(0), I.mean(0)
    du, di = U - um, I - im
    su2 = (np.abs(du) ** 2).sum(0) / (p - 1)
    si2 = (np.abs(di) ** 2).sum(0) / (p - 1)
    sui = (du * np.conj(di)).sum(0) / (p - 1)
    if h > 0:  # pooled over the 2h+1 neighbouring lines, truncated at the ends
        k = np.ones(2 * h + 1)
        cnt = np.convolve(np.ones(len(lines)), k, mode="same")
        su2 = np.convolve(su2, k, mode="same") / cnt
        si2 = np.convolve(si2, k, mode="same") / cnt
        sui = np.convolve(sui, k, mode="same") / cnt
    z = um / im
    var = (su2 + np.abs(z) ** 2 * si2 - 2.0 * np.real(np.conj(z) * sui)) / (p * np.abs(im) ** 2)
    return z, np.sqrt(np.maximum(var, 1e-300))


def grid_search(f, z, c, f0s, qs):
    """Best (chi2, f0, q, r, l, rp) over the grid, R, L, Rp > 0 (weighted linear LS)."""
    w = 2 * np.pi * f
    best = (np.inf, None)
    for f0 in f0s:
        x = f / f0 - f0 / f                      # (K,)
        d = 1.0 + 1j * np.outer(qs, x)           # (nq, K)
        cols = [np.ones_like(d), np.broadcast_to(1j * w, d.shape), 1.0 / d]
        a = np.stack([np.concatenate([col.real, col.imag], axis=1) for col in cols], axis=2)
        wt = np.sqrt(np.concatenate([c, c]))     # (2K,)
        aw = a * wt[None, :, None]
        bw = np.concatenate([z.real, z.imag]) * wt
        ata = np.einsum("qki,qkj->qij", aw, aw)
        atb = np.einsum("qki,k->qi", aw, bw)
        try:
            sol = np.linalg.solve(ata, atb[..., None])[..., 0]
        except np.linalg.LinAlgError:
            continue
        res = np.einsum("qki,qi->qk", aw, sol) - bw
        chi2 = (res ** 2).sum(1)
        ok = (sol > 0).all(1)
        if ok.any():
            j = np.argmin(np.where(ok, chi2, np.inf))
            if chi2[j] < best[0]:
                best = (chi2[j], (f0, qs[j], *sol[j]))
    return best


def fit(f, z, sigma, m):
    c = 2.0 / sigma ** 2
    f0s = np.geomspace(m["f0_min_hz"], m["f0_max_hz"], m["grid_f0"])
    qs = np.geomspace(m["q_min"], m["q_max"], m["grid_q"])
    chi2, p = grid_search(f, z, c, f0s, qs)
    if p is None:
        raise ValueError("no (f0, Q) grid point gives positive R, L and Rp")
    for _ in range(2):
        i = int(np.argmin(np.abs(f0s - p[0])))
        j = int(np.argmin(np.abs(qs - p[1])))
        f0s = np.geomspace(f0s[max(i - 1, 0)], f0s[min(i + 1, len(f0s) - 1)], 21)
        qs = np.geomspace(qs[max(j - 1, 0)], qs[min(j + 1, len(qs) - 1)], 21)
        c2, p2 = grid_search(f, z, c, f0s, qs)
        if p2 is None or c2 >= chi2:
            break
        chi2, p = c2, p2
    f0, q, r, l, rp = p
    s = math.sqrt(2.0) / sigma
    w = 2 * np.pi * f

    def residual(t):
        r_, l_, rp_, f0_, q_ = np.exp(t)
        e = (r_ + 1j * w * l_ + rp_ / (1 + 1j * q_ * (f / f0_ - f0_ / f)) - z) * s
        return np.concatenate([e.real, e.imag])

    res = least_squares(residual, np.log([r, l, rp, f0, q]), method="lm", ftol=1e-12, xtol=1e-10)
    jac = res.jac
    cov = np.linalg.inv(jac.T @ jac)
    f0_hat = math.exp(res.x[3])
    return f0_hat, f0_hat * math.sqrt(cov[3, 3])


def main(argv):
    if len(argv) != 2:
        fail(3, "usage: fit_pipeline_scipy.py MANIFEST.json")
    with open(argv[1]) as fh:
        m = json.load(fh)
    n = int(m["period_samples"])
    lines = np.array(m["lines"], dtype=int)
    f = lines * m["sample_rate_hz"] / n
    runs = []
    for path in m["recordings"]:
        data = np.fromfile(path, dtype="<f8")
        u, i = data[: len(data) // 2], data[len(data) // 2:]
        t0 = time.perf_counter()
        z, sigma = estimate(u, i, n, lines, int(m["transient_periods"]),
                            int(m["noise_smoothing_lines"]))
        f0, f0_sigma = fit(f, z, sigma, m)
        ms = (time.perf_counter() - t0) * 1e3
        runs.append({"f0_hz": f0, "f0_sigma_hz": f0_sigma, "ms": ms})
    ms = [r["ms"] for r in runs]
    print(json.dumps({"scipy_version": scipy.__version__, "numpy_version": np.__version__,
                      "runs": runs, "ms_mean": float(np.mean(ms)), "ms_min": float(np.min(ms))}))


if __name__ == "__main__":
    try:
        main(sys.argv)
    except (OSError, ValueError, KeyError, TypeError, np.linalg.LinAlgError) as e:
        fail(3, "%s: %s" % (type(e).__name__, e))
