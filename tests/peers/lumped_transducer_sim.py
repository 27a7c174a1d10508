#!/usr/bin/python3
"""The "simulation" of an electrodynamic transducer from its lumped (Thiele-Small) parameters,
for `eol gap` on a real measured loudspeaker impedance (tests/data/loudspeaker-ls10-impedance).

  Z(f) = Re + j w Le + Bl^2 / (Rms + j w Mms + 1 / (j w Cms)),   w = 2 pi f

(a pure inductance Le: the lossy, semi-inductive voice coil is what the simulation lacks).
Python 3 standard library and NumPy only (SciPy for `refit` alone). Subcommands:

  sim MEASURED.csv OUT.csv [--params PARAMS.json]
      writes the simulated impedance on the measured file's frequencies, as an FRF CSV
      f_hz,re_ohm,im_ohm (drivers/io/frf_files.h; no sigma: a simulation is noise-free).
      Parameters (SI units: ohm, H, T m, kg, m/N, kg/s) default to DEFAULT_PARAMS below;
      PARAMS.json overrides any of "Re", "Le", "Bl", "Mms", "Cms", "Rms".
  convert IN.txt OUT.csv
      converts the source's text export (tab separated, header "Freq Z_abs Z_rad": Hz, ohm,
      phase in radians) to f_hz,re_ohm,im_ohm: Re = |Z| cos(phase), Im = |Z| sin(phase).
      Nothing else is changed (every line is kept, values printed with 17 significant digits).
  derive FREE.csv ADDED.csv ADDED_MASS_KG
      the classical added-mass Thiele-Small extraction (Small 1972; IEC 60268-5 practice) from
      the magnitude of the free-air and mass-loaded impedances: Re = |Z| at the lowest line,
      fs and Zmax at the peak (parabolic interpolation on |Z|), f1, f2 where |Z| =
      sqrt(Re Zmax) (linear interpolation), Qms = fs sqrt(r0) / (f2 - f1), r0 = Zmax / Re,
      Qes = Qms / (r0 - 1); Mms = M / ((fs / fs')^2 - 1), Cms = 1 / (w_s^2 Mms),
      Rms = w_s Mms / Qms, Bl = sqrt(w_s Mms Re / Qes); Le = Im Z(1 kHz) / (2 pi 1 kHz)
      (the datasheet convention "Le at 1 kHz"). Prints one JSON object.
  refit MEASURED.csv SIM.csv [--form impedance|admittance] [--f-lo-hz F] [--f-hi-hz F]
      the reference for `eol gap`: needs SciPy (imported only here; python3-scipy). With the
      line sigma `eol gap` estimates for a file without sigma (analysis/gap/noise.h: second
      differences, median over +-25 lines, replicated below), g = sqrt(mean |Z - Z_model|^2 /
      sigma^2) of: the simulation as given; the nominal R + s L + Rp / (1 + Q (s/w0 + w0/s))
      (= Thiele-Small, Rp = Bl^2/Rms, w0 = 1/sqrt(Mms Cms), Q = w0 Mms/Rms) refitted; with an
      L2-R2 eddy branch, R + s L + s L2 R2 / (s L2 + R2) + motional; with the coil as a pure
      semi-inductance, R + K (j w)^n + motional; and with both, R + s L + K (j w)^n + motional
      (the form of effects.h fractional_inductance); with that and a second parallel R-L-C
      (effects.h second_mode). Weighted least squares (Re and Im of the normalised residual,
      scipy.optimize.least_squares, trust-region reflective, several starts) in the residual
      form of analysis/gap/effect_fit.h: impedance (Z - Z_model) / sigma (default), or
      admittance (1/Z - 1/Z_model) |Z|^2 / sigma, the form `eol gap` chooses (and reports g in)
      when the relative sigma grows with |Z| ("residual_form" in its JSON). Prints one JSON
      object with g of each model in the chosen form.

Files whose name ends in .gz are read and written gzip-compressed (eol reads those too).
Exit status 0 on success, 3 on bad input (the error on stderr).
"""

import csv
import gzip
import io
import json
import math
import sys

import numpy as np

