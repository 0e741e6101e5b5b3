//! Property tests of the running generator over the paper's range (2–25 km/h) and body heights
//! 1.5–2.0 m: steady state reaches the commanded v, sl, sf (1 %), t_flight and H within one
//! frame of eqs. 3–5; both feet are off the ground exactly during flight; no stance-foot sliding
//! (≤ 2 mm), no ground penetration (≤ 1 mm); the swing foot clears the ground; joints and
//! landmarks are continuous; left and right are mirror images one step apart. Modest case
//! counts keep CI fast (each case generates a few seconds of motion in milliseconds).
use gaitfit::events::{EventKind, Side};
use gaitfit::generator::checks::{
    contact_on_ground, flight_timing, ground_penetration, stance_sliding, swing_clearance,
    symmetry, ContinuityOptions,
};
use gaitfit::generator::motion::{Motion, MotionMetadata};
use gaitfit::generator::running::state::G;
use gaitfit::generator::running::{
    generate_run, GenerateOptions, Param, RunAttributes, RunModel, RunParams, RunReport, Runner,
    Schedule,
};
use gaitfit::generator::skeleton::{mirror_vec, side_index, Joint, Landmark};
use proptest::prelude::*;

const FPS: f64 = 120.0;

thread_local! {
    /// Worst value of each measured quantity in this test's thread, with where it occurred
    /// (printed by `worst_cases_over_a_grid`).
    static WORST: std::cell::RefCell<std::collections::BTreeMap<&'static str, (f64, String)>> =
        Default::default();
}

/// Records `value` of quantity `name` (larger is worse).
fn note(name: &'static str, value: f64, at: impl FnOnce() -> String) {
    WORST.with(|w| {
        let mut w = w.borrow_mut();
        let e = w.entry(name).or_insert((f64::NEG_INFINITY, String::new()));
        if value > e.0 {
            *e = (value, at());
        }
    });
}

fn run(kmh: f64, h: f64, seconds: f64, stop: bool) -> (Motion, RunReport, RunParams) {
    let m = RunModel::published(h).unwrap();
    let a = RunAttributes::defaults(h);
    let p = m.natural(kmh / 3.6, 0.0, &a).unwrap();
    let (mo, rep) = run_params(&m, p, None, seconds, stop);
    (mo, rep, p)
}

fn run_params(
    m: &RunModel,
    p: RunParams,
    schedule: Option<Schedule>,
    seconds: f64,
    stop: bool,
) -> (Motion, RunReport) {
    let a = RunAttributes::defaults(p.body_height);
    let opts = GenerateOptions {
        seconds,
        fps: FPS,
        stop_at_end: stop,
    };
    generate_run(m, p, a, schedule, &opts).unwrap()
}

/// The ground checks every generated motion must pass (the whole motion: start from a stand,
/// build-up, changes and stop included).
fn ground_checks(mo: &Motion, what: &str) -> Result<(), TestCaseError> {
    for r in [
        stance_sliding(mo, 0.002, 0.002),
        ground_penetration(mo, 0.001),
        contact_on_ground(mo, 0.001),
        swing_clearance(mo, 0.5, 0.005),
    ] {
        // Clearance is a minimum (smaller is worse): noted negated.
        let v = if r.check == "swing_clearance" {
            -r.worst
        } else {
            r.worst
        };
        note(r.check, v, || format!("{what}: {r}"));
        prop_assert!(r.passed, "{what}: {r}");
    }
    let (ratio, at) = interior_continuity(mo, &ContinuityOptions::default());
    note("continuity_ratio", ratio, || format!("{what}: {at}"));
    prop_assert!(ratio <= 5.0, "{what}: continuity ratio {ratio:.2} at {at}");
    Ok(())
}

/// Frames [a, b) of a motion as a motion of their own (for checks on the steady part).
fn sub(m: &Motion, a: usize, b: usize) -> Motion {
    let mut o = Motion::new(m.skeleton().clone(), m.fps(), MotionMetadata::default()).unwrap();
    for i in a..b.min(m.len()) {
        o.push_frame(*m.pose(i), m.contacts()[i]);
    }
    o
}

