//! What of the data a plot draws: every row as a point, coloured by subject or data set, or —
//! above [`MAX_SCATTER_POINTS`] rows — the density of all rows as a 2-D histogram (rows per
//! cell on a log colour scale) with each colour group's binned mean drawn over it.
//!
//! The reduction never feeds back into the fit: coefficients, band and residual statistics
//! come from all rows (`fit::pipeline`); this module only decides what is drawn, in two linear
//! passes over the rows for all panels of a figure (extents, then points or cells).
use crate::fit::pipeline::{FitOutcome, Prepared};

/// Above this many rows a figure draws densities instead of points. At 800 × 560 px, 5000
/// markers already overlap into solid ink where the data are dense, and each SVG marker costs
/// ~90 bytes: 5000 points keep an SVG near 0.5 MB, half the 1 MB bound.
pub const MAX_SCATTER_POINTS: usize = 5_000;

/// At most this many colour groups (the ten colours of [`PALETTE`]); more subjects are
/// coloured by data set, more data sets than this put the smallest in one "other" group.
pub const MAX_GROUPS: usize = 10;

/// Bins along x of the binned group means drawn over a density (40: a mean every ~15 px).
pub const MEAN_BINS: usize = 40;

/// A binned mean is drawn only from bins with at least this many rows of its group (a mean of
/// 20 rows has a standard error under a quarter of the rows' spread).
pub const MIN_MEAN_BIN_ROWS: u32 = 20;

/// Group colours: Tableau 10 (the category10 palette of d3/Vega and matplotlib's default cycle).
pub const PALETTE: [(u8, u8, u8); MAX_GROUPS] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// What the colours of a figure stand for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GroupBy {
    /// One colour for all rows (one subject in one data set, or too many of both to colour).
    Single,
    /// One colour per subject within a data set.
    Subject,
    /// One colour per data set (the input file).
    DataSet,
}

/// The colour groups of a fit's rows.
#[derive(Debug, Clone)]
pub struct Groups {
    /// What a colour stands for.
    pub by: GroupBy,
    /// Legend label per group.
    pub labels: Vec<String>,
    /// Per group: its subject (index into `Prepared::subjects`) when the group is one
    /// subject's rows.
    pub subject: Vec<Option<usize>>,
    /// Rows per group.
    pub rows: Vec<usize>,
    /// Number of subjects and data sets among the rows.
    pub n_subjects: usize,
    /// Number of data sets among the rows.
    pub n_datasets: usize,
    table: Vec<u16>,
    nf: usize,
}

/// A data set's short name: its file's stem (`data/run_hamner2013.csv` → `run_hamner2013`).
pub fn dataset_name(path: &str) -> String {
    std::path::Path::new(path)
        .file_stem()
        .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned())
}

fn file_of(p: &Prepared, i: usize) -> usize {
    p.file.get(i).map_or(0, |&f| f as usize)
}

/// Subjects × data sets beyond which pairs are not counted (each pair is a counter).
const MAX_PAIR_TABLE: usize = 1 << 22;

