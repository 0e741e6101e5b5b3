//! The studio's controls: every parameter, body measure and attribute of a generator, with its
//! unit and range taken from the generator's own tables (RUNNER's [`SPECS`], KLAW's
//! [`ATTRIBUTES`]) and limits ([`SPEED_RANGE`], [`SF_SEARCH`], [`LEVEL_RANGE`], the anthropometry's
//! [`HEIGHT_RANGE_M`] and [`MASS_RANGE_KG`], KLAW's anatomical limits). The page draws whatever
//! this module lists; it holds no second copy of a range.
//!
//! Values cross the page boundary in the units the controls show (km/h, degrees, steps/min) and
//! are converted to SI here, once.
use crate::generator::anthropometry::{HEIGHT_RANGE_M, MASS_RANGE_KG};
use crate::generator::running::attributes::{AttrUnit, SPECS};
use crate::generator::running::equations::RunRelations;
use crate::generator::running::params::{
    default_mass, HEIGHT_RANGE as RUN_HEIGHT_RANGE, LEVEL_RANGE, SF_SEARCH, SPEED_RANGE,
};
use crate::generator::walking::{WalkAttributes, WalkOptions, ATTRIBUTES};
use serde::Serialize;

/// Speed control, km/h (the papers quote speeds in km/h).
pub const SPEED: &str = "speed_km_per_h";
/// Step length control, m.
pub const STEP_LENGTH: &str = "step_length_m";
/// Step frequency control, steps/min (the papers' unit).
pub const STEP_FREQ: &str = "step_freq_steps_per_min";
/// Flight height control (RUNNER's H, eq. 3), m.
pub const FLIGHT_HEIGHT: &str = "flight_height_m";
/// Expertise level control (RUNNER), −1 … 1.
pub const LEVEL: &str = "level";
/// Body height control, m.
pub const HEIGHT: &str = "height_m";
/// Body mass control, kg.
pub const MASS: &str = "mass_kg";
/// Prefix of attribute controls: `attr.<name>` with the generator's attribute name.
pub const ATTR_PREFIX: &str = "attr.";

/// The parameters that can be locked, in the order the papers list them.
pub const LOCKABLE: [&str; 4] = [SPEED, STEP_LENGTH, STEP_FREQ, FLIGHT_HEIGHT];

/// Number of slider positions across a range (the slider's resolution; number inputs beside
/// the sliders take any value).
const SLIDER_STEPS: f64 = 400.0;

/// One control of the page.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Control {
    /// Key the page sends the value under (`speed_km_per_h`, `attr.bounciness`, …).
    pub key: String,
    /// `parameter`, `body` or `attribute`.
    pub group: &'static str,
    /// Label shown.
    pub label: String,
    /// Unit shown.
    pub unit: String,
    /// Lower end of the slider.
    pub min: f64,
    /// Upper end of the slider.
    pub max: f64,
    /// Slider step.
    pub step: f64,
    /// Current value (after the locks and relations resolved the request).
    pub value: f64,
    /// Default value.
    pub default: f64,
    /// Whether the parameter can be locked (kept while another one moves).
    pub lockable: bool,
    /// What it does (from the generator's tables).
    pub doc: String,
    /// For a switch: the values and their names (RUNNER's heel/toe strike).
    pub choices: Vec<(f64, String)>,
}

impl Control {
    fn new(key: &str, group: &'static str, label: &str, unit: &str, range: (f64, f64)) -> Self {
        Control {
            key: key.to_string(),
            group,
            label: label.to_string(),
            unit: unit.to_string(),
            min: range.0,
            max: range.1,
            step: nice_step((range.1 - range.0) / SLIDER_STEPS),
            value: range.0,
            default: range.0,
            lockable: false,
            doc: String::new(),
            choices: Vec::new(),
        }
    }
    fn doc(mut self, doc: &str) -> Self {
        self.doc = doc.trim().to_string();
        self
    }
    fn lockable(mut self) -> Self {
        self.lockable = true;
        self
    }
    fn value(mut self, value: f64, default: f64) -> Self {
        self.value = value;
        self.default = default;
        // A locked stride may lie outside the natural range the slider spans: widen it.
        if value.is_finite() {
            self.min = self.min.min(value);
            self.max = self.max.max(value);
        }
        self
    }
}

