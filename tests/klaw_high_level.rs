//! Reference tests of KLAW's high level (§3) against the paper's own numbers.
use gaitfit::generator::walking::attributes::WalkAttributes;
use gaitfit::generator::walking::body::Body;
use gaitfit::generator::walking::high_level::{
    complete, froude_number, heel_strike, phase_times, walk_run_note, Locomotion, WalkParams,
    WalkRelations, WALK_RUN_FROUDE,
};
use gaitfit::generator::walking::{generate_walk, ramp_schedule, ScheduleEntry, WalkOptions};

const KMH: f64 = 1.0 / 3.6;

fn fig10(sl: Option<f64>) -> (f64, f64) {
    let p = WalkParams {
        speed_m_per_s: Some(5.0 * KMH),
        step_length_m: sl,
        ..Default::default()
    };
    let l = complete(
        &p,
        1.8,
        &WalkRelations::published(),
        &WalkAttributes::default(),
    )
    .unwrap();
    (l.step_length_m, l.step_freq_steps_per_min)
}

#[test]
fn figure_10_natural_short_and_long_steps() {
    // Fig. 10 caption, v = 5 km/h, h = 1.8 m (printed to the digits shown).
    let (sl, sf) = fig10(None);
    assert!(
        (sl - 0.77).abs() < 0.005 && (sf - 107.5).abs() < 0.1,
        "natural: {sl} m, {sf}"
    );
    let (_, sf) = fig10(Some(0.50));
    assert!((sf - 166.7).abs() < 0.05, "short steps: {sf}");
    let (_, sf) = fig10(Some(1.05));
    assert!((sf - 79.4).abs() < 0.05, "long steps: {sf}");
}

#[test]
fn anatomical_limits_give_clear_errors() {
    let a = WalkAttributes::default();
    // 5 km/h with 0.45 m steps needs 185 steps/min > sf_max = 182.
    let p = WalkParams {
        speed_m_per_s: Some(5.0 * KMH),
        step_length_m: Some(0.45),
        ..Default::default()
    };
    let e = complete(&p, 1.8, &WalkRelations::published(), &a)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sf_max") && e.contains("182"), "{e}");
    let p = WalkParams {
        step_length_m: Some(1.5),
        step_freq_steps_per_min: Some(60.0),
        ..Default::default()
    };
    let e = complete(&p, 1.8, &WalkRelations::published(), &a)
        .unwrap_err()
        .to_string();
    assert!(e.contains("step_length_m"), "{e}");
    let p = WalkParams {
        speed_m_per_s: Some(-1.0),
        ..Default::default()
    };
    assert!(complete(&p, 1.8, &WalkRelations::published(), &a).is_err());
    assert!(complete(&WalkParams::default(), 1.8, &WalkRelations::published(), &a).is_err());
    // Inconsistent triple.
    let p = WalkParams {
        speed_m_per_s: Some(1.0),
        step_length_m: Some(0.7),
        step_freq_steps_per_min: Some(100.0),
    };
    assert!(complete(&p, 1.8, &WalkRelations::published(), &a).is_err());
}

#[test]
fn completion_is_consistent_for_every_combination() {
    let rel = WalkRelations::published();
    let a = WalkAttributes::default();
    for p in [
        WalkParams {
            step_length_m: Some(0.7),
            ..Default::default()
        },
        WalkParams {
            step_freq_steps_per_min: Some(100.0),
            ..Default::default()
        },
        WalkParams {
            step_length_m: Some(0.7),
            step_freq_steps_per_min: Some(100.0),
            ..Default::default()
        },
        WalkParams {
            speed_m_per_s: Some(1.2),
            step_freq_steps_per_min: Some(100.0),
            ..Default::default()
        },
    ] {
        let l = complete(&p, 1.75, &rel, &a).unwrap();
        assert!(
            (l.step_length_m * l.step_freq_steps_per_min / 60.0 - l.speed_m_per_s).abs() < 1e-12
        );
    }
    // Only sl or only sf: eq. (1) holds exactly.
    let l = complete(
        &WalkParams {
            step_length_m: Some(0.7),
            ..Default::default()
        },
        1.75,
        &rel,
        &a,
    )
    .unwrap();
    assert!((l.step_length_m / (l.step_freq_steps_per_min * 1.75) - 0.004).abs() < 1e-15);
}

