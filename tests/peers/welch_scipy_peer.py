#!/usr/bin/python3
"""Independent peer of EstimateWelchFrf (analysis/signal/welch.h) in SciPy.

Reads two channels from a CSV (header x,y), computes with scipy.signal, periodic Hann window,
detrend 'constant', one-sided density spectra:
  Pxy = csd(x, y)  (SciPy's csd is conj(X) Y),  Pxx = welch(x),  Pyy = welch(y),
  H1 = Pxy / Pxx,  H2 = Pyy / conj(Pxy),  coherence(x, y) = |Pxy|^2 / (Pxx Pyy),
and prints them as one JSON object on the bins with F_LO <= f <= F_HI.

Usage: welch_scipy_peer.py DATA.csv FS_HZ NPERSEG NOVERLAP F_LO F_HI
Exit status 0 on success; 2 when SciPy or NumPy is missing (a declared dependency);
3 on bad input. Errors are printed as {"error": "..."}.
"""

import json
import sys


def fail(code, message):
    print(json.dumps({"error": message}))
    sys.exit(code)


try:
    import numpy as np
    import scipy
    from scipy import signal
except ImportError as e:  # python3-scipy is a declared dependency: say so, loudly.
    fail(2, "cannot import scipy/numpy with %s: %s (install python3-scipy)" % (sys.executable, e))


def main(argv):
    if len(argv) != 7:
        fail(3, "usage: welch_scipy_peer.py DATA.csv FS_HZ NPERSEG NOVERLAP F_LO F_HI")
    data = np.loadtxt(argv[1], delimiter=",", skiprows=1)
    x, y = data[:, 0], data[:, 1]
    fs, nperseg, noverlap = float(argv[2]), int(argv[3]), int(argv[4])
    f_lo, f_hi = float(argv[5]), float(argv[6])
    kw = dict(fs=fs, window="hann", nperseg=nperseg, noverlap=noverlap, detrend="constant")
    f, pxy = signal.csd(x, y, **kw)
    _, pxx = signal.welch(x, **kw)
    _, pyy = signal.welch(y, **kw)
    _, coh = signal.coherence(x, y, **kw)
    sel = (f >= f_lo) & (f <= f_hi)
    h1 = pxy[sel] / pxx[sel]
    h2 = pyy[sel] / np.conj(pxy[sel])
    print(json.dumps({
        "scipy_version": scipy.__version__,
        "f_hz": f[sel].tolist(),
        "h1_re": h1.real.tolist(), "h1_im": h1.imag.tolist(),
        "h2_re": h2.real.tolist(), "h2_im": h2.imag.tolist(),
        "coherence": coh[sel].tolist(),
    }))


if __name__ == "__main__":
    try:
        main(sys.argv)
    except (OSError, ValueError, IndexError) as e:
        fail(3, "%s: %s" % (type(e).__name__, e))