/// The continuity measure of `gaitfit::generator::checks::continuity` (each frame-to-frame step
/// of every landmark and joint rotation against the median of the `window` steps on either
/// side, with the same floors), evaluated where the window is complete on both sides: at a
/// clip's very end the window is one-sided, and a joint that starts moving in the last frames
/// (a run cut just after a toe off) would be compared with nothing but the rest before it.
fn interior_continuity(m: &Motion, o: &ContinuityOptions) -> (f64, String) {
    let w = o.window;
    let n = m.len();
    let mut worst = (0.0, String::new());
    let mut scan = |steps: &[f64], floor: f64, name: &str| {
        for i in w..steps.len().saturating_sub(w) {
            let mut nb: Vec<f64> = steps[i - w..i]
                .iter()
                .chain(steps[i + 1..=i + w].iter())
                .copied()
                .collect();
            nb.sort_by(f64::total_cmp);
            let med = 0.5 * (nb[w - 1] + nb[w]);
            let r = steps[i] / med.max(floor);
            if r > worst.0 {
                worst = (r, format!("frame {i}, {name}"));
            }
        }
    };
    for l in Landmark::ALL {
        let s: Vec<f64> = (0..n - 1)
            .map(|i| (m.landmark(i + 1, l) - m.landmark(i, l)).length())
            .collect();
        scan(&s, o.floor_m, l.name());
    }
    for j in Joint::ALL {
        let s: Vec<f64> = (0..n - 1)
            .map(|i| {
                let r =
                    m.pose(i).rotations[j.index()].conjugate() * m.pose(i + 1).rotations[j.index()];
                2.0 * r.xyz().length().atan2(r.w.abs())
            })
            .collect();
        scan(&s, o.floor_rad, j.name());
    }
    worst
}

/// Heel strikes from the contact flags: (frame of the rising edge, side).
fn touchdowns(m: &Motion) -> Vec<(usize, Side)> {
    let c = m.contacts();
    let mut out = Vec::new();
    for i in 1..c.len() {
        for side in [Side::Left, Side::Right] {
            let k = side_index(side);
            if c[i][k] && !c[i - 1][k] {
                out.push((i, side));
            }
        }
    }
    out.sort_by_key(|t| t.0);
    out
}

/// The footprint (heel on the ground) of the contact run starting at frame `f`.
fn footprint_x(m: &Motion, f: usize, side: Side) -> f64 {
    let heel = Landmark::foot(side)[0];
    let mut best = (f64::INFINITY, 0.0);
    let mut i = f;
    while i < m.len() && m.contact(i, side) {
        let p = m.landmark(i, heel);
        if p.y < best.0 {
            best = (p.y, p.x);
        }
        i += 1;
    }
    best.1
}

fn check_steady(kmh: f64, h: f64) -> Result<(), TestCaseError> {
    let m = RunModel::published(h).unwrap();
    let p = m
        .natural(kmh / 3.6, 0.0, &RunAttributes::defaults(h))
        .unwrap();
    let reachable = check_steady_params(&m, p)?;
    prop_assert!(
        reachable,
        "{kmh:.2} km/h, h {h:.2} m: natural parameters out of reach"
    );
    Ok(())
}

