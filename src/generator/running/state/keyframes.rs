//! The state keyframes of one step (§3.2): the toe-off leg length of eq. 8, the pelvis at toe
//! off by case I (flight time given, eqs. 7–8) or case II (flight height given: every flight
//! time that gives H bracketed along eqs. 7–8, the one nearest eq. 5's chosen by
//! [`CASE_TWO_RULE`], then the paper's 2-D Newton–Raphson on eqs. 3 and 8), the landing built
//! bottom-up, and the flight time and height.
use super::*;

pub(super) fn numerical(stage: &str, message: String) -> GenerateError {
    GenerateError::Numerical {
        stage: stage.into(),
        message,
    }
}

/// The toe-off leg length `rad` of eq. 8: distance from the toe tip to the hip in the foot's
/// vertical plane for knee flexion `k`, ankle angle `a` and toe angle `m` at toe off, with the
/// hip `dz` to the side of the foot. The chain toe→ankle→hip is a triangle whose angle at the
/// ankle follows from the ankle angle and the knee's offset of the hip–ankle line from the shank.
pub fn toe_off_radius(d: &RunnerDims, k: f64, a: f64, m: f64, dz: f64) -> Option<f64> {
    let dd = d.hip_ankle(k);
    let ds2 = dd * dd - dz * dz;
    if ds2 <= 0.0 {
        return None;
    }
    let ds = ds2.sqrt();
    let tf = d.toe_f(m);
    let r_ta = tf.length();
    let delta = (d.thigh * k.sin() / dd).clamp(-1.0, 1.0).asin();
    let gamma = (std::f64::consts::FRAC_PI_2 - a + delta) - tf.y.atan2(tf.x);
    let rad2 = ds * ds + r_ta * r_ta - 2.0 * ds * r_ta * gamma.cos();
    (rad2 > 0.0).then(|| rad2.sqrt())
}

/// Case II of §3.2: unknowns (x1, y1) of the pelvis at toe off, given H. Residuals: eq. 8
/// (generalised to the hip's offset from the pelvis centre) and eq. 3 with eq. 7's
/// t = (x2 − x1)/v substituted (the paper prints "(x2 − x1)/y1", a typo: eq. 7 gives
/// t_flight = (x2 − x1)/v). Eq. 3 is used unsquared, g·t/2 − (y1 − y2)/t = √(2gH), which picks
/// the branch with the apex after toe off.
struct CaseTwo {
    rad: f64,
    off: DVec3,
    x_toe: f64,
    x2: f64,
    y2: f64,
    v: f64,
    h: f64,
}

impl CaseTwo {
    fn parts(&self, x1: f64) -> (f64, f64) {
        let xh = x1 + self.off.x - self.x_toe;
        (xh, (self.rad * self.rad - xh * xh).max(1e-12).sqrt())
    }
}

impl Operator for CaseTwo {
    type Param = Vector2<f64>;
    type Output = Vector2<f64>;
    fn apply(&self, p: &Self::Param) -> Result<Self::Output, argmin::core::Error> {
        let (x1, y1) = (p[0], p[1]);
        let (_, root) = self.parts(x1);
        let t = (self.x2 - x1) / self.v;
        let r1 = y1 + self.off.y - root;
        let r2 = 0.5 * G * t - (y1 - self.y2) / t - (2.0 * G * self.h).sqrt();
        Ok(Vector2::new(r1, r2))
    }
}

impl Jacobian for CaseTwo {
    type Param = Vector2<f64>;
    type Jacobian = Matrix2<f64>;
    fn jacobian(&self, p: &Self::Param) -> Result<Self::Jacobian, argmin::core::Error> {
        let (x1, y1) = (p[0], p[1]);
        let (xh, root) = self.parts(x1);
        let t = (self.x2 - x1) / self.v;
        let dr2_dt = 0.5 * G + (y1 - self.y2) / (t * t);
        Ok(Matrix2::new(xh / root, 1.0, -dr2_dt / self.v, -1.0 / t))
    }
}

impl CostFunction for CaseTwo {
    type Param = Vector2<f64>;
    type Output = f64;
    fn cost(&self, p: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(self.apply(p)?.norm())
    }
}

