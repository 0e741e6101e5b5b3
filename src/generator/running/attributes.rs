//! The nineteen attributes of §3.1.2 (5 arm/shoulder, 2 torso, 3 pelvis, 9 leg), their automatic
//! couplings to the parameters, and the hidden attributes.
//!
//! Every attribute has a user setting (what a slider or `--attr name=value` sets) and an
//! *effective* value used for a step. The paper: "These relationships are implemented as linear
//! functions of the current parameters, the attribute values and their extreme values." Here a
//! coupled attribute's effective value is `setting + Σ slope·(driver − reference)`, clamped to the
//! attribute's range; an uncoupled attribute's effective value is its setting. So a user who
//! raises overstride keeps the raise while the speed coupling keeps acting on top of it.
//!
//! Lengths scale with body height and the drivers are normalised to a 1.8 m figure (speed and
//! step frequency by the Froude factor √(h/1.8), lengths by h/1.8), so a small and a tall figure
//! running at dynamically similar speeds get geometrically similar styles. Table values below
//! are for a 1.8 m figure.
//!
//! Hidden attributes (§3.1.2, not settable): the ankle and toe (metatarsal) angles at toe off as
//! functions of step length, and the foot angle at impact as a function of overstride and the
//! heel/toe strike switch.
use crate::generator::GenerateError;

/// Whether the heel or the ball of the foot touches the ground first (§3.1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strike {
    /// Heel strike: the foot rotates about the heel to flat (§3.3.1).
    Heel,
    /// Toe (forefoot) strike: the foot rotates about the metatarsal joint to flat.
    Toe,
}

/// Unit in which an attribute is shown and set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttrUnit {
    /// Degrees (stored in radians).
    Degrees,
    /// Metres (scaled with body height).
    Metres,
    /// Dimensionless factor.
    Factor,
    /// 0 = heel strike, 1 = toe strike.
    Switch,
}

/// What drives an automatic coupling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Driver {
    /// Speed, m/s, normalised ×√(1.8/h).
    Speed,
    /// Step length, m, normalised ×1.8/h.
    StepLength,
    /// Step frequency, steps/s, normalised ×√(h/1.8).
    StepFreq,
    /// Flight height, m, normalised ×1.8/h.
    FlightHeight,
    /// The effective stride width, m, normalised ×1.8/h.
    StrideWidth,
}

/// One linear coupling `slope·(driver − reference)` (units: the attribute's per driver's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// The parameter that drives the attribute.
    pub driver: Driver,
    /// Driver value at which the coupling adds nothing.
    pub reference: f64,
    /// Change of the attribute (its SI unit, at 1.8 m) per unit of the driver.
    pub slope: f64,
    /// The driver is clamped to this range before the coupling acts (the couplings are
    /// linear "with their extreme values").
    pub range: (f64, f64),
}

const ALL_RANGE: (f64, f64) = (f64::NEG_INFINITY, f64::INFINITY);
/// Normalised step lengths over which the toe-off pose changes (m): below `SL_SHORT` the
/// toe-off pose is that of a shuffle, above `SL_LONG` that of a full push-off. The paper's
/// locked-speed example (sl 1.07 → 0.95 m) lies entirely in the full push-off range, and
/// slow runs (2–9 km/h, eq. 5's short flights) need the shorter toe-off leg to keep a
/// positive take-off velocity.
pub const SL_SHORT: f64 = 0.65;
/// See [`SL_SHORT`].
pub const SL_LONG: f64 = 0.95;

