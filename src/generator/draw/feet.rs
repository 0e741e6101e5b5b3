//! A foot's whole drawn path from sampled targets: contact runs become the rolling foot of
//! [`super::foot`] (pivot fixed, exactly flat between foot flat and heel off), flight runs the
//! C² spline of the sampled flight plus two quintic corrections that make its ends meet the
//! rolling foot's value, rate and acceleration at toe off and at the next contact. So the ankle, pitch and bend are C² over the
//! whole walk (at the flat foot's ends by rest, elsewhere by keys), and the planted foot is
//! exactly planted.
use super::foot::{stance_roll, FootPose, Sole};
use super::track::{spline_keys, C2Track, End, Key};
use crate::generator::GenerateError;

/// One sampled target of a foot: time (s), ankle (x, y, z; m), pitch and toe bend (rad) and
/// whether the foot is on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootSample {
    /// Time, s.
    pub t: f64,
    /// Ankle joint centre (x forward, y up, z right), m.
    pub ankle: [f64; 3],
    /// Pitch from flat, toes up positive, rad.
    pub pitch: f64,
    /// Toe bend, rad.
    pub bend: f64,
    /// On the ground.
    pub contact: bool,
}

/// The drawn foot at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawnFoot {
    /// Ankle joint centre, m.
    pub ankle: [f64; 3],
    /// Pitch, rad.
    pub pitch: f64,
    /// Toe bend, rad.
    pub bend: f64,
    /// On the ground.
    pub contact: bool,
}

#[derive(Debug, Clone, PartialEq)]
enum Piece {
    Contact {
        roll: C2Track,
        flat_ankle: [f64; 2],
        z: f64,
    },
    Flight {
        /// x, y, z, pitch, bend: the simulated flight and its corrections at toe off and at
        /// the next contact (each at rest from mid-flight on, or up to it).
        q: Box<[[C2Track; 3]; 5]>,
    },
}

/// A foot's drawn path ([`FootPath::fit`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FootPath {
    /// Pieces with their start times; each runs to the next's start.
    pieces: Vec<(f64, Piece)>,
    sole: Sole,
    bend_max: f64,
}

