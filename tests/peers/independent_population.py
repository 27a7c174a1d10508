#!/usr/bin/python3
"""Independent production population of clamped ten-pole rotors, written from the physics.

Shares no code or model with analysis/ (issue 12): its own chain topology, its own spreads,
its own damping law and its own measurement simulation. Only the nominal numbers are chosen so
that the station's shipped recipe (recipes/pmsm-10pole.json) sees the same band: good rotors
ring near 390 Hz in the fixture (analysis/README.md section 2: 706 Hz rigid shaft, 529 Hz with every
magnet bonded on one side only, 390 Hz in the real fixture).

Mechanics: a clamped torsional chain, N = 14 degrees of freedom (angles, rad):
  magnets m1..m10 (J_m each) --bond k_b,i + c_b,i--> pole body (J_p, the laminated poles)
  pole body --bridges (ten in parallel, k_br each)--> hub (J_h)
  hub --shaft k_s--> clamp collar (J_c) --fixture k_f--> ground.
Equation of motion, torque vector tau:  (K - w^2 M + j w C) theta = tau.
Every spring has a hysteretic-like damper c = eta k / w_ref (w_ref = 2 pi 390 rad/s), eta
per material: adhesive 0.03, steel 0.01, fixture contact 0.03. A soft bond keeps the
adhesive's loss factor by default (--poor-loss-factor 0.03: the defect is softness only);
--poor-loss-factor 0.06 models a lossier, under-cured adhesive, which lowers Q too and lets the
station's Q limit catch all-ten-soft rotors from a loss of about 0.85 (the blind populations of
issue 12 showed no such help: their escapes sat 17-30 Hz low and still passed Q).
The electromagnetic torque acts on the magnets: torque T i shared 1/10 per magnet, and the
back-EMF is T times the mean magnet velocity, so with the mobility Y(w) = j w (K - w^2 M +
j w C)^-1 (rad/s per N m) and b = (1/10, ..., 1/10, 0, ...):
  Z(w) = R + j w L + T^2 b^T Y(w) b            (the paper's eq. 12-14, T^2 / Z_m).

Production spread (per unit, independent normal unless stated): magnet inertia 2 %, pole body
1.5 %, hub 1 %, clamp collar 2 %, bond stiffness 12 % lognormal and bond loss factor 20 % per
magnet, each bridge 3 %, shaft 2 %; the clamp: fixture stiffness proportional to
(F / 5.5 bar)^(1/3) with clamp pressure F ~ N(5.5, 0.3) bar clipped to 4.5-6.5 bar, times a
2 % lognormal seat/wear factor. Electrical: R = 0.5 ohm (1 +- 1 %) (1 + 0.00393 (T_w - 20)),
winding temperature T_w uniform 15-35 degC; L = 2 mH (2 %); torque constant T = 0.05 N m/A (4 %).

Bond softness (defects), a continuum from mild to severe: a soft magnet loses a share
a = 1 - r of its bond stiffness (r: the fraction it keeps). For the one_soft and three_soft
classes each soft magnet draws its own loss, uniform on [--loss-lo, --loss-hi] (default
0.20-0.99: 0.96 is the paper's one-side-cemented case, 888 -> 37 N m/rad). For all_soft the ten
magnets share one loss a uniform on the same range, each magnet's kept fraction spread around
it, r_i = (1 - a) exp(0.15 N(0, 1)) capped at 1 (one glue batch or cure, per-magnet
thickness). Physics (--loss-table prints it): the bond (918 N m/rad) sits in series with the
bridges (5020) and the fixture (891), so the mode barely moves until the bond is a fraction of
those: all ten at a loss of 0.5 lower the nominal 390.0 Hz by 0.8 Hz, 0.8 by 3.3 Hz, 0.9 by
8 Hz, 0.94 by 15 Hz, 0.96 by 24 Hz; one magnet alone moves it by less than 3.2 Hz up to a
loss of 0.96, and beyond about 0.98 its own local mode falls to the rotor's.
Classes: good (no soft magnet), one_soft, three_soft (three distinct magnets), all_soft.

Measurement: periodic Schroeder multisine over 200-800 Hz at 1 Hz spacing (601 lines), 2 V
peak with crest factor 1.7 (line amplitude A = 2 / (1.7 sqrt(601 / 2)) V), sampled at 8 kHz,
P = 4 periods of 1 s. The DAQ adds white noise of 2 mV (voltage) and 1 mA (current) rms per
sample: per period and line the DFT error is complex Gaussian with E|e|^2 = 4 s^2 / N
(N = 8000 samples). Z = mean U / mean I; its sigma from the period-to-period scatter (analysis/README.md
section 3), var Z = |Z|^2 / P (s_U^2 / |U|^2 + s_I^2 / |I|^2 - 2 Re(s_UI / (U I*))), the
sample (co)variances pooled over 11 neighbouring lines (4 periods alone give 3 degrees of
freedom per line).

Second motor (--motor pmsm-8pole-heavy): another design drawn by the same physics
and spreads, eight heavier magnets on a heavier rotor (magnets 1e-5 each, pole body 6.4e-5,
hub 3e-5, clamp collar 8.7e-6 kg m^2; bonds 2060, bridges 8 x 1230, shaft 9800, fixture
4420 N m/rad, loss factors at w_ref = 2 pi 588 rad/s) and another winding (R 1.1 ohm,
L 4.5 mH, T 0.09 N m/A): the good rotor rings near 588 Hz in its fixture, about 50 % above
the ten-pole one. Its measurement is the excitation its recipe plays (--f-lo, --f-hi,
--spacing, --peak-v, --periods, --crest; the lines at whole multiples of the spacing inside
the band; defaults per motor: 280-1180 Hz at 6.8847 Hz, 8 V peak, 2 periods, crest 1.525, the
excitation of recipes/pmsm-8pole-heavy.json within a percent: its line grid follows the golden
units' Q). The classes keep their names: three_soft is three of the
eight magnets, all_soft all eight.

Output in --out: unit-NNNN.csv (f_hz,re_ohm,im_ohm,sigma_ohm), and truth.csv: unit, class,
first_mode_hz (lowest mode of the undamped chain; with a very soft bond it is that
magnet's local mode), k_fixture, defect_size (the stiffness loss a: that of the one soft
magnet, the largest of three, the common loss of all ten; 0 for good units), and per magnet
the kept fraction r_bond_i and the loss loss_i = 1 - r_bond_i (0 for a good bond), and the
clamp pressure (bar, 0.001 resolution: what the station reads at clamp confirmation).
"""
import argparse
import csv
import os
import sys

