//! Unit-suffixed column names → SI, and SI → the papers' units.
//!
//! Every numeric CSV header carries its unit (`speed_m_per_s`, `step_freq_steps_per_min`, …).
//! gaitfit converts once, at the boundary, to SI (m, m/s, s, steps/s, rad); the relations convert
//! to the papers' units (m/min, steps/min) where the published coefficients are expressed in them.
//!
//! [`parse_header`] splits a header into a known [`Quantity`] and a [`Unit`] suffix and gives the
//! factor that converts a value to SI:
//!
//! ```
//! use gaitfit::units::{parse_header, Quantity};
//! let c = parse_header("speed_km_per_h").unwrap().unwrap();
//! assert_eq!(c.quantity, Quantity::Speed);
//! assert!((c.to_si(18.0) - 5.0).abs() < 1e-12); // 18 km/h = 5 m/s
//! ```

/// Metres per minute per metre per second.
pub const M_PER_MIN_PER_M_PER_S: f64 = 60.0;
/// Steps per minute per step per second.
pub const STEPS_PER_MIN_PER_HZ: f64 = 60.0;
/// Standard gravity, m/s² (used by the running paper's eq. 3 and the KLAW dynamics).
pub const G: f64 = 9.80665;

/// m/s → m/min (the papers' speed unit).
pub fn m_per_s_to_m_per_min(v: f64) -> f64 {
    v * M_PER_MIN_PER_M_PER_S
}
/// m/min → m/s.
pub fn m_per_min_to_m_per_s(v: f64) -> f64 {
    v / M_PER_MIN_PER_M_PER_S
}
/// km/h → m/s.
pub fn km_per_h_to_m_per_s(v: f64) -> f64 {
    v / 3.6
}
/// steps/s → steps/min (the papers' step-frequency unit).
pub fn hz_to_steps_per_min(f: f64) -> f64 {
    f * STEPS_PER_MIN_PER_HZ
}
/// steps/min → steps/s.
pub fn steps_per_min_to_hz(f: f64) -> f64 {
    f / STEPS_PER_MIN_PER_HZ
}

/// The physical dimension of a quantity, which decides the unit suffixes it accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dimension {
    /// Length (SI: m).
    Length,
    /// Speed (SI: m/s).
    Speed,
    /// Step frequency (SI: steps/s).
    Frequency,
    /// Duration (SI: s).
    Time,
    /// Percentage of the gait cycle (kept as %).
    PercentCycle,
    /// Plane angle (SI: rad).
    Angle,
}

impl Dimension {
    /// The unit suffixes accepted for this dimension, with the factor to SI.
    pub fn units(self) -> &'static [Unit] {
        match self {
            Dimension::Length => &[Unit::M, Unit::Cm, Unit::Mm, Unit::In],
            Dimension::Speed => &[Unit::MPerS, Unit::MPerMin, Unit::KmPerH],
            Dimension::Frequency => &[Unit::StepsPerMin, Unit::Hz, Unit::StepsPerS],
            Dimension::Time => &[Unit::S, Unit::Ms],
            Dimension::PercentCycle => &[Unit::PctCycle],
            Dimension::Angle => &[Unit::Deg, Unit::Rad],
        }
    }
    /// The canonical suffix gaitfit writes (SI, except steps/min and degrees, as in
    /// [`crate::ingest::trials::CANONICAL_COLUMNS`]).
    pub fn canonical_unit(self) -> Unit {
        self.units()[0]
    }
}

/// A unit suffix of a column header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// Metres (`_m`).
    M,
    /// Centimetres (`_cm`).
    Cm,
    /// Millimetres (`_mm`).
    Mm,
    /// Inches (`_in`; Ko & Badler's tables use inches).
    In,
    /// Metres per second (`_m_per_s`).
    MPerS,
    /// Metres per minute (`_m_per_min`, the papers' speed unit).
    MPerMin,
    /// Kilometres per hour (`_km_per_h`).
    KmPerH,
    /// Steps per minute (`_steps_per_min`, the papers' step-frequency unit).
    StepsPerMin,
    /// Steps per second (`_hz`).
    Hz,
    /// Steps per second (`_steps_per_s`).
    StepsPerS,
    /// Seconds (`_s`).
    S,
    /// Milliseconds (`_ms`).
    Ms,
    /// Percent of the gait cycle (`_pct_cycle`).
    PctCycle,
    /// Radians (`_rad`).
    Rad,
    /// Degrees (`_deg`).
    Deg,
}

