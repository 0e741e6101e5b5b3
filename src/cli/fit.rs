//! `gaitfit fit`: refit the published relations on trials tables → `fits/` and `reports/`.
use crate::export::coeffs::write_fit_files;
use crate::fit::inference::{SeMethod, CR2_RECOMMENDED_BELOW};
use crate::fit::pipeline::{fit_all, load_tables, FitOptions};
use crate::relations::{by_id, registry, Relation};
use anyhow::Context;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

/// Bootstrap replicates of the bundled refit (`gaitfit fit` without `--data`): enough that the
/// percentile intervals' Monte Carlo error (a few percent of their width) is small beside the
/// differences between methods they are compared with.
pub const BUNDLED_BOOTSTRAP: usize = 2000;

/// Arguments of `gaitfit fit`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Refit the published gait relations on trials tables and write fits/ and reports/",
    long_about = "Refit the published gait relations (running 1996 eqs. 2, 4–5; walking 1989 eq. 1 \
and the t_ds formula) on per-step trials tables, with full statistics.\n\n\
Input: CSV trials tables with a unit in every numeric header (see data/README.md), e.g. \
subject,gait,speed_m_per_s,step_length_m,step_freq_steps_per_min,flight_time_s,body_height_m; \
or raw measured files (.c3d, .trc with its .forces/_grf.mot, .mot GRF, .forces, WBDS *grf.txt, \
Winter's table, a per-frame CSV without subject/gait columns, a folder of them, or \
MARKERS+FORCES), whose steps are first derived as `gaitfit events` does with its defaults. \
Rows lacking what a relation needs, or whose speed, step length and step frequency disagree by \
more than 2 %, are rejected and reported, never silently used.\n\n\
Output: fits/<id>.json and fits/<id>.toml per relation (coefficients with standard errors, 95 % \
intervals, t-tests against the published values, r², rmse, AIC/BIC, leave-one-out and \
leave-one-subject-out errors, the published coefficients' fit on the same rows, data hash), and \
reports/ (per relation: data with refit curve, 95 % band and published curve; residuals vs \
fitted; normal Q–Q; summary.md). Files are replaced atomically; a relation that fails to fit \
leaves its existing fits/ files untouched and makes the command exit 1.\n\n\
Inference: gait rows are repeated measures (many steps per subject), so with two or more \
subjects standard errors are clustered by subject. From 20 subjects on: CR1 exactly as \
statsmodels cov_type='cluster' (small-sample factor G/(G−1)·(n−1)/(n−K)), t-tests and intervals \
with G − 1 degrees of freedom. With fewer than 20 subjects the default is CR2 (Bell & McCaffrey \
2002) with Satterthwaite degrees of freedom, which keeps close to the nominal level where CR1 \
under-covers with few or unbalanced subjects (Imbens & Kolesár 2016; Pustejovsky & Tipton \
2018; measured on the bundled walking data by tools/reference/coverage.py). Each fit record \
states its method. Breakpoints get the F-based profile confidence set over every \
admissible value (its pieces and hull); only a regular profile gives them a standard error.\n\n\
Relations: the ids listed under --relation (from the relations registry); kb-mu \
(Ko & Badler 1993 eqs. 21–24: one observation per μ-function and row, α bounds enforced; r² is \
pooled with each μ centred on its own mean; per-μ statistics are listed as derived).",
    after_help = "Examples:\n  gaitfit fit                                   # data/*.csv, all relations\n  \
gaitfit fit --data my_trials.csv --relation run-sl-v\n  \
gaitfit fit --data ../shared/data/wbds --relation walk-sl-sf walk-tds-sf\n  \
gaitfit fit --robust --bootstrap 1000 --seed 7"
)]
pub struct Args {
    /// Trials tables (CSV) or raw measured files / folders (events are detected first), fitted
    /// together. Default: every data/*.csv.
    #[arg(long = "data", value_name = "FILE", num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// Relation id(s) to fit (the registry's ids, listed in the help). Default: all (relations
    /// with no usable rows are skipped).
    #[arg(long = "relation", value_name = "ID", num_args = 1.., help = relation_help())]
    pub relation: Vec<String>,
    /// Folder for the fit records (JSON and TOML per relation).
    #[arg(long, value_name = "DIR", default_value = "fits")]
    pub fits: PathBuf,
    /// Folder for plots and summary.md.
    #[arg(long, value_name = "DIR", default_value = "reports")]
    pub reports: PathBuf,
    /// Also fit a Huber robust M-estimate (IRLS, k = 1.345) and report it beside least squares;
    /// its standard errors are the cluster-robust M-estimator sandwich by subject (CR1, t with
    /// G − 1 df) when the fit clusters, Huber's H1 (statsmodels RLM) with `--se iid`.
    #[arg(long)]
    pub robust: bool,
    /// Weighted least squares with weights (inverse variances, > 0) from this column.
    #[arg(long, value_name = "COLUMN")]
    pub weights: Option<String>,
    /// Bootstrap replicates, resampling subjects, for percentile 95 % intervals and bootstrap
    /// standard deviations (0 = none). Default: 0, or 2000 when refitting the bundled data/ (no
    /// --data), so that the committed fits carry the subject bootstrap beside the analytic
    /// intervals.
    #[arg(long, value_name = "N")]
    pub bootstrap: Option<usize>,
    /// Seed of the bootstrap.
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Standard errors, t-tests and intervals: `cluster` (CR1 by subject, as statsmodels
    /// cov_type='cluster', t with G − 1 df; the default from 20 subjects on), `cr2`
    /// (Bell–McCaffrey CR2 by subject with Satterthwaite df; the default with 2–19 subjects,
    /// where CR1 under-covers), or `iid` (rows independent; the default with one subject).
    #[arg(long, value_enum, value_name = "METHOD")]
    pub se: Option<SeArg>,
    /// Also fit a random-intercept model by REML (subjects' levels as random effects, Gaussian)
    /// for the linear relations (walk-sl-sf, walk-tds-sf) and record its fixed effects and
    /// variance components beside least squares (checked against statsmodels MixedLM).
    #[arg(long)]
    pub random_subject: bool,
    /// Do not write reports/ (plots and summary).
    #[arg(long)]
    pub no_report: bool,
}

/// `--se` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SeArg {
    /// Rows independent, one variance (per output).
    Iid,
    /// Clustered by subject, CR1 (statsmodels cov_type='cluster'), t with G − 1 df.
    Cluster,
    /// Clustered by subject, CR2 (Bell–McCaffrey) with Satterthwaite df.
    Cr2,
}

