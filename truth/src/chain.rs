//! The belt as a closed chain of point masses in maximal coordinates:
//! node positions and velocities in the plane, stiff axial springs with
//! damping between neighbours, and at every node a bending moment from the
//! continuum law at the node's discrete curvature `κ = θ/ℓ0` (θ the
//! turning angle between the two segments, ℓ0 their rest length).
//!
//! The bending energy of a node is `ℓ0·W(κ)` (W the energy per unit
//! length), so its generalised force against θ is `M(κ)`: the forces on
//! the three nodes are `−M·∂θ/∂x`. The same holds for the dissipative
//! moment (a Rayleigh function per unit length). Nothing here depends on
//! the number of nodes but the resolution.

use crate::law::{FrictionLaw, Material};

/// 2-vector.
pub type V2 = [f64; 2];

fn perp(a: V2) -> V2 {
    [-a[1], a[0]]
}

/// The chain's state and its per-node internal variables.
#[derive(Debug, Clone)]
pub struct Chain {
    /// Number of nodes.
    pub n: usize,
    /// Rest length of a segment, m.
    pub l0: f64,
    /// Half the belt thickness, m (nodes sit on the neutral axis).
    pub half_t: f64,
    /// Mass of a node, kg.
    pub node_mass: f64,
    /// Axial stiffness of a segment, N/m.
    pub k_axial: f64,
    /// Axial damping of a segment, N·s/m.
    pub c_axial: f64,
    /// Positions, m.
    pub x: Vec<V2>,
    /// Velocities, m/s.
    pub v: Vec<V2>,
    /// Forces of the current step, N.
    pub f: Vec<V2>,
    /// Per-node factor on the elastic law (the belt is not uniform).
    pub ei_scale: Vec<f64>,
    /// Discrete curvature at each node, 1/m (last force evaluation).
    pub kappa: Vec<f64>,
    /// Curvature rate, 1/(m·s).
    pub rate: Vec<f64>,
    /// Dahl friction moment state, N·m.
    pub dahl: Vec<f64>,
    /// Slow mean curvature (Payne memory), 1/m.
    pub kbar: Vec<f64>,
    /// Remembered strain amplitude (Payne memory), 1/m.
    pub amp: Vec<f64>,
    /// Power dissipated in bending in the last evaluation, W.
    pub bending_power_w: f64,
}

impl Chain {
    /// A chain with nodes at `x` (a closed loop, counter-clockwise), at rest.
    pub fn new(
        x: Vec<V2>,
        l0: f64,
        half_t: f64,
        mass_kg: f64,
        ea_n: f64,
        ei_scale: Vec<f64>,
    ) -> Self {
        let n = x.len();
        let node_mass = mass_kg / n as f64;
        let k_axial = ea_n / l0;
        // About 5 % of critical damping of one segment's axial mode.
        let c_axial = 0.1 * (k_axial * node_mass).sqrt();
        Chain {
            n,
            l0,
            half_t,
            node_mass,
            k_axial,
            c_axial,
            v: vec![[0.0; 2]; n],
            f: vec![[0.0; 2]; n],
            ei_scale,
            kappa: vec![0.0; n],
            rate: vec![0.0; n],
            dahl: vec![0.0; n],
            kbar: vec![0.0; n],
            amp: vec![0.0; n],
            bending_power_w: 0.0,
            x,
        }
    }

