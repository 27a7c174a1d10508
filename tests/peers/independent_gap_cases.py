#!/usr/bin/python3
"""Blind cases for `eol gap`, written from the physics with no code shared with analysis/.

Each case is a random clamped motor (the paper's network, analysis/README.md 1-2), one hidden effect or
none, and a periodic multisine measurement with noise on both channels, written as
  case-NNN-sim.csv   the nominal's impedance, noise-free (f_hz,re_ohm,im_ohm)
  case-NNN-meas.csv  the measured impedance with sigma from the periods (f_hz,re_ohm,im_ohm,
                     sigma_ohm,sigma_dof: sigma^2 on 2 (P - 1) = 14 degrees of freedom)
plus truth.json (the effect, its parameters, the strength S, the sigma degrees of freedom).

Physics (s = j w). Mechanical impedances are torque / angular velocity (N m s/rad):
  inertia J: s J;  spring k: k / s;  damper c: c;
  elements at one node add; elements in series add as admittances (1/Z).
Nominal: the magnets' inertia J (the torque acts there) on the rotor spring k_r (damper c_r)
to the shaft end, the shaft end on the fixture spring k_f (damper c_f) to ground:
  Zm = s J + 1 / (1 / (k_r/s + c_r) + 1 / (k_f/s + c_f))
  Z  = R + s L + T^2 / Zm                         (T: torque constant, N m/A)
Hidden effects (the measured unit has them, the simulation does not):
  coupled_inertia (rotor): J2 on k2 (damper c2) at the magnets' node:
      Zm += 1 / (1 / (k2/s + c2) + 1 / (s J2))
  coupled_inertia (shaft): the same branch at the shaft-end node (added to k_f/s + c_f)
  fractional_inductance: part of L is a lossy (semi-)inductance,
      s L -> s L (1 - a) + a L w_ref^(1-n) (j w)^n, 0.5 < n < 0.8 (same |Z_L| at w_ref),
      a in 0.05-0.3 (--fractional a_lo,a_hi; 1,1: the whole winding is K (j w)^n)
  eddy_branch: s L -> s (L - L2) + s L2 R2 / (s L2 + R2)   (L at low frequency)
  channel_delay: Z -> Z exp(-s tau)
  stray_capacitance: Z -> Z / (1 + s C Z)
  fixture_spring: a further massless spring k_x (loss factor eta) in series at the shaft end
  series_resistance: R -> R + dR
Measurement: a Schroeder multisine voltage on every line of the band, P periods; per period
and line the channels are U_p = V + n_u, I_p = V / Z + n_i with independent complex Gaussian
noise (what white noise gives on the lines of a whole period). Z = mean U / mean I and
  var Z = |Z|^2 / P (s_U^2/|U|^2 + s_I^2/|I|^2 - 2 Re(s_UI / (U I*)))   (analysis/README.md 3)
with the sample (co)variances of the P periods: sigma^2 then has 2 (P - 1) degrees of freedom.
The channel noise is scaled so that the effect's strength
  S = sqrt(sum_k 2 |Z_meas_true - Z_nominal|^2 / sigma_true_k^2)
is log-uniform in [s_lo, s_hi]; a case is "separable" when it has no effect or S >= 20, and
for a coupled inertia also when the data can tell it from a fixture spring: --score fits the
best massless fixture spring (`eol gap --effects fixture_compliance`) and counts the case only
when the true model's cost (-2 ln L as `eol gap` scores it: chi2 = sum 2 |r|^2 for an exact
sigma, the Student t for one on few degrees of freedom, r in the report's residual form) is
at least 10 (the diagnosis' min_score_gain) below that fit's. A coupled mode at 1.3-3.5 f0 can be so weak that
the fixture spring fits as well as the truth: no rule can name it then.

Usage:
  independent_gap_cases.py --out DIR [--cases 70] [--seed 1] [--plan E1,E2,...]
                           [--coupled mu_lo,mu_hi,f2_lo,f2_hi,cap_hz] [--fractional a_lo,a_hi]
  independent_gap_cases.py --out DIR --score --eol build/eol [-- extra eol gap arguments]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

PERIODS = 8
F_LO, F_HI, DF = 50.0, 2000.0, 2.5

# Hidden effect -> the names `eol gap` may answer that count as naming it.
EXPECTED = {
    "none": {"none"},
    "coupled_inertia": {"coupled_inertia"},
    "fractional_inductance": {"lossy_inductance", "fractional_inductance"},
    "eddy_branch": {"lossy_inductance", "fractional_inductance"},
    "channel_delay": {"channel_delay"},
    "stray_capacitance": {"stray_capacitance"},
    "fixture_spring": {"fixture_compliance"},
    "series_resistance": {"series_resistance"},
}
# Case i gets PLAN[i % len(PLAN)]: 70 cases -> 10 none, 10 coupled inertia, 10 fractional,
# 8 or so of each other effect.
PLAN = ["none", "coupled_inertia", "fractional_inductance", "eddy_branch", "channel_delay",
        "coupled_inertia", "stray_capacitance", "fixture_spring", "none",
        "series_resistance", "fractional_inductance", "coupled_inertia", "channel_delay",
        "none", "fractional_inductance"]


def lines():
    return np.arange(F_LO, F_HI + 0.5 * DF, DF)


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def draw_motor(rng):
    """A random nominal clamped motor; mode f0 of J on k_r and k_f in series."""
    m = {}
    m["R"] = rng.uniform(0.2, 2.0)
    m["L"] = log_uniform(rng, 0.5e-3, 5e-3)
    m["J"] = log_uniform(rng, 2e-4, 5e-3)
    f0 = rng.uniform(250.0, 800.0)
    k_series = m["J"] * (2 * math.pi * f0) ** 2
    # Fixture stiffness relative to the rotor's: 0.4 (a soft clamp) to 5.
    ratio = log_uniform(rng, 0.4, 5.0)
    m["k_r"] = k_series * (1 + ratio) / ratio
    m["k_f"] = ratio * m["k_r"]
    q = rng.uniform(20.0, 80.0)
    c = math.sqrt(k_series * m["J"]) / q
    # Stiffness-proportional damping (c = beta k): the two springs in series are then again
    # one spring with one damper, the single-mode nominal the simulation is.
    beta = c / k_series
    m["c_r"] = beta * m["k_r"]
    m["c_f"] = beta * m["k_f"]
    # Torque constant: motional peak T^2 / c between 0.05 and 2 times w0 L.
    peak = log_uniform(rng, 0.05, 2.0) * 2 * math.pi * f0 * m["L"]
    m["T"] = math.sqrt(peak * c)
    m["f0_hz"] = f0
    return m


def branch(s, j2, k2, c2):
    """J2 on spring k2 with damper c2, seen from the node the spring is fixed to."""
    return 1.0 / (1.0 / (k2 / s + c2) + 1.0 / (s * j2))


def impedance(m, f, effect=None, p=None):
    """The unit's impedance with one hidden effect (or none); impedance_with for several."""
    return impedance_with(m, f, [(effect, p or {})] if effect else [])


