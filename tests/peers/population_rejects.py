#!/usr/bin/python3
"""The teaching workflow of analysis/qc/README.md on independent populations: rejected units per class.

For each seed: independent_population.py writes a population (truth.csv says each unit's
class); `eol teach --recipe R --golden <the first --golden good units> --out taught.json`
learns limits; `eol analyze --measured unit.csv --recipe taught.json --json` judges every
other unit. A unit is rejected when its verdict is not PASS (FAIL, or ERROR / not
analysable: the station would not ship it either); the table says which.

Prints the table (class, units judged, rejected, FAIL, ERROR/unusable, lowest f0 of the
class) and, with --json FILE, writes the same as JSON for tests. With --hits FILE it writes
the per-unit hit/miss table (class, size = the truth's bond stiffness loss, hit, f0_hz) and
runs `eol pod --hits FILE --json` on it: POD(a) and a90/95 per defect class, fitted by eol
(analysis/qc/pod.h), printed and added to the JSON; --pod-svg FILE draws it with the taught
f0 lower limit. With --clamp-pressure every unit's clamp pressure (truth.csv, what the station
reads at clamp confirmation) goes with it, as on the station: the golden units are analysed
with `eol analyze --recipe R --json --clamp-pressure-bar P` and taught from those outputs (so
teach may normalise f0 by the pressure, analysis/qc/f0_pressure.h), and every judged unit gets
--clamp-pressure-bar P. Exit 0 when everything ran,
1 when teach failed (its stderr is printed), 2 on usage errors.
"""
import argparse
import concurrent.futures
import csv
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CLASSES = ("good", "one_soft", "three_soft", "all_soft")


def pressure_args(a, t):
    return ["--clamp-pressure-bar", t["clamp_pressure_bar"]] if a.clamp_pressure else []


def judge(eol, recipe, path, extra=()):
    r = subprocess.run([eol, "analyze", "--measured", path, "--recipe", recipe, "--json"]
                       + list(extra), capture_output=True, text=True)
    try:
        out = json.loads(r.stdout)
    except ValueError:
        return {"outcome": "UNUSABLE", "why": (r.stderr or r.stdout).strip()[:200]}
    if not out.get("usable", False):
        return {"outcome": "UNUSABLE", "why": out.get("error", "")}
    v = out.get("verdict", {})
    return {"outcome": v.get("outcome", "UNUSABLE"), "reasons": v.get("reasons", []),
            "f0_hz": out.get("resonance", {}).get("f_hz")}


