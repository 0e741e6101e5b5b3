"""Reference standard errors and breakpoint confidence sets for `tests/reference_inference.rs`.

Data: the bundled trials tables `data/*.csv` (committed), read as gaitfit reads them
(`common.py`). Sources: statsmodels OLS with `cov_type='cluster'` (CR1, `use_t=True`: t with
G − 1 df), and dense numpy implementations written from the definitions for what statsmodels
lacks (CR2 with Bell–McCaffrey degrees of freedom: n_g × n_g adjustment matrices; the
F-based confidence set of a breakpoint by fitting every admissible partition; the clustered
standard error of a mean of per-subject slopes). Nothing here reads gaitfit's output.

Run: /work/venv/bin/python tools/reference/inference.py  (writes tools/reference/inference.json)
"""
import math
import os

import numpy as np
import scipy
import scipy.optimize
import scipy.stats
import statsmodels
import statsmodels.api as sm

from common import ROOT, bm_df, bundled, cr1, cr2, rows, subject_codes, write_json

OUT = os.path.join(os.path.dirname(__file__), "inference.json")


def linear(x, y, g):
    """OLS with iid, CR1 (statsmodels) and CR2 (dense) standard errors and BM df."""
    ols = sm.OLS(y, x).fit()
    cl = sm.OLS(y, x).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
    v2, adj, m = cr2(x, ols.resid, g)
    p = x.shape[1]
    df2 = [bm_df(x, g, adj, m, np.eye(p)[j]) for j in range(p)]
    return {
        "n": int(len(y)),
        "clusters": int(g.max() + 1),
        "coef": list(ols.params),
        "se_iid": list(ols.bse),
        "se_cr1": list(cl.bse),
        "df_cr1": float(cl.df_resid_inference),
        "se_cr2": list(np.sqrt(np.diag(v2))),
        "df_cr2": df2,
    }


def centred_to_raw(deg, c, s):
    """T with raw = T · β for the basis ((x − c)/s)^i."""
    t = np.zeros((deg + 1, deg + 1))
    for i in range(deg + 1):
        for k in range(i + 1):
            t[k, i] = math.comb(i, k) * (-c) ** (i - k) / s ** i
    return t


def tflight(df):
    d = rows(df, "run", ["sf", "tf"])
    x = d.sf.values * 60.0
    y = d.tf.values
    g, _ = subject_codes(d.subject)
    keys = np.unique(x)
    nk = len(keys)
    min_distinct = 5  # RunTflightSf::MIN_DISTINCT: 5 distinct step frequencies per piece

    def design(j):
        below = x < keys[j]
        # Centred, scaled pieces (quadratic below, cubic above; k2 = 230 lies above the data).
        c1, s1 = keys[j] - 25.0, 25.0
        c2, s2 = (keys[j] + 230.0) / 2.0, (230.0 - keys[j]) / 2.0
        u = (x - c1) / s1
        w = (x - c2) / s2
        cols = [below * 1.0, below * u, below * u ** 2,
                ~below * 1.0, ~below * w, ~below * w ** 2, ~below * w ** 3]
        tmat = np.zeros((7, 7))
        tmat[:3, :3] = centred_to_raw(2, c1, s1)
        tmat[3:, 3:] = centred_to_raw(3, c2, s2)
        return np.array(cols).T, tmat

    def rss(j):
        xd, _ = design(j)
        beta, *_ = np.linalg.lstsq(xd, y, rcond=None)
        e = y - xd @ beta
        return float(e @ e)

    # Admissible partitions: at least 5 distinct keys on each side (the search bracket
    # [keys[4], keys[n − 5]] of RunTflightSf::plan_sorted; partition j puts keys < keys[j] below).
    js = list(range(min_distinct, nk - min_distinct + 1))
    r = np.array([rss(j) for j in js])
    n = len(y)
    G = g.max() + 1
    k = 8  # 7 linear coefficients and k1 (k2 held)
    dfr = n - k
    best = js[int(np.argmin(r))]

    def pieces_of(thr):
        acc = [j for j, v in zip(js, r) if v <= thr]
        pieces = []
        i = 0
        while i < len(acc):
            e = i
            while e + 1 < len(acc) and acc[e + 1] == acc[e] + 1:
                e += 1
            a, b = acc[i], acc[e]
            pieces.append([None if a == js[0] else float(keys[a - 1]),
                           None if b == js[-1] else float(keys[b])])
            i = e + 1
        return len(acc), pieces

    # Linear coefficients at the estimate (midpoint of the best gap), CR1 conditional on k1.
    xd, tmat = design(best)
    cl = sm.OLS(y, xd).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
    raw = tmat @ cl.params
    vraw = tmat @ cl.cov_params() @ tmat.T
    # The plain F set, and the clustered one: the likelihood ratio divided by Rao & Scott's
    # first-order design effect tr(V_iid⁻¹ V_CR1)/p of the linear coefficients (V_iid with
    # σ² = RSS/(n − 8), k1 counted), against F(1, G − 1).
    sigma2 = r.min() / dfr
    v_iid = sigma2 * np.linalg.inv(xd.T @ xd)
    delta = float(np.trace(np.linalg.solve(v_iid, cl.cov_params())) / 7)
    n_iid, pieces_iid = pieces_of(r.min() + sigma2 * scipy.stats.f.ppf(0.95, 1, dfr))
    n_acc, pieces = pieces_of(r.min() + sigma2 * delta * scipy.stats.f.ppf(0.95, 1, G - 1))
    # The same with CR2 (the default below 20 subjects): the design effect from the dense CR2
    # covariance of the linear coefficients, against the same F(1, G − 1).
    v2, _, _ = cr2(xd, y - xd @ cl.params, g)
    delta2 = float(np.trace(np.linalg.solve(v_iid, v2)) / 7)
    n_acc2, pieces2 = pieces_of(r.min() + sigma2 * delta2 * scipy.stats.f.ppf(0.95, 1, G - 1))
    return {
        "n": int(n),
        "clusters": int(g.max() + 1),
        "k1": float(0.5 * (keys[best - 1] + keys[best])),
        "k1_admissible": len(js),
        "k1_accepted": n_acc,
        "k1_pieces": pieces,
        "k1_design_effect": delta,
        "k1_accepted_iid": n_iid,
        "k1_design_effect_cr2": delta2,
        "k1_accepted_cr2": n_acc2,
        "k1_pieces_cr2": pieces2,
        "k1_pieces_iid": pieces_iid,
        "coef": list(raw),
        "se_cr1_conditional": list(np.sqrt(np.diag(vraw))),
    }


