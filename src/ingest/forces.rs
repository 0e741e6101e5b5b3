//! Cortex `.forces` force-plate exports (`bmclab/walk1.forces`).
//!
//! Layout:
//! ```text
//! [Force Data]
//! NumberOfForcePlates=7
//! SampleRate=450.000000
//! NumberOfSamples=1092
//! #Sample  FX1  FY1  FZ1  X1  Y1  Z1  MZ1  FX2 …
//! 1        0.00 …
//! ```
//! Decisions:
//! - Units are Cortex's, which the file does not state: force N, centre of pressure mm, `MZ`
//!   N·mm; converted to N, m, N·m. `MZ` is the free moment about the plate's normal, i.e. the
//!   vertical.
//! - Sample `k` is at time (k − 1)/SampleRate, on the clock of the same-named `.trc` (Cortex
//!   records both from frame 1).
//! - The number of data rows must equal `NumberOfSamples` (else the file is truncated or
//!   corrupt: error), sample numbers must increase, every cell must be finite.
//! - Cortex writes the plate centre as COP while a plate is unloaded; the COP is `NaN` while the
//!   vertical force is below [`ReadOptions::cop_min_force_n`].
use super::frame_detect;
use super::text;
use super::types::{ForcePlate, Trial};
use super::{finish, IngestError, ReadOptions};
use std::path::Path;

/// Reads a `.forces` file into a trial of force plates only.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let (plates, notes) = read_plates(path, opts)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name);
    trial.plates = plates;
    trial.notes = notes;
    finish(&mut trial, opts, None);
    Ok(trial)
}

/// Reads the plates of a `.forces` file, with notes.
pub fn read_plates(
    path: &Path,
    opts: &ReadOptions,
) -> Result<(Vec<ForcePlate>, Vec<String>), IngestError> {
    let bytes = text::read_bytes(path)?;
    parse_plates(&bytes, path, opts)
}

