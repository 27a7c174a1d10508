#!/usr/bin/python3
"""The information limit beside the taught recipe: what supervised rules do with labelled units
of the independent generator, and what the station's taught recipe does with the same units,
per defect class.

1. Training: independent_population.py draws --train-good good units and --per-class units of
   each defect class (seed --train-seed, stiffness losses --loss-lo..--loss-hi); with
   --raw WAVE as raw recordings of the voltage in WAVE (independent_population.py --raw).
2. The recipe: population_rejects.py teaches --recipe from the first 40 good units of a second
   population (seed --test-seed, raw too with --raw) and judges the rest of it with
   `eol analyze` (--eol).
3. The rules, trained on the training population, each judging the same test units as the
   recipe (golden ones left out), per defect class:
   curve_qda  the full measured curve (Re Z and Im Z on every line; from a raw recording the
              DFT of its last period, U / I, computed here), standardised by the good training
              units' mean and std per line, projected on the --components leading principal
              components; the likelihood ratio of two normals fitted to the good and the
              class's units (covariances shrunk by 1e-3 of their mean variance);
   feat_qda   the same on the fitted features of `eol analyze --json --recipe R` (f0, Q, Rp, R,
              L, log second_mode_chi2_drop, log fit_chi2_per_dof; --features, raw or FRF);
   feat_kde   a normal for the good units against a kernel density of the class's units
              (Gaussian kernels of the good units' covariance times h^2, h = n^(-1/(d+4))) on
              the features: a nonlinear rule for a class spread along a curve;
   feat_outlier  the good units' normal alone on the features (how unlikely a unit is as a
              good one; the class's units are not used);
   curve_spe_qda  QDA on the curve's components and its log SPE: the squared residual outside
              the good units' leading --components (each line scaled by the good units'
              residual std there; a soft magnet's own mode at any frequency leaves one);
   feat_spe_qda, feat_spe_kde  the features and the curve's log SPE, QDA and kernel density;
   both_qda   QDA on the features, the log SPE and the curve's leading 8 components.
   Each rule's threshold is the (1 - budget) quantile of the good training units' held-out
   scores (5-fold: each scored by the rule fitted without its fold; the false-reject budget,
   default 0.3 %). A unit eol cannot analyse counts as rejected by the feature rules. The
   measured limit of a class is the rule that detects most of the class's held-out training
   units (chosen on training, so the test count is not selected on itself); when the taught
   recipe detects more on test, the recipe is the lower bound of the limit and the table says
   so.
Prints one table (class, test units, rejected by the recipe, by each rule, the limit and the
recipe's distance to it) and the good units' false rejects; --json FILE writes it; --cache
FILE.npz keeps what was measured (a second run with it judges again without drawing). Needs
python3-numpy and the eol binary. Run it with /usr/bin/python3 (Debian's numpy).
"""
import argparse
import concurrent.futures
import csv
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFECTS = ("one_soft", "three_soft", "all_soft")


def unit_curve(path, raw):
    """Re Z then Im Z on the excited lines: an FRF file's, or the last period's DFT of a raw one."""
    if not raw:
        data = np.loadtxt(path, delimiter=",", skiprows=1)
        return np.concatenate([data[:, 1], data[:, 2]])
    u, i, period = raw_channels(path, raw)
    uf, jf = np.fft.rfft(u[-period:]), np.fft.rfft(i[-period:])
    z = uf[raw["bins"]] / jf[raw["bins"]]
    return np.concatenate([z.real, z.imag])


def raw_channels(path, raw):
    with open(path) as f:
        head = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, head.index("u_v")], data[:, head.index("i_a")], raw["period"]


def excitation_of(wave):
    """The played waveform's period (samples) and excited DFT bins (the generator reads it too)."""
    u = np.loadtxt(wave, delimiter=",", skiprows=1, usecols=1)
    n = u.size
    for period in (p for p in range(2, n + 1) if n % p == 0):
        if np.allclose(u[period:], u[:n - period], rtol=0.0, atol=1e-9 * np.abs(u).max()):
            break
    spec = np.abs(np.fft.rfft(u[:period]))
    bins = np.nonzero(spec > 1e-9 * spec.max())[0]
    return {"period": period, "bins": bins[bins > 0]}