def run_sl_v(df):
    d = rows(df, "run", ["v", "sl", "h"])
    d = d[d.h > 0].reset_index(drop=True)
    v = d.v.values * 60.0
    h = d.h.values
    y = d.sl.values
    r = np.sqrt(h / 1.8)
    g, names = subject_codes(d.subject)
    G = g.max() + 1
    n = len(y)
    onehot = np.eye(G)[g]

    def design(t):
        z = np.minimum(v, t * r) * r
        return np.column_stack([np.ones(n), onehot * z[:, None]])

    def rss(t):
        x = design(t)
        beta, *_ = np.linalg.lstsq(x, y, rcond=None)
        e = y - x @ beta
        return float(e @ e)

    u = np.unique(v / r)
    lo, hi = u[2], u[-3]  # RunSlV::plan_sorted: 3 distinct normalised speeds on each side
    grid = np.linspace(lo, hi, 20001)
    rg = np.array([rss(t) for t in grid])
    i = int(np.argmin(rg))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    opt = scipy.optimize.minimize_scalar(rss, bounds=(a, b), method="bounded",
                                         options={"xatol": 1e-10})
    t = float(opt.x)
    x = design(t)
    fit = sm.OLS(y, x).fit()
    e = fit.resid
    K = 1 + G  # linear columns of the design
    cl = sm.OLS(y, x).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
    gam = fit.params[1:]
    gbar = gam.mean()
    minv = np.linalg.inv(x.T @ x)
    ell = np.concatenate([[0.0], np.full(G, 1.0 / G)])
    # The clustered influence of a mean of subject slopes: the full-design influence of the
    # contrast plus each subject's slope deviation (its between-subject part).
    c1 = G / (G - 1) * (n - 1) / (n - K)
    psi = []
    for c in range(G):
        sc = x[g == c].T @ e[g == c]
        psi.append(ell @ minv @ sc + (gam[c] - gbar) / G)
    se_b = math.sqrt(c1 * sum(p * p for p in psi))
    # Levels: iid within subject, σ² = RSS/(n − K − 1) (v_norm counted).
    sigma2 = float(e @ e) / (n - K - 1)
    se_lev = []
    for s in range(G):
        ls = np.zeros(K)
        ls[1:] = -1.0 / G
        ls[1 + s] += 1.0
        se_lev.append(math.sqrt(sigma2 * ls @ minv @ ls))
    # With v_norm free: Gauss–Newton column ∂sl/∂v_norm = (b + level)·r² on the plateau.
    jac = np.where(v > t * r, gam[g] * r * r, 0.0)
    xa = np.column_stack([x, jac])
    ma = np.linalg.inv(xa.T @ xa)
    ka = K + 1
    c1a = G / (G - 1) * (n - 1) / (n - ka)
    meat = np.zeros((ka, ka))
    psib = []
    ella = np.concatenate([ell, [0.0]])
    for c in range(G):
        sc = xa[g == c].T @ e[g == c]
        pc = ma @ sc
        meat += np.outer(pc, pc)
        psib.append(ella @ pc + (gam[c] - gbar) / G)
    va = c1a * meat
    # v_norm's confidence set: the profile likelihood ratio divided by v_norm's own design
    # effect V_CR1/V_iid (Gauss–Newton, σ² = RSS/(n − K − 1)) against F(1, G − 1); its ends by
    # root finding on the profile.
    sigma2 = float(e @ e) / (n - ka)
    delta = va[K, K] / (sigma2 * ma[K, K])
    rmin = float(e @ e)
    thr = rmin + sigma2 * delta * scipy.stats.f.ppf(0.95, 1, G - 1)
    inside = [tt for tt, rr in zip(grid, rg) if rr <= thr]
    f = lambda tt: rss(tt) - thr
    lo_end = scipy.optimize.brentq(f, inside[0] - (grid[1] - grid[0]), inside[0], xtol=1e-9)
    hi_end = scipy.optimize.brentq(f, inside[-1], inside[-1] + (grid[1] - grid[0]), xtol=1e-9)
    return {
        "n": int(n),
        "clusters": int(G),
        "subjects": names,
        "v_norm": t,
        "a": float(fit.params[0]),
        "b": float(gbar),
        "levels": list(gam - gbar),
        "se_a_cr1": float(cl.bse[0]),
        "se_b_cr1": se_b,
        "se_levels_iid": se_lev,
        "se_a_cr1_free": float(math.sqrt(va[0, 0])),
        "se_b_cr1_free": float(math.sqrt(c1a * sum(p * p for p in psib))),
        "se_v_norm_cr1_free": float(math.sqrt(va[K, K])),
        "v_norm_design_effect": float(delta),
        "v_norm_set": [float(lo_end), float(hi_end)],
    }