/// Runs at `p` (from a stand, building up speed) and checks the steady state and the ground.
/// Returns false, having checked nothing else, when the generator reported the stance hip out
/// of the leg's reach (a step too long for the figure at that frequency): the user is told
/// (a report note), and the stance foot may then lift.
fn check_steady_params(m: &RunModel, p: RunParams) -> Result<bool, TestCaseError> {
    let kmh = p.speed * 3.6;
    let h = p.body_height;
    // Long enough for the start, the speed build-up and ten steady steps.
    let (mo, rep) = run_params(m, p, None, 1.0 + 20.0 / p.step_freq, false);
    if rep.steps.iter().any(|s| s.report.out_of_reach) {
        prop_assert!(
            rep.notes.iter().any(|n| n.contains("out of reach")),
            "out of reach, silently"
        );
        return Ok(false);
    }
    let dt = 1.0 / FPS;
    ground_checks(
        &mo,
        &format!(
            "{kmh:.2} km/h, sf {:.1}/min, h {h:.2} m",
            p.step_freq * 60.0
        ),
    )?;
    // Both feet off the ground exactly during flight: every frame with both contact flags clear
    // has all six sole points strictly above the ground; in contact, the foot touches (checked
    // above by contact_on_ground). The toe leaves the ground tangentially, so within a
    // millisecond of a toe off (or heel strike) it may still sit on the ground to rounding (1 µm).
    let near_event = |t: f64| {
        mo.events.iter().any(|e| {
            matches!(e.kind, EventKind::ToeOff | EventKind::HeelStrike)
                && (e.time_s - t).abs() < 1e-3
        })
    };
    for i in 0..mo.len() {
        if mo.contacts()[i] == [false, false] {
            let floor = if near_event(mo.frame_time(i)) {
                -1e-6
            } else {
                0.0
            };
            for side in [Side::Left, Side::Right] {
                for l in Landmark::foot(side) {
                    let y = mo.landmark(i, l).y;
                    prop_assert!(
                        y > floor,
                        "{kmh:.2} km/h: frame {i} in flight, {} at {y}",
                        l.name()
                    );
                }
            }
        }
    }
    // Steady state: from the second touchdown after the last step that was still building up
    // speed from the stand (the runner accelerates from a stand step by step).
    let td = touchdowns(&mo);
    let ramp = rep
        .steps
        .iter()
        .filter(|s| (s.speed - p.speed).abs() > 1e-9)
        .count();
    prop_assert!(
        td.len() >= ramp + 8,
        "{} touchdowns, {ramp} ramp steps",
        td.len()
    );
    let steady = &td[ramp + 1..];
    let n = steady.len() - 1;
    // Step length: successive footprints.
    for w in steady.windows(2) {
        let sl = footprint_x(&mo, w[1].0, w[1].1) - footprint_x(&mo, w[0].0, w[0].1);
        note("sl_rel_error", (sl / p.step_length - 1.0).abs(), || {
            format!("{kmh:.2} km/h, h {h:.2}")
        });
        prop_assert!(
            (sl / p.step_length - 1.0).abs() < 0.01,
            "{kmh:.2} km/h: sl {sl} vs {}",
            p.step_length
        );
    }
    // Step frequency: touchdown frames over n steps (one-frame resolution over n steps).
    let span = (steady[n].0 - steady[0].0) as f64 * dt;
    let sf = n as f64 / span;
    note("sf_rel_error", (sf / p.step_freq - 1.0).abs(), || {
        format!("{kmh:.2} km/h, h {h:.2}")
    });
    prop_assert!(
        (sf / p.step_freq - 1.0).abs() < 0.01,
        "{kmh:.2} km/h: sf {sf} vs {}",
        p.step_freq
    );
    // Speed: pelvis displacement over whole strides.
    let k = if n % 2 == 0 { n } else { n - 1 };
    let (fa, fb) = (steady[0].0, steady[k].0);
    let v = (mo.landmark(fb, Landmark::Pelvis).x - mo.landmark(fa, Landmark::Pelvis).x)
        / ((fb - fa) as f64 * dt);
    note("v_rel_error", (v / p.speed - 1.0).abs(), || {
        format!("{kmh:.2} km/h, h {h:.2}")
    });
    prop_assert!(
        (v / p.speed - 1.0).abs() < 0.01,
        "{kmh:.2} km/h: v {v} vs {}",
        p.speed
    );
    // Flight time within one frame of eqs. 4–5 (frames with both feet off the ground).
    let st = sub(&mo, steady[0].0, steady[n].0);
    let ft = flight_timing(&st, p.flight_time, dt);
    note("t_flight_error_frames", ft.worst / dt, || {
        format!("{kmh:.2} km/h, h {h:.2}: {ft}")
    });
    prop_assert!(ft.passed && ft.examined >= 3, "{kmh:.2} km/h: {ft}");
    // Flight height within one frame of eq. 3: apex of the pelvis over each flight's frames
    // minus its height at toe off, sampled from the generator at the exact toe-off time. Not
    // interpolated between the frames around it: at sprint cadences the pelvis decelerates
    // from rising ~5 m/s to eq. 3's take-off speed within the last frames of a 65 ms support
    // (~500 m/s², 25 km/h, 1.50 m, 271 steps/min), and the chord across the toe off then lies
    // up to |y''|·dt²/8 ≈ 4 mm low, twice the 2.5 mm H itself (measured 5.5 mm for an exact
    // 2.50 mm; hidden while this property stayed below 259 steps/min for the arms).
    let mut exact = Runner::new(m.clone(), p, RunAttributes::defaults(h), None).unwrap();
    let mut q = m.skeleton.rest_pose();
    let mut pel = |t: f64| {
        exact.pose_at(t, &mut q).unwrap();
        m.skeleton.landmarks(&q)[Landmark::Pelvis.index()].y
    };
    let t0 = steady[0].0 as f64 * dt;
    let mut toe_offs: Vec<_> = mo
        .events
        .iter()
        .filter(|e| {
            e.kind == EventKind::ToeOff
                && e.time_s > t0
                && e.time_s + p.flight_time < mo.duration_s()
        })
        .collect();
    // The generator is sampled forward in time.
    toe_offs.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    for e in toe_offs {
        let (a, b) = (
            (e.time_s * FPS).ceil() as usize,
            ((e.time_s + p.flight_time) * FPS).floor() as usize,
        );
        let apex = (a..=b)
            .map(|i| mo.landmark(i, Landmark::Pelvis).y)
            .fold(f64::NEG_INFINITY, f64::max);
        let measured = (apex - pel(e.time_s)).max(0.0);
        // Eq. 3's H is the apex of the flight parabola above the toe-off height; when the pelvis
        // lands much higher than it took off (long steps at a low frequency) the apex lies
        // beyond the landing, and the highest point in flight is the landing instead.
        let w = rep.steps[ramp + 1].report.takeoff_vy.max(0.0);
        let t_f = p.flight_time;
        prop_assert!(
            w == 0.0 || (w * w / (2.0 * G) / p.flight_height - 1.0).abs() < 1e-6,
            "{kmh:.2} km/h: take-off speed {w} vs H {}",
            p.flight_height
        );
        let one_frame = w * dt + G * dt * dt;
        let expected = if w / G <= t_f {
            w * w / (2.0 * G)
        } else {
            w * t_f - 0.5 * G * t_f * t_f
        };
        note(
            "H_error_in_one_frame_units",
            (measured - expected).abs() / one_frame,
            || format!("{kmh:.2} km/h, h {h:.2}: H {measured} vs {expected}"),
        );
        prop_assert!(
            (measured - expected).abs() <= one_frame,
            "{kmh:.2} km/h: H {measured} vs {expected} (one frame {one_frame})"
        );
    }
    // Left/right symmetry at constant parameters: one step later the figure is its own mirror.
    // On the frames: the check interpolates linearly between frames at t + one step, which errs
    // by up to |x''|·dt²/8 on smooth motion and by a quarter of the second difference across a
    // velocity kink (a heel landing) — for a fast foot about 2 cm at 120 fps — so the tolerance
    // is a quarter of the motion's own largest second difference, plus 2 mm (joints: 0.02 rad)…
    let mut d2 = 0.0f64;
    for i in 1..st.len() - 1 {
        for l in Landmark::ALL {
            let a = st.landmark(i + 1, l) - 2.0 * st.landmark(i, l) + st.landmark(i - 1, l);
            d2 = d2.max(a.length());
        }
    }
    let mut r2 = 0.0f64;
    for i in 1..st.len() - 1 {
        for j in Joint::ALL {
            let q = |k: usize| st.pose(k).rotations[j.index()];
            let a = (q(i).conjugate() * q(i + 1)).to_scaled_axis();
            let b = (q(i - 1).conjugate() * q(i)).to_scaled_axis();
            r2 = r2.max((a - b).length());
        }
    }
    let sym = symmetry(
        &st,
        0..st.len(),
        1.0 / p.step_freq,
        d2 / 4.0 + 0.002,
        r2 / 4.0 + 0.02,
    );
    note("symmetry_frames_landmarks_m", sym.landmarks.worst, || {
        format!("{kmh:.2} km/h, h {h:.2}: {}", sym.landmarks)
    });
    note("symmetry_frames_joints_rad", sym.joints.worst, || {
        format!("{kmh:.2} km/h, h {h:.2}: {}", sym.joints)
    });
    prop_assert!(
        sym.landmarks.passed && sym.joints.passed,
        "{kmh:.2} km/h: {} / {}",
        sym.landmarks,
        sym.joints
    );
    // …and exactly, by sampling the generator itself at t and t + one step.
    let m = m.clone();
    let a = RunAttributes::defaults(h);
    let sk = m.skeleton.clone();
    let mut r0 = Runner::new(m.clone(), p, a.clone(), None).unwrap();
    let mut r1 = Runner::new(m, p, a, None).unwrap();
    let (mut q0, mut q1) = (sk.rest_pose(), sk.rest_pose());
    let step = 1.0 / p.step_freq;
    let t_start = steady[0].0 as f64 * dt;
    for i in 0..40 {
        let t = t_start + i as f64 * step / 13.0;
        r0.pose_at(t, &mut q0).unwrap();
        r1.pose_at(t + step, &mut q1).unwrap();
        let (l0, l1) = (sk.landmarks(&q0), sk.landmarks(&q1));
        let (p0, p1) = (l0[Landmark::Pelvis.index()], l1[Landmark::Pelvis.index()]);
        for l in Landmark::ALL {
            let a = mirror_vec(l0[l.index()] - p0);
            let b = l1[l.mirrored().index()] - p1;
            note("symmetry_exact_m", (a - b).length(), || {
                format!("{kmh:.2} km/h, h {h:.2}: {}", l.name())
            });
            prop_assert!(
                (a - b).length() < 1e-6,
                "{kmh:.2} km/h: t {t:.4}: {} vs {} differ by {}",
                l.name(),
                l.mirrored().name(),
                (a - b).length()
            );
        }
    }
    Ok(true)
}

