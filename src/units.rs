//! Unit-suffixed column names → SI, and SI → the papers' units.
//!
//! Every numeric CSV header carries its unit (`speed_m_per_s`, `step_freq_steps_per_min`, …).
//! gaitfit converts once, at the boundary, to SI (m, m/s, s, steps/s, rad); the relations convert
//! to the papers' units (m/min, steps/min) where the published coefficients are expressed in them.

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