impl Unit {
    /// The header suffix, without the leading underscore.
    pub fn suffix(self) -> &'static str {
        match self {
            Unit::M => "m",
            Unit::Cm => "cm",
            Unit::Mm => "mm",
            Unit::In => "in",
            Unit::MPerS => "m_per_s",
            Unit::MPerMin => "m_per_min",
            Unit::KmPerH => "km_per_h",
            Unit::StepsPerMin => "steps_per_min",
            Unit::Hz => "hz",
            Unit::StepsPerS => "steps_per_s",
            Unit::S => "s",
            Unit::Ms => "ms",
            Unit::PctCycle => "pct_cycle",
            Unit::Rad => "rad",
            Unit::Deg => "deg",
        }
    }
    /// Multiply a value in this unit by this factor to get SI (or % for `_pct_cycle`).
    pub fn to_si_factor(self) -> f64 {
        match self {
            Unit::M | Unit::MPerS | Unit::Hz | Unit::StepsPerS | Unit::S | Unit::Rad => 1.0,
            Unit::PctCycle => 1.0,
            Unit::Cm => 0.01,
            Unit::Mm | Unit::Ms => 0.001,
            Unit::In => 0.0254,
            Unit::MPerMin => 1.0 / M_PER_MIN_PER_M_PER_S,
            Unit::KmPerH => 1.0 / 3.6,
            Unit::StepsPerMin => 1.0 / STEPS_PER_MIN_PER_HZ,
            Unit::Deg => std::f64::consts::PI / 180.0,
        }
    }
}

/// A numeric quantity of the trials schema (see `data/README.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Time of the step's heel strike from the start of the trial.
    Time,
    /// Speed of progression.
    Speed,
    /// Step length.
    StepLength,
    /// Step frequency.
    StepFreq,
    /// Stance time.
    StanceTime,
    /// Swing time.
    SwingTime,
    /// Double-support time of one step.
    DoubleSupportTime,
    /// Double support of one step as a percentage of the gait cycle.
    DoubleSupportPct,
    /// Flight time of one running step.
    FlightTime,
    /// Flight height H (running paper eq. 3).
    FlightHeight,
    /// Body height.
    BodyHeight,
    /// Leg length.
    LegLength,
    /// Knee flexion at heel strike (Ko–Badler μ1).
    KneeAngleHs,
    /// Foot-sole angle at heel strike (μ2).
    FootAngleHs,
    /// Foot-sole angle at toe off (μ3).
    FootAngleTo,
    /// Metatarsal angle at toe off (μ4).
    MetaAngleTo,
}

impl Quantity {
    /// Every quantity, in schema order.
    pub const ALL: [Quantity; 16] = [
        Quantity::Time,
        Quantity::Speed,
        Quantity::StepLength,
        Quantity::StepFreq,
        Quantity::StanceTime,
        Quantity::SwingTime,
        Quantity::DoubleSupportTime,
        Quantity::DoubleSupportPct,
        Quantity::FlightTime,
        Quantity::FlightHeight,
        Quantity::BodyHeight,
        Quantity::LegLength,
        Quantity::KneeAngleHs,
        Quantity::FootAngleHs,
        Quantity::FootAngleTo,
        Quantity::MetaAngleTo,
    ];