import numpy as np
import scipy.linalg

W_REF = 2.0 * np.pi * 390.0
MAGNETS = 10

# Nominal parts. Bond and bridge stiffness were set so that the rigidly clamped chain rings at
# about 706 Hz and at about 530 Hz with every bond at 4 %, and the fixture so that the clamped
# good rotor rings at about 390 Hz (main() --nominal prints these).
NOMINAL = dict(
    j_magnet=2.5e-6, j_pole=6.5e-5, j_hub=1.0e-5, j_clamp=5.0e-6,  # kg m^2
    k_bond=918.0, k_bridge=502.0, k_shaft=3000.0, k_fixture=891.0,  # N m/rad
    eta_bond=0.03, eta_poor=0.03, eta_steel=0.01, eta_fixture=0.03,
    r_ohm=0.5, l_h=2.0e-3, t_nm_per_a=0.05)

CLASSES = {"good": 0, "one_soft": 1, "three_soft": 3, "all_soft": MAGNETS}

# The second motor (docstring): its own nominal parts, the same materials' loss factors.
NOMINAL_8POLE = dict(NOMINAL, j_magnet=1.0e-5, j_pole=6.4e-5, j_hub=3.0e-5, j_clamp=8.7e-6,
                     k_bond=2060.0, k_bridge=1230.0, k_shaft=9800.0, k_fixture=4420.0,
                     r_ohm=1.1, l_h=4.5e-3, t_nm_per_a=0.09)