# Derived with `derive` from tests/data/loudspeaker-ls10-impedance (free.csv, added-mass.csv,
# 0.1 kg); rounded to 4 significant digits. See that folder's README.md.
DEFAULT_PARAMS = {
    "Re": 7.409,      # ohm
    "Le": 3.802e-3,   # H
    "Bl": 20.32,      # T m
    "Mms": 0.1295,    # kg
    "Cms": 1.121e-4,  # m/N
    "Rms": 4.585,     # kg/s
}


def fail(message):
    sys.stderr.write("lumped_transducer_sim.py: %s\n" % message)
    sys.exit(3)


def open_text(path, mode):
    """Plain or gzip-compressed (a name ending in .gz) text."""
    if path.endswith(".gz"):  # written with mtime 0: the same bytes on every run
        raw = gzip.GzipFile(path, mode + "b", mtime=0) if mode == "w" else gzip.open(path, "rb")
        return io.TextIOWrapper(raw, newline="")
    return open(path, mode, newline="")


def read_frf(path):
    with open_text(path, "r") as fh:
        rows = [r for r in csv.reader(line for line in fh if not line.startswith("#"))]
    if not rows:
        fail("%s: empty" % path)
    head = [h.strip() for h in rows[0]]
    try:
        i_f, i_re, i_im = head.index("f_hz"), head.index("re_ohm"), head.index("im_ohm")
    except ValueError:
        fail("%s: header must name f_hz, re_ohm, im_ohm" % path)
    data = np.array([[float(r[i_f]), float(r[i_re]), float(r[i_im])] for r in rows[1:] if r])
    return data[:, 0], data[:, 1] + 1j * data[:, 2]


def write_frf(path, f, z):
    with open_text(path, "w") as fh:
        fh.write("f_hz,re_ohm,im_ohm\n")
        for fk, zk in zip(f, z):
            fh.write("%.17g,%.17g,%.17g\n" % (fk, zk.real, zk.imag))


def impedance(f, p):
    w = 2.0 * np.pi * np.asarray(f, dtype=float)
    s = 1j * w
    return p["Re"] + s * p["Le"] + p["Bl"] ** 2 / (p["Rms"] + s * p["Mms"] + 1.0 / (s * p["Cms"]))


def cmd_sim(args):
    if len(args) not in (2, 4) or (len(args) == 4 and args[2] != "--params"):
        fail("usage: sim MEASURED.csv OUT.csv [--params PARAMS.json]")
    p = dict(DEFAULT_PARAMS)
    if len(args) == 4:
        with open(args[3]) as fh:
            extra = json.load(fh)
        unknown = set(extra) - set(p)
        if unknown:
            fail("unknown parameters %s" % sorted(unknown))
        p.update({k: float(v) for k, v in extra.items()})
    if any(not (v > 0.0 and math.isfinite(v)) for v in p.values()):
        fail("every parameter must be positive: %s" % p)
    f, _ = read_frf(args[0])
    write_frf(args[1], f, impedance(f, p))


def cmd_convert(args):
    if len(args) != 2:
        fail("usage: convert IN.txt OUT.csv")
    rows = []
    with open_text(args[0], "r") as fh:
        head = fh.readline().split()
        if head[:3] != ["Freq", "Z_abs", "Z_rad"]:
            fail("%s: expected the header Freq Z_abs Z_rad, got %s" % (args[0], head))
        for n, line in enumerate(fh, start=2):
            if not line.strip():
                continue
            parts = line.split()
            try:
                rows.append([float(parts[0]), float(parts[1]), float(parts[2])])
            except (IndexError, ValueError):
                fail("%s:%d: not three numbers" % (args[0], n))
    d = np.array(rows)
    write_frf(args[1], d[:, 0], d[:, 1] * np.exp(1j * d[:, 2]))


def peak(f, m):
    k = int(np.argmax(m))
    if 0 < k < len(m) - 1:  # parabola through the three lines around the maximum
        y0, y1, y2 = m[k - 1], m[k], m[k + 1]
        den = y0 - 2.0 * y1 + y2
        d = 0.5 * (y0 - y2) / den if den != 0.0 else 0.0
        step = 0.5 * (f[k + 1] - f[k - 1])
        return f[k] + d * step, y1 - 0.25 * (y0 - y2) * d
    return f[k], m[k]


