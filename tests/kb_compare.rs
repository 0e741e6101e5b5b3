//! Measured against reality (Schreiber & Moissenet 2019, 6 subjects × self-selected and fast
//! walks): a step generalized from another subject to this subject's body and step length must
//! be clearly closer to the measured stride than the naive uniform scaling of the other
//! subject's stride. Prints the table the report quotes.
use gaitfit::generator::generalize::compare::{
    compare, schreiber_strides, table_markdown, Scores, Target,
};
use gaitfit::generator::generalize::DEFAULT_ALPHA;
use gaitfit::shared_data;

#[test]
#[ignore = "needs ../shared/data"]
fn generalization_beats_naive_scaling_on_schreiber() {
    let root = shared_data::require("schreiber2019");
    let (strides, failed) = schreiber_strides(&root, DEFAULT_ALPHA).unwrap();
    for f in &failed {
        println!("not built: {f}");
    }
    for s in &strides {
        let w = &s.prototype.walk;
        println!(
            "{} {} {}: sl {:.3} m, ll {:.3} m, moments {:?}, μ* {:?}",
            s.subject,
            s.condition,
            s.side,
            w.step_length(),
            w.body().leg_length(),
            [w.moments().fgm(), w.moments().mom(), w.moments().tom()],
            s.prototype.mu_star
        );
    }
    let rows = compare(&strides, DEFAULT_ALPHA, Target::Measured);
    println!("{}", table_markdown(&rows));
    let model_rows = compare(&strides, DEFAULT_ALPHA, Target::Model);
    println!("in model space:\n{}", table_markdown(&model_rows));
    for r in &rows {
        for f in &r.failures {
            println!("failed: {} {} {}: {f}", r.subject, r.condition, r.side);
        }
    }
    assert!(strides.len() >= 20, "only {} strides built", strides.len());

    let mean =
        |rows: &[gaitfit::generator::generalize::compare::CompareRow],
         f: &dyn Fn(&gaitfit::generator::generalize::compare::CompareRow) -> Scores| {
            let mut s = [0.0; 4];
            for r in rows {
                let v = f(r);
                s[0] += v.hip_deg / rows.len() as f64;
                s[1] += v.knee_deg / rows.len() as f64;
                s[2] += v.ankle_deg / rows.len() as f64;
                s[3] += v.ankle_path_cm / rows.len() as f64;
            }
            s
        };
    for (space, rs) in [("measured", &rows), ("model", &model_rows)] {
        let g = mean(rs, &|r| r.generalized_same);
        let n = mean(rs, &|r| r.naive_same);
        let go = mean(rs, &|r| r.generalized_other);
        let no = mean(rs, &|r| r.naive_other);
        // The swing ankle path, which the generalization constrains (it lands at B's step
        // length, from B's toe-off pose), is clearly better than uniform scaling.
        assert!(
            g[3] < 0.8 * n[3] && go[3] < 0.8 * no[3],
            "{space}: ankle path {g:?} vs {n:?}"
        );
        println!("{space}: generalized {g:?} naive {n:?}; other speed {go:?} vs {no:?}");
    }
    // In model space (the model's own rendering error removed) the joint angles are no worse
    // than uniform scaling on average.
    let g = mean(&model_rows, &|r| r.generalized_same);
    let n = mean(&model_rows, &|r| r.naive_same);
    assert!(
        g[0] + g[1] + g[2] <= n[0] + n[1] + n[2],
        "model space angles {g:?} vs {n:?}"
    );
}