    /// The header stem before the unit suffix (`speed`, `step_length`, …).
    pub fn stem(self) -> &'static str {
        match self {
            Quantity::Time => "time",
            Quantity::Speed => "speed",
            Quantity::StepLength => "step_length",
            Quantity::StepFreq => "step_freq",
            Quantity::StanceTime => "stance_time",
            Quantity::SwingTime => "swing_time",
            Quantity::DoubleSupportTime => "double_support_time",
            Quantity::DoubleSupportPct => "double_support",
            Quantity::FlightTime => "flight_time",
            Quantity::FlightHeight => "flight_height",
            Quantity::BodyHeight => "body_height",
            Quantity::LegLength => "leg_length",
            Quantity::KneeAngleHs => "knee_angle_hs",
            Quantity::FootAngleHs => "foot_angle_hs",
            Quantity::FootAngleTo => "foot_angle_to",
            Quantity::MetaAngleTo => "meta_angle_to",
        }
    }

    /// Its dimension.
    pub fn dimension(self) -> Dimension {
        match self {
            Quantity::Speed => Dimension::Speed,
            Quantity::StepFreq => Dimension::Frequency,
            Quantity::StepLength
            | Quantity::FlightHeight
            | Quantity::BodyHeight
            | Quantity::LegLength => Dimension::Length,
            Quantity::Time
            | Quantity::StanceTime
            | Quantity::SwingTime
            | Quantity::DoubleSupportTime
            | Quantity::FlightTime => Dimension::Time,
            Quantity::DoubleSupportPct => Dimension::PercentCycle,
            Quantity::KneeAngleHs
            | Quantity::FootAngleHs
            | Quantity::FootAngleTo
            | Quantity::MetaAngleTo => Dimension::Angle,
        }
    }

    /// Plausible SI range `[lo, hi]` of a value (for catching unit slips such as a step length of
    /// 80 written under `_m`). Generous: it only rejects values no human gait produces.
    pub fn plausible_si(self) -> (f64, f64) {
        match self {
            Quantity::Time => (0.0, 1.0e6),
            Quantity::Speed => (0.0, 12.5), // faster than the 100 m world record
            Quantity::StepLength => (0.0, 3.5), // longer than a sprinter's step
            Quantity::StepFreq => (0.0, 6.0), // 360 steps/min
            Quantity::StanceTime | Quantity::SwingTime => (0.0, 5.0),
            Quantity::DoubleSupportTime => (0.0, 5.0),
            Quantity::DoubleSupportPct => (0.0, 60.0),
            Quantity::FlightTime => (0.0, 1.0),
            Quantity::FlightHeight => (0.0, 1.0),
            Quantity::BodyHeight => (0.4, 2.6),
            Quantity::LegLength => (0.2, 1.5),
            Quantity::KneeAngleHs
            | Quantity::FootAngleHs
            | Quantity::FootAngleTo
            | Quantity::MetaAngleTo => (-std::f64::consts::PI, std::f64::consts::PI),
        }
    }

    /// Whether negative values are meaningful (only the angles).
    pub fn may_be_negative(self) -> bool {
        self.dimension() == Dimension::Angle
    }

    /// The canonical header gaitfit writes (`speed_m_per_s`, `step_freq_steps_per_min`, …).
    pub fn canonical_header(self) -> String {
        format!(
            "{}_{}",
            self.stem(),
            self.dimension().canonical_unit().suffix()
        )
    }
}

/// A numeric column: its quantity and unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Column {
    /// What it measures.
    pub quantity: Quantity,
    /// The unit of the values in the file.
    pub unit: Unit,
}

impl Column {
    /// Converts a value in the column's unit to SI.
    pub fn to_si(&self, value: f64) -> f64 {
        value * self.unit.to_si_factor()
    }
    /// Converts an SI value to the column's unit.
    pub fn from_si(&self, value: f64) -> f64 {
        value / self.unit.to_si_factor()
    }
}

/// Why a header could not be used.
#[derive(Debug, Clone, PartialEq)]
pub struct UnknownUnit {
    /// The quantity the header starts with.
    pub quantity: Quantity,
    /// The suffix found.
    pub suffix: String,
}

