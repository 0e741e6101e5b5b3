//! C3D files (`schreiber2019/*/dynamic/*.c3d`, `bmclab/Gait.c3d`): markers, analog channels,
//! force platforms, the EVENT group and subject parameters.
//!
//! Why not the `c3dio` crate: version 0.8 was tried first on the shared files. It reads markers
//! and analog data, but returns every event time of the Schreiber files as 0, removes the
//! parameters it interprets from the parameter tree (SUBJECT survives, FORCE_PLATFORM and
//! EVENT do not), and computes forces at the marker rate in the plate's own frame with a 2-D
//! COP. What gaitfit needs (lab-frame GRF at the analog rate, COP in the lab, events, subject
//! parameters) would have been rewritten anyway, so this module reads the format directly
//! (C3D User Guide, c3d.org):
//! - header block (512 bytes): parameter block, 0x50 key, points, analog values per frame,
//!   first/last frame, scale factor (negative → float data), data block, frame rate;
//! - parameter section: processor type (84 Intel, 85 DEC, 86 MIPS), then group and parameter
//!   records (char/byte/int16/float, up to 7 dimensions, first dimension fastest);
//! - data section: per frame, X Y Z and a residual word per point (residual < 0 → invalid),
//!   then the analog samples interleaved by channel; analog = (raw − OFFSET)·SCALE·GEN_SCALE.
//!
//! Numbers: Intel is IEEE little-endian; MIPS is IEEE big-endian (integers too); DEC stores
//! VAX F-floats (16-bit words swapped, exponent bias 2 higher: swap and divide by 4) with
//! little-endian integers. `Gait.c3d` is DEC with integer data, the Schreiber files Intel with
//! float data.
//!
//! Force platforms: see `c3d/plates.rs` ([`force_plates`]).
//!
//! Events: EVENT:TIMES (minutes, seconds) relative to the first frame of the original capture;
//! the trial's time 0 is the file's first frame, so t = 60·min + s − (first − 1)/rate.
//! Labels containing "strike" (Foot Strike) become heel strikes and "off" (Foot Off) toe offs;
//! the context gives the side. Subject parameters: a SUBJECT group of LABELS/VALUES/UNITS
//! (Schreiber: height m, weight kg, R_legLength/L_legLength m), or Vicon's PROCESSING group
//! (Height, Bodymass, LLegLength, RLegLength in mm), or SUBJECT:HEIGHT/WEIGHT/MASS.
//!
//! Not supported (error or note): header-only events (the 18 header event slots), files with
//! more than 65535 frames stored only in TRIAL:ACTUAL_END_FIELD beyond what the header says,
//! force platform type 5–7, POINT:LABELS2 for more than 255 markers (read when present).
mod plates;

use super::frame_detect;
use super::text;
use super::types::{MarkerSet, Trial};
use super::{finish, IngestError, ReadOptions};
use crate::gait::{EventKind, EventSource, Gait, GaitEvent, Side};
pub use plates::force_plates;
use std::collections::HashMap;
use std::path::Path;

/// The processor (number format) of a C3D file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Processor {
    /// Intel: IEEE little-endian.
    Intel,
    /// DEC: VAX floats, little-endian integers.
    Dec,
    /// MIPS/SGI: IEEE big-endian.
    Mips,
}

impl Processor {
    fn i16(self, b: [u8; 2]) -> i16 {
        match self {
            Processor::Mips => i16::from_be_bytes(b),
            _ => i16::from_le_bytes(b),
        }
    }
    fn u16(self, b: [u8; 2]) -> u16 {
        self.i16(b) as u16
    }
    fn f32(self, b: [u8; 4]) -> f32 {
        match self {
            Processor::Intel => f32::from_le_bytes(b),
            Processor::Mips => f32::from_be_bytes(b),
            Processor::Dec => {
                let u = u32::from_le_bytes(b);
                f32::from_bits(u.rotate_left(16)) / 4.0
            }
        }
    }
}

/// The value of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// Character data, split along the first dimension into strings (trailing spaces trimmed).
    Text(Vec<String>),
    /// Bytes.
    Bytes(Vec<u8>),
    /// 16-bit integers.
    Ints(Vec<i16>),
    /// Floats.
    Floats(Vec<f32>),
}

/// One parameter: dimensions (first fastest) and value.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Dimensions as stored.
    pub dims: Vec<usize>,
    /// Value.
    pub value: ParamValue,
}

