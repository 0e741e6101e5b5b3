//! The prototype W(S*, sl*) built from Winter's walk (Winter 1990, Table A.1 via BMClab, CC BY
//! 4.0): its measures against Ko & Badler's Table 2 (whose subject column is Winter's subject,
//! in cm), its consistency, and the raw table against Winter's own filtered version.
use gaitfit::generator::generalize::prototype::{build_prototype, winter_leg};
use gaitfit::ingest::{winter, ReadOptions};
use gaitfit::shared_data;

fn build(
    file: &str,
) -> (
    gaitfit::generator::generalize::WalkData,
    gaitfit::generator::generalize::MuFunctions,
    gaitfit::generator::generalize::prototype::PrototypeReport,
) {
    let p = shared_data::require(format!("bmclab/{file}"));
    let trial = winter::read(&p, &ReadOptions::default()).unwrap();
    let (leg, ev) = winter_leg(&trial).unwrap();
    build_prototype(&leg, &ev, [0.0; 4]).unwrap()
}

#[test]
#[ignore = "needs ../shared/data"]
fn winter_prototype_probe() {
    for f in ["wn35b.txt", "WinterTableA1.txt"] {
        let (w, mu, r) = build(f);
        let b = w.body();
        println!("{f}: {r:#?}");
        println!(
            "body thigh {:.4} shin {:.4} hN {:.4} bN {:.4} aN {:.4} bt {:.4} ll {:.4}",
            b.thigh(),
            b.shin(),
            b.heel_to_n(),
            b.ball_to_n(),
            b.ankle_to_n(),
            b.ball_to_toe(),
            b.leg_length()
        );
        println!(
            "a-h {:.4} a-b {:.4} h-b {:.4} angles {:.4} {:.4} {:.4}",
            b.ankle_to_heel(),
            b.ankle_to_ball(),
            b.heel_to_ball(),
            b.ball_angle(),
            b.heel_angle(),
            b.ankle_angle()
        );
        println!(
            "mu {:?} hip0 {:?} hip1 {:?}",
            mu.mu_star(),
            w.hip().first(),
            w.hip().last()
        );
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn winter_probe_reach() {
    use gaitfit::generator::generalize::geometry::{foot_on_pivot, Pivot};
    let p = shared_data::require("bmclab/wn35b.txt");
    let trial = winter::read(&p, &ReadOptions::default()).unwrap();
    let (leg, ev) = winter_leg(&trial).unwrap();
    let i = leg
        .time_s
        .iter()
        .position(|&t| (t - ev.heel_strike).abs() < 1e-6)
        .unwrap();
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    println!(
        "HS frame idx {i}: |hip-ankle| {:.4} |hip-knee| {:.4} |knee-ankle| {:.4}",
        d(leg.hip[i], leg.ankle[i]),
        d(leg.hip[i], leg.knee[i]),
        d(leg.knee[i], leg.ankle[i])
    );
    for j in (i..i + 70).step_by(5) {
        println!(
            "frame {} |hip-ankle| {:.4} th {:.4} sh {:.4} hip {:?} heel {:?} ankle {:?}",
            j + 1,
            d(leg.hip[j], leg.ankle[j]),
            d(leg.hip[j], leg.knee[j]),
            d(leg.knee[j], leg.ankle[j]),
            leg.hip[j],
            leg.heel[j],
            leg.ankle[j]
        );
    }
    let (w, mu, _r) = build_prototype(&leg, &ev, [0.0; 4]).unwrap();
    let a0 = foot_on_pivot(w.body(), Pivot::Heel(0.0), mu.mu_star()[1], 0.0).ankle;
    println!("model ankle at HS {a0:?}, H(0) {:?}", w.hip().first());
}