# name: (nominal parts, magnets, w_ref, measurement defaults f_lo, f_hi, spacing, peak, periods,
# crest)
MOTORS = {
    "pmsm-10pole": (NOMINAL, 10, 390.0, (200.0, 800.0, 1.0, 2.0, 4, 1.7)),
    "pmsm-8pole-heavy": (NOMINAL_8POLE, 8, 588.0, (280.0, 1180.0, 6.8847, 8.0, 2, 1.525)),
}


def select_motor(name):
    """Makes `name` the motor every function below draws."""
    global NOMINAL, MAGNETS, W_REF, CLASSES
    NOMINAL, MAGNETS, w_ref, _ = MOTORS[name]
    W_REF = 2.0 * np.pi * w_ref
    CLASSES = {"good": 0, "one_soft": 1, "three_soft": 3, "all_soft": MAGNETS}


def chain_matrices(p, r_bond, rigid=False):
    """M, K, C of the chain for part values p and bond stiffness fractions r_bond (10,)."""
    n = MAGNETS + 2 + (0 if rigid else 1)
    pole, hub, clamp = MAGNETS, MAGNETS + 1, MAGNETS + 2
    m = np.zeros(n)
    m[:MAGNETS] = p["j_magnets"]
    m[pole], m[hub] = p["j_pole"], p["j_hub"]
    if not rigid:
        m[clamp] = p["j_clamp"]
    k = np.zeros((n, n))
    c = np.zeros((n, n))

    def spring(a, b, kk, eta):
        cc = eta * kk / W_REF
        for mat, v in ((k, kk), (c, cc)):
            mat[a, a] += v
            if b is not None:
                mat[b, b] += v
                mat[a, b] -= v
                mat[b, a] -= v

    for i in range(MAGNETS):
        poor = r_bond[i] < 1.0
        spring(i, pole, p["k_bonds"][i] * r_bond[i],
               (p.get("eta_poor", NOMINAL["eta_poor"]) if poor else p["eta_bonds"][i]))
    spring(pole, hub, float(np.sum(p["k_bridges"])), NOMINAL["eta_steel"])
    if rigid:
        spring(hub, None, p["k_shaft"], NOMINAL["eta_steel"])
    else:
        spring(hub, clamp, p["k_shaft"], NOMINAL["eta_steel"])
        spring(clamp, None, p["k_fixture"], NOMINAL["eta_fixture"])
    return np.diag(m), k, c


def first_mode_hz(p, r_bond, rigid=False):
    m, k, _ = chain_matrices(p, r_bond, rigid)
    w2 = scipy.linalg.eigh(k, m, eigvals_only=True)
    return float(np.sqrt(w2[0]) / (2.0 * np.pi))


def impedance(p, r_bond, f_hz):
    m, k, c = chain_matrices(p, r_bond)
    b = np.zeros(m.shape[0])
    b[:MAGNETS] = 1.0 / MAGNETS
    z = np.empty(f_hz.size, dtype=complex)
    for i, f in enumerate(f_hz):
        w = 2.0 * np.pi * f
        theta = np.linalg.solve(k - w * w * m + 1j * w * c, b)  # rad per N m of total torque
        z[i] = p["t"] ** 2 * (1j * w * (b @ theta))
    return p["r"] + 1j * 2.0 * np.pi * f_hz * p["l"] + z