def impedance_with(m, f, effects):
    """The unit's impedance with every (kind, params) of `effects` at its place."""
    s = 2j * math.pi * f
    kinds = {kind: p for kind, p in effects}
    shaft = m["k_f"] / s + m["c_f"]
    rotor_node = s * m["J"]
    if "coupled_inertia" in kinds:
        p = kinds["coupled_inertia"]
        b = branch(s, p["J2"], p["k2"], p["c2"])
        if p["at"] == "rotor":
            rotor_node = rotor_node + b
        else:
            shaft = shaft + b
    if "fixture_spring" in kinds:
        p = kinds["fixture_spring"]
        shaft = 1.0 / (1.0 / shaft + 1.0 / (p["k_x"] * (1 + 1j * p["eta"]) / s))
    zm = rotor_node + 1.0 / (1.0 / (m["k_r"] / s + m["c_r"]) + 1.0 / shaft)
    r = m["R"] + (kinds["series_resistance"]["dR"] if "series_resistance" in kinds else 0.0)
    if "fractional_inductance" in kinds:
        p = kinds["fractional_inductance"]
        a, n, w_ref = p["a"], p["n"], p["w_ref"]
        zl = s * m["L"] * (1 - a) + a * m["L"] * w_ref ** (1 - n) * (1j * np.abs(s.imag)) ** n
    elif "eddy_branch" in kinds:
        p = kinds["eddy_branch"]
        l2, r2 = p["L2"], p["R2"]
        zl = s * (m["L"] - l2) + s * l2 * r2 / (s * l2 + r2)
    else:
        zl = s * m["L"]
    z = r + zl + m["T"] ** 2 / zm
    if "stray_capacitance" in kinds:
        z = z / (1 + s * kinds["stray_capacitance"]["C"] * z)
    if "channel_delay" in kinds:
        z = z * np.exp(-s * kinds["channel_delay"]["tau"])
    return z


