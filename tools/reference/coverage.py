"""Monte Carlo coverage of 95 % intervals on the bundled walking designs (issue 18, done-when:
why the analytic intervals and the subject bootstrap disagree, and which to trust).

The walking rows of data/*.csv come from 9–10 subjects, one of whom contributes 252 of 295
rows. On those exact designs (the rows' inputs and subjects), responses are drawn from a
random-intercept model y = Xβ + u_g + e, u_g ~ N(0, σ_u²), e ~ N(0, σ_e²), with β, σ_u and σ_e
estimated from the data (β by OLS; σ_e from the within-subject residuals, σ_u from the
subjects' mean residuals, method of moments). For each draw the script forms three 95 %
intervals for every coefficient and records whether they cover the true β:

- CR1 (statsmodels `cov_type='cluster'`, t with G − 1 df): gaitfit's `--se cluster`;
- CR2 with Bell–McCaffrey degrees of freedom (Imbens & Kolesár 2016): gaitfit's `--se cr2`;
- the pairs cluster (subject) bootstrap percentile interval, B replicates: gaitfit's
  `--bootstrap`.

Nothing here reads gaitfit's output. Run: /work/venv/bin/python tools/reference/coverage.py
(writes tools/reference/coverage.json; a few minutes).
"""
import os

import numpy as np
import scipy
import scipy.stats
import statsmodels
import statsmodels.api as sm

from common import bm_df, bundled, cr2, rows, subject_codes, write_json

OUT = os.path.join(os.path.dirname(__file__), "coverage.json")
REPS = 400
BOOT = 399
SEED = 20261207


def components(x, y, g):
    """β (OLS), σ_e (pooled within-subject residual SD) and σ_u (SD of the subjects' mean
    residuals less their sampling part), method of moments."""
    beta = np.linalg.lstsq(x, y, rcond=None)[0]
    e = y - x @ beta
    G = g.max() + 1
    within, dfw, means, sizes = 0.0, 0, [], []
    for c in range(G):
        ec = e[g == c]
        within += ((ec - ec.mean()) ** 2).sum()
        dfw += len(ec) - 1
        means.append(ec.mean())
        sizes.append(len(ec))
    s2e = within / dfw
    means, sizes = np.array(means), np.array(sizes)
    s2u = max(means.var(ddof=1) - s2e * np.mean(1.0 / sizes), 0.0)
    return beta, np.sqrt(s2e), np.sqrt(s2u)


def run(name, x, y, g, rng):
    n, p = x.shape
    G = int(g.max() + 1)
    beta, se, su = components(x, y, g)
    sizes = np.bincount(g)
    # Per-cluster cross-products for the bootstrap (a replicate is a weighted sum of them).
    xx = np.array([x[g == c].T @ x[g == c] for c in range(G)])
    cover = {"cr1": np.zeros(p), "cr2_bm": np.zeros(p), "bootstrap": np.zeros(p)}
    width = {k: np.zeros(p) for k in cover}
    dfs = np.zeros(p)
    t1 = scipy.stats.t.ppf(0.975, G - 1)
    for _ in range(REPS):
        yy = x @ beta + su * rng.standard_normal(G)[g] + se * rng.standard_normal(n)
        fit = sm.OLS(yy, x).fit()
        b = fit.params
        cl = sm.OLS(yy, x).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
        s1 = cl.bse
        v2, adj, m = cr2(x, fit.resid, g)
        s2 = np.sqrt(np.diag(v2))
        for j in range(p):
            ell = np.eye(p)[j]
            d = bm_df(x, g, adj, m, ell)
            dfs[j] += d
            t2 = scipy.stats.t.ppf(0.975, d)
            for key, lo, hi in (
                ("cr1", b[j] - t1 * s1[j], b[j] + t1 * s1[j]),
                ("cr2_bm", b[j] - t2 * s2[j], b[j] + t2 * s2[j]),
            ):
                cover[key][j] += lo <= beta[j] <= hi
                width[key][j] += hi - lo
        xy = np.array([x[g == c].T @ yy[g == c] for c in range(G)])
        counts = rng.multinomial(G, np.full(G, 1.0 / G), size=BOOT)
        reps = []
        for w in counts:
            a = np.tensordot(w, xx, axes=1)
            r = w @ xy
            try:
                reps.append(np.linalg.solve(a, r))
            except np.linalg.LinAlgError:
                pass
        reps = np.array(reps)
        lo, hi = np.percentile(reps, [2.5, 97.5], axis=0)
        for j in range(p):
            cover["bootstrap"][j] += lo[j] <= beta[j] <= hi[j]
            width["bootstrap"][j] += hi[j] - lo[j]
    mc = np.sqrt(0.95 * 0.05 / REPS)
    return {
        "n": int(n),
        "clusters": G,
        "largest_cluster_rows": int(sizes.max()),
        "beta": list(beta),
        "sigma_e": float(se),
        "sigma_u": float(su),
        "coverage": {k: list(v / REPS) for k, v in cover.items()},
        "mean_width": {k: list(v / REPS) for k, v in width.items()},
        "mean_bm_df": list(dfs / REPS),
        "monte_carlo_se_of_coverage": float(mc),
    }


def main():
    rng = np.random.default_rng(SEED)
    df = bundled()
    out = {
        "source": "Monte Carlo on the bundled walking designs, random-intercept model; "
        "statsmodels CR1 (cov_type='cluster', use_t), dense CR2 + Bell–McCaffrey df "
        "(common.py), pairs cluster bootstrap percentile intervals",
        "script": "tools/reference/coverage.py",
        "reps": REPS,
        "bootstrap_replicates": BOOT,
        "seed": SEED,
        "versions": {"statsmodels": statsmodels.__version__, "numpy": np.__version__,
                     "scipy": scipy.__version__},
    }
    d = rows(df, "walk", ["sl", "sf", "h"])
    g, _ = subject_codes(d.subject)
    out["walk-sl-sf"] = run("walk-sl-sf", (d.sf.values * 60.0 * d.h.values)[:, None],
                            d.sl.values, g, rng)
    d = rows(df, "walk", ["sf", "ds_pct"])
    g, _ = subject_codes(d.subject)
    out["walk-tds-sf"] = run("walk-tds-sf",
                             np.column_stack([np.ones(len(d)), d.sf.values * 60.0]),
                             d.ds_pct.values, g, rng)
    write_json(out, OUT)


if __name__ == "__main__":
    main()
