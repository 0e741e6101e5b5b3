//! Any request the page (or anything else) can send is answered without a panic, and every
//! motion the studio resolves keeps eq. 1 of both papers, v = sl·sf, in the values it shows.
use gaitfit::studio::controls::{SPEED, STEP_FREQ, STEP_LENGTH};
use gaitfit::studio::session::{
    generate, GeneratorKind, RelationsChoice, ScheduleRowIn, Sources, StudioRequest,
};
use proptest::prelude::*;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn sources() -> Sources {
    Sources {
        fits: PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fits"),
    }
}

fn request(generator: GeneratorKind) -> StudioRequest {
    StudioRequest {
        generator,
        values: BTreeMap::new(),
        locks: vec![],
        changed: None,
        flight_from_height: false,
        relations: RelationsChoice::Published,
        seconds: 1.5,
        fps: Some(30.0),
        from_rest: false,
        stop: false,
        schedule: vec![],
    }
}

/// The controls of each generator at their defaults: (key, min, max, lockable).
fn controls(g: GeneratorKind) -> Vec<(String, f64, f64, bool)> {
    let out = generate(&request(g), &sources()).expect("defaults generate");
    out.controls
        .iter()
        .map(|c| (c.key.clone(), c.min, c.max, c.lockable))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn any_request_is_answered_and_keeps_eq_1(
        which in 0usize..3,
        picks in proptest::collection::vec((0usize..64, -0.5f64..1.5), 1..5),
        lock_bits in 0u8..16,
        changed_pick in 0usize..8,
        refit in any::<bool>(),
        stop in any::<bool>(),
        row in proptest::option::of((0usize..6, 2.0f64..20.0)),
    ) {
        let g = [GeneratorKind::Run, GeneratorKind::Walk, GeneratorKind::Generalize][which];
        let ctl = controls(g);
        let mut req = request(g);
        // Values anywhere from half a range below the slider to half a range above it.
        for (k, f) in &picks {
            let (key, lo, hi, _) = &ctl[k % ctl.len()];
            req.values.insert(key.clone(), lo + f * (hi - lo));
        }
        let lockable: Vec<&String> = ctl.iter().filter(|c| c.3).map(|c| &c.0).collect();
        req.locks = lockable
            .iter()
            .enumerate()
            .filter(|(i, _)| lock_bits & (1 << i) != 0)
            .map(|(_, k)| (*k).clone())
            .collect();
        let keys: Vec<&String> = req.values.keys().collect();
        req.changed = keys.get(changed_pick).map(|k| (*k).clone());
        req.relations = if refit { RelationsChoice::Refit } else { RelationsChoice::Published };
        req.stop = stop && g != GeneratorKind::Generalize;
        if let Some((step, kmh)) = row {
            req.schedule = vec![ScheduleRowIn {
                step: step as f64,
                speed_km_per_h: Some(kmh),
                ..Default::default()
            }];
        }
        // A refusal is fine; a panic fails the test.
        if let Ok(out) = generate(&req, &sources()) {
            prop_assert!(!out.motion.is_empty());
            let v = |k: &str| out.controls.iter().find(|c| c.key == k).map(|c| c.value).unwrap_or(f64::NAN);
            let (speed, sl, sf) = (v(SPEED), v(STEP_LENGTH), v(STEP_FREQ));
            prop_assert!(
                (speed / 3.6 - sl * sf / 60.0).abs() <= 1e-9 * speed.max(1.0),
                "v = {speed} km/h but sl·sf = {} km/h", sl * sf / 60.0 * 3.6
            );
            for c in &out.controls {
                prop_assert!(c.min <= c.max, "{}: range [{}, {}]", c.key, c.min, c.max);
            }
        }
    }
}
