//! RUNNER's case II (flight height given, §3.2) when eq. 3 with eqs. 7–8 has two flight times for
//! one H: the rule (`CASE_TWO_RULE`, the root nearest eq. 5's flight time) lands on the flight
//! time of the flight-time relation itself. Case I at eq. 5's flight time gives H; case II at that H must give back the
//! same flight time — with the published relations and with the refitted `fits/`, 2.5–6 m/s and
//! 1.6–1.9 m figures. And where there are two roots, the other is reported and longer.
use gaitfit::generator::running::equations::RunRelations;
use gaitfit::generator::running::state::{FlightSpec, CASE_TWO_RULE};
use gaitfit::generator::running::{
    generate_run, GenerateOptions, RunAttributes, RunModel, RunParams,
};
use gaitfit::generator::skeleton::Skeleton;
use std::path::Path;

fn models(h: f64) -> Vec<(String, RunModel)> {
    let skel = || Skeleton::from_height(h, gaitfit::generator::running::params::default_mass(h));
    let fits = Path::new(env!("CARGO_MANIFEST_DIR")).join("fits");
    vec![
        ("published".into(), RunModel::published(h).unwrap()),
        (
            "fits/".into(),
            RunModel::new(skel().unwrap(), RunRelations::from_fits(&fits).unwrap()).unwrap(),
        ),
    ]
}

#[test]
fn case_two_round_trips_the_relations_flight_time() {
    assert!(CASE_TWO_RULE.contains("nearest"));
    let (mut two_roots, mut checked, mut downward) = (0, 0, 0);
    for h in [1.6, 1.75, 1.9] {
        let attrs = RunAttributes::defaults(h);
        for (name, m) in models(h) {
            for k in 0..8 {
                let v = 2.5 + 0.5 * k as f64;
                let p = m.natural(v, 0.0, &attrs).unwrap();
                let opts = GenerateOptions {
                    seconds: 2.0,
                    fps: 100.0,
                    stop_at_end: false,
                };
                // Case II is eq. 3 on the branch with the apex after toe off; a case I flight
                // that takes off downwards (eq. 3 then reports the mirrored apex) has no case II
                // counterpart.
                let (_, one) = generate_run(&m, p, attrs.clone(), None, &opts).unwrap();
                // (the start from a stand excepted: its pelvis rises straight to toe off).
                if one.steps.iter().skip(1).any(|s| s.report.takeoff_vy < 0.0) {
                    println!("{name} {h} m {v} m/s takes off downwards");
                    downward += 1;
                    continue;
                }
                let (hh, t2) = m
                    .steady_flight(
                        v,
                        p.step_length,
                        p.step_freq,
                        FlightSpec::Height {
                            height: p.flight_height,
                            near: p.flight_time,
                        },
                        &attrs,
                    )
                    .unwrap();
                assert!(
                    (t2 - p.flight_time).abs() < 1e-6 && (hh - p.flight_height).abs() < 1e-9,
                    "{name} {h} m {v} m/s: relation t_flight {} s, H {} m -> case II {t2} s",
                    p.flight_time,
                    p.flight_height
                );
                checked += 1;
                let params = RunParams {
                    flight_from_height: true,
                    ..p
                };
                let (_, report) = generate_run(&m, params, attrs.clone(), None, &opts).unwrap();
                for s in report
                    .steps
                    .iter()
                    .filter(|s| s.report.other_flight_time.is_some())
                {
                    two_roots += 1;
                    let other = s.report.other_flight_time.unwrap();
                    assert!(
                        (other - s.report.t_flight).abs() > 1e-3,
                        "{other} {}",
                        s.report.t_flight
                    );
                }
            }
        }
    }
    println!("{checked} runs round-trip; {downward} take off downwards; steps with two flight times: {two_roots}");
    assert!(checked >= 30 && two_roots > 0);
}