impl UnknownUnit {
    /// The accepted spellings for this quantity, for the error message.
    pub fn accepted(&self) -> String {
        self.quantity
            .dimension()
            .units()
            .iter()
            .map(|u| format!("{}_{}", self.quantity.stem(), u.suffix()))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Parses a numeric column header `<quantity>_<unit suffix>`.
///
/// Returns `Ok(Some(column))` for a known quantity with a known unit, `Err` for a known quantity
/// with an unknown suffix (`speed_mph`), and `Ok(None)` for a header that names no known quantity
/// (text columns such as `subject`, or extra columns gaitfit ignores). Matching is
/// case-insensitive and ignores surrounding whitespace.
pub fn parse_header(header: &str) -> Result<Option<Column>, UnknownUnit> {
    let h = header.trim().to_ascii_lowercase();
    // Longest stem first, so `double_support_time_s` is not read as `double_support` + `time_s`.
    let mut best: Option<(Quantity, &str)> = None;
    for q in Quantity::ALL {
        let stem = q.stem();
        if let Some(rest) = h.strip_prefix(stem).and_then(|r| r.strip_prefix('_')) {
            if best.is_none_or(|(b, _)| b.stem().len() < stem.len()) {
                best = Some((q, rest));
            }
        }
    }
    let Some((quantity, suffix)) = best else {
        return Ok(None);
    };
    // `double_support_time_*` has the longer stem; `double_support_pct_cycle` falls through to
    // the percentage quantity.
    match quantity
        .dimension()
        .units()
        .iter()
        .find(|u| u.suffix() == suffix)
    {
        Some(&unit) => Ok(Some(Column { quantity, unit })),
        None => Err(UnknownUnit {
            quantity,
            suffix: suffix.to_string(),
        }),
    }
}

/// A command-line value that could not be read ([`parse_value`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{text:?}: {reason}")]
pub struct ValueError {
    /// The text given.
    pub text: String,
    /// What is wrong, with the accepted units.
    pub reason: String,
}

/// The unit written after a number on the command line or in a schedule cell, for `dim`:
/// the spellings people type (`km/h`, `/min`, `Hz`, `°`) and the header suffixes
/// ([`Unit::suffix`]: `km_per_h`, `steps_per_min`, …). `None` if `unit` is not one of them.
pub fn value_unit(dim: Dimension, unit: &str) -> Option<Unit> {
    let u = unit.to_ascii_lowercase();
    let typed = match (dim, u.as_str()) {
        (Dimension::Speed, "m/s" | "mps") => Some(Unit::MPerS),
        (Dimension::Speed, "km/h" | "kmh" | "kph") => Some(Unit::KmPerH),
        (Dimension::Speed, "m/min") => Some(Unit::MPerMin),
        (Dimension::Frequency, "/min" | "spm" | "steps/min") => Some(Unit::StepsPerMin),
        (Dimension::Frequency, "/s" | "steps/s") => Some(Unit::StepsPerS),
        (Dimension::Angle, "°") => Some(Unit::Deg),
        (Dimension::PercentCycle, "%") => Some(Unit::PctCycle),
        _ => None,
    };
    typed.or_else(|| dim.units().iter().copied().find(|x| x.suffix() == u))
}

/// The unit of a bare number for `dim` on the command line: m, m/s, steps/min, s, degrees, %.
pub fn bare_unit(dim: Dimension) -> Unit {
    match dim {
        Dimension::Length => Unit::M,
        Dimension::Speed => Unit::MPerS,
        Dimension::Frequency => Unit::StepsPerMin,
        Dimension::Time => Unit::S,
        Dimension::PercentCycle => Unit::PctCycle,
        Dimension::Angle => Unit::Deg,
    }
}

/// Parses a number with an optional unit into SI for `dim` — the one parser of values with
/// units for the whole command line (speeds, lengths, frequencies, durations, angles):
/// `12km/h`, `3.3 m/s`, `200m/min`, `1.07m`, `107cm`, `4mm`, `187/min`, `3.1Hz`, `15deg`,
/// `0.26rad`, `250ms`, or a header suffix (`12km_per_h`). A bare number is in
/// [`bare_unit`]'s unit (m, m/s, steps/min, s, degrees).
///
/// ```
/// use gaitfit::units::{parse_value, Dimension};
/// assert!((parse_value("12km/h", Dimension::Speed).unwrap() - 12.0 / 3.6).abs() < 1e-12);
/// assert!((parse_value("187/min", Dimension::Frequency).unwrap() - 187.0 / 60.0).abs() < 1e-12);
/// assert!((parse_value("180cm", Dimension::Length).unwrap() - 1.8).abs() < 1e-12);
/// assert!(parse_value("12 furlongs", Dimension::Speed).is_err());
/// ```
pub fn parse_value(text: &str, dim: Dimension) -> Result<f64, ValueError> {
    let err = |reason: String| ValueError {
        text: text.to_string(),
        reason,
    };
    let t: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let split = t
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || ((c == '-' || c == '+') && (i == 0 || t[..i].ends_with(['e', 'E'])))
                || ((c == 'e' || c == 'E')
                    && i > 0
                    && t[i + 1..]
                        .starts_with(|d: char| d.is_ascii_digit() || d == '-' || d == '+')))
        })
        .map_or(t.len(), |(i, _)| i);
    let (num, unit) = t.split_at(split);
    let v: f64 = num
        .parse()
        .map_err(|_| err("no number at the start".into()))?;
    if !v.is_finite() {
        return Err(err("not a finite number".into()));
    }
    let unit = if unit.is_empty() {
        bare_unit(dim)
    } else {
        value_unit(dim, unit).ok_or_else(|| {
            let accepted = match dim {
                Dimension::Speed => "km/h, m/s, m/min",
                Dimension::Length => "m, cm, mm, in",
                Dimension::Frequency => "/min (steps/min), Hz or /s (steps/s)",
                Dimension::Angle => "deg, rad",
                Dimension::Time => "s, ms",
                Dimension::PercentCycle => "%",
            };
            err(format!(
                "unknown unit {unit:?}; use {accepted} (a bare number is {})",
                bare_unit(dim).suffix().replace("_per_", "/")
            ))
        })?
    };
    Ok(v * unit.to_si_factor())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_documented_suffix() {
        let cases = [
            ("body_height_m", Quantity::BodyHeight, 1.0),
            ("body_height_cm", Quantity::BodyHeight, 0.01),
            ("body_height_mm", Quantity::BodyHeight, 0.001),
            ("leg_length_m", Quantity::LegLength, 1.0),
            ("leg_length_cm", Quantity::LegLength, 0.01),
            ("leg_length_mm", Quantity::LegLength, 0.001),
            ("speed_m_per_s", Quantity::Speed, 1.0),
            ("speed_m_per_min", Quantity::Speed, 1.0 / 60.0),
            ("speed_km_per_h", Quantity::Speed, 1.0 / 3.6),
            ("step_length_m", Quantity::StepLength, 1.0),
            ("step_length_cm", Quantity::StepLength, 0.01),
            ("step_freq_steps_per_min", Quantity::StepFreq, 1.0 / 60.0),
            ("step_freq_hz", Quantity::StepFreq, 1.0),
            ("flight_time_s", Quantity::FlightTime, 1.0),
            ("flight_time_ms", Quantity::FlightTime, 0.001),
            ("double_support_time_s", Quantity::DoubleSupportTime, 1.0),
            ("double_support_time_ms", Quantity::DoubleSupportTime, 0.001),
            ("double_support_pct_cycle", Quantity::DoubleSupportPct, 1.0),
            ("stance_time_s", Quantity::StanceTime, 1.0),
            ("swing_time_s", Quantity::SwingTime, 1.0),
            (
                "knee_angle_hs_deg",
                Quantity::KneeAngleHs,
                std::f64::consts::PI / 180.0,
            ),
            ("knee_angle_hs_rad", Quantity::KneeAngleHs, 1.0),
            ("Speed_M_Per_S ", Quantity::Speed, 1.0),
        ];
        for (h, q, f) in cases {
            let c = parse_header(h).unwrap().unwrap();
            assert_eq!(c.quantity, q, "{h}");
            assert!((c.to_si(1.0) - f).abs() < 1e-15, "{h}");
            assert!((c.from_si(c.to_si(3.7)) - 3.7).abs() < 1e-12);
        }
    }

    #[test]
    fn unknown_suffix_is_an_error_listing_the_accepted_ones() {
        let e = parse_header("speed_mph").unwrap_err();
        assert_eq!(e.quantity, Quantity::Speed);
        assert_eq!(e.suffix, "mph");
        assert!(e.accepted().contains("speed_km_per_h"));
        assert!(parse_header("step_length_furlongs").is_err());
    }

    #[test]
    fn text_and_unrelated_columns_are_not_quantities() {
        for h in ["subject", "gait", "source", "trial", "side", "mass_kg"] {
            assert_eq!(parse_header(h).unwrap(), None, "{h}");
        }
    }

    #[test]
    fn canonical_headers_round_trip() {
        for q in Quantity::ALL {
            let h = q.canonical_header();
            let c = parse_header(&h).unwrap().unwrap();
            assert_eq!(c.quantity, q);
            assert!(
                crate::ingest::trials::CANONICAL_COLUMNS.contains(&h.as_str()),
                "{h}"
            );
        }
    }

    #[test]
    fn values_with_units() {
        let close = |t: &str, d: Dimension, v: f64| {
            let got = parse_value(t, d).unwrap();
            assert!(
                (got - v).abs() < 1e-12 * v.abs().max(1.0),
                "{t}: {got} vs {v}"
            );
        };
        close("12km/h", Dimension::Speed, 12.0 / 3.6);
        close("12 km/h", Dimension::Speed, 12.0 / 3.6);
        close("12kmh", Dimension::Speed, 12.0 / 3.6);
        close("12km_per_h", Dimension::Speed, 12.0 / 3.6);
        close("3.3m/s", Dimension::Speed, 3.3);
        close("1.4", Dimension::Speed, 1.4);
        close("84m/min", Dimension::Speed, 1.4);
        close("187/min", Dimension::Frequency, 187.0 / 60.0);
        close("187", Dimension::Frequency, 187.0 / 60.0);
        close("3.1Hz", Dimension::Frequency, 3.1);
        close("3.1steps_per_s", Dimension::Frequency, 3.1);
        close("4mm", Dimension::Length, 0.004);
        close("180cm", Dimension::Length, 1.8);
        close("70in", Dimension::Length, 1.778);
        close("1e-3m", Dimension::Length, 0.001);
        close("1.5e+2cm", Dimension::Length, 1.5);
        close("-15deg", Dimension::Angle, -15f64.to_radians());
        close("15°", Dimension::Angle, 15f64.to_radians());
        close("0.2rad", Dimension::Angle, 0.2);
        close("250ms", Dimension::Time, 0.25);
        for (t, d) in [
            ("12 furlongs", Dimension::Speed),
            ("fast", Dimension::Speed),
            ("1.8kg", Dimension::Length),
            ("inf", Dimension::Length),
            ("1-2m", Dimension::Length),
            ("", Dimension::Time),
        ] {
            let e = parse_value(t, d).unwrap_err().to_string();
            assert!(e.contains(&format!("{t:?}")), "{e}");
        }
        let e = parse_value("12mph", Dimension::Speed)
            .unwrap_err()
            .to_string();
        assert!(e.contains("km/h, m/s, m/min"), "{e}");
    }

    #[test]
    fn paper_unit_helpers() {
        assert!((m_per_s_to_m_per_min(km_per_h_to_m_per_s(12.0)) - 200.0).abs() < 1e-12);
        assert!((hz_to_steps_per_min(steps_per_min_to_hz(187.0)) - 187.0).abs() < 1e-12);
    }
}
