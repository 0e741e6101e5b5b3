//! Closing the loop: gaitfit's own event detection (`gaitfit::events` on `Motion::to_trial`)
//! run on generated KLAW walks recovers the commanded step length, step frequency and double
//! support.
//!
//! - Default options (the primary source picked automatically: for a walk from markers alone the
//!   foot-speed detector — Zeni windows refined by the heel and toe speed over the ground,
//!   Bonci et al. 2022 —, 6 Hz marker filter): mean step length and frequency within 1 %, every
//!   steady step's length within 1 %, and the double support within 3 frames (or 10 %) of t_ds
//!   at 5 and 7 km/h (measured +1.4 and +0.1 frames; the Zeni coordinate method gave +31 % at
//!   7 km/h). At 1.5 and 3 km/h it is still long (+0.21 s, +0.06 s, measured): there the
//!   generated swing foot stays within 5 mm of the floor and moves at less than a quarter of
//!   the walking speed for 50–170 ms after its toe off (the swing does start from the virtual
//!   leg's toe-off angles and rates, but the meta-off knee blend ends at rest, so the foot leaves
//!   with almost no speed), so no speed criterion can see it leave; those two speeds are printed
//!   and listed in `TOE_LEAVES_TOO_SLOWLY`, to be asserted once the generated foot leaves the
//!   ground with a human toe-off speed.
//! - Foot-marker heights (the data are noise free: 1 mm height tolerance, 45 Hz filter): the
//!   double support comes back within 3 frames (30 ms) of t_ds at every speed. With the default
//!   1 cm tolerance the toe, which rises tangentially and is held only 5 mm (the toe-clearance
//!   attribute) above the ground early in slow swings, is never seen leaving.
use gaitfit::events::{steps_from_trial, EventOptions, Gait, PrimarySource};
use gaitfit::generator::walking::high_level::phase_times;
use gaitfit::generator::walking::{generate_walk, ScheduleEntry, WalkOptions, WalkParams};
use gaitfit::ingest::trials::StepRow;

/// Speeds (km/h) whose generated toe off the default detector cannot see yet (module docs).
const TOE_LEAVES_TOO_SLOWLY: &[f64] = &[1.5, 3.0];

#[test]
fn detection_recovers_step_length_frequency_and_double_support() {
    let default = EventOptions {
        gait: Some(Gait::Walk),
        ..EventOptions::default()
    };
    let zeni = EventOptions {
        primary: PrimarySource::ZeniCoordinate,
        ..default.clone()
    };
    let mut heights = EventOptions {
        primary: PrimarySource::FootHeight,
        gait: Some(Gait::Walk),
        ..EventOptions::default()
    };
    heights.phases.height_tol_m = 1e-3;
    heights.kinematic.cutoff_hz = 45.0;
    for (kmh, h) in [(1.5, 1.6), (3.0, 1.7), (5.0, 1.8), (7.0, 1.95)] {
        let opts = WalkOptions {
            height_m: h,
            ..Default::default()
        };
        let sched = [ScheduleEntry {
            params: WalkParams {
                speed_m_per_s: Some(kmh / 3.6),
                ..Default::default()
            },
            steps: 10,
        }];
        let (m, r) = generate_walk(&sched, &opts).unwrap();
        let sl = r.steps[0].step_length_m;
        let sf = r.steps[0].step_freq_steps_per_min / 60.0;
        let t_ds = phase_times(r.steps[0].step_freq_steps_per_min, &opts.relations).double_support;
        let trial = m.to_trial("klaw");
        // Steady steps away from the ends (the filter's edges).
        let detect = |eo: &EventOptions| -> Vec<StepRow> {
            let table = match steps_from_trial(&trial, eo) {
                Ok(t) => t,
                Err(e) => panic!("{kmh} km/h: {e}"),
            };
            table
                .rows
                .into_iter()
                .filter(|s| {
                    s.time_s
                        .is_some_and(|t| t > 0.3 && t < m.duration_s() - 1.0 / sf - 0.2)
                })
                .collect()
        };
        let values = |rows: &[StepRow], f: &dyn Fn(&StepRow) -> Option<f64>| -> Vec<f64> {
            let v: Vec<f64> = rows.iter().filter_map(f).collect();
            assert!(v.len() >= 4, "{kmh} km/h: {} values", v.len());
            v
        };
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let rows = detect(&default);
        let sls = values(&rows, &|r| r.step_length_m);
        let sf_m = mean(&values(&rows, &|r| r.step_freq_hz));
        let ds_default = mean(&values(&rows, &|r| r.double_support_time_s));
        let ds_zeni = mean(&values(&detect(&zeni), &|r| r.double_support_time_s));
        let rows_h = detect(&heights);
        let ds_m = mean(&values(&rows_h, &|r| r.double_support_time_s));
        println!(
            "{kmh} km/h, h {h}: sl {:.4} (cmd {sl:.4}) m, sf {:.2} (cmd {:.2}) steps/min, \
             t_ds {ds_default:.4} by default, {ds_m:.4} by foot heights, {ds_zeni:.4} by Zeni \
             (cmd {t_ds:.4}) s",
            mean(&sls),
            sf_m * 60.0,
            sf * 60.0,
        );
        assert!(
            (mean(&sls) - sl).abs() < 0.01 * sl,
            "{kmh} km/h: sl {sls:?} vs {sl}"
        );
        for s in &sls {
            assert!(
                (s - sl).abs() < 0.01 * sl,
                "{kmh} km/h: a step of {s} vs {sl}"
            );
        }
        assert!(
            (sf_m - sf).abs() < 0.01 * sf,
            "{kmh} km/h: sf {sf_m} vs {sf}"
        );
        assert!(
            (ds_m - t_ds).abs() <= 3.0 / opts.fps,
            "{kmh} km/h: t_ds {ds_m} vs {t_ds}"
        );
        let err = (ds_default - t_ds).abs();
        if !TOE_LEAVES_TOO_SLOWLY.contains(&kmh) {
            assert!(
                err <= 3.0 / opts.fps || err <= 0.1 * t_ds,
                "{kmh} km/h: default t_ds {ds_default} vs {t_ds}"
            );
        }
    }
}
