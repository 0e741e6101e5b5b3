//! Reference events and plates (issue 19 item 5): where both exist, the steps are built (by
//! default, and with `--events force-then-reference`) from the plates' events where the plates saw the event (20 N on the unfiltered
//! vertical force, the truth there; its timing is checked against numpy in
//! tests/events_force_timing.rs) and from the file's own events elsewhere, and the two
//! sources' disagreement is measured.
use gaitfit::events::{
    analyse, force_then_reference, EventKind, EventOptions, EventSource, GaitEvent, PrimarySource,
    Side,
};
use gaitfit::ingest::{read_trial, ReadOptions};
use gaitfit::shared_data::require;

fn ev(t: f64, side: Side, kind: EventKind, source: EventSource) -> GaitEvent {
    GaitEvent {
        time_s: t,
        side,
        kind,
        source,
    }
}

#[test]
fn plates_replace_the_events_they_saw_and_the_file_fills_in() {
    use EventKind::{HeelStrike as Hs, ToeOff as To};
    use EventSource::{Force as F, Reference as R};
    use Side::{Left as L, Right as Rt};
    let file = vec![
        ev(0.10, L, Hs, R),
        ev(0.60, Rt, Hs, R),
        ev(0.75, L, To, R),
        ev(1.10, L, Hs, R),
    ];
    let plates = vec![
        ev(0.095, L, Hs, F),  // replaces the file's 0.10
        ev(0.735, Rt, To, F), // wrong foot for the file's 0.75: added
        ev(0.78, L, To, F),   // replaces 0.75
        ev(1.30, L, Hs, F),   // 0.2 s from 1.10: beyond the tolerance, added
    ];
    let (m, d) = force_then_reference(&plates, &file, 0.06);
    let got: Vec<(f64, EventSource)> = m.iter().map(|e| (e.time_s, e.source)).collect();
    assert_eq!(
        got,
        vec![
            (0.095, F),
            (0.60, R),
            (0.735, F),
            (0.78, F),
            (1.10, R),
            (1.30, F)
        ]
    );
    let d: Vec<(EventKind, i64)> = d
        .iter()
        .map(|(k, x)| (*k, (x * 1e3).round() as i64))
        .collect();
    assert_eq!(d, vec![(Hs, 5), (To, -30)]);
}

#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_steps_take_the_plates_where_they_saw_the_event() {
    let root = require("schreiber2019");
    let mut files: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .flatten()
        .flat_map(|s| {
            std::fs::read_dir(s.path().join("dynamic"))
                .into_iter()
                .flatten()
        })
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "c3d"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 12);
    // The default (auto) takes the plates where they saw the event, the files' events elsewhere.
    let opts = EventOptions::default();
    assert_eq!(opts.primary, PrimarySource::Auto);
    let (mut hs, mut to) = (Vec::new(), Vec::new());
    for f in &files {
        let t = read_trial(f, &ReadOptions::default()).unwrap();
        let an = analyse(&t, &opts).unwrap();
        let e = &an.events;
        assert_eq!(e.primary, EventSource::ForceThenReference);
        let merged = e.primary_events();
        // Every plate event is in the steps' events, with its own time and source.
        for p in &e.force {
            assert!(
                merged.iter().any(|m| m == p),
                "{}: plate {p:?} missing",
                f.display()
            );
        }
        // Every file event is kept unless a plate event of that foot and kind replaced it.
        let kept = merged
            .iter()
            .filter(|m| m.source == EventSource::Reference)
            .count();
        assert_eq!(
            kept + e.reference_minus_force_s.len(),
            e.reference.len(),
            "{}",
            f.display()
        );
        for (k, d) in &e.reference_minus_force_s {
            match k {
                EventKind::HeelStrike => hs.push(d * 1e3),
                _ => to.push(d * 1e3),
            }
        }
    }
    let ms = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
        (m, sd)
    };
    let ((mh, sh), (mt, st)) = (ms(&hs), ms(&to));
    println!(
        "file − plates: heel strike {mh:+.1} ± {sh:.1} ms (n {}), toe off {mt:+.1} ± {st:.1} ms (n {})",
        hs.len(),
        to.len()
    );
    // The plates see two heel strikes and two toe offs per trial; the files' toe offs are
    // late against them (the reason the plates take precedence).
    assert_eq!((hs.len(), to.len()), (24, 24));
    assert!(mt > 5.0, "toe off {mt}");
}
