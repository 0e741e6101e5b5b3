use gaitfit::generator::checks::*;
use gaitfit::generator::walking::generate::*;
use gaitfit::generator::walking::high_level::*;

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let (kmh, h, nsteps, rest) = (
        args[0],
        args[1],
        args[2] as usize,
        args.get(3).copied().unwrap_or(0.0) > 0.0,
    );
    let opt = WalkOptions {
        height_m: h,
        start_from_rest: rest,
        ..Default::default()
    };
    let p = WalkParams {
        speed_m_per_s: Some(kmh / 3.6),
        ..Default::default()
    };
    let l = complete(&p, h, &opt.relations, &opt.attributes).unwrap();
    let steps = vec![l; nsteps];
    let t0 = std::time::Instant::now();
    match generate_steps(&steps, &opt) {
        Ok((m, r)) => {
            println!("{} frames in {:?}", m.len(), t0.elapsed());
            for s in &r.steps {
                println!(
                    "{:2} {:5} it {:?} F {:?} err {:?} rec {} clr {:.4} lock {:?}",
                    s.index,
                    s.stance_side.to_string(),
                    s.iterations,
                    s.forces.map(|x| (x * 1000.0).round() / 1000.0),
                    s.errors.map(|x| format!("{x:.1e}")),
                    s.recovery_rounds,
                    s.min_clearance_m,
                    s.lock_s
                );
            }
            println!("{}", stance_sliding(&m, 0.002, 0.002));
            println!("{}", ground_penetration(&m, 0.001));
            println!("{}", contact_on_ground(&m, 0.002));
            println!("{}", continuity(&m, &ContinuityOptions::default()));
            let td = gaitfit::generator::walking::high_level::phase_times(
                l.step_freq_steps_per_min,
                &opt.relations,
            );
            println!(
                "{}",
                double_support_timing(&m, td.double_support, 1.0 / opt.fps)
            );
            for l in [
                gaitfit::generator::skeleton::Landmark::LHip,
                gaitfit::generator::skeleton::Landmark::LKnee,
                gaitfit::generator::skeleton::Landmark::LAnkle,
            ] {
                dump(&m, l, 257, 263);
            }
            if let Some(path) = std::env::var("KLAW_BVH").ok() {
                gaitfit::export::motion::write(&m, std::path::Path::new(&path)).unwrap();
            }
        }
        Err(e) => println!("error after {:?}: {e}", t0.elapsed()),
    }
}
#[allow(dead_code)]
fn dump(
    m: &gaitfit::generator::motion::Motion,
    lm: gaitfit::generator::skeleton::Landmark,
    a: usize,
    b: usize,
) {
    for i in a..b {
        println!("{i} {:?}", m.landmark(i, lm));
    }
}