/// Solves case II with argmin's Gauss–Newton, which on a square system with an invertible
/// Jacobian takes exactly the Newton–Raphson step J⁻¹r of the paper's 2-D method.
fn solve_case_two(problem: CaseTwo, guess: (f64, f64)) -> Result<(f64, f64), GenerateError> {
    let h = problem.h;
    let solver = GaussNewton::new()
        .with_tolerance(1e-15)
        .map_err(|e| numerical("case II Newton-Raphson", e.to_string()))?;
    let check = CaseTwo { ..problem };
    let res = Executor::new(problem, solver)
        .configure(|s| {
            s.param(Vector2::new(guess.0, guess.1))
                .max_iters(60)
                .target_cost(1e-12)
        })
        .run()
        .map_err(|e| numerical("case II Newton-Raphson", format!("H = {h} m: {e}")))?;
    let p = res
        .state()
        .get_best_param()
        .copied()
        .unwrap_or(Vector2::new(guess.0, guess.1));
    let r = check.apply(&p).map(|r| r.norm()).unwrap_or(f64::INFINITY);
    if r.is_nan() || r >= 1e-9 || !p[0].is_finite() || !p[1].is_finite() {
        return Err(numerical(
            "case II Newton-Raphson",
            format!("no toe-off pelvis gives flight height H = {h} m (residual {r:.3e}); lower H or unlock the step frequency"),
        ));
    }
    Ok((p[0], p[1]))
}

/// Case II's rule when eq. 3 gives several flight times for one flight height H: the one nearest
/// the flight-time relation's (eq. 5 at the step frequency) is used. Along the toe-off leg's
/// circle (eqs. 7–8) H(t) is large at short flights (the pelvis must climb from a low toe off in
/// little time), falls to a minimum and grows again with the ballistic g·t/2, so an H above the
/// minimum is reached twice, and which root is the runner's differs: at 2.5 m/s and 1.6 m the
/// published relation's 0.189 s flight is the long root (the other is 0.029 s), while with the
/// refitted `fits/` at 3 m/s the measured 0.080 s is the short one (the other 0.196 s). With this
/// rule case I at eq. 5's flight time and case II at the H it gives return the same flight time
/// (`tests/run_case_two.rs`).
pub const CASE_TWO_RULE: &str = "the flight time nearest the flight-time relation's (eq. 5)";

/// Every flight time t in (0, `t_max`] at which eq. 3's unsquared form, g·t/2 − (y1(t) − y2)/t =
/// √(2gH), holds, ascending; `y1(t)` is the toe-off pelvis height of case I (eqs. 7–8), `None`
/// where the toe-off leg cannot reach. A scan of 400 intervals brackets the sign changes, then
/// bisection to 1e-12 s.
pub(super) fn case_two_flight_times(
    y1: impl Fn(f64) -> Option<f64>,
    y2: f64,
    h: f64,
    t_max: f64,
) -> Vec<f64> {
    let w = (2.0 * G * h).sqrt();
    let r = |t: f64| y1(t).map(|y| 0.5 * G * t - (y - y2) / t - w);
    let n = 400;
    let mut roots = Vec::new();
    let mut prev: Option<(f64, f64)> = None;
    for i in 1..=n {
        let t = t_max * i as f64 / n as f64;
        let cur = r(t).map(|v| (t, v));
        if let (Some((ta, ra)), Some((tb, rb))) = (prev, cur) {
            if ra == 0.0 {
                roots.push(ta);
            } else if ra * rb < 0.0 {
                let (mut lo, mut hi, mut rlo) = (ta, tb, ra);
                while hi - lo > 1e-12 {
                    let mid = 0.5 * (lo + hi);
                    match r(mid) {
                        Some(rm) if rm * rlo > 0.0 => {
                            lo = mid;
                            rlo = rm;
                        }
                        Some(_) => hi = mid,
                        None => break,
                    }
                }
                roots.push(0.5 * (lo + hi));
            }
        }
        prev = cur;
    }
    roots
}

/// Least support time as a fraction of the step. Eqs. 4–5 never ask for less (published: ≥ 26 %
/// up to 25 km/h and +10 % step frequency), but a refitted eq. 5 extrapolated beyond its data
/// can (0.231 s of flight in a 0.243 s step), and the legs then whirl through the support;
/// sprinters' support is about 40 % of the step.
pub const MIN_STANCE_FRACTION: f64 = 0.25;

/// Longest overstride the landing may be moved ahead to for long supports, m at 1.8 m (the
/// attribute's range).
pub const OVERSTRIDE_MAX: f64 = 0.4;

