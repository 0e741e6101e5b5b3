//! Zero-phase Butterworth low-pass filtering (forward–backward, as `scipy.signal.sosfiltfilt`).
//!
//! Design: the analog Butterworth prototype of order `n` (poles on the unit circle), pre-warped
//! cutoff `ω = 2·fs·tan(π·fc/fs)`, bilinear transform, one second-order section per conjugate
//! pole pair (and one first-order section for odd orders), each normalised to unit DC gain.
//! Filtering: odd extension of `3·ntaps` samples at both ends (scipy's default padding), the
//! steady-state initial conditions of each section scaled by the first sample (scipy's
//! `sosfilt_zi`), forward pass, backward pass. The forward–backward pass squares the magnitude
//! response: the gain at the cutoff is 1/2 (−6 dB), not 1/√2; biomechanics papers that quote a
//! "4th-order zero-lag Butterworth" mean order 2 here.
//!
//! A hand-written filter rather than a crate: the maintained Rust DSP crates either lack a
//! forward–backward pass with scipy's edge handling or pull in a second linear-algebra stack.
//! The tests compare with scipy 1.17 to 1e-12.
use super::EventError;

/// One second-order section `b0 b1 b2 / 1 a1 a2` (direct form II transposed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    /// Numerator.
    pub b: [f64; 3],
    /// Denominator (`a[0]` is 1).
    pub a: [f64; 3],
}

impl Biquad {
    /// DC gain `Σb / Σa`.
    fn dc_gain(&self) -> f64 {
        (self.b[0] + self.b[1] + self.b[2]) / (self.a[0] + self.a[1] + self.a[2])
    }
    /// The state `[z0, z1]` that a unit step input holds in steady state.
    fn step_state(&self) -> [f64; 2] {
        let g = self.dc_gain();
        [
            self.b[1] + self.b[2] - g * (self.a[1] + self.a[2]),
            self.b[2] - g * self.a[2],
        ]
    }
}

/// A Butterworth low-pass filter as a cascade of second-order sections.
#[derive(Debug, Clone, PartialEq)]
pub struct Butterworth {
    order: usize,
    cutoff_hz: f64,
    rate_hz: f64,
    sections: Vec<Biquad>,
}