impl Groups {
    /// Groups the rows of `p`: by subject (within data set) when there are at most
    /// [`MAX_GROUPS`] such pairs, else by data set.
    pub fn new(p: &Prepared) -> Groups {
        let ns = p.subjects.len().max(1);
        let nf = p.files.len().max(1);
        let names: Vec<String> = (0..nf)
            .map(|f| {
                p.files
                    .get(f)
                    .map_or_else(String::new, |d| dataset_name(&d.path))
            })
            .collect();
        let mut per_file = vec![0usize; nf];
        let mut pairs: Vec<(usize, usize, usize)> = Vec::new(); // (subject, file, rows)
        if ns * nf <= MAX_PAIR_TABLE {
            let mut c = vec![0usize; ns * nf];
            for i in 0..p.obs.len() {
                c[p.subject[i] * nf + file_of(p, i)] += 1;
            }
            pairs = (0..ns * nf)
                .filter(|&k| c[k] > 0)
                .map(|k| (k / nf, k % nf, c[k]))
                .collect();
            for &(_, f, rows) in &pairs {
                per_file[f] += rows;
            }
        } else {
            for i in 0..p.obs.len() {
                per_file[file_of(p, i)] += 1;
            }
        }
        let files_used: Vec<usize> = (0..nf).filter(|&f| per_file[f] > 0).collect();
        let n_subjects = p.subjects.len();
        let mut g = Groups {
            by: GroupBy::Single,
            labels: Vec::new(),
            subject: Vec::new(),
            rows: Vec::new(),
            n_subjects,
            n_datasets: files_used.len(),
            table: vec![0; ns * nf],
            nf,
        };
        if !pairs.is_empty() && pairs.len() <= MAX_GROUPS && pairs.len() > 1 {
            g.by = GroupBy::Subject;
            for (k, &(s, f, rows)) in pairs.iter().enumerate() {
                g.table[s * nf + f] = k as u16;
                let subj = p.subjects.get(s).cloned().unwrap_or_default();
                g.labels.push(if files_used.len() > 1 {
                    format!("{subj} · {}", names[f])
                } else {
                    subj
                });
                g.subject.push(Some(s));
                g.rows.push(rows);
            }
        } else if files_used.len() > 1 {
            g.by = GroupBy::DataSet;
            let mut order = files_used.clone();
            order.sort_by_key(|&f| std::cmp::Reverse(per_file[f]));
            let keep = if order.len() <= MAX_GROUPS {
                order.len()
            } else {
                MAX_GROUPS - 1
            };
            let mut group_of_file = vec![keep as u16; nf];
            for (k, &f) in order.iter().take(keep).enumerate() {
                group_of_file[f] = k as u16;
                g.labels.push(names[f].clone());
                g.subject.push(None);
                g.rows.push(per_file[f]);
            }
            if keep < order.len() {
                g.labels
                    .push(format!("{} other data sets", order.len() - keep));
                g.subject.push(None);
                g.rows
                    .push(order[keep..].iter().map(|&f| per_file[f]).sum());
            }
            for row in g.table.chunks_mut(nf) {
                row.copy_from_slice(&group_of_file);
            }
        } else {
            g.labels.push(match (n_subjects, files_used.first()) {
                (1, Some(&f)) => format!("{} · {}", p.subjects[0], names[f]),
                (_, Some(&f)) => names[f].clone(),
                _ => "all rows".into(),
            });
            g.subject.push(if n_subjects == 1 { Some(0) } else { None });
            g.rows.push(p.obs.len());
        }
        g
    }

    /// The group of row `i`.
    #[inline]
    pub fn of(&self, p: &Prepared, i: usize) -> u16 {
        self.table[p.subject[i] * self.nf + file_of(p, i)]
    }

    /// Number of groups.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// True when there are no groups.
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// What the colours stand for, for the legend and the caption.
    pub fn describe(&self) -> String {
        match self.by {
            GroupBy::Subject => "coloured by subject (data set)".into(),
            GroupBy::DataSet => format!(
                "coloured by data set ({} subjects: too many to colour each)",
                self.n_subjects
            ),
            GroupBy::Single if self.n_subjects > 1 => format!(
                "one colour ({} subjects in one data set: too many to colour each)",
                self.n_subjects
            ),
            GroupBy::Single => "one subject, one colour".into(),
        }
    }
}

/// A plotted quantity of a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Input `j` of the relation.
    Input(usize),
    /// The measured response.
    Response,
    /// The refit's fitted value (with the subject's level).
    Fitted,
    /// Response − fitted.
    Residual,
}

/// The rows a panel draws: `y` against `x`, of one output (multi-output relations) or all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Source {
    /// Abscissa.
    pub x: Axis,
    /// Ordinate.
    pub y: Axis,
    /// Only rows of this output.
    pub output: Option<usize>,
}

/// The extent of a panel's rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// Rows.
    pub n: usize,
    /// x range of the rows.
    pub x: (f64, f64),
    /// y range of the rows.
    pub y: (f64, f64),
}