/// Toe-off leg lean (hip ahead of the toe tip, from the vertical) beyond which a long support
/// moves the landing ahead, rad. Real runners leave the ground at about 30–40°; the published
/// relations' runs stay at or under 26°, so they are unaffected.
pub const TOE_OFF_LEAN_MAX: f64 = 30.0 * std::f64::consts::PI / 180.0;

/// The state keyframes of one step (§3.2): the pelvis at toe off (p1) and at the next heel
/// strike (p2), the flight time and height, and what the rest of the plan needs from them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateKeys {
    /// Where the other foot lands.
    pub next_print: Footprint,
    /// Pelvis at toe off (x1, y1, z1).
    pub p1: DVec3,
    /// Pelvis at the next heel strike (x2, y2, z2).
    pub p2: DVec3,
    /// Flight time, s.
    pub t_flight: f64,
    /// Support time, s.
    pub t_stance: f64,
    /// Case II only: the next flight time that gives the same flight height (eq. 3 has, in
    /// general, two; [`CASE_TWO_RULE`] chose `t_flight`), s; `None` for case I or one root.
    pub other_flight_time: Option<f64>,
    /// Flight height by eq. 3, m.
    pub flight_height: f64,
    /// Vertical take-off velocity, m/s.
    pub w: f64,
    /// Toe-off leg length (eq. 8's rad), m.
    pub rad: f64,
    /// Case I or II.
    pub case: FlightCase,
    /// Landing hip relative to the pelvis at heel strike (world frame).
    pub o2: DVec3,
    /// Pelvic rotation at toe off, rad.
    pub yaw1: f64,
    /// Pelvic rotation at heel strike, rad.
    pub yaw2: f64,
    /// Pelvic list at heel strike, rad.
    pub roll2: f64,
    /// Heel of the next footprint ahead of the pelvis at its heel strike, m: the overstride
    /// attribute, or more for a long support (see [`TOE_OFF_LEAN_MAX`]).
    pub overstride: f64,
}