/// The attributes (§3.1.2, Fig. 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Attr {
    /// Arm swing factor: shoulder flexion = factor × the opposite leg's arm drive, between its
    /// hip–ankle angle at its toe off and its swing hip flexion (§3.3.3;
    /// `upper_body::arm_driver`).
    ArmSwing,
    /// Minimum elbow flexion (backward swing at toe off).
    ElbowMin,
    /// Maximum elbow flexion (forward swing at toe off).
    ElbowMax,
    /// Counter-rotation of the shoulders against the pelvis, fraction of pelvic rotation (§3.3.3).
    ShoulderRotation,
    /// Upper-arm abduction (arms carried away from the body).
    ArmAbduction,
    /// Forward torso tilt.
    TorsoTilt,
    /// Torso sway amplitude in the sagittal plane.
    TorsoSway,
    /// Maximum pelvic rotation (transverse plane), reached at toe off.
    PelvicRotation,
    /// Maximum pelvic list (coronal plane), reached at mid-support.
    PelvicList,
    /// Maximum lateral displacement of the pelvis, reached at mid-support.
    LateralDisplacement,
    /// Heel (0) or toe (1) strike.
    Strike,
    /// Bounciness: knee flexion of the stance leg at mid-support.
    Bounciness,
    /// Overstride: how far ahead of the pelvis the heel lands.
    Overstride,
    /// Stride width: lateral distance between the two feet's centre lines.
    StrideWidth,
    /// Knee flexion at heel strike.
    KneeHeelStrike,
    /// Knee flexion at toe off.
    KneeToeOff,
    /// Maximum knee flexion of the swing leg (at mid-support).
    SwingKnee,
    /// Maximum hip flexion of the swing leg (at the other leg's toe off) — the paper's "hip
    /// extension" of the swing leg.
    SwingHip,
    /// Ankle dorsiflexion of the swing foot (at mid-support and toe off of the other leg).
    SwingAnkle,
}

/// Specification of one attribute: name, unit, range, default and couplings (1.8 m figure).
#[derive(Debug, Clone, Copy)]
pub struct AttrSpec {
    /// The attribute.
    pub attr: Attr,
    /// Name used on the command line (`--attr name=value`) and in reports.
    pub name: &'static str,
    /// Unit.
    pub unit: AttrUnit,
    /// Smallest effective value (SI: rad, m, factor).
    pub min: f64,
    /// Largest effective value.
    pub max: f64,
    /// Default setting.
    pub default: f64,
    /// Automatic couplings (empty for an independent attribute).
    pub couplings: &'static [Coupling],
    /// One-line meaning.
    pub doc: &'static str,
}

const D: f64 = std::f64::consts::PI / 180.0;

/// Reference speed of the couplings: the paper's example, 12 km/h.
pub const V_REF: f64 = 12.0 / 3.6;
/// Reference step length: eq. 2 at 12 km/h, 1.8 m.
pub const SL_REF: f64 = 1.0694;
/// Reference step frequency, steps/s (187 steps/min).
pub const SF_REF: f64 = 187.02 / 60.0;
/// Reference flight height, m (the paper's 0.004 m at 12 km/h).
pub const H_REF: f64 = 0.004;
/// Reference stride width, m.
pub const SW_REF: f64 = 0.08;

