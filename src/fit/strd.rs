//! Reader for NIST Statistical Reference Datasets (StRD) `.dat` files, linear (LLS) and
//! nonlinear (NLS) regression, used by the golden tests of the fitting layer.
//!
//! The header's "Certified Values (lines a to b)" and "Data (lines a to b)" give 1-based line
//! ranges, which this reader trusts (they are reliable in every StRD file). CRLF and LF line
//! endings are accepted; blank or whitespace-only lines inside the data range (Norris.dat ends
//! with one) are skipped, and the number of data rows is checked against the header's
//! "N Observations".
use std::path::Path;

use super::FitError;

/// One certified parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct CertifiedParameter {
    /// Name as NIST spells it (`B0`, `b1`, …).
    pub name: String,
    /// Certified estimate.
    pub value: f64,
    /// Certified standard deviation of the estimate.
    pub std_dev: f64,
    /// NIST starting values (NLS only): start 1 and start 2.
    pub starts: Option<[f64; 2]>,
}

/// Which StRD procedure a file certifies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrdKind {
    /// Linear least squares regression.
    Linear,
    /// Nonlinear least squares regression.
    Nonlinear,
}

/// A parsed StRD file.
#[derive(Debug, Clone, PartialEq)]
pub struct StrdDataset {
    /// Data set name (`Norris`, `Misra1a`, …).
    pub name: String,
    /// Linear or nonlinear.
    pub kind: StrdKind,
    /// The model line(s) of the header, verbatim (e.g. `y = B0 + B1*x + e`).
    pub model: String,
    /// Certified parameters, in file order.
    pub parameters: Vec<CertifiedParameter>,
    /// Certified residual standard deviation.
    pub residual_sd: f64,
    /// Certified R² (LLS only).
    pub r_squared: Option<f64>,
    /// Certified residual sum of squares (NLS; for LLS from the ANOVA table when present).
    pub rss: Option<f64>,
    /// Degrees of freedom as printed in the file (NLS; Rat43 prints 9 although n − p = 11).
    pub df: Option<usize>,
    /// Number of observations stated in the header.
    pub n_obs: usize,
    /// Column names of the data block (`y`, `x`, `x1`, …).
    pub columns: Vec<String>,
    /// Data rows, one `Vec` per observation, in column order.
    pub rows: Vec<Vec<f64>>,
}

impl StrdDataset {
    /// The values of column `name` (e.g. `"y"`), or `None` if there is no such column.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self
            .columns
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))?;
        Some(self.rows.iter().map(|r| r[j]).collect())
    }

    /// Certified estimates, in parameter order.
    pub fn certified_values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// NIST starting values `k` (1 or 2) for NLS sets.
    pub fn start(&self, k: usize) -> Option<Vec<f64>> {
        if !(1..=2).contains(&k) {
            return None;
        }
        self.parameters
            .iter()
            .map(|p| p.starts.map(|s| s[k - 1]))
            .collect()
    }
}

/// Reads and parses a StRD file.
pub fn read(path: &Path) -> Result<StrdDataset, FitError> {
    let text = std::fs::read_to_string(path).map_err(|e| FitError::Strd {
        file: path.display().to_string(),
        line: 0,
        message: format!("cannot read: {e}"),
    })?;
    parse(&text, &path.display().to_string())
}

fn number(tok: &str) -> Option<f64> {
    // Fortran-style exponents use E or D; both parse once D is mapped to E.
    tok.replace(['D', 'd'], "E").parse::<f64>().ok()
}

