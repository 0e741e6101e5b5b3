//! The root finding that turns step constraints into forces and torques (§4.1): each phase is
//! simulated repeatedly, varying its force parameter(s), until it ends on its final conditions at
//! exactly its duration.
//!
//! As in the paper, a bracketing stage finds a reasonable approximation and a secant stage refines
//! it (the secant "converges fast, but needs a good first approximation"):
//! - one unknown ([`solve_1d`]): the bracket is found by expanding secant steps from the starting
//!   value (the previous step's profile), then refined by the Illinois variant of regula falsi — a
//!   secant iteration kept inside the bracket, with bisection whenever it stalls;
//! - two unknowns (the stance phase's `F_θ1` and `F_w`, [`solve_2d`]): Broyden's method (the
//!   multidimensional secant method) from a finite-difference Jacobian, with step halving; if it
//!   does not converge, alternating one-dimensional bracketed solves supply a better start.
//!
//! As the paper carries the previous step's profile to start the next, the solvers also take the
//! previous step's solver state: [`solve_1d_with`] a slope (the first trial is then the Newton
//! step, followed by secant steps while they converge) and [`solve_2d_with`] a Jacobian (no
//! finite differences; a fresh one if it gives no descent). Both hand theirs back in
//! [`Solved::jacobian`].
//!
//! Every evaluation of the residual is one simulation of the phase; the counts are reported per
//! phase ([`Solved::iterations`]).

/// Result of a shooting solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solved<const N: usize> {
    /// The force parameters found.
    pub x: [f64; N],
    /// Residuals at `x`.
    pub residual: [f64; N],
    /// Number of phase simulations used.
    pub iterations: usize,
    /// The last Jacobian `∂f_i/∂x_j` the solve used (Broyden-updated), to start the next solve
    /// of the same phase from ([`solve_2d_with`]); `None` if the solve needed none.
    pub jacobian: Option<[[f64; N]; N]>,
}

/// Solves `f(x) = 0` from `x0` with a first trial step `dx`, to `|f| ≤ tol`, with at most
/// `max_evals` evaluations of `f`.
pub fn solve_1d<F: FnMut(f64) -> f64>(
    f: F,
    x0: f64,
    dx: f64,
    tol: f64,
    max_evals: usize,
) -> Result<Solved<1>, String> {
    solve_1d_with(f, x0, dx, tol, max_evals, None)
}