impl Param {
    /// Numbers as `f64` (integers as signed; bytes as unsigned); `None` for text. Floats are
    /// widened through their shortest decimal form (a stored 73.8f32 gives 73.8, not
    /// 73.80000305).
    pub fn numbers(&self) -> Option<Vec<f64>> {
        match &self.value {
            ParamValue::Ints(v) => Some(v.iter().map(|&x| f64::from(x)).collect()),
            ParamValue::Floats(v) => Some(
                v.iter()
                    .map(|&x| x.to_string().parse::<f64>().unwrap_or(f64::from(x)))
                    .collect(),
            ),
            ParamValue::Bytes(v) => Some(v.iter().map(|&x| f64::from(x)).collect()),
            ParamValue::Text(_) => None,
        }
    }
    /// Integers read as unsigned 16-bit (counts and frame numbers above 32767).
    pub fn unsigned(&self) -> Option<Vec<f64>> {
        match &self.value {
            ParamValue::Ints(v) => Some(v.iter().map(|&x| f64::from(x as u16)).collect()),
            _ => self.numbers(),
        }
    }
    /// Strings; `None` for numbers.
    pub fn strings(&self) -> Option<&[String]> {
        match &self.value {
            ParamValue::Text(v) => Some(v),
            _ => None,
        }
    }
}

/// A C3D file as read: header, parameters, markers and analog channels in file units converted
/// to SI where the file says how (markers → m).
#[derive(Debug, Clone, PartialEq)]
pub struct C3dFile {
    /// Number format.
    pub processor: Processor,
    /// True when the data section holds floats (negative POINT:SCALE).
    pub float_data: bool,
    /// POINT:SCALE (header scale factor when the parameter is absent).
    pub point_scale: f64,
    /// First frame number (header).
    pub first_frame: usize,
    /// Marker rate, Hz (POINT:RATE, else the header).
    pub point_rate_hz: f64,
    /// Analog rate, Hz (ANALOG:RATE; 0 without analog data).
    pub analog_rate_hz: f64,
    /// Parameters by group and name (upper case).
    pub params: HashMap<String, HashMap<String, Param>>,
    /// Markers (metres, NaN where the residual marks a sample invalid).
    pub markers: MarkerSet,
    /// POINT:UNITS as written.
    pub point_units: String,
    /// Analog channel labels.
    pub analog_labels: Vec<String>,
    /// Analog channel units as written (`N`, `Nmm`, `V`, …).
    pub analog_units: Vec<String>,
    /// `analog[channel][sample]`, scaled (offset, SCALE, GEN_SCALE applied), file units.
    pub analog: Vec<Vec<f64>>,
}

impl C3dFile {
    /// The parameter `group:name` (case-insensitive).
    pub fn param(&self, group: &str, name: &str) -> Option<&Param> {
        self.params
            .get(&group.to_ascii_uppercase())?
            .get(&name.to_ascii_uppercase())
    }
    fn numbers(&self, group: &str, name: &str) -> Option<Vec<f64>> {
        self.param(group, name)?.numbers()
    }
    fn strings(&self, group: &str, name: &str) -> Option<Vec<String>> {
        self.param(group, name)?.strings().map(|s| s.to_vec())
    }
}

struct Bytes<'a> {
    b: &'a [u8],
    path: &'a Path,
}

impl<'a> Bytes<'a> {
    fn get(&self, at: usize, n: usize, what: &str) -> Result<&'a [u8], IngestError> {
        self.b.get(at..at + n).ok_or_else(|| {
            IngestError::malformed(
                self.path,
                format!(
                    "byte {at}: the file ends inside the {what} ({} bytes): truncated or not a \
                     C3D file",
                    self.b.len()
                ),
            )
        })
    }
    fn u8(&self, at: usize, what: &str) -> Result<u8, IngestError> {
        Ok(self.get(at, 1, what)?[0])
    }
    fn two(&self, at: usize, what: &str) -> Result<[u8; 2], IngestError> {
        let s = self.get(at, 2, what)?;
        Ok([s[0], s[1]])
    }
    fn four(&self, at: usize, what: &str) -> Result<[u8; 4], IngestError> {
        let s = self.get(at, 4, what)?;
        Ok([s[0], s[1], s[2], s[3]])
    }
}

/// Reads and decodes a C3D file (no force-plate processing, no gap filling).
pub fn read_file(path: &Path) -> Result<C3dFile, IngestError> {
    let bytes = text::read_bytes(path)?;
    parse_file(&bytes, path)
}