impl Butterworth {
    /// A low-pass Butterworth filter of `order` (1–8) with cutoff `cutoff_hz` for a signal
    /// sampled at `rate_hz`. Errors when the cutoff is not strictly between 0 and Nyquist.
    pub fn low_pass(order: usize, cutoff_hz: f64, rate_hz: f64) -> Result<Self, EventError> {
        if !(1..=8).contains(&order) {
            return Err(EventError::Options(format!(
                "Butterworth order {order}: use 1 to 8"
            )));
        }
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(EventError::Options(format!(
                "sampling rate {rate_hz} Hz is not a positive number"
            )));
        }
        if !(cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < 0.5 * rate_hz) {
            return Err(EventError::Options(format!(
                "low-pass cutoff {cutoff_hz} Hz must lie between 0 and the Nyquist frequency \
                 {} Hz of a {rate_hz} Hz signal",
                0.5 * rate_hz
            )));
        }
        let fs2 = 2.0 * rate_hz;
        let warped = fs2 * (std::f64::consts::PI * cutoff_hz / rate_hz).tan();
        let mut sections = Vec::new();
        // Poles of the normalised prototype: exp(iπ(2k + n + 1)/(2n)), k = 0..n-1; take the
        // upper-half-plane member of each conjugate pair.
        let n = order as f64;
        for k in 0..order / 2 {
            let theta = std::f64::consts::PI * (2.0 * k as f64 + n + 1.0) / (2.0 * n);
            let (sre, sim) = (warped * theta.cos(), warped * theta.sin());
            // z = (fs2 + s) / (fs2 − s)
            let (nre, nim) = (fs2 + sre, sim);
            let (dre, dim) = (fs2 - sre, -sim);
            let den = dre * dre + dim * dim;
            let zre = (nre * dre + nim * dim) / den;
            let zim = (nim * dre - nre * dim) / den;
            let a = [1.0, -2.0 * zre, zre * zre + zim * zim];
            let g = (a[0] + a[1] + a[2]) / 4.0;
            sections.push(Biquad {
                b: [g, 2.0 * g, g],
                a,
            });
        }
        if order % 2 == 1 {
            let s = -warped;
            let z = (fs2 + s) / (fs2 - s);
            let g = (1.0 - z) / 2.0;
            sections.push(Biquad {
                b: [g, g, 0.0],
                a: [1.0, -z, 0.0],
            });
        }
        Ok(Butterworth {
            order,
            cutoff_hz,
            rate_hz,
            sections,
        })
    }

    /// The filter order.
    pub fn order(&self) -> usize {
        self.order
    }
    /// The cutoff, Hz.
    pub fn cutoff_hz(&self) -> f64 {
        self.cutoff_hz
    }
    /// The sampling rate, Hz.
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
    /// The second-order sections.
    pub fn sections(&self) -> &[Biquad] {
        &self.sections
    }

    /// Number of edge samples padded on each side (scipy: `3 × ntaps`).
    pub fn pad_len(&self) -> usize {
        let ntaps = 2 * self.sections.len() + 1;
        let bz = self.sections.iter().filter(|s| s.b[2] == 0.0).count();
        let az = self.sections.iter().filter(|s| s.a[2] == 0.0).count();
        3 * (ntaps - bz.min(az))
    }

    /// The shortest signal [`Butterworth::filtfilt`] accepts.
    pub fn min_len(&self) -> usize {
        self.pad_len() + 1
    }

    /// Magnitude of the (single-pass) frequency response at `f_hz`.
    pub fn magnitude(&self, f_hz: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f_hz / self.rate_hz;
        let (c1, s1, c2, s2) = (w.cos(), w.sin(), (2.0 * w).cos(), (2.0 * w).sin());
        let mut mag = 1.0;
        for s in &self.sections {
            let nre = s.b[0] + s.b[1] * c1 + s.b[2] * c2;
            let nim = -(s.b[1] * s1 + s.b[2] * s2);
            let dre = s.a[0] + s.a[1] * c1 + s.a[2] * c2;
            let dim = -(s.a[1] * s1 + s.a[2] * s2);
            mag *= ((nre * nre + nim * nim) / (dre * dre + dim * dim)).sqrt();
        }
        mag
    }

    /// One causal pass over `x` with initial section states `zi × x[0]`.
    fn pass(&self, x: &mut [f64]) {
        let Some(&x0) = x.first() else { return };
        let mut scale = x0;
        let mut states: Vec<[f64; 2]> = Vec::with_capacity(self.sections.len());
        for s in &self.sections {
            let z = s.step_state();
            states.push([z[0] * scale, z[1] * scale]);
            scale *= s.dc_gain();
        }
        for v in x.iter_mut() {
            let mut u = *v;
            for (s, z) in self.sections.iter().zip(states.iter_mut()) {
                let y = s.b[0] * u + z[0];
                z[0] = s.b[1] * u - s.a[1] * y + z[1];
                z[1] = s.b[2] * u - s.a[2] * y;
                u = y;
            }
            *v = u;
        }
    }

    /// Zero-phase filtering of `x` (forward and backward pass with odd edge extension).
    ///
    /// `x` must be finite and at least [`Butterworth::min_len`] samples long; the caller names
    /// the signal in the error (see [`filtfilt_gappy`] for signals with gaps).
    pub fn filtfilt(&self, x: &[f64]) -> Option<Vec<f64>> {
        let n = x.len();
        let pad = self.pad_len();
        if n <= pad || x.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut ext = Vec::with_capacity(n + 2 * pad);
        let (first, last) = (x[0], x[n - 1]);
        for i in (1..=pad).rev() {
            ext.push(2.0 * first - x[i]);
        }
        ext.extend_from_slice(x);
        for i in 1..=pad {
            ext.push(2.0 * last - x[n - 1 - i]);
        }
        self.pass(&mut ext);
        ext.reverse();
        self.pass(&mut ext);
        ext.reverse();
        Some(ext[pad..pad + n].to_vec())
    }
}

