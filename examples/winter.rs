use gaitfit::events::input::{expand_inputs, read_input};
use gaitfit::events::*;
use gaitfit::ingest::ReadOptions;
use std::path::PathBuf;
fn main() {
    let a: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    for i in expand_inputs(&a).unwrap() {
        let t = read_input(&i, &ReadOptions::default()).unwrap();
        let an = analyse(&t, &EventOptions::default()).unwrap();
        let k = an.kinematics.as_ref().unwrap();
        println!(
            "{} rate {} first frame {} t0 {}",
            i.label(),
            k.rate_hz,
            k.first_frame,
            k.time_s[0]
        );
        for (n, ev) in [
            ("fs", &an.events.foot_speed),
            ("zeni", &an.events.zeni_coordinate),
        ] {
            for e in ev.iter() {
                println!(
                    "{n} {:?} {:?} t {:.4} frame(1-based) {:.2}",
                    e.side,
                    e.kind,
                    e.time_s,
                    e.time_s * k.rate_hz + 1.0
                );
            }
        }
    }
}
