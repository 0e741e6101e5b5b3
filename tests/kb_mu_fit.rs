//! `kb-mu` through the generic pipeline (`gaitfit fit --relation kb-mu`): the bounded fit of the
//! μ-functions (Ko & Badler 1993, appendix A) against an independent closed form on the bundled
//! tables, on synthetic tables with known coefficients (inside and beyond the bounds), and the
//! committed `fits/kb-mu.json` (the generator's built-in slopes) against the closed form.
use gaitfit::fit::pipeline::{fit_relation, load_tables, FitOptions};
use gaitfit::generator::generalize::default_alpha;
use gaitfit::ingest::trials::parse_trials;
use gaitfit::relations::kb_mu::{separable_line, KbMu, WINTER_SUBJECT, WINTER_TABLE_LEG_LENGTH};
use gaitfit::relations::Relation;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bundled_tables() -> Vec<PathBuf> {
    let d = root().join("data");
    vec![d.join("walk_schreiber2019.csv"), d.join("walk_bmclab.csv")]
}

fn value(rec: &gaitfit::export::coeffs::FitRecord, name: &str) -> f64 {
    rec.coefficients
        .iter()
        .find(|c| c.name == name)
        .map(|c| c.value)
        .unwrap()
}

/// (x, μ) points of μ `i` read straight from the CSV text (degrees → rad), independently of the
/// trials reader and the relation.
fn points_from_csv(path: &Path, i: usize) -> Vec<(f64, f64)> {
    subject_points_from_csv(path, i)
        .into_iter()
        .map(|(_, x, y)| (x, y))
        .collect()
}

/// As [`points_from_csv`], with each point's subject.
fn subject_points_from_csv(path: &Path, i: usize) -> Vec<(String, f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let mu_col = col([
        "knee_angle_hs_deg",
        "foot_angle_hs_deg",
        "foot_angle_to_deg",
        "meta_angle_to_deg",
    ][i]);
    let (sl, ll, gait) = (col("step_length_m"), col("leg_length_m"), col("gait"));
    let subj = col("subject");
    lines
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let m: f64 = f[mu_col].parse().ok()?;
            (f[gait] == "walk").then(|| {
                let x = f[sl].parse::<f64>().unwrap() * WINTER_TABLE_LEG_LENGTH
                    / f[ll].parse::<f64>().unwrap();
                (f[subj].to_string(), x, m.to_radians())
            })
        })
        .collect()
}