/// [`read_file`] on bytes in memory.
pub fn parse_file(bytes: &[u8], path: &Path) -> Result<C3dFile, IngestError> {
    let b = Bytes { b: bytes, path };
    if bytes.len() < 512 {
        return Err(IngestError::malformed(
            path,
            format!(
                "{} bytes: a C3D file has at least a 512-byte header",
                bytes.len()
            ),
        ));
    }
    if bytes[1] != 0x50 {
        return Err(IngestError::malformed(
            path,
            format!(
                "header byte 2 is {:#04x}, not the C3D key 0x50: not a C3D file (or a corrupt \
                 header)",
                bytes[1]
            ),
        ));
    }
    let pblock = bytes[0] as usize;
    if pblock < 2 {
        return Err(IngestError::malformed(
            path,
            format!("header byte 1: parameter block {pblock} (must be ≥ 2): corrupt header"),
        ));
    }
    let pstart = (pblock - 1) * 512;
    let proc_byte = b.u8(pstart + 3, "parameter section header")?;
    let processor = match proc_byte {
        84 => Processor::Intel,
        85 => Processor::Dec,
        86 => Processor::Mips,
        other => {
            return Err(IngestError::malformed(
                path,
                format!(
                    "byte {}: processor type {other} (expected 84 Intel, 85 DEC or 86 MIPS): \
                     corrupt parameter section",
                    pstart + 3
                ),
            ))
        }
    };
    let p = processor;
    let hword = |w: usize| -> Result<[u8; 2], IngestError> { b.two(2 * (w - 1), "header") };
    let n_points_h = p.u16(hword(2)?) as usize;
    let analog_per_frame_h = p.u16(hword(3)?) as usize;
    let first_frame = p.u16(hword(4)?) as usize;
    let last_frame = p.u16(hword(5)?) as usize;
    let scale_h = p.f32(b.four(12, "header")?);
    let data_block_h = p.u16(hword(9)?) as usize;
    let rate_h = p.f32(b.four(20, "header")?);

    let params = parse_params(&b, pstart + 4, p)?;
    let get = |g: &str, n: &str| params.get(g).and_then(|m| m.get(n));
    let num = |g: &str, n: &str| get(g, n).and_then(|x| x.numbers());
    let unum = |g: &str, n: &str| get(g, n).and_then(|x| x.unsigned());
    let strs = |g: &str, n: &str| {
        get(g, n)
            .and_then(|x| x.strings().map(|s| s.to_vec()))
            .unwrap_or_default()
    };

    let n_points = unum("POINT", "USED")
        .and_then(|v| v.first().copied())
        .map_or(n_points_h, |v| v as usize);
    let point_scale = num("POINT", "SCALE")
        .and_then(|v| v.first().copied())
        .unwrap_or(f64::from(scale_h));
    let float_data = point_scale < 0.0 || (point_scale == 0.0 && scale_h < 0.0);
    let point_rate = num("POINT", "RATE")
        .and_then(|v| v.first().copied())
        .unwrap_or(f64::from(rate_h));
    if !(point_rate.is_finite() && point_rate > 0.0) {
        return Err(IngestError::malformed(
            path,
            format!("POINT:RATE = {point_rate}: the marker rate must be positive"),
        ));
    }
    let data_block = unum("POINT", "DATA_START")
        .and_then(|v| v.first().copied())
        .map_or(data_block_h, |v| v as usize);
    if data_block < 2 {
        return Err(IngestError::malformed(
            path,
            format!("data start block {data_block} (must be ≥ 2): corrupt header"),
        ));
    }
    let n_frames = if last_frame >= first_frame {
        last_frame - first_frame + 1
    } else {
        0
    };
    let n_frames = match unum("POINT", "FRAMES").and_then(|v| v.first().copied()) {
        Some(f) if (f as usize) > n_frames => f as usize,
        _ => n_frames,
    };
    let n_analog = unum("ANALOG", "USED")
        .and_then(|v| v.first().copied())
        .map_or(0, |v| v as usize);
    let analog_rate = num("ANALOG", "RATE")
        .and_then(|v| v.first().copied())
        .unwrap_or(0.0);
    let spf = analog_per_frame_h.checked_div(n_analog).unwrap_or(0);
    if n_analog > 0 && spf * n_analog != analog_per_frame_h {
        return Err(IngestError::malformed(
            path,
            format!(
                "header: {analog_per_frame_h} analog values per frame is not a multiple of \
                 ANALOG:USED = {n_analog}"
            ),
        ));
    }
    let word = if float_data { 4 } else { 2 };
    let frame_bytes = n_points * 4 * word + analog_per_frame_h * word;
    let dstart = (data_block - 1) * 512;
    let need = dstart + n_frames * frame_bytes;
    if bytes.len() < need {
        let whole = bytes.len().saturating_sub(dstart) / frame_bytes.max(1);
        return Err(IngestError::malformed(
            path,
            format!(
                "the data section needs {need} bytes for {n_frames} frames but the file has {}: \
                 truncated after frame {whole}",
                bytes.len()
            ),
        ));
    }
    let units = strs("POINT", "UNITS").first().cloned().unwrap_or_default();
    let to_m = if units.trim().is_empty() {
        1e-3
    } else {
        text::length_scale(&units).ok_or_else(|| IngestError::UnknownUnit {
            path: path.to_path_buf(),
            column: "POINT:UNITS".into(),
            message: format!("{units:?} is not a length unit: mm, cm or m"),
        })?
    };
    let mut labels = strs("POINT", "LABELS");
    for extra in ["LABELS2", "LABELS3", "LABELS4"] {
        labels.extend(strs("POINT", extra));
    }
    labels.truncate(n_points);
    while labels.len() < n_points {
        labels.push(format!("point{}", labels.len() + 1));
    }
    let a_labels = {
        let mut l = strs("ANALOG", "LABELS");
        l.extend(strs("ANALOG", "LABELS2"));
        l.truncate(n_analog);
        while l.len() < n_analog {
            l.push(format!("channel{}", l.len() + 1));
        }
        l
    };
    let a_units = {
        let mut u = strs("ANALOG", "UNITS");
        u.extend(strs("ANALOG", "UNITS2"));
        u.resize(n_analog, String::new());
        u
    };
    let fill = |v: Option<Vec<f64>>, d: f64| -> Vec<f64> {
        let mut v = v.unwrap_or_default();
        v.resize(n_analog, d);
        v
    };
    let a_scale = fill(num("ANALOG", "SCALE"), 1.0);
    let unsigned = strs("ANALOG", "FORMAT")
        .first()
        .is_some_and(|f| f.trim().eq_ignore_ascii_case("UNSIGNED"));
    let a_offset = if unsigned {
        fill(unum("ANALOG", "OFFSET"), 0.0)
    } else {
        fill(num("ANALOG", "OFFSET"), 0.0)
    };
    let gen_scale = num("ANALOG", "GEN_SCALE")
        .and_then(|v| v.first().copied())
        .unwrap_or(1.0);

    // Data section.
    let mut pos: Vec<Vec<[f64; 3]>> = (0..n_points)
        .map(|_| Vec::with_capacity(n_frames))
        .collect();
    let mut analog: Vec<Vec<f64>> = (0..n_analog)
        .map(|_| Vec::with_capacity(n_frames * spf))
        .collect();
    let pscale = point_scale.abs();
    for f in 0..n_frames {
        let base = dstart + f * frame_bytes;
        let fr = &bytes[base..base + frame_bytes];
        let val = |i: usize| -> f64 {
            if float_data {
                f64::from(p.f32([fr[4 * i], fr[4 * i + 1], fr[4 * i + 2], fr[4 * i + 3]]))
            } else {
                f64::from(p.i16([fr[2 * i], fr[2 * i + 1]]))
            }
        };
        for (m, traj) in pos.iter_mut().enumerate() {
            let (x, y, z, r) = (val(4 * m), val(4 * m + 1), val(4 * m + 2), val(4 * m + 3));
            let s = if float_data { to_m } else { pscale * to_m };
            // The residual word: negative → the sample is invalid.
            let invalid = if float_data {
                (r as i32 as i16) < 0 || r < 0.0
            } else {
                r < 0.0
            };
            traj.push(
                if invalid || !(x.is_finite() && y.is_finite() && z.is_finite()) {
                    [f64::NAN; 3]
                } else {
                    [x * s, y * s, z * s]
                },
            );
        }
        let a0 = 4 * n_points;
        for s in 0..spf {
            for (c, ch) in analog.iter_mut().enumerate() {
                let i = a0 + s * n_analog + c;
                let raw = if !float_data && unsigned {
                    f64::from(p.u16([fr[2 * i], fr[2 * i + 1]]))
                } else {
                    val(i)
                };
                ch.push((raw - a_offset[c]) * a_scale[c] * gen_scale);
            }
        }
    }
    let markers = MarkerSet {
        rate_hz: point_rate,
        time_s: (0..n_frames).map(|f| f as f64 / point_rate).collect(),
        names: labels,
        positions: pos,
    };
    Ok(C3dFile {
        processor,
        float_data,
        point_scale,
        first_frame,
        point_rate_hz: point_rate,
        analog_rate_hz: if n_analog > 0 { analog_rate } else { 0.0 },
        params,
        markers,
        point_units: units,
        analog_labels: a_labels,
        analog_units: a_units,
        analog,
    })
}