# The coupled inertia's draw: mass ratio mu log-uniform in [mu_lo, mu_hi], J2-on-k2 frequency
# uniform in [f2_lo, f2_hi] times f0 and at most cap_hz (0: no cap). The default keeps the
# coupled mode inside the band; --coupled changes it (a stiffer coupling, heavier parts).
COUPLED = (0.05, 0.5, 1.3, 3.5, 0.7 * F_HI)
# The fractional inductance's share a of L, uniform in [a_lo, a_hi]; a = 1 is a winding whose
# whole inductance is the semi-inductance K (j w)^n (--fractional 1,1).
FRACTIONAL = (0.05, 0.3)


def draw_effect(rng, kind, m, coupled=COUPLED, fractional=FRACTIONAL):
    w0 = 2 * math.pi * m["f0_hz"]
    w_hi = 2 * math.pi * F_HI
    if kind == "none":
        return {}
    if kind == "coupled_inertia":
        at = "rotor" if rng.uniform() < 0.5 else "shaft"
        mu_lo, mu_hi, f2_lo, f2_hi, cap_hz = coupled
        mu = log_uniform(rng, mu_lo, mu_hi)
        j2 = mu * m["J"]
        # Uncoupled J2-on-k2 frequency (default 1.3-3.5 f0: the coupled mode rings in the band).
        f2 = rng.uniform(f2_lo, f2_hi) * m["f0_hz"]
        f2 = min(f2, cap_hz) if cap_hz > 0 else f2
        k2 = j2 * (2 * math.pi * f2) ** 2
        q2 = rng.uniform(15.0, 80.0)
        return {"at": at, "J2": j2, "k2": k2, "c2": math.sqrt(k2 * j2) / q2, "mass_ratio": mu,
                "f2_hz": f2, "q2": q2}
    if kind == "fractional_inductance":
        return {"a": rng.uniform(fractional[0], fractional[1]), "n": rng.uniform(0.5, 0.8),
                "w_ref": 2 * math.pi * math.sqrt(F_LO * F_HI)}
    if kind == "eddy_branch":
        l2 = rng.uniform(0.05, 0.4) * m["L"]
        fc = log_uniform(rng, 0.3 * F_LO, 2 * F_HI)
        return {"L2": l2, "R2": 2 * math.pi * fc * l2, "corner_hz": fc}
    if kind == "channel_delay":
        return {"tau": rng.choice([-1, 1]) * log_uniform(rng, 1e-4, 3e-2) / w_hi}
    if kind == "stray_capacitance":
        f_self = log_uniform(rng, 2.0, 10.0) * F_HI
        return {"C": 1.0 / (m["L"] * (2 * math.pi * f_self) ** 2), "f_self_hz": f_self}
    if kind == "fixture_spring":
        k_ser = 1.0 / (1.0 / m["k_r"] + 1.0 / m["k_f"])
        return {"k_x": log_uniform(rng, 0.5, 20.0) * k_ser, "eta": rng.uniform(0.0, 0.05)}
    if kind == "series_resistance":
        return {"dR": rng.uniform(-0.1, 0.3) * m["R"]}
    raise ValueError(kind)