/// A 2-D histogram of a panel's rows, with each colour group's binned mean of y.
#[derive(Debug, Clone, PartialEq)]
pub struct Density {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// x range covered.
    pub x: (f64, f64),
    /// y range covered.
    pub y: (f64, f64),
    /// Rows per cell, row-major from (x low, y low).
    pub counts: Vec<u32>,
    /// The largest count.
    pub max: u32,
    /// Per group: `(x bin centre, mean y)` over bins with ≥ [`MIN_MEAN_BIN_ROWS`] rows.
    pub means: Vec<Vec<(f64, f64)>>,
}

/// A panel's axis ranges: `((x lo, x hi), (y lo, y hi))`.
pub type Ranges = ((f64, f64), (f64, f64));

/// What a panel draws of its rows.
#[derive(Debug, Clone, PartialEq)]
pub enum DataLayer {
    /// Every row: `(x, y, group)`.
    Points(Vec<(f64, f64, u16)>),
    /// The density of all rows.
    Density(Density),
}

/// The rows of one fit, as the report reads them.
pub struct Frame<'a> {
    /// The fit.
    pub o: &'a FitOutcome,
    /// The colour groups.
    pub groups: &'a Groups,
    outputs: Option<Vec<u8>>,
}

impl<'a> Frame<'a> {
    /// The rows of `o`, coloured by `groups`.
    pub fn new(o: &'a FitOutcome, groups: &'a Groups) -> Frame<'a> {
        let rel = o.refit.relation();
        let outputs = (rel.card().outputs.len() > 1).then(|| {
            o.prepared
                .obs
                .iter()
                .map(|ob| ob.x.output.min(255) as u8)
                .collect()
        });
        Frame { o, groups, outputs }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.o.prepared.obs.len()
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether figures draw densities (more than [`MAX_SCATTER_POINTS`] rows).
    pub fn dense(&self) -> bool {
        self.len() > MAX_SCATTER_POINTS
    }

    #[inline]
    fn value(&self, a: Axis, i: usize) -> f64 {
        match a {
            Axis::Input(j) => self.o.prepared.obs[i].x[j],
            Axis::Response => self.o.prepared.obs[i].y,
            Axis::Fitted => self.o.fitted[i],
            Axis::Residual => self.o.residuals[i],
        }
    }

    #[inline]
    fn in_output(&self, out: Option<usize>, i: usize) -> bool {
        match (out, &self.outputs) {
            (Some(k), Some(v)) => v[i] as usize == k,
            _ => true,
        }
    }

    /// One pass: the extent of every source's finite rows, and per colour group its rows, the
    /// range of input 0 and the mean of every input (for the refit drawn at each group's own
    /// inputs).
    pub fn extents(&self, sources: &[Source]) -> (Vec<Extent>, Vec<GroupInputs>) {
        let mut e = vec![
            Extent {
                n: 0,
                x: (f64::INFINITY, f64::NEG_INFINITY),
                y: (f64::INFINITY, f64::NEG_INFINITY),
            };
            sources.len()
        ];
        let mut gi = vec![
            GroupInputs {
                n: 0,
                x0: (f64::INFINITY, f64::NEG_INFINITY),
                mean: [0.0; crate::relations::MAX_INPUTS],
            };
            self.groups.len()
        ];
        let p = &self.o.prepared;
        for (i, ob) in p.obs.iter().enumerate() {
            let g = &mut gi[self.groups.of(p, i) as usize];
            g.n += 1;
            g.x0 = (g.x0.0.min(ob.x[0]), g.x0.1.max(ob.x[0]));
            for (m, x) in g.mean.iter_mut().zip(ob.x.values) {
                *m += x;
            }
            for (s, e) in sources.iter().zip(e.iter_mut()) {
                if !self.in_output(s.output, i) {
                    continue;
                }
                let (x, y) = (self.value(s.x, i), self.value(s.y, i));
                if x.is_finite() && y.is_finite() {
                    e.n += 1;
                    e.x = (e.x.0.min(x), e.x.1.max(x));
                    e.y = (e.y.0.min(y), e.y.1.max(y));
                }
            }
        }
        for g in &mut gi {
            for m in &mut g.mean {
                *m /= g.n.max(1) as f64;
            }
        }
        (e, gi)
    }