type Params = HashMap<String, HashMap<String, Param>>;

fn parse_params(b: &Bytes, start: usize, p: Processor) -> Result<Params, IngestError> {
    let mut groups: HashMap<i8, String> = HashMap::new();
    let mut raw: Vec<(i8, String, Param)> = Vec::new();
    let mut at = start;
    let limit = b.b.len();
    for _ in 0..100_000 {
        if at + 2 > limit {
            break;
        }
        let nchars = b.u8(at, "parameter record")? as i8;
        if nchars == 0 {
            break;
        }
        let id = b.u8(at + 1, "parameter record")? as i8;
        let n = nchars.unsigned_abs() as usize;
        let name = String::from_utf8_lossy(b.get(at + 2, n, "parameter name")?)
            .trim()
            .to_ascii_uppercase();
        let off_at = at + 2 + n;
        let next = p.i16(b.two(off_at, "parameter record")?);
        let mut q = off_at + 2;
        if id < 0 {
            groups.insert(-id, name);
        } else if id > 0 {
            let t = b.u8(q, "parameter type")? as i8;
            let nd = b.u8(q + 1, "parameter dimensions")? as usize;
            let dims: Vec<usize> = b
                .get(q + 2, nd, "parameter dimensions")?
                .iter()
                .map(|&d| d as usize)
                .collect();
            q += 2 + nd;
            let count: usize = dims
                .iter()
                .product::<usize>()
                .max(if nd == 0 { 1 } else { 0 });
            let size = t.unsigned_abs() as usize;
            let data = b.get(q, count * size, &format!("data of parameter {name}"))?;
            let value = match t {
                -1 => {
                    let len = dims.first().copied().unwrap_or(count).max(1);
                    ParamValue::Text(
                        data.chunks(len)
                            .map(|c| {
                                String::from_utf8_lossy(c)
                                    .trim_end_matches([' ', '\0'])
                                    .to_string()
                            })
                            .collect(),
                    )
                }
                1 => ParamValue::Bytes(data.to_vec()),
                2 => ParamValue::Ints(data.chunks(2).map(|c| p.i16([c[0], c[1]])).collect()),
                4 => ParamValue::Floats(
                    data.chunks(4)
                        .map(|c| p.f32([c[0], c[1], c[2], c[3]]))
                        .collect(),
                ),
                other => {
                    return Err(IngestError::malformed(
                        b.path,
                        format!(
                            "byte {q}: parameter {name} has data type {other} (expected −1, 1, \
                             2 or 4): corrupt parameter section"
                        ),
                    ))
                }
            };
            raw.push((id, name, Param { dims, value }));
        }
        if next <= 0 {
            break;
        }
        at = off_at + next as usize;
    }
    let mut out: Params = HashMap::new();
    for (id, name, param) in raw {
        let g = groups
            .get(&id)
            .cloned()
            .unwrap_or_else(|| format!("GROUP{id}"));
        out.entry(g).or_default().insert(name, param);
    }
    for g in groups.values() {
        out.entry(g.clone()).or_default();
    }
    Ok(out)
}

