//! `reports/summary.md`: one section per relation — published vs refit coefficients with their
//! confidence intervals, r² (saying which), rmse, n, validation errors, notes and the plots, each
//! captioned with what of the data it draws.
use super::Figure;
use crate::export::coeffs::FitRecord;
use std::collections::BTreeMap;
use std::fmt::Write;

fn g(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        format!("{:.6}", v)
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.4e}")
    }
}

fn go(v: Option<f64>) -> String {
    v.map_or("open".into(), g)
}

/// The paragraph that says how the uncertainty in this report was computed.
fn inference_paragraph(records: &[FitRecord]) -> String {
    let methods: Vec<String> = {
        let mut v: Vec<String> = records
            .iter()
            .filter_map(|r| r.inference.as_ref().map(|i| i.method.clone()))
            .collect();
        v.sort();
        v.dedup();
        v
    };
    let boot = records.iter().find_map(|r| r.bootstrap.as_ref());
    format!(
        "**How the uncertainty was computed.** Gait rows are repeated measures: each subject \
         contributes many steps, and steps of one person are not independent, so every standard \
         error here is clustered by subject ({}), with t-tests and 95 % intervals whose degrees \
         of freedom follow the number of subjects G, not the number of rows. From {} subjects \
         on the method is CR1 as statsmodels `cov_type='cluster'` computes it (small-sample \
         factor G/(G−1)·(n−1)/(n−K), G − 1 degrees of freedom). Below that it is CR2, Bell & \
         McCaffrey's bias-reduced sandwich, with their Satterthwaite degrees of freedom (Imbens \
         & Kolesár 2016): with few subjects, or one subject holding most rows, CR1 is biased \
         down and its t-intervals under-cover (Cameron & Miller 2015, §VI), while CR2's degrees \
         of freedom shrink with the subjects' leverage (see each coefficient's t-test) and its \
         intervals widen accordingly. The subject bootstrap{} is shown beside every \
         analytic interval, but with few and unequal subjects it is not a reference either: a \
         Monte Carlo on the bundled walking designs (9–10 subjects, one with 252 of 295 rows; \
         tools/reference/coverage.py, numbers in tools/reference/coverage.json) finds that for \
         walk-sl-sf (one coefficient, no intercept) CR1 and the bootstrap intervals fall far \
         below their nominal 95 % coverage while CR2 with Bell–McCaffrey degrees of freedom \
         comes close to it, and that for walk-tds-sf all three reach it, CR2 conservatively; \
         so where they disagree here the CR2 interval is the one that does not overstate the \
         precision of the linear coefficients. Per-subject levels of run-sl-v are informed by \
         one subject each and get only a within-subject (iid) standard error; the global slope is the mean of the \
         subjects' slopes and its clustered standard error includes their spread. A \
         breakpoint's 95 % set is every value whose profile residual sum of squares passes the \
         F-test against the minimum (the likelihood ratio divided by the clustering's design \
         effect), searched over all admissible partitions of the rows (or a fine grid for a \
         continuous breakpoint) and reported as its pieces and their hull; a breakpoint whose \
         model jumps, or whose profile is irregular (several pieces or minima), has no standard \
         error or t-test, and the linear coefficients' standard errors are then conditional on \
         it — the bootstrap refits the breakpoints in every replicate and shows what that \
         conditioning leaves out (for run-tflight-sf's polynomial coefficients, which swing \
         with k1, its intervals are the ones to read). Where a breakpoint's profile is regular, \
         the linear standard errors are those with the breakpoint free (Gauss–Newton), with the \
         conditional ones beside them. Coefficients the paper does not give (Ko–Badler's α) \
         have no published value and no t-test.{}",
        methods.join(", "),
        crate::fit::inference::CR2_RECOMMENDED_BELOW,
        boot.map_or(String::new(), |b| format!(
            " ({} replicates, seed {})",
            b.n, b.seed
        )),
        agreement(records),
    )
}