proptest! {
    // 32 cases each in CI; `RUNNER_PROPTEST_CASES=1000` for a deeper search.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("RUNNER_PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(32),
        failure_persistence: None,
        .. ProptestConfig::default()
    })]
    #[test]
    fn steady_running_invariants(kmh in 2.0f64..25.0, h in 1.5f64..2.0) {
        check_steady(kmh, h)?;
    }

    /// The paper's Fig. 4 manipulation over the range: speed locked, step frequency moved off
    /// its natural value (step length gives way, eq. 1); the steady state reaches the new sl, sf.
    /// −10 % to +10 %, up to 271 steps/min (25 km/h, 1.50 m), where the stance lasts ≈ 65 ms:
    /// see `arms_are_continuous_at_sprint_cadences`.
    #[test]
    fn locked_speed_other_step_frequency(kmh in 6.0f64..25.0, h in 1.5f64..2.0, f in 0.9f64..1.1) {
        let m = RunModel::published(h).unwrap();
        let a = RunAttributes::defaults(h);
        let mut p = m.natural(kmh / 3.6, 0.0, &a).unwrap();
        p.locks.set(Param::Speed, true);
        let p = m.set(&p, Param::StepFreq, p.step_freq * f, &a).unwrap();
        prop_assert!((p.speed * 3.6 - kmh).abs() < 1e-9);
        // Long steps at a low frequency can be beyond the figure's legs (reported, not run).
        let reachable = check_steady_params(&m, p)?;
        prop_assume!(reachable);
    }

    /// The same invariants with the repository's refitted relations (`fits/`, as `--fits fits/`
    /// uses them), 2–18 km/h (18 km/h ≈ the top of the data, Hamner's 5 m/s). The range started
    /// at 6 km/h for an elbow continuity ratio of 5.4 at 5.1 km/h, 1.73 m; on f83c97b (before
    /// the arms followed a phase) that case measured 3.60 (l_ankle), and a grid over 2–6 km/h
    /// every 0.05 × 1.5–2.0 m every 0.05 passed every check both then and now (continuity ≤ 4.20
    /// over 2–6.5 km/h every 0.02 × every 0.01 m, at an ankle). Faster, beyond eq. 5's data
    /// (> 209 steps/min), the fitted relation holds its boundary value (it once followed its
    /// cubic to 0.231 s of flight, which the generator refused; see
    /// `refitted_relations_refuse_too_short_supports`). Eq. 5's real-data flights (~0.1 s at
    /// 18 km/h against the published 0.19 s) leave long supports (1.1 m of ground); the landing
    /// moves ahead for them (`refitted_long_supports_land_ahead`).
    #[test]
    fn refitted_relations_run_cleanly(kmh in 2.0f64..18.0, h in 1.5f64..2.0) {
        refitted_case(kmh, h)?;
    }

    /// Parameter changes at the next step (a schedule changing speed twice, then a stop): the
    /// ground checks and the continuity of every joint and landmark hold across the changes,
    /// and the run ends standing.
    #[test]
    /// Each change is at most 10 km/h (a runner does not go from 25 to 2 km/h in one step). The
    /// cap was also given for the arms, which when they copied the legs swept faster than the
    /// continuity criterion at such jumps; with the phase-driven arms every jump of more than
    /// 10 km/h within 2–25 km/h (whole km/h, v1 → v2 → v1, 1.5/1.75/2.0 m: 546 runs) meets
    /// these ground and continuity checks (worst ratio 4.42, l_hip, 5 → 25 km/h at 1.5 m).
    fn parameter_changes_are_continuous(
        v1 in 2.0f64..25.0, d2 in -10.0f64..10.0, d3 in -10.0f64..10.0, h in 1.5f64..2.0,
    ) {
        let v2 = (v1 + d2).clamp(2.0, 25.0);
        let v3 = (v2 + d3).clamp(2.0, 25.0);
        let text = format!("step,speed_km_per_h,action\n0,{v1},run\n5,{v2},run\n9,{v3},run\n13,,stop\n");
        let sched = Schedule::parse(&text, "proptest").unwrap();
        let m = RunModel::published(h).unwrap();
        let p = m.natural(v1 / 3.6, 0.0, &RunAttributes::defaults(h)).unwrap();
        let (mo, rep) = run_params(&m, p, Some(sched), 30.0, false);
        let what = format!("{v1:.2} → {v2:.2} → {v3:.2} km/h, h {h:.2} m");
        ground_checks(&mo, &what)?;
        // The changes take effect at the scheduled steps.
        let at = |i: usize| rep.steps.get(i).map(|s| s.speed * 3.6).unwrap_or(f64::NAN);
        prop_assert!((at(5) - v2).abs() < 1e-6, "{what}: step 5 at {:.3} km/h", at(5));
        prop_assert!((at(9) - v3).abs() < 1e-6, "{what}: step 9 at {:.3} km/h", at(9));
        let last = mo.len() - 1;
        prop_assert!(mo.contacts()[last] == [true, true], "{what}: does not end standing");
    }
}