impl FootPath {
    /// The path through `samples` (time order, at least two) of a foot with sole `sole` and toe
    /// bend limit `bend_max` (rad), knots about `spacing` s apart. A contact run's roll is
    /// `ρ = −pitch`; its flat foot is its longest run of zero pitch, its flat ankle read there
    /// (or, without one, from its first sample about the pivot of its rocker).
    pub fn fit(
        samples: &[FootSample],
        sole: Sole,
        bend_max: f64,
        spacing: f64,
    ) -> Result<FootPath, GenerateError> {
        if samples.len() < 2 {
            return Err(GenerateError::Numerical {
                stage: "drawing a foot".into(),
                message: format!("{} samples, at least two needed", samples.len()),
            });
        }
        // Runs of equal contact: [start, end) sample indices.
        let mut runs: Vec<(usize, usize)> = Vec::new();
        let mut s = 0;
        for i in 1..=samples.len() {
            if i == samples.len() || samples[i].contact != samples[s].contact {
                runs.push((s, i));
                s = i;
            }
        }
        // Contact pieces first (flights need their ends' rates).
        let mut contacts: Vec<Option<Piece>> = vec![None; runs.len()];
        for (r, &(a, b)) in runs.iter().enumerate() {
            if !samples[a].contact {
                continue;
            }
            let run = &samples[a..b];
            let flat_run = longest_flat(run);
            let flat_ankle = match flat_run {
                Some((i, _)) => [run[i].ankle[0], run[i].ankle[1]],
                None => flat_ankle_of(&sole, &run[0]),
            };
            let rolls: Vec<(f64, f64)> = run.iter().map(|p| (p.t, -p.pitch)).collect();
            let roll = if rolls.len() >= 2 {
                stance_roll(&rolls, flat_run.map(|(i, j)| (run[i].t, run[j].t)), spacing)?
            } else {
                C2Track::new(vec![Key {
                    t: run[0].t,
                    p: rolls[0].1,
                    v: 0.0,
                    a: 0.0,
                }])?
            };
            contacts[r] = Some(Piece::Contact {
                roll,
                flat_ankle,
                z: run[0].ankle[2],
            });
        }
        let mut pieces = Vec::with_capacity(runs.len());
        for (r, &(a, b)) in runs.iter().enumerate() {
            if let Some(p) = contacts[r].take() {
                // A contact run starts where the previous flight's last sample was, so the
                // flight ends at this contact's first sample.
                pieces.push((samples[a].t, p));
                continue;
            }
            // Flight: from the previous contact's last sample to the next contact's first.
            let t0 = if a > 0 {
                samples[a - 1].t
            } else {
                samples[a].t
            };
            let t1 = if b < samples.len() {
                samples[b].t
            } else {
                samples[b - 1].t
            };
            let start = if a > 0 {
                Some(contact_state(
                    &pieces.last().expect("a contact precedes").1,
                    t0,
                    &sole,
                    bend_max,
                ))
            } else {
                None
            };
            let end = if b < samples.len() {
                // The next run is a contact built above (not yet moved into `pieces`).
                contacts[r + 1]
                    .as_ref()
                    .map(|p| contact_state(p, t1, &sole, bend_max))
            } else {
                None
            };
            // The simulated flight, densely (its own samples; the spline's end quadratics reach
            // its contact neighbours' times), plus two corrections that take it onto the
            // rolling foot at its ends: quintics from the difference (value, rate,
            // acceleration) at toe off to rest at mid-flight, and from rest at mid-flight to the
            // difference at the next contact. The simulated targets need not meet the rolling
            // foot where the contact switches (swing and stance are drawn by different rules).
            let run = &samples[a..b];
            let ts: Vec<f64> = run.iter().map(|p| p.t).collect();
            let mid = 0.5 * (t0 + t1);
            let mut q: Vec<[C2Track; 3]> = Vec::with_capacity(5);
            for c in 0..5 {
                let ys: Vec<f64> = run.iter().map(|p| coords(p)[c]).collect();
                let sim = if ts.len() >= 2 {
                    C2Track::new(spline_keys(&ts, &ys, End::Natural, End::Natural))?
                } else {
                    C2Track::new(vec![Key::rest(ts[0], ys[0])])?
                };
                let diff = |st: Option<[[f64; 3]; 5]>, t: f64| {
                    st.map(|s| {
                        let m = sim.at(t);
                        [s[c][0] - m[0], s[c][1] - m[1], s[c][2] - m[2]]
                    })
                    .unwrap_or([0.0; 3])
                };
                let d0 = diff(start, t0);
                let d1 = diff(end, t1);
                let key = |t: f64, d: [f64; 3]| Key {
                    t,
                    p: d[0],
                    v: d[1],
                    a: d[2],
                };
                let c0 = if mid > t0 {
                    C2Track::new(vec![key(t0, d0), Key::rest(mid, 0.0)])?
                } else {
                    C2Track::new(vec![Key::rest(t0, 0.0)])?
                };
                // The landing correction acts over the flight's last quarter (at least `spacing`
                // s): for a simulated foot that approaches the ground at a steady rate v over that
                // window W, the corrected height is v·W·(1 − s)³(1 + 2s + 3s²) ≥ 0 (s the
                // window's fraction): the foot slows into the contact without going through the
                // ground. (Over half the flight a fast heel went through by up to 21 mm; over 40
                // ms the knee's landing broke continuity: docs/klaw.md, session 7.)
                let land = (t1 - spacing.max(0.25 * (t1 - t0))).max(mid);
                let c1 = if t1 > land {
                    C2Track::new(vec![Key::rest(land, 0.0), key(t1, d1)])?
                } else {
                    C2Track::new(vec![Key::rest(t1, 0.0)])?
                };
                q.push([sim, c0, c1]);
            }
            let q: [[C2Track; 3]; 5] = q.try_into().expect("five coordinates");
            pieces.push((t0, Piece::Flight { q: Box::new(q) }));
        }
        Ok(FootPath {
            pieces,
            sole,
            bend_max,
        })
    }