    /// Clear the forces and add the internal ones (axial springs, bending),
    /// with the elastic law times `stiff` and the dissipative laws times
    /// `damp` (temperature factors).
    pub fn internal_forces(&mut self, mat: &Material, stiff: f64, damp: f64) {
        let n = self.n;
        for f in self.f.iter_mut() {
            *f = [0.0; 2];
        }
        // Axial springs.
        for j in 0..n {
            let k = (j + 1) % n;
            let d = [self.x[k][0] - self.x[j][0], self.x[k][1] - self.x[j][1]];
            let len = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-12);
            let e = [d[0] / len, d[1] / len];
            let dv = [self.v[k][0] - self.v[j][0], self.v[k][1] - self.v[j][1]];
            let t = self.k_axial * (len - self.l0) + self.c_axial * (dv[0] * e[0] + dv[1] * e[1]);
            self.f[j][0] += t * e[0];
            self.f[j][1] += t * e[1];
            self.f[k][0] -= t * e[0];
            self.f[k][1] -= t * e[1];
        }
        // Bending.
        let mut power = 0.0;
        for i in 0..n {
            let p = (i + n - 1) % n;
            let q = (i + 1) % n;
            let a = [self.x[i][0] - self.x[p][0], self.x[i][1] - self.x[p][1]];
            let b = [self.x[q][0] - self.x[i][0], self.x[q][1] - self.x[i][1]];
            let cross = a[0] * b[1] - a[1] * b[0];
            let dot = a[0] * b[0] + a[1] * b[1];
            let theta = cross.atan2(dot);
            let la2 = (a[0] * a[0] + a[1] * a[1]).max(1e-18);
            let lb2 = (b[0] * b[0] + b[1] * b[1]).max(1e-18);
            let pa = perp(a);
            let pb = perp(b);
            let ga = [pa[0] / la2, pa[1] / la2];
            let gb = [pb[0] / lb2, pb[1] / lb2];
            let gi = [-ga[0] - gb[0], -ga[1] - gb[1]];
            let theta_dot = ga[0] * self.v[p][0]
                + ga[1] * self.v[p][1]
                + gi[0] * self.v[i][0]
                + gi[1] * self.v[i][1]
                + gb[0] * self.v[q][0]
                + gb[1] * self.v[q][1];
            let k = theta / self.l0;
            let r = theta_dot / self.l0;
            self.kappa[i] = k;
            self.rate[i] = r;
            let s = self.ei_scale[i] * stiff;
            let m_el = match mat.payne {
                None => s * mat.elastic.moment(k),
                Some(pl) => {
                    let mb = mat.elastic.moment(self.kbar[i]);
                    s * (mb + pl.factor(self.amp[i]) * (mat.elastic.moment(k) - mb))
                }
            };
            let m_fr = match mat.friction {
                FrictionLaw::None => 0.0,
                FrictionLaw::Dahl { .. } => self.dahl[i] * damp,
                FrictionLaw::Tanh { m_c, rate } => damp * m_c * (r / rate).tanh(),
            };
            let m_d = damp * mat.damping.moment(r) + m_fr;
            power += m_d * theta_dot;
            let m = m_el + m_d;
            self.f[p][0] -= m * ga[0];
            self.f[p][1] -= m * ga[1];
            self.f[i][0] -= m * gi[0];
            self.f[i][1] -= m * gi[1];
            self.f[q][0] -= m * gb[0];
            self.f[q][1] -= m * gb[1];
        }
        self.bending_power_w = power;
    }

    /// Add gravity (g downwards, m/s²).
    pub fn gravity(&mut self, g: f64) {
        let w = self.node_mass * g;
        for f in self.f.iter_mut() {
            f[1] -= w;
        }
    }

    /// Add a drag `−c·m·v` on every node (used only while settling).
    pub fn settling_drag(&mut self, c_per_s: f64) {
        let c = c_per_s * self.node_mass;
        for (f, v) in self.f.iter_mut().zip(&self.v) {
            f[0] -= c * v[0];
            f[1] -= c * v[1];
        }
    }

    /// Kick–drift step (symplectic Euler) with the forces in `f`.
    pub fn advance(&mut self, h: f64) {
        let a = h / self.node_mass;
        for ((x, v), f) in self.x.iter_mut().zip(self.v.iter_mut()).zip(&self.f) {
            v[0] += a * f[0];
            v[1] += a * f[1];
            x[0] += h * v[0];
            x[1] += h * v[1];
        }
    }

    /// Update the internal variables (Dahl moment, Payne memory) over a
    /// step `h`, with the curvatures and rates of the last evaluation.
    pub fn update_states(&mut self, mat: &Material, h: f64) {
        if let FrictionLaw::Dahl { m_c, kappa_s } = mat.friction {
            for (z, r) in self.dahl.iter_mut().zip(&self.rate) {
                let dk = r * h;
                if dk != 0.0 {
                    let target = m_c * dk.signum();
                    *z = target + (*z - target) * (-dk.abs() / kappa_s).exp();
                }
            }
        }
        if let Some(pl) = mat.payne {
            let am = 1.0 - (-h / pl.tau_mean_s).exp();
            let aa = 1.0 - (-h / pl.tau_mem_s).exp();
            for i in 0..self.n {
                self.kbar[i] += (self.kappa[i] - self.kbar[i]) * am;
                let dev = std::f64::consts::FRAC_PI_2 * (self.kappa[i] - self.kbar[i]).abs();
                self.amp[i] += (dev - self.amp[i]) * aa;
            }
        }
    }

    /// Start the Payne memory at the present shape (mean = now, no amplitude).
    pub fn reset_memory(&mut self) {
        self.kbar.copy_from_slice(&self.kappa);
        for a in self.amp.iter_mut() {
            *a = 0.0;
        }
    }

    /// Kinetic energy, J.
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.node_mass
            * self
                .v
                .iter()
                .map(|v| v[0] * v[0] + v[1] * v[1])
                .sum::<f64>()
    }

    /// Elastic energy (bending and axial), J, of the elastic law alone.
    pub fn elastic_energy(&self, mat: &Material) -> f64 {
        let mut e = 0.0;
        for i in 0..self.n {
            let p = (i + self.n - 1) % self.n;
            let q = (i + 1) % self.n;
            let a = [self.x[i][0] - self.x[p][0], self.x[i][1] - self.x[p][1]];
            let b = [self.x[q][0] - self.x[i][0], self.x[q][1] - self.x[i][1]];
            let theta = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
            e += self.l0 * self.ei_scale[i] * mat.elastic.energy_density(theta / self.l0);
            let len = (b[0] * b[0] + b[1] * b[1]).sqrt();
            e += 0.5 * self.k_axial * (len - self.l0) * (len - self.l0);
        }
        e
    }

    /// Height of the centre of mass, m.
    pub fn mean_height(&self) -> f64 {
        self.x.iter().map(|x| x[1]).sum::<f64>() / self.n as f64
    }

    /// Largest node speed, m/s.
    pub fn max_speed(&self) -> f64 {
        self.v
            .iter()
            .map(|v| (v[0] * v[0] + v[1] * v[1]).sqrt())
            .fold(0.0, f64::max)
    }

    /// True when every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.x
            .iter()
            .chain(&self.v)
            .all(|p| p[0].is_finite() && p[1].is_finite())
    }

    /// Overall width of the outer surface, m.
    pub fn width(&self) -> f64 {
        let lo = self.x.iter().map(|x| x[0]).fold(f64::INFINITY, f64::min);
        let hi = self
            .x
            .iter()
            .map(|x| x[0])
            .fold(f64::NEG_INFINITY, f64::max);
        hi - lo + 2.0 * self.half_t
    }

    /// The explicit step that keeps the kick–drift scheme stable, s, for
    /// bending tangent stiffness up to `b_max` (N·m²), bending damping slope
    /// up to `c_max` (N·m²·s) and an extra contact stiffness `k_contact`
    /// (N/m) and contact damping `c_contact` (N·s/m) on a node.
    ///
    /// Reasoning: the fastest modes of a node chain are the axial one
    /// (ω² = 4k/m, k the segment stiffness, plus a quarter of the contact
    /// stiffness) and the bending zig-zag (ω² = 16·B/(m·ℓ0³), from θ = 4u/ℓ0
    /// at every node); the zig-zag's damping rate is γ = 16·c/(m·ℓ0³) (plus
    /// the axial and contact damping). Kick–drift with the damping taken at
    /// the old velocity has, for `x'' = −ω²x − γx'`, the amplification
    /// matrix with trace 2 − h²ω² − hγ and determinant 1 − hγ: it is stable
    /// for hγ < 2 and h²ω² + 2hγ < 4. We take the root of the second and
    /// keep a factor `safety` (< 1) below it for the nonlinear laws.
    pub fn stable_step(
        &self,
        b_max: f64,
        c_max: f64,
        k_contact: f64,
        c_contact: f64,
        safety: f64,
    ) -> f64 {
        let m = self.node_mass;
        let l3 = self.l0 * self.l0 * self.l0;
        let w2 = 4.0 * (self.k_axial + 0.25 * k_contact) / m + 16.0 * b_max / (m * l3);
        let g = (16.0 * c_max / l3 + 4.0 * self.c_axial + c_contact) / m;
        safety * (2.0 * (g * g + 4.0 * w2).sqrt() - 2.0 * g) / (2.0 * w2)
    }
}
