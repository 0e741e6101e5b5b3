//! The relations beside the figure: for the generator in use, each relation's curve with the
//! published coefficients and with the refitted ones (`--fits`), evaluated at the figure's body
//! height (and RUNNER's level) by the same functions the generators call, the current point,
//! and the points of the data tables (`--data`, the trials tables `gaitfit fit` reads).
use super::controls::STEP_FREQ;
use super::session::{Generated, GeneratorKind, RelationsChoice};
use crate::generator::running::equations::RunRelations;
use crate::generator::running::params::{SF_SEARCH, SPEED_RANGE};
use crate::generator::walking::WalkRelations;
use crate::relations::{by_id, Relation};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Points per curve.
const CURVE_POINTS: usize = 161;

/// An axis: the relation's variable in the paper's units.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Axis {
    /// Symbol (`v`, `sl`, `sf`, `t_flight`, `t_ds`).
    pub symbol: &'static str,
    /// Unit as the paper writes it.
    pub unit: &'static str,
}

/// One curve.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Curve {
    /// `published` or `refit`.
    pub label: &'static str,
    /// Whether the generator uses these coefficients now.
    pub in_use: bool,
    /// (x, y) points; a `null` pair (NaN) breaks the line (eqs. 4–5's jump at the knot).
    pub points: Vec<[f64; 2]>,
}

/// One relation's plot.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Plot {
    /// Relation id (`run-sl-v`, …), the key of its data points.
    pub id: &'static str,
    /// Title with the paper and equation.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Published and (when `--fits` has it) refitted curves.
    pub curves: Vec<Curve>,
    /// The current motion's (first step's) commanded point.
    pub point: Option<[f64; 2]>,
    /// What the reader should know (curves' body height, why a refit is missing).
    pub note: String,
}

/// The data tables' points of one relation.
#[derive(Debug, Clone, Serialize, PartialEq, Default)]
pub struct DataPoints {
    /// (x, y) in the relation's units.
    pub points: Vec<[f64; 2]>,
    /// Which tables and how many rows.
    pub source: String,
}

fn sample(lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(CURVE_POINTS + 2);
    let mut prev: Option<f64> = None;
    for i in 0..CURVE_POINTS {
        let x = lo + (hi - lo) * i as f64 / (CURVE_POINTS - 1) as f64;
        let y = f(x);
        // A jump larger than a tenth of the curve's scale is a discontinuity: break the line.
        if let Some(p) = prev {
            if (y - p).abs() > 0.1 * (y.abs().max(p.abs())) && (y - p).abs() > 1e-3 {
                out.push([f64::NAN, f64::NAN]);
            }
        }
        prev = Some(y);
        if y.is_finite() {
            out.push([x, y]);
        }
    }
    out
}

fn title(id: &str) -> String {
    by_id(id)
        .map(|r| {
            let c = r.card().citation;
            format!("{} — {}", r.card().title, c.equation)
        })
        .unwrap_or_else(|_| id.to_string())
}