/// The attribute table. Values are for a 1.8 m figure; see the module docs for scaling.
pub const SPECS: [AttrSpec; 19] = [
    AttrSpec { attr: Attr::ArmSwing, name: "arm_swing", unit: AttrUnit::Factor, min: 0.0, max: 3.0, default: 1.0, couplings: &[],
        doc: "shoulder flexion = factor × the opposite leg's swing: back to its hip–ankle angle at its toe off, forward to its swing hip flexion" },
    AttrSpec { attr: Attr::ElbowMin, name: "elbow_min", unit: AttrUnit::Degrees, min: 0.0, max: 150.0 * D, default: 65.0 * D, couplings: &[],
        doc: "elbow flexion at the back of the arm swing (toe off of the same-side leg's opposite)" },
    AttrSpec { attr: Attr::ElbowMax, name: "elbow_max", unit: AttrUnit::Degrees, min: 0.0, max: 150.0 * D, default: 100.0 * D, couplings: &[],
        doc: "elbow flexion at the front of the arm swing" },
    AttrSpec { attr: Attr::ShoulderRotation, name: "shoulder_rotation", unit: AttrUnit::Factor, min: 0.0, max: 2.0, default: 0.5, couplings: &[],
        doc: "spine counter-rotation above T7 as a fraction of pelvic rotation" },
    AttrSpec { attr: Attr::ArmAbduction, name: "arm_abduction", unit: AttrUnit::Degrees, min: 0.0, max: 60.0 * D, default: 8.0 * D, couplings: &[],
        doc: "upper arms carried away from the trunk" },
    AttrSpec { attr: Attr::TorsoTilt, name: "torso_tilt", unit: AttrUnit::Degrees, min: -15.0 * D, max: 40.0 * D, default: 6.0 * D,
        couplings: &[Coupling { driver: Driver::Speed, reference: V_REF, slope: 1.2 * D, range: ALL_RANGE }],
        doc: "forward lean of the trunk; rises with speed (§3.3.3)" },
    AttrSpec { attr: Attr::TorsoSway, name: "torso_sway", unit: AttrUnit::Degrees, min: 0.0, max: 15.0 * D, default: 2.0 * D, couplings: &[],
        doc: "sagittal sway: forward at mid-support, back at toe off" },
    AttrSpec { attr: Attr::PelvicRotation, name: "pelvic_rotation", unit: AttrUnit::Degrees, min: 0.0, max: 30.0 * D, default: 8.0 * D,
        couplings: &[Coupling { driver: Driver::StepLength, reference: SL_REF, slope: 6.0 * D, range: ALL_RANGE }],
        doc: "maximum pelvic rotation (toe off); rises with step length" },
    AttrSpec { attr: Attr::PelvicList, name: "pelvic_list", unit: AttrUnit::Degrees, min: 0.0, max: 20.0 * D, default: 5.0 * D, couplings: &[],
        doc: "maximum pelvic list (mid-support), swing side down" },
    AttrSpec { attr: Attr::LateralDisplacement, name: "lateral_displacement", unit: AttrUnit::Metres, min: 0.0, max: 0.1, default: 0.02,
        couplings: &[
            Coupling { driver: Driver::StrideWidth, reference: SW_REF, slope: 0.25, range: ALL_RANGE },
            Coupling { driver: Driver::StepFreq, reference: SF_REF, slope: -0.01, range: ALL_RANGE },
        ],
        doc: "maximum sideways shift of the pelvis over the stance foot; rises with stride width, falls with step frequency" },
    AttrSpec { attr: Attr::Strike, name: "strike", unit: AttrUnit::Switch, min: 0.0, max: 1.0, default: 0.0, couplings: &[],
        doc: "0 = heel strike, 1 = toe strike" },
    AttrSpec { attr: Attr::Bounciness, name: "bounciness", unit: AttrUnit::Degrees, min: 5.0 * D, max: 80.0 * D, default: 40.0 * D,
        couplings: &[Coupling { driver: Driver::FlightHeight, reference: H_REF, slope: 5.0 * D / 0.01, range: ALL_RANGE }],
        doc: "stance knee flexion at mid-support (pelvis low point); rises with flight height" },
    AttrSpec { attr: Attr::Overstride, name: "overstride", unit: AttrUnit::Metres, min: 0.0, max: 0.4, default: 0.03,
        couplings: &[Coupling { driver: Driver::Speed, reference: V_REF, slope: -0.006, range: ALL_RANGE }],
        doc: "heel ahead of the pelvis at impact (the least: long supports land further ahead); falls with speed" },
    AttrSpec { attr: Attr::StrideWidth, name: "stride_width", unit: AttrUnit::Metres, min: 0.0, max: 0.4, default: SW_REF, couplings: &[],
        doc: "lateral distance between the feet's centre lines" },
    AttrSpec { attr: Attr::KneeHeelStrike, name: "knee_heel_strike", unit: AttrUnit::Degrees, min: 0.0, max: 70.0 * D, default: 15.0 * D, couplings: &[],
        doc: "knee flexion at heel strike" },
    AttrSpec { attr: Attr::KneeToeOff, name: "knee_toe_off", unit: AttrUnit::Degrees, min: 0.0, max: 70.0 * D, default: 20.0 * D,
        couplings: &[Coupling { driver: Driver::StepLength, reference: SL_LONG, slope: -100.0 * D, range: (SL_SHORT, SL_LONG) }],
        doc: "knee flexion at toe off; falls with step length (short, slow strides leave the ground with a bent knee)" },
    AttrSpec { attr: Attr::SwingKnee, name: "swing_knee", unit: AttrUnit::Degrees, min: 20.0 * D, max: 160.0 * D, default: 110.0 * D,
        couplings: &[Coupling { driver: Driver::Speed, reference: V_REF, slope: 7.0 * D, range: ALL_RANGE }],
        doc: "maximum knee flexion in swing (mid-support); rises with speed" },
    AttrSpec { attr: Attr::SwingHip, name: "swing_hip", unit: AttrUnit::Degrees, min: 0.0, max: 100.0 * D, default: 33.0 * D,
        couplings: &[Coupling { driver: Driver::Speed, reference: V_REF, slope: 4.0 * D, range: ALL_RANGE }],
        doc: "maximum hip flexion of the swing leg (other leg's toe off); rises with speed" },
    AttrSpec { attr: Attr::SwingAnkle, name: "swing_ankle", unit: AttrUnit::Degrees, min: -40.0 * D, max: 40.0 * D, default: 5.0 * D, couplings: &[],
        doc: "ankle dorsiflexion of the swing foot" },
];

