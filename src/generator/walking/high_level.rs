//! The high-level concepts of §3: completing the locomotion parameters with the normalizing
//! formula (eq. 1) within anatomical limits, the state-phase timings (eq. 2 and the t_ds
//! relation), and step symmetry with the kinematic foot (eq. 3).
//!
//! Units: the paper's relations use m, m/min and steps/min; gaitfit keeps SI inside (m/s,
//! steps/s) and converts here, once, at the boundary.
use super::attributes::WalkAttributes;
use super::body::Body;
use crate::generator::GenerateError;
use crate::relations::walk_sl_sf::WalkSlSf;
use crate::relations::walk_tds_sf::WalkTdsSf;
use crate::units::{km_per_h_to_m_per_s, m_per_min_to_m_per_s, m_per_s_to_m_per_min};
use std::path::Path;

/// The two walking relations KLAW uses, from the relations layer: eq. (1) `sl / (sf·h) = k`
/// ([`WalkSlSf`]) and `t_ds = (d0 + d1·sf)·t_cycle/100` ([`WalkTdsSf`]), published or refitted.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkRelations {
    /// Eq. (1).
    pub sl_sf: WalkSlSf,
    /// The double-support relation.
    pub tds_sf: WalkTdsSf,
}

impl WalkRelations {
    /// The published relations: k = 0.004, d0 = 29.08, d1 = −0.16 (§3).
    pub fn published() -> WalkRelations {
        WalkRelations {
            sl_sf: WalkSlSf::published(),
            tds_sf: WalkTdsSf::published(),
        }
    }

    /// The refitted relations `DIR/walk-sl-sf.json` and `DIR/walk-tds-sf.json` (`--fits DIR`).
    pub fn from_fits_dir(dir: &Path) -> Result<WalkRelations, GenerateError> {
        let load_err = |id: &str, e: String| {
            GenerateError::Parameter {
            name: "fits".into(),
            value: f64::NAN,
            message: format!(
                "{}: {e}; run `gaitfit fit` to write it, or omit --fits to use the published relations",
                dir.join(format!("{id}.json")).display()
            ),
        }
        };
        let sl_sf = WalkSlSf::from_fit_file(&dir.join(format!("{}.json", WalkSlSf::ID)))
            .map_err(|e| load_err(WalkSlSf::ID, e.to_string()))?;
        let tds_sf = WalkTdsSf::from_fit_file(&dir.join(format!("{}.json", WalkTdsSf::ID)))
            .map_err(|e| load_err(WalkTdsSf::ID, e.to_string()))?;
        Ok(WalkRelations { sl_sf, tds_sf })
    }

    /// `k` of eq. (1).
    pub fn k(&self) -> f64 {
        self.sl_sf.k()
    }
    /// `d0`, % of the cycle.
    pub fn d0(&self) -> f64 {
        self.tds_sf.d0()
    }
    /// `d1`, % of the cycle per step/min.
    pub fn d1(&self) -> f64 {
        self.tds_sf.d1()
    }
}

impl Default for WalkRelations {
    fn default() -> Self {
        WalkRelations::published()
    }
}

/// The locomotion parameters as the animator gives them: at least one of the three (§3).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WalkParams {
    /// Forward speed v, m/s.
    pub speed_m_per_s: Option<f64>,
    /// Step length sl, m.
    pub step_length_m: Option<f64>,
    /// Step frequency sf, steps/min (the paper's unit).
    pub step_freq_steps_per_min: Option<f64>,
}

/// Complete, checked locomotion parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Locomotion {
    /// Forward speed, m/s.
    pub speed_m_per_s: f64,
    /// Step length, m.
    pub step_length_m: f64,
    /// Step frequency, steps/min.
    pub step_freq_steps_per_min: f64,
}

fn param_err(name: &str, value: f64, message: String) -> GenerateError {
    GenerateError::Parameter {
        name: name.to_string(),
        value,
        message,
    }
}

fn positive(name: &str, v: Option<f64>) -> Result<Option<f64>, GenerateError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(param_err(
            name,
            x,
            "must be a positive, finite number".into(),
        )),
        other => Ok(other),
    }
}