FEATURES = ("f0_hz", "Q", "Rp_ohm", "R_ohm", "L_h")
LOG_FEATURES = ("second_mode_chi2_drop", "fit_chi2_per_dof")


def unit_features(eol, recipe, path):
    """The fitted features of `eol analyze --json` (NaN when eol cannot analyse the unit)."""
    r = subprocess.run([eol, "analyze", "--measured", path, "--recipe", recipe, "--json"],
                       capture_output=True, text=True)
    try:
        out = json.loads(r.stdout)
        values = [out["params"][k]["value"] for k in FEATURES]
        meas = {m["name"]: m["value"] for m in out["verdict"]["measurements"]}
        values += [np.log(max(meas[k], 1e-3)) for k in LOG_FEATURES]
        return np.array(values, dtype=float)
    except (ValueError, KeyError, TypeError):
        return np.full(len(FEATURES) + len(LOG_FEATURES), np.nan)


def read_population(a, directory, raw, skip=()):
    """Curves, features (or None) and classes of a generator's output directory."""
    with open(os.path.join(directory, "truth.csv")) as f:
        truth = [t for t in csv.DictReader(f) if t["unit"] not in skip]
    paths = [os.path.join(directory, t["unit"] + ".csv") for t in truth]
    curves = np.array([unit_curve(p, raw) for p in paths])
    features = None
    if a.features:
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
            features = np.array(list(ex.map(lambda p: unit_features(a.eol, a.recipe, p), paths)))
    return curves, features, np.array([t["class"] for t in truth])


def draw(a, seed, good, per_class, out):
    subprocess.run([sys.executable, os.path.join(HERE, "independent_population.py"), "--motor",
                    a.motor, "--out", out, "--seed", str(seed), "--good", str(good),
                    "--one-soft", str(per_class), "--three-soft", str(per_class), "--all-soft",
                    str(per_class), "--loss-lo", str(a.loss_lo), "--loss-hi", str(a.loss_hi)]
                   + (["--raw", a.raw] if a.raw else []), check=True)


def taught_from(a, workdir):
    """The recipe teach starts from: --recipe, or with --design-slack a copy whose
    excitation_design.sigma_f0_hz is that factor larger (a design requirement only: eol teach
    moves the design's nominal to the golden units and keeps the requirement, so a taught
    recipe whose good units ring at a lower Q than the design's nominal is refused at load)."""
    if a.design_slack == 1.0:
        return a.recipe
    with open(a.recipe) as f:
        recipe = json.load(f)
    recipe["excitation_design"]["sigma_f0_hz"] *= a.design_slack
    path = os.path.join(workdir, "recipe-design-slack.json")
    os.makedirs(workdir, exist_ok=True)
    with open(path, "w") as f:
        json.dump(recipe, f, indent=1)
    return path


def recipe_column(a, workdir):
    """population_rejects.py on the test seed: its JSON, and the golden units it taught from."""
    out = os.path.join(workdir, "rejects.json")
    raw = ["--generator-arg=--raw", "--generator-arg=" + a.raw] if a.raw else []
    subprocess.run([sys.executable, os.path.join(HERE, "population_rejects.py"), "--eol", a.eol,
                    "--recipe", taught_from(a, workdir), "--motor", a.motor, "--seeds", str(a.test_seed),
                    "--golden", "40", "--good", str(a.test_good), "--one-soft", str(a.per_class),
                    "--three-soft", str(a.per_class), "--all-soft", str(a.per_class),
                    "--loss-lo", str(a.loss_lo), "--loss-hi", str(a.loss_hi), "--jobs",
                    str(a.jobs), "--workdir", workdir, "--json", out] + raw, check=True,
                   stdout=subprocess.DEVNULL)
    with open(out) as f:
        return json.load(f)


