//! The integrator: classical fixed-step Runge–Kutta 4 with exact phase ends, events located on
//! the discrete flow, and a step size proven stable for the stiffness in use.
//!
//! **Why this integrator.** The paper used LSODE (an implicit, A-stable BDF code) because the
//! spring–damper terms (leg spring `k_w`, `v_w`; upper-body and hip springs) can make the system
//! stiff. With the default locomotion attributes the stiffest mode of the linearized equations
//! has |λ| ≈ 20–60 s⁻¹ (see [`spectral_radius`]), so over a phase of 0.1–1 s the stiffness ratio
//! is modest and an explicit method is both accurate and far cheaper than Newton iterations on an
//! implicit stage. We keep RK4 unconditionally safe for any attribute values by choosing the step
//! `h ≤ RK4_SAFE_RADIUS / ρ`, where `ρ` bounds the spectral radius of the Jacobian: the RK4
//! stability polynomial satisfies |R(z)| ≤ 1 on the half disk |z| ≤ 2, Re z ≤ 0 (tested below),
//! so every damped mode is integrated stably; stiffer user attributes just mean smaller steps.
//!
//! A *fixed* step (each phase divided into equal steps that land exactly on its end) also makes
//! the final state a smooth function of the force parameters, which the shooting method
//! ([`super::shooting`]) needs: adaptive step-size control would add noise of the order of its
//! tolerance to every residual and stall the secant iteration.

/// Radius of the left half disk on which RK4 is stable with margin (|R(z)| ≤ 1 up to ≈ 2.6).
pub const RK4_SAFE_RADIUS: f64 = 2.0;

/// The RK4 stability polynomial `R(z) = 1 + z + z²/2 + z³/6 + z⁴/24` (complex `z = (re, im)`).
pub fn rk4_amplification(re: f64, im: f64) -> f64 {
    // Horner in complex arithmetic.
    let coeffs = [1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0, 1.0];
    let (mut pr, mut pi) = (0.0, 0.0);
    for c in coeffs {
        let (nr, ni) = (pr * re - pi * im + c, pr * im + pi * re);
        pr = nr;
        pi = ni;
    }
    (pr * pr + pi * pi).sqrt()
}