def nominal_parts():
    n = NOMINAL
    return dict(j_magnets=np.full(MAGNETS, n["j_magnet"]), j_pole=n["j_pole"], j_hub=n["j_hub"],
                j_clamp=n["j_clamp"], k_bonds=np.full(MAGNETS, n["k_bond"]),
                eta_bonds=np.full(MAGNETS, n["eta_bond"]),
                k_bridges=np.full(MAGNETS, n["k_bridge"]), k_shaft=n["k_shaft"],
                k_fixture=n["k_fixture"], r=n["r_ohm"], l=n["l_h"], t=n["t_nm_per_a"])


def draw_parts(rng):
    n = NOMINAL
    g = lambda rel, size=None: 1.0 + rel * rng.standard_normal(size)
    pressure = float(np.clip(rng.normal(5.5, 0.3), 4.5, 6.5))
    temp_c = rng.uniform(15.0, 35.0)
    return dict(
        j_magnets=n["j_magnet"] * g(0.02, MAGNETS), j_pole=n["j_pole"] * g(0.015),
        j_hub=n["j_hub"] * g(0.01), j_clamp=n["j_clamp"] * g(0.02),
        k_bonds=n["k_bond"] * np.exp(0.12 * rng.standard_normal(MAGNETS)),
        eta_bonds=n["eta_bond"] * g(0.2, MAGNETS).clip(0.3),
        k_bridges=n["k_bridge"] * g(0.03, MAGNETS), k_shaft=n["k_shaft"] * g(0.02),
        k_fixture=n["k_fixture"] * (pressure / 5.5) ** (1.0 / 3.0)
        * np.exp(0.02 * rng.standard_normal()),
        r=n["r_ohm"] * g(0.01) * (1.0 + 0.00393 * (temp_c - 20.0)),
        l=n["l_h"] * g(0.02), t=n["t_nm_per_a"] * g(0.04), clamp_pressure_bar=pressure)


ALL_SOFT_SPREAD = 0.15  # lognormal spread of each magnet's kept fraction around the common one


def draw_bonds(rng, soft_count, loss_lo, loss_hi):
    """Kept bond fractions r (10,) and the defect size a (docstring)."""
    r = np.ones(MAGNETS)
    if soft_count == 0:
        return r, 0.0
    if soft_count == MAGNETS:
        a = rng.uniform(loss_lo, loss_hi)
        r = np.minimum(1.0, (1.0 - a) * np.exp(ALL_SOFT_SPREAD * rng.standard_normal(MAGNETS)))
        return r, a
    which = rng.choice(MAGNETS, size=soft_count, replace=False)
    losses = rng.uniform(loss_lo, loss_hi, size=soft_count)
    r[which] = 1.0 - losses
    return r, float(np.max(losses))