impl From<SeArg> for SeMethod {
    fn from(a: SeArg) -> SeMethod {
        match a {
            SeArg::Iid => SeMethod::Iid,
            SeArg::Cluster => SeMethod::Cluster,
            SeArg::Cr2 => SeMethod::Cr2,
        }
    }
}

fn default_data() -> anyhow::Result<Vec<PathBuf>> {
    let dir = PathBuf::from("data");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| {
            "no --data given and no data/ folder here: run from the repository root or pass \
             --data FILE"
                .to_string()
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .collect();
    v.sort();
    if v.is_empty() {
        anyhow::bail!("no data/*.csv trials tables found; pass --data FILE");
    }
    Ok(v)
}

/// Trials tables as they are; raw measured files (C3D, TRC + forces, treadmill GRF, folders of
/// them, a per-frame CSV recognised by its header) through the events layer, in the given order.
fn load_inputs(paths: &[PathBuf]) -> anyhow::Result<Vec<crate::ingest::trials::TrialsTable>> {
    use crate::events::input::{is_raw_input, raw_step_rows};
    let mut tables = Vec::with_capacity(paths.len());
    for p in paths {
        if crate::fit::pipeline::is_trials_table(p) && is_raw_input(p) {
            // A per-frame CSV: load_tables routes every .csv to the trials reader.
            let rows = raw_step_rows(p)?;
            let mut t = crate::ingest::trials::TrialsTable::from_step_rows(p, &rows);
            if let Ok(bytes) = std::fs::read(p) {
                t.sha256 = crate::ingest::trials::sha256_hex(&bytes);
            }
            tables.push(t);
        } else {
            tables.extend(load_tables(std::slice::from_ref(p), Some(raw_step_rows))?);
        }
    }
    Ok(tables)
}

/// The help of `--relation`: the ids come from the relations registry (one list).
fn relation_help() -> String {
    format!(
        "Relation id(s) to fit: {}. Default: all (relations with no usable rows are skipped)",
        crate::relations::ids().join(", ")
    )
}

/// Runs `gaitfit fit`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let paths = if args.data.is_empty() {
        default_data()?
    } else {
        args.data.clone()
    };
    let relations: Vec<Box<dyn Relation>> = if args.relation.is_empty() {
        registry()
    } else {
        args.relation
            .iter()
            .map(|id| by_id(id))
            .collect::<Result<_, _>>()?
    };
    let tables = load_inputs(&paths)?;
    let opts = FitOptions {
        robust: args.robust,
        weights: args.weights.clone(),
        bootstrap: args.bootstrap.unwrap_or(if args.data.is_empty() {
            BUNDLED_BOOTSTRAP
        } else {
            0
        }),
        seed: args.seed,
        se: args.se.map(SeMethod::from),
        random_subject: args.random_subject,
    };
    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(relations.len() as u64);
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} fitting {msg}")
        {
            b.set_style(style);
        }
        Some(b)
    } else {
        None
    };
    // One relation at a time, its files written as soon as it is fitted; without reports, only
    // its record is kept (the rows, fitted values and residuals of a relation are dropped before
    // the next is fitted, so memory holds one relation's working set, not all of them).
    let mut run = crate::fit::pipeline::FitRun::default();
    let mut records = Vec::new();
    let mut lines = Vec::new();
    for rel in &relations {
        let one = fit_all(
            std::slice::from_ref(rel),
            &tables,
            &opts,
            args.relation.is_empty(),
            |id| {
                if let Some(b) = &bar {
                    b.set_message(id.to_string());
                    b.inc(1);
                }
            },
        );
        for o in one.outcomes {
            write_fit_files(&args.fits, &o.record)?;
            lines.push(summary_line(&o, &args.fits));
            if args.no_report {
                records.push(o.record);
            } else {
                run.outcomes.push(o);
            }
        }
        run.failures.extend(one.failures);
        run.skipped.extend(one.skipped);
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    for l in &lines {
        println!("{l}");
    }
    let few: Vec<String> = records
        .iter()
        .chain(run.outcomes.iter().map(|o| &o.record))
        .filter_map(|r| r.inference.as_ref().map(|i| (&r.relation, i)))
        .filter(|(_, i)| i.method == "CR1" && i.clusters < CR2_RECOMMENDED_BELOW)
        .map(|(r, i)| format!("{r} ({})", i.clusters))
        .collect();
    if !few.is_empty() {
        println!(
            "note: fewer than {CR2_RECOMMENDED_BELOW} subjects in {}: CR1 (asked for) \
             under-covers with few clusters; CR2 (the default there) is recommended",
            few.join(", ")
        );
    }
    for (id, why) in &run.skipped {
        println!("{id}: skipped ({why})");
    }
    for (id, why) in &run.failures {
        eprintln!("gaitfit: {id}: not fitted: {why} (existing fits left untouched)");
    }
    if !args.no_report && !run.outcomes.is_empty() {
        let files = crate::report::write_report(&args.reports, &run.outcomes, &run.failures)?;
        println!(
            "reports: {} files in {}",
            files.len(),
            args.reports.display()
        );
    }
    let fitted = !records.is_empty() || !run.outcomes.is_empty();
    Ok(if run.failures.is_empty() && fitted {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The line `gaitfit fit` prints for a fitted relation.
fn summary_line(o: &crate::fit::pipeline::FitOutcome, fits: &std::path::Path) -> String {
    let r = &o.record;
    let unit = r
        .units
        .get(o.refit.card().response.symbol)
        .cloned()
        .unwrap_or_default();
    // Ko–Badler's α have no published values: its "published" curve is a reference.
    let against = if crate::report::summary::reference_words(r).is_some() {
        "paper's reference curve"
    } else {
        "published"
    };
    format!(
        "{}: n = {}, r² = {:.4} ({against} {:.4}), rmse = {:.4} {} → {}",
        r.relation,
        r.n,
        r.r2,
        r.published_fit.r2,
        r.rmse,
        unit,
        fits.join(format!("{}.json", r.relation)).display()
    )
}
