//! Box-constrained linear least squares on normal equations, exactly: a primal active-set
//! method (Lawson & Hanson 1974, ch. 23, for bounds on both sides; Nocedal & Wright 2006,
//! §16.5) for `min ½βᵀAβ − cᵀβ` subject to `lo ≤ β ≤ hi`, `A` positive definite.
//!
//! A relation linear in its coefficients with bounds on some of them (Ko–Badler's α) is a
//! convex quadratic programme: its solution is unique and the active-set method reaches it in
//! finitely many steps, each one equality-constrained solve. Convergence is not a tolerance on
//! a step: the returned solution is checked against the KKT conditions (feasible; the gradient
//! `Aβ − c` zero on free coefficients, pointing out of the box on active ones), and the result
//! says whether that check passed. Leave-one-subject-out folds and bootstrap replicates solve
//! the same problem from summed per-subject normal equations, so every bounded refit is exact
//! and its convergence is known.
use nalgebra::{DMatrix, DVector};

/// The outcome of [`solve_box`].
#[derive(Debug, Clone, PartialEq)]
pub struct BoxSolution {
    /// The coefficients.
    pub beta: DVector<f64>,
    /// Per coefficient: on its lower bound (−1), free (0), on its upper bound (+1).
    pub active: Vec<i8>,
    /// Active-set iterations.
    pub iterations: usize,
    /// Whether the KKT conditions hold at `beta` (to rounding).
    pub converged: bool,
}

/// Iteration budget of [`solve_box`] per coefficient: each iteration adds or releases one
/// bound, and the method never revisits an active set, so a handful per coefficient is ample.
const ITER_PER_COEF: usize = 8;

/// Relative tolerance of the KKT check: gradients and bound violations below this times the
/// scale of the problem are rounding.
const KKT_TOL: f64 = 1e-9;

/// Solves `A_FF β_F = c_F − A_FB β_B` for the free set `F` with `β_B` fixed; `None` if singular.
fn solve_free(
    a: &DMatrix<f64>,
    c: &DVector<f64>,
    beta: &DVector<f64>,
    active: &[i8],
) -> Option<DVector<f64>> {
    let p = c.len();
    let free: Vec<usize> = (0..p).filter(|&j| active[j] == 0).collect();
    let mut out = beta.clone();
    if free.is_empty() {
        return Some(out);
    }
    let k = free.len();
    let mut xtx = vec![0.0; k * k];
    let mut xty = vec![0.0; k];
    for (ia, &a_) in free.iter().enumerate() {
        let mut r = c[a_];
        for j in 0..p {
            if active[j] != 0 {
                r -= a[(a_, j)] * beta[j];
            }
        }
        xty[ia] = r;
        for (ib, &b_) in free.iter().enumerate() {
            xtx[ia * k + ib] = a[(a_, b_)];
        }
    }
    let (sol, _) = super::design::solve_normal(k, &xtx, &xty, 0.0)?;
    for (ia, &a_) in free.iter().enumerate() {
        out[a_] = sol[ia];
    }
    Some(out)
}

/// Minimises `½βᵀAβ − cᵀβ` over `lo ≤ β ≤ hi` (see the module docs). `None` when `A` restricted
/// to some free set is singular.
pub fn solve_box(
    a: &DMatrix<f64>,
    c: &DVector<f64>,
    lo: &[f64],
    hi: &[f64],
) -> Option<BoxSolution> {
    let p = c.len();
    let mut active = vec![0i8; p];
    // Feasible start: the unconstrained solution clamped into the box, clamped ones active.
    let mut beta = solve_free(a, c, &DVector::zeros(p), &active)?;
    for j in 0..p {
        if beta[j] < lo[j] {
            beta[j] = lo[j];
            active[j] = -1;
        } else if beta[j] > hi[j] {
            beta[j] = hi[j];
            active[j] = 1;
        }
    }
    let scale = |v: &DVector<f64>| v.amax().max(f64::MIN_POSITIVE);
    let budget = ITER_PER_COEF * p + 4;
    let mut iterations = 0;
    while iterations < budget {
        iterations += 1;
        let target = solve_free(a, c, &beta, &active)?;
        // Step from the feasible β toward the target until the first bound is hit.
        let mut t = 1.0f64;
        let mut hit = None;
        for j in 0..p {
            if active[j] != 0 {
                continue;
            }
            let d = target[j] - beta[j];
            if d < 0.0 && target[j] < lo[j] {
                let s = (lo[j] - beta[j]) / d;
                if s < t {
                    t = s;
                    hit = Some((j, -1i8));
                }
            } else if d > 0.0 && target[j] > hi[j] {
                let s = (hi[j] - beta[j]) / d;
                if s < t {
                    t = s;
                    hit = Some((j, 1i8));
                }
            }
        }
        beta += (&target - &beta) * t.max(0.0);
        if let Some((j, side)) = hit {
            beta[j] = if side < 0 { lo[j] } else { hi[j] };
            active[j] = side;
            continue;
        }
        // At the minimum over the current free set: release the bound whose multiplier has
        // the wrong sign the most, or stop.
        let g = a * &beta - c;
        let gs = scale(&g).max(scale(c));
        let mut worst: Option<(usize, f64)> = None;
        for j in 0..p {
            // On the lower bound the objective must not decrease upwards: g_j ≥ 0.
            let v = match active[j] {
                -1 => -g[j],
                1 => g[j],
                _ => continue,
            };
            if v > KKT_TOL * gs && worst.is_none_or(|w| v > w.1) {
                worst = Some((j, v));
            }
        }
        match worst {
            Some((j, _)) => active[j] = 0,
            None => break,
        }
    }
    let converged = kkt_holds(a, c, &beta, &active, lo, hi);
    Some(BoxSolution {
        beta,
        active,
        iterations,
        converged,
    })
}