/// The model is separable per μ, so the bounded least-squares optimum is each μ's own line
/// with its slope clamped into the bounds and the intercept refitted — computed here in closed
/// form from the CSV text, independently of argmin, the trials reader and the pipeline.
#[test]
fn bounded_fit_equals_clamped_separable_lines() {
    let rel = KbMu::published();
    let tables = load_tables(&bundled_tables(), None).unwrap();
    let rec = fit_relation(&rel, &tables, &FitOptions::default())
        .unwrap()
        .record;
    let sl = rel.sl_star();
    for i in 0..4 {
        let pts: Vec<(f64, f64)> = bundled_tables()
            .iter()
            .flat_map(|p| points_from_csv(p, i))
            .collect();
        let (alpha, mu) = separable_line(&pts, i, sl, rel.bounds(i));
        let a = value(&rec, &format!("alpha{}", i + 1));
        let m = value(&rec, &format!("mu{}_star", i + 1));
        // CSV values carry 2 decimals of a degree; the reader converts the same numbers.
        assert!((a - alpha).abs() < 1e-9, "alpha{}: {a} vs {alpha}", i + 1);
        assert!((m - mu).abs() < 1e-9, "mu{}_star: {m} vs {mu}", i + 1);
    }
    // α₁ wants to be negative on these data: held on its bound and said so.
    let c = &rec.coefficients[0];
    assert_eq!(c.value, 0.0);
    assert!(c.std_error.is_none());
    assert_eq!(c.flag.as_deref(), Some("bound active"));
    assert!(c.held.as_deref().unwrap_or("").contains("bound active"));
    assert!(rec.notes.iter().any(|n| n.contains("alpha1: bound active")));
    // Pooled r² with each μ centred on its own mean, recomputed here.
    let (mut rss, mut tss) = (0.0, 0.0);
    for i in 0..4 {
        let pts: Vec<(f64, f64)> = bundled_tables()
            .iter()
            .flat_map(|p| points_from_csv(p, i))
            .collect();
        let (a, m) = separable_line(&pts, i, sl, rel.bounds(i));
        let s = if i == 0 { -1.0 } else { 1.0 };
        let mean = pts.iter().map(|p| p.1).sum::<f64>() / pts.len() as f64;
        for (x, y) in &pts {
            rss += (y - (s * a * (x - sl) + m)).powi(2);
            tss += (y - mean).powi(2);
        }
    }
    assert!(
        (rec.r2 - (1.0 - rss / tss)).abs() < 1e-9,
        "{} vs {}",
        rec.r2,
        1.0 - rss / tss
    );
    assert!(rec.derived.iter().any(|d| d.name == "mu4: r² (centred)"));
    // Per-μ leave-one-subject-out: every fold re-solves the bounded problem; the model is
    // separable, so a fold is each μ's clamped line on the other subjects' points.
    let d = |n: &str| rec.derived.iter().find(|d| d.name == n).map(|d| d.value);
    let (mut all_sq, mut all_n) = (0.0, 0usize);
    for i in 0..4 {
        let pts: Vec<(String, f64, f64)> = bundled_tables()
            .iter()
            .flat_map(|p| subject_points_from_csv(p, i))
            .collect();
        let subjects: std::collections::BTreeSet<&str> = pts.iter().map(|p| p.0.as_str()).collect();
        let s = if i == 0 { -1.0 } else { 1.0 };
        let mut sq = 0.0;
        for held in &subjects {
            let train: Vec<(f64, f64)> = pts
                .iter()
                .filter(|p| p.0 != *held)
                .map(|p| (p.1, p.2))
                .collect();
            let (a, m) = separable_line(&train, i, sl, rel.bounds(i));
            sq += pts
                .iter()
                .filter(|p| p.0 == *held)
                .map(|p| (p.2 - (s * a * (p.1 - sl) + m)).powi(2))
                .sum::<f64>();
        }
        let want = (sq / pts.len() as f64).sqrt();
        let got = d(&format!("mu{}: leave-one-subject-out rmse", i + 1)).unwrap();
        assert!(
            (got - want).abs() < 1e-9 * want,
            "mu{}: {got} vs {want}",
            i + 1
        );
        all_sq += sq;
        all_n += pts.len();
    }
    let pooled = (all_sq / all_n as f64).sqrt();
    let loso = rec.loso_rmse.unwrap();
    assert!((pooled - loso).abs() < 1e-9 * loso, "{pooled} vs {loso}");
    let b = rec.bounded.as_ref().unwrap();
    assert!(b.solves > 1 && b.converged == b.solves);
}

/// A trials table of `subjects × steps` walking steps with μ = the μ-functions at `alpha`, `mu`
/// plus uniform noise of ±0.6°.
fn synthetic(
    alpha: [f64; 4],
    mu: [f64; 4],
    seed: u64,
) -> Vec<gaitfit::ingest::trials::TrialsTable> {
    let rel = KbMu::published();
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut csv = String::from(
        "subject,gait,step_length_m,leg_length_m,knee_angle_hs_rad,foot_angle_hs_rad,\
         foot_angle_to_rad,meta_angle_to_rad\n",
    );
    for s in 0..8 {
        let ll: f64 = r.random_range(0.75..0.95);
        for _ in 0..5 {
            let sl: f64 = r.random_range(0.5..0.85);
            let x = sl * rel.ll_star() / ll;
            let m: Vec<String> = (0..4)
                .map(|i| {
                    let sign = if i == 0 { -1.0 } else { 1.0 };
                    let noise: f64 = r.random_range(-0.01..0.01);
                    format!(
                        "{:.9}",
                        sign * alpha[i] * (x - rel.sl_star()) + mu[i] + noise
                    )
                })
                .collect();
            csv.push_str(&format!("s{s},walk,{sl:.6},{ll:.6},{}\n", m.join(",")));
        }
    }
    vec![parse_trials(Path::new("synthetic.csv"), csv.as_bytes()).unwrap()]
}