    /// One pass: per source, every row as a point (when the frame is not [`Frame::dense`]) or
    /// the density on its `cells` (nx × ny) grid over its range.
    pub fn layers(
        &self,
        sources: &[Source],
        ranges: &[Ranges],
        cells: &[(usize, usize)],
    ) -> Vec<DataLayer> {
        if !self.dense() {
            return sources
                .iter()
                .map(|s| {
                    DataLayer::Points(
                        (0..self.len())
                            .filter(|&i| self.in_output(s.output, i))
                            .map(|i| {
                                (
                                    self.value(s.x, i),
                                    self.value(s.y, i),
                                    self.groups.of(&self.o.prepared, i),
                                )
                            })
                            .filter(|p| p.0.is_finite() && p.1.is_finite())
                            .collect(),
                    )
                })
                .collect();
        }
        let ng = self.groups.len();
        struct Acc {
            nx: usize,
            ny: usize,
            counts: Vec<u32>,
            sum: Vec<f64>,
            cnt: Vec<u32>,
            sx: f64,
            sy: f64,
            mx: f64,
        }
        let mut acc: Vec<Acc> = ranges
            .iter()
            .zip(cells)
            .map(|((x, y), &(nx, ny))| Acc {
                nx,
                ny,
                counts: vec![0; nx * ny],
                sum: vec![0.0; ng * MEAN_BINS],
                cnt: vec![0; ng * MEAN_BINS],
                sx: nx as f64 / (x.1 - x.0),
                sy: ny as f64 / (y.1 - y.0),
                mx: MEAN_BINS as f64 / (x.1 - x.0),
            })
            .collect();
        let p = &self.o.prepared;
        for i in 0..self.len() {
            let g = self.groups.of(p, i) as usize;
            for ((s, r), a) in sources.iter().zip(ranges).zip(acc.iter_mut()) {
                if !self.in_output(s.output, i) {
                    continue;
                }
                let (x, y) = (self.value(s.x, i), self.value(s.y, i));
                let fx = (x - r.0 .0) * a.sx;
                let fy = (y - r.1 .0) * a.sy;
                // Rows outside the ranges (none: the ranges cover the extents) and NaN skip.
                if !(fx >= 0.0 && fy >= 0.0 && fx <= a.nx as f64 && fy <= a.ny as f64) {
                    continue;
                }
                let (cx, cy) = ((fx as usize).min(a.nx - 1), (fy as usize).min(a.ny - 1));
                a.counts[cy * a.nx + cx] += 1;
                let b = (((x - r.0 .0) * a.mx) as usize).min(MEAN_BINS - 1);
                a.sum[g * MEAN_BINS + b] += y;
                a.cnt[g * MEAN_BINS + b] += 1;
            }
        }
        acc.into_iter()
            .zip(ranges)
            .map(|(a, r)| {
                let w = (r.0 .1 - r.0 .0) / MEAN_BINS as f64;
                let means = (0..ng)
                    .map(|g| {
                        (0..MEAN_BINS)
                            .filter(|&b| a.cnt[g * MEAN_BINS + b] >= MIN_MEAN_BIN_ROWS)
                            .map(|b| {
                                (
                                    r.0 .0 + (b as f64 + 0.5) * w,
                                    a.sum[g * MEAN_BINS + b] / a.cnt[g * MEAN_BINS + b] as f64,
                                )
                            })
                            .collect()
                    })
                    .collect();
                let max = a.counts.iter().copied().max().unwrap_or(0);
                DataLayer::Density(Density {
                    nx: a.nx,
                    ny: a.ny,
                    x: r.0,
                    y: r.1,
                    counts: a.counts,
                    max,
                    means,
                })
            })
            .collect()
    }
}

/// A colour group's inputs (see [`Frame::extents`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupInputs {
    /// Rows.
    pub n: usize,
    /// Range of input 0.
    pub x0: (f64, f64),
    /// Mean of each input.
    pub mean: [f64; crate::relations::MAX_INPUTS],
}