/// The largest of 1, 2, 5 × 10ⁿ not above `x` (a slider step that prints cleanly).
fn nice_step(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let e = x.log10().floor();
    let base = 10f64.powf(e);
    let m = x / base;
    let k = if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    };
    k * base
}

/// Body heights every generator accepts, m: the anthropometry's range, narrowed by RUNNER's.
pub fn height_range(run: bool) -> (f64, f64) {
    if run {
        (
            HEIGHT_RANGE_M.0.max(RUN_HEIGHT_RANGE.0),
            HEIGHT_RANGE_M.1.min(RUN_HEIGHT_RANGE.1),
        )
    } else {
        HEIGHT_RANGE_M
    }
}

/// The current parameter values of a motion (SI), as the controls show them after resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamValues {
    /// Speed, m/s.
    pub speed_m_per_s: f64,
    /// Step length, m.
    pub step_length_m: f64,
    /// Step frequency, steps/min.
    pub step_freq_steps_per_min: f64,
    /// RUNNER's flight height H, m (running only).
    pub flight_height_m: Option<f64>,
    /// RUNNER's flight time, s (running only).
    pub flight_time_s: Option<f64>,
    /// RUNNER's expertise level (running only).
    pub level: Option<f64>,
    /// Body height, m.
    pub height_m: f64,
    /// Body mass, kg (not used by RUNNER's kinematics: not shown for a run).
    pub mass_kg: Option<f64>,
}