/// Whether `beta` with its active set satisfies the KKT conditions of the box problem.
fn kkt_holds(
    a: &DMatrix<f64>,
    c: &DVector<f64>,
    beta: &DVector<f64>,
    active: &[i8],
    lo: &[f64],
    hi: &[f64],
) -> bool {
    let g = a * beta - c;
    let gs = g.amax().max(c.amax()).max(f64::MIN_POSITIVE);
    let bs = beta.amax().max(1.0);
    (0..beta.len()).all(|j| {
        let feasible = beta[j] >= lo[j] - KKT_TOL * bs && beta[j] <= hi[j] + KKT_TOL * bs;
        let stationary = match active[j] {
            -1 => g[j] >= -KKT_TOL * gs,
            1 => g[j] <= KKT_TOL * gs,
            _ => g[j].abs() <= KKT_TOL * gs,
        };
        feasible && stationary
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over all 3^p active patterns: the feasible KKT point of least objective.
    fn brute(a: &DMatrix<f64>, c: &DVector<f64>, lo: &[f64], hi: &[f64]) -> DVector<f64> {
        let p = c.len();
        let mut best: Option<(f64, DVector<f64>)> = None;
        for code in 0..3usize.pow(p as u32) {
            let mut act = vec![0i8; p];
            let mut beta = DVector::zeros(p);
            let mut k = code;
            for j in 0..p {
                act[j] = (k % 3) as i8 - 1;
                k /= 3;
                if act[j] == -1 {
                    beta[j] = lo[j];
                } else if act[j] == 1 {
                    beta[j] = hi[j];
                }
            }
            if act
                .iter()
                .zip(lo.iter().zip(hi))
                .any(|(&s, (l, h))| (s == -1 && !l.is_finite()) || (s == 1 && !h.is_finite()))
            {
                continue;
            }
            let Some(b) = solve_free(a, c, &beta, &act) else {
                continue;
            };
            if (0..p).any(|j| b[j] < lo[j] - 1e-12 || b[j] > hi[j] + 1e-12) {
                continue;
            }
            let f = 0.5 * b.dot(&(a * &b)) - c.dot(&b);
            if best.as_ref().is_none_or(|x| f < x.0) {
                best = Some((f, b));
            }
        }
        best.unwrap().1
    }

    #[test]
    fn matches_brute_force_on_random_boxes() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 10_000) as f64 / 5_000.0 - 1.0
        };
        for case in 0..200 {
            let p = 1 + case % 5;
            let m = DMatrix::from_fn(p + 3, p, |_, _| next());
            let a = m.transpose() * &m + DMatrix::identity(p, p) * 0.05;
            let c = DVector::from_fn(p, |_, _| 2.0 * next());
            let lo: Vec<f64> = (0..p)
                .map(|j| {
                    if j % 3 == 2 {
                        f64::NEG_INFINITY
                    } else {
                        -0.3 + 0.1 * next()
                    }
                })
                .collect();
            let hi: Vec<f64> = (0..p)
                .map(|j| {
                    if j % 4 == 1 {
                        f64::INFINITY
                    } else {
                        0.4 + 0.1 * next()
                    }
                })
                .collect();
            let s = solve_box(&a, &c, &lo, &hi).unwrap();
            assert!(s.converged, "case {case}");
            let want = brute(&a, &c, &lo, &hi);
            assert!(
                (&s.beta - &want).amax() < 1e-9,
                "case {case}: {} vs {}",
                s.beta,
                want
            );
        }
    }
}