/// [`solve_1d`] with a carried slope `f'(x)` (e.g. the [`Solved::jacobian`] of the previous
/// step's solve of the same phase): the second evaluation is then the Newton step from `x0`
/// (its length kept within 1/8–8 × `|dx|`) instead of `x0 + dx`. A wrong slope only costs
/// that evaluation: the bracketing continues from it as from `x0 + dx`.
pub fn solve_1d_with<F: FnMut(f64) -> f64>(
    mut f: F,
    x0: f64,
    dx: f64,
    tol: f64,
    max_evals: usize,
    slope: Option<f64>,
) -> Result<Solved<1>, String> {
    let mut evals = 0usize;
    // The last two evaluations, for the slope handed back.
    let mut hist = [(f64::NAN, f64::NAN); 2];
    let mut eval = |x: f64, evals: &mut usize, hist: &mut [(f64, f64); 2]| {
        *evals += 1;
        let r = f(x);
        *hist = [hist[1], (x, r)];
        r
    };
    let (mut a, mut fa) = (x0, eval(x0, &mut evals, &mut hist));
    let done = |x: f64, r: f64, n: usize, hist: [(f64, f64); 2]| {
        let m = (hist[1].1 - hist[0].1) / (hist[1].0 - hist[0].0);
        Ok(Solved {
            x: [x],
            residual: [r],
            iterations: n,
            jacobian: (m.is_finite() && m != 0.0)
                .then_some([[m]])
                .or(slope.map(|m| [[m]])),
        })
    };
    if fa.abs() <= tol {
        return done(a, fa, evals, hist);
    }
    if !fa.is_finite() {
        return Err(format!("residual not finite at the start value {x0}"));
    }
    let (mut b, mut fb) = match slope {
        Some(m0) if m0 != 0.0 && m0.is_finite() => {
            // Secant iteration from the carried slope while it converges (each residual at
            // most half the last one); otherwise the bracketing goes on from its last two
            // points.
            let mut m = m0;
            loop {
                let newton = -fa / m;
                let step = newton.signum() * newton.abs().min(8.0 * dx.abs());
                let (xn, fxn) = (a + step, eval(a + step, &mut evals, &mut hist));
                if fxn.abs() <= tol {
                    return done(xn, fxn, evals, hist);
                }
                // False for a non-finite residual too.
                let converging = fxn.abs() <= 0.5 * fa.abs();
                if !converging || evals >= max_evals.min(6) {
                    break (xn, fxn);
                }
                let mn = (fxn - fa) / step;
                if mn != 0.0 && mn.is_finite() {
                    m = mn;
                }
                a = xn;
                fa = fxn;
            }
        }
        _ => (x0 + dx, eval(x0 + dx, &mut evals, &mut hist)),
    };
    // Bracketing by expanding secant steps.
    while fa.signum() == fb.signum() || !fb.is_finite() {
        if fb.abs() <= tol {
            return done(b, fb, evals, hist);
        }
        if evals >= max_evals {
            return Err(format!(
                "no sign change found after {evals} simulations (last value {b}, residual {fb})"
            ));
        }
        if !fb.is_finite() {
            // Step back toward the good point.
            b = 0.5 * (a + b);
            fb = eval(b, &mut evals, &mut hist);
            continue;
        }
        if fb.abs() > fa.abs() {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut fa, &mut fb);
        }
        let d = b - a;
        let secant = if fb != fa {
            -fb * d / (fb - fa)
        } else {
            2.0 * d
        };
        // Continue beyond b, between half and eight times the last step.
        let step = d.signum() * secant.abs().clamp(0.5 * d.abs(), 8.0 * d.abs());
        a = b;
        fa = fb;
        b += step;
        fb = eval(b, &mut evals, &mut hist);
    }
    if fb.abs() <= tol {
        return done(b, fb, evals, hist);
    }
    // Illinois on the bracket [a, b] (the generators' one root finder).
    let budget = max_evals.saturating_sub(evals);
    let r = crate::generator::numeric::illinois(
        |x| eval(x, &mut evals, &mut hist),
        (a, fa),
        (b, fb),
        crate::generator::numeric::Stop {
            f_tol: tol,
            x_tol: 1e-10,
            max_evals: budget,
        },
    );
    match r.status {
        crate::generator::numeric::Status::Root => done(r.last.0, r.last.1, evals, hist),
        // The bracket has collapsed onto a jump of the residual (no exact root in floating
        // point): return the best point; the caller reports the remaining error.
        crate::generator::numeric::Status::Narrow => {
            let (x, fx) = r.best();
            done(x, fx, evals, hist)
        }
        crate::generator::numeric::Status::Exhausted => Err(format!(
            "no convergence in {max_evals} simulations (bracket [{}, {}])",
            r.a.0, r.b.0
        )),
    }
}

/// Solves `f(x) = 0` for two unknowns from `x0` (trial steps `dx` for the finite-difference
/// Jacobian), to `|f_i| ≤ tol_i`, with at most `max_evals` evaluations.
pub fn solve_2d<F: FnMut([f64; 2]) -> [f64; 2]>(
    f: F,
    x0: [f64; 2],
    dx: [f64; 2],
    tol: [f64; 2],
    max_evals: usize,
) -> Result<Solved<2>, String> {
    solve_2d_with(f, x0, dx, tol, max_evals, None)
}

/// Line-search halvings allowed to a carried Jacobian before it is replaced by a
/// finite-difference one (a carried Jacobian that gives no descent at full or half step is
/// stale: more halvings would only spend simulations on a poor direction).
const CARRIED_TRIES: usize = 2;