/// [`read_plates`] on bytes in memory.
pub fn parse_plates(
    bytes: &[u8],
    path: &Path,
    opts: &ReadOptions,
) -> Result<(Vec<ForcePlate>, Vec<String>), IngestError> {
    let mut it = text::lines(bytes);
    let (_, first) = it
        .next()
        .ok_or_else(|| IngestError::malformed(path, "empty file"))?;
    if text::trim(first) != b"[Force Data]" {
        return Err(IngestError::malformed(
            path,
            "line 1: a Cortex .forces file starts with [Force Data]",
        ));
    }
    let mut keys: Vec<(String, String, usize)> = Vec::new();
    let mut names_line = None;
    for (ln, line) in it.by_ref() {
        let t = text::text(line);
        if t.starts_with('#') {
            names_line = Some((ln, line));
            break;
        }
        if let Some((k, v)) = t.split_once('=') {
            keys.push((k.trim().to_string(), v.trim().to_string(), ln));
        }
    }
    let Some((nl, names_line)) = names_line else {
        return Err(IngestError::malformed(
            path,
            "no column-name line (#Sample FX1 FY1 …) after the header",
        ));
    };
    let key = |k: &str| -> Result<(f64, usize), IngestError> {
        let (_, v, ln) = keys
            .iter()
            .find(|(kk, _, _)| kk.eq_ignore_ascii_case(k))
            .ok_or_else(|| IngestError::MissingColumn {
                path: path.to_path_buf(),
                column: k.to_string(),
                message: "the [Force Data] header must give NumberOfForcePlates, SampleRate \
                              and NumberOfSamples"
                    .to_string(),
            })?;
        Ok((text::finite(v.as_bytes(), path, *ln, k)?, *ln))
    };
    let (nplates, pl) = key("NumberOfForcePlates")?;
    let (rate, rl) = key("SampleRate")?;
    let (nsamples, sl) = key("NumberOfSamples")?;
    for (v, ln, k) in [
        (nplates, pl, "NumberOfForcePlates"),
        (nsamples, sl, "NumberOfSamples"),
    ] {
        if v < 0.0 || v.fract() != 0.0 {
            return Err(IngestError::cell(
                path,
                ln,
                k,
                format!("{v} is not a whole number"),
            ));
        }
    }
    if rate <= 0.0 {
        return Err(IngestError::cell(
            path,
            rl,
            "SampleRate",
            "the rate must be positive",
        ));
    }
    let (nplates, nsamples) = (nplates as usize, nsamples as usize);
    let names: Vec<String> = text::cells(names_line, b'\t').map(text::text).collect();
    let col = |n: &str| names.iter().position(|x| x.eq_ignore_ascii_case(n));
    let mut idx = Vec::with_capacity(nplates);
    for p in 1..=nplates {
        let mut c = [0usize; 7];
        for (j, base) in ["FX", "FY", "FZ", "X", "Y", "Z", "MZ"].iter().enumerate() {
            let n = format!("{base}{p}");
            c[j] = col(&n).ok_or_else(|| IngestError::MissingColumn {
                path: path.to_path_buf(),
                column: n.clone(),
                message: format!(
                    "line {nl}: NumberOfForcePlates = {nplates} needs FX, FY, FZ, X, Y, Z, MZ \
                     for each plate"
                ),
            })?;
        }
        idx.push(c);
    }
    let ncol = names.len();
    let mut data: Vec<Vec<f64>> = (0..ncol).map(|_| Vec::with_capacity(nsamples)).collect();
    let mut lines_of = Vec::with_capacity(nsamples);
    let mut row = Vec::with_capacity(ncol);
    for (ln, line) in it {
        if text::is_blank(line) {
            continue;
        }
        text::numeric_row(line, b'\t', ncol, &mut row)
            .map_err(|e| e.into_ingest(path, ln, line, b'\t', &names))?;
        for (d, v) in data.iter_mut().zip(&row) {
            d.push(*v);
        }
        lines_of.push(ln);
    }
    let rows = lines_of.len();
    if rows != nsamples {
        return Err(IngestError::malformed(
            path,
            format!(
                "NumberOfSamples = {nsamples} (line {sl}) but {rows} data rows: the file is \
                 truncated or corrupt"
            ),
        ));
    }
    text::check_time(&data[0], &lines_of, path, &names[0])?;
    let time: Vec<f64> = data[0].iter().map(|s| (s - 1.0) / rate).collect();
    let mut plates: Vec<ForcePlate> = idx
        .iter()
        .enumerate()
        .map(|(i, c)| ForcePlate {
            name: format!("FP{}", i + 1),
            rate_hz: rate,
            time_s: time.clone(),
            force_n: (0..rows)
                .map(|s| [data[c[0]][s], data[c[1]][s], data[c[2]][s]])
                .collect(),
            cop_m: (0..rows)
                .map(|s| {
                    [
                        data[c[3]][s] * 1e-3,
                        data[c[4]][s] * 1e-3,
                        data[c[5]][s] * 1e-3,
                    ]
                })
                .collect(),
            free_moment_nm: data[c[6]].iter().map(|m| m * 1e-3).collect(),
            side: None,
        })
        .collect();
    let vertical = opts
        .vertical
        .map(|axis| frame_detect::Direction {
            axis,
            sign: 1.0,
            how: String::new(),
        })
        .or_else(|| frame_detect::vertical_from_plates(&plates));
    let mut loaded = Vec::new();
    if let Some(v) = &vertical {
        let k = v.axis.index();
        for p in &mut plates {
            let mut any = false;
            for (f, c) in p.force_n.iter().zip(p.cop_m.iter_mut()) {
                if v.sign * f[k] < opts.cop_min_force_n {
                    *c = [f64::NAN; 3];
                } else {
                    any = true;
                }
            }
            if any {
                loaded.push(p.name.clone());
            }
        }
    }
    let notes = vec![format!(
        ".forces: {nplates} plates at {rate} Hz, {rows} samples from {}; units N, COP mm → m, \
         MZ N·mm → N·m (Cortex convention, not stated in the file); loaded plates: {}",
        path.display(),
        if loaded.is_empty() {
            "none".to_string()
        } else {
            loaded.join(", ")
        }
    )];
    Ok((plates, notes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(n_declared: usize, rows: usize) -> String {
        let mut s = format!(
            "[Force Data]\r\nNumberOfForcePlates=1\r\nSampleRate=450.000000\r\n\
             NumberOfSamples={n_declared}\r\n#Sample\tFX1\tFY1\tFZ1\tX1\tY1\tZ1\tMZ1\r\n"
        );
        for i in 1..=rows {
            let fy = if i % 2 == 0 { 600.0 } else { 0.0 };
            s.push_str(&format!(
                "{i}\t1.0\t{fy}\t-2.0\t2149.0\t0.0\t976.7\t-4000.0\r\n"
            ));
        }
        s
    }

    #[test]
    fn reads_si_and_masks_unloaded_cop() {
        let (p, notes) = parse_plates(
            file(4, 4).as_bytes(),
            Path::new("w.forces"),
            &ReadOptions::default(),
        )
        .unwrap();
        assert_eq!(p.len(), 1);
        assert!((p[0].time_s[1] - 1.0 / 450.0).abs() < 1e-15);
        assert!(p[0].cop_m[0][0].is_nan());
        assert!((p[0].cop_m[1][0] - 2.149).abs() < 1e-12);
        assert!((p[0].free_moment_nm[1] + 4.0).abs() < 1e-12);
        assert!(notes[0].contains("FP1"));
    }

    #[test]
    fn sample_count_must_match() {
        let e = parse_plates(
            file(5, 4).as_bytes(),
            Path::new("w.forces"),
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("NumberOfSamples = 5") && e.contains("4 data rows"),
            "{e}"
        );
        let e = parse_plates(
            file(3, 4).as_bytes(),
            Path::new("w.forces"),
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("NumberOfSamples = 3"), "{e}");
    }
}
