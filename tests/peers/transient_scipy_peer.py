#!/usr/bin/python3
"""Independent peer for the transient-aware FRF estimator (analysis/signal/transient_frf.h).

Simulates, FROM REST and written from the physics alone (analysis/README.md 1-2: the clamped rotor as
one inertia J on a spring k with damper c, transducer T, winding R and L, the amplifier's
output and shunt resistance Rs in series), the recording the station would make of a
periodic multisine switched on at t = 0:

    J theta'' = -k theta - c theta' + T i
    L i'      = u_amp(t) - (R + Rs) i - T theta'
    recorded:   u = u_amp - Rs i  (motor voltage),  i

integrated with scipy.integrate.solve_ivp (DOP853, tight tolerances) on the continuous
amplifier voltage u_amp(t) = sum_k A cos(2 pi f_k t + phi_k) (Schroeder phases, the station's
band and spacing; no sample hold: a band-limited DAC), sampled at fs. White Gaussian noise is
added per sample and channel (numpy's generator, one seed per record).

The motor is given as the five identifiable parameters (R, L, Rp, f0, Q); with J chosen
(it does not change Z): k = J w0^2, c = J w0 / Q, T = sqrt(Rp c).

Usage: transient_scipy_peer.py OUT_DIR RECORDS SEED
Writes OUT_DIR/rec_<n>.csv (t_s,u_v,i_a) and prints one JSON object with the truth.
Exit 2 when scipy is missing.
"""
import json
import os
import sys

try:
    import numpy as np
    import scipy
    from scipy.integrate import solve_ivp
except ImportError as e:  # a declared dependency: the test fails on exit code 2
    print("scipy missing: %s" % e)
    sys.exit(2)

FS = 8000.0
SPACING = 4.0
F_LO, F_HI = 200.0, 800.0
PERIODS = 2
PEAK_V = 2.0
R, L, RP, F0, Q = 0.5, 2.0e-3, 0.51, 390.0, 50.0
RS = 0.15
J = 1.0e-4
NOISE_U, NOISE_I = 2.0e-3, 1.0e-3


def main():
    out_dir, records, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    w0 = 2 * np.pi * F0
    k = J * w0 ** 2
    c = J * w0 / Q
    t_tr = np.sqrt(RP * c)

    bins = np.arange(int(round(F_LO / SPACING)), int(round(F_HI / SPACING)) + 1)
    f = bins * SPACING
    nl = len(bins)
    phi = -np.pi * np.arange(1, nl + 1) * np.arange(0, nl) / nl  # Schroeder
    n_per = int(round(FS / SPACING))
    t = np.arange(PERIODS * n_per) / FS
    tt = np.arange(n_per) / FS
    one = np.cos(2 * np.pi * np.outer(tt, f) + phi).sum(axis=1)
    amp = PEAK_V / np.max(np.abs(one))

    def u_amp(time):
        return amp * np.sum(np.cos(2 * np.pi * f * time + phi))

    def rhs(time, x):
        theta, omega, i = x
        return [omega, (-k * theta - c * omega + t_tr * i) / J,
                (u_amp(time) - (R + RS) * i - t_tr * omega) / L]

    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0, 0.0], method="DOP853", t_eval=t,
                    rtol=1e-10, atol=1e-13, max_step=1.0 / (8 * F_HI))
    if not sol.success:
        print("solve_ivp failed: %s" % sol.message)
        sys.exit(1)
    i_clean = sol.y[2]
    u_clean = amp * np.cos(2 * np.pi * np.outer(t, f) + phi).sum(axis=1) - RS * i_clean

    # The size of the start transient: the current's first period against its second.
    transient_rms = float(np.sqrt(np.mean((i_clean[:n_per] - i_clean[n_per:2 * n_per]) ** 2)))
    rng = np.random.default_rng(seed)
    for r in range(records):
        u = u_clean + NOISE_U * rng.standard_normal(len(t))
        i = i_clean + NOISE_I * rng.standard_normal(len(t))
        path = os.path.join(out_dir, "rec_%d.csv" % r)
        with open(path, "w") as fh:
            fh.write("t_s,u_v,i_a\n")
            for a, b, d in zip(t, u, i):
                fh.write("%.9f,%.12g,%.12g\n" % (a, b, d))
    print(json.dumps({"scipy_version": scipy.__version__, "f0_hz": F0, "q": Q, "r_ohm": R,
                      "l_h": L, "rp_ohm": RP, "records": records, "samples": len(t),
                      "transient_rms_a": transient_rms,
                      "current_rms_a": float(np.sqrt(np.mean(i_clean[n_per:] ** 2)))}))


if __name__ == "__main__":
    main()