/// A deterministic grid over the whole range (2–25 km/h every km/h, heights 1.5, 1.75, 2.0 m):
/// every check of `steady_running_invariants`; the worst value of each measured quantity is
/// printed (`cargo test --release --test runner_properties worst -- --nocapture`).
#[test]
fn worst_cases_over_a_grid() {
    for kmh in 2..=25 {
        for h in [1.5, 1.75, 2.0] {
            check_steady(kmh as f64, h).unwrap();
        }
    }
    WORST.with(|w| {
        for (name, (v, at)) in w.borrow().iter() {
            println!("{name}: {v:.6}  [{at}]");
        }
    });
}

/// With the refitted relations at 14–18 km/h (supports of 0.22–0.26 s over 1.0–1.1 m of
/// ground), the landing moves ahead of the overstride attribute so that the stance hip stays in
/// reach: no out-of-reach step, no lowered mid-support, the pelvis takes off at most 2 cm lower
/// than it lands (no lower, or the toe-off leg leans at most 30°) and not far below where the published relations' run lands it at the same speed
/// (before the change, 0.73 m at 16–18 km/h, 1.8 m, where that run lands at 0.93 m); eq. 3's H
/// stays a few centimetres
/// (before: 0.2–0.5 m). With the published relations the landing is the attribute's.
#[test]
fn refitted_long_supports_land_ahead() {
    for h in [1.5, 1.75, 2.0] {
        let fitted = refitted_model(h);
        let published = RunModel::published(h).unwrap();
        for kmh in [14.0, 15.0, 16.0, 17.0, 18.0] {
            let what = format!("{kmh} km/h, h {h} m");
            let a = RunAttributes::defaults(h);
            let p = fitted.natural(kmh / 3.6, 0.0, &a).unwrap();
            let (_, rep) = run_params(&fitted, p, None, 1.0 + 20.0 / p.step_freq, false);
            let pp = published.natural(kmh / 3.6, 0.0, &a).unwrap();
            let (_, prep) = run_params(&published, pp, None, 1.0 + 20.0 / pp.step_freq, false);
            let steady = |r: &RunReport| {
                r.steps
                    .iter()
                    .rev()
                    .take(6)
                    .map(|s| s.report)
                    .collect::<Vec<_>>()
            };
            let pub_land = steady(&prep)
                .iter()
                .map(|r| r.p2.y)
                .fold(f64::INFINITY, f64::min);
            for r in steady(&prep) {
                assert!(
                    r.overstride < 0.06 * h / 1.8,
                    "{what}: published run moved its landing to {}",
                    r.overstride
                );
            }
            assert!(
                rep.notes.iter().all(|n| !n.contains("out of reach")),
                "{what}: {:?}",
                rep.notes
            );
            let r = steady(&rep)[0];
            println!(
                "{what}: overstride {:.3} m, pelvis at toe off {:.3} m, at landing {:.3} m \
                 (published run lands at {pub_land:.3} m), H {:.4} m",
                r.overstride, r.p1.y, r.p2.y, r.flight_height
            );
            for r in steady(&rep) {
                assert!(
                    !r.out_of_reach && r.mid_support_lowered == 0,
                    "{what}: {r:?}"
                );
                assert!(
                    r.p1.y > r.p2.y - 0.02 * h / 1.8,
                    "{what}: takes off at {} below landing {}",
                    r.p1.y,
                    r.p2.y
                );
                assert!(
                    r.p1.y > 0.92 * pub_land,
                    "{what}: pelvis at toe off {} vs published landing {pub_land}",
                    r.p1.y
                );
                assert!(
                    r.flight_height < 0.03 * h / 1.8,
                    "{what}: H {}",
                    r.flight_height
                );
            }
            // The change is in force: a longer landing than the attribute's at 16 km/h and up
            // (at 1.5 m, 18 km/h is past v_norm·√(h/1.8): shorter steps, longer flights).
            if kmh >= 16.0 && h >= 1.75 {
                assert!(
                    steady(&rep).iter().all(|r| r.overstride > 0.1 * h / 1.8),
                    "{what}"
                );
            }
        }
    }
}

