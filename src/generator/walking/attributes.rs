//! The locomotion attributes: the values that individualize a walk (§2.1: "up to 28 locomotion
//! attributes … may also be specified", e.g. lateral distance between the feet, toe clearance,
//! maximum rotation and list of the pelvis), with their defaults.
//!
//! The paper names only a few and gives one value (`sf_max = 182 steps/min`); the others, their
//! defaults and ranges are gaitfit's choices, listed in [`ATTRIBUTES`] (the table below is
//! generated from it by `gaitfit generate walk --help`). Angles are in degrees here because that is
//! how an animator states them; they are converted to radians where used.
use crate::generator::GenerateError;

macro_rules! attributes {
    ($( $(#[doc = $doc:literal])* $name:ident : $default:expr, [$lo:expr, $hi:expr], $unit:literal; )*) => {
        /// The locomotion attributes of one walk (see the module docs and [`ATTRIBUTES`]).
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct WalkAttributes {
            $( $(#[doc = $doc])* pub $name: f64, )*
        }

        impl Default for WalkAttributes {
            fn default() -> Self {
                WalkAttributes { $( $name: $default, )* }
            }
        }

        /// Every attribute: name, unit, default, accepted range and description.
        pub const ATTRIBUTES: &[AttributeSpec] = &[
            $( AttributeSpec {
                name: stringify!($name),
                unit: $unit,
                default: $default,
                min: $lo,
                max: $hi,
                doc: concat!($($doc),*),
            }, )*
        ];

        impl WalkAttributes {
            /// Sets the attribute called `name` (as in [`ATTRIBUTES`]) after checking its range.
            pub fn set(&mut self, name: &str, value: f64) -> Result<(), GenerateError> {
                let spec = ATTRIBUTES.iter().find(|s| s.name == name).ok_or_else(|| {
                    GenerateError::Parameter {
                        name: name.to_string(),
                        value,
                        message: format!(
                            "unknown locomotion attribute; known: {}",
                            ATTRIBUTES.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
                        ),
                    }
                })?;
                spec.check(value)?;
                match name {
                    $( stringify!($name) => self.$name = value, )*
                    _ => {}
                }
                Ok(())
            }

            /// The value of the attribute called `name`.
            pub fn get(&self, name: &str) -> Option<f64> {
                match name {
                    $( stringify!($name) => Some(self.$name), )*
                    _ => None,
                }
            }

            /// Checks every attribute against its range, and the relations between them.
            pub fn validate(&self) -> Result<(), GenerateError> {
                $( ATTRIBUTES.iter().find(|s| s.name == stringify!($name))
                    .map(|s| s.check(self.$name)).transpose()?; )*
                if self.swing1_end >= self.swing2_end {
                    return Err(GenerateError::Parameter {
                        name: "swing2_end".into(),
                        value: self.swing2_end,
                        message: format!(
                            "must come after swing1_end = {} (fractions of the swing)",
                            self.swing1_end
                        ),
                    });
                }
                if self.sf_min_steps_per_min >= self.sf_max_steps_per_min {
                    return Err(GenerateError::Parameter {
                        name: "sf_min_steps_per_min".into(),
                        value: self.sf_min_steps_per_min,
                        message: format!("must be below sf_max_steps_per_min = {}", self.sf_max_steps_per_min),
                    });
                }
                if self.sl_min_per_height >= self.sl_max_per_height {
                    return Err(GenerateError::Parameter {
                        name: "sl_min_per_height".into(),
                        value: self.sl_min_per_height,
                        message: format!("must be below sl_max_per_height = {}", self.sl_max_per_height),
                    });
                }
                Ok(())
            }
        }
    };
}

/// Description of one locomotion attribute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttributeSpec {
    /// Name (as given to `--attr name=value`).
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Default value.
    pub default: f64,
    /// Smallest accepted value.
    pub min: f64,
    /// Largest accepted value.
    pub max: f64,
    /// What it does.
    pub doc: &'static str,
}

impl AttributeSpec {
    /// Checks `value` against the range.
    pub fn check(&self, value: f64) -> Result<(), GenerateError> {
        if value.is_finite() && value >= self.min && value <= self.max {
            Ok(())
        } else {
            Err(GenerateError::Parameter {
                name: self.name.to_string(),
                value,
                message: format!(
                    "locomotion attribute out of range: accepted {} to {} {} ({})",
                    self.min,
                    self.max,
                    self.unit,
                    self.doc.trim()
                ),
            })
        }
    }
}

attributes! {
    /// Anatomical upper limit of the step frequency (§3; the paper's example value). The
    /// double-support relation vanishes at 181.75 steps/min with the published coefficients,
    /// where walking becomes running.
    sf_max_steps_per_min: 182.0, [30.0, 300.0], "steps/min";
    /// Anatomical lower limit of the step frequency.
    sf_min_steps_per_min: 30.0, [5.0, 150.0], "steps/min";
    /// Anatomical upper limit of the step length, as a fraction of body height.
    sl_max_per_height: 0.65, [0.1, 1.0], "1";
    /// Anatomical lower limit of the step length, as a fraction of body height.
    sl_min_per_height: 0.08, [0.01, 0.5], "1";
    /// Ankle angle θ5 at heel strike (eq. 3): angle between the shank and the sole, 90° neutral,
    /// larger in dorsiflexion.
    ankle_heel_strike_deg: 90.0, [70.0, 115.0], "deg";
    /// Ankle angle θ5 of the swing foot at the end of swing1 (dorsiflexed for toe clearance).
    ankle_mid_swing_deg: 100.0, [70.0, 125.0], "deg";
    /// Dorsiflexion limit of the swing ankle θ5: the toe-clearance rule of the kinematic swing
    /// foot dorsiflexes the ankle up to here (a typical active range is 20–30° past neutral).
    ankle_swing_dorsiflexion_max_deg: 115.0, [90.0, 140.0], "deg";
    /// Knee flexion at toe-off, reached through the meta-off period (θ5 at toe-off follows).
    knee_toe_off_deg: 35.0, [0.0, 80.0], "deg";
    /// Shortest heel rocker (heel strike → foot flat), fraction of the step: the foot lowers
    /// onto the ground along a C¹ blend of this duration (longer when the leg, straight, could
    /// not yet reach a flatter foot), instead of slapping down the moment the leg can reach.
    heel_rocker_fraction: 0.15, [0.02, 0.6], "1";
    /// Ankle dorsiflexion limit θ5 that ends the normal period and starts heel-off (§4.2).
    ankle_dorsiflexion_max_deg: 100.0, [90.0, 125.0], "deg";
    /// Metatarsal (toe) joint limit θ6 that ends heel-off and starts meta-off (§4.2).
    metatarsal_max_deg: 30.0, [5.0, 60.0], "deg";
    /// End of swing1 as a fraction of the swing (§4.3: about 50 %).
    swing1_end: 0.5, [0.2, 0.8], "1";
    /// End of swing2 as a fraction of the swing (§4.3: about 85 %).
    swing2_end: 0.85, [0.4, 0.97], "1";
    /// Minimum clearance of the swing foot over the ground; the swing2 recovery raises the hip
    /// torque until it is met (§4.3).
    toe_clearance_m: 0.005, [0.0, 0.1], "m";
    /// Height of the ankle curve's maximum a_max above the higher of its end points, at 1 m/s
    /// (divided by the speed in m/s: the faster the walk, the smaller a_max, §4.3).
    ankle_lift_m: 0.035, [0.0, 0.2], "m";
    /// Time constant of swing1's decaying-exponential hip torque, fraction of swing1.
    swing1_tau: 0.4, [0.02, 10.0], "1";
    /// Time constant of swing2's decaying-exponential knee torque, fraction of swing2.
    swing2_tau: 0.5, [0.02, 10.0], "1";
    /// Time constant of swing3's decaying-exponential hip torque, fraction of swing3.
    swing3_tau: 1.0, [0.02, 10.0], "1";
    /// Natural frequency of swing2's hip spring–damper that holds the thigh.
    swing_hip_freq_hz: 2.0, [0.1, 20.0], "Hz";
    /// Damping ratio of swing2's hip spring–damper.
    swing_hip_damping: 0.8, [0.0, 5.0], "1";
    /// Leg spring stiffness k_w as a multiple of body weight per leg length (k_w = value·m·g/l1).
    leg_stiffness: 20.0, [1.0, 1000.0], "1";
    /// Damping ratio of the leg spring–damper (v_w = 2·ratio·√(k_w·m2)).
    leg_damping: 0.4, [0.0, 20.0], "1";
    /// Fraction of the step after which the step torque F_θ1 is switched off (§4.2: 0.4).
    hip_torque_off: 0.4, [0.05, 1.0], "1";
    /// Natural frequency of the upper body's balancing spring–damper F_θ2.
    trunk_freq_hz: 1.5, [0.2, 20.0], "Hz";
    /// Damping ratio of the upper body's balancing spring–damper.
    trunk_damping: 1.0, [0.0, 20.0], "1";
    /// Forward lean of the upper body held by F_θ2.
    trunk_lean_deg: 2.0, [-20.0, 30.0], "deg";
    /// Pelvic rotation about the vertical, each way, maximal at heel strike (determinant of gait).
    pelvic_rotation_deg: 4.0, [0.0, 20.0], "deg";
    /// Pelvic list (swing side drops), maximal at mid-step (determinant of gait).
    pelvic_list_deg: 4.0, [0.0, 15.0], "deg";
    /// Lateral displacement of the pelvis toward the stance foot, maximal shortly after toe-off.
    lateral_displacement_m: 0.02, [0.0, 0.1], "m";
    /// Lateral distance between the centres of the two feet (stride width).
    stride_width_m: 0.1, [0.0, 0.4], "m";
    /// Arm swing: shoulder flexion amplitude, with the opposite leg.
    arm_swing_deg: 18.0, [0.0, 60.0], "deg";
    /// Mean elbow flexion.
    elbow_flexion_deg: 15.0, [0.0, 90.0], "deg";
    /// Fraction of the pelvic rotation counter-rotated by the thoracic spine and shoulders.
    spine_compensation: 1.0, [0.0, 2.0], "1";
    /// Largest change of walking speed from one step to the next, m/s per step. A schedule's
    /// larger change between stretches is spread over as many steps as it needs, at equal
    /// increments of speed (`generate_walk`). Default 0.5: within what people do
    /// (walking accelerations ≲ 0.5–1 m/s², ≈ 0.3–0.6 m/s per step; measured: docs/klaw.md).
    /// 10 turns the ramps off (the paper's one-step changes, §2.4).
    max_speed_change_m_per_s: 0.5, [0.05, 10.0], "m/s";
    /// Largest integration step (the stability bound may make it smaller). 4 ms: the shooting
    /// absorbs the integration error into the forces, which then differ by at most 0.2 % from a
    /// 0.5 ms integration (5 km/h, h = 1.8 m), at an eighth of the cost.
    max_step_s: 0.004, [0.0001, 0.01], "s";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_setting_checks_ranges() {
        let mut a = WalkAttributes::default();
        a.validate().unwrap();
        assert_eq!(a.sf_max_steps_per_min, 182.0);
        a.set("pelvic_list_deg", 8.0).unwrap();
        assert_eq!(a.get("pelvic_list_deg"), Some(8.0));
        let e = a.set("pelvic_list_deg", 80.0).unwrap_err().to_string();
        assert!(
            e.contains("pelvic_list_deg") && e.contains("0 to 15"),
            "{e}"
        );
        assert!(a
            .set("no_such", 1.0)
            .unwrap_err()
            .to_string()
            .contains("unknown"));
        assert!(ATTRIBUTES.len() >= 28);
    }

    #[test]
    fn the_speed_change_limit_is_range_checked() {
        let mut a = WalkAttributes::default();
        assert_eq!(a.max_speed_change_m_per_s, 0.5);
        a.set("max_speed_change_m_per_s", 0.3).unwrap();
        assert_eq!(a.get("max_speed_change_m_per_s"), Some(0.3));
        for bad in [0.0, 0.04, -0.5, 10.5, f64::NAN, f64::INFINITY] {
            let e = a
                .set("max_speed_change_m_per_s", bad)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("max_speed_change_m_per_s") && e.contains("0.05 to 10 m/s"),
                "{e}"
            );
        }
        // A walk's options are validated as a whole, too.
        a.max_speed_change_m_per_s = 0.0;
        assert!(a.validate().is_err());
    }
}