/// RUNNER's controls: the parameter panel of Fig. 4 and the attribute panel of Fig. 5.
/// `attrs` are the current settings (SI); `h_max` the largest steady flight height over the
/// speed range (the flight-height slider's end, from [`run_flight_height_span`]).
pub fn run_controls(
    p: &ParamValues,
    attrs: &crate::generator::running::RunAttributes,
    relations: &RunRelations,
    h_max: f64,
) -> Vec<Control> {
    let h = p.height_m;
    // Step lengths along eq. 2 over the speed range, at both ends of the level range.
    let sls = [SPEED_RANGE.0, SPEED_RANGE.1]
        .iter()
        .flat_map(|&v| [LEVEL_RANGE.0, LEVEL_RANGE.1].map(|l| relations.step_length(v, l, h)))
        .collect::<Vec<_>>();
    let sl_range = (
        sls.iter().copied().fold(f64::INFINITY, f64::min),
        sls.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let mut out = vec![
        Control::new(SPEED, "parameter", "speed v", "km/h", (SPEED_RANGE.0 * 3.6, SPEED_RANGE.1 * 3.6))
            .doc("eq. 1: v = sl·sf; changing it updates the unlocked parameters by eqs. 1–5 (§3.1.1)")
            .lockable()
            .value(p.speed_m_per_s * 3.6, 12.0),
        Control::new(STEP_LENGTH, "parameter", "step length sl", "m", sl_range)
            .doc("eq. 2 (Froude-normalised, with plateau at v_norm); slider spans eq. 2 over the speed and level ranges")
            .lockable()
            .value(p.step_length_m, relations.step_length(12.0 / 3.6, 0.0, h)),
        Control::new(STEP_FREQ, "parameter", "step frequency sf", "steps/min", SF_SEARCH)
            .doc("eq. 1: sf = v/sl")
            .lockable()
            .value(p.step_freq_steps_per_min, f64::NAN),
        Control::new(FLIGHT_HEIGHT, "parameter", "flight height H", "m", (0.0, h_max))
            .doc("eq. 3: the pelvis's rise in flight above its toe-off height; the flight time then follows from H (case II) when H is set")
            .lockable()
            .value(p.flight_height_m.unwrap_or(f64::NAN), f64::NAN),
        Control::new(LEVEL, "parameter", "expertise level", "−1 poor … 1 skilled", LEVEL_RANGE)
            .doc("scaled to the paper's ±0.001 in eq. 2 and ±0.0001 in eqs. 4–5")
            .value(p.level.unwrap_or(0.0), 0.0),
        Control::new(HEIGHT, "body", "body height", "m", height_range(true))
            .doc("table B-1 proportions; lengths of the attributes scale with it")
            .value(h, 1.8),
    ];
    let s = h / 1.8;
    for spec in SPECS.iter() {
        let (scale, unit) = match spec.unit {
            AttrUnit::Degrees => (180.0 / std::f64::consts::PI, "deg"),
            AttrUnit::Metres => (s, "m"),
            AttrUnit::Factor => (1.0, "factor"),
            AttrUnit::Switch => (1.0, "heel / toe"),
        };
        // Degrees: SI → display; metres: the 1.8 m table scaled to the body.
        let show = |x: f64| x * scale;
        let current = match spec.unit {
            AttrUnit::Degrees => attrs.get(spec.attr).to_degrees(),
            _ => attrs.get(spec.attr),
        };
        let mut c = Control::new(
            &format!("{ATTR_PREFIX}{}", spec.name),
            "attribute",
            &spec.name.replace('_', " "),
            unit,
            (show(spec.min), show(spec.max)),
        )
        .doc(spec.doc)
        .value(current, show(spec.default));
        if spec.unit == AttrUnit::Switch {
            c.step = 1.0;
            c.choices = vec![(0.0, "heel strike".into()), (1.0, "toe strike".into())];
        }
        out.push(c);
    }
    out
}

/// Converts a RUNNER attribute's shown value (degrees, metres, factor, 0/1) to SI.
pub fn run_attr_to_si(unit: AttrUnit, shown: f64) -> f64 {
    match unit {
        AttrUnit::Degrees => shown.to_radians(),
        _ => shown,
    }
}

/// KLAW's controls: the three locomotion parameters (sliders spanning the anatomical limits of
/// the attributes `sl_min/max_per_height` and `sf_min/max_steps_per_min`), body height and mass
/// (the dynamics use both), and every locomotion attribute.
pub fn walk_controls(p: &ParamValues, attrs: &WalkAttributes) -> Vec<Control> {
    let mut out = locomotion_controls(p, attrs, true);
    out.push(
        Control::new(MASS, "body", "body mass", "kg", MASS_RANGE_KG)
            .doc("the dynamics' segment masses and inertias (table B-1)")
            .value(
                p.mass_kg.unwrap_or(WalkOptions::default().mass_kg),
                WalkOptions::default().mass_kg,
            ),
    );
    let defaults = WalkAttributes::default();
    for spec in ATTRIBUTES {
        out.push(
            Control::new(
                &format!("{ATTR_PREFIX}{}", spec.name),
                "attribute",
                &spec.name.replace('_', " "),
                spec.unit,
                (spec.min, spec.max),
            )
            .doc(spec.doc)
            .value(
                attrs.get(spec.name).unwrap_or(spec.default),
                defaults.get(spec.name).unwrap_or(spec.default),
            ),
        );
    }
    out
}

/// Ko–Badler's controls: step length and cadence (speed = their product), within the same
/// anatomical limits as KLAW's defaults (the generalization has none of its own), and the body.
pub fn generalize_controls(p: &ParamValues, default_sf: f64, default_sl: f64) -> Vec<Control> {
    let attrs = WalkAttributes::default();
    let mut out = locomotion_controls(p, &attrs, false);
    for c in out.iter_mut() {
        match c.key.as_str() {
            STEP_FREQ => {
                c.default = default_sf;
                c.doc = "cadence; by default the prototype's, scaled by √(leg length ratio) \
                         (dynamic similarity)"
                    .into();
            }
            STEP_LENGTH => {
                c.default = default_sl;
                c.doc = "the generalization's parameter: φ_ρ (appendix B) stretches the \
                         prototype step to it"
                    .into();
            }
            _ => {}
        }
    }
    out.push(
        Control::new(MASS, "body", "body mass", "kg", MASS_RANGE_KG)
            .doc("skeleton metadata only (the generalization is kinematic)")
            .value(p.mass_kg.unwrap_or(70.0), 70.0),
    );
    out
}

fn locomotion_controls(p: &ParamValues, a: &WalkAttributes, klaw: bool) -> Vec<Control> {
    let h = p.height_m;
    let sl = (a.sl_min_per_height * h, a.sl_max_per_height * h);
    let sf = (a.sf_min_steps_per_min, a.sf_max_steps_per_min);
    let v = (sl.0 * sf.0 / 60.0 * 3.6, sl.1 * sf.1 / 60.0 * 3.6);
    let (v_doc, sl_doc, sf_doc) = if klaw {
        (
            "KLAW eq. 1 completes the parameters not given: sf² = v/(k·h)",
            "eq. 1: sl = k·sf·h; limits sl_min/max_per_height × body height",
            "limits sf_min/max_steps_per_min (the paper's sf_max = 182)",
        )
    } else {
        ("v = sl·sf", "", "")
    };
    vec![
        Control::new(SPEED, "parameter", "speed v", "km/h", v)
            .doc(v_doc)
            .lockable()
            .value(p.speed_m_per_s * 3.6, 5.0),
        Control::new(STEP_LENGTH, "parameter", "step length sl", "m", sl)
            .doc(sl_doc)
            .lockable()
            .value(p.step_length_m, f64::NAN),
        Control::new(STEP_FREQ, "parameter", "step frequency sf", "steps/min", sf)
            .doc(sf_doc)
            .lockable()
            .value(p.step_freq_steps_per_min, f64::NAN),
        Control::new(HEIGHT, "body", "body height", "m", height_range(false))
            .doc("table B-1 proportions")
            .value(
                h,
                if klaw {
                    WalkOptions::default().height_m
                } else {
                    1.75
                },
            ),
    ]
}

/// The flight-height slider's upper end: the largest steady flight height (eq. 3) of natural
/// runs over the speed range, sampled at `n` speeds.
pub fn run_flight_height_span(
    model: &crate::generator::running::RunModel,
    attrs: &crate::generator::running::RunAttributes,
    level: f64,
    n: usize,
) -> f64 {
    let mut hi: f64 = 0.0;
    for i in 0..n.max(2) {
        let v = SPEED_RANGE.0 + (SPEED_RANGE.1 - SPEED_RANGE.0) * i as f64 / (n.max(2) - 1) as f64;
        if let Ok(p) = model.natural(v, level, attrs) {
            if p.flight_height.is_finite() {
                hi = hi.max(p.flight_height);
            }
        }
    }
    hi
}

/// The default mass of a runner of height `h` (RUNNER's kinematics do not use it).
pub fn run_mass(h: f64) -> f64 {
    default_mass(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(0.03), 0.02);
        assert_eq!(nice_step(0.7), 0.5);
        assert_eq!(nice_step(1.0), 1.0);
        assert!((nice_step(0.000_13) - 0.0001).abs() < 1e-15);
        assert_eq!(nice_step(f64::NAN), 1.0);
    }

    #[test]
    fn run_attribute_ranges_come_from_the_table() {
        let attrs = crate::generator::running::RunAttributes::defaults(1.8);
        let p = ParamValues {
            speed_m_per_s: 12.0 / 3.6,
            step_length_m: 1.07,
            step_freq_steps_per_min: 187.0,
            flight_height_m: Some(0.004),
            flight_time_s: Some(0.188),
            level: Some(0.0),
            height_m: 1.8,
            mass_kg: None,
        };
        let c = run_controls(&p, &attrs, &RunRelations::published(), 0.05);
        assert_eq!(c.iter().filter(|c| c.group == "attribute").count(), 19);
        let b = c.iter().find(|c| c.key == "attr.bounciness").unwrap();
        assert!((b.min - 5.0).abs() < 1e-9 && (b.max - 80.0).abs() < 1e-9);
        assert!((b.value - 40.0).abs() < 1e-9);
        let v = c.iter().find(|c| c.key == SPEED).unwrap();
        assert!((v.max - SPEED_RANGE.1 * 3.6).abs() < 1e-9 && v.lockable);
    }
}