/// Computes the state keyframes for a step whose stance foot (side sign `s`) is planted at
/// `fp`: heel position at the end of the step, the pelvis at heel strike bottom-up, and the
/// pelvis at toe off by case I (eqs. 7–8) or case II (Newton–Raphson on eqs. 3 and 8).
pub fn state_keyframes(
    d: &RunnerDims,
    inp: &StepInput,
    s: f64,
    fp: &Footprint,
) -> Result<StateKeys, GenerateError> {
    let e = inp.eff;
    let (v, sl, sf) = (inp.speed, inp.step_length, inp.step_freq);
    let t_step = 1.0 / sf;
    let (rot_max, list_max, lat_max) = (e.pelvic_rotation, e.pelvic_list, e.lateral_displacement);
    // Fig. 7: at heel strike 20 % rotation (landing hip forward), 80 % list (swing side down),
    // 80 % lateral displacement toward the landing foot.
    let (yaw2, roll2, z2) = (-s * 0.2 * rot_max, s * 0.8 * list_max, -s * 0.8 * lat_max);
    let o2 = pelvis_matrix(yaw2, roll2) * d.hip_local(-s);
    let scale = d.body_height / 1.8;
    // --- Heel strike at the end of the step (HSL), bottom-up, for a landing `os` ahead. ---
    let landing = |os: f64| -> Result<(Footprint, f64, f64), GenerateError> {
        let next_print = Footprint {
            heel: DVec3::new(fp.heel.x + sl, 0.0, -s * e.stride_width / 2.0),
            strike: e.strike,
            impact_pitch: if os > e.overstride {
                hidden_impact_pitch(os / scale, e.strike)
            } else {
                e.impact_pitch
            },
        };
        let x2 = next_print.heel.x - os;
        let a2 = next_print.impact_ankle(d);
        let dd2 = d.hip_ankle(e.knee_heel_strike);
        let (dx2, dz2) = (x2 + o2.x - a2.x, z2 + o2.z - a2.z);
        let r2 = dd2 * dd2 - dx2 * dx2 - dz2 * dz2;
        if r2 <= 0.0 {
            return Err(GenerateError::Parameter {
                name: "overstride".into(),
                value: os,
                message: format!(
                    "the landing leg cannot reach its heel {:.3} m ahead and {:.3} m aside of the hip; lower overstride or stride width",
                    -dx2, dz2.abs()
                ),
            });
        }
        Ok((next_print, x2, a2.y + r2.sqrt() - o2.y))
    };

    // --- Toe off of the stance leg (TOR), backwards from HSL. ---
    let x_toe = fp.heel.x + d.foot_length();
    let (yaw1, z1) = (-s * rot_max, s * 0.8 * lat_max); // rotation maximal, list zero
    let o1 = pelvis_matrix(yaw1, 0.0) * d.hip_local(s);
    let dz1 = z1 + o1.z - fp.heel.z;
    let rad = toe_off_radius(d, e.knee_toe_off, e.ankle_toe_off, e.meta_toe_off, dz1).ok_or_else(|| {
        numerical("toe-off leg", format!("the hip is {dz1:.3} m aside of the foot, beyond the leg; lower stride width or lateral displacement"))
    })?;
    let case_one = |x2: f64, t_f: f64| -> Result<(f64, f64), GenerateError> {
        // Eq. 7: x1 = x2 − v·t_flight; eq. 8: y1 = √(rad² − (x1 − x_toe)²), for the hip.
        let x1 = x2 - v * t_f;
        let xh = x1 + o1.x - x_toe;
        if xh.abs() >= rad {
            return Err(numerical(
                "toe-off pelvis (eq. 8)",
                format!(
                    "the toe-off leg ({rad:.3} m) cannot reach from the toe to a hip {xh:.3} m ahead of it \
                     (v = {v:.3} m/s, sl = {sl:.3} m, t_flight = {t_f:.3} s); the step is too long or too short for its flight time"
                ),
            ));
        }
        Ok((x1, (rad * rad - xh * xh).sqrt() - o1.y))
    };
    // Long supports (a refitted eq. 5's short flights at high speed: 1.1 m of ground in 0.22 s
    // at 18 km/h) cannot all be covered behind the toe: the toe-off hip would sink (0.69 m vs
    // 1.02 m with the published flights). Real runners then land further ahead. The paper keeps
    // overstride an attribute; here, with the flight time given (case I), the landing moves
    // ahead (the attribute stays the least overstride) until the pelvis takes off no lower than
    // it lands (the take-off of an unforced flight), or the toe-off leg leans no more than
    // TOE_OFF_LEAN_MAX; the published relations never lean it further (≤ 26° over 2–25 km/h).
    // Case II plans the landing for the flight time it chooses by (`near`, the relation's), so
    // that case I at a flight time and case II at the H it gives plan the same step.
    let mut os = e.overstride;
    let planned_flight = match inp.flight {
        FlightSpec::Time(t_f) => t_f,
        FlightSpec::Height { near, .. } => near,
    };
    {
        let t_f = planned_flight;
        let gap = |os: f64| match landing(os) {
            Err(_) => f64::INFINITY,
            Ok((_, x2, y2)) => match case_one(x2, t_f) {
                Ok((x1, y1)) => (y1 - y2).max(rad * TOE_OFF_LEAN_MAX.sin() - (x1 + o1.x - x_toe)),
                Err(_) if x2 - v * t_f + o1.x > x_toe => f64::NEG_INFINITY,
                Err(_) => f64::INFINITY,
            },
        };
        if gap(os) < 0.0 {
            let (mut lo, mut hi) = (os, OVERSTRIDE_MAX * scale);
            if gap(hi) >= 0.0 {
                for _ in 0..50 {
                    let mid = 0.5 * (lo + hi);
                    if gap(mid) < 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                // The reachable side of the bracket, so that the landing leg reaches its heel.
                os = if gap(hi).is_finite() { hi } else { lo };
            }
        }
    }
    let (next_print, x2, y2) = landing(os)?;
    let mut other_flight_time = None;
    let (x1, y1, t_flight, case) = match inp.flight {
        FlightSpec::Time(t_f) => {
            let (x1, y1) = case_one(x2, t_f)?;
            (x1, y1, t_f, FlightCase::I)
        }
        FlightSpec::Height { height: h, near } => {
            // Eq. 3 with eqs. 7–8 has, in general, two flight times for one H (H(t) falls from
            // the take-off's height difference at short flights and rises with the ballistic
            // g·t/2 at long ones): all are found along case I's toe-off pelvis, the shortest is
            // used by `CASE_TWO_RULE` (nearest the flight-time relation's) and the nearest other
            // one is reported. Newton–Raphson then refines it, as the paper solves case II.
            let t_max = (1.0 - MIN_STANCE_FRACTION) * t_step;
            let roots =
                case_two_flight_times(|t| case_one(x2, t).ok().map(|(_, y1)| y1), y2, h, t_max);
            let by_distance = |t: &f64| (t - near).abs();
            let mut sorted = roots.clone();
            sorted.sort_by(|a, b| by_distance(a).total_cmp(&by_distance(b)));
            let Some(&guess_t) = sorted.first() else {
                return Err(numerical(
                    "case II",
                    format!(
                        "no flight time up to {t_max:.3} s (a support of at least {:.0} % of the \
                         step) gives flight height H = {h} m at v = {v:.3} m/s, sl = {sl:.3} m; \
                         lower H or unlock the step frequency",
                        MIN_STANCE_FRACTION * 100.0
                    ),
                ));
            };
            other_flight_time = sorted.get(1).copied();
            let (gx, gy) = case_one(x2, guess_t)?;
            let (x1, y1) = solve_case_two(
                CaseTwo {
                    rad,
                    off: o1,
                    x_toe,
                    x2,
                    y2,
                    v,
                    h,
                },
                (gx, gy),
            )?;
            (x1, y1, (x2 - x1) / v, FlightCase::II)
        }
    };
    if !(t_flight > 0.0 && t_flight < t_step) {
        return Err(numerical(
            "flight time",
            format!("t_flight = {t_flight:.4} s must lie within (0, 1/sf = {t_step:.4} s); lower the flight height or the step frequency"),
        ));
    }
    let t_stance = t_step - t_flight;
    if t_stance < MIN_STANCE_FRACTION * t_step {
        return Err(numerical(
            "flight time",
            format!(
                "t_flight = {t_flight:.4} s leaves a support of {t_stance:.4} s, under {:.0} % of the step (1/sf = {t_step:.4} s), which no leg can push off in; lower the flight height or the step frequency (or, with --fits, keep to the step frequencies the refitted eq. 5 was fitted on)",
                MIN_STANCE_FRACTION * 100.0
            ),
        ));
    }
    let w = (y2 - y1) / t_flight + 0.5 * G * t_flight; // vertical take-off velocity
    let flight_height = w * w / (2.0 * G); // eq. 3
    Ok(StateKeys {
        next_print,
        p1: DVec3::new(x1, y1, z1),
        p2: DVec3::new(x2, y2, z2),
        t_flight,
        t_stance,
        flight_height,
        w,
        rad,
        case,
        other_flight_time,
        o2,
        yaw1,
        yaw2,
        roll2,
        overstride: os,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::running::attributes::{Drivers, RunAttributes};

    #[test]
    fn toe_off_radius_matches_forward_kinematics() {
        let d = RunnerDims::from_height(1.8).unwrap();
        let (k, a, m) = (0.35, -0.6, 0.5);
        let rad = toe_off_radius(&d, k, a, m, 0.0).unwrap();
        for pitch in [-0.5, -0.2, 0.1] {
            let ang = LegAngles {
                pitch,
                roll: 0.0,
                knee: k,
                ankle: a,
                meta: m,
            };
            let p = leg_fk(&d, DVec3::ZERO, &ang);
            assert!(((p.toe - p.hip).length() - rad).abs() < 1e-12);
        }
    }

    #[test]
    fn case_two_inverts_case_one() {
        let d = RunnerDims::from_height(1.8).unwrap();
        let attrs = RunAttributes::defaults(1.8);
        let v = 12.0 / 3.6;
        let sl = 1.0694;
        let sf = v / sl;
        let eff = attrs.effective(&Drivers {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight_height: 0.004,
        });
        let mut carry = standing_carry(&d, &eff, 0.0, 1.0, f64::INFINITY);
        carry.standing = false;
        carry.pelvis_vel = DVec3::new(v, -1.0, 0.0);
        let inp = StepInput {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight: FlightSpec::Time(0.188),
            eff,
            next_eff: eff,
            p: 0.75,
        };
        let one = plan_step(&d, &inp, &carry, StepKind::Normal).unwrap();
        let h = one.report.flight_height;
        let inp2 = StepInput {
            flight: FlightSpec::Height {
                height: h,
                near: 0.188,
            },
            ..inp
        };
        let two = plan_step(&d, &inp2, &carry, StepKind::Normal).unwrap();
        assert_eq!(two.report.case, Some(FlightCase::II));
        assert!((two.t_flight - 0.188).abs() < 1e-9, "{}", two.t_flight);
        assert!((two.report.p1 - one.report.p1).length() < 1e-9);
    }
}
