use gaitfit::generator::walking::attributes::WalkAttributes;
use gaitfit::generator::walking::body::Body;
use gaitfit::generator::walking::dynamics::StanceModel;
use gaitfit::generator::walking::high_level::*;
use gaitfit::generator::walking::stance::*;

fn main() {
    let args: Vec<f64> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let (kmh, h) = (args[0], args[1]);
    let b = Body::from_height(h, 75.0).unwrap();
    let a = WalkAttributes::default();
    let p = WalkParams { speed_m_per_s: Some(kmh / 3.6), ..Default::default() };
    let l = complete(&p, h, &WalkRelations::PUBLISHED, &a).unwrap();
    let c = step_constraints(&b, &l, &WalkRelations::PUBLISHED, &a).unwrap();
    let model = StanceModel::new(&b);
    let k_w = a.leg_stiffness * b.mass_kg * 9.81 / b.l1;
    let ieff = b.i2 + b.m2 * b.r2 * b.r2;
    let om = 2.0 * std::f64::consts::PI * a.trunk_freq_hz;
    let spec = StanceSpec {
        model,
        l1: b.l1,
        k_w,
        v_w: 2.0 * a.leg_damping * (k_w * b.m2).sqrt(),
        k2: ieff * om * om + b.m2 * 9.81 * b.r2,
        c2: 2.0 * a.trunk_damping * ieff * om,
        theta2_ref: a.trunk_lean_deg.to_radians(),
        duration: c.times.step,
        torque_off: a.hip_torque_off * c.times.step,
        monitor_gain: 20.0,
        target: [c.heel_strike.w, c.heel_strike.theta1],
        max_step: a.max_step_s,
    };
    let hs = c.heel_strike;
    let v = l.speed_m_per_s;
    let th = -hs.theta1;
    let start = StanceStart { q: [hs.w, th, spec.theta2_ref], qd: [v * th.sin(), v * th.cos() / hs.w, 0.0] };
    println!("sl {:.3} sf {:.1} T {:.3} w_end {:.4} l1 {:.4} th1 {:.2}deg th3 {:.2}deg", l.step_length_m, l.step_freq_steps_per_min, c.times.step, hs.w, b.l1, hs.theta1.to_degrees(), hs.theta3.to_degrees());
    let t0 = std::time::Instant::now();
    let r = spec.solve(&start, [0.0, 0.0]);
    match r {
        Ok((s, run)) => {
            println!("A {:.3} P {:.4} iters {} res {:?} lock {:?} ext {:?} in {:?}", s.x[0], s.x[1], s.iterations, s.residual, run.lock_time, run.extend_time, t0.elapsed());
            println!("end {:?}", run.end);
            let n = run.track.nodes.len();
            for k in (0..n).step_by(n / 12) {
                let nd = &run.track.nodes[k];
                println!("t {:.3} w {:.4} th1 {:.2} th2 {:.2} wd {:.3} th1d {:.3} hipy {:.4}", nd.t, nd.q[0], nd.q[1].to_degrees(), nd.q[2].to_degrees(), nd.qd[0], nd.qd[1], nd.q[0]*nd.q[1].cos());
            }
        }
        Err(e) => println!("fail {e}"),
    }
}