def run_population(a, seed, workdir):
    pop = os.path.join(workdir, "pop-%d" % seed)
    counts = ["--good", str(a.golden + a.good), "--one-soft", str(a.one_soft),
              "--three-soft", str(a.three_soft), "--all-soft", str(a.all_soft),
              "--loss-lo", str(a.loss_lo), "--loss-hi", str(a.loss_hi)]
    if a.poor_loss_factor is not None:
        counts += ["--poor-loss-factor", str(a.poor_loss_factor)]
    counts += ["--motor", a.motor] + a.generator_arg
    subprocess.run([sys.executable, os.path.join(HERE, "independent_population.py"),
                    "--out", pop, "--seed", str(seed)] + counts, check=True)
    with open(os.path.join(pop, "truth.csv")) as f:
        truth = list(csv.DictReader(f))
    golden_rows = [t for t in truth if t["class"] == "good"][:a.golden]
    golden = [t["unit"] for t in golden_rows]
    golden_files = [os.path.join(pop, u + ".csv") for u in golden]
    if a.clamp_pressure:  # analysed as the station would, the pressure kept in the output
        golden_files = []
        for t in golden_rows:
            out = os.path.join(pop, t["unit"] + ".analyze.json")
            with open(out, "w") as f:
                subprocess.run([a.eol, "analyze", "--measured", os.path.join(pop, t["unit"] + ".csv"),
                                "--recipe", a.recipe, "--json"] + pressure_args(a, t),
                               stdout=f, check=True)
            golden_files.append(out)
    taught = os.path.join(pop, "taught.json")
    r = subprocess.run([a.eol, "teach", "--recipe", a.recipe, "--out", taught, "--json",
                        "--golden"] + golden_files
                       + a.teach_arg, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write("eol teach failed (seed %d): %s\n" % (seed, r.stderr))
        return None, None
    summary = json.loads(r.stdout)
    judged = [t for t in truth if t["unit"] not in set(golden)]
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
        verdicts = list(ex.map(lambda t: judge(a.eol, taught, os.path.join(pop, t["unit"] + ".csv"),
                                               pressure_args(a, t)),
                               judged))
    for t, v in zip(judged, verdicts):
        t.update(v)
    return summary, judged


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--eol", required=True, help="the eol binary")
    ap.add_argument("--recipe", required=True, help="recipe to teach (recipes/pmsm-10pole.json)")
    ap.add_argument("--seeds", default="1", help="comma-separated population seeds")
    ap.add_argument("--golden", type=int, default=40, help="good units taught from")
    ap.add_argument("--good", type=int, default=200, help="good units judged (besides golden)")
    ap.add_argument("--one-soft", type=int, default=20)
    ap.add_argument("--three-soft", type=int, default=20)
    ap.add_argument("--all-soft", type=int, default=20)
    ap.add_argument("--loss-lo", type=float, default=0.20,
                    help="smallest bond stiffness loss of a soft magnet (generator)")
    ap.add_argument("--loss-hi", type=float, default=0.99,
                    help="largest bond stiffness loss of a soft magnet (generator)")
    ap.add_argument("--poor-loss-factor", type=float,
                    help="loss factor of a soft bond (generator; default: the generator's)")
    ap.add_argument("--motor", default="pmsm-10pole",
                    help="the generator's motor type (independent_population.py --motor)")
    ap.add_argument("--generator-arg", action="append", default=[],
                    help="extra argument passed to independent_population.py (repeat)")
    ap.add_argument("--hits", help="write the per-unit hit/miss CSV here and fit POD with eol pod")
    ap.add_argument("--pod-svg", help="with --hits: the POD figure (eol pod --pod-svg)")
    ap.add_argument("--clamp-pressure", action="store_true",
                    help="give eol each unit's clamp pressure (see above)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--teach-arg", action="append", default=[],
                    help="extra argument passed to eol teach (repeat)")
    ap.add_argument("--workdir", help="keep populations here (default: a temporary directory)")
    ap.add_argument("--json", help="write the table as JSON to this file")
    a = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        workdir = a.workdir or tmp
        os.makedirs(workdir, exist_ok=True)
        rows, teach = [], []
        for seed in [int(s) for s in a.seeds.split(",")]:
            summary, judged = run_population(a, seed, workdir)
            if summary is None:
                return 1
            teach.append({"seed": seed, "message": summary.get("message"),
                          "limits": summary.get("limits"),
                          "expected_false_reject": summary.get("expected_false_reject"),
                          "f0_pressure": summary.get("f0_pressure")})
            rows += judged

    table = {}
    print("| class | judged | rejected | FAIL | ERROR/unusable | lowest f0 Hz |")
    print("|---|---|---|---|---|---|")
    for c in CLASSES:
        units = [t for t in rows if t["class"] == c]
        fail = sum(t["outcome"] == "FAIL" for t in units)
        err = sum(t["outcome"] not in ("PASS", "FAIL") for t in units)
        f0 = [t["f0_hz"] for t in units if t.get("f0_hz") is not None]
        table[c] = {"judged": len(units), "rejected": fail + err, "fail": fail, "error": err,
                    "lowest_f0_hz": min(f0) if f0 else None}
        print("| %s | %d | %d | %d | %d | %s |" % (c, len(units), fail + err, fail, err,
                                                  "%.1f" % min(f0) if f0 else "-"))
    for t in teach:
        print("teach seed %d: %s" % (t["seed"], t["message"]))
        if t.get("f0_pressure"):
            print("  clamp-pressure-normalised resonance: %s" % t["f0_pressure"].get("note"))
        for lim in t["limits"] or []:
            print("  %s: lo %s hi %s" % (lim.get("name"), lim.get("lo"), lim.get("hi")))
    pod = None
    if a.hits:
        with open(a.hits, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["class", "size", "hit", "f0_hz", "unit"])
            for t in rows:
                w.writerow([t["class"], t["defect_size"], 0 if t["outcome"] == "PASS" else 1,
                            "" if t.get("f0_hz") is None else "%.3f" % t["f0_hz"], t["unit"]])
        cmd = [a.eol, "pod", "--hits", a.hits, "--json"]
        if a.pod_svg:
            cmd += ["--pod-svg", a.pod_svg]
            for t in teach:
                for lim in t["limits"] or []:
                    if lim.get("name") == "resonance_f_hz" and lim.get("lo") is not None:
                        cmd += ["--f0-limit", str(lim["lo"])]
        r = subprocess.run(cmd, capture_output=True, text=True)
        try:
            pod = json.loads(r.stdout)["pod"]
        except (ValueError, KeyError):
            sys.stderr.write("eol pod failed: %s\n" % (r.stderr or r.stdout))
            return 1
        for cls, fit in pod.items():
            print("POD %s: %s" % (cls, fit.get("message")))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"table": table, "teach": teach, "pod": pod,
                       "units": [{k: t.get(k) for k in ("unit", "class", "outcome", "f0_hz",
                                                        "first_mode_hz", "defect_size")}
                                 for t in rows]},
                      f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
