//! Measured against reality (Schreiber & Moissenet 2019, 6 subjects × self-selected and fast
//! walks): a step generalized from another subject to this subject's body and step length must
//! be clearly closer to the measured stride than the naive uniform scaling of the other
//! subject's stride. Prints the table the report quotes.
use gaitfit::generator::generalize::compare::{compare, schreiber_strides, table_markdown, Target};
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
}
