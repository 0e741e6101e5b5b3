"""Reference Huber M-estimates for `tests/reference_inference.rs` (issue 18, Build 4).

Data: the bundled trials tables `data/*.csv` (committed), read as gaitfit reads them
(`common.py`). Source: statsmodels `RLM(y, X, M=HuberT(t=1.345)).fit(scale_est='mad',
cov='H1')` — its defaults, with the IRLS run to a fixed point (conv='coefs', tol=1e-13) so that
the comparison measures the covariance formula, not where two iterations stopped. Nothing here
reads gaitfit's output.

Run: /work/venv/bin/python tools/reference/robust.py  (writes tools/reference/robust.json)
"""
import json
import os

import numpy as np
import statsmodels
import statsmodels.api as sm

from common import bundled

OUT = os.path.join(os.path.dirname(__file__), "robust.json")


def rows(df, gait, cols):
    d = df[(df.gait == gait) & (~df.flagged)]
    return d.dropna(subset=cols).reset_index(drop=True)


def rlm(x, y):
    r = sm.RLM(y, x, M=sm.robust.norms.HuberT(t=1.345)).fit(
        scale_est="mad", cov="H1", conv="coefs", tol=1e-13, maxiter=1000
    )
    return {
        "n": int(len(y)),
        "coef": [float(v) for v in r.params],
        "se_h1": [float(v) for v in r.bse],
        "scale": float(r.scale),
        "rows_downweighted": int(np.sum(r.weights < 1.0)),
        "iterations": int(r.fit_history["iteration"]),
    }


def main():
    df = bundled()
    out = {
        "source": "statsmodels RLM, HuberT(t=1.345), scale_est='mad', cov='H1' (defaults), "
        "conv='coefs', tol=1e-13; data/*.csv",
        "script": "tools/reference/robust.py",
        "versions": {"statsmodels": statsmodels.__version__, "numpy": np.__version__},
    }
    d = rows(df, "walk", ["sf", "ds_pct"])
    out["walk-tds-sf"] = rlm(np.column_stack([np.ones(len(d)), d.sf.values * 60.0]),
                             d.ds_pct.values)
    d = rows(df, "walk", ["sl", "sf", "h"])
    out["walk-sl-sf"] = rlm((d.sf.values * 60.0 * d.h.values)[:, None], d.sl.values)
    with open(OUT, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