/// Parses the text of a StRD file; `file` names it in error messages.
pub fn parse(text: &str, file: &str) -> Result<StrdDataset, FitError> {
    let lines: Vec<&str> = text.lines().map(|l| l.trim_end_matches('\r')).collect();
    let err = |line: usize, message: String| FitError::Strd {
        file: file.to_string(),
        line,
        message,
    };
    let range_of = |label: &str| -> Result<(usize, usize), FitError> {
        for (i, l) in lines.iter().enumerate().take(20) {
            let t = l.trim_start();
            if let Some(rest) = t
                .strip_prefix(label)
                .filter(|r| r.trim_start().starts_with("(lines"))
            {
                let nums: Vec<usize> = rest
                    .split(|c: char| !c.is_ascii_digit())
                    .filter(|s| !s.is_empty())
                    .filter_map(|s| s.parse().ok())
                    .collect();
                if nums.len() == 2 && nums[0] >= 1 && nums[0] <= nums[1] && nums[1] <= lines.len() {
                    return Ok((nums[0], nums[1]));
                }
                return Err(err(i + 1, format!("cannot read the line range in {t:?}")));
            }
        }
        Err(err(
            0,
            format!("no \"{label} (lines a to b)\" in the header"),
        ))
    };

    let name = lines
        .iter()
        .find_map(|l| l.trim_start().strip_prefix("Dataset Name:"))
        .and_then(|r| r.split_whitespace().next())
        .ok_or_else(|| err(0, "no \"Dataset Name:\" line".into()))?
        .to_string();
    let kind = if lines.iter().any(|l| l.contains("Nonlinear Least Squares")) {
        StrdKind::Nonlinear
    } else if lines.iter().any(|l| l.contains("Linear Least Squares")) {
        StrdKind::Linear
    } else {
        return Err(err(
            0,
            "no \"Procedure:\" line naming the regression type".into(),
        ));
    };
    let (c0, c1) = range_of("Certified Values")?;
    let (d0, d1) = range_of("Data")?;

    let n_obs = lines
        .iter()
        .take(c0)
        .find_map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            (t.len() == 2 && t[1] == "Observations")
                .then(|| t[0].parse::<usize>().ok())
                .flatten()
        })
        .ok_or_else(|| err(0, "no \"N Observations\" line in the header".into()))?;

    let model = {
        let start = lines.iter().position(|l| l.starts_with("Model:"));
        match start {
            Some(s) => lines[s..c0.saturating_sub(1).max(s)]
                .iter()
                .filter(|l| l.contains('='))
                .map(|l| l.trim())
                .collect::<Vec<_>>()
                .join(" "),
            None => String::new(),
        }
    };

    let mut parameters = Vec::new();
    let mut residual_sd = None;
    let mut r_squared = None;
    let mut rss = None;
    let mut df = None;
    let cert = &lines[c0 - 1..c1];
    let mut pending_residual = false;
    for (k, l) in cert.iter().enumerate() {
        let lineno = c0 + k;
        let toks: Vec<&str> = l.split_whitespace().collect();
        if toks.is_empty() {
            continue;
        }
        let is_param_name = |s: &str| {
            let mut ch = s.chars();
            matches!(ch.next(), Some('b' | 'B'))
                && ch.clone().count() > 0
                && ch.all(|c| c.is_ascii_digit())
        };
        match kind {
            StrdKind::Linear => {
                if is_param_name(toks[0]) && toks.len() == 3 {
                    let (v, s) = (number(toks[1]), number(toks[2]));
                    match (v, s) {
                        (Some(value), Some(std_dev)) => parameters.push(CertifiedParameter {
                            name: toks[0].to_string(),
                            value,
                            std_dev,
                            starts: None,
                        }),
                        _ => return Err(err(lineno, format!("cannot read parameter line {l:?}"))),
                    }
                } else if toks[0] == "Residual" && toks.len() == 1 {
                    pending_residual = true;
                } else if l.contains("Standard Deviation") && pending_residual {
                    residual_sd = toks.last().and_then(|t| number(t));
                    pending_residual = false;
                } else if toks[0] == "R-Squared" {
                    r_squared = toks.get(1).and_then(|t| number(t));
                } else if toks[0] == "Residual" && toks.len() >= 4 {
                    // ANOVA row: Residual df SS MS
                    rss = number(toks[2]);
                    df = toks[1].parse().ok();
                }
            }
            StrdKind::Nonlinear => {
                if is_param_name(toks[0]) && toks.get(1) == Some(&"=") {
                    let nums: Vec<f64> = toks[2..].iter().filter_map(|t| number(t)).collect();
                    if nums.len() != 4 || toks.len() != 6 {
                        return Err(err(
                            lineno,
                            format!("expected start1 start2 estimate sd in {l:?}"),
                        ));
                    }
                    parameters.push(CertifiedParameter {
                        name: toks[0].to_string(),
                        value: nums[2],
                        std_dev: nums[3],
                        starts: Some([nums[0], nums[1]]),
                    });
                } else if l.contains("Residual Sum of Squares:") {
                    rss = toks.last().and_then(|t| number(t));
                } else if l.contains("Residual Standard Deviation:") {
                    residual_sd = toks.last().and_then(|t| number(t));
                } else if l.contains("Degrees of Freedom:") {
                    df = toks.last().and_then(|t| t.parse().ok());
                }
            }
        }
    }
    if parameters.is_empty() {
        return Err(err(
            c0,
            "no certified parameters in the certified-values lines".into(),
        ));
    }
    let residual_sd =
        residual_sd.ok_or_else(|| err(c0, "no certified residual standard deviation".into()))?;
    if kind == StrdKind::Linear && r_squared.is_none() {
        return Err(err(c0, "no certified R-Squared".into()));
    }

    let header_line = lines[..d0 - 1]
        .iter()
        .rposition(|l| l.trim_start().starts_with("Data:"))
        .ok_or_else(|| {
            err(
                d0,
                "no \"Data:\" column header before the data lines".into(),
            )
        })?;
    let columns: Vec<String> = lines[header_line]
        .trim_start()
        .trim_start_matches("Data:")
        .split_whitespace()
        .map(str::to_string)
        .collect();
    let mut rows = Vec::with_capacity(n_obs);
    for (k, l) in lines[d0 - 1..d1].iter().enumerate() {
        if l.trim().is_empty() {
            continue;
        }
        let row: Option<Vec<f64>> = l.split_whitespace().map(number).collect();
        match row {
            Some(r) if r.len() == columns.len() => rows.push(r),
            _ => {
                return Err(err(
                    d0 + k,
                    format!(
                        "expected {} numbers ({:?}), found {l:?}",
                        columns.len(),
                        columns
                    ),
                ))
            }
        }
    }
    if rows.len() != n_obs {
        return Err(err(
            d0,
            format!(
                "header says {n_obs} observations, data lines hold {}",
                rows.len()
            ),
        ));
    }
    Ok(StrdDataset {
        name,
        kind,
        model,
        parameters,
        residual_sd,
        r_squared,
        rss,
        df,
        n_obs,
        columns,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINI_NLS: &str = "NIST/ITL StRD\r\nDataset Name:  Tiny   (Tiny.dat)\r\n\r\nFile Format:   ASCII\r\n               Starting Values   (lines 10 to 11)\r\n               Certified Values  (lines 10 to 14)\r\n               Data              (lines 17 to 19)\r\nProcedure:     Nonlinear Least Squares Regression\r\n               3 Observations\r\n  b1 =   1     2      3.0E+00  1.0E-01\r\n  b2 =   0.5   0.25   2.0E-01  1.0E-02\r\nResidual Sum of Squares:                    1.0E-02\r\nResidual Standard Deviation:                1.0E-01\r\nDegrees of Freedom:                                1\r\n\r\nData:   y    x\r\n  1.0  2.0\r\n  3.0  4.0\r\n  5.0E0  6.0\r\n";

    #[test]
    fn parses_crlf_nls() {
        let d = parse(MINI_NLS, "Tiny.dat").unwrap();
        assert_eq!(d.name, "Tiny");
        assert_eq!(d.kind, StrdKind::Nonlinear);
        assert_eq!(d.parameters.len(), 2);
        assert_eq!(d.start(1), Some(vec![1.0, 0.5]));
        assert_eq!(d.start(2), Some(vec![2.0, 0.25]));
        assert_eq!(d.certified_values(), vec![3.0, 0.2]);
        assert_eq!(d.rss, Some(0.01));
        assert_eq!(d.df, Some(1));
        assert_eq!(d.column("x"), Some(vec![2.0, 4.0, 6.0]));
        // LF works identically.
        let lf = MINI_NLS.replace("\r\n", "\n");
        assert_eq!(parse(&lf, "Tiny.dat").unwrap(), d);
    }

    #[test]
    fn reports_bad_rows_with_line_numbers() {
        let bad = MINI_NLS.replace("  3.0  4.0", "  3.0  x4");
        match parse(&bad, "Tiny.dat") {
            Err(FitError::Strd { line, .. }) => assert_eq!(line, 18),
            other => panic!("expected a Strd error, got {other:?}"),
        }
        let short = MINI_NLS.replace(
            "               3 Observations",
            "               4 Observations",
        );
        assert!(parse(&short, "Tiny.dat").is_err());
    }
}
