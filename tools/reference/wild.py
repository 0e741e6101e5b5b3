"""Reference wild cluster bootstrap-t (Webb six-point weights, unrestricted) for
`tests/reference_inference.rs` (wild_cluster_bootstrap_matches_the_numpy_enumeration), and the CR2 / Bell–McCaffrey intervals it is compared with.

Data: the bundled trials tables `data/*.csv` (committed), read as gaitfit reads them
(`common.py`). Relations: the two linear in every coefficient with no breakpoint, bound or
per-subject column (walk-sl-sf: sl = k·sf·h through the origin; walk-tds-sf: ds% = d0 + d1·sf).

Method, written from the definitions (MacKinnon & Webb 2017; Webb 2023): OLS β̂, residuals û.
A bootstrap sample is y* = Xβ̂ + w_g û_g, one weight per subject from {±√(1/2), ±1, ±√(3/2)}
(each 1/6). Each sample is refitted and studentised by its own CR1 standard error
(statsmodels' small-sample factor G/(G−1)·(n−1)/(n−p)): t* = (β*_k − β̂_k)/SE*_k. Every one of
the 6^G weight patterns is evaluated (G = 10 and 9 here): the distribution of t* is exact, no
Monte Carlo error. Quantiles are order statistics (numpy `inverted_cdf`); the percentile-t
interval is [β̂ − q*_.975·SE, β̂ − q*_.025·SE] with SE the CR1 standard error of the data.

The enumeration uses the closed form of a refit (β* − β̂ = (XᵀX)⁻¹Xᵀ(w∘û) and the sample's
cluster scores X_gᵀ(y*_g − X_gβ*)), vectorised over patterns; 200 random patterns are also
refitted from scratch with statsmodels (OLS, cov_type='cluster') and must give the same t*
(checked here, 1e-9). Nothing here reads gaitfit's output.

Run: /work/venv/bin/python tools/reference/wild.py  (writes tools/reference/wild.json; ~1 min,
~1 GB for the 6^10 values of walk-sl-sf)
"""
import os

import numpy as np
import scipy.stats
import statsmodels
import statsmodels.api as sm

from common import bm_df, bundled, cr2, rows, subject_codes, write_json

OUT = os.path.join(os.path.dirname(__file__), "wild.json")
WEBB = np.array([-np.sqrt(1.5), -1.0, -np.sqrt(0.5), np.sqrt(0.5), 1.0, np.sqrt(1.5)])
CHUNK_DIGITS = 6  # patterns evaluated 6^6 at a time


def t_stats(x, y, g, w):
    """t* of every coefficient for weight patterns `w` (patterns × G): refit + CR1, closed form."""
    n, p = x.shape
    G = g.max() + 1
    xtx_inv = np.linalg.inv(x.T @ x)
    beta = xtx_inv @ x.T @ y
    e = y - x @ beta
    c1 = G / (G - 1) * (n - 1) / (n - p)
    # Per subject: X_gᵀû_g and X_gᵀX_g.
    a = np.array([x[g == c].T @ e[g == c] for c in range(G)])  # G × p
    m = np.array([x[g == c].T @ x[g == c] for c in range(G)])  # G × p × p
    d = w @ a @ xtx_inv  # patterns × p: β* − β̂
    # Scores of the sample's own residuals: w_g a_g − M_g d, mapped by (XᵀX)⁻¹.
    s = w[:, :, None] * a[None, :, :] - np.einsum("gij,kj->kgi", m, d)  # patterns × G × p
    u = np.einsum("ij,kgj->kgi", xtx_inv, s)
    var = c1 * np.einsum("kgi,kgi->ki", u, u)
    return d / np.sqrt(var)


def refit_t(x, y, g, wg):
    """t* of one weight pattern by refitting the sample from scratch with statsmodels."""
    beta = np.linalg.lstsq(x, y, rcond=None)[0]
    fitted = x @ beta
    ys = fitted + wg[g] * (y - fitted)
    r = sm.OLS(ys, x).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
    return (r.params - beta) / r.bse