#[test]
fn double_support_relation_and_eq_2() {
    // sf = 107.5: t_ds = (29.08 − 0.16·107.5)% of the cycle = 11.88 % of 1.1163 s.
    let t = phase_times(107.5, &WalkRelations::published());
    assert!((t.double_support - 0.1188 * 120.0 / 107.5).abs() < 1e-12);
    assert!((t.stance - (t.step + t.double_support)).abs() < 1e-15);
    assert!((t.swing - (t.step - t.double_support)).abs() < 1e-15);
}

#[test]
fn eq_3_puts_the_swing_heel_on_the_ground_and_mirrors_the_stance_leg() {
    let b = Body::from_height(1.8, 80.0).unwrap();
    for (sl, theta5_deg, ahead) in [(0.77, 90.0, 0.0), (0.5, 95.0, 0.006), (1.05, 85.0, 0.01)] {
        let hs = heel_strike(&b, sl, f64::to_radians(theta5_deg), ahead).unwrap();
        // Stance model: ankle₁ at (0, l9), hip at w·(sin θ1, cos θ1) from it.
        let hip = [hs.w * hs.theta1.sin(), b.l9 + hs.w * hs.theta1.cos()];
        assert!((hip[0] - sl / 2.0).abs() < 1e-12);
        assert!((hip[1] - hs.hip_height).abs() < 1e-12);
        // Swing leg, extended, from the swing hip (ahead by the pelvic offset): ankle, then the heel
        // of a foot pitched so that the ankle angle is θ5.
        let sh = [hip[0] + ahead, hip[1]];
        let ankle = [
            sh[0] - b.l1 * hs.theta3.sin(),
            sh[1] - b.l1 * hs.theta3.cos(),
        ];
        let (s, c) = hs.foot_pitch.sin_cos();
        let heel = [
            ankle[0] + c * b.heel[0] - s * b.heel[1],
            ankle[1] + s * b.heel[0] + c * b.heel[1],
        ];
        assert!((heel[0] - (sl - b.l8)).abs() < 1e-9, "heel x {heel:?}");
        assert!(heel[1].abs() < 1e-9, "heel y {heel:?}");
        // The foot raises the hip at impact: w > l1 (§3); and |θ3| < θ1 with a dorsiflexed foot.
        assert!(hs.w > b.l1);
    }
}

/// The walk–run notes of `ramp_schedule` for a schedule of (km/h, steps) at body height `h`.
fn walk_run_notes(schedule: &[(f64, usize)], h: f64) -> Vec<String> {
    let opts = WalkOptions {
        height_m: h,
        ..Default::default()
    };
    let entries: Vec<ScheduleEntry> = schedule
        .iter()
        .map(|&(kmh, n)| ScheduleEntry::at_speed(kmh * KMH, n))
        .collect();
    let (_, notes) = ramp_schedule(&entries, &opts).unwrap();
    notes
        .into_iter()
        .filter(|n| n.contains("walk-run transition"))
        .collect()
}

