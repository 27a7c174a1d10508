#!/usr/bin/python3
"""The information limit beside the taught recipe: what the best linear rule does
with labelled units of the independent generator, and what the station's taught recipe does
with the same units, per defect class.

1. Training: independent_population.py draws --train-good good units and --per-class units of
   each defect class (seed --train-seed, stiffness losses --loss-lo..--loss-hi).
2. The recipe: population_rejects.py teaches --recipe from the first 40 good units of a second
   population (seed --test-seed) and judges the rest of it with `eol analyze` (--eol).
3. The classifier, on the full measured curve (Re Z and Im Z on every line, standardised by
   the good training units' mean and std per line, projected on the --components leading
   principal components of the training set), per defect class: --rule qda (default) the
   likelihood ratio of two normals fitted to the good and the class's training units
   (covariances shrunk by 1e-3 of their mean variance), its threshold the (1 - budget)
   quantile of the good training units' ratios (the false-reject budget, default 0.3 %);
   --rule lda Fisher's discriminant w = (S_good + S_class)^-1 (m_class - m_good), threshold
   mean + z(1 - budget) std of the good training scores. It judges the same test units as the
   recipe (golden ones left out).
Prints one table (class, test units, rejected by the recipe, rejected by the classifier) and the
good units' false rejects of both; --json FILE writes it. Needs python3-numpy and the eol binary.
Supervised and linear: a lower bound on what labelled units allow, an upper reference for a
recipe taught from good units alone.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFECTS = ("one_soft", "three_soft", "all_soft")
Z_ONE_SIDED = {0.003: 2.7478, 0.005: 2.5758, 0.001: 3.0902}


def read_population(directory, skip=()):
    """Curves (n x 2 lines: Re then Im) and classes of a generator's output directory."""
    with open(os.path.join(directory, "truth.csv")) as f:
        truth = [t for t in csv.DictReader(f) if t["unit"] not in skip]
    curves = []
    for t in truth:
        data = np.loadtxt(os.path.join(directory, t["unit"] + ".csv"), delimiter=",", skiprows=1)
        curves.append(np.concatenate([data[:, 1], data[:, 2]]))
    return np.array(curves), np.array([t["class"] for t in truth]), truth


def draw(a, seed, good, per_class, out):
    subprocess.run([sys.executable, os.path.join(HERE, "independent_population.py"), "--motor",
                    a.motor, "--out", out, "--seed", str(seed), "--good", str(good),
                    "--one-soft", str(per_class), "--three-soft", str(per_class), "--all-soft",
                    str(per_class), "--loss-lo", str(a.loss_lo), "--loss-hi", str(a.loss_hi)],
                   check=True)


def recipe_column(a, workdir):
    """population_rejects.py on the test seed: its JSON, and the golden units it taught from."""
    out = os.path.join(workdir, "rejects.json")
    subprocess.run([sys.executable, os.path.join(HERE, "population_rejects.py"), "--eol", a.eol,
                    "--recipe", a.recipe, "--motor", a.motor, "--seeds", str(a.test_seed),
                    "--golden", "40", "--good", str(a.test_good), "--one-soft", str(a.per_class),
                    "--three-soft", str(a.per_class), "--all-soft", str(a.per_class),
                    "--loss-lo", str(a.loss_lo), "--loss-hi", str(a.loss_hi), "--jobs",
                    str(a.jobs), "--workdir", workdir, "--json", out], check=True,
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


def gaussian_log_density(p):
    """The log density of a normal fitted to the rows of p (covariance shrunk by 1e-3)."""
    mu = p.mean(axis=0)
    cov = np.cov(p.T)
    cov += 1e-3 * np.trace(cov) / cov.shape[0] * np.eye(cov.shape[0])
    inv = np.linalg.inv(cov)
    _, logdet = np.linalg.slogdet(cov)
    return lambda x: -0.5 * (np.einsum("ij,jk,ik->i", x - mu, inv, x - mu) + logdet)


def discriminant(p_good, p_class, budget, rule):
    """A score (higher: more like the class) and its threshold at the budget."""
    if rule == "qda":  # the likelihood ratio of two fitted normals
        good, cls = gaussian_log_density(p_good), gaussian_log_density(p_class)
        score = lambda x: cls(x) - good(x)
        return score, np.quantile(score(p_good), 1.0 - budget)
    cov = np.cov(p_good.T) + np.cov(p_class.T)
    cov += 1e-3 * np.trace(cov) / cov.shape[0] * np.eye(cov.shape[0])
    w = np.linalg.solve(cov, p_class.mean(axis=0) - p_good.mean(axis=0))
    s = p_good @ w
    return (lambda x: x @ w), s.mean() + Z_ONE_SIDED[budget] * s.std(ddof=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--eol", required=True)
    ap.add_argument("--recipe", required=True)
    ap.add_argument("--motor", default="pmsm-10pole")
    ap.add_argument("--train-seed", type=int, default=901)
    ap.add_argument("--test-seed", type=int, default=902)
    ap.add_argument("--train-good", type=int, default=1000)
    ap.add_argument("--test-good", type=int, default=300)
    ap.add_argument("--per-class", type=int, default=100)
    ap.add_argument("--loss-lo", type=float, default=0.8)
    ap.add_argument("--loss-hi", type=float, default=0.99)
    ap.add_argument("--components", type=int, default=15)
    ap.add_argument("--rule", choices=("qda", "lda"), default="qda")
    ap.add_argument("--budget", type=float, default=0.003, choices=sorted(Z_ONE_SIDED))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        draw(a, a.train_seed, a.train_good, a.per_class, os.path.join(tmp, "train"))
        rejects = recipe_column(a, os.path.join(tmp, "test"))
        pop = os.path.join(tmp, "test", "pop-%d" % a.test_seed)
        with open(os.path.join(pop, "truth.csv")) as f:
            golden = [t["unit"] for t in csv.DictReader(f) if t["class"] == "good"][:40]
        x_train, c_train, _ = read_population(os.path.join(tmp, "train"))
        x_test, c_test, _ = read_population(pop, skip=set(golden))
    project = fit_projection(x_train, c_train == "good", a.components)
    p_train, p_test = project(x_train), project(x_test)
    flagged_good = np.zeros(int((c_test == "good").sum()), dtype=bool)
    rows = {}
    for cls in DEFECTS:
        score, threshold = discriminant(p_train[c_train == "good"], p_train[c_train == cls],
                                        a.budget, a.rule)
        hit = score(p_test[c_test == cls]) > threshold
        flagged_good |= score(p_test[c_test == "good"]) > threshold
        rows[cls] = {"units": int(hit.size), "classifier": int(hit.sum()),
                     "recipe": rejects["table"][cls]["rejected"]}
    rows["good"] = {"units": int(flagged_good.size), "classifier": int(flagged_good.sum()),
                    "recipe": rejects["table"]["good"]["rejected"]}
    print("| class (loss %.2f-%.2f) | test units | rejected by the taught recipe | rejected by the "
          "classifier |" % (a.loss_lo, a.loss_hi))
    print("|---|---|---|---|")
    for cls, r in rows.items():
        print("| %s | %d | %d | %d |" % (cls, r["units"], r["recipe"], r["classifier"]))
    print("(good: false rejects; the classifier's good row counts a unit any of the three "
          "discriminants flags, each set at the %g budget)" % a.budget)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"motor": a.motor, "budget": a.budget, "rows": rows}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