impl Attr {
    /// All attributes in table order.
    pub const ALL: [Attr; 19] = [
        Attr::ArmSwing,
        Attr::ElbowMin,
        Attr::ElbowMax,
        Attr::ShoulderRotation,
        Attr::ArmAbduction,
        Attr::TorsoTilt,
        Attr::TorsoSway,
        Attr::PelvicRotation,
        Attr::PelvicList,
        Attr::LateralDisplacement,
        Attr::Strike,
        Attr::Bounciness,
        Attr::Overstride,
        Attr::StrideWidth,
        Attr::KneeHeelStrike,
        Attr::KneeToeOff,
        Attr::SwingKnee,
        Attr::SwingHip,
        Attr::SwingAnkle,
    ];

    /// Index in [`SPECS`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The specification.
    pub fn spec(self) -> &'static AttrSpec {
        &SPECS[self.index()]
    }

    /// Looks an attribute up by its command-line name.
    pub fn from_name(name: &str) -> Option<Attr> {
        SPECS.iter().find(|s| s.name == name.trim()).map(|s| s.attr)
    }
}

/// The driver values a step's effective attributes are computed from (SI, unnormalised).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drivers {
    /// Speed, m/s.
    pub speed: f64,
    /// Step length, m.
    pub step_length: f64,
    /// Step frequency, steps/s.
    pub step_freq: f64,
    /// Flight height, m.
    pub flight_height: f64,
}

/// User settings of the nineteen attributes for one figure (SI: rad, m, factor).
#[derive(Debug, Clone, PartialEq)]
pub struct RunAttributes {
    body_height: f64,
    values: [f64; 19],
}

/// Effective attribute values for one step (SI), plus the hidden attributes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effective {
    /// Arm swing factor.
    pub arm_swing: f64,
    /// Elbow flexion at the back of the swing, rad.
    pub elbow_min: f64,
    /// Elbow flexion at the front of the swing, rad.
    pub elbow_max: f64,
    /// Shoulder counter-rotation fraction.
    pub shoulder_rotation: f64,
    /// Arm abduction, rad.
    pub arm_abduction: f64,
    /// Torso tilt, rad.
    pub torso_tilt: f64,
    /// Torso sway amplitude, rad.
    pub torso_sway: f64,
    /// Maximum pelvic rotation, rad.
    pub pelvic_rotation: f64,
    /// Maximum pelvic list, rad.
    pub pelvic_list: f64,
    /// Maximum lateral displacement, m.
    pub lateral_displacement: f64,
    /// Heel or toe strike.
    pub strike: Strike,
    /// Stance knee flexion at mid-support, rad.
    pub bounciness: f64,
    /// Overstride, m.
    pub overstride: f64,
    /// Stride width, m.
    pub stride_width: f64,
    /// Knee flexion at heel strike, rad.
    pub knee_heel_strike: f64,
    /// Knee flexion at toe off, rad.
    pub knee_toe_off: f64,
    /// Maximum swing knee flexion, rad.
    pub swing_knee: f64,
    /// Maximum swing hip flexion, rad.
    pub swing_hip: f64,
    /// Swing ankle dorsiflexion, rad.
    pub swing_ankle: f64,
    /// Hidden: ankle dorsiflexion at toe off (negative = plantarflexion), rad; more
    /// plantarflexion with longer steps.
    pub ankle_toe_off: f64,
    /// Hidden: toe dorsiflexion at toe off, rad; rises with step length.
    pub meta_toe_off: f64,
    /// Hidden: sole pitch at impact (positive = toe up, heel strike; negative = toe down, toe
    /// strike), rad; rises with overstride.
    pub impact_pitch: f64,
}

