//! Axis tick labels: as many decimals as the tick step needs, and no "-0".
//!
//! plotters formats an f64 tick with `{}`-style rules of its own, which wrote "100.0" beside
//! "95" and "-0.0" at zero. Here the step of the ticks plotters will draw (its own key points
//! for the axis range) fixes one number of decimals for the whole axis.
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;

/// Tick labels per axis (plotters' default, set explicitly so [`decimals`] sees the same ticks).
pub const LABELS: usize = 10;

/// The ticks plotters draws on an axis over `lo..hi` with at most `n` labels.
pub fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    RangedCoordf64::from(lo..hi).key_points(n)
}

/// Decimals needed to write every tick of `lo..hi` (at most `n` labels) exactly.
pub fn decimals(lo: f64, hi: f64, n: usize) -> usize {
    let t = ticks(lo, hi, n);
    let step = t
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(f64::INFINITY, f64::min);
    if !step.is_finite() || step <= 0.0 {
        // One tick: enough decimals for its own value.
        return t.first().map_or(0, |v| decimals_of(*v));
    }
    decimals_of(step)
}

/// The fewest decimals (≤ 12) that write `v` to within a millionth of itself.
fn decimals_of(v: f64) -> usize {
    let v = v.abs();
    if v == 0.0 {
        return 0;
    }
    (0..=12)
        .find(|&d| {
            let s = v * 10f64.powi(d as i32);
            (s - s.round()).abs() <= 1e-6 * s.max(1.0)
        })
        .unwrap_or(12)
}

/// `v` with `d` decimals; a value that rounds to zero is written "0" (never "-0.0").
pub fn label(v: f64, d: usize) -> String {
    let s = format!("{v:.d$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_steps_have_no_decimals_and_zero_has_no_sign() {
        let d = decimals(94.0, 166.0, LABELS);
        assert_eq!(d, 0);
        assert_eq!(label(100.0, d), "100");
        let d = decimals(-0.31, 0.29, LABELS);
        assert_eq!(d, 1);
        assert_eq!(label(-0.0, d), "0");
        assert_eq!(label(-1e-17, d), "0");
        assert_eq!(label(-0.1, d), "-0.1");
        assert_eq!(label(0.30000000000000004, d), "0.3");
    }

    #[test]
    fn decimals_follow_the_step_plotters_draws() {
        for (lo, hi) in [
            (0.0, 1.0),
            (0.0, 0.05),
            (140.0, 210.0),
            (-3.2, 7.7),
            (1e-4, 9e-4),
        ] {
            let d = decimals(lo, hi, LABELS);
            let t = ticks(lo, hi, LABELS);
            assert!(t.len() >= 2, "{lo}..{hi}");
            // Every tick is written exactly, and one decimal fewer would not do for all.
            for v in &t {
                let back: f64 = label(*v, d).parse().unwrap();
                assert!(
                    (back - v).abs() <= 1e-9 * (hi - lo),
                    "{v} → {}",
                    label(*v, d)
                );
            }
            if d > 0 {
                assert!(t.iter().any(|v| {
                    let back: f64 = label(*v, d - 1).parse().unwrap();
                    (back - v).abs() > 1e-9 * (hi - lo)
                }));
            }
        }
    }
}