/// Line-search halvings allowed to a fresh finite-difference Jacobian.
const FRESH_TRIES: usize = 6;

/// [`solve_2d`] starting from a carried Jacobian `jac0` (`∂f_i/∂x_j`, e.g. the
/// [`Solved::jacobian`] of the previous step's solve of the same phase), as the paper carries the
/// previous step's profile: the finite-difference Jacobian costs two simulations per solve, and
/// Broyden's updates keep a carried one current. If the carried Jacobian is singular or gives no
/// descent, the solve falls back to a finite-difference Jacobian at the current point.
pub fn solve_2d_with<F: FnMut([f64; 2]) -> [f64; 2]>(
    mut f: F,
    x0: [f64; 2],
    dx: [f64; 2],
    tol: [f64; 2],
    max_evals: usize,
    jac0: Option<[[f64; 2]; 2]>,
) -> Result<Solved<2>, String> {
    let mut evals = 0usize;
    let ok = |r: &[f64; 2]| r[0].abs() <= tol[0] && r[1].abs() <= tol[1];
    let norm = |r: &[f64; 2]| (r[0] / tol[0]).hypot(r[1] / tol[1]);
    let det = |j: &[[f64; 2]; 2]| j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let mut x = x0;
    let mut r = f(x);
    evals += 1;
    if ok(&r) {
        return Ok(Solved {
            x,
            residual: r,
            iterations: evals,
            jacobian: jac0,
        });
    }
    let mut carried = jac0.filter(|j| {
        let d = det(j);
        d != 0.0 && d.is_finite()
    });
    let mut last_jac = carried;
    let mut attempt = 0;
    while attempt < 2 {
        let from_carried = carried.is_some();
        let mut jac = match carried.take() {
            Some(j) => j,
            None => {
                // Finite-difference Jacobian.
                let mut jac = [[0.0; 2]; 2];
                for j in 0..2 {
                    let mut xp = x;
                    xp[j] += dx[j];
                    let rp = f(xp);
                    evals += 1;
                    for i in 0..2 {
                        jac[i][j] = (rp[i] - r[i]) / dx[j];
                    }
                }
                jac
            }
        };
        let tries = if from_carried {
            CARRIED_TRIES
        } else {
            FRESH_TRIES
        };
        let mut stalled = false;
        while evals < max_evals {
            let d = det(&jac);
            if d == 0.0 || !d.is_finite() {
                stalled = true;
                break;
            }
            let step = [
                -(r[0] * jac[1][1] - jac[0][1] * r[1]) / d,
                -(jac[0][0] * r[1] - jac[1][0] * r[0]) / d,
            ];
            let mut lambda = 1.0;
            let mut accepted = None;
            for _ in 0..tries {
                let xn = [x[0] + lambda * step[0], x[1] + lambda * step[1]];
                let rn = f(xn);
                evals += 1;
                if rn[0].is_finite() && rn[1].is_finite() && norm(&rn) < norm(&r) {
                    accepted = Some((xn, rn));
                    break;
                }
                lambda *= 0.5;
                if evals >= max_evals {
                    break;
                }
            }
            let Some((xn, rn)) = accepted else {
                stalled = true;
                break;
            };
            // Broyden's ("good") rank-one update.
            let s = [xn[0] - x[0], xn[1] - x[1]];
            let y = [rn[0] - r[0], rn[1] - r[1]];
            let ss = s[0] * s[0] + s[1] * s[1];
            if ss > 0.0 {
                for i in 0..2 {
                    let js = jac[i][0] * s[0] + jac[i][1] * s[1];
                    for j in 0..2 {
                        jac[i][j] += (y[i] - js) * s[j] / ss;
                    }
                }
            }
            last_jac = Some(jac);
            x = xn;
            r = rn;
            if ok(&r) {
                return Ok(Solved {
                    x,
                    residual: r,
                    iterations: evals,
                    jacobian: last_jac,
                });
            }
        }
        if !stalled {
            break;
        }
        if from_carried {
            // The carried Jacobian failed: a fresh finite-difference one, same attempt.
            continue;
        }
        attempt += 1;
        if attempt == 2 {
            break;
        }
        // Alternating one-dimensional bracketed solves give a better start.
        for _ in 0..3 {
            for j in 0..2 {
                let mut g = |v: f64| {
                    let mut xx = x;
                    xx[j] = v;
                    f(xx)[j]
                };
                let budget = max_evals.saturating_sub(evals).clamp(1, 40);
                match solve_1d(&mut g, x[j], dx[j] * 10.0, tol[j], budget) {
                    Ok(s) => {
                        x[j] = s.x[0];
                        evals += s.iterations;
                    }
                    Err(e) => {
                        return Err(format!(
                            "no convergence in {evals} simulations (unknown {}: {e})",
                            j + 1
                        ))
                    }
                }
            }
        }
        r = f(x);
        evals += 1;
        if ok(&r) {
            return Ok(Solved {
                x,
                residual: r,
                iterations: evals,
                jacobian: last_jac,
            });
        }
    }
    Err(format!(
        "no convergence in {evals} simulations (residuals {:.3e}, {:.3e})",
        r[0], r[1]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimensional_brackets_then_converges() {
        // A monotone, curved residual with the root far from the start.
        let s = solve_1d(|x| x.exp() - 50.0, 0.0, 0.1, 1e-12, 60).unwrap();
        assert!((s.x[0] - 50f64.ln()).abs() < 1e-12);
        assert!(s.iterations < 25, "{}", s.iterations);
        // Started near the root (a carried-over profile): a handful of simulations.
        let s = solve_1d(|x| x.exp() - 50.0, 3.9, 0.01, 1e-12, 60).unwrap();
        assert!(s.iterations <= 8, "{}", s.iterations);
        // Decreasing residual works too.
        let s = solve_1d(|x| 2.0 - x * x * x, -1.0, 0.5, 1e-12, 60).unwrap();
        assert!((s.x[0] - 2f64.cbrt()).abs() < 1e-10);
    }

    #[test]
    fn two_dimensional_secant_solves_a_coupled_system() {
        let f = |x: [f64; 2]| {
            [
                x[0] + 0.3 * x[1].sin() - 1.0,
                x[1] + 0.2 * x[0] * x[0] - 2.0,
            ]
        };
        let s = solve_2d(f, [0.0, 0.0], [1e-3, 1e-3], [1e-12, 1e-12], 50).unwrap();
        let r = f(s.x);
        assert!(r[0].abs() <= 1e-12 && r[1].abs() <= 1e-12);
        assert!(s.iterations < 20, "{}", s.iterations);
    }

    /// A coupled system like a phase's end conditions, and its exact Jacobian.
    fn coupled(x: [f64; 2]) -> [f64; 2] {
        [
            x[0] + 0.3 * x[1].sin() - 1.0,
            x[1] + 0.2 * x[0] * x[0] - 2.0,
        ]
    }

    fn coupled_jacobian(x: [f64; 2]) -> [[f64; 2]; 2] {
        [[1.0, 0.3 * x[1].cos()], [0.4 * x[0], 1.0]]
    }

    #[test]
    fn a_carried_jacobian_saves_the_finite_differences() {
        let tol = [1e-12, 1e-12];
        // The previous solve's root moved a little (the next step's start): carried Jacobian
        // (from a solve of a neighbouring system) against the fresh finite-difference start.
        let prev = solve_2d(coupled, [0.0, 0.0], [1e-3, 1e-3], tol, 50).unwrap();
        let jac = prev
            .jacobian
            .expect("a Broyden solve hands back its Jacobian");
        // The handed-back Jacobian is the system's, to Broyden's accuracy.
        let exact = coupled_jacobian(prev.x);
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (jac[i][j] - exact[i][j]).abs() < 0.05,
                    "{jac:?} vs {exact:?}"
                );
            }
        }
        let shifted = |x: [f64; 2]| {
            let r = coupled(x);
            [r[0] - 0.01, r[1] + 0.02]
        };
        let fresh = solve_2d(shifted, prev.x, [1e-3, 1e-3], tol, 50).unwrap();
        let carried = solve_2d_with(shifted, prev.x, [1e-3, 1e-3], tol, 50, Some(jac)).unwrap();
        for s in [fresh, carried] {
            let r = shifted(s.x);
            assert!(r[0].abs() <= tol[0] && r[1].abs() <= tol[1], "{r:?}");
        }
        assert!(
            carried.iterations + 2 <= fresh.iterations,
            "carried {} vs fresh {}",
            carried.iterations,
            fresh.iterations
        );
    }

    #[test]
    fn a_wrong_carried_jacobian_falls_back_to_finite_differences() {
        let tol = [1e-12, 1e-12];
        let fresh = solve_2d(coupled, [0.0, 0.0], [1e-3, 1e-3], tol, 50).unwrap();
        // Sign-flipped (every step goes uphill): its tries, then the fresh solve from the start.
        // Singular: ignored. Rows swapped (descends, poorly): a few Broyden updates more.
        let exact = coupled_jacobian([0.0, 0.0]);
        let cases = [
            (
                [[-exact[0][0], -exact[0][1]], [-exact[1][0], -exact[1][1]]],
                Some(fresh.iterations + CARRIED_TRIES),
            ),
            ([[1.0, 2.0], [2.0, 4.0]], Some(fresh.iterations)),
            ([exact[1], exact[0]], None),
        ];
        for (jac, evals) in cases {
            let s = solve_2d_with(coupled, [0.0, 0.0], [1e-3, 1e-3], tol, 50, Some(jac)).unwrap();
            let r = coupled(s.x);
            assert!(
                r[0].abs() <= tol[0] && r[1].abs() <= tol[1],
                "{jac:?}: {r:?}"
            );
            assert!((s.x[0] - fresh.x[0]).abs() < 1e-10 && (s.x[1] - fresh.x[1]).abs() < 1e-10);
            match evals {
                Some(n) => assert_eq!(s.iterations, n, "{jac:?}"),
                None => assert!(s.iterations <= 2 * fresh.iterations, "{jac:?}"),
            }
        }
    }

    #[test]
    fn a_carried_slope_starts_the_secant_at_the_newton_step() {
        let f = |x: f64| x.exp() - 50.0;
        let root = 50f64.ln();
        let plain = solve_1d(f, 3.9, 0.5, 1e-12, 60).unwrap();
        let slope = plain.jacobian.expect("the last secant slope")[0][0];
        assert!((slope - 50.0).abs() < 1.0, "{slope}");
        // Next "step": the target moved.
        let g = |x: f64| x.exp() - 52.0;
        let plain = solve_1d(g, root, 0.5, 1e-12, 60).unwrap();
        let carried = solve_1d_with(g, root, 0.5, 1e-12, 60, Some(slope)).unwrap();
        for s in [plain, carried] {
            assert!((s.x[0] - 52f64.ln()).abs() < 1e-12);
        }
        assert!(
            carried.iterations + 1 < plain.iterations,
            "carried {} vs plain {}",
            carried.iterations,
            plain.iterations
        );
        // A wrong slope (wrong sign, far too small or too large) still converges: the
        // bracketing takes over.
        for m in [-50.0, 1e-3, 1e6] {
            let s = solve_1d_with(g, root, 0.5, 1e-12, 60, Some(m)).unwrap();
            assert!((s.x[0] - 52f64.ln()).abs() < 1e-12, "slope {m}: {:?}", s.x);
        }
    }

    #[test]
    fn failure_is_reported() {
        assert!(solve_1d(|x| x * x + 1.0, 0.0, 0.1, 1e-9, 30).is_err());
    }
}
