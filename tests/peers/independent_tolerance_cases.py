#!/usr/bin/python3
"""Blind cases for `eol gap` where the simulation is not the unit: calibration offsets.

Written from the physics with no code shared with analysis/ (the network, the effects and the
measurement are independent_gap_cases.py's, beside this file). Each case is a random clamped
motor (f0 250 Hz - 2 kHz) as designed (the simulation, noise-free) and a unit of that design
as built: every design parameter off by its tolerance, the DAQ with a gain error, and none,
one or two hidden effects:
  R, L, torque constant T, rotor inertia J, support stiffness k (rotor spring and fixture
  together): each off by 5-12 % (either sign);  damping c: x 0.5-2 (log-uniform);
  DAQ gain: the measured Z times 1 +- (0.2-1.5) %.
Classes, cycled over the cases: `none` (calibration only), one effect (coupled_inertia,
fractional_inductance, eddy_branch, channel_delay, stray_capacitance, fixture_spring), and
two at once (PAIRS). Files as independent_gap_cases.py writes them (case-NNN-sim.csv,
case-NNN-meas.csv with sigma from 8 periods and its degrees of freedom, truth.json); the band
is 50 Hz to 2.5 f0 (at least 2 kHz), 2.5 Hz lines below f0 = 800 Hz, 5 Hz above.

Noise: an effect case's channel noise is scaled so that its weakest effect's strength
  S_m = sqrt(sum_k 2 |Z_unit - Z_unit without m|^2 / sigma_k^2)
is log-uniform in [s_lo, s_hi]; a calibration-only case's so that the calibration's own
strength (the unit against the simulation) is log-uniform in [20, 1000].

Separable (the oracle, written into truth.json with the case): the design's tolerances taken as a Gaussian prior on the
logarithms of R, L, T, J, k, c and the gain (1 sd: 10, 8, 6, 6, 15 %, x3, 1 %: the defaults
`eol gap` states), the calibrated nominal is the least-squares fit (scipy) of those seven
under that prior to the measurement (from the design, from the true offsets and from the best
point of a grid over the stiffness and the damping). An effect m is separable when the calibrated unit
without it (the other effect, if any, kept at its true parameters) costs at least
10 + p_m ln(2K) more than the truth (cost -2 ln L as `eol gap` scores it, Student t on the
sigma's degrees of freedom, impedance form; plus the prior's sum (delta / sd)^2; p_m the
parameters `eol gap` fits for it, 2K the real residuals): the decision rule's own margin
(BIC, min_score_gain 10). A case is separable when every effect is; calibration-only cases
always are.

Usage:
  independent_tolerance_cases.py --out DIR [--cases 48] [--seed 1]
  independent_tolerance_cases.py --out DIR --score --eol build/eol [--classes none,single]
                                 [-- extra eol gap arguments]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import independent_gap_cases as gen  # noqa: E402  (the physics and the measurement)

SINGLES = ["coupled_inertia", "fractional_inductance", "eddy_branch", "channel_delay",
           "stray_capacitance", "fixture_spring"]
PAIRS = [("fixture_spring", "channel_delay"), ("coupled_inertia", "stray_capacitance"),
         ("eddy_branch", "coupled_inertia"), ("fractional_inductance", "fixture_spring"),
         ("channel_delay", "coupled_inertia"), ("stray_capacitance", "fixture_spring"),
         ("fractional_inductance", "stray_capacitance"), ("coupled_inertia", "fractional_inductance")]
# The parameters `eol gap` fits per effect (its BIC charges p ln(2K)).
PARAMS = {"coupled_inertia": 4, "fractional_inductance": 3, "eddy_branch": 2, "channel_delay": 1,
          "stray_capacitance": 1, "fixture_spring": 2}
# Design tolerances, 1 sd of ln(value): R, L, T, J, k, c, gain.
NAMES = ["R", "L", "T", "J", "k", "c", "G"]
SD = np.array([0.10, 0.08, 0.06, 0.06, 0.15, math.log(3.0), 0.01])
PERIODS = gen.PERIODS


def draw_motor(rng):
    """A random design (independent_gap_cases.draw_motor with f0 250 Hz - 2 kHz)."""
    m = gen.draw_motor(rng)
    f0 = gen.log_uniform(rng, 250.0, 2000.0)
    scale = (f0 / m["f0_hz"]) ** 2
    for key in ("k_r", "k_f", "c_r", "c_f"):
        m[key] *= scale if key.startswith("k") else 1.0
    # Keep Q: c scales with sqrt(k J), i.e. with f0 at fixed J; T^2 with c keeps the peak's
    # share of w0 L, which itself grows with f0.
    for key in ("c_r", "c_f"):
        m[key] *= f0 / m["f0_hz"]
    m["T"] *= math.sqrt(f0 / m["f0_hz"] * f0 / m["f0_hz"])
    m["f0_hz"] = f0
    return m


def lines(f0):
    hi = max(2000.0, 2.5 * f0)
    df = 2.5 if f0 < 800.0 else 5.0
    return np.arange(50.0, hi + 0.5 * df, df)


def built(m, delta):
    """The design with the log-offsets delta (R, L, T, J, k, c; the gain is applied apart)."""
    u = dict(m)
    u["R"] *= math.exp(delta[0])
    u["L"] *= math.exp(delta[1])
    u["T"] *= math.exp(delta[2])
    u["J"] *= math.exp(delta[3])
    for key in ("k_r", "k_f"):
        u[key] *= math.exp(delta[4])
    for key in ("c_r", "c_f"):
        u[key] *= math.exp(delta[5])
    return u


def unit_z(m, delta, f, effects):
    return math.exp(delta[6]) * gen.impedance_with(built(m, delta), f, effects)


def draw_offsets(rng):
    d = [rng.choice([-1, 1]) * rng.uniform(0.05, 0.12) for _ in range(5)]
    d.append(math.log(gen.log_uniform(rng, 0.5, 2.0)))
    d.append(math.log1p(rng.choice([-1, 1]) * rng.uniform(0.002, 0.015)))
    return np.array(d)


def draw_effect(rng, kind, m, f_hi):
    old = gen.F_HI
    gen.F_HI = f_hi  # the band's top sets the delay's and the capacitance's scale
    try:
        p = gen.draw_effect(rng, kind, m, (0.05, 0.5, 1.3, 3.5, 0.7 * f_hi))
    finally:
        gen.F_HI = old
    if kind == "fixture_spring":  # a fault: a clearly softer clamp (f0 down 14-50 %)
        k_ser = 1.0 / (1.0 / m["k_r"] + 1.0 / m["k_f"])
        p["k_x"] = gen.log_uniform(rng, 0.3, 3.0) * k_ser
    return p


def strength(z_a, z_b, sigma):
    return math.sqrt(np.sum(2 * np.abs(z_a - z_b) ** 2 / sigma ** 2))


def generate(out_dir, cases, seed, s_lo, s_hi):
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng(seed)
    truth = []
    for c in range(cases):
        cls = ["none", "single", "pair"][c % 3]
        kinds = ([] if cls == "none" else [SINGLES[(c // 3) % len(SINGLES)]] if cls == "single"
                 else list(PAIRS[(c // 3) % len(PAIRS)]))
        m = draw_motor(rng)
        f = lines(m["f0_hz"])
        delta = draw_offsets(rng)
        effects = [(k, draw_effect(rng, k, m, f[-1])) for k in kinds]
        z0 = gen.impedance_with(m, f, [])
        z1 = unit_z(m, delta, f, effects)
        v_amp, rel_i = 1.0, gen.log_uniform(rng, 0.3, 3.0)
        i_rms = np.sqrt(np.mean(np.abs(v_amp / z1) ** 2))
        unit_u, unit_i = v_amp, rel_i * i_rms
        _, _, sig_unit = gen.measure(np.random.default_rng(0), z1, unit_u, unit_i, v_amp)
        if effects:
            s_unit = min(strength(z1, unit_z(m, delta, f, [e for e in effects if e[0] != k]),
                                  sig_unit) for k, _ in effects)
            target = gen.log_uniform(rng, s_lo, s_hi)
        else:
            s_unit = strength(z1, z0, sig_unit)
            target = gen.log_uniform(rng, 20.0, 1000.0)
        scale = s_unit / target
        z, sig, sig_true = gen.measure(rng, z1, scale * unit_u, scale * unit_i, v_amp)
        name = "case-%03d" % c
        gen.write_csv(os.path.join(out_dir, name + "-sim.csv"), f, z0)
        gen.write_csv(os.path.join(out_dir, name + "-meas.csv"), f, z, sig)
        s_eff = [strength(z1, unit_z(m, delta, f, [e for e in effects if e[0] != k]), sig_true)
                 for k, _ in effects]
        truth.append({"case": name, "class": cls, "effects": kinds,
                      "effect": "+".join(kinds) or "none", "params": [p for _, p in effects],
                      "strength": min(s_eff) if s_eff else strength(z1, z0, sig_true),
                      "offsets": dict(zip(NAMES, delta.tolist())), "motor": m,
                      "sigma_dof": 2 * (PERIODS - 1)})
        truth[-1]["separable"], truth[-1]["margins"] = separable(truth[-1], out_dir)
    with open(os.path.join(out_dir, "truth.json"), "w") as out:
        json.dump(truth, out, indent=1, default=float)
    return truth


def read_meas(path):
    with open(path) as src:
        rows = [ln for ln in src if ln.strip() and ln[0] not in "#f"]
    d = np.loadtxt(rows, delimiter=",", ndmin=2)
    return d[:, 0], d[:, 1] + 1j * d[:, 2], d[:, 3]


def cost(z, model, sigma, nu):
    u = np.abs((z - model) / sigma) ** 2
    return float(np.sum((nu + 2) * np.log1p(2 * u / nu)))


def calibrated_cost(m, f, z, sigma, nu, effects, start):
    """min over the seven log-offsets of cost + sum (delta / sd)^2, the effects fixed."""
    def residual(d):
        r = (z - unit_z(m, d, f, effects)) / sigma
        u = np.abs(r) ** 2
        g = np.sqrt((nu + 2) * np.log1p(2 * u / nu) / np.maximum(u, 1e-300))
        return np.concatenate([g * r.real, g * r.imag, d / SD])
    # A mode moved far (a fixture spring taken up by the stiffness) is out of LM's reach from
    # the design: a grid over the stiffness and the damping (the rest at zero) adds the start.
    grid = []
    for dk in np.linspace(-4.0, 4.0, 33) * SD[4]:
        for dc in (-1.0, 0.0, 1.0):
            d = np.zeros(7)
            d[4], d[5] = dk, dc * SD[5]
            grid.append((float(np.sum(residual(d) ** 2)), d))
    best = math.inf
    for d0 in (np.zeros(7), start, min(grid, key=lambda g: g[0])[1]):
        sol = least_squares(residual, d0, method="lm", xtol=1e-12, ftol=1e-12, max_nfev=4000)
        best = min(best, float(np.sum(sol.fun ** 2)))
    return best


def separable(t, out_dir):
    if not t["effects"]:
        return True, []
    t = json.loads(json.dumps(t, default=float))  # plain floats, as truth.json holds them
    f, z, sigma = read_meas(os.path.join(out_dir, t["case"] + "-meas.csv"))
    nu = float(t["sigma_dof"])
    delta = np.array([t["offsets"][n] for n in NAMES])
    effects = list(zip(t["effects"], t["params"]))
    truth = cost(z, unit_z(t["motor"], delta, f, effects), sigma, nu) + float(
        np.sum((delta / SD) ** 2))
    margins = []
    for k in t["effects"]:
        rest = [e for e in effects if e[0] != k]
        cal = calibrated_cost(t["motor"], f, z, sigma, nu, rest, delta)
        margins.append(cal - truth - (10.0 + PARAMS[k] * math.log(2 * len(f))))
    return all(x >= 0.0 for x in margins), margins


def members(answer):
    return [] if answer in ("none", "unexplained") or answer.startswith("error") else \
        answer.split("+")


def exact(answer, kinds):
    """The answer names exactly the hidden effects (each by a name that counts for it)."""
    got = members(answer)
    if len(got) != len(kinds):
        return False
    if len(kinds) == 1:
        return got[0] in gen.EXPECTED[kinds[0]]
    a, b = kinds
    return ((got[0] in gen.EXPECTED[a] and got[1] in gen.EXPECTED[b]) or
            (got[0] in gen.EXPECTED[b] and got[1] in gen.EXPECTED[a]))


def score(out_dir, eol, extra, classes):
    with open(os.path.join(out_dir, "truth.json")) as f:
        truth = [t for t in json.load(f) if t["class"] in classes]
    rows = []
    t0 = time.time()
    for t in truth:
        base = os.path.join(out_dir, t["case"])
        cmd = [eol, "gap", "--sim", base + "-sim.csv", "--measured", base + "-meas.csv",
               "--json"] + extra
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            answer = "error: " + (p.stderr.strip().splitlines() or ["?"])[-1]
        else:
            answer = json.loads(p.stdout)["effect"]
        sep, margins = ((t["separable"], t["margins"]) if "separable" in t
                        else separable(t, out_dir))
        ok = answer == "none" if not t["effects"] else exact(answer, t["effects"])
        rows.append({"case": t["case"], "class": t["class"], "hidden": t["effect"],
                     "separable": sep, "margins": margins, "strength": t["strength"],
                     "f0_hz": t["motor"]["f0_hz"], "answer": answer, "ok": ok,
                     "pair_answered": len(members(answer)) == 2})
    elapsed = time.time() - t0
    print("%-9s %-7s %-44s %5s %8s %6s  %-44s %s" % ("case", "class", "hidden", "sep", "S", "f0",
                                                      "answer", "ok"))
    for r in rows:
        print("%-9s %-7s %-44s %5s %8.1f %6.0f  %-44s %s" % (
            r["case"], r["class"], r["hidden"], r["separable"], r["strength"], r["f0_hz"],
            r["answer"], "yes" if r["ok"] else "NO"))
    summary = {}
    for cls in ("none", "single", "pair"):
        every = [r for r in rows if r["class"] == cls]
        sep = [r for r in every if r["separable"]]
        summary[cls] = {"cases": len(every), "ok": sum(r["ok"] for r in every),
                        "separable": len(sep), "separable_ok": sum(r["ok"] for r in sep),
                        "pair_answered": sum(r["pair_answered"] for r in every)}
    n, s, p = summary["none"], summary["single"], summary["pair"]
    print("\ncalibration only `none`: %d / %d (a pair answered: %d)" %
          (n["ok"], n["cases"], n["pair_answered"]))
    print("one effect named alone:  %d / %d separable (%d / %d all)" %
          (s["separable_ok"], s["separable"], s["ok"], s["cases"]))
    print("pairs named exactly:     %d / %d separable (%d / %d all)" %
          (p["separable_ok"], p["separable"], p["ok"], p["cases"]))
    print("run time %.1f s" % elapsed)
    result = {"summary": summary, "rows": rows, "seconds": elapsed}
    with open(os.path.join(out_dir, "score.json"), "w") as out:
        json.dump(result, out, indent=1)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--cases", type=int, default=48)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--s-lo", type=float, default=20.0)
    ap.add_argument("--s-hi", type=float, default=150.0)
    ap.add_argument("--score", action="store_true", help="run `eol gap` on the cases")
    ap.add_argument("--eol", default="build/eol")
    ap.add_argument("--classes", default="none,single,pair",
                    help="--score only the cases of these classes (comma-separated)")
    ap.add_argument("extra", nargs="*", help="extra `eol gap` arguments (after --)")
    a = ap.parse_args()
    if a.score:
        classes = a.classes.split(",")
        if not classes or any(c not in ("none", "single", "pair") for c in classes):
            ap.error("--classes: a comma-separated list of none, single, pair")
        score(a.out, a.eol, a.extra, classes)
    else:
        if a.cases < 1 or not 0 < a.s_lo <= a.s_hi:
            ap.error("want --cases >= 1 and 0 < --s-lo <= --s-hi")
        t = generate(a.out, a.cases, a.seed, a.s_lo, a.s_hi)
        print("%d cases written to %s" % (len(t), a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