/// Hidden attribute: ankle dorsiflexion at toe off (rad) for a normalised step length (m).
pub fn hidden_ankle_toe_off(sl_n: f64) -> f64 {
    (-36.0 + 150.0 * (SL_LONG - sl_n.clamp(SL_SHORT, SL_LONG))) * D
}

/// Hidden attribute: toe dorsiflexion at toe off (rad) for a normalised step length (m).
pub fn hidden_meta_toe_off(sl_n: f64) -> f64 {
    (30.0 - 30.0 * (SL_LONG - sl_n.clamp(SL_SHORT, SL_LONG))) * D
}

/// Hidden attribute: sole pitch at impact (rad) from the normalised overstride (m) and the
/// strike switch. Heel strike lands toe up, more so with a longer overstride; toe strike lands
/// toe down, less so with a longer overstride.
pub fn hidden_impact_pitch(overstride_n: f64, strike: Strike) -> f64 {
    match strike {
        Strike::Heel => ((8.0 + 60.0 * overstride_n) * D).clamp(2.0 * D, 35.0 * D),
        Strike::Toe => (-(16.0 - 20.0 * overstride_n) * D).clamp(-30.0 * D, -4.0 * D),
    }
}

impl RunAttributes {
    /// Default settings for a figure of `body_height` m.
    pub fn defaults(body_height: f64) -> Self {
        let s = body_height / 1.8;
        let mut values = [0.0; 19];
        for (v, spec) in values.iter_mut().zip(SPECS.iter()) {
            *v = if spec.unit == AttrUnit::Metres {
                spec.default * s
            } else {
                spec.default
            };
        }
        RunAttributes {
            body_height,
            values,
        }
    }

    /// Body height the settings are for, m.
    pub fn body_height(&self) -> f64 {
        self.body_height
    }

    /// The setting of `a` (SI).
    pub fn get(&self, a: Attr) -> f64 {
        self.values[a.index()]
    }

    /// Sets `a` to `value` (SI: rad, m, factor, 0/1), checked against the attribute's range
    /// (scaled to the body height for lengths).
    pub fn set(&mut self, a: Attr, value: f64) -> Result<(), GenerateError> {
        let spec = a.spec();
        let s = if spec.unit == AttrUnit::Metres {
            self.body_height / 1.8
        } else {
            1.0
        };
        let (lo, hi) = (spec.min * s, spec.max * s);
        let shown = |x: f64| {
            if spec.unit == AttrUnit::Degrees {
                x.to_degrees()
            } else {
                x
            }
        };
        if !value.is_finite() || value < lo - 1e-12 || value > hi + 1e-12 {
            return Err(GenerateError::Parameter {
                name: spec.name.into(),
                value: shown(value),
                message: format!(
                    "must be within [{}, {}] ({})",
                    shown(lo),
                    shown(hi),
                    unit_name(spec.unit)
                ),
            });
        }
        if spec.unit == AttrUnit::Switch && value != 0.0 && value != 1.0 {
            return Err(GenerateError::Parameter {
                name: spec.name.into(),
                value,
                message: "must be 0 (heel strike) or 1 (toe strike), or `heel`/`toe`".into(),
            });
        }
        self.values[a.index()] = value;
        Ok(())
    }