#[test]
fn recovers_known_coefficients_inside_the_bounds() {
    let (alpha, mu) = ([0.15, 0.4, 0.8, 1.1], [0.05, 0.4, 1.2, 0.9]);
    let rec = fit_relation(
        &KbMu::published(),
        &synthetic(alpha, mu, 1),
        &FitOptions::default(),
    )
    .unwrap()
    .record;
    assert_eq!(rec.n, 160);
    for i in 0..4 {
        let c = &rec.coefficients[i];
        assert!((c.value - alpha[i]).abs() < 0.05, "{}: {}", c.name, c.value);
        let ci = c.ci95;
        assert!(ci[0].unwrap() < alpha[i] && alpha[i] < ci[1].unwrap());
        assert!((value(&rec, &format!("mu{}_star", i + 1)) - mu[i]).abs() < 0.01);
    }
    assert!(rec.coefficients.iter().all(|c| c.flag.is_none()));
    assert!(rec.r2 > 0.5 && rec.loso_rmse.is_some());
}

#[test]
fn reports_an_active_bound_on_either_side() {
    // True α₁ = −0.2 (knee flexes more in longer steps): the fit must stop at 0 and say so.
    let t = synthetic([-0.2, 0.4, 0.8, 1.1], [0.05, 0.4, 1.2, 0.9], 2);
    let rec = fit_relation(&KbMu::published(), &t, &FitOptions::default())
        .unwrap()
        .record;
    let c = &rec.coefficients[0];
    assert_eq!((c.value, c.flag.as_deref()), (0.0, Some("bound active")));
    // α₁ above 0.3 stops at 0.3; α₃ < 0 stops at 0.
    let t = synthetic([0.6, 0.4, -0.3, 1.1], [0.05, 0.4, 1.2, 0.9], 3);
    let rec = fit_relation(&KbMu::published(), &t, &FitOptions::default())
        .unwrap()
        .record;
    assert_eq!(rec.coefficients[0].value, 0.3);
    assert_eq!(rec.coefficients[2].value, 0.0);
    assert!(rec.coefficients[1].flag.is_none() && rec.coefficients[3].flag.is_none());
    // A slope merely near its bound stays free (KKT check, not the optimiser's proximity).
    let t = synthetic([0.29, 0.02, 0.8, 1.1], [0.05, 0.4, 1.2, 0.9], 4);
    let rec = fit_relation(&KbMu::published(), &t, &FitOptions::default())
        .unwrap()
        .record;
    for i in 0..4 {
        let (lo, hi) = KbMu::published().bounds(i);
        let v = rec.coefficients[i].value;
        assert!(v >= lo && v <= hi);
        if rec.coefficients[i].flag.is_none() {
            assert!(rec.coefficients[i].std_error.is_some());
        }
    }
}

/// The generator's built-in slopes (read from the committed `fits/kb-mu.json` at build time) are
/// the bounded least-squares optimum on the committed tables, computed here in closed form from
/// the CSV text (each μ's line, slope clamped into its bounds): fails if fits/kb-mu.json is stale
/// against data/ or the wrong coefficients are read. ll(S*) is Winter's row.
#[test]
fn built_in_alpha_is_the_committed_tables_optimum_and_winter_leg_length_matches() {
    let rel = KbMu::published();
    let built_in = default_alpha();
    for (i, d) in built_in.iter().enumerate() {
        let pts: Vec<(f64, f64)> = bundled_tables()
            .iter()
            .flat_map(|p| points_from_csv(p, i))
            .collect();
        let (alpha, _) = separable_line(&pts, i, rel.sl_star(), rel.bounds(i));
        // CSV values carry 2 decimals of a degree; the closed form and the fit solve the same
        // normal equations differently.
        assert!((alpha - d).abs() <= 1e-9, "alpha{}: {d} vs {alpha}", i + 1);
    }
    // The same file through the relation's own reader.
    let r = KbMu::from_fit_file(&root().join("fits/kb-mu.json")).unwrap();
    assert_eq!(r.alpha(), built_in);
    let t = load_tables(&[root().join("data/walk_bmclab.csv")], None).unwrap();
    let ll = t[0].columns[gaitfit::units::Quantity::LegLength as usize]
        .as_ref()
        .unwrap();
    let row = (0..t[0].len())
        .find(|&i| t[0].subject_name(i) == WINTER_SUBJECT)
        .unwrap();
    assert_eq!(ll[row], WINTER_TABLE_LEG_LENGTH);
}

/// The relation reads sl* and μ* from the bundled prototype file itself (no generator import):
/// they must be the values the generator's prototype carries.
#[test]
fn published_values_are_the_prototypes() {
    let p = gaitfit::generator::generalize::prototype::Prototype::bundled();
    let r = KbMu::published();
    assert_eq!(r.mu_star(), p.mu_star);
    assert_eq!(r.sl_star(), p.walk.step_length());
    assert_eq!(r.alpha(), [0.0; 4]);
}