def fit_projection(x_train, good_mask, components):
    mu, sd = x_train[good_mask].mean(axis=0), x_train[good_mask].std(axis=0) + 1e-12
    z = (x_train - mu) / sd
    centre = z.mean(axis=0)
    _, _, vt = np.linalg.svd(z - centre, full_matrices=False)
    basis = vt[:components].T
    return lambda x: ((x - mu) / sd - centre) @ basis


def shrunk_cov(p):
    cov = np.atleast_2d(np.cov(p.T))
    return cov + 1e-3 * np.trace(cov) / cov.shape[0] * np.eye(cov.shape[0])


def gaussian_log_density(p):
    """The log density of a normal fitted to the rows of p (covariance shrunk by 1e-3)."""
    mu, cov = p.mean(axis=0), shrunk_cov(p)
    inv = np.linalg.inv(cov)
    _, logdet = np.linalg.slogdet(cov)
    return lambda x: -0.5 * (np.einsum("ij,jk,ik->i", x - mu, inv, x - mu) + logdet)


def kde_log_density(p, cov):
    """Log of a Gaussian kernel density on the rows of p, kernel covariance h^2 cov."""
    h = p.shape[0] ** (-1.0 / (p.shape[1] + 4))
    chol = np.linalg.cholesky(h * h * cov)
    white = np.linalg.solve(chol, p.T).T

    def density(x):
        d2 = ((np.linalg.solve(chol, x.T).T[:, None, :] - white[None, :, :]) ** 2).sum(axis=2)
        m = (-0.5 * d2).max(axis=1)
        return m + np.log(np.exp(-0.5 * d2 - m[:, None]).mean(axis=1))
    return density


def fit_rule(kind, p_good, p_class):
    """A score, higher: more like the class."""
    good = gaussian_log_density(p_good)
    if kind == "outlier":
        return lambda x: -good(x)
    if kind == "kde":
        cls = kde_log_density(p_class, shrunk_cov(p_good))
    else:
        cls = gaussian_log_density(p_class)
    return lambda x: cls(x) - good(x)


def held_out_scores(kind, p_good, p_class, folds=5):
    """Every training unit scored by the rule fitted without its fold."""
    out_g, out_c = np.empty(len(p_good)), np.empty(len(p_class))
    fg, fc = np.arange(len(p_good)) % folds, np.arange(len(p_class)) % folds
    for k in range(folds):
        score = fit_rule(kind, p_good[fg != k], p_class[fc != k])
        out_g[fg == k], out_c[fc == k] = score(p_good[fg == k]), score(p_class[fc == k])
    return out_g, out_c


def judge_rule(kind, train, c_train, test, c_test, cls, budget):
    """Held-out training detection, test detections and false rejects of one rule."""
    ok = np.all(np.isfinite(train), axis=1)
    p_good, p_class = train[ok & (c_train == "good")], train[ok & (c_train == cls)]
    out_g, out_c = held_out_scores(kind, p_good, p_class)
    threshold = np.quantile(out_g, 1.0 - budget)
    score = fit_rule(kind, p_good, p_class)
    finite = np.all(np.isfinite(test), axis=1)
    hit = np.ones(len(test), dtype=bool)  # a unit eol cannot analyse is rejected
    hit[finite] = score(test[finite]) > threshold
    return {"train_detect": float(np.mean(out_c > threshold)),
            "hits": hit[c_test == cls], "good_hits": hit[c_test == "good"]}


def fit_residual(x_good, components):
    """log SPE: the squared residual of a curve outside the good units' leading principal
    components, each line scaled by the good units' residual std there (an anomaly anywhere on
    the curve: a soft magnet's own mode at any frequency)."""
    mu, sd = x_good.mean(axis=0), x_good.std(axis=0) + 1e-12
    z = (x_good - mu) / sd
    _, _, vt = np.linalg.svd(z, full_matrices=False)
    basis = vt[:components].T

    def residual(x):
        zz = (x - mu) / sd
        return zz - (zz @ basis) @ basis.T
    scale = residual(x_good).std(axis=0) + 1e-12
    return lambda x: np.log(((residual(x) / scale) ** 2).sum(axis=1, keepdims=True))