    /// The drawn foot at `t` s.
    pub fn at(&self, t: f64) -> DrawnFoot {
        let i = self.pieces.partition_point(|p| p.0 <= t).saturating_sub(1);
        match &self.pieces[i].1 {
            Piece::Contact {
                roll,
                flat_ankle,
                z,
            } => {
                let p = self.sole.rolled(*flat_ankle, roll.value(t), self.bend_max);
                DrawnFoot {
                    ankle: [p.ankle[0], p.ankle[1], *z],
                    pitch: p.pitch,
                    bend: p.bend,
                    contact: true,
                }
            }
            Piece::Flight { q } => {
                let v = |c: usize| q[c][0].value(t) + q[c][1].value(t) + q[c][2].value(t);
                DrawnFoot {
                    ankle: [v(0), v(1), v(2)],
                    pitch: v(3),
                    bend: v(4),
                    contact: false,
                }
            }
        }
    }
}

/// The longest run of zero pitch in a contact run: (first, last) index.
fn longest_flat(run: &[FootSample]) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize)> = None;
    let mut start = None;
    for (i, p) in run.iter().enumerate() {
        if p.pitch.abs() <= FLAT_PITCH {
            let s = *start.get_or_insert(i);
            if best.is_none_or(|(a, b)| i - s > b - a) {
                best = Some((s, i));
            }
        } else {
            start = None;
        }
    }
    best
}

/// Pitch below which a sampled contact foot is flat, rad (rounding of a zero roll).
const FLAT_PITCH: f64 = 1e-12;

/// The flat ankle of a foot rolled about the pivot of its rocker (the heel for toes up, the toe
/// tip for heel up) as sampled in `p`.
fn flat_ankle_of(sole: &Sole, p: &FootSample) -> [f64; 2] {
    let flat = [0.0, 0.0];
    let pose = FootPose {
        ankle: [p.ankle[0], p.ankle[1]],
        pitch: p.pitch,
        bend: p.bend,
    };
    // The pivot's drawn position, and where it is when the foot is flat at the origin.
    let pts = sole.points(&pose, sole.mtp);
    let (now, at_flat) = if p.pitch >= 0.0 {
        (pts[0], sole.heel)
    } else {
        (pts[3], sole.toe)
    };
    [flat[0] + now[0] - at_flat[0], flat[1] + now[1] - at_flat[1]]
}

/// Value, rate and acceleration of x, y, z, pitch and bend of a contact piece at `t`.
fn contact_state(p: &Piece, t: f64, sole: &Sole, bend_max: f64) -> [[f64; 3]; 5] {
    match p {
        Piece::Contact {
            roll,
            flat_ankle,
            z,
        } => {
            let r = sole.rolled_rates(*flat_ankle, roll.at(t), bend_max);
            [r[0], r[1], [*z, 0.0, 0.0], r[2], r[3]]
        }
        Piece::Flight { q } => q.as_ref().clone().map(|c| {
            let (x, y, z) = (c[0].at(t), c[1].at(t), c[2].at(t));
            [x[0] + y[0] + z[0], x[1] + y[1] + z[1], x[2] + y[2] + z[2]]
        }),
    }
}

/// A sample's x, y, z, pitch and bend.
fn coords(p: &FootSample) -> [f64; 5] {
    [p.ankle[0], p.ankle[1], p.ankle[2], p.pitch, p.bend]
}

#[cfg(test)]
mod tests {
    use super::super::foot::tests::sole;
    use super::*;

