use gaitfit::events::input::{expand_inputs, read_input};
use gaitfit::ingest::ReadOptions;
use std::path::PathBuf;
fn main() {
    let a: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    for i in expand_inputs(&a).unwrap() {
        let t = read_input(&i, &ReadOptions::default()).unwrap();
        println!(
            "{}: {:?}",
            i.label(),
            t.markers.as_ref().map(|m| m.names.clone())
        );
    }
}