fn refitted_model(h: f64) -> RunModel {
    let fits = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fits");
    let rel = gaitfit::generator::running::equations::RunRelations::from_fits(&fits).unwrap();
    let sk = gaitfit::generator::skeleton::Skeleton::from_height(
        h,
        gaitfit::generator::running::params::default_mass(h),
    )
    .unwrap();
    RunModel::new(sk, rel).unwrap()
}

/// With the refitted relations at 4–25 km/h: a natural step whose eq. 5 flight leaves less
/// than a quarter of the step for support is refused (with a message), never generated; every
/// other step is generated.
#[test]
fn refitted_relations_refuse_too_short_supports() {
    let mut refused = 0;
    for kmh in (4..=25).map(f64::from) {
        for h in [1.5, 1.75, 2.0] {
            let m = refitted_model(h);
            let v = kmh / 3.6;
            let sf = v / m.relations.step_length(v, 0.0, h);
            let flight = m.relations.flight_time(sf, 0.0);
            let p = m.natural(v, 0.0, &RunAttributes::defaults(h));
            if flight > 0.75 / sf {
                let e = p.expect_err("too short a support accepted").to_string();
                assert!(e.contains("t_flight"), "{e}");
                refused += 1;
            } else {
                assert!(p.is_ok(), "{kmh} km/h, h {h}: {:?}", p.err());
            }
        }
    }
    // The refitted eq. 5 once overreached here (its cubic followed past the fitted step
    // frequencies, 0.231 s at 230 steps/min); the fitted relation now holds the boundary value
    // beyond its range (relations::FittedRange), so whether any step is refused depends only on
    // the held curve: each case above checks that refusal and the rule agree.
    println!("{refused} of 66 natural steps refused");
}

