//! Recovery 3 of §3.3.1, foot stubbing: where a swinging foot comes closer to the ground than
//! its required clearance, a control point with more knee flexion is inserted.
use super::*;

/// Shortest time over which a swinging foot's required clearance grows from zero (after toe
/// off) or shrinks to zero (before heel strike), s.
pub const CLEARANCE_RAMP: f64 = 0.1;

/// Required clearance of a swinging foot at time `t` of a window [t_a, t_b] that starts
/// (`ramp_in`) and/or ends (`ramp_out`) at a ground contact: `margin`, ramped smoothly from zero
/// over the first/last quarter of the window (a foot leaves and reaches the ground with the
/// joint rates of the neighbouring phase, so its height grows from zero smoothly).
pub(super) fn required_clearance(
    t: f64,
    t_a: f64,
    t_b: f64,
    ramp_in: bool,
    ramp_out: bool,
    margin: f64,
) -> f64 {
    // A quarter of the window, but at least CLEARANCE_RAMP: short flights (slow runs) need not
    // lift the foot a full margin within a few milliseconds.
    let q = (0.25 * (t_b - t_a)).max(CLEARANCE_RAMP);
    let ramp = |tau: f64| {
        let s = (tau / q).clamp(0.0, 1.0);
        s * s * (3.0 - 2.0 * s)
    };
    let mut r = margin;
    if ramp_in {
        r = r.min(margin * ramp(t - t_a));
    }
    if ramp_out {
        r = r.min(margin * ramp(t_b - t));
    }
    r
}

/// Checks a swinging foot's clearance on a track over [t_a, t_b] and, where it stubs the
/// ground, adds a temporary knee flexion peaking at the worst instant (§3.3.1's recovery:
/// "inserts a new control point with temporarily increased knee flexion"), raised until the
/// foot clears. Returns the number of raises and the deficit before the first (m, 0 if the
/// foot cleared).
#[allow(clippy::too_many_arguments)]
pub(super) fn clear_track(
    plan: &mut StepPlan,
    d: &RunnerDims,
    sign: f64,
    hind: bool,
    t_a: f64,
    t_b: f64,
    ramp_in: bool,
    ramp_out: bool,
    margin: f64,
) -> (u32, f64) {
    let n = 40;
    let worst = |plan: &StepPlan| {
        let track = if hind { &plan.hind } else { &plan.swing };
        let mut worst = (0.0, 0.0); // (deficit, t)
        for i in 1..n {
            let t = t_a + (t_b - t_a) * i as f64 / n as f64;
            let (ang, _) = track.eval(t);
            let pts = leg_fk(d, hip_of(plan, d, t, sign), &ang);
            // A twentieth of a millimetre of slack (numerical noise), so the foot is strictly off
            // the ground wherever the requirement is positive.
            let deficit =
                required_clearance(t, t_a, t_b, ramp_in, ramp_out, margin) - pts.lowest() - 0.00005;
            if deficit > worst.0 {
                worst = (deficit, t);
            }
        }
        worst
    };
    let (deficit, t_worst) = worst(plan);
    if deficit <= 0.0 {
        return (0, 0.0);
    }
    let first = deficit;
    // The bump's peak is kept off the window's ends so the extra flexion builds up smoothly.
    // A held bump (hind leg) may peak after the window: the next step inherits its value and
    // rate.
    let t_peak = if hind {
        t_worst.max(t_a + 0.5 * (t_b - t_a))
    } else {
        t_worst.clamp(t_a + 0.3 * (t_b - t_a), t_b - 0.3 * (t_b - t_a))
    };
    let mut raises = 0;
    let mut deficit = deficit;
    let lever = 0.5 * d.shank;
    while deficit > 0.0 && raises < 16 {
        let track = if hind {
            &mut plan.hind
        } else {
            &mut plan.swing
        };
        track.bump = KneeBump {
            t0: t_a,
            peak: t_peak,
            t1: t_b,
            amount: track.bump.amount + (deficit / lever).max(3f64.to_radians()),
            hold: hind,
        };
        raises += 1;
        deficit = worst(plan).0;
    }
    (raises, first)
}
