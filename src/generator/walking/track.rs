//! Recorded trajectories of a phase: nodes `(t, q, q̇, q̈)` and quintic Hermite interpolation
//! between them (exact in position, velocity and acceleration at the nodes), so the swing
//! simulation can read the stance hip's acceleration at any instant.
use crate::generator::curves::Quintic;

/// One recorded node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node<const N: usize> {
    /// Time, s.
    pub t: f64,
    /// Coordinates.
    pub q: [f64; N],
    /// Velocities.
    pub qd: [f64; N],
    /// Accelerations (the limit from inside the interval that follows, or precedes for the last
    /// node of a segment).
    pub qdd: [f64; N],
}

/// A recorded trajectory. Segment boundaries (where the equations switch) appear as two nodes at
/// the same time; interpolation never crosses them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Track<const N: usize> {
    /// The nodes in time order.
    pub nodes: Vec<Node<N>>,
}

impl<const N: usize> Track<N> {
    /// Appends a node (times must not decrease).
    pub fn push(&mut self, n: Node<N>) {
        self.nodes.push(n);
    }

    /// First and last time.
    pub fn span(&self) -> (f64, f64) {
        match (self.nodes.first(), self.nodes.last()) {
            (Some(a), Some(b)) => (a.t, b.t),
            _ => (0.0, 0.0),
        }
    }

    /// Times where two nodes coincide (switches of the equations of motion).
    pub fn breakpoints(&self) -> Vec<f64> {
        self.nodes
            .windows(2)
            .filter(|w| w[1].t == w[0].t)
            .map(|w| w[0].t)
            .collect()
    }

    /// `(q, q̇, q̈)` at `t` (clamped to the span). For `t` on a breakpoint the later segment is
    /// used.
    pub fn at(&self, t: f64) -> ([f64; N], [f64; N], [f64; N]) {
        let n = self.nodes.len();
        if n == 0 {
            return ([0.0; N], [0.0; N], [0.0; N]);
        }
        if n == 1 || t <= self.nodes[0].t {
            let a = &self.nodes[0];
            return (a.q, a.qd, a.qdd);
        }
        if t >= self.nodes[n - 1].t {
            let a = &self.nodes[n - 1];
            return (a.q, a.qd, a.qdd);
        }
        // Last node with time ≤ t, then skip zero-length intervals forward.
        let mut k = self.nodes.partition_point(|x| x.t <= t).saturating_sub(1);
        while k + 1 < n && self.nodes[k + 1].t == self.nodes[k].t {
            k += 1;
        }
        if k + 1 >= n {
            let a = &self.nodes[n - 1];
            return (a.q, a.qd, a.qdd);
        }
        let (a, b) = (&self.nodes[k], &self.nodes[k + 1]);
        let h = b.t - a.t;
        let s = (t - a.t) / h;
        let mut q = [0.0; N];
        let mut qd = [0.0; N];
        let mut qdd = [0.0; N];
        for i in 0..N {
            let seg = Quintic::new([a.q[i], a.qd[i], a.qdd[i]], [b.q[i], b.qd[i], b.qdd[i]], h);
            [q[i], qd[i], qdd[i]] = seg.at_fraction(s);
        }
        (q, qd, qdd)
    }
}

/// Linear interpolation of `(t, ρ)` roll samples at `t`, held at the end values outside them
/// (the walk's frames and the stop read the virtual legs' recorded rolls this way).
pub fn interp_rho(samples: &[(f64, f64)], t: f64) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    let k = samples.partition_point(|s| s.0 <= t);
    if k == 0 {
        return samples[0].1;
    }
    if k >= samples.len() {
        return samples[samples.len() - 1].1;
    }
    let (a, b) = (samples[k - 1], samples[k]);
    if b.0 == a.0 {
        return b.1;
    }
    a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_hermite_reproduces_smooth_motion() {
        let f = |t: f64| (2.0 * t).sin();
        let mut tr = Track::<1>::default();
        for k in 0..=50 {
            let t = k as f64 * 0.02;
            tr.push(Node {
                t,
                q: [f(t)],
                qd: [2.0 * (2.0 * t).cos()],
                qdd: [-4.0 * f(t)],
            });
        }
        for k in 0..97 {
            let t = 0.0103 * k as f64;
            let (q, qd, qdd) = tr.at(t);
            assert!((q[0] - f(t)).abs() < 1e-12);
            assert!((qd[0] - 2.0 * (2.0 * t).cos()).abs() < 1e-9);
            assert!((qdd[0] + 4.0 * f(t)).abs() < 1e-6);
        }
    }

    #[test]
    fn breakpoints_split_the_interpolation() {
        let mut tr = Track::<1>::default();
        tr.push(Node {
            t: 0.0,
            q: [0.0],
            qd: [0.0],
            qdd: [1.0],
        });
        tr.push(Node {
            t: 1.0,
            q: [0.5],
            qd: [1.0],
            qdd: [1.0],
        });
        tr.push(Node {
            t: 1.0,
            q: [0.5],
            qd: [1.0],
            qdd: [-1.0],
        });
        tr.push(Node {
            t: 2.0,
            q: [1.0],
            qd: [0.0],
            qdd: [-1.0],
        });
        assert_eq!(tr.breakpoints(), vec![1.0]);
        assert!((tr.at(0.5).2[0] - 1.0).abs() < 1e-12);
        assert!((tr.at(1.5).2[0] + 1.0).abs() < 1e-12);
        assert!((tr.at(1.5).0[0] - (0.5 + 0.5 - 0.125)).abs() < 1e-12);
    }
}