/// Completes the missing locomotion parameters with eq. (1), `sl / (sf·h) = k`, and `v = sl·sf`,
/// then checks them against the anatomical limits of the attributes.
///
/// ```
/// use gaitfit::generator::walking::high_level::{complete, WalkParams, WalkRelations};
/// use gaitfit::generator::walking::attributes::WalkAttributes;
/// // Fig. 10, top: only v = 5 km/h given, h = 1.8 m → sl ≈ 0.77 m, sf ≈ 107.5 steps/min.
/// let p = WalkParams { speed_m_per_s: Some(5.0 / 3.6), ..Default::default() };
/// let l = complete(&p, 1.8, &WalkRelations::published(), &WalkAttributes::default()).unwrap();
/// assert!((l.step_length_m - 0.77).abs() < 0.005);
/// assert!((l.step_freq_steps_per_min - 107.5).abs() < 0.1);
/// ```
pub fn complete(
    p: &WalkParams,
    height_m: f64,
    rel: &WalkRelations,
    attrs: &WalkAttributes,
) -> Result<Locomotion, GenerateError> {
    let v = positive("speed_m_per_s", p.speed_m_per_s)?.map(m_per_s_to_m_per_min);
    let sl = positive("step_length_m", p.step_length_m)?;
    let sf = positive("step_freq_steps_per_min", p.step_freq_steps_per_min)?;
    let kh = rel.k() * height_m;
    let (v, sl, sf) = match (v, sl, sf) {
        (Some(v), None, None) => {
            // sf² = v / (k·h), eq. (1).
            let sf = rel.sl_sf.step_freq_for_speed(v, height_m);
            (v, v / sf, sf)
        }
        (Some(v), Some(sl), None) => (v, sl, v / sl),
        (Some(v), None, Some(sf)) => (v, v / sf, sf),
        (None, Some(sl), Some(sf)) => (sl * sf, sl, sf),
        (None, Some(sl), None) => {
            let sf = sl / kh;
            (sl * sf, sl, sf)
        }
        (None, None, Some(sf)) => {
            let sl = rel.sl_sf.step_length(sf, height_m);
            (sl * sf, sl, sf)
        }
        (Some(v), Some(sl), Some(sf)) => {
            if ((sl * sf - v) / v).abs() > 0.01 {
                return Err(param_err(
                    "speed_m_per_s",
                    m_per_min_to_m_per_s(v),
                    format!(
                        "inconsistent with step length {sl} m × step frequency {sf} steps/min = {} m/s; \
                         give at most two of the three",
                        m_per_min_to_m_per_s(sl * sf)
                    ),
                ));
            }
            (v, sl, sf)
        }
        (None, None, None) => {
            return Err(param_err(
                "speed_m_per_s",
                f64::NAN,
                "give at least one of speed, step length and step frequency".into(),
            ))
        }
    };
    let l = Locomotion {
        speed_m_per_s: m_per_min_to_m_per_s(v),
        step_length_m: sl,
        step_freq_steps_per_min: sf,
    };
    check_limits(&l, height_m, rel, attrs)?;
    Ok(l)
}

/// Checks complete parameters against the anatomical limits (locomotion attributes) and against
/// the double-support relation (t_ds must stay positive: otherwise the gait is running).
pub fn check_limits(
    l: &Locomotion,
    height_m: f64,
    rel: &WalkRelations,
    a: &WalkAttributes,
) -> Result<(), GenerateError> {
    let sf = l.step_freq_steps_per_min;
    if sf > a.sf_max_steps_per_min {
        return Err(param_err(
            "step_freq_steps_per_min",
            sf,
            format!(
                "above the anatomical limit sf_max = {} steps/min; lower the speed or give a longer \
                 step length (or raise the attribute sf_max_steps_per_min)",
                a.sf_max_steps_per_min
            ),
        ));
    }
    if sf < a.sf_min_steps_per_min {
        return Err(param_err(
            "step_freq_steps_per_min",
            sf,
            format!(
                "below the limit sf_min = {} steps/min; raise the speed or give a shorter step",
                a.sf_min_steps_per_min
            ),
        ));
    }
    let sl = l.step_length_m;
    let (lo, hi) = (
        a.sl_min_per_height * height_m,
        a.sl_max_per_height * height_m,
    );
    if sl > hi || sl < lo {
        return Err(param_err(
            "step_length_m",
            sl,
            format!(
                "outside the anatomical limits {lo:.3} to {hi:.3} m for a body height of {height_m} m \
                 (attributes sl_min_per_height, sl_max_per_height)"
            ),
        ));
    }
    let ds_pct = rel.tds_sf.double_support_pct(sf);
    if ds_pct <= 0.0 || ds_pct >= 50.0 {
        return Err(param_err(
            "step_freq_steps_per_min",
            sf,
            format!(
                "the double-support time (d0 + d1·sf = {ds_pct:.2} % of the cycle) must lie in (0, 50) %: \
                 at this step frequency the gait is not a walk"
            ),
        ));
    }
    Ok(())
}