def measure(rng, z_true, noise_u, noise_i, v_amp):
    """P periods of the multisine; returns Z, its sigma and the true sigma."""
    k = np.arange(1, len(z_true) + 1)
    v = v_amp * np.exp(-1j * math.pi * k * (k - 1) / len(k))  # Schroeder phases
    i = v / z_true
    cn = lambda sd: sd * (rng.standard_normal((PERIODS, len(k))) +
                          1j * rng.standard_normal((PERIODS, len(k)))) / math.sqrt(2)
    u_p = v[None, :] + cn(noise_u)
    i_p = i[None, :] + cn(noise_i)
    u, ii = u_p.mean(0), i_p.mean(0)
    z = u / ii
    du, di = u_p - u, i_p - ii
    s_u = (np.abs(du) ** 2).sum(0) / (PERIODS - 1)
    s_i = (np.abs(di) ** 2).sum(0) / (PERIODS - 1)
    s_ui = (du * np.conj(di)).sum(0) / (PERIODS - 1)
    var = np.abs(z) ** 2 / PERIODS * (s_u / np.abs(u) ** 2 + s_i / np.abs(ii) ** 2 -
                                      2 * np.real(s_ui / (u * np.conj(ii))))
    var_true = np.abs(z_true) ** 2 / PERIODS * (noise_u ** 2 / np.abs(v) ** 2 +
                                                noise_i ** 2 / np.abs(i) ** 2)
    return z, np.sqrt(var), np.sqrt(var_true)


def write_csv(path, f, z, sigma=None):
    with open(path, "w") as out:
        out.write("# written by tests/peers/independent_gap_cases.py\n")
        # sigma_dof: each line's sigma^2 rests on 2 (P - 1) degrees of freedom.
        out.write("f_hz,re_ohm,im_ohm" + (",sigma_ohm,sigma_dof" if sigma is not None else "") +
                  "\n")
        for k in range(len(f)):
            row = "%.6f,%.12e,%.12e" % (f[k], z[k].real, z[k].imag)
            if sigma is not None:
                row += ",%.6e,%d" % (sigma[k], 2 * (PERIODS - 1))
            out.write(row + "\n")


def generate(out_dir, cases, seed, s_lo, s_hi, plan=None, coupled=COUPLED,
             fractional=FRACTIONAL):
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng(seed)
    f = lines()
    truth = []
    for c in range(cases):
        kind = (plan or PLAN)[c % len(plan or PLAN)]
        m = draw_motor(rng)
        p = draw_effect(rng, kind, m, coupled, fractional)
        z0 = impedance(m, f)
        z1 = impedance(m, f, kind, p)
        v_amp = 1.0
        # Relative noise on each channel, the current's 0.3-3 times the voltage's.
        rel_u = 1.0
        rel_i = log_uniform(rng, 0.3, 3.0)
        i_rms = np.sqrt(np.mean(np.abs(v_amp / z1) ** 2))
        unit_u, unit_i = rel_u * v_amp, rel_i * i_rms
        _, _, sig_unit = measure(np.random.default_rng(0), z1, unit_u, unit_i, v_amp)
        s_unit = math.sqrt(np.sum(2 * np.abs(z1 - z0) ** 2 / sig_unit ** 2))
        if kind == "none":
            target = 1.0
            scale = 10 ** rng.uniform(-4.0, -2.0) / (math.sqrt(np.mean(sig_unit ** 2) /
                                                               np.mean(np.abs(z0) ** 2)))
        else:
            target = log_uniform(rng, s_lo, s_hi)
            scale = s_unit / target
        z, sig, sig_true = measure(rng, z1, scale * unit_u, scale * unit_i, v_amp)
        strength = math.sqrt(np.sum(2 * np.abs(z1 - z0) ** 2 / sig_true ** 2))
        name = "case-%03d" % c
        write_csv(os.path.join(out_dir, name + "-sim.csv"), f, z0)
        write_csv(os.path.join(out_dir, name + "-meas.csv"), f, z, sig)
        truth.append({"case": name, "effect": kind, "params": p, "strength": strength,
                      "separable": kind == "none" or strength >= 20.0,
                      "sigma_dof": 2 * (PERIODS - 1), "motor": m})
    with open(os.path.join(out_dir, "truth.json"), "w") as out:
        json.dump(truth, out, indent=1, default=float)
    return truth