def crossing(f, m, level, k0, step):
    k = k0
    while 0 < k < len(m) - 1 and m[k] > level:
        k += step
    a, b = (k, k - step)  # m[a] <= level < m[b]
    return f[a] + (level - m[a]) * (f[b] - f[a]) / (m[b] - m[a])


def cmd_derive(args):
    if len(args) != 3:
        fail("usage: derive FREE.csv ADDED.csv ADDED_MASS_KG")
    f, z = read_frf(args[0])
    fa, za = read_frf(args[1])
    mass = float(args[2])
    band = (f > 5.0) & (f < 500.0)  # the mechanical resonance; above it the coil rises
    m = np.abs(z)
    re = float(m[0])
    fb, mb = f[band], m[band]
    fs, zmax = peak(fb, mb)
    r0 = zmax / re
    level = math.sqrt(re * zmax)
    k0 = int(np.argmax(mb))
    f1, f2 = crossing(fb, mb, level, k0, -1), crossing(fb, mb, level, k0, +1)
    qms = fs * math.sqrt(r0) / (f2 - f1)
    qes = qms / (r0 - 1.0)
    banda = (fa > 5.0) & (fa < 500.0)
    fsa, _ = peak(fa[banda], np.abs(za[banda]))
    mms = mass / ((fs / fsa) ** 2 - 1.0)
    ws = 2.0 * math.pi * fs
    cms = 1.0 / (ws ** 2 * mms)
    rms = ws * mms / qms
    bl = math.sqrt(ws * mms * re / qes)
    k1k = int(np.argmin(np.abs(f - 1000.0)))
    le = float(z[k1k].imag / (2.0 * math.pi * f[k1k]))
    print(json.dumps({
        "Re": re, "Le": le, "Bl": bl, "Mms": mms, "Cms": cms, "Rms": rms,
        "fs_hz": fs, "fs_added_mass_hz": fsa, "Zmax_ohm": zmax, "f1_hz": f1, "f2_hz": f2,
        "Qms": qms, "Qes": qes, "Qts": qms * qes / (qms + qes),
        "Res_ohm": bl ** 2 / rms, "Le_at_hz": float(f[k1k]),
    }, indent=1))


def neighbour_magnitude(z, rel_var, half_width=3):
    """analysis/gap/noise.cc NeighbourMagnitude: |a| of the least-squares a + c x^2 through the
    lines k +- 1 .. k +- m (m = half_width, fewer near the ends; their mean when m = 1; |z[k]|
    itself at the end lines): line k's magnitude from its neighbours alone, unless they miss
    the line by more than 9 times the difference's expected (1 + sum w^2) rel_var |z[k]|^2."""
    n = len(z)
    out = np.abs(z).astype(float)
    for k in range(n):
        m = min(half_width, k, n - 1 - k)
        if m == 0:
            continue
        x = np.arange(1, m + 1)
        if m == 1:
            w = np.array([0.5])
        else:
            x2 = x ** 2.0
            s2, s4 = 2.0 * x2.sum(), 2.0 * (x2 ** 2).sum()
            w = (s4 - s2 * x2) / (2.0 * m * s4 - s2 * s2)
        a = np.sum(w * (z[k - x] + z[k + x]))
        w2 = 2.0 * np.sum(w ** 2)
        if abs(z[k] - a) ** 2 > 9.0 * (1.0 + w2) * rel_var[k] * abs(z[k]) ** 2:
            continue
        if abs(a) > 0.0:
            out[k] = abs(a)
    return out