/// The plots for a generated motion; `fits` is the `--fits` folder.
pub fn plots(g: &Generated, fits: &Path) -> Vec<Plot> {
    let h = g.params.height_m;
    let refit_in_use = g.relations == RelationsChoice::Refit;
    match g.generator {
        GeneratorKind::Run => {
            let level = g.params.level.unwrap_or(0.0);
            let mut sets: Vec<(&'static str, bool, RunRelations)> =
                vec![("published", !refit_in_use, RunRelations::published())];
            let mut note = format!("curves at body height {h:.2} m, level {level}");
            match RunRelations::from_fits(fits) {
                Ok(r) => sets.push(("refit", refit_in_use, r)),
                Err(e) => note += &format!("; no refit: {e}"),
            }
            let (v0, v1) = (SPEED_RANGE.0 * 60.0, SPEED_RANGE.1 * 60.0);
            let sl_v = Plot {
                id: "run-sl-v",
                title: title("run-sl-v"),
                x: Axis {
                    symbol: "v",
                    unit: "m/min",
                },
                y: Axis {
                    symbol: "sl",
                    unit: "m",
                },
                curves: sets
                    .iter()
                    .map(|(label, in_use, r)| Curve {
                        label,
                        in_use: *in_use,
                        points: sample(v0, v1, |v| r.step_length(v / 60.0, level, h)),
                    })
                    .collect(),
                point: Some([g.params.speed_m_per_s * 60.0, g.params.step_length_m]),
                note: note.clone(),
            };
            let tf = Plot {
                id: "run-tflight-sf",
                title: title("run-tflight-sf"),
                x: Axis {
                    symbol: "sf",
                    unit: "steps/min",
                },
                y: Axis {
                    symbol: "t_flight",
                    unit: "s",
                },
                curves: sets
                    .iter()
                    .map(|(label, in_use, r)| Curve {
                        label,
                        in_use: *in_use,
                        points: sample(SF_SEARCH.0, SF_SEARCH.1, |sf| {
                            r.flight_time(sf / 60.0, level)
                        }),
                    })
                    .collect(),
                point: g
                    .params
                    .flight_time_s
                    .map(|t| [g.params.step_freq_steps_per_min, t]),
                note: if g.flight_from_height {
                    format!("{note}; H was set, so the flight time follows from H (case II) and leaves the curve")
                } else {
                    note
                },
            };
            vec![sl_v, tf]
        }
        GeneratorKind::Walk | GeneratorKind::Generalize => {
            let klaw = g.generator == GeneratorKind::Walk;
            let mut sets: Vec<(&'static str, bool, WalkRelations)> = vec![(
                "published",
                !(klaw && refit_in_use),
                WalkRelations::published(),
            )];
            let mut note = format!("curves at body height {h:.2} m");
            match WalkRelations::from_fits_dir(fits) {
                Ok(r) => sets.push(("refit", klaw && refit_in_use, r)),
                Err(e) => note += &format!("; no refit: {e}"),
            }
            if !klaw {
                note += "; Ko–Badler uses no sl–sf relation: KLAW's eq. 1 is shown for reference";
            }
            let (sf0, sf1) = g
                .controls
                .iter()
                .find(|c| c.key == STEP_FREQ)
                .map_or((30.0, 182.0), |c| (c.min, c.max));
            let sf = g.params.step_freq_steps_per_min;
            let in_use = sets
                .iter()
                .find(|s| s.1)
                .map(|s| s.2.clone())
                .unwrap_or_default();
            let mut out = vec![Plot {
                id: "walk-sl-sf",
                title: title("walk-sl-sf"),
                x: Axis {
                    symbol: "sf",
                    unit: "steps/min",
                },
                y: Axis {
                    symbol: "sl",
                    unit: "m",
                },
                curves: sets
                    .iter()
                    .map(|(label, in_use, r)| Curve {
                        label,
                        in_use: *in_use,
                        points: sample(sf0, sf1, |sf| r.sl_sf.step_length(sf, h)),
                    })
                    .collect(),
                point: Some([sf, g.params.step_length_m]),
                note: note.clone(),
            }];
            if klaw {
                out.push(Plot {
                    id: "walk-tds-sf",
                    title: title("walk-tds-sf"),
                    x: Axis {
                        symbol: "sf",
                        unit: "steps/min",
                    },
                    y: Axis {
                        symbol: "t_ds",
                        unit: "% of cycle",
                    },
                    curves: sets
                        .iter()
                        .map(|(label, in_use, r)| Curve {
                            label,
                            in_use: *in_use,
                            points: sample(sf0, sf1, |sf| r.tds_sf.double_support_pct(sf)),
                        })
                        .collect(),
                    point: Some([sf, in_use.tds_sf.double_support_pct(sf)]),
                    note,
                });
            }
            out
        }
    }
}

/// The ids of the relations the studio plots.
pub const PLOTTED: [&str; 4] = ["run-sl-v", "run-tflight-sf", "walk-sl-sf", "walk-tds-sf"];

/// Reads every `*.csv` trials table in `dir` and reduces its rows to each plotted relation's
/// (x, y), in the relation's units. Returns the points and one note per table that could not
/// be read (the studio runs without data; the page says why).
pub fn data_points(dir: &Path) -> (BTreeMap<String, DataPoints>, Vec<String>) {
    let mut out: BTreeMap<String, DataPoints> = BTreeMap::new();
    let mut notes = Vec::new();
    let mut files: Vec<_> = match std::fs::read_dir(dir) {
        Ok(rd) => rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "csv"))
            .collect(),
        Err(e) => {
            notes.push(format!(
                "{}: no data tables ({e}); give --data DIR",
                dir.display()
            ));
            return (out, notes);
        }
    };
    files.sort();
    let rels: Vec<Box<dyn Relation>> = PLOTTED.iter().filter_map(|id| by_id(id).ok()).collect();
    let mut used: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    for f in &files {
        let table = match crate::ingest::trials::read_trials(f) {
            Ok(t) => t,
            Err(e) => {
                notes.push(format!("{}: skipped: {e}", f.display()));
                continue;
            }
        };
        let name = f
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        for r in &rels {
            let d = out.entry(r.card().id.to_string()).or_default();
            let before = d.points.len();
            for i in 0..table.len() {
                if table.is_flagged[i] || table.gait[i] != Some(r.card().gait) {
                    continue;
                }
                if let Ok(o) = r.observe(&table.values(i), 0) {
                    if o.x[0].is_finite() && o.y.is_finite() {
                        d.points.push([o.x[0], o.y]);
                    }
                }
            }
            let n = d.points.len() - before;
            if n > 0 {
                used.entry(r.card().id)
                    .or_default()
                    .push(format!("{name} ({n})"));
            }
        }
    }
    for (id, d) in out.iter_mut() {
        d.source = match used.get(id.as_str()) {
            Some(v) => format!("{}: {}", dir.display(), v.join(", ")),
            None => format!("{}: no rows for this relation", dir.display()),
        };
    }
    (out, notes)
}
