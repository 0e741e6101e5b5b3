use gaitfit::events::input::{expand_inputs, read_input};
use gaitfit::events::*;
use gaitfit::ingest::ReadOptions;
use std::io::Write;
use std::path::PathBuf;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cutoff: f64 = args[1].parse().unwrap();
    let out = PathBuf::from(&args[2]);
    let inputs: Vec<PathBuf> = args[3..].iter().map(PathBuf::from).collect();
    let inputs = expand_inputs(&inputs).unwrap();
    let mut evf = std::fs::File::create(out.join("events.csv")).unwrap();
    writeln!(evf, "trial,side,kind,source,t").unwrap();
    for (ti, inp) in inputs.iter().enumerate() {
        let trial = read_input(inp, &ReadOptions::default()).unwrap();
        let mut opts = EventOptions::default();
        let an = analyse(&trial, &opts).unwrap();
        for (src, ev) in [
            ("force", &an.events.force),
            ("zeni", &an.events.zeni_coordinate),
            ("ref", &an.events.reference),
        ] {
            for e in ev.iter() {
                writeln!(
                    evf,
                    "{ti},{},{},{src},{}",
                    e.side.prefix(),
                    e.kind.as_str(),
                    e.time_s
                )
                .unwrap();
            }
        }
        opts.kinematic.cutoff_hz = cutoff;
        let k = kinematic::Kinematics::from_trial(&trial, None, &opts.kinematic, None).unwrap();
        let mut f = std::fs::File::create(out.join(format!("k{ti}.csv"))).unwrap();
        eprintln!(
            "{ti} {} rate {} {:?}",
            inp.label(),
            k.rate_hz,
            k.leg(Side::Right).names
        );
        write!(f, "t,pel_f,pel_u").unwrap();
        for s in ["l", "r"] {
            for m in ["heel", "toe", "meta"] {
                write!(f, ",{s}_{m}_f,{s}_{m}_u,{s}_{m}_l").unwrap();
            }
        }
        writeln!(f).unwrap();
        for i in 0..k.time_s.len() {
            write!(
                f,
                "{},{},{}",
                k.time_s[i],
                k.fwd(&k.pelvis[i]),
                k.up(&k.pelvis[i])
            )
            .unwrap();
            for s in [Side::Left, Side::Right] {
                let l = k.leg(s);
                for m in [&l.heel, &l.toe, &l.meta] {
                    match m {
                        Some(m) => write!(
                            f,
                            ",{},{},{}",
                            k.fwd(&m[i]),
                            k.up(&m[i]),
                            m[i][3 - k.vertical - k.forward]
                        )
                        .unwrap(),
                        None => write!(f, ",nan,nan,nan").unwrap(),
                    }
                }
            }
            writeln!(f).unwrap();
        }
    }
}