    /// Two contacts 0.7 m apart joined by a 0.4 s flight whose sampled ankle arrives at the
    /// next heel moving (a collision the drawing has to smooth) and does not meet the rolling
    /// foot at either end.
    fn samples() -> Vec<FootSample> {
        let s = sole();
        let bend_max = 0.6;
        let roll = |t: f64| {
            if t < 0.1 {
                -0.25 * (1.0 - t / 0.1)
            } else if t <= 0.35 {
                0.0
            } else {
                ((t - 0.35) / 0.25).powf(1.5)
            }
        };
        let mut out = Vec::new();
        for i in 0..=1400 {
            let t = i as f64 * 1e-3;
            let (x0, tc) = if t <= 0.6 { (0.0, t) } else { (0.7, t - 1.0) };
            if t <= 0.6 || t >= 1.0 {
                let p = s.rolled([x0, 0.08], roll(tc), bend_max);
                out.push(FootSample {
                    t,
                    ankle: [p.ankle[0], p.ankle[1], 0.1],
                    pitch: p.pitch,
                    bend: p.bend,
                    contact: true,
                });
            } else {
                let u = (t - 0.6) / 0.4;
                out.push(FootSample {
                    t,
                    ankle: [
                        0.3 + 0.4 * u,
                        0.1 + 0.1 * (std::f64::consts::PI * u).sin(),
                        0.1,
                    ],
                    pitch: -1.0 + 1.25 * u,
                    bend: 0.3 * (1.0 - u),
                    contact: false,
                });
            }
        }
        out
    }

    #[test]
    fn a_foot_path_is_planted_while_flat_and_c1_everywhere() {
        let path = FootPath::fit(&samples(), sole(), 0.6, 0.04).unwrap();
        for i in 0..=250 {
            for t0 in [0.1, 1.1] {
                let f = path.at(t0 + 1e-3 * i as f64);
                let x = if t0 < 1.0 { 0.0 } else { 0.7 };
                assert!((f.ankle[0] - x).abs() <= 1e-9 && (f.ankle[1] - 0.08).abs() <= 1e-9);
                assert!(f.contact && f.pitch == 0.0);
            }
        }
        // Rates from 10 µs differences change by O(h · acceleration) between neighbouring
        // probes everywhere, toe off, heel strike and the flat foot's ends included (C¹ of the
        // drawn ankle, pitch and bend here; C² at knots is `track`'s guarantee).
        let h = 1e-5;
        let q = |t: f64| {
            let f = path.at(t);
            [f.ankle[0], f.ankle[1], f.pitch, f.bend]
        };
        let mut worst = 0.0f64;
        let mut last: Option<[f64; 4]> = None;
        for i in 0..140_000 {
            let t = i as f64 * h;
            let (a, b) = (q(t), q(t + h));
            let v = [0, 1, 2, 3].map(|c| (b[c] - a[c]) / h);
            if let Some(l) = last {
                for c in 0..4 {
                    worst = worst.max((v[c] - l[c]).abs());
                }
            }
            last = Some(v);
        }
        // Accelerations here stay below ~1,000 /s²: one 10 µs step moves a rate by ≤ 0.01.
        assert!(worst < 0.02, "largest rate jump {worst}");
        // In contact the soles never go below the ground.
        for i in 0..=1400 {
            let f = path.at(i as f64 * 1e-3);
            if f.contact {
                let pose = FootPose {
                    ankle: [f.ankle[0], f.ankle[1]],
                    pitch: f.pitch,
                    bend: f.bend,
                };
                for p in sole().points(&pose, sole().mtp) {
                    assert!(p[1] >= -1e-12);
                }
            }
        }
    }

    #[test]
    fn too_few_samples_are_an_error() {
        assert!(FootPath::fit(&samples()[..1], sole(), 0.6, 0.04).is_err());
    }
}