def truth_beats_fixture(base, t, eol, extra):
    """The best fixture spring's cost minus the true model's, both as `eol gap` scores a fit.

    cost = sum rho(|r|^2), rho(u) = (nu + 2) ln(1 + 2 u / nu) (-2 ln L of the Student t for a
    sigma^2 on nu degrees of freedom; 2 u, the chi2, when nu = 0), with r in the residual form
    the report used: (Z_meas - Z) / sigma, or (1/Z_meas - 1/Z) |Z_meas|^2 / sigma on the lines
    it took in admittance form (the current channel's noise dominates there)."""
    with open(base + "-meas.csv") as src:  # comment lines and the header skipped
        rows = [ln for ln in src if ln.strip() and ln[0] not in "#f"]
    data = np.loadtxt(rows, delimiter=",", ndmin=2)
    if data.shape[1] < 4:
        return float("nan")  # no sigma in the file (stripped by a harness): no margin
    f, z, sigma = data[:, 0], data[:, 1] + 1j * data[:, 2], data[:, 3]
    cmd = [eol, "gap", "--sim", base + "-sim.csv", "--measured", base + "-meas.csv", "--json",
           "--effects", "fixture_compliance", "--no-pairs"] + extra
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    report = json.loads(p.stdout)
    z_true = impedance(t["motor"], f, t["effect"], t["params"])
    admittance = np.full(len(f), report["residual_form"] == "admittance")
    if report["residual_form"] == "mixed":  # per line: the lines the report lists
        admittance = np.isin(f, report["residual_admittance_hz"][0])
    r = np.where(admittance, (1.0 / z - 1.0 / z_true) * np.abs(z) ** 2 / sigma,
                 (z - z_true) / sigma)
    nu = float(report.get("sigma_dof") or 0.0)
    u = np.abs(r) ** 2
    cost_true = np.sum((nu + 2) * np.log1p(2 * u / nu)) if nu > 0 else np.sum(2 * u)
    fits = [r for r in report["ranking"] if r["effect"] == "fixture_compliance"]
    return fits[0]["cost"] - cost_true