/// One classical RK4 step of size `h` from `(t, y)`.
#[inline]
pub fn rk4_step<const N: usize, F>(f: &mut F, t: f64, y: &[f64; N], h: f64) -> [f64; N]
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
{
    let k1 = f(t, y);
    let mut tmp = [0.0; N];
    for i in 0..N {
        tmp[i] = y[i] + 0.5 * h * k1[i];
    }
    let k2 = f(t + 0.5 * h, &tmp);
    for i in 0..N {
        tmp[i] = y[i] + 0.5 * h * k2[i];
    }
    let k3 = f(t + 0.5 * h, &tmp);
    for i in 0..N {
        tmp[i] = y[i] + h * k3[i];
    }
    let k4 = f(t + h, &tmp);
    let mut out = [0.0; N];
    for i in 0..N {
        out[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

/// Number of equal steps of at most `h_max` covering `duration`.
pub fn step_count(duration: f64, h_max: f64) -> usize {
    if duration <= 0.0 {
        return 0;
    }
    ((duration / h_max).ceil() as usize).max(1)
}

/// How an integration segment ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentEnd<const N: usize> {
    /// Time reached, s.
    pub t: f64,
    /// State reached.
    pub y: [f64; N],
    /// Whether the event function crossed zero (upwards) before `t1`.
    pub event: bool,
}

/// Integrates from `(t0, y0)` to `t1` in equal steps of at most `h_max`, calling `observe` after
/// every step (with the step's start state and end state). If `event` is given, stops at the
/// first upward zero crossing of `event(t, y)`, located on the discrete flow (the crossing time
/// τ solves `event(t + τ, RK4(y, τ)) = 0` by the Illinois method, to 1e-12 s), so the event time
/// is a smooth function of the parameters.
pub fn integrate<const N: usize, F, E, O>(
    f: &mut F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    h_max: f64,
    mut event: Option<&mut E>,
    observe: &mut O,
) -> SegmentEnd<N>
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
    E: FnMut(f64, &[f64; N]) -> f64,
    O: FnMut(f64, &[f64; N], f64, &[f64; N]),
{
    let n = step_count(t1 - t0, h_max);
    if n == 0 {
        return SegmentEnd {
            t: t0,
            y: y0,
            event: false,
        };
    }
    let h = (t1 - t0) / n as f64;
    let mut y = y0;
    let mut g_prev = event.as_mut().map(|e| e(t0, &y0));
    for k in 0..n {
        let t = t0 + k as f64 * h;
        let t_next = if k + 1 == n {
            t1
        } else {
            t0 + (k + 1) as f64 * h
        };
        let y_next = rk4_step(f, t, &y, t_next - t);
        if let (Some(e), Some(gp)) = (event.as_mut(), g_prev) {
            let g = e(t_next, &y_next);
            if gp < 0.0 && g >= 0.0 {
                // The crossing time τ ∈ (0, h] on the discrete flow (a zero joins the
                // after-the-event side).
                let r = crate::generator::numeric::illinois(
                    |tau| e(t + tau, &rk4_step(f, t, &y, tau)),
                    (0.0, gp),
                    (t_next - t, g),
                    crate::generator::numeric::Stop {
                        f_tol: 1e-14,
                        x_tol: 1e-12,
                        max_evals: 60,
                    },
                );
                let tau = match r.status {
                    crate::generator::numeric::Status::Narrow => r.b.0,
                    _ if r.last.0.is_finite() => r.last.0,
                    _ => r.b.0,
                };
                let yt = rk4_step(f, t, &y, tau);
                observe(t, &y, t + tau, &yt);
                return SegmentEnd {
                    t: t + tau,
                    y: yt,
                    event: true,
                };
            }
            g_prev = Some(g);
        }
        observe(t, &y, t_next, &y_next);
        y = y_next;
    }
    SegmentEnd {
        t: t1,
        y,
        event: false,
    }
}

/// Spectral radius of the Jacobian of `f` at `(t, y)` (central differences, QR eigenvalues).
pub fn spectral_radius<const N: usize, F>(f: &mut F, t: f64, y: &[f64; N]) -> f64
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
{
    let mut jac = nalgebra::DMatrix::<f64>::zeros(N, N);
    for j in 0..N {
        let d = 1e-6 * (1.0 + y[j].abs());
        let mut yp = *y;
        let mut ym = *y;
        yp[j] += d;
        ym[j] -= d;
        let fp = f(t, &yp);
        let fm = f(t, &ym);
        for i in 0..N {
            jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * d);
        }
    }
    jac.complex_eigenvalues()
        .iter()
        .map(|c| c.norm())
        .fold(0.0, f64::max)
}

/// The largest RK4 step that is stable for a system whose Jacobian has spectral radius `rho`,
/// capped at `h_accuracy`.
pub fn stable_step(rho: f64, h_accuracy: f64) -> f64 {
    if rho > 0.0 && rho.is_finite() {
        h_accuracy.min(RK4_SAFE_RADIUS / rho)
    } else {
        h_accuracy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rk4_is_stable_on_the_safe_half_disk() {
        // Dense polar grid of the half disk |z| ≤ RK4_SAFE_RADIUS, Re z ≤ 0.
        for i in 0..=200 {
            let r = RK4_SAFE_RADIUS * i as f64 / 200.0;
            for j in 0..=180 {
                let phi = std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * j as f64 / 180.0;
                let a = rk4_amplification(r * phi.cos(), r * phi.sin());
                assert!(a <= 1.0 + 1e-12, "|R| = {a} at r = {r}, φ = {phi}");
            }
        }
        // And not far beyond it on the real axis (the known limit is ≈ −2.785).
        assert!(rk4_amplification(-2.9, 0.0) > 1.0);
    }

    #[test]
    fn rk4_has_fourth_order_and_lands_on_the_end() {
        // y' = −y, y(0) = 1 over [0, 1].
        let err = |h: f64| {
            let mut f = |_t: f64, y: &[f64; 1]| [-y[0]];
            let end = integrate::<1, _, fn(f64, &[f64; 1]) -> f64, _>(
                &mut f,
                0.0,
                [1.0],
                1.0,
                h,
                None,
                &mut |_, _, _, _| {},
            );
            assert_eq!(end.t, 1.0);
            (end.y[0] - (-1.0f64).exp()).abs()
        };
        let ratio = err(0.1) / err(0.05);
        assert!((ratio - 16.0).abs() < 1.0, "order ratio {ratio}");
    }

    #[test]
    fn event_is_located_on_the_discrete_flow() {
        // Free fall from 1 m: y reaches 0 at sqrt(2/g).
        let g = 9.81;
        let mut f = |_t: f64, y: &[f64; 2]| [y[1], -g];
        let mut ev = |_t: f64, y: &[f64; 2]| -y[0];
        let end = integrate(
            &mut f,
            0.0,
            [1.0, 0.0],
            2.0,
            0.01,
            Some(&mut ev),
            &mut |_, _, _, _| {},
        );
        assert!(end.event);
        assert!((end.t - (2.0 / g).sqrt()).abs() < 1e-10, "t = {}", end.t);
        assert!(end.y[0].abs() < 1e-10);
    }

    #[test]
    fn stable_step_bounds_a_stiff_damper() {
        // x'' = −k x − c x' with c = 5000 s⁻¹: ρ ≈ 5000, the chosen step keeps RK4 bounded.
        let (k, c) = (1.0e4, 5.0e3);
        let mut f = |_t: f64, y: &[f64; 2]| [y[1], -k * y[0] - c * y[1]];
        let rho = spectral_radius(&mut f, 0.0, &[1.0, 0.0]);
        assert!((rho - c).abs() / c < 0.01, "ρ = {rho}");
        let h = stable_step(rho, 0.01);
        let end = integrate::<2, _, fn(f64, &[f64; 2]) -> f64, _>(
            &mut f,
            0.0,
            [1.0, 0.0],
            1.0,
            h,
            None,
            &mut |_, _, _, _| {},
        );
        assert!(end.y[0].abs() < 1.0 && end.y[1].abs() < 10.0, "{:?}", end.y);
    }
}