def kb_mu(df):
    """Ko–Badler μ-lines: per output, μ = sign·α·(x − sl*) + μ*, x = sl·ll*/ll. α1 sits on its
    bound 0 on these data (its unconstrained slope is negative), so output 1 fits μ1* alone.
    Standard errors: iid with one residual variance per output (each output's own OLS), and CR1
    on the stacked outputs clustered by subject (statsmodels)."""
    sl_star = 0.7071025  # KbMu::published().sl_star(): the bundled prototype's step length
    ll_star = 0.81  # WINTER_TABLE_LEG_LENGTH
    d = df[(df.gait == "walk") & (~df.flagged)].dropna(subset=["sl", "ll"])
    d = d[(d.sl > 0) & (d.ll > 0)]
    cols = ["knee_hs", "foot_hs", "foot_to", "meta_to"]
    blocks = []
    for k, c in enumerate(cols):
        e = d.dropna(subset=[c])
        xk = e.sl.values * ll_star / e.ll.values
        sign = -1.0 if k == 0 else 1.0
        blocks.append((k, sign * (xk - sl_star), e[c].values, list(e.subject)))
    # Subjects in order of first appearance over rows, output by output within a row (gaitfit).
    order = []
    for _, r in d.iterrows():
        if any(not np.isnan(r[c]) for c in cols) and r.subject not in order:
            order.append(r.subject)
    names = ["alpha2", "alpha3", "alpha4", "mu1_star", "mu2_star", "mu3_star", "mu4_star"]
    xs, ys, gs = [], [], []
    se_iid = {}
    for k, z, y, subj in blocks:
        if k == 0:
            xk = np.ones((len(y), 1))
        else:
            xk = np.column_stack([z, np.ones(len(y))])
        o = sm.OLS(y, xk).fit()
        if k == 0:
            se_iid["mu1_star"] = float(o.bse[0])
        else:
            se_iid[f"alpha{k + 1}"] = float(o.bse[0])
            se_iid[f"mu{k + 1}_star"] = float(o.bse[1])
        row = np.zeros((len(y), 7))
        if k == 0:
            row[:, 3] = 1.0
        else:
            row[:, k - 1] = z
            row[:, 3 + k] = 1.0
        xs.append(row)
        ys.append(y)
        gs += [order.index(s_) for s_ in subj]
    x = np.vstack(xs)
    y = np.concatenate(ys)
    g = np.array(gs)
    cl = sm.OLS(y, x).fit(cov_type="cluster", cov_kwds={"groups": g}, use_t=True)
    return {
        "n": int(len(y)),
        "clusters": int(g.max() + 1),
        "names": names,
        "coef": dict(zip(names, map(float, cl.params))),
        "se_cr1": dict(zip(names, map(float, cl.bse))),
        "se_iid_per_output": se_iid,
    }


def main():
    df = bundled()
    out = {
        "source": "statsmodels OLS cov_type='cluster' (CR1, use_t) and dense numpy CR2 / "
        "Bell–McCaffrey df / exhaustive partition F sets; data/*.csv",
        "script": "tools/reference/inference.py",
        "versions": {"statsmodels": statsmodels.__version__, "numpy": np.__version__,
                     "scipy": scipy.__version__},
    }
    d = rows(df, "walk", ["sf", "ds_pct"])
    g, _ = subject_codes(d.subject)
    out["walk-tds-sf"] = linear(np.column_stack([np.ones(len(d)), d.sf.values * 60.0]),
                                d.ds_pct.values, g)
    d = rows(df, "walk", ["sl", "sf", "h"])
    g, _ = subject_codes(d.subject)
    out["walk-sl-sf"] = linear((d.sf.values * 60.0 * d.h.values)[:, None], d.sl.values, g)
    out["run-tflight-sf"] = tflight(df)
    out["run-sl-v"] = run_sl_v(df)
    out["kb-mu"] = kb_mu(df)
    write_json(out, OUT, 3000)


if __name__ == "__main__":
    main()