def score(out_dir, eol, extra):
    with open(os.path.join(out_dir, "truth.json")) as f:
        truth = json.load(f)
    rows = []
    t0 = time.time()
    for t in truth:
        base = os.path.join(out_dir, t["case"])
        cmd = [eol, "gap", "--sim", base + "-sim.csv", "--measured", base + "-meas.csv",
               "--json"] + extra
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            answer = "error: " + p.stderr.strip().splitlines()[-1] if p.stderr else "error"
        else:
            answer = json.loads(p.stdout)["effect"]
        ok = answer in EXPECTED[t["effect"]]
        sub = t["effect"] + ("(" + t["params"]["at"] + ")" if "at" in t["params"] else "")
        separable, margin = t["separable"], float("nan")
        if t["effect"] == "coupled_inertia" and separable:
            margin = truth_beats_fixture(base, t, eol, extra)
            separable = math.isnan(margin) or bool(margin >= 10.0)
        rows.append((t["case"], sub, t["effect"], separable, t["strength"], answer, ok, margin))
    elapsed = time.time() - t0
    # margin: for a coupled inertia, the best fixture spring's cost minus the truth's.
    print("%-9s %-24s %5s %8s %7s  %-40s %s" % ("case", "hidden", "sep", "S", "margin", "answer",
                                                "ok"))
    for r in rows:
        margin = "" if math.isnan(r[7]) else "%.1f" % r[7]
        print("%-9s %-24s %5s %8.1f %7s  %-40s %s" % (r[0], r[1], r[3], r[4], margin, r[5],
                                                       "yes" if r[6] else "NO"))
    print("\nper hidden effect (separable cases named / separable; all cases named / all):")
    summary = {}
    for kind in sorted({r[2] for r in rows}):
        sep = [r for r in rows if r[2] == kind and r[3]]
        every = [r for r in rows if r[2] == kind]
        summary[kind] = (sum(r[6] for r in sep), len(sep))
        print("  %-22s %2d / %2d   (%2d / %2d)" % (kind, sum(r[6] for r in sep), len(sep),
                                                  sum(r[6] for r in every), len(every)))
    sep = [r for r in rows if r[3]]
    named = sum(r[6] for r in sep)
    print("separable named: %d / %d (%.1f %%); run time %.1f s" %
          (named, len(sep), 100.0 * named / max(1, len(sep)), elapsed))
    result = {"separable_named": named, "separable": len(sep), "per_effect": summary,
              "rows": [{"case": r[0], "hidden": r[1], "separable": r[3], "answer": r[5],
                        "ok": r[6], "margin": None if math.isnan(r[7]) else r[7]} for r in rows]}
    with open(os.path.join(out_dir, "score.json"), "w") as out:
        json.dump(result, out, indent=1)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--cases", type=int, default=70)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--s-lo", type=float, default=15.0)
    ap.add_argument("--s-hi", type=float, default=150.0)
    ap.add_argument("--plan", default="",
                    help="comma-separated hidden effects, cycled over the cases (default: PLAN)")
    ap.add_argument("--coupled", default=",".join("%g" % v for v in COUPLED),
                    help="coupled inertia draw: mu_lo,mu_hi,f2_lo,f2_hi (times f0),cap_hz "
                         "(0: none); default %(default)s")
    ap.add_argument("--fractional", default=",".join("%g" % v for v in FRACTIONAL),
                    help="fractional inductance's share of L: a_lo,a_hi in (0, 1]; "
                         "default %(default)s")
    ap.add_argument("--score", action="store_true", help="run `eol gap` on the cases")
    ap.add_argument("--eol", default="build/eol")
    ap.add_argument("extra", nargs="*", help="extra `eol gap` arguments (after --)")
    a = ap.parse_args()
    if a.score:
        score(a.out, a.eol, a.extra)
    else:
        plan = [p for p in a.plan.split(",") if p]
        for p in plan:
            if p not in EXPECTED:
                ap.error("--plan: unknown effect '%s' (known: %s)" % (p, ", ".join(EXPECTED)))
        try:
            coupled = tuple(float(v) for v in a.coupled.split(","))
        except ValueError:
            coupled = ()
        if len(coupled) != 5 or not (0 < coupled[0] <= coupled[1] and
                                     0 < coupled[2] <= coupled[3] and coupled[4] >= 0):
            ap.error("--coupled: want mu_lo,mu_hi,f2_lo,f2_hi,cap_hz with 0 < lo <= hi and "
                     "cap_hz >= 0, got '%s'" % a.coupled)
        try:
            fractional = tuple(float(v) for v in a.fractional.split(","))
        except ValueError:
            fractional = ()
        if len(fractional) != 2 or not 0 < fractional[0] <= fractional[1] <= 1:
            ap.error("--fractional: want a_lo,a_hi with 0 < a_lo <= a_hi <= 1, got '%s'"
                     % a.fractional)
        t = generate(a.out, a.cases, a.seed, a.s_lo, a.s_hi, plan, coupled, fractional)
        print("%d cases written to %s" % (len(t), a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