/// Filters each finite run of `x` separately; runs shorter than the filter's minimum length are
/// returned unfiltered (they are too short to carry a gait event). `NaN` stays `NaN`.
pub fn filtfilt_gappy(filter: &Butterworth, x: &[f64]) -> Vec<f64> {
    let mut out = x.to_vec();
    let mut i = 0;
    while i < x.len() {
        if !x[i].is_finite() {
            i += 1;
            continue;
        }
        let start = i;
        while i < x.len() && x[i].is_finite() {
            i += 1;
        }
        if let Some(y) = filter.filtfilt(&x[start..i]) {
            out[start..i].copy_from_slice(&y);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal() -> Vec<f64> {
        (0..200)
            .map(|i| {
                let t = i as f64;
                (2.0 * std::f64::consts::PI * 3.0 * t / 100.0).sin()
                    + 0.5 * (2.0 * std::f64::consts::PI * 30.0 * t / 100.0).sin()
                    + 0.01 * t
                    + 0.3 * ((0.7 * t * t) % 13.0).cos()
            })
            .collect()
    }

    /// Expected values: `scipy.signal.sosfiltfilt(scipy.signal.butter(order, fc, fs=fs,
    /// output='sos'), x)` with scipy 1.17.1, numpy float64, for the signal above (the Python
    /// expression `np.sin(2π·3i/100) + 0.5·np.sin(2π·30i/100) + 0.01i + 0.3·np.cos(0.7·(i² % 13))`).
    #[test]
    fn matches_scipy_sosfiltfilt() {
        let idx = [0usize, 1, 5, 50, 100, 150, 198, 199];
        let cases: [(usize, f64, f64, [f64; 8]); 3] = [
            (
                2,
                6.0,
                100.0,
                [
                    0.2914894765083959,
                    0.4170269002672995,
                    0.8945927892876188,
                    0.5706654433365475,
                    0.8841366891366133,
                    1.6169229224248964,
                    1.2993175243877062,
                    1.3142773640830452,
                ],
            ),
            (
                4,
                20.0,
                300.0,
                [
                    0.29479354412357767,
                    0.43631295257189123,
                    0.9340881822845151,
                    0.5676273682559245,
                    0.8647950731645335,
                    1.6325678451576269,
                    1.3102771795510448,
                    1.3384649154205974,
                ],
            ),
            (
                3,
                10.0,
                100.0,
                [
                    0.3038088452673822,
                    0.40124303707333775,
                    0.907467287412059,
                    0.5229399869654493,
                    0.8682073216833892,
                    1.6568968643000974,
                    1.3777074486105998,
                    1.3287885361032112,
                ],
            ),
        ];
        let x = signal();
        for (order, fc, fs, expected) in cases {
            let f = Butterworth::low_pass(order, fc, fs).unwrap();
            let y = f.filtfilt(&x).unwrap();
            for (k, &i) in idx.iter().enumerate() {
                assert!(
                    (y[i] - expected[k]).abs() < 1e-12,
                    "order {order} fc {fc}: y[{i}] = {} vs scipy {}",
                    y[i],
                    expected[k]
                );
            }
        }
    }

    /// scipy's `butter(2, 6, fs=100, output='sos')` = [[0.02785976611713602, …, 1,
    /// −1.475480443592646, 0.5869195080611902]].
    #[test]
    fn second_order_coefficients_match_scipy() {
        let f = Butterworth::low_pass(2, 6.0, 100.0).unwrap();
        let s = f.sections()[0];
        assert!((s.b[0] - 0.02785976611713602).abs() < 1e-15);
        assert!((s.a[1] + 1.475480443592646).abs() < 1e-14);
        assert!((s.a[2] - 0.5869195080611902).abs() < 1e-14);
    }

    #[test]
    fn magnitude_is_butterworth() {
        for order in 1..=6 {
            let f = Butterworth::low_pass(order, 20.0, 1000.0).unwrap();
            assert!((f.magnitude(0.0) - 1.0).abs() < 1e-12);
            assert!((f.magnitude(20.0) - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-9);
            assert!(f.magnitude(200.0) < f.magnitude(100.0));
        }
    }

    #[test]
    fn constant_passes_and_ramp_matches_scipy() {
        let f = Butterworth::low_pass(2, 6.0, 100.0).unwrap();
        let c = vec![3.5; 50];
        for v in f.filtfilt(&c).unwrap() {
            assert!((v - 3.5).abs() < 1e-12);
        }
        // A ramp is bent only near the ends (scipy: max deviation 0.0261 for this ramp); the
        // middle passes through.
        let r: Vec<f64> = (0..60).map(|i| 0.1 * i as f64 - 2.0).collect();
        let y = f.filtfilt(&r).unwrap();
        let worst = y
            .iter()
            .zip(&r)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!((worst - 0.026100005743497245).abs() < 1e-9, "{worst}");
        assert!((y[30] - r[30]).abs() < 1e-3);
    }

    #[test]
    fn rejects_bad_settings_and_short_signals() {
        assert!(Butterworth::low_pass(2, 60.0, 100.0).is_err());
        assert!(Butterworth::low_pass(0, 6.0, 100.0).is_err());
        assert!(Butterworth::low_pass(2, 6.0, f64::NAN).is_err());
        let f = Butterworth::low_pass(2, 6.0, 100.0).unwrap();
        assert_eq!(f.pad_len(), 9);
        assert!(f.filtfilt(&[1.0; 9]).is_none());
        assert!(f.filtfilt(&[1.0; 10]).is_some());
    }

    #[test]
    fn gappy_filters_each_run() {
        let f = Butterworth::low_pass(2, 6.0, 100.0).unwrap();
        let mut x: Vec<f64> = vec![1.0; 40];
        x[20] = f64::NAN;
        x[2] = f64::NAN;
        let y = filtfilt_gappy(&f, &x);
        assert!(y[20].is_nan() && y[2].is_nan());
        assert_eq!(y[0], 1.0); // run of 2: left as is
        assert!((y[10] - 1.0).abs() < 1e-12);
    }
}