/// How the analytic standard errors compare with the bootstrap's on these fits, and what the
/// Monte Carlo says about each method's coverage (empty without a bootstrap).
fn agreement(records: &[FitRecord]) -> String {
    let mut per: Vec<String> = Vec::new();
    let (mut within, mut total) = (0, 0);
    for r in records {
        let ratios: Vec<f64> = r
            .coefficients
            .iter()
            .filter_map(|c| Some(c.std_error? / c.se_bootstrap?))
            .filter(|q| q.is_finite())
            .collect();
        if ratios.is_empty() {
            continue;
        }
        total += ratios.len();
        within += ratios.iter().filter(|&&q| (q - 1.0).abs() <= 0.1).count();
        let (lo, hi) = ratios
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &q| {
                (a.min(q), b.max(q))
            });
        per.push(if ratios.len() == 1 || (hi - lo) < 0.005 {
            format!("{} {lo:.2}", r.relation)
        } else {
            format!("{} {lo:.2}–{hi:.2}", r.relation)
        });
    }
    let Some(b) = records
        .iter()
        .find_map(|r| r.bootstrap.as_ref().map(|b| b.n))
    else {
        return String::new();
    };
    if total == 0 || b < 2 {
        return String::new();
    }
    // Relative standard error of a standard deviation from b normal draws: 1/√(2(b − 1)).
    let mc = 100.0 / (2.0 * (b as f64 - 1.0)).sqrt();
    format!(
        " **Analytic vs bootstrap, stated plainly:** the ratio of each analytic standard error \
         to the bootstrap standard deviation of the same coefficient is {} ({within} of {total} \
         coefficients within ±10 %; the bootstrap standard deviation's own Monte Carlo error is \
         about {mc:.1} % with {b} replicates); so the two do not agree within Monte Carlo error everywhere, and \
         the disagreement is not a numerical fault: with 5–10 unequal subjects neither is exact. \
         {}\
         Where the ratio is far below 1 (run-tflight-sf's polynomial coefficients), the analytic \
         standard error is conditional on an irregular k1 and the bootstrap, which refits k1, is \
         the interval to read; where it is above 1 (walk-tds-sf d0), CR2 is the conservative one.",
        per.join(", "),
        coverage_sentence(records),
    ) + &wild_sentence(records)
}

/// The wild cluster bootstrap-t intervals beside the analytic ones (relations linear in every
/// coefficient; empty when no record has one).
fn wild_sentence(records: &[FitRecord]) -> String {
    let mut parts = Vec::new();
    let (mut agree, mut total) = (0, 0);
    let mut exact = true;
    for r in records {
        let Some(w) = &r.wild_bootstrap else {
            continue;
        };
        exact &= w.enumerated;
        let method = r
            .inference
            .as_ref()
            .map_or("analytic", |i| i.method.as_str());
        for wc in &w.coefficients {
            let (Some([wl, wh]), Some(c)) = (wc.ci95, r.coefficient(&wc.name)) else {
                continue;
            };
            let [Some(al), Some(ah)] = c.ci95 else {
                continue;
            };
            let ratio = (wh - wl) / (ah - al);
            let t_crit = c.std_error.map_or(f64::NAN, |se| (ah - al) / (2.0 * se));
            total += 1;
            agree += usize::from((ratio - 1.0).abs() <= 0.1);
            parts.push(format!(
                "{} {}: wild [{}, {}] (CR1 SE × t* {:.2}…{:.2}) vs {method} [{}, {}] ({method} SE \
                 × t ±{t_crit:.2}), width ratio {ratio:.2}",
                r.relation,
                wc.name,
                g(wl),
                g(wh),
                wc.t_quantiles[0],
                wc.t_quantiles[1],
                g(al),
                g(ah),
            ));
        }
    }
    if total == 0 {
        return String::new();
    }
    format!(
        " **Wild cluster bootstrap-t** (unrestricted, Webb six-point weights, each sample \
         refitted and studentised by its own CR1 standard error; {}): {}. {agree} of {total} \
         intervals agree with the analytic ones within ±10 % of their width. The differences are \
         between methods, not Monte Carlo error: the wild interval is CR1's standard error times \
         the bootstrap's t* quantiles, so where one subject holds most rows (walk-sl-sf on the \
         bundled data) it keeps CR1's leverage-shrunk standard error and comes out about as \
         short as CR1's own interval, which covered far below 95 % in the Monte Carlo above, \
         while CR2 undoes the shrinkage and its Bell–McCaffrey df widen it; with more balanced \
         subjects (walk-tds-sf) the t* quantiles lie between t with G − 1 df and t with \
         Bell–McCaffrey's df, and the wild intervals are shorter than CR2's. The unrestricted \
         wild bootstrap is known to over-reject with few, unequal clusters (MacKinnon & Webb \
         2017; the restricted one would need a bootstrap per candidate value to give an \
         interval), so CR2 with Bell–McCaffrey df remains the interval to read.",
        if exact {
            "every 6^G weight pattern enumerated, so these are exact, with no Monte Carlo error; \
             the independent numpy enumeration tools/reference/wild.py reproduces them"
        } else {
            "seeded draws"
        },
        parts.join("; "),
    )
}