/// Reads a C3D file into a trial: markers, force plates (lab frame, analog rate), reference
/// events, subject parameters; short gaps filled, frame detected.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let bytes = text::read_bytes(path)?;
    parse(&bytes, path, opts)
}

/// [`read`] on bytes in memory.
pub fn parse(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let c = parse_file(bytes, path)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name);
    trial.notes.push(format!(
        "C3D: {:?} processor, {} data, {} markers × {} frames at {} Hz (POINT:UNITS {:?}, scale \
         {}), {} analog channels at {} Hz",
        c.processor,
        if c.float_data { "float" } else { "integer" },
        c.markers.names.len(),
        c.markers.len(),
        c.point_rate_hz,
        c.point_units,
        c.point_scale,
        c.analog.len(),
        c.analog_rate_hz
    ));
    // Vertical from the markers first: the plates' sign convention is checked against it.
    let up = match opts.vertical {
        Some(axis) => Some((axis, 1.0)),
        None => frame_detect::vertical_from_markers(&c.markers).map(|d| (d.axis, d.sign)),
    };
    let (plates, notes) = force_plates(&c, path, opts, up)?;
    trial.plates = plates;
    trial.notes.extend(notes);
    let (events, notes) = events(&c);
    trial.reference_events = events;
    trial.notes.extend(notes);
    subject(&c, &mut trial);
    gait_from_events(&mut trial);
    trial.markers = Some(c.markers);
    finish(&mut trial, opts, None);
    Ok(trial)
}