/// The arms at sprint cadences (locked speed, raised step frequency; stance ≈ 65 ms at
/// 270 steps/min). When the arms copied the swing thigh frame by frame they swept ~45° within
/// the stance, and the elbow's frame-to-frame step grew past k = 5 × its neighbours' from
/// 260.4 steps/min up: 9.16 at 24.99 km/h, 1.50 m, 270.8/min, found by a random case of
/// `locked_speed_other_step_frequency`, which then stayed below 259/min. Now the arms follow a
/// phase that advances π from toe off to toe off (`running::upper_body::arm_driver`): measured
/// over 18–25 km/h every 0.25 × 1.5–2.0 m every 0.05 × +0–10 % every 1 %, the arms' worst ratio
/// is 2.78 (9.47 before) and the whole figure's 4.99 (the swing hip at 25 km/h, 1.50 m, +10 %).
#[test]
fn arms_are_continuous_at_sprint_cadences() {
    let (kmh, h) = (24.99, 1.5);
    let m = RunModel::published(h).unwrap();
    let a = RunAttributes::defaults(h);
    let mut p = m.natural(kmh / 3.6, 0.0, &a).unwrap();
    p.locks.set(Param::Speed, true);
    for per_min in [270.8, 265.0, 260.4] {
        let p = m.set(&p, Param::StepFreq, per_min / 60.0, &a).unwrap();
        let what = format!("{kmh} km/h, h {h} m, sf {per_min}/min");
        let (mo, _) = run_params(&m, p, None, 1.0 + 20.0 / p.step_freq, false);
        let (ratio, at) = interior_continuity(&mo, &ContinuityOptions::default());
        println!("{what}: continuity ratio {ratio:.2} at {at}");
        assert!(ratio <= 5.0, "{what}: continuity ratio {ratio:.2} at {at}");
        match check_steady_params(&m, p) {
            Ok(true) => {}
            r => panic!("{what}: {r:?}"),
        }
    }
}