    /// Effective values for a step with the given drivers (couplings applied, clamped).
    pub fn effective(&self, drv: &Drivers) -> Effective {
        let h = self.body_height;
        let s = h / 1.8;
        let fr = s.sqrt();
        let sw_set_n = self.values[Attr::StrideWidth.index()] / s;
        let driver_n = |d: Driver| match d {
            Driver::Speed => drv.speed / fr,
            Driver::StepLength => drv.step_length / s,
            Driver::StepFreq => drv.step_freq * fr,
            Driver::FlightHeight => drv.flight_height / s,
            Driver::StrideWidth => sw_set_n,
        };
        let eff = |a: Attr| {
            let spec = a.spec();
            let scale = if spec.unit == AttrUnit::Metres {
                s
            } else {
                1.0
            };
            let mut v = self.values[a.index()] / scale;
            for c in spec.couplings {
                v += c.slope * (driver_n(c.driver).clamp(c.range.0, c.range.1) - c.reference);
            }
            v.clamp(spec.min, spec.max) * scale
        };
        let strike = if self.values[Attr::Strike.index()] >= 0.5 {
            Strike::Toe
        } else {
            Strike::Heel
        };
        let overstride = eff(Attr::Overstride);
        let sl_n = drv.step_length / s;
        Effective {
            arm_swing: eff(Attr::ArmSwing),
            elbow_min: eff(Attr::ElbowMin),
            elbow_max: eff(Attr::ElbowMax),
            shoulder_rotation: eff(Attr::ShoulderRotation),
            arm_abduction: eff(Attr::ArmAbduction),
            torso_tilt: eff(Attr::TorsoTilt),
            torso_sway: eff(Attr::TorsoSway),
            pelvic_rotation: eff(Attr::PelvicRotation),
            pelvic_list: eff(Attr::PelvicList),
            lateral_displacement: eff(Attr::LateralDisplacement),
            strike,
            bounciness: eff(Attr::Bounciness),
            overstride,
            stride_width: eff(Attr::StrideWidth),
            knee_heel_strike: eff(Attr::KneeHeelStrike),
            knee_toe_off: eff(Attr::KneeToeOff),
            swing_knee: eff(Attr::SwingKnee),
            swing_hip: eff(Attr::SwingHip),
            swing_ankle: eff(Attr::SwingAnkle),
            ankle_toe_off: hidden_ankle_toe_off(sl_n),
            meta_toe_off: hidden_meta_toe_off(sl_n),
            impact_pitch: hidden_impact_pitch(overstride / s, strike),
        }
    }
}

/// Human-readable unit name.
pub fn unit_name(u: AttrUnit) -> &'static str {
    match u {
        AttrUnit::Degrees => "deg",
        AttrUnit::Metres => "m",
        AttrUnit::Factor => "factor",
        AttrUnit::Switch => "0 heel / 1 toe",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_in_enum_order_and_defaults_in_range() {
        for (i, s) in SPECS.iter().enumerate() {
            assert_eq!(s.attr.index(), i, "{}", s.name);
            assert!(s.min <= s.default && s.default <= s.max, "{}", s.name);
            assert_eq!(Attr::from_name(s.name), Some(s.attr));
        }
    }

    #[test]
    fn couplings_act_in_the_papers_directions() {
        let a = RunAttributes::defaults(1.8);
        let slow = Drivers {
            speed: 2.0,
            step_length: 0.8,
            step_freq: 2.5,
            flight_height: 0.002,
        };
        let fast = Drivers {
            speed: 5.0,
            step_length: 1.5,
            step_freq: 3.3,
            flight_height: 0.01,
        };
        let (es, ef) = (a.effective(&slow), a.effective(&fast));
        assert!(ef.overstride < es.overstride, "overstride falls with v");
        assert!(
            ef.pelvic_rotation > es.pelvic_rotation,
            "pelvic rotation rises with sl"
        );
        assert!(ef.bounciness > es.bounciness, "bounciness rises with H");
        assert!(ef.torso_tilt > es.torso_tilt, "tilt rises with v");
        assert!(
            ef.lateral_displacement < es.lateral_displacement,
            "lateral falls with sf"
        );
        assert!(ef.meta_toe_off > es.meta_toe_off);
        assert!(ef.ankle_toe_off < es.ankle_toe_off);
        assert!(
            ef.knee_toe_off < es.knee_toe_off,
            "knee (flexion) at toe off falls with sl"
        );
    }

    #[test]
    fn settings_are_range_checked() {
        let mut a = RunAttributes::defaults(1.8);
        assert!(a.set(Attr::Overstride, 5.0).is_err());
        assert!(a.set(Attr::Strike, 0.5).is_err());
        assert!(a.set(Attr::Strike, 1.0).is_ok());
        assert!(a.set(Attr::ElbowMax, f64::NAN).is_err());
    }
}