/// The reference events of the EVENT group, with notes.
fn events(c: &C3dFile) -> (Vec<GaitEvent>, Vec<String>) {
    let mut notes = Vec::new();
    let used = c
        .param("EVENT", "USED")
        .and_then(|p| p.unsigned())
        .and_then(|v| v.first().copied())
        .unwrap_or(0.0) as usize;
    if used == 0 {
        notes.push("C3D: no EVENT group events".to_string());
        return (Vec::new(), notes);
    }
    let times = c.numbers("EVENT", "TIMES").unwrap_or_default();
    let labels = c.strings("EVENT", "LABELS").unwrap_or_default();
    let contexts = c.strings("EVENT", "CONTEXTS").unwrap_or_default();
    let first = c
        .param("TRIAL", "ACTUAL_START_FIELD")
        .and_then(|p| p.unsigned())
        .and_then(|v| {
            let lo = *v.first()?;
            let hi = v.get(1).copied().unwrap_or(0.0);
            Some(lo + 65536.0 * hi)
        })
        .filter(|v| *v >= 1.0)
        .unwrap_or(c.first_frame.max(1) as f64);
    let t0 = (first - 1.0) / c.point_rate_hz;
    let dur = c.markers.len() as f64 / c.point_rate_hz;
    let mut out = Vec::new();
    let mut ignored = Vec::new();
    for i in 0..used {
        let (Some(min), Some(sec)) = (times.get(2 * i), times.get(2 * i + 1)) else {
            break;
        };
        // Times are f32 in the file: round to the microsecond.
        let t = ((60.0 * min + sec - t0) * 1e6).round() / 1e6;
        let label = labels.get(i).map(|s| s.trim()).unwrap_or("");
        let ctx = contexts.get(i).map(|s| s.trim()).unwrap_or("");
        let l = label.to_ascii_lowercase();
        let kind = if l.contains("strike") || l.contains("contact") {
            Some(EventKind::HeelStrike)
        } else if l.contains("off") {
            Some(EventKind::ToeOff)
        } else {
            None
        };
        match (kind, Side::parse(ctx)) {
            (Some(kind), Some(side)) => {
                if t < -0.5 / c.point_rate_hz || t > dur {
                    notes.push(format!(
                        "event {label:?} ({ctx}) at {t:.3} s lies outside the trial (0–{dur:.3} s)"
                    ));
                }
                out.push(GaitEvent {
                    time_s: t,
                    side,
                    kind,
                    source: EventSource::Reference,
                });
            }
            _ => ignored.push(format!("{label:?}/{ctx:?}")),
        }
    }
    out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    notes.push(format!(
        "C3D EVENT group: {} reference events (foot strike → heel_strike, foot off → toe_off; \
         time from the file's first frame){}",
        out.len(),
        if ignored.is_empty() {
            String::new()
        } else {
            format!("; ignored: {}", ignored.join(", "))
        }
    ));
    (out, notes)
}

/// Subject parameters (height, mass, leg length) from the groups that carry them.
fn subject(c: &C3dFile, trial: &mut Trial) {
    let s = &mut trial.subject;
    // Schreiber style: SUBJECT:LABELS / VALUES / UNITS.
    if let (Some(labels), Some(values)) = (
        c.strings("SUBJECT", "LABELS"),
        c.numbers("SUBJECT", "VALUES"),
    ) {
        let units = c.strings("SUBJECT", "UNITS").unwrap_or_default();
        let mut legs = Vec::new();
        for (i, l) in labels.iter().enumerate() {
            let Some(&v) = values.get(i) else { continue };
            let l = l.trim().to_ascii_lowercase();
            let unit = units
                .get(i)
                .map(|u| u.trim().to_string())
                .unwrap_or_default();
            let len = |v: f64| -> f64 {
                match text::length_scale(&unit) {
                    Some(sc) => v * sc,
                    None if v > 10.0 => v * 1e-3,
                    None => v,
                }
            };
            if l == "height" || l == "bodyheight" || l == "body_height" {
                s.body_height_m = Some(len(v));
            } else if l == "weight" || l == "mass" || l == "bodymass" || l == "body_mass" {
                s.mass_kg = Some(v);
            } else if l.contains("leg") {
                legs.push(len(v));
            }
        }
        if !legs.is_empty() {
            s.leg_length_m = Some(legs.iter().sum::<f64>() / legs.len() as f64);
        }
        s.notes.push(format!(
            "subject from C3D SUBJECT:LABELS/VALUES ({}){}",
            labels
                .iter()
                .zip(&values)
                .map(|(l, v)| format!("{}={v}", l.trim()))
                .collect::<Vec<_>>()
                .join(", "),
            if legs.len() > 1 {
                "; leg length = mean of the legs"
            } else {
                ""
            }
        ));
    }
    // Vicon Plug-in Gait: PROCESSING:Height, Bodymass, LLegLength, RLegLength (mm).
    let mm = |v: f64| if v > 10.0 { v * 1e-3 } else { v };
    let first = |g: &str, n: &str| c.numbers(g, n).and_then(|v| v.first().copied());
    if s.body_height_m.is_none() {
        if let Some(h) = first("PROCESSING", "Height").or_else(|| first("SUBJECT", "HEIGHT")) {
            s.body_height_m = Some(mm(h));
            s.notes
                .push("height from C3D PROCESSING:Height or SUBJECT:HEIGHT".into());
        }
    }
    if s.mass_kg.is_none() {
        if let Some(m) = first("PROCESSING", "Bodymass")
            .or_else(|| first("SUBJECT", "WEIGHT"))
            .or_else(|| first("SUBJECT", "MASS"))
        {
            s.mass_kg = Some(m);
            s.notes
                .push("mass from C3D PROCESSING:Bodymass or SUBJECT:WEIGHT/MASS".into());
        }
    }
    if s.leg_length_m.is_none() {
        let legs: Vec<f64> = ["LLegLength", "RLegLength"]
            .iter()
            .filter_map(|n| first("PROCESSING", n))
            .map(mm)
            .collect();
        if !legs.is_empty() {
            s.leg_length_m = Some(legs.iter().sum::<f64>() / legs.len() as f64);
            s.notes
                .push("leg length from C3D PROCESSING:L/RLegLength".into());
        }
    }
    if s.body_height_m.is_none() && s.mass_kg.is_none() && s.leg_length_m.is_none() {
        s.notes
            .push("the C3D file carries no subject height, mass or leg length".into());
    }
}

