//! One vocabulary of points and joints across BVH, CSV and TRC (issue 22): the README's table
//! "Names of points and joints" lists every joint and landmark once, says which files carry it,
//! and a name that is both a joint and a landmark is the same point (the landmark sits on the
//! joint centre, or on the joint's BVH end site), so a BVH joint and a CSV/TRC marker of one name
//! never differ.
use gaitfit::export::motion_csv;
use gaitfit::generator::skeleton::{Joint, Landmark, Skeleton};
use glam::DVec3;
use std::collections::BTreeMap;

/// Rows of the README table: name → (BVH cell, CSV/TRC cell, angle cell).
fn table() -> BTreeMap<String, [String; 3]> {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let start = readme
        .find("### Names of points and joints")
        .expect("README section 'Names of points and joints'");
    let mut rows = BTreeMap::new();
    for line in readme[start..]
        .lines()
        .skip_while(|l| !l.starts_with("| name |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
    {
        let cells: Vec<String> = line.split('|').map(|c| c.trim().to_string()).collect();
        // "", name, point, bvh, csv, angles, ""
        assert_eq!(cells.len(), 7, "{line}");
        for name in cells[1].split(',') {
            let name = name.trim().trim_matches('`').to_string();
            let prev = rows.insert(
                name.clone(),
                [cells[3].clone(), cells[4].clone(), cells[5].clone()],
            );
            assert!(prev.is_none(), "{name} is in the table twice");
        }
    }
    assert!(rows.len() > 30, "{rows:?}");
    rows
}

#[test]
fn the_readme_table_names_every_joint_and_landmark_once() {
    let rows = table();
    let header = motion_csv::header();
    for j in Joint::ALL {
        let r = rows
            .get(j.name())
            .unwrap_or_else(|| panic!("joint {} is not in the table", j.name()));
        assert!(r[0].contains("joint"), "{}: BVH cell {:?}", j.name(), r[0]);
        let angles = if j == Joint::Pelvis {
            "✓ (world orientation)"
        } else {
            "✓"
        };
        assert_eq!(r[2], angles, "{}", j.name());
        assert!(header.contains(&format!("{}_z_deg", j.name())));
    }
    for l in Landmark::ALL {
        let r = rows
            .get(l.name())
            .unwrap_or_else(|| panic!("landmark {} is not in the table", l.name()));
        assert_eq!(r[1], "✓", "{}: CSV/TRC cell", l.name());
        assert!(header.contains(&format!("{}_x_m", l.name())));
    }
    for (name, r) in &rows {
        let joint = Joint::from_name(name);
        let landmark = Landmark::from_name(name);
        assert!(
            joint.is_some() || landmark.is_some(),
            "{name} in the table is neither a joint nor a landmark"
        );
        assert_eq!(
            landmark.is_some(),
            r[1] == "✓",
            "{name}: CSV/TRC cell {:?}",
            r[1]
        );
        assert_eq!(
            joint.is_some(),
            r[0].contains("joint"),
            "{name}: BVH cell {:?}",
            r[0]
        );
        assert_eq!(
            joint.is_some(),
            r[2].starts_with('✓'),
            "{name}: angle cell {:?}",
            r[2]
        );
    }
}

#[test]
fn one_name_is_one_point() {
    let rows = table();
    for h in [1.5, 1.8, 2.0] {
        let sk = Skeleton::from_height(h, 70.0).unwrap();
        for l in Landmark::ALL {
            let (at, offset) = sk.landmark_attachment(l);
            let bvh = &rows[l.name()][0];
            if let Some(j) = Joint::from_name(l.name()) {
                // Named as a joint: it is that joint's centre.
                assert_eq!((at, offset), (j, DVec3::ZERO), "{} at {h} m", l.name());
            } else if bvh.starts_with("end site") {
                // A BVH end site: the landmark is the joint's end site.
                assert_eq!(sk.end_site(at), Some(offset), "{} at {h} m", l.name());
            } else {
                assert!(bvh.is_empty(), "{}: {bvh}", l.name());
            }
        }
        // The two the issue found: `head` (the C1 joint) and the top of the head are different
        // names; `l_ball` is on the sole under `l_metatarsal`.
        let (j, o) = sk.landmark_attachment(Landmark::Vertex);
        assert_eq!(j, Joint::Head);
        assert!((o.length() - 0.13 * h).abs() < 1e-9, "{o}");
        let (j, o) = sk.landmark_attachment(Landmark::LBall);
        assert_eq!(j, Joint::LMetatarsal);
        assert!(o.x == 0.0 && o.z == 0.0 && o.y < 0.0, "{o}");
    }
    // 2.7 cm at 1.8 m, as the table says.
    let sk = Skeleton::from_height(1.8, 75.0).unwrap();
    let (_, o) = sk.landmark_attachment(Landmark::LBall);
    assert!((o.y + 0.027).abs() < 0.0005, "{o}");
}
