use gaitfit::events::*;
use gaitfit::generator::walking::{generate_walk, ScheduleEntry, WalkOptions, WalkParams};
fn main() {
    let kmh: f64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let h: f64 = std::env::args().nth(2).unwrap().parse().unwrap();
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
    let (m, _r) = generate_walk(&sched, &opts).unwrap();
    let trial = m.to_trial("klaw");
    let eo = EventOptions {
        gait: Some(Gait::Walk),
        ..EventOptions::default()
    };
    let an = analyse(&trial, &eo).unwrap();
    let k = an.kinematics.as_ref().unwrap();
    println!(
        "fps {} ground/speed {:?}",
        k.rate_hz,
        k.ground_and_walking_speed(&an.events.zeni_coordinate)
    );
    let mut all: Vec<(f64, String)> = Vec::new();
    for e in &m.events {
        all.push((e.time_s, format!("GEN {:?} {:?}", e.side, e.kind)));
    }
    for e in &an.events.foot_speed {
        all.push((e.time_s, format!("   FS {:?} {:?}", e.side, e.kind)));
    }
    for e in &an.events.zeni_coordinate {
        all.push((e.time_s, format!("      Z {:?} {:?}", e.side, e.kind)));
    }
    for e in &an.events.foot_contact {
        all.push((e.time_s, format!("         FH {:?} {:?}", e.side, e.kind)));
    }
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (t, s) in all.iter().take(12) {
        println!("{t:8.4} {s}");
    }
    let l = k.leg(Side::Right);
    let (h, to) = (l.heel.as_ref().unwrap(), l.toe.as_ref().unwrap());
    let raw = trial.markers.as_ref().unwrap();
    let ri = raw.names.iter().position(|n| n == "r_toe").unwrap();
    for i in 25..100 {
        let sp = |x: &Vec<[f64; 3]>| {
            let v: Vec<f64> = (0..3)
                .map(|a| (x[i + 1][a] - x[i - 1][a]) * k.rate_hz / 2.0)
                .collect();
            (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
        };
        println!(
            "{:6.3} heel u {:7.4} sp {:6.3} | toe u {:7.4} sp {:6.3} fwd {:7.4} raw toe {:?}",
            k.time_s[i],
            k.up(&h[i]),
            sp(h),
            k.up(&to[i]),
            sp(to),
            k.fwd(&to[i]),
            raw.positions[ri][i]
        );
    }
}
#[allow(dead_code)]
fn unused() {}