/// Walk or run from the reference events: after a foot strike, the other foot leaves the
/// ground later in walking (double support) and has already left it in running (flight).
fn gait_from_events(trial: &mut Trial) {
    if trial.gait.is_some() {
        return;
    }
    let ev = &trial.reference_events;
    let (mut walk, mut run) = (0, 0);
    for e in ev.iter().filter(|e| e.kind == EventKind::HeelStrike) {
        let other_off = ev
            .iter()
            .filter(|o| o.kind == EventKind::ToeOff && o.side != e.side)
            .min_by(|a, b| {
                (a.time_s - e.time_s)
                    .abs()
                    .total_cmp(&(b.time_s - e.time_s).abs())
            });
        if let Some(o) = other_off {
            if (o.time_s - e.time_s).abs() < 0.3 {
                if o.time_s > e.time_s {
                    walk += 1;
                } else {
                    run += 1;
                }
            }
        }
    }
    if walk + run > 0 {
        let g = if walk >= run { Gait::Walk } else { Gait::Run };
        trial.gait = Some(g);
        trial.notes.push(format!(
            "gait: {g} from the reference events ({walk} double-support / {run} flight pattern(s))"
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dec_floats() {
        // 1.0 in VAX F-float: bytes 0x80 0x40 0x00 0x00.
        assert_eq!(Processor::Dec.f32([0x80, 0x40, 0x00, 0x00]), 1.0);
        assert_eq!(Processor::Dec.f32([0; 4]), 0.0);
        assert_eq!(Processor::Mips.f32(1.5f32.to_be_bytes()), 1.5);
        assert_eq!(Processor::Intel.f32((-2.25f32).to_le_bytes()), -2.25);
    }

    /// A minimal C3D writer for the tests: one group POINT (USED, SCALE, RATE, DATA_START,
    /// FRAMES, UNITS, LABELS) and an EVENT group, markers only, float data.
    pub(crate) fn tiny_c3d(p: Processor, frames: &[[[f32; 3]; 2]]) -> Vec<u8> {
        let i16b = |v: i16| match p {
            Processor::Mips => v.to_be_bytes(),
            _ => v.to_le_bytes(),
        };
        let f32b = |v: f32| match p {
            Processor::Intel => v.to_le_bytes(),
            Processor::Mips => v.to_be_bytes(),
            Processor::Dec => (v * 4.0).to_bits().rotate_left(16).to_le_bytes(),
        };
        let mut h = vec![0u8; 512];
        h[0] = 2;
        h[1] = 0x50;
        h[2..4].copy_from_slice(&i16b(2));
        h[6..8].copy_from_slice(&i16b(1));
        h[8..10].copy_from_slice(&i16b(frames.len() as i16));
        h[12..16].copy_from_slice(&f32b(-1.0));
        h[16..18].copy_from_slice(&i16b(3));
        h[20..24].copy_from_slice(&f32b(100.0));
        let mut par = vec![0x01, 0x50, 1, 83 + p as u8 + 1];
        let mut rec = |id: i8, name: &str, body: Vec<u8>| {
            par.push(name.len() as u8);
            par.push(id as u8);
            par.extend(name.as_bytes());
            par.extend(i16b(2 + body.len() as i16));
            par.extend(body);
        };
        rec(-1, "POINT", vec![0]);
        rec(-2, "EVENT", vec![0]);
        let ints = |v: &[i16]| -> Vec<u8> {
            let mut b = vec![2u8, 0];
            if v.len() > 1 {
                b[1] = 1;
                b.push(v.len() as u8);
            }
            for x in v {
                b.extend(i16b(*x));
            }
            b.push(0);
            b
        };
        let floats = |v: &[f32], dims: &[u8]| -> Vec<u8> {
            let mut b = vec![4u8, dims.len() as u8];
            b.extend(dims);
            for x in v {
                b.extend(f32b(*x));
            }
            b.push(0);
            b
        };
        let chars = |v: &[&str], w: usize| -> Vec<u8> {
            let mut b = vec![0xffu8, 2, w as u8, v.len() as u8];
            for x in v {
                let mut s = x.as_bytes().to_vec();
                s.resize(w, b' ');
                b.extend(s);
            }
            b.push(0);
            b
        };
        rec(1, "USED", ints(&[2]));
        rec(1, "SCALE", floats(&[-1.0], &[]));
        rec(1, "RATE", floats(&[100.0], &[]));
        rec(1, "DATA_START", ints(&[3]));
        rec(1, "FRAMES", ints(&[frames.len() as i16]));
        rec(1, "UNITS", chars(&["mm"], 2));
        rec(1, "LABELS", chars(&["RHEE", "RASI"], 4));
        rec(2, "USED", ints(&[2]));
        rec(2, "TIMES", floats(&[0.0, 0.01, 0.0, 0.02], &[2, 2]));
        rec(2, "LABELS", chars(&["Foot Strike", "Foot Off"], 11));
        rec(2, "CONTEXTS", chars(&["Right", "Left"], 5));
        par.extend([0u8, 0, 0, 0]);
        par.resize(512, 0);
        let mut out = h;
        out.extend(par);
        for f in frames {
            for m in f {
                for v in m {
                    out.extend(f32b(*v));
                }
                out.extend(f32b(0.0));
            }
        }
        out
    }

    #[test]
    fn tiny_files_round_trip_in_every_processor_format() {
        let frames = [
            [[1.0, 2.0, 3.0], [10.0, 20.0, 900.0]],
            [[1.5, 2.5, 3.5], [11.0, 21.0, 901.0]],
            [[2.0, 3.0, 4.0], [12.0, 22.0, 902.0]],
        ];
        for p in [Processor::Intel, Processor::Dec, Processor::Mips] {
            let b = tiny_c3d(p, &frames);
            let c = parse_file(&b, Path::new("t.c3d")).unwrap();
            assert_eq!(c.processor, p);
            assert_eq!(c.markers.names, vec!["RHEE", "RASI"]);
            assert_eq!(c.markers.len(), 3);
            assert_eq!(c.point_rate_hz, 100.0);
            assert!((c.markers.positions[1][2][2] - 0.902).abs() < 1e-9, "{p:?}");
            let (ev, _) = events(&c);
            assert_eq!(ev.len(), 2);
            assert_eq!(
                (ev[0].kind, ev[0].side),
                (EventKind::HeelStrike, Side::Right)
            );
            assert_eq!((ev[1].kind, ev[1].side), (EventKind::ToeOff, Side::Left));
            assert!((ev[1].time_s - 0.02).abs() < 1e-6);
        }
    }

    #[test]
    fn truncated_data_is_an_error() {
        let frames = [[[1.0, 2.0, 3.0], [10.0, 20.0, 900.0]]; 4];
        let b = tiny_c3d(Processor::Intel, &frames);
        let e = parse_file(&b[..b.len() - 10], Path::new("t.c3d"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated after frame 3"), "{e}");
        let e = parse_file(&b[..700], Path::new("t.c3d"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.c3d"), "{e}");
    }

    #[test]
    fn bad_header_is_an_error() {
        let mut b = vec![0u8; 1024];
        b[0] = 2;
        b[1] = 0x51;
        let e = parse_file(&b, Path::new("x.c3d")).unwrap_err().to_string();
        assert!(e.contains("0x51"), "{e}");
        b[1] = 0x50;
        b[512 + 3] = 99;
        let e = parse_file(&b, Path::new("x.c3d")).unwrap_err().to_string();
        assert!(e.contains("processor type 99"), "{e}");
        let e = parse_file(&b[..100], Path::new("x.c3d"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("512-byte header"), "{e}");
    }
}