/// Froude number `v²/(g·l)` above which people change from walking to running.
pub const WALK_RUN_FROUDE: f64 = 0.5;

/// Froude number `v²/(g·l1)` of a walk at `speed` m/s with a leg `l1` m long: the square of
/// [`super::stance::froude_speed`].
pub fn froude_number(speed: f64, l1: f64) -> f64 {
    super::stance::froude_speed(speed, l1).powi(2)
}

/// The note for schedule entry `entry` (1-based) walking at `l` with a body of height
/// `height_m` and leg `l1` (the stance model's, [`Body::l1`]) when its Froude number
/// ([`froude_number`]) exceeds [`WALK_RUN_FROUDE`]: the entry, its speed, the body height, the
/// Froude number and the remedies (a slower speed, a taller body, or `gaitfit generate run`).
/// `None` at or below the transition.
///
/// ```
/// use gaitfit::generator::walking::high_level::{walk_run_note, Locomotion};
/// let l = Locomotion { speed_m_per_s: 7.0 / 3.6, step_length_m: 0.84, step_freq_steps_per_min: 139.0 };
/// let note = walk_run_note(2, &l, 1.5, 0.7234).unwrap();
/// assert!(note.contains("schedule entry 2") && note.contains("0.53"));
/// assert!(walk_run_note(2, &l, 1.8, 0.868).is_none()); // Fr 0.44
/// ```
pub fn walk_run_note(entry: usize, l: &Locomotion, height_m: f64, l1: f64) -> Option<String> {
    let v = l.speed_m_per_s;
    let fr = froude_number(v, l1);
    if fr.is_nan() || fr <= WALK_RUN_FROUDE {
        return None;
    }
    let kmh = |v: f64| v / km_per_h_to_m_per_s(1.0);
    // Fr ∝ v², and ∝ 1/h since l1 is a fixed fraction of the body height (table B-1).
    // Rounded to the printed digits on the safe side: the remedy as printed clears the note.
    let v_max_kmh = (kmh(v * (WALK_RUN_FROUDE / fr).sqrt()) * 100.0).floor() / 100.0;
    let h_min = (height_m * fr / WALK_RUN_FROUDE * 100.0).ceil() / 100.0;
    Some(format!(
        "schedule entry {entry}: {:.2} km/h ({v:.3} m/s) for a body height of {height_m} m is beyond \
         the walk-run transition: Froude number v^2/(g*l1) = {fr:.3} > WALK_RUN_FROUDE = \
         {WALK_RUN_FROUDE} (leg l1 = {l1:.4} m, step {:.2} x l1), where people run; the walk is \
         generated but strained. Walk at most {v_max_kmh:.2} km/h, give a body of at least \
         {h_min:.2} m, or use `gaitfit generate run`",
        kmh(v),
        l.step_length_m / l1,
    ))
}

/// The state-phase timings of one step (eq. 2), seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseTimes {
    /// Step duration `1/sf`.
    pub step: f64,
    /// Cycle duration `2·t_step`.
    pub cycle: f64,
    /// Double support `(d0 + d1·sf)·t_cycle/100`.
    pub double_support: f64,
    /// Stance `t_step + t_ds` (eq. 2).
    pub stance: f64,
    /// Swing `t_step − t_ds` (eq. 2).
    pub swing: f64,
}