def residual_scores(x_train, good, x_test, components, folds=5):
    """log SPE of every unit; the good training units' each from a fit without its fold (an
    in-sample residual is smaller than a new unit's)."""
    spe = fit_residual(x_train[good], components)
    q_train, q_test = spe(x_train), spe(x_test)
    index = np.nonzero(good)[0]
    fold = np.arange(index.size) % folds
    for k in range(folds):
        q_train[index[fold == k]] = fit_residual(x_train[index[fold != k]],
                                                 components)(x_train[index[fold == k]])
    return q_train, q_test


def rule_inputs(a, train, test):
    """name -> (rule kind, training matrix, test matrix)."""
    (x_train, f_train, c_train), (x_test, f_test, _) = train, test
    project = fit_projection(x_train, c_train == "good", a.components)
    p_train, p_test = project(x_train), project(x_test)
    q_train, q_test = residual_scores(x_train, c_train == "good", x_test, a.components)
    rules = {"curve_qda": ("qda", p_train, p_test),
             "curve_spe_qda": ("qda", np.hstack([p_train, q_train]), np.hstack([p_test, q_test]))}
    if f_train is not None:
        good = f_train[(c_train == "good") & np.all(np.isfinite(f_train), axis=1)]
        mu, sd = good.mean(axis=0), good.std(axis=0) + 1e-30
        s_train, s_test = (f_train - mu) / sd, (f_test - mu) / sd
        rules["feat_qda"] = ("qda", s_train, s_test)
        rules["feat_kde"] = ("kde", s_train, s_test)
        rules["feat_outlier"] = ("outlier", s_train, s_test)
        rules["feat_spe_qda"] = ("qda", np.hstack([s_train, q_train]),
                                 np.hstack([s_test, q_test]))
        rules["feat_spe_kde"] = ("kde", np.hstack([s_train, q_train]),
                                 np.hstack([s_test, q_test]))
        rules["both_qda"] = ("qda", np.hstack([s_train, q_train, p_train[:, :8]]),
                             np.hstack([s_test, q_test, p_test[:, :8]]))
    return rules


def class_rows(a, rules, c_train, c_test, rejects):
    rows, flagged = {}, {}
    for cls in DEFECTS:
        row = {"recipe": rejects["table"][cls]["rejected"], "rules": {}}
        for name, (kind, tr, te) in rules.items():
            r = judge_rule(kind, tr, c_train, te, c_test, cls, a.budget)
            row["units"] = int(r["hits"].size)
            row["rules"][name] = {"rejected": int(r["hits"].sum()),
                                  "train_detect": round(r["train_detect"], 4),
                                  "good_rejected": int(r["good_hits"].sum())}
            flagged[name] = flagged.get(name, False) | r["good_hits"]
        best = max(row["rules"], key=lambda n: row["rules"][n]["train_detect"])
        row["limit_rule"], row["limit"] = best, row["rules"][best]["rejected"]
        row["recipe_is_lower_bound"] = row["recipe"] > row["limit"]
        row["limit"] = max(row["limit"], row["recipe"])
        row["distance"] = row["limit"] - row["recipe"]
        rows[cls] = row
    good = {"units": int(np.sum(c_test == "good")), "recipe": rejects["table"]["good"]["rejected"],
            "rules": {n: int(np.sum(f)) for n, f in flagged.items()}}
    return rows, good