def estimate_line_sigma(z, half_window=25):
    """analysis/gap/noise.cc EstimateLineSigma, line for line."""
    n = len(z)
    rho = np.zeros(n)
    d = z[:-2] - 2.0 * z[1:-1] + z[2:]
    rho[1:-1] = np.abs(d) ** 2 / (6.0 * np.maximum(np.abs(z[1:-1]) ** 2, 1e-300))
    rho[0], rho[-1] = rho[1], rho[-2]
    rel = np.empty(n)
    for k in range(n):
        win = np.sort(rho[max(0, k - half_window):min(n - 1, k + half_window) + 1])
        rel[k] = win[len(win) // 2] / math.log(2.0)
    return neighbour_magnitude(z, rel) * np.sqrt(rel)


def cmd_refit(args):
    try:
        from scipy.optimize import least_squares
    except ImportError as e:
        fail("refit needs SciPy (python3-scipy): %s" % e)
    if len(args) < 2:
        fail("usage: refit MEASURED.csv SIM.csv [--form impedance|admittance] [--f-lo-hz F] "
             "[--f-hi-hz F]")
    f, z = read_frf(args[0])
    fs_, zs = read_frf(args[1])
    if len(fs_) != len(f) or np.max(np.abs(fs_ - f)) > 1e-9 * np.max(f):
        fail("the simulation must be on the measured lines")
    sigma = estimate_line_sigma(z)  # on the whole file, as eol gap does before the band
    lo, hi = 0.0, math.inf
    form = "impedance"
    rest = args[2:]
    while rest:
        if rest[0] == "--form" and len(rest) > 1 and rest[1] in ("impedance", "admittance"):
            form = rest[1]
        elif rest[0] == "--f-lo-hz" and len(rest) > 1:
            lo = float(rest[1])
        elif rest[0] == "--f-hi-hz" and len(rest) > 1:
            hi = float(rest[1])
        else:
            fail("unknown option %s" % rest[0])
        rest = rest[2:]
    keep = (f >= lo) & (f <= hi)
    f, z, zs, sigma = f[keep], z[keep], zs[keep], sigma[keep]
    s = 1j * 2.0 * np.pi * f

    def normalised(zm):
        if form == "admittance":
            return (1.0 / z - 1.0 / zm) * np.abs(z) ** 2 / sigma
        return (z - zm) / sigma

    def g_of(zm):
        return float(np.sqrt(np.mean(np.abs(normalised(zm)) ** 2)))

    def motional(rp, f0, q):
        w0 = 2.0 * np.pi * f0
        return rp / (1.0 + q * (s / w0 + w0 / s))

    # Each model: names, z(theta) with theta = ln(positive params) (n: plain), starts.
    def m_nominal(t):
        r, l, rp, f0, q = np.exp(t)
        return r + s * l + motional(rp, f0, q)

    def m_l2r2(t):
        r, l, l2, r2, rp, f0, q = np.exp(t)
        return r + s * l + s * l2 * r2 / (s * l2 + r2) + motional(rp, f0, q)

    def m_frac(t):
        r, k, rp, f0, q = np.exp(t[[0, 1, 3, 4, 5]])
        n = t[2]
        return r + k * s ** n + motional(rp, f0, q)

    def m_frac_l(t):
        r, l, k, rp, f0, q = np.exp(t[[0, 1, 2, 4, 5, 6]])
        n = t[3]
        return r + s * l + k * s ** n + motional(rp, f0, q)

    p = DEFAULT_PARAMS
    rp0 = p["Bl"] ** 2 / p["Rms"]
    f00 = 1.0 / (2.0 * math.pi * math.sqrt(p["Mms"] * p["Cms"]))
    q0 = 2.0 * math.pi * f00 * p["Mms"] / p["Rms"]
    base = [p["Re"], p["Le"], rp0, f00, q0]

    def fit(model, starts, lower, upper):
        best = None
        for t0 in starts:
            t0 = np.clip(np.asarray(t0, dtype=float), lower + 1e-9, upper - 1e-9)

            def res(t):
                r = normalised(model(t))
                return np.concatenate([r.real, r.imag])

            sol = least_squares(res, t0, bounds=(lower, upper), method="trf", x_scale="jac",
                                max_nfev=3000, xtol=1e-10, ftol=1e-10, gtol=1e-10)
            if best is None or sol.cost < best.cost:
                best = sol
        return best

    L = np.log
    out = {"lines": int(len(f)), "f_lo_hz": float(f[0]), "f_hi_hz": float(f[-1]),
           "sigma": "estimated as analysis/gap/noise.h (half window 25 lines)",
           "residual_form": form,
           "g_simulation": g_of(zs)}
    inf = np.inf
    sol = fit(m_nominal, [L(base)], np.full(5, -inf), np.full(5, inf))
    r, l, rp, f0, q = np.exp(sol.x)
    out["nominal_refit"] = {"g": g_of(m_nominal(sol.x)), "R_ohm": r, "L_h": l, "Rp_ohm": rp,
                            "f0_hz": f0, "Q": q}
    starts = [L([base[0], base[1] * fr, base[1] * fr2, rr, *base[2:]])
              for fr in (1.0, 0.5) for fr2 in (0.5, 2.0) for rr in (5.0, 20.0, 80.0)]
    sol = fit(m_l2r2, starts, np.full(7, -inf), np.full(7, inf))
    r, l, l2, r2, rp, f0, q = np.exp(sol.x)
    out["l2r2_refit"] = {"g": g_of(m_l2r2(sol.x)), "R_ohm": r, "L_h": l, "L2_h": l2,
                         "R2_ohm": r2, "Rp_ohm": rp, "f0_hz": f0, "Q": q}
    starts = []
    for n0 in (0.55, 0.65, 0.75):
        k0 = abs(zs[-1] - p["Re"]) / (2.0 * math.pi * f[-1]) ** n0
        starts.append(np.array([L(base[0]), L(k0), n0, L(base[2]), L(base[3]), L(base[4])]))
    lower = np.array([-inf, -inf, 0.0, -inf, -inf, -inf])
    upper = np.array([inf, inf, 1.0, inf, inf, inf])
    sol = fit(m_frac, starts, lower, upper)
    r, k, rp, f0, q = np.exp(sol.x[[0, 1, 3, 4, 5]])
    out["fractional_refit"] = {"g": g_of(m_frac(sol.x)), "R_ohm": r, "K": k, "n": sol.x[2],
                               "Rp_ohm": rp, "f0_hz": f0, "Q": q}
    starts = [np.array([t[0], L(base[1] * fl), t[1], t[2], t[3], t[4], t[5]])
              for t in [sol.x] for fl in (0.02, 0.1, 0.3)]
    lower = np.array([-inf, -inf, -inf, 0.0, -inf, -inf, -inf])
    upper = np.array([inf, inf, inf, 1.0, inf, inf, inf])
    sol = fit(m_frac_l, starts, lower, upper)
    r, l, k, rp, f0, q = np.exp(sol.x[[0, 1, 2, 4, 5, 6]])
    out["fractional_plus_l_refit"] = {"g": g_of(m_frac_l(sol.x)), "R_ohm": r, "L_h": l,
                                      "K": k, "n": sol.x[3], "Rp_ohm": rp, "f0_hz": f0, "Q": q}

    def m_frac_l_mode(t):
        h, f2, q2 = np.exp(t[7:10])
        return m_frac_l(t[:7]) + motional(h, f2, q2)

    frac_l = sol.x
    starts = [np.concatenate([frac_l, L([h, f2, q2])])
              for f2 in (200.0, 400.0) for q2 in (1.0, 5.0) for h in (2.0,)]
    lower = np.array([-inf, -inf, -inf, 0.0, -inf, -inf, -inf, -inf, -inf, -inf])
    upper = np.array([inf, inf, inf, 1.0, inf, inf, inf, inf, inf, inf])
    sol = fit(m_frac_l_mode, starts, lower, upper)
    r, l, k, rp, f0, q, h, f2, q2 = np.exp(sol.x[[0, 1, 2, 4, 5, 6, 7, 8, 9]])
    out["fractional_plus_l_second_mode_refit"] = {
        "g": g_of(m_frac_l_mode(sol.x)), "R_ohm": r, "L_h": l, "K": k, "n": sol.x[3],
        "Rp_ohm": rp, "f0_hz": f0, "Q": q, "mode_height_ohm": h, "mode_f_hz": f2, "mode_q": q2}
    print(json.dumps(out, indent=1))


def main(argv):
    cmds = {"sim": cmd_sim, "convert": cmd_convert, "derive": cmd_derive, "refit": cmd_refit}
    if len(argv) < 2 or argv[1] not in cmds:
        fail("usage: lumped_transducer_sim.py sim|convert|derive|refit ... (see the docstring)")
    cmds[argv[1]](argv[2:])


if __name__ == "__main__":
    main(sys.argv)