/// The committed Monte Carlo coverage study (`tools/reference/coverage.py`), read at build time
/// so that the report quotes the numbers the script wrote, never a copy of them.
const COVERAGE_JSON: &str = include_str!("../../tools/reference/coverage.json");

/// One sentence with the coverage the Monte Carlo measured for each relation it studied, quoted
/// only where the study's design (rows and subjects) is the one fitted here; otherwise it says
/// that the study must be re-run on this data.
fn coverage_sentence(records: &[FitRecord]) -> String {
    let Ok(study) = serde_json::from_str::<serde_json::Value>(COVERAGE_JSON) else {
        return String::new();
    };
    let reps = study["reps"].as_u64().unwrap_or(0);
    let pct = |v: &serde_json::Value| -> Option<String> {
        let xs: Vec<String> = v
            .as_array()?
            .iter()
            .map(|x| x.as_f64().map(|f| format!("{:.1}", 100.0 * f)))
            .collect::<Option<_>>()?;
        Some(format!("{} %", xs.join("/")))
    };
    let mut parts = Vec::new();
    let mut stale = Vec::new();
    for r in records {
        let Some(d) = study.get(&r.relation) else {
            continue;
        };
        let clusters = r.inference.as_ref().map_or(r.n_subjects, |i| i.clusters);
        if d["n"].as_u64() != Some(r.n as u64) || d["clusters"].as_u64() != Some(clusters as u64) {
            stale.push(r.relation.clone());
            continue;
        }
        let names: Vec<&str> = r.coefficients.iter().map(|c| c.name.as_str()).collect();
        let c = &d["coverage"];
        let (Some(cr1), Some(cr2), Some(boot)) =
            (pct(&c["cr1"]), pct(&c["cr2_bm"]), pct(&c["bootstrap"]))
        else {
            continue;
        };
        let se = d["monte_carlo_se_of_coverage"]
            .as_f64()
            .map_or(String::new(), |s| format!(", ± {:.1} %", 100.0 * s));
        let coefs = d["beta"].as_array().map_or(0, |b| b.len()).min(names.len());
        parts.push(format!(
            "{} {} — CR1 {cr1}, CR2 with Bell–McCaffrey df {cr2}, subject bootstrap {boot}{se}",
            r.relation,
            names[..coefs].join("/")
        ));
    }
    let mut out = String::new();
    if !parts.is_empty() {
        out = format!(
            "The Monte Carlo above ({reps} simulated data sets with these designs; \
             tools/reference/coverage.json) measured the coverage of nominal 95 % intervals: {}.",
            parts.join("; ")
        );
    }
    if !stale.is_empty() {
        let _ = write!(
            out,
            " The coverage study was run on a different design than the one fitted here for {} \
             (rows or subjects differ): re-run tools/reference/coverage.py before reading its \
             numbers.",
            stale.join(", ")
        );
    }
    if !out.is_empty() {
        out.push(' ');
    }
    out
}