def print_table(a, rows, good):
    names = list(good["rules"])
    print("| class (loss %.2f-%.2f) | test units | taught recipe | %s | limit (rule) | distance |"
          % (a.loss_lo, a.loss_hi, " | ".join(names)))
    print("|---" * (5 + len(names)) + "|")
    for cls, r in rows.items():
        chosen = r["rules"][r["limit_rule"]]
        limit = ("%d (recipe: lower bound; best rule %s %d)"
                 % (r["limit"], r["limit_rule"], chosen["rejected"])
                 if r["recipe_is_lower_bound"] else "%d (%s, %d good rejected)"
                 % (r["limit"], r["limit_rule"], chosen["good_rejected"]))
        print("| %s | %d | %d | %s | %s | %d |" % (
            cls, r["units"], r["recipe"],
            " | ".join("%d" % r["rules"][n]["rejected"] for n in names), limit, r["distance"]))
    print("| good: false rejects | %d | %d | %s | | |" % (
        good["units"], good["recipe"], " | ".join("%d" % good["rules"][n] for n in names)))
    print("(a rule's good row counts a unit any of its three class thresholds flags, each at the "
          "%g budget; the limit is the rule with the best held-out training detection)"
          % a.budget)


def measure_populations(a):
    """(curves, features, classes) of the training and the judged test units, and the recipe's
    rejects."""
    raw = excitation_of(a.raw) if a.raw else None
    with tempfile.TemporaryDirectory() as tmp:
        draw(a, a.train_seed, a.train_good, a.per_class, os.path.join(tmp, "train"))
        rejects = recipe_column(a, os.path.join(tmp, "test"))
        pop = os.path.join(tmp, "test", "pop-%d" % a.test_seed)
        with open(os.path.join(pop, "truth.csv")) as f:
            golden = [t["unit"] for t in csv.DictReader(f) if t["class"] == "good"][:40]
        train = read_population(a, os.path.join(tmp, "train"), raw)
        test = read_population(a, pop, raw, skip=set(golden))
    return train, test, rejects


def save_cache(path, train, test, rejects):
    arrays = {}
    for name, (x, f, c) in (("train", train), ("test", test)):
        arrays.update({name + "_x": x, name + "_c": c})
        if f is not None:
            arrays[name + "_f"] = f
    np.savez(path, rejects=json.dumps(rejects), **arrays)


def load_cache(path):
    d = np.load(path)
    pops = [(d[n + "_x"], d[n + "_f"] if n + "_f" in d else None, d[n + "_c"])
            for n in ("train", "test")]
    return pops[0], pops[1], json.loads(str(d["rejects"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--eol", required=True)
    ap.add_argument("--recipe", required=True)
    ap.add_argument("--motor", default="pmsm-10pole")
    ap.add_argument("--raw", metavar="WAVE", help="raw recordings of this played voltage "
                    "(independent_population.py --raw; WAVE from eol simulate --format recording)")
    ap.add_argument("--features", action="store_true",
                    help="also the rules on eol analyze's fitted features")
    ap.add_argument("--train-seed", type=int, default=901)
    ap.add_argument("--test-seed", type=int, default=902)
    ap.add_argument("--train-good", type=int, default=1000)
    ap.add_argument("--test-good", type=int, default=300)
    ap.add_argument("--per-class", type=int, default=100)
    ap.add_argument("--loss-lo", type=float, default=0.8)
    ap.add_argument("--loss-hi", type=float, default=0.99)
    ap.add_argument("--components", type=int, default=15)
    ap.add_argument("--budget", type=float, default=0.003)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--design-slack", type=float, default=1.0,
                    help="teach from a copy of --recipe with excitation_design.sigma_f0_hz times "
                    "this (see taught_from; 1: the recipe as it is)")
    ap.add_argument("--cache", help="keep the measured curves, features and the recipe's rejects "
                    "in this .npz; when it exists, judge from it instead of drawing again")
    ap.add_argument("--json")
    a = ap.parse_args()
    if a.cache and os.path.exists(a.cache):
        train, test, rejects = load_cache(a.cache)
    else:
        train, test, rejects = measure_populations(a)
        if a.cache:
            save_cache(a.cache, train, test, rejects)
    rows, good = class_rows(a, rule_inputs(a, train, test), train[2], test[2], rejects)
    print_table(a, rows, good)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"motor": a.motor, "recipe": a.recipe, "raw": bool(a.raw),
                       "budget": a.budget, "rows": rows, "good": good}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