def measure(z, rng, periods=4, f_lines=601, peak_v=2.0, crest=1.7, s_u=2e-3, s_i=1e-3,
            n_samples=8000, pool=11):
    # n_samples: samples per period (8 kHz / line spacing).
    """Z estimate and its sigma from P periods of a periodic multisine (docstring)."""
    k = np.arange(1, z.size + 1)
    amp = peak_v / (crest * np.sqrt(f_lines / 2.0))
    u0 = amp * np.exp(-1j * np.pi * k * (k - 1) / f_lines)  # Schroeder phases
    i0 = u0 / z
    def noise(s):
        return np.sqrt(2.0 * s * s / n_samples) * (rng.standard_normal((periods, z.size))
                                                   + 1j * rng.standard_normal((periods, z.size)))
    up = u0 + noise(s_u)
    ip = i0 + noise(s_i)
    um, im = up.mean(axis=0), ip.mean(axis=0)
    zh = um / im
    du, di = up - um, ip - im
    var_u = (np.abs(du) ** 2).sum(axis=0) / (periods - 1)
    var_i = (np.abs(di) ** 2).sum(axis=0) / (periods - 1)
    cov_ui = (du * np.conj(di)).sum(axis=0) / (periods - 1)
    rel = (var_u / np.abs(um) ** 2 + var_i / np.abs(im) ** 2
           - 2.0 * np.real(cov_ui / (um * np.conj(im))))
    kernel = np.ones(pool) / pool
    rel = np.convolve(np.pad(rel, pool // 2, mode="edge"), kernel, mode="valid")
    sigma = np.abs(zh) * np.sqrt(np.maximum(rel, 0.0) / periods)
    return zh, sigma


def read_waveform(path):
    """Sample rate, played voltage and its period (samples) of a recording CSV (docstring)."""
    with open(path) as f:
        head = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    t, u = data[:, head.index("t_s")], data[:, head.index("u_v")]
    n = u.size
    for period in (p for p in range(2, n + 1) if n % p == 0):
        if np.allclose(u[period:], u[:n - period], rtol=0.0, atol=1e-9 * np.abs(u).max()):
            break
    return (n - 1) / (t[-1] - t[0]), u, period


def state_space(p, r_bond):
    """A, B of the state x = (i, theta, w) (docstring); output i = x[0]."""
    m, k, c = chain_matrices(p, r_bond)
    n = m.shape[0]
    b = np.zeros(n)
    b[:MAGNETS] = 1.0 / MAGNETS
    minv = np.diag(1.0 / np.diag(m))
    a = np.zeros((2 * n + 1, 2 * n + 1))
    a[0, 0] = -p["r"] / p["l"]
    a[0, n + 1:] = -p["t"] * b / p["l"]
    a[1:n + 1, n + 1:] = np.eye(n)
    a[n + 1:, 0] = minv @ (p["t"] * b)
    a[n + 1:, 1:n + 1] = -minv @ k
    a[n + 1:, n + 1:] = -minv @ c
    bb = np.zeros(2 * n + 1)
    bb[0] = 1.0 / p["l"]
    return a, bb


def raw_current(p, r_bond, rate, u, period):
    """The current from rest for the played voltage u (periodic with `period` samples)."""
    spec = np.fft.rfft(u[:period]) / period
    bins = np.nonzero(np.abs(spec) > 1e-9 * np.abs(spec).max())[0]
    bins = bins[bins > 0]
    f_hz = bins * rate / period
    a, bb = state_space(p, r_bond)
    x0 = np.zeros(a.shape[0])
    i_spec = np.zeros(spec.size, dtype=complex)
    z = impedance(p, r_bond, f_hz)
    for k, f, zk in zip(bins, f_hz, z):
        xk = np.linalg.solve(2j * np.pi * f * np.eye(a.shape[0]) - a, bb * spec[k])
        if abs(xk[0] - spec[k] / zk) > 1e-9 * abs(xk[0]):
            raise RuntimeError("state equations disagree with the impedance at %.2f Hz" % f)
        i_spec[k] = xk[0]
        x0 += 2.0 * xk.real  # u(t) = sum over lines of 2 Re(U_k exp(j w_k t))
    i_ss = np.tile(np.fft.irfft(i_spec * period, n=period), u.size // period)
    step = scipy.linalg.expm(a / rate)
    free = np.empty(u.size)
    x = -x0
    for s in range(u.size):
        free[s] = x[0]
        x = step @ x
    return i_ss + free


def quantise(x, full_scale, bits):
    lsb = 2.0 * full_scale / 2 ** bits
    return np.clip(np.round(x / lsb), -2 ** (bits - 1), 2 ** (bits - 1) - 1) * lsb


def write_raw_unit(path, p, r_bond, wave, rng, a):
    """One unit's raw recording (docstring: Raw recordings)."""
    rate, u, period = wave
    i = raw_current(p, r_bond, rate, u, period)
    u_rec = quantise(u + a.noise_v * rng.standard_normal(u.size), a.full_scale_v, a.adc_bits)
    i_rec = quantise(i + a.noise_a * rng.standard_normal(u.size), a.full_scale_a, a.adc_bits)
    t = np.arange(u.size) / rate
    with open(path, "w") as f:
        f.write("t_s,u_v,i_a,u_full_scale_v,i_full_scale_a\n")
        for row in zip(t, u_rec, i_rec):
            f.write("%.7f,%.6f,%.7f,%g,%g\n" % (row + (a.full_scale_v, a.full_scale_a)))


def write_frf_unit(path, p, r_bond, f_hz, rng, a, sample_rate):
    zh, sigma = measure(impedance(p, r_bond, f_hz), rng, periods=a.periods, f_lines=f_hz.size,
                        peak_v=a.peak_v, crest=a.crest,
                        n_samples=int(round(sample_rate / a.spacing)))
    with open(path, "w") as f:
        f.write("f_hz,re_ohm,im_ohm,sigma_ohm\n")
        for fk, zk, sk in zip(f_hz, zh, sigma):
            f.write("%.4f,%.9g,%.9g,%.6g\n" % (fk, zk.real, zk.imag, sk))


def main():
    soft = __doc__[__doc__.index("Bond softness"):__doc__.index("Measurement:")]
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0], epilog=soft,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", help="output directory (created)")
    ap.add_argument("--seed", type=int, default=1)
    for name, default in (("good", 100), ("one_soft", 20), ("three_soft", 20),
                          ("all_soft", 20)):
        ap.add_argument("--" + name.replace("_", "-"), type=int, default=default,
                        dest=name, help="units of class " + name)
    ap.add_argument("--loss-lo", type=float, default=0.20,
                    help="smallest bond stiffness loss of a soft magnet (0-1, default 0.20)")
    ap.add_argument("--loss-hi", type=float, default=0.99,
                    help="largest bond stiffness loss of a soft magnet (0-1, default 0.99)")
    ap.add_argument("--poor-loss-factor", type=float, default=NOMINAL["eta_poor"],
                    help="loss factor of a soft bond (default %g; the good adhesive's is %g)"
                    % (NOMINAL["eta_poor"], NOMINAL["eta_bond"]))
    ap.add_argument("--motor", choices=sorted(MOTORS), default="pmsm-10pole",
                    help="the motor type drawn (default pmsm-10pole)")
    for opt, i, kind in (("--f-lo", 0, float), ("--f-hi", 1, float), ("--spacing", 2, float),
                         ("--peak-v", 3, float), ("--periods", 4, int), ("--crest", 5, float)):
        ap.add_argument(opt, type=kind, default=None, dest=opt[2:].replace("-", "_"),
                        help="measurement (default: the motor's, see above)")
    ap.add_argument("--raw", metavar="WAVE",
                    help="write raw recordings of the voltage in this recording CSV (see above)")
    for opt, default, what in (("--noise-v", 2e-3, "voltage noise, V rms per sample"),
                               ("--noise-a", 1e-3, "current noise, A rms per sample"),
                               ("--full-scale-v", 10.0, "voltage converter's full scale, V"),
                               ("--full-scale-a", 2.0, "current converter's full scale, A")):
        ap.add_argument(opt, type=float, default=default, help="--raw: %s (default %g)"
                        % (what, default))
    ap.add_argument("--adc-bits", type=int, default=16,
                    help="--raw: converter resolution over +-full scale (default 16)")
    ap.add_argument("--nominal", action="store_true",
                    help="print the nominal chain's first modes and exit")
    ap.add_argument("--loss-table", action="store_true",
                    help="print the nominal first mode against the stiffness loss and exit")
    a = ap.parse_args()
    select_motor(a.motor)
    defaults = MOTORS[a.motor][3]
    for i, name in enumerate(("f_lo", "f_hi", "spacing", "peak_v", "periods", "crest")):
        if getattr(a, name) is None:
            setattr(a, name, defaults[i])
    if not (0 < a.f_lo < a.f_hi < 4000.0 and a.spacing > 0 and a.peak_v > 0 and a.periods >= 2):
        ap.error("measurement: need 0 < f-lo < f-hi < 4000, spacing > 0, peak-v > 0, periods >= 2")
    f_hz = a.spacing * np.arange(np.ceil(a.f_lo / a.spacing - 1e-9),
                                 np.floor(a.f_hi / a.spacing + 1e-9) + 1.0)
    sample_rate = 8000.0

    if a.nominal:
        p = nominal_parts()
        soft = np.full(MAGNETS, 0.04)
        print("rigid shaft end: %.1f Hz good, %.1f Hz all bonds at 4 %%" %
              (first_mode_hz(p, np.ones(MAGNETS), True), first_mode_hz(p, soft, True)))
        print("in the fixture:  %.1f Hz good, %.1f Hz all bonds at 4 %%" %
              (first_mode_hz(p, np.ones(MAGNETS)), first_mode_hz(p, soft)))
        return 0
    if a.loss_table:
        p = nominal_parts()
        good = first_mode_hz(p, np.ones(MAGNETS))
        print("loss  all     three  one   (first mode Hz in the fixture; good %.1f Hz)" % good)
        for loss in (0.2, 0.4, 0.6, 0.8, 0.85, 0.9, 0.92, 0.94, 0.95, 0.96, 0.98, 0.99):
            modes = []
            for n in (MAGNETS, 3, 1):
                r = np.ones(MAGNETS)
                r[:n] = 1.0 - loss
                modes.append(first_mode_hz(p, r))
            print("%.2f  %6.1f  %6.1f  %6.1f" % ((loss,) + tuple(modes)))
        return 0
    if not a.out:
        ap.error("--out is required")
    if not 0.0 < a.loss_lo <= a.loss_hi < 1.0:
        ap.error("--loss-lo and --loss-hi: need 0 < lo <= hi < 1 (got %g, %g)"
                 % (a.loss_lo, a.loss_hi))

    wave = None
    if a.raw:
        if not (a.noise_v >= 0 and a.noise_a >= 0 and a.full_scale_v > 0 and a.full_scale_a > 0
                and 2 <= a.adc_bits <= 32):
            ap.error("--raw: need noise >= 0, full scales > 0 and 2 <= adc-bits <= 32")
        wave = read_waveform(a.raw)
    os.makedirs(a.out, exist_ok=True)
    rng = np.random.default_rng(a.seed)
    plan = [c for c in CLASSES for _ in range(getattr(a, c))]
    order = rng.permutation(len(plan))  # classes interleaved, as on a line
    with open(os.path.join(a.out, "truth.csv"), "w", newline="") as tf:
        tw = csv.writer(tf)
        tw.writerow(["unit", "class", "first_mode_hz", "k_fixture_nm_per_rad", "defect_size"]
                    + ["r_bond_%d" % (i + 1) for i in range(MAGNETS)]
                    + ["loss_%d" % (i + 1) for i in range(MAGNETS)] + ["clamp_pressure_bar"])
        for idx, j in enumerate(order):
            cls = plan[j]
            p = draw_parts(rng)
            p["eta_poor"] = a.poor_loss_factor
            r, size = draw_bonds(rng, CLASSES[cls], a.loss_lo, a.loss_hi)
            name = "unit-%04d" % (idx + 1)
            if wave is not None:
                write_raw_unit(os.path.join(a.out, name + ".csv"), p, r, wave, rng, a)
            else:
                write_frf_unit(os.path.join(a.out, name + ".csv"), p, r, f_hz, rng, a,
                               sample_rate)
            tw.writerow([name, cls, "%.3f" % first_mode_hz(p, r), "%.2f" % p["k_fixture"],
                         "%.4f" % size] + ["%.4f" % x for x in r] + ["%.4f" % (1.0 - x) for x in r]
                        + ["%.3f" % p["clamp_pressure_bar"]])
    return 0


if __name__ == "__main__":
    sys.exit(main())
