use gaitfit::generator::running::{attributes::RunAttributes, params::*};
#[test]
fn scratch() {
    let m = RunModel::published(1.8).unwrap();
    let a = RunAttributes::defaults(1.8);
    let p = m.natural(12.0 / 3.6, 0.0, &a).unwrap();
    println!("natural {:?}", p);
    let mut q = p;
    q.locks.speed = true;
    let r = m.set(&q, Param::StepFreq, 210.0 / 60.0, &a).unwrap();
    println!("sf210 {:?}", r);
    for kmh in [2.0, 5.0, 8.0, 12.0, 16.0, 20.0, 25.0] {
        match m.natural(kmh / 3.6, 0.0, &a) {
            Ok(p) => println!("{kmh} km/h: sl {:.3} sf {:.1} tf {:.3} H {:.4}", p.step_length, p.step_freq * 60.0, p.flight_time, p.flight_height),
            Err(e) => println!("{kmh} km/h: {e}"),
        }
    }
}