/// For a relation whose paper gives no value for some coefficients (Ko–Badler's α: only their
/// ranges), the "published" fit is of a reference curve with those at the relation's reference
/// values: its words (`None` when the paper gives every value).
/// Where the "published" curve of `r` is only a reference (the paper gives no value for some of
/// the relation's own coefficients, e.g. Ko–Badler's α, held at the values named here): why.
pub fn reference_words(r: &FitRecord) -> Option<String> {
    // Only the relation's own coefficients the paper cites no value for (not per-subject
    // levels, which the published curve has none of).
    let rel = crate::relations::by_id(&r.relation).ok()?;
    let specs: Vec<&crate::relations::ParameterSpec> = r
        .coefficients
        .iter()
        .filter(|c| c.published.is_none())
        .filter_map(|c| {
            rel.card()
                .parameters
                .iter()
                .find(|s| s.name == c.name && !s.cited)
        })
        .collect();
    if specs.is_empty() {
        return None;
    }
    let refs: Vec<String> = specs
        .iter()
        .map(|s| format!("{} = {}", s.name, g(s.published)))
        .collect();
    let names: Vec<&str> = specs.iter().map(|s| s.name).collect();
    Some(format!(
        "the paper's values with {}: it gives only ranges for {}, so this is a reference, not \
         a published curve",
        refs.join(", "),
        names.join(", ")
    ))
}