/// The number printed after `key` in `note`.
fn number_after(note: &str, key: &str) -> f64 {
    let i = note
        .find(key)
        .unwrap_or_else(|| panic!("{key:?} not in {note}"))
        + key.len();
    let s: String = note[i..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    s.parse()
        .unwrap_or_else(|_| panic!("no number after {key:?} in {note}"))
}

#[test]
fn a_walk_beyond_the_walk_run_transition_is_noted() {
    // Closed form, independently of the generator's body: l1 = (l3 + l4)·h from table B-1
    // (0.23669 + 0.24556 of the height), Fr = v²/(g·l1) with g = 9.80665 m/s².
    let fr_closed = |kmh: f64, h: f64| (kmh * KMH).powi(2) / (9.80665 * (0.23669 + 0.24556) * h);
    assert!((fr_closed(7.0, 1.5) - 0.533).abs() < 5e-4);
    let body = Body::from_height(1.5, 70.0).unwrap();
    assert!((froude_number(7.0 * KMH, body.l1) - fr_closed(7.0, 1.5)).abs() < 1e-9);

    // 7 km/h × 1.5 m (Fr 0.53): one note, naming the entry, speed, height, Fr and the remedies.
    let notes = walk_run_notes(&[(5.0, 2), (7.0, 4)], 1.5);
    assert_eq!(notes.len(), 1, "{notes:?}");
    let n = &notes[0];
    assert!(n.starts_with("schedule entry 2:"), "{n}");
    assert!(
        n.contains("7.00 km/h") && n.contains("body height of 1.5 m"),
        "{n}"
    );
    let fr = number_after(n, "v^2/(g*l1) =");
    assert!((fr - fr_closed(7.0, 1.5)).abs() < 0.01, "{fr} {n}");
    assert!(n.contains("gaitfit generate run"), "{n}");
    // The remedies as printed clear the note: the speed at most, the height at least.
    let v_max = number_after(n, "at most");
    let h_min = number_after(n, "at least");
    assert!(v_max < 7.0 && h_min > 1.5, "{n}");
    assert!(
        walk_run_notes(&[(v_max, 4)], 1.5).is_empty(),
        "{v_max} km/h"
    );
    assert!(walk_run_notes(&[(7.0, 4)], h_min).is_empty(), "{h_min} m");
    assert!(!walk_run_notes(&[(v_max + 0.02, 4)], 1.5).is_empty());
    assert!(!walk_run_notes(&[(7.0, 4)], h_min - 0.02).is_empty());
    // An entry without steps is not walked and gets no note.
    assert!(walk_run_notes(&[(5.0, 2), (7.0, 0)], 1.5).is_empty());

    // Below the transition: 5 km/h × 1.8 m (Fr 0.23), 6 km/h × 2.0 m (Fr 0.29), 7 km/h × 1.8 m
    // (Fr 0.44).
    for (kmh, h) in [(5.0, 1.8), (6.0, 2.0), (7.0, 1.8)] {
        assert!(fr_closed(kmh, h) < WALK_RUN_FROUDE);
        assert!(
            walk_run_notes(&[(kmh, 4)], h).is_empty(),
            "{kmh} km/h × {h} m"
        );
    }
}

#[test]
fn the_walk_run_boundary_is_exact() {
    assert_eq!(WALK_RUN_FROUDE, 0.5);
    let at = |v: f64| Locomotion {
        speed_m_per_s: v,
        step_length_m: 0.9,
        step_freq_steps_per_min: v / 0.9 * 60.0,
    };
    // For every body of 1.50–2.00 m the note switches on between two consecutive floats of the
    // speed: none at the fastest speed with Fr ≤ 0.5, one at the next float, Fr > 0.5. (Fr is
    // the square of `stance::froude_speed`, and no float squares to exactly 0.5: 1/√2 rounds to
    // a float whose square is 0.5000000000000001, the float below it to 0.4999999999999999.)
    for cm in 150..=200 {
        let h = f64::from(cm) / 100.0;
        let l1 = Body::from_height(h, 70.0).unwrap().l1;
        let mut v = (0.5 * 9.80665 * l1).sqrt().next_down().next_down();
        for _ in 0..8 {
            if froude_number(v, l1) > WALK_RUN_FROUDE {
                break;
            }
            v = v.next_up();
        }
        // v: the slowest float above the transition.
        let below = v.next_down();
        assert!(froude_number(v, l1) > WALK_RUN_FROUDE, "{h} m");
        assert!(froude_number(below, l1) <= WALK_RUN_FROUDE, "{h} m");
        assert!((froude_number(v, l1) - WALK_RUN_FROUDE).abs() < 1e-14);
        assert!(walk_run_note(1, &at(below), h, l1).is_none(), "{h} m");
        assert!(walk_run_note(1, &at(v), h, l1).is_some(), "{h} m");
    }
}

#[test]
fn the_walk_run_note_reaches_the_report_and_the_cli() {
    // The report and the motion's metadata of a generated walk (it is still generated).
    let opts = WalkOptions {
        height_m: 1.5,
        ..Default::default()
    };
    let (motion, report) = generate_walk(&[ScheduleEntry::at_speed(7.0 * KMH, 2)], &opts).unwrap();
    assert_eq!(report.steps.len(), 2);
    let noted = |notes: &[String]| notes.iter().any(|n| n.contains("walk-run transition"));
    assert!(noted(&report.notes), "{:?}", report.notes);
    assert!(noted(&motion.metadata.notes), "{:?}", motion.metadata.notes);
    // The CLI prints it to stderr; not at 7 km/h × 1.8 m.
    let dir = tempfile::tempdir().unwrap();
    let stderr = |h: &str| {
        let out = assert_cmd::Command::cargo_bin("gaitfit")
            .unwrap()
            .current_dir(dir.path())
            .args(["generate", "walk", "--speed", "7km/h", "--height", h])
            .args(["--seconds", "1", "-o", "walk.csv"])
            .assert()
            .success();
        String::from_utf8_lossy(&out.get_output().stderr).to_string()
    };
    let err = stderr("1.5");
    assert!(
        err.contains("note: schedule entry 1:") && err.contains("walk-run transition"),
        "{err}"
    );
    assert!(!stderr("1.8").contains("walk-run"));
}