def patterns(G, lead):
    """All 6^G weight patterns whose first G − CHUNK_DIGITS digits are `lead` (an int)."""
    k = min(G, CHUNK_DIGITS)
    idx = np.indices((6,) * k).reshape(k, -1).T  # 6^k × k, first digit slowest
    head = []
    for _ in range(G - k):
        head.append(lead % 6)
        lead //= 6
    head = np.array(head[::-1], dtype=int)
    full = np.hstack([np.broadcast_to(head, (len(idx), G - k)), idx])
    return WEBB[full]


def wild(name, x, y, g, names):
    n, p = x.shape
    G = int(g.max() + 1)
    rng = np.random.default_rng(20260)
    # Closed form against refitting, on random patterns.
    wr = WEBB[rng.integers(0, 6, size=(200, G))]
    fast = t_stats(x, y, g, wr)
    slow = np.array([refit_t(x, y, g, wg) for wg in wr])
    err = np.max(np.abs(fast - slow) / np.maximum(np.abs(slow), 1e-12))
    assert err < 1e-9, (name, err)
    # Every pattern.
    k = min(G, CHUNK_DIGITS)
    t = np.concatenate([t_stats(x, y, g, patterns(G, lead)) for lead in range(6 ** (G - k))])
    assert len(t) == 6 ** G and np.isfinite(t).all()
    q = np.quantile(t, [0.025, 0.975], axis=0, method="inverted_cdf")  # 2 × p
    ols = sm.OLS(y, x).fit()
    cl = sm.OLS(y, x).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
    v2, adj, m = cr2(x, ols.resid, g)
    out = {"n": int(n), "clusters": G, "samples": int(6 ** G),
           "closed_form_vs_refit_max_rel": float(err), "coefficients": {}}
    for j, nm in enumerate(names):
        se1 = float(cl.bse[j])
        se2 = float(np.sqrt(v2[j, j]))
        df2 = float(bm_df(x, g, adj, m, np.eye(p)[j]))
        t2 = float(scipy.stats.t.ppf(0.975, df2))
        b = float(ols.params[j])
        out["coefficients"][nm] = {
            "estimate": b,
            "se_cr1": se1,
            "t_quantiles": [float(q[0, j]), float(q[1, j])],
            "ci95_wild": [b - float(q[1, j]) * se1, b - float(q[0, j]) * se1],
            "se_cr2": se2,
            "df_cr2": df2,
            "ci95_cr2": [b - t2 * se2, b + t2 * se2],
            "ci95_cr1": [b - float(scipy.stats.t.ppf(0.975, G - 1)) * se1,
                         b + float(scipy.stats.t.ppf(0.975, G - 1)) * se1],
            "width_ratio_wild_to_cr2": float((q[1, j] - q[0, j]) * se1 / (2 * t2 * se2)),
        }
    return out


def main():
    df = bundled()
    out = {
        "source": "wild cluster bootstrap-t, Webb six-point weights, unrestricted, every 6^G "
        "pattern (numpy closed form, checked against statsmodels refits); CR2 + Bell–McCaffrey "
        "df (dense numpy, common.py); data/*.csv",
        "script": "tools/reference/wild.py",
        "versions": {"statsmodels": statsmodels.__version__, "numpy": np.__version__,
                     "scipy": scipy.__version__},
    }
    d = rows(df, "walk", ["sl", "sf", "h"])
    g, _ = subject_codes(d.subject)
    out["walk-sl-sf"] = wild("walk-sl-sf", (d.sf.values * 60.0 * d.h.values)[:, None],
                             d.sl.values, g, ["k"])
    d = rows(df, "walk", ["sf", "ds_pct"])
    g, _ = subject_codes(d.subject)
    out["walk-tds-sf"] = wild("walk-tds-sf",
                              np.column_stack([np.ones(len(d)), d.sf.values * 60.0]),
                              d.ds_pct.values, g, ["d0", "d1"])
    write_json(out, OUT)


if __name__ == "__main__":
    main()