/// Renders the summary of `records` (in the given order). `failures` lists relations that could
/// not be fitted, with the reason.
/// `figures` holds, per relation id, the plots written for it (see
/// [`super::plots::write_plots`]).
pub fn render_summary(
    records: &[FitRecord],
    failures: &[(String, String)],
    figures: &BTreeMap<String, Vec<Figure>>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# gaitfit — refit of the published gait relations\n");
    let _ = writeln!(
        s,
        "Generated by `gaitfit fit` (gaitfit {}). Coefficients are in the papers' units (m, m/min, \
         steps/min, s). The t-test p compares each refit coefficient with its published value \
         (— where the paper gives none).\n",
        crate::GAITFIT_VERSION
    );
    let _ = writeln!(s, "{}\n", inference_paragraph(records));
    let _ = writeln!(
        s,
        "| relation | n | subjects | r² | published r² | rmse | published rmse | LOSO rmse |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|");
    let mut footnotes = Vec::new();
    for r in records {
        let mark = match reference_words(r) {
            Some(w) => {
                footnotes.push(format!("† `{}`: {w}.", r.relation));
                "†"
            }
            None => "",
        };
        let _ = writeln!(
            s,
            "| [`{}`](#{}) | {} | {} | {:.4} | {:.4}{mark} | {} | {}{mark} | {} |",
            r.relation,
            r.relation,
            r.n,
            r.n_subjects,
            r.r2,
            r.published_fit.r2,
            g(r.rmse),
            g(r.published_fit.rmse),
            r.loso_rmse.map_or("—".into(), g)
        );
    }
    for (id, why) in failures {
        let _ = writeln!(
            s,
            "| `{id}` | — | — | not fitted: {} | | | | |",
            why.replace('|', "/")
        );
    }
    if !footnotes.is_empty() {
        let _ = writeln!(s, "\n{}", footnotes.join("\n"));
    }
    for r in records {
        let _ = writeln!(s, "\n## {}\n", r.relation);
        let _ = writeln!(s, "**{}** — {}.\n", r.title, r.citation);
        let _ = writeln!(s, "`{}`\n", r.equation);
        let _ = writeln!(
            s,
            "n = {} rows from {} subject(s); r² = {:.5} ({}); adjusted r² = {:.5}; rmse = {}; \
             residual mean square = {}; AIC = {:.2}; BIC = {:.2}; leave-one-out rmse = {}; \
             leave-one-subject-out rmse = {} ({}).\n",
            r.n,
            r.n_subjects,
            r.r2,
            r.r2_definition,
            r.adj_r2,
            g(r.rmse),
            g(r.residual_mean_square),
            r.aic,
            r.bic,
            g(r.loo_rmse),
            r.loso_rmse.map_or("n/a".into(), g),
            r.loso_note
        );
        let reference = reference_words(r);
        let _ = writeln!(
            s,
            "{} on the same rows: r² = {:.5}, rmse = {}.\n",
            match &reference {
                Some(w) => format!("Reference curve ({w})"),
                None => "Published coefficients".to_string(),
            },
            r.published_fit.r2,
            g(r.published_fit.rmse)
        );
        if let Some(inf) = &r.inference {
            let _ = writeln!(
                s,
                "Inference: **{}** — {} ({} subject(s){}). Breakpoints: {}. {}.\n",
                inf.method,
                inf.description,
                inf.clusters,
                inf.df.map_or(String::new(), |d| format!(", {} df", g(d))),
                inf.breakpoints,
                inf.recommendation
            );
        }
        for b in &r.breakpoints {
            let _ = writeln!(
                s,
                "Confidence set of `{}` ({}): {} of {} accepted, {} piece(s): {}; {} local \
                 minima of the profile; {}.\n",
                b.name,
                b.method,
                b.accepted,
                b.admissible,
                b.pieces.len(),
                b.pieces
                    .iter()
                    .map(|p| format!("[{}, {}]", go(p[0]), go(p[1])))
                    .collect::<Vec<_>>()
                    .join(" ∪ "),
                b.local_minima,
                match &b.irregular_because {
                    None => "regular: Wald standard error and t-test with the breakpoint free"
                        .to_string(),
                    Some(w) => format!("irregular ({w}): no standard error, no t-test"),
                }
            );
        }
        let _ = writeln!(
            s,
            "| coefficient | unit | published | refit | std. error | 95 % CI | t-test p vs published | bootstrap SD | note |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|---|---:|---:|---|");
        for c in &r.coefficients {
            // The cell's parts are separate statements: joined with "; " (a bare concatenation
            // once read "no standard error**bound active**").
            let mut parts: Vec<String> = Vec::new();
            if let Some(h) = &c.held {
                parts.push(h.clone());
            }
            // A flag the held note already starts with is not said twice.
            if let Some(f) = c
                .flag
                .as_ref()
                .filter(|f| !c.held.as_ref().is_some_and(|h| h.starts_with(f.as_str())))
            {
                parts.push(format!("**{f}**"));
            }
            if let Some(b) = c.ci95_bootstrap {
                parts.push(format!("boot [{}, {}]", g(b[0]), g(b[1])));
            }
            if let Some(sc) = c.std_error_conditional {
                parts.push(format!("conditional on the breakpoints: SE {}", g(sc)));
            }
            let note = parts.join("; ");
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} | {} | [{}, {}] | {} | {} | {} |",
                c.name,
                c.unit,
                c.published.map_or("—".into(), g),
                g(c.value),
                c.std_error.map_or("—".into(), g),
                go(c.ci95[0]),
                go(c.ci95[1]),
                c.t_test
                    .as_ref()
                    .and_then(|t| t.p_value)
                    .map_or("—".into(), |p| format!("{p:.3}")),
                c.se_bootstrap.map_or("—".into(), g),
                note.replace('|', "/")
            );
        }
        if !r.derived.is_empty() {
            let _ = writeln!(
                s,
                "\n| derived | {} | refit |\n|---|---:|---:|",
                if reference.is_some() {
                    "reference (see above)"
                } else {
                    "published"
                }
            );
            for d in &r.derived {
                let _ = writeln!(
                    s,
                    "| {} ({}) | {} | {} |",
                    d.name,
                    d.unit,
                    g(d.published),
                    g(d.value)
                );
            }
        }
        if let Some(rb) = &r.robust {
            let _ = writeln!(
                s,
                "\nHuber robust refit (k = {}, scale {}, {} rows down-weighted, {} iterations{}): {}.",
                rb.k,
                g(rb.scale),
                rb.rows_downweighted,
                rb.iterations,
                if rb.converged { "" } else { ", NOT converged" },
                rb.coefficients
                    .iter()
                    .map(|c| format!("{} = {}", c.name, g(c.value)))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        if let Some(w) = &r.weights {
            let _ = writeln!(s, "\nWeighted by column `{w}`.");
        }
        let _ = writeln!(
            s,
            "\nValid range of the data: {}.",
            r.valid_range
                .iter()
                .map(|v| format!("{} ∈ [{}, {}] {}", v.input, g(v.lo), g(v.hi), v.unit))
                .collect::<Vec<_>>()
                .join("; ")
        );
        let _ = writeln!(
            s,
            "\nData: `{}` (sha256 `{}`): {} rows used, {} rejected, {} of the other gait.",
            r.data.path,
            &r.data.sha256[..r.data.sha256.len().min(16)],
            r.data.rows_used,
            r.data.rows_rejected,
            r.data.rows_other_gait
        );
        for rej in &r.data.rejected {
            let _ = writeln!(
                s,
                "- rejected {}: {} (e.g. {})",
                rej.count,
                rej.reason,
                rej.examples
                    .iter()
                    .take(3)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        if !r.notes.is_empty() {
            let _ = writeln!(s, "\nNotes:");
            for n in &r.notes {
                let _ = writeln!(s, "- {n}");
            }
        }
        if let Some(figs) = figures.get(&r.relation) {
            write_figures(&mut s, figs);
        }
    }
    s
}

/// The plots of one relation: each image with a caption saying what it shows and what of the
/// data is drawn (all rows, or their density).
fn write_figures(s: &mut String, figs: &[Figure]) {
    let _ = writeln!(s, "\nPlots (SVG; a PNG of each beside it):");
    for f in figs {
        let _ = writeln!(
            s,
            "\n![{stem}]({stem}.svg)\n\n*`{stem}.svg`: {}. Drawn: {}.*",
            f.shows,
            f.drawn,
            stem = f.stem
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn committed(relation: &str) -> FitRecord {
        let path = format!("{}/fits/{relation}.json", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).expect("committed fit record");
        serde_json::from_str(&text).expect("a fit record")
    }

    #[test]
    fn coverage_is_quoted_from_the_study_only_for_the_design_it_simulated() {
        let study: serde_json::Value = serde_json::from_str(COVERAGE_JSON).unwrap();
        let mut rec = committed("walk-sl-sf");
        rec.n = study["walk-sl-sf"]["n"].as_u64().unwrap() as usize;
        if let Some(i) = rec.inference.as_mut() {
            i.clusters = study["walk-sl-sf"]["clusters"].as_u64().unwrap() as usize;
        }
        let cr1 = 100.0 * study["walk-sl-sf"]["coverage"]["cr1"][0].as_f64().unwrap();
        let s = coverage_sentence(std::slice::from_ref(&rec));
        assert!(s.contains(&format!("walk-sl-sf k — CR1 {cr1:.1} %")), "{s}");
        assert!(!s.contains("re-run"), "{s}");

        rec.n += 1;
        let s = coverage_sentence(std::slice::from_ref(&rec));
        assert!(!s.contains("CR1"), "{s}");
        assert!(s.contains("re-run tools/reference/coverage.py"), "{s}");
    }
}