/// The extremes of the ranges, always checked.
#[test]
fn extremes() {
    for (kmh, h) in [
        (2.0, 1.5),
        (2.0, 2.0),
        (25.0, 1.5),
        (25.0, 2.0),
        (12.0, 1.8),
    ] {
        check_steady(kmh, h).unwrap();
    }
}

/// From a stand to a stand: the run ends standing still with both feet flat on the ground.
#[test]
fn start_and_stop_in_a_stand() {
    for (kmh, h) in [(5.0, 1.7), (12.0, 1.8), (20.0, 1.9)] {
        let (mo, _, _) = run(kmh, h, 5.0, true);
        for r in [
            stance_sliding(&mo, 0.002, 0.002),
            ground_penetration(&mo, 0.001),
            contact_on_ground(&mo, 0.001),
        ] {
            assert!(r.passed, "{kmh} km/h: {r}");
        }
        let (ratio, at) = interior_continuity(&mo, &ContinuityOptions::default());
        assert!(
            ratio <= 5.0,
            "{kmh} km/h: continuity ratio {ratio:.2} at {at}"
        );
        let last = mo.len() - 1;
        assert_eq!(mo.contacts()[0], [true, true], "starts standing");
        assert_eq!(mo.contacts()[last], [true, true], "ends standing");
        let moved = (mo.landmark(last, Landmark::Pelvis)
            - mo.landmark(last - 12, Landmark::Pelvis))
        .length();
        assert!(
            moved < 1e-9,
            "{kmh} km/h: still {moved} m in the last 0.1 s"
        );
        for side in [Side::Left, Side::Right] {
            for l in Landmark::foot(side) {
                assert!(
                    mo.landmark(last, l).y.abs() < 1e-6,
                    "{kmh} km/h: {} not on the ground",
                    l.name()
                );
            }
        }
    }
}

/// Refitted relations at the slow end (eq. 5's flights of 45 ms at 6 km/h): cases a random
/// proptest seed found failing continuity at the last frame before the first heel strike
/// (l_toe, or r_elbow in frame 47; 18 of 5151 cases of a 0.01 km/h × 0.01 m grid over
/// 6–7 km/h × 1.5–2.0 m, all at 6.0–6.3 km/h, h ≥ 1.98 m; these two at 5.81 and 5.65). The landing knee alone was sped up
/// to bring the heel down (`LANDING_SPEED`), flinging the foot forward into contact; the hip
/// now shares it. And one a second seed found (6.41 km/h, 1.51 m: ratio 5.32 at frame 11,
/// r_knee, the stance knee of the start switching into the toes-flat recovery; see
/// `running::phase::KNEE_RAISE_BLEND`).
#[test]
fn refitted_slow_landings_are_continuous() {
    for (kmh, h) in [
        (6.0, 1.98),
        (6.1, 2.0),
        (6.405921262642802, 1.507816178452286),
    ] {
        refitted_case(kmh, h).unwrap();
    }
}

fn refitted_case(kmh: f64, h: f64) -> Result<(), TestCaseError> {
    let m = refitted_model(h);
    let p = m
        .natural(kmh / 3.6, 0.0, &RunAttributes::defaults(h))
        .unwrap();
    let reachable = check_steady_params(&m, p)?;
    prop_assert!(reachable, "{kmh:.2} km/h, h {h:.2} m: out of reach");
    Ok(())
}