/// Eq. (2) and the t_ds relation for a step frequency in steps/min.
///
/// ```
/// use gaitfit::generator::walking::high_level::{phase_times, WalkRelations};
/// let t = phase_times(107.5, &WalkRelations::published());
/// assert!((t.step - 60.0 / 107.5).abs() < 1e-12);
/// assert!((t.double_support - (29.08 - 0.16 * 107.5) * t.cycle / 100.0).abs() < 1e-12);
/// assert!((t.stance - t.double_support - t.step).abs() < 1e-12);
/// assert!((t.swing + t.double_support - t.step).abs() < 1e-12);
/// ```
pub fn phase_times(sf_steps_per_min: f64, rel: &WalkRelations) -> PhaseTimes {
    let step = 60.0 / sf_steps_per_min;
    let cycle = 2.0 * step;
    let double_support = rel.tds_sf.double_support_time(sf_steps_per_min);
    PhaseTimes {
        step,
        cycle,
        double_support,
        stance: step + double_support,
        swing: step - double_support,
    }
}

/// The final conditions of a step at heel strike (eq. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeelStrike {
    /// Stance leg length w (ankle₁ to hip), m.
    pub w: f64,
    /// Stance leg angle θ1, rad (positive: hip ahead of ankle₁).
    pub theta1: f64,
    /// Swing thigh angle θ3 with the knee extended, rad (negative: leg forward).
    pub theta3: f64,
    /// Hip height above the ground at heel strike, m.
    pub hip_height: f64,
    /// Hip-to-heel distance `r` of the extended swing leg with its foot, m.
    pub r: f64,
    /// Angle `ω3` at the hip between the hip–ankle and hip–heel lines, rad.
    pub omega3: f64,
    /// Foot pitch at heel strike (toes up positive), rad.
    pub foot_pitch: f64,
}

/// Eq. (3): w, θ1 and θ3 at heel strike for step length `sl`, ankle angle `theta5` at impact and
/// the swing hip `swing_hip_ahead` m ahead of the stance model's hip (pelvic rotation; 0 in the
/// paper's one-hip model). The stance origin is ankle₁ at height `l9` (the paper's "distance l0
/// above the ground" is a typo for l9: l0 is the pelvis width), the swing heel lands at
/// `x_a + sl − l8` (printed "l_g").
///
/// ```
/// use gaitfit::generator::walking::{body::Body, high_level::heel_strike};
/// let b = Body::from_height(1.8, 80.0).unwrap();
/// let hs = heel_strike(&b, 0.77, 90f64.to_radians(), 0.0).unwrap();
/// assert!(hs.w > b.l1); // the foot raises the hip at impact: w > l1 (§3)
/// assert!(hs.theta3 < 0.0 && -hs.theta3 < hs.theta1); // θ3 negative, |θ3| < θ1
/// ```
pub fn heel_strike(
    b: &Body,
    sl: f64,
    theta5: f64,
    swing_hip_ahead: f64,
) -> Result<HeelStrike, GenerateError> {
    let omega8 = (b.l8 / b.l11).clamp(-1.0, 1.0).acos();
    let r2 = b.l1 * b.l1 + b.l11 * b.l11 - 2.0 * b.l1 * b.l11 * (theta5 + omega8).cos();
    let r = r2.sqrt();
    let omega3 = ((b.l1 * b.l1 + r2 - b.l11 * b.l11) / (2.0 * b.l1 * r))
        .clamp(-1.0, 1.0)
        .acos();
    // Relative to ankle₁ = (0, l9): heel at sl − l8, hip at sl/2 (+ the pelvic offset).
    let dx = sl - b.l8 - (0.5 * sl + swing_hip_ahead);
    if dx.abs() >= r {
        return Err(param_err(
            "step_length_m",
            sl,
            format!("too long for the leg: the heel would be {dx:.3} m ahead of the hip, the leg reaches {r:.3} m"),
        ));
    }
    let hip_height = (r2 - dx * dx).sqrt();
    if hip_height <= b.l9 {
        return Err(param_err(
            "step_length_m",
            sl,
            "too long for the leg: the hip would be below the ankle".into(),
        ));
    }
    let w = ((hip_height - b.l9).powi(2) + 0.25 * sl * sl).sqrt();
    let theta1 = (0.5 * sl / w).asin();
    let theta3 = -omega3 - (dx / r).asin();
    // θ5 = π/2 + foot pitch + shank tilt (shank tilt = θ3 + θ4, θ4 = 0 at heel strike).
    let foot_pitch = theta5 - std::f64::consts::FRAC_PI_2 - theta3;
    Ok(HeelStrike {
        w,
        theta1,
        theta3,
        hip_height,
        r,
        omega3,
        foot_pitch,
    })
}
